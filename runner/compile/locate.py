"""Where an XML element came from: file and line, also through xacro.

xacro's output is a new document, so its line numbers mean nothing to a user. For an element of expanded
xacro output we look for its most distinctive attribute (`name="..."`, `filename="..."`) in the xacro
file and every file it included, and point there.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any


class Locator:
    """file:line of an element: the URDF's own line, or for xacro output, the line in the xacro sources
    that holds the element's most distinctive attribute."""

    def __init__(
        self,
        file: Path | None,
        sources: list[Path],
        expanded: bool,
        origins: list[tuple[Path, int] | None] | None = None,
    ):
        self.file = file
        self.sources = sources
        self.expanded = expanded
        self._texts: dict[Path, list[str]] = {}
        self._origins = origins
        self._of: dict[int, tuple[Path, int]] = {}
        self._keep: list[Any] = []

    def bind(self, root: Any) -> None:
        """The parsed output of xacro: each element's origin as xacro recorded it (the file and line it is
        written at, a macro's element in the macro's file), known by the element itself from now on, however
        the tree changes."""
        if self._origins is None:
            return
        elements = [e for e in root.iter() if isinstance(e.tag, str)]
        if len(elements) != len(self._origins):
            return  # (not the tree xacro wrote: the search below)
        self._keep = elements  # (lxml keeps an element's proxy, and so its id, while one is referenced)
        self._of = {id(e): o for e, o in zip(elements, self._origins, strict=True) if o is not None}

    def __call__(self, el: Any) -> tuple[Path | None, int | None]:
        if not self.expanded:
            return self.file, el.sourceline
        found = self._of.get(id(el))
        if found is not None:
            return found
        keys = ("filename", "name", "reference", "type")
        needles = [f'{k}="{v}"' for k, v in el.attrib.items() if k in keys]
        for needle in needles:
            for src in self.sources:
                line = self._find(src, needle, 0)
                if line is not None:
                    return src, line
        # No distinctive attribute: the first such tag after the parent's line, in the parent's file.
        parent = el.getparent()
        if parent is not None:
            file, start = self(parent)
            if file is not None and start is not None:
                line = self._find(file, f"<{el.tag}", start)
                if line is not None:
                    return file, line
        for src in self.sources:
            line = self._find(src, f"<{el.tag}", 0)
            if line is not None:
                return src, line
        return self.file, None

    def _find(self, src: Path, needle: str, start: int) -> int | None:
        lines = self._texts.get(src)
        if lines is None:
            try:
                lines = src.read_text(encoding="utf-8", errors="replace").splitlines()
            except OSError:
                lines = []
            self._texts[src] = lines
        for i in range(max(start - 1, 0), len(lines)):
            if needle in lines[i]:
                return i + 1
        return None
