"""YAML -> plain data, remembering where every node came from.

`load_file` returns a `Document`: the data (dicts, lists, scalars, exactly as `yaml.safe_load` would give)
and a table from each node's path (`("robots", 1, "plugins", 0)`) to its file/line/column, so that any
later pass can point at the line. Duplicate keys are an error (plain PyYAML keeps the last one silently).
"""

from __future__ import annotations

import datetime
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


@dataclass
class MappedDocument(Document):
    """The document as a pass over a derived copy of its data sees it (one world of several, the data
    with what the schema refused taken out): `map_path` takes a path in that copy to the same place in
    the user's file, where it is located."""

    def map_path(self, path: PathKey) -> PathKey:
        return tuple(path)

    def locate(self, path: PathKey) -> Location:
        return super().locate(self.map_path(path))


UNREAD = "nothing else is checked until the file reads as YAML"

# Limits checked before anything expensive: a scenario is a few kilobytes of hand-written YAML.
MAX_BYTES = 4_000_000
MAX_DEPTH = 64  # mappings and lists inside each other
# values once aliases are expanded (a "billion laughs" alias bomb is a few hundred bytes)
MAX_VALUES = 100_000


class _TooMany(Exception):
    pass


class _Builder:
    def __init__(self, file: Path | None):
        self.file = file
        self.positions: dict[PathKey, Location] = {}
        self.values = 0
        # A SafeLoader instance only to reuse its scalar resolution (ints, floats, bools, nulls...).
        self._scalars = yaml.SafeLoader("")

    def mark(self, node: yaml.Node) -> Location:
        return Location(self.file, node.start_mark.line + 1, node.start_mark.column + 1)

    def build(self, node: yaml.Node, path: PathKey) -> Any:
        self.values += 1
        if self.values > MAX_VALUES:
            raise _TooMany
        self.positions[path] = self.mark(node)
        if isinstance(node, yaml.MappingNode):
            self._scalars.flatten_mapping(node)  # handles `<<: *anchor` merges
            out: dict[Any, Any] = {}
            for key_node, value_node in node.value:
                key = self._scalar(key_node, path)
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
        return self._scalar(node, path)

    def _scalar(self, node: yaml.Node, path: PathKey) -> Any:
        try:
            value = self._scalars.construct_object(node, deep=True)
        except yaml.constructor.ConstructorError as e:
            raise ScenarioError(
                Problem(
                    f"this YAML value cannot be read: {e.problem}",
                    self.mark(node),
                    path,
                    hint="scenarios use plain YAML: remove the `!tag` (quote the value if it is text)",
                )
            ) from None
        except Exception as e:  # a tagged value that does not parse, e.g. `!!int abc`, `!!timestamp x`
            raise ScenarioError(
                Problem(
                    f"{_short(node.value)} cannot be read as {node.tag.replace('tag:yaml.org,2002:', '!!')}"
                    + (f" ({e})" if isinstance(e, ValueError) else ""),
                    self.mark(node),
                    path,
                    hint="remove the `!!tag`, or quote the value",
                )
            ) from None
        if isinstance(value, datetime.date | bytes | set):
            # YAML reads `2024-01-01` as a date: nothing in a scenario is one, so keep the text
            return str(node.value) if isinstance(node, yaml.ScalarNode) else value
        return value


_DEFAULT_HINT = "check the indentation and that every `key: value` has a space after the colon"


def _unclosed(text: str) -> tuple[int, int, str] | None:
    """(line, column, bracket) of the first '[' or '{' that is never closed (outside quotes and comments)."""
    stack: list[tuple[int, int, str]] = []
    for ln, line in enumerate(text.splitlines(), 1):
        quote = ""
        for col, ch in enumerate(line, 1):
            if quote:
                if ch == quote:
                    quote = ""
            elif ch in "'\"" and (col == 1 or line[col - 2] in " [{,:"):
                quote = ch
            elif ch == "#" and (col == 1 or line[col - 2] in " \t"):
                break
            elif ch in "[{":
                stack.append((ln, col, ch))
            elif ch in "]}" and stack and stack[-1][2] == {"]": "[", "}": "{"}[ch]:
                stack.pop()
    return stack[0] if stack else None


def _yaml_problem(e: yaml.MarkedYAMLError, text: str, file: Path | None) -> Problem:
    """A YAML syntax error in words, pointing where the mistake most likely is."""
    problem = e.problem or e.context or "unknown error"
    context = e.context or ""
    mark = e.problem_mark or e.context_mark
    message = f"this is not valid YAML: {problem}"
    hint = _DEFAULT_HINT
    at_end = "end of stream" in problem or "<stream end>" in problem
    opener = _unclosed(text) if ("flow" in context or at_end) else None
    if "'\\t'" in problem or "\t" in problem:
        message = "this is not valid YAML: a tab character; YAML indents with spaces only"
        hint = "replace the tab with spaces"
    elif "quoted scalar" in context and e.context_mark is not None:
        mark = e.context_mark
        message = "this is not valid YAML: a quoted string is never closed"
        hint = "add the closing quote, or escape the quote inside the string"
    elif opener is not None:
        line, column, bracket = opener
        closer = {"[": "]", "{": "}"}[bracket]
        message = f"this is not valid YAML: {bracket!r} is never closed with {closer!r}"
        hint = f"close it with {closer!r}, and separate its items with ', '"
        return Problem(message, Location(file, line, column), hint=hint)
    elif "mapping values are not allowed" in problem:
        message = "this is not valid YAML: a ':' where no key can start"
        hint = (
            "check the indentation (a key indented deeper than the one before it), or quote a value "
            "that holds ': '"
        )
    elif "expected ',' or" in problem:
        hint = (
            "inside [...] and {...}, quote text that holds '[', ']', '{', '}', ',' or ': ' "
            "(e.g. 'robots[0].pose.xyz': [...])"
        )
    elif "expected <block end>" in problem:
        hint = "check the indentation: the items of one list or mapping start in the same column"
    elif "undefined alias" in problem:
        hint = "define the anchor (`&name`) before using it (`*name`)"
    elif "cannot start any token" in problem:
        hint = "quote the value: '@', '`' and '%' cannot start a plain value"
    loc = Location(file, mark.line + 1, mark.column + 1) if mark else Location(file, 1, 1)
    return Problem(message, loc, hint=hint)


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _check_limits(text: str, file: Path | None) -> None:
    """Size and nesting depth, from the parser's events (linear in the text, before anything is built)."""
    size = len(text.encode("utf-8", errors="replace"))
    if size > MAX_BYTES:
        raise ScenarioError(
            Problem(
                f"this file is {size / 1e6:.1f} MB; a scenario may be at most {MAX_BYTES / 1e6:.0f} MB",
                Location(file, 1, 1),
                hint="keep data (meshes, maps, long timelines) in files the scenario refers to",
            )
        )
    depth = 0
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, yaml.MappingStartEvent | yaml.SequenceStartEvent):
            depth += 1
            if depth > MAX_DEPTH:
                mark = event.start_mark
                raise ScenarioError(
                    Problem(
                        f"this YAML is nested more than {MAX_DEPTH} levels deep",
                        Location(file, mark.line + 1, mark.column + 1),
                        hint="a scenario needs a few levels: check for runaway indentation or brackets",
                    )
                )
        elif isinstance(event, yaml.MappingEndEvent | yaml.SequenceEndEvent):
            depth -= 1


def _first_alias(text: str, file: Path | None) -> Location:
    for event in yaml.parse(text, Loader=yaml.SafeLoader):
        if isinstance(event, yaml.AliasEvent):
            return Location(file, event.start_mark.line + 1, event.start_mark.column + 1)
    return Location(file, 1, 1)


def load_text(text: str, file: Path | None = None) -> Document:
    try:
        _check_limits(text, file)
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as e:
        raise ScenarioError(_yaml_problem(e, text, file), note=UNREAD) from None
    except yaml.YAMLError as e:
        raise ScenarioError(
            Problem(f"this is not valid YAML: {e}", Location(file, 1, 1)), note=UNREAD
        ) from None
    except RecursionError:
        raise ScenarioError(Problem("this YAML is nested too deeply to read", Location(file, 1, 1))) from None
    if node is None:
        return Document({}, file, {(): Location(file, 1, 1)})
    builder = _Builder(file)
    try:
        data = builder.build(node, ())
    except _TooMany:
        raise ScenarioError(
            Problem(
                f"aliases expand this YAML to more than {MAX_VALUES} values",
                _first_alias(text, file),
                hint="each `*name` repeats everything its `&name` holds; an alias of aliases multiplies it",
            )
        ) from None
    except RecursionError:
        raise ScenarioError(Problem("this YAML is nested too deeply to read", Location(file, 1, 1))) from None
    return Document(data, file, builder.positions)


def load_file(path: str | Path) -> Document:
    p = Path(path)
    try:
        if p.is_file() and p.stat().st_size > MAX_BYTES:
            raise ScenarioError(
                Problem(
                    f"this file is {p.stat().st_size / 1e6:.1f} MB; a scenario may be at most "
                    f"{MAX_BYTES / 1e6:.0f} MB",
                    Location(p.resolve(), 1, 1),
                    hint="keep data (meshes, maps, long timelines) in files the scenario refers to",
                )
            )
        # at most MAX_BYTES + 1 whatever it is: `validate /dev/zero` read until a MemoryError at 3.4 GB
        # (a pipe, `validate <(envsubst < s.yaml)`, is read as a file is)
        with p.open("rb") as f:
            data = f.read(MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            raise ScenarioError(
                Problem(
                    f"this file goes on past {MAX_BYTES / 1e6:.0f} MB, the most a scenario may be",
                    Location(p, 1, 1),
                    hint="keep data (meshes, maps, long timelines) in files the scenario refers to",
                )
            )
        text = data.decode("utf-8").replace("\r\n", "\n").replace("\r", "\n")  # (as read_text reads)
    except FileNotFoundError:
        raise ScenarioError(
            Problem("file not found", Location(p), hint="check the path (relative to the current folder)")
        ) from None
    except IsADirectoryError:
        raise ScenarioError(Problem("this is a folder, not a scenario file", Location(p))) from None
    except UnicodeDecodeError as e:
        before = e.object[: e.start]
        line = before.count(b"\n") + 1
        column = e.start - (before.rfind(b"\n") + 1) + 1
        raise ScenarioError(
            Problem(
                f"not a UTF-8 text file: byte 0x{e.object[e.start]:02x} ({e.reason})",
                Location(p.resolve(), line, column),
                hint="save the file as UTF-8 (an editor's 'encoding' setting; `iconv -f latin1 -t utf-8`)",
            )
        ) from None
    return load_text(text, p.resolve())
