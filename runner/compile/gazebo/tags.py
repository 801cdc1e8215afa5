"""Reading Gazebo tags: `TagReader` reads an element's children by any of their spellings and remembers
which it read (what is left is reported), and the small helpers every part shares to turn tag text into
numbers, ROS topic names and plugin names."""

from __future__ import annotations

import re
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Any

# While `reading()` is active: every element a TagReader handed out (tests/test_sensor_ledger.py checks
# that each element of a description was read or said). The list keeps the elements alive, so that lxml's
# proxies (and their ids) stay theirs.
_READ: ContextVar[list[Any] | None] = ContextVar("gazebo_tags_read", default=None)


@contextmanager
def reading() -> Iterator[list[Any]]:
    """Record every element `TagReader.child()`/`.children()` returns while active; yields the list."""
    taken: list[Any] = []
    token = _READ.set(taken)
    try:
        yield taken
    finally:
        _READ.reset(token)


def _record(*els: Any) -> None:
    taken = _READ.get()
    if taken is not None:
        taken.extend(els)


class TagReader:
    """Reads children of one element by any of several spellings and remembers which were used.

    `attr_values`: a child's `value` attribute stands for its text, as in the URDF extension keys of a
    `<gazebo>` block (`<mu1 value="0.5"/>` is `<mu1>0.5</mu1>` to Gazebo's URDF parser, the attribute
    winning when both are given). Plugin and sensor parameters are SDF and have no such form."""

    def __init__(self, el: Any, attr_values: bool = False):
        self.el = el
        self.attr_values = attr_values
        self.used: set[str] = set()  # tags read whole (every element of that name)
        self.single: set[str] = set()  # tags read as one value: a repeated one is reported, not dropped
        # elements read one by one, kept alive: lxml hands out the same proxy only while one is referenced
        self._taken: list[Any] = []
        self.not_numbers: list[tuple[Any, str | None]] = []  # (element, text) asked as a number, not one

    def child(self, *names: str) -> Any | None:
        for n in names:
            found = self.el.find(n)
            if found is not None:
                self.single.add(n)
                if not any(found is t for t in self._taken):
                    self._taken.append(found)
                _record(found)
                return found
        return None

    def children(self, *names: str) -> list[Any]:
        out = []
        for n in names:
            found = self.el.findall(n)
            if found:
                self.used.add(n)
                out += found
                _record(*found)
        return out

    def text(self, *names: str) -> str | None:
        el = self.child(*names)
        if el is None:
            return None
        if self.attr_values and el.get("value") is not None:
            return str(el.get("value")).strip()
        return el.text.strip() if el.text is not None else None

    def float(self, *names: str) -> float | None:
        t = self.text(*names)
        try:
            return float(t) if t is not None else None
        except ValueError:
            # Gazebo logs that it cannot read it and uses its default: so do we, said at the tag
            self.not_numbers.append((self.child(*names), t))
            return None

    def bool(self, *names: str) -> bool | None:
        t = self.text(*names)
        if t is None:
            return None
        return t.lower() in ("1", "true", "yes", "on")

    def mark(self, *names: str) -> None:
        self.used.update(names)

    def leftovers(self) -> list[Any]:
        """Elements nothing read: unknown tags, and the second and later copies of a one-value tag."""
        return [
            c
            for c in self.el
            if isinstance(c.tag, str) and c.tag not in self.used and not any(c is t for t in self._taken)
        ]


class SdfReader(TagReader):
    """A TagReader of an SDF element sdformat itself parses (a `<sensor>` and its blocks): a value that is
    not a number is an error there (sdformat refuses the description), not a default as a plugin's
    parameter is: `float` raises ValueError, which the Gazebo reader turns into an error at the tag."""

    def float(self, *names: str) -> float | None:
        t = self.text(*names)
        return float(t) if t is not None else None


def floats(text: str | None, n: int) -> list[float] | None:
    if not text:
        return None
    try:
        vals = [float(v) for v in text.split()]
    except ValueError:
        return None
    return vals if len(vals) == n else None


def ros_topic(name: str | None) -> str | None:
    """A ROS topic from a plugin parameter, relative to the robot's namespace (leading '/' dropped:
    the scenario places every robot's topics under its namespace)."""
    if name is None:
        return None
    name = name.strip().strip("/")
    name = re.sub(r"^~/?", "", name)
    return name or None


def join_topic(*parts: str | None) -> str:
    return "/".join(p.strip("/") for p in parts if p and p.strip("/"))


def sibling_topic(topic: str, name: str) -> str:
    head = topic.rsplit("/", 1)[0] if "/" in topic else ""
    return join_topic(head, name)


def plugin_base(filename: str) -> str:
    """`libgazebo_ros_diff_drive.so` -> `gazebo_ros_diff_drive`; `gz-sim-diff-drive-system` as is."""
    base = Path(filename).name
    base = re.sub(r"\.so(\.\d+)*$", "", base)
    base = re.sub(r"^lib", "", base)
    return re.sub(r"^(ignition-gazebo|gz-sim)\d*-", "gz-sim-", base)


def is_zero(text: str | None) -> bool:
    """An unset, zero or false parameter value."""
    if text is None or not text.strip():
        return True
    try:
        return float(text) == 0.0
    except ValueError:
        return text.strip().lower() == "false"
