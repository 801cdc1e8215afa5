"""YAML -> plain data, remembering where every node came from.

`load_file` returns a `Document`: the data (dicts, lists, scalars, exactly as `yaml.safe_load` would give)
and a table from each node's path (`("robots", 1, "plugins", 0)`) to its file/line/column, so that any
later pass can point at the line. Duplicate keys are an error (plain PyYAML keeps the last one silently).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from runner.errors import Location, Problem, ScenarioError

PathKey = tuple[str | int, ...]


@dataclass
class Document:
    data: Any
    file: Path | None
    positions: dict[PathKey, Location] = field(default_factory=dict)

    def locate(self, path: PathKey) -> Location:
        """The location of `path`, or of its nearest ancestor that exists in the file."""
        p = tuple(path)
        while p:
            if p in self.positions:
                return self.positions[p]
            p = p[:-1]
        return self.positions.get((), Location(self.file, 1, 1))

    @property
    def base_dir(self) -> Path:
        return self.file.parent if self.file else Path.cwd()


class _Builder:
    def __init__(self, file: Path | None):
        self.file = file
        self.positions: dict[PathKey, Location] = {}
        # A SafeLoader instance only to reuse its scalar resolution (ints, floats, bools, nulls...).
        self._scalars = yaml.SafeLoader("")

    def mark(self, node: yaml.Node) -> Location:
        return Location(self.file, node.start_mark.line + 1, node.start_mark.column + 1)

    def build(self, node: yaml.Node, path: PathKey) -> Any:
        self.positions[path] = self.mark(node)
        if isinstance(node, yaml.MappingNode):
            self._scalars.flatten_mapping(node)  # handles `<<: *anchor` merges
            out: dict[Any, Any] = {}
            for key_node, value_node in node.value:
                key = self._scalars.construct_object(key_node, deep=True)
                if not isinstance(key, str | int | float | bool) and key is not None:
                    raise ScenarioError(
                        Problem(
                            "a mapping key must be a plain value",
                            self.mark(key_node),
                            path,
                            found=type(key).__name__,
                        )
                    )
                if key in out:
                    raise ScenarioError(
                        Problem(
                            f"duplicate key {key!r}",
                            self.mark(key_node),
                            path,
                            hint=f"{key!r} is already set at line {self.positions[(*path, key)].line}; "
                            "remove one of them",
                        )
                    )
                key_path = (*path, key)
                out[key] = self.build(value_node, key_path)
                # Point at the key rather than at the value: that is where a reader looks.
                self.positions[key_path] = self.mark(key_node)
            return out
        if isinstance(node, yaml.SequenceNode):
            return [self.build(item, (*path, i)) for i, item in enumerate(node.value)]
        return self._scalars.construct_object(node, deep=True)


def load_text(text: str, file: Path | None = None) -> Document:
    try:
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        loc = Location(file, mark.line + 1, mark.column + 1) if mark else Location(file)
        raise ScenarioError(
            Problem(
                f"this is not valid YAML: {e.problem or e.context}",
                loc,
                hint="check the indentation and that every `key: value` has a space after the colon",
            )
        ) from None
    except yaml.YAMLError as e:
        raise ScenarioError(Problem(f"this is not valid YAML: {e}", Location(file))) from None
    if node is None:
        return Document({}, file, {(): Location(file, 1, 1)})
    builder = _Builder(file)
    data = builder.build(node, ())
    return Document(data, file, builder.positions)


def load_file(path: str | Path) -> Document:
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(
            Problem("file not found", Location(p), hint="check the path (relative to the current folder)")
        ) from None
    except IsADirectoryError:
        raise ScenarioError(Problem("this is a folder, not a scenario file", Location(p))) from None
    except UnicodeDecodeError as e:
        raise ScenarioError(Problem(f"not a UTF-8 text file ({e.reason})", Location(p))) from None
    return load_text(text, p.resolve())
