"""YAML -> plain data, remembering where every node came from.

`load_file` returns a `Document`: the data (dicts, lists, scalars, exactly as `yaml.safe_load` would give)
and a table from each node's path (`("robots", 1, "plugins", 0)`) to its file/line/column, so that any
later pass can point at the line. Duplicate keys are an error (plain PyYAML keeps the last one silently).
"""

from __future__ import annotations

import datetime
import math
from collections.abc import Callable
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

# Limits checked while the file is read, before anything expensive. Each counts what its message says:
MAX_BYTES = 4_000_000  # the file's size: a long timeline of ~40,000 entries fits
MAX_DEPTH = 64  # mappings and lists inside each other
# values that aliases produce (each `*name` repeats what its `&name` holds): a "billion laughs" alias bomb
# is a few hundred bytes. Values written out in the file are not counted here: MAX_BYTES bounds them.
MAX_ALIAS_VALUES = 100_000
# a syntax error is explained by the pure-Python parser (its messages are the ones the hints know) when
# the text up to the error is at most this long; past it, libyaml's own words are shown
_EXPLAIN_BYTES = 256_000

_STR = "tag:yaml.org,2002:str"
_MERGE = "tag:yaml.org,2002:merge"
_Anchor = tuple[Any, list[tuple[PathKey, Location]], int]  # (value, positions below it, values in it)


class _TooMany(Exception):
    pass


class _Composed(Exception):
    """A mistake found while building (an undefined alias...), as PyYAML's composer words it."""

    def __init__(self, error: yaml.MarkedYAMLError):
        self.error = error


def _copy(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_copy(v) for v in value]
    return value


class _Builder:
    """Plain data and positions straight from libyaml's events, in one pass: no node tree (composing one
    for a 2 MB timeline cost more than everything else `validate` does with it). Nesting is checked on
    the way in, so the recursion below is at most MAX_DEPTH deep."""

    def __init__(self, file: Path | None):
        self.file = file
        self.positions: dict[PathKey, Location] = {}
        self.values = 0  # values built, aliases' included
        self.aliased = 0  # values produced by aliases
        self.next: Callable[[], yaml.Event] = iter(()).__next__
        self.anchors: dict[str, _Anchor] = {}
        self.open_anchors: set[str] = set()
        self.log: list[tuple[PathKey, Location]] = []  # positions set while an anchor is being read
        self.logging = 0
        self.depth = 0
        # A SafeLoader instance only to reuse its scalar resolution (ints, floats, bools, nulls...).
        self._scalars = yaml.SafeLoader("")
        self._constructors = yaml.SafeLoader.yaml_constructors
        self._memo: dict[tuple[str, Any, str | None], Any] = {}

    def mark(self, event: yaml.Event | yaml.Node) -> Location:
        return Location(self.file, event.start_mark.line + 1, event.start_mark.column + 1)

    def at(self, path: PathKey, loc: Location) -> None:
        self.positions[path] = loc
        if self.logging:
            self.log.append((path, loc))

    def document(self, text: str) -> Any:
        parser = yaml.CSafeLoader(text)
        # libyaml's get_event, called directly: yaml.parse's generator cost a third of the reading
        self.next = parser.get_event
        try:
            data: Any = None
            documents = 0
            first: yaml.Event | None = None
            event = self.next()
            while event is not None and not isinstance(event, yaml.StreamEndEvent):
                if isinstance(event, yaml.DocumentStartEvent):
                    documents += 1
                    if documents == 2:
                        raise _Composed(
                            yaml.composer.ComposerError(
                                "expected a single document in the stream",
                                first.start_mark if first else None,
                                "but found another document",
                                event.start_mark,
                            )
                        )
                    first = event
                    data = self.build(self.next(), ())
                event = self.next()
            return {} if documents == 0 else data
        finally:
            parser.dispose()

    def build(self, event: yaml.Event, path: PathKey) -> Any:
        if isinstance(event, yaml.AliasEvent):
            return self.alias(event, path)
        anchor = event.anchor
        if anchor is not None:
            if anchor in self.anchors or anchor in self.open_anchors:
                raise _Composed(
                    yaml.composer.ComposerError(
                        f"found duplicate anchor {anchor!r}; first occurrence",
                        None,
                        "second occurrence",
                        event.start_mark,
                    )
                )
            self.open_anchors.add(anchor)
            self.logging += 1
            start, before = len(self.log), self.values
        self.values += 1
        self.at(path, self.mark(event))
        if isinstance(event, yaml.ScalarEvent):
            value = self.scalar(event, path)
        elif isinstance(event, yaml.SequenceStartEvent | yaml.MappingStartEvent):
            self.depth += 1
            if self.depth > MAX_DEPTH:
                mark = event.start_mark
                raise ScenarioError(
                    Problem(
                        f"this YAML is nested more than {MAX_DEPTH} levels deep",
                        Location(self.file, mark.line + 1, mark.column + 1),
                        hint="a scenario needs a few levels: check for runaway indentation or brackets",
                    )
                )
            value = self.sequence(path) if isinstance(event, yaml.SequenceStartEvent) else self.mapping(path)
            self.depth -= 1
        else:  # pragma: no cover - libyaml gives no other event here
            raise ScenarioError(Problem(f"unexpected YAML event {event}", self.mark(event), path))
        if anchor is not None:
            self.logging -= 1
            n = len(path)
            below = [(p[n:], loc) for p, loc in self.log[start:]]
            if not self.logging:
                del self.log[:]
            count = self.values - before
            self.open_anchors.discard(anchor)
            self.anchors[anchor] = (value, below, count)
        return value

    def alias(self, event: yaml.AliasEvent, path: PathKey) -> Any:
        got = self.anchors.get(event.anchor)
        if got is None:
            inside = event.anchor in self.open_anchors
            what = "an alias inside its own anchor" if inside else "undefined alias"
            raise _Composed(
                yaml.composer.ComposerError(None, None, f"found {what} {event.anchor!r}", event.start_mark)
            )
        value, below, count = got
        self.aliased += count
        self.values += count
        if self.aliased > MAX_ALIAS_VALUES:
            raise _TooMany
        for rel, loc in below:
            self.at((*path, *rel), loc)
        return _copy(value)

    def sequence(self, path: PathKey) -> list[Any]:
        out: list[Any] = []
        event = self.next()
        while not isinstance(event, yaml.SequenceEndEvent):
            out.append(self.build(event, (*path, len(out))))
            event = self.next()
        return out

    def mapping(self, path: PathKey) -> dict[Any, Any]:
        # The hot loop of a long file: a few hundred thousand keys; attribute look-ups taken out of it.
        out: dict[Any, Any] = {}
        merged: set[Any] = set()  # keys that came from a `<<:` merge (the mapping's own keys override them)
        next_event, memo, file, scalar_event = self.next, self._memo, self.file, yaml.ScalarEvent
        event = next_event()
        while not isinstance(event, yaml.MappingEndEvent):
            mark = event.start_mark
            key_loc = Location(file, mark.line + 1, mark.column + 1)
            plain = type(event) is scalar_event
            if plain and event.value == "<<" and self.tag(event) == _MERGE:
                self.merge(path, out, merged)
                event = next_event()
                continue
            if plain:
                key = memo.get((event.value, event.implicit, event.tag), self)
                if key is self:
                    key = self.scalar(event, path)
                if event.anchor is not None:  # `&k key: ...`: a key may be aliased too
                    self.anchors[event.anchor] = (key, [((), key_loc)], 1)
            elif isinstance(event, yaml.AliasEvent) and event.anchor in self.anchors:
                key = self.anchors[event.anchor][0]
            else:
                key = self.build(event, (*path, "<key>"))
            if not isinstance(key, str | int | float | bool) and key is not None:
                raise ScenarioError(
                    Problem("a mapping key must be a plain value", key_loc, path, found=type(key).__name__)
                )
            key_path = (*path, key)
            if key in out and key not in merged:
                raise ScenarioError(
                    Problem(
                        f"duplicate key {key!r}",
                        key_loc,
                        path,
                        hint=f"{key!r} is already set at line {self.positions[key_path].line}; "
                        "remove one of them",
                    )
                )
            if merged:
                merged.discard(key)
            event = next_event()
            if type(event) is scalar_event and event.anchor is None:  # most values: no call to build
                self.values += 1
                value = memo.get((event.value, event.implicit, event.tag), self)
                out[key] = self.scalar(event, key_path) if value is self else value
            else:
                out[key] = self.build(event, key_path)
            # Point at the key rather than at the value: that is where a reader looks.
            if self.logging:
                self.log.append((key_path, key_loc))
            self.positions[key_path] = key_loc
            event = next_event()
        return out

    def merge(self, path: PathKey, out: dict[Any, Any], merged: set[Any]) -> None:
        """`<<: *base` (or `<<: [*a, *b]`): the keys not set yet are taken, the first mapping's first;
        each keeps the position it has in its anchor."""
        event = self.next()
        here = (*path, "<<")
        self.logging += 1
        start = len(self.log)
        value = self.build(event, here)
        self.logging -= 1
        entries = self.log[start:]
        if not self.logging:
            del self.log[:]
        sources = value if isinstance(value, list) else [value]
        if not all(isinstance(m, dict) for m in sources):
            raise ScenarioError(
                Problem(
                    "`<<:` merges mappings: its value must be a mapping or a list of mappings",
                    self.mark(event),
                    here,
                    found=type(value).__name__,
                    hint="write `<<: *name` where `&name` marks a mapping",
                )
            )
        source: dict[Any, int] = {}  # key -> the mapping of `sources` it is taken from
        for i, m in enumerate(sources):
            for k, v in m.items():
                if k not in out:
                    out[k] = v
                    merged.add(k)
                    source[k] = i
        listed = isinstance(value, list)
        n = len(here) + listed  # where the key is in an entry's path
        for p, _ in entries:
            self.positions.pop(p, None)
        for p, loc in entries:
            if len(p) > n and p[n] in source and (not listed or source[p[n]] == p[n - 1]):
                self.at((*path, *p[n:]), loc)

    def tag(self, event: yaml.ScalarEvent) -> str:
        tag = event.tag
        if tag is None or tag == "!":
            tag = self._scalars.resolve(yaml.ScalarNode, event.value, event.implicit)
        return tag

    def scalar(self, event: yaml.ScalarEvent, path: PathKey) -> Any:
        # A long timeline repeats the same few keys and values: each is resolved (a regular expression
        # per kind) and constructed once. Only immutable results are kept.
        memo = (event.value, event.implicit, event.tag)
        got = self._memo.get(memo, self)
        if got is not self:
            return got
        value = self._scalar(event, path)
        if isinstance(value, str | int | float | bool) or value is None:
            if len(self._memo) > 100_000:
                self._memo.clear()
            self._memo[memo] = value
        return value

    def _scalar(self, event: yaml.ScalarEvent, path: PathKey) -> Any:
        tag = self.tag(event)
        if tag == _STR:
            return event.value
        node = yaml.ScalarNode(tag, event.value, event.start_mark, event.end_mark, event.style)
        try:
            construct = self._constructors.get(tag)
            # (the constructor itself, not construct_object: that one keeps every node it has seen)
            value = (
                construct(self._scalars, node)
                if construct is not None
                else self._scalars.construct_object(node, deep=True)
            )
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
            return str(event.value)
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
    elif "inside its own anchor" in problem:
        hint = "an anchor cannot hold an alias of itself (that would repeat it without end)"
    elif "undefined alias" in problem:
        hint = "define the anchor (`&name`) before using it (`*name`)"
    elif "cannot start any token" in problem:
        hint = "quote the value: '@', '`' and '%' cannot start a plain value"
    loc = Location(file, mark.line + 1, mark.column + 1) if mark else Location(file, 1, 1)
    return Problem(message, loc, hint=hint)


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _check_size(text: str, file: Path | None) -> None:
    size = len(text.encode("utf-8", errors="replace"))
    if size > MAX_BYTES:
        raise ScenarioError(
            Problem(
                f"this file is {size / 1e6:.1f} MB; a scenario may be at most {MAX_BYTES / 1e6:.0f} MB",
                Location(file, 1, 1),
                hint="keep data (meshes, maps, long timelines) in files the scenario refers to",
            )
        )


def _first_alias(text: str, file: Path | None) -> Location:
    for event in yaml.parse(text, Loader=yaml.CSafeLoader):
        if isinstance(event, yaml.AliasEvent):
            return Location(file, event.start_mark.line + 1, event.start_mark.column + 1)
    return Location(file, 1, 1)


def _explained(e: yaml.MarkedYAMLError, text: str) -> yaml.MarkedYAMLError:
    """libyaml's syntax error as the pure-Python parser words it (the hints know its words), when the
    text up to it is short enough to parse again at Python's speed; else libyaml's own."""
    mark = e.problem_mark or e.context_mark
    cut = len(text)
    if mark is not None:
        lines = text.splitlines(keepends=True)
        cut = sum(len(x) for x in lines[: mark.line + 2])
    if cut > _EXPLAIN_BYTES:
        return e
    try:
        for _ in yaml.parse(text[:cut], Loader=yaml.SafeLoader):
            pass
    except yaml.MarkedYAMLError as py:
        py_mark = py.problem_mark or py.context_mark
        if mark is None or py_mark is None or py_mark.line <= mark.line + 1:
            return py
    return e


def _too_deep(text: str, file: Path | None, e: yaml.MarkedYAMLError) -> Problem:
    """Where the nesting passes MAX_DEPTH (the pure-Python parser reads one event at a time, so it stops
    there), when the text up to libyaml's error is short enough; else libyaml's place."""
    mark = e.problem_mark or e.context_mark
    depth = 0
    if mark is None or mark.index <= _EXPLAIN_BYTES:
        try:
            for event in yaml.parse(text, Loader=yaml.SafeLoader):
                if isinstance(event, yaml.MappingStartEvent | yaml.SequenceStartEvent):
                    depth += 1
                    if depth > MAX_DEPTH:
                        mark = event.start_mark
                        break
                elif isinstance(event, yaml.MappingEndEvent | yaml.SequenceEndEvent):
                    depth -= 1
        except yaml.YAMLError:
            pass
    return Problem(
        f"this YAML is nested more than {MAX_DEPTH} levels deep",
        Location(file, mark.line + 1, mark.column + 1) if mark else Location(file, 1, 1),
        hint="a scenario needs a few levels: check for runaway indentation or brackets",
    )


def load_text(text: str, file: Path | None = None) -> Document:
    _check_size(text, file)
    builder = _Builder(file)
    try:
        data = builder.document(text)
    except _Composed as c:
        raise ScenarioError(_yaml_problem(c.error, text, file), note=UNREAD) from None
    except yaml.MarkedYAMLError as e:
        if "maximum nesting depth" in str(e.problem):  # libyaml's own bound (1000), found ahead of ours
            raise ScenarioError(_too_deep(text, file, e)) from None
        raise ScenarioError(_yaml_problem(_explained(e, text), text, file), note=UNREAD) from None
    except yaml.YAMLError as e:
        raise ScenarioError(
            Problem(f"this is not valid YAML: {e}", Location(file, 1, 1)), note=UNREAD
        ) from None
    except _TooMany:
        raise ScenarioError(
            Problem(
                f"aliases expand this YAML to more than {MAX_ALIAS_VALUES} values",
                _first_alias(text, file),
                hint="each `*name` repeats everything its `&name` holds; an alias of aliases multiplies it",
            )
        ) from None
    builder.positions.setdefault((), Location(file, 1, 1))
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


def non_finite(value: Any, path: tuple[Any, ...] = ()) -> tuple[tuple[Any, ...], float] | None:
    """(path, value) of the first NaN or infinity in plain data as loaded (YAML's .nan, .inf and numbers
    beyond 1.8e308), or None."""
    if isinstance(value, float) and not math.isfinite(value):
        return path, value
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for k, v in items:
        found = non_finite(v, (*path, k))
        if found is not None:
            return found
    return None
