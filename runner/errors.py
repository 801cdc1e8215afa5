"""One root for every error a user can cause.

A `ScenarioError` says where (file, line, column), what (the path in the scenario, e.g.
`robots[1].plugins[0].params.samples`), what was expected, what was found, and a hint. The CLI prints
these and exits 1; any other exception is a bug and keeps its traceback.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

# Characters a terminal acts on rather than shows: C0 controls but tab and newline (ESC starts the
# sequences that clear the screen, set the window title, write the clipboard), DEL, C1 controls, and the
# bidirectional overrides that reorder what is shown ("Trojan Source").
_CONTROLS = re.compile("[\\x00-\\x08\\x0b-\\x1f\\x7f-\\x9f\\u202a-\\u202e\\u2066-\\u2069]")


def visible(text: str) -> str:
    """`text` with every control character written as an escape (`\\x1b`, `\\u202e`), as `repr` would: for
    what others wrote (a scenario's names, another process's type names) on its way to a terminal."""
    return _CONTROLS.sub(lambda m: repr(m.group())[1:-1], text)


def closest(name: str, names: Iterable[str]) -> str | None:
    """The one of `names` that `name` was most likely meant as: the same but for case, else the closest by
    `difflib` (a typo, a missing or doubled letter), else None."""
    pool = sorted({str(n) for n in names})
    folded = [n for n in pool if n.casefold() == name.casefold()]
    if folded:
        return folded[0]
    close = difflib.get_close_matches(name, pool, n=1, cutoff=0.6)
    return close[0] if close else None


def did_you_mean(name: str, names: Iterable[str], what: str = "names", limit: int = 12) -> str:
    """The hint for a name that names nothing (a robot, link, topic, node...): "did you mean 'r1'?" when
    one of `names` is close, else the names there are (`what`: how to call them, "robots"), so that every
    unknown name is said with what to write instead."""
    pool = sorted({str(n) for n in names})
    near = closest(name, pool)
    if near is not None:
        return f"did you mean {near!r}?"
    if not pool:
        return f"there are no {what} to name here"
    shown = ", ".join(pool[:limit]) + (f" ... ({len(pool)} in all)" if len(pool) > limit else "")
    return f"{what}: {shown}"


def missing_file_hint(path: Path, relative_to: str = "the scenario's folder") -> str:
    """The hint for a file that is not there: a file of a close name in its folder ("did you mean"), or the
    first folder of its path that does not exist."""
    folder = path.parent
    if not folder.is_dir():
        missing = folder
        while not missing.parent.is_dir() and missing != missing.parent:
            missing = missing.parent
        return (
            f"paths are relative to {relative_to}, and it has no folder {missing.name!r} "
            f"(in {str(missing.parent)!r})"
        )
    try:
        entries = [p.name for _, p in zip(range(5000), folder.iterdir(), strict=False)]
    except OSError:
        entries = []
    near = closest(path.name, entries)
    if near is not None:
        return f"did you mean {near!r}? (in {str(folder)!r})"
    return f"paths are relative to {relative_to}; {str(folder)!r} has no file of a name close to it"


@dataclass(frozen=True)
class Location:
    file: Path | None = None
    line: int | None = None  # 1-based
    column: int | None = None  # 1-based

    def __str__(self) -> str:
        parts = [str(self.file) if self.file else "<scenario>"]
        if self.line is not None:
            parts.append(str(self.line))
            if self.column is not None:
                parts.append(str(self.column))
        return ":".join(parts)


def format_path(path: Sequence[str | int]) -> str:
    """`("robots", 1, "plugins", 0, "rate")` -> `robots[1].plugins[0].rate`."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += f".{part}" if out else str(part)
    return out or "<document>"


@dataclass
class Problem:
    """One thing wrong with the input."""

    message: str
    location: Location = field(default_factory=Location)
    path: tuple[str | int, ...] = ()
    expected: str | None = None
    found: str | None = None
    hint: str | None = None

    def render(self) -> str:
        head = f"{self.location}: "
        if self.path:
            head += f"{format_path(self.path)}: "
        lines = [head + self.message]
        if self.expected is not None:
            lines.append(f"  expected: {self.expected}")
        if self.found is not None:
            lines.append(f"  found:    {self.found}")
        if self.hint:
            lines.append(f"  hint:     {self.hint}")
        return "\n".join(_printable(line) for line in lines)


def _printable(text: str) -> str:
    """Control characters (a NUL in a path, an escape sequence) shown as escapes, never sent to the
    terminal; line breaks and tabs kept (MuJoCo's messages span lines)."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or c in "\n\t" else repr(c)[1:-1] for c in text)


class ScenarioError(Exception):
    """A user mistake in a scenario or in a file it refers to. Holds one or more problems."""

    def __init__(self, problems: Problem | Iterable[Problem], note: str | None = None):
        self.problems = [problems] if isinstance(problems, Problem) else list(problems)
        self.note = note  # e.g. that the checks stopped early, and what was not looked at
        super().__init__(self.render())

    def render(self) -> str:
        n = len(self.problems)
        body = "\n".join(p.render() for p in self.problems)
        body = body if n == 1 else f"{n} problems:\n{body}"
        return body + (f"\n({self.note})" if self.note else "")


class Problems:
    """The problems of a pass over independent items (robots, plugins, timeline entries...): each item's
    mistakes are kept and the pass goes on with the next, so that one `validate` reports them all.

        problems = Problems(doc.file)
        for i, robot in enumerate(sc.robots):
            with problems.each():  # a ScenarioError inside is kept; the rest of this item is skipped
                ...
        problems.raise_all()  # in the file's order
    """

    def __init__(self, file: Path | None = None) -> None:
        self.file = file
        # one per mistake: a problem in another file (a xacro's line) with the one after it that names
        # the scenario's line ("while loading robot 'r1'")
        self.groups: list[list[Problem]] = []
        self._said: set[tuple[str, ...]] = set()  # each group as rendered: one said once is not said again

    def __bool__(self) -> bool:
        return bool(self.groups)

    def __len__(self) -> int:
        return sum(len(g) for g in self.groups)

    def _here(self, p: Problem) -> bool:
        at = p.location
        return at.line is not None and (self.file is None or at.file == self.file)

    def add(self, problems: Problem | Iterable[Problem]) -> None:
        """Problems of one error; one said already (the same settings checked by each world) is not
        said again."""
        pending: list[Problem] = []
        for p in [problems] if isinstance(problems, Problem) else problems:
            pending.append(p)
            if self._here(p):
                self._keep(pending)
                pending = []
        if pending:
            self._keep(pending)

    def _keep(self, group: list[Problem]) -> None:
        text = tuple(p.render() for p in group)
        if text not in self._said:
            self._said.add(text)
            self.groups.append(group)

    @contextmanager
    def each(self) -> Iterator[None]:
        try:
            yield
        except ScenarioError as e:
            self.add(e.problems)

    def ordered(self) -> list[Problem]:
        def first(group: list[Problem]) -> tuple[float, float]:
            lines = [(p.location.line or 0, p.location.column or 0) for p in group if self._here(p)]
            return min(lines) if lines else (float("inf"), 0)

        order = sorted(range(len(self.groups)), key=lambda k: (first(self.groups[k]), k))
        return [p for k in order for p in self.groups[k]]

    def raise_all(self, note: str | None = None) -> None:
        if self.groups:
            raise ScenarioError(self.ordered(), note)


# The kinds of notice that the checks give by name (`Notices.add(..., kind=...)`); any other notice's kind is
# its message with the parts that vary (quoted names, <tags>, numbers) taken out (`kind_of`). `scenario
# validate` prints one line per kind (and what it is about), and leads with the kinds that change what the
# run does (runner.cli.plans: LEADING).
UNSUBSCRIBED = "command-unsubscribed"  # a timeline entry or bridge publishes where nothing subscribes
DRIVE_GEOMETRY = "drive-geometry"  # a drive's declared wheel values are not the robot's: it is scaled
PLUGIN_UNSUPPORTED = "plugin-unsupported"  # a Gazebo plugin or sensor left out (its topics, motion)
NO_PUBLISHER = "sensor-no-publisher"  # a sensor that publishes nothing (as in Gazebo)
TAG_IGNORED = "tag-ignored"  # a tag read but not acted on (about: the tag)

_VARYING = re.compile(
    r"'[^']*'|\"[^\"]*\"|`[^`]*`"  # quoted names and values
    r"|</?[A-Za-z_][\w:.-]*(?:\s[^<>]*)?/?>"  # <tags>, with their attributes
    r"|-?\d+(?:\.\d+)?(?:e-?\d+)?"  # numbers
)


def kind_of(message: str) -> str:
    """The kind of a notice not given one: its message with quoted names, <tags> and numbers written as
    `…`, so that "<always_on> in <sensor name='imu'> is ignored" and the same of another sensor are one
    kind."""
    return _VARYING.sub("…", message)


def varying_parts(message: str) -> list[str]:
    """What `kind_of` takes out of `message`, in order: the quoted names, <tags> and numbers."""
    return _VARYING.findall(message)


@dataclass(frozen=True)
class Notice:
    """A warning: something in an input that we read but do not act on (never fatal, never silent).
    `kind` says which check gave it (see `kind_of`), `about` what it is about where notices of one kind
    about different things are to be told apart (a topic, a tag)."""

    message: str
    location: Location = field(default_factory=Location)
    hint: str | None = None
    kind: str = ""
    about: str | None = None

    def render(self) -> str:
        text = f"{self.location}: {self.message}"
        return text + (f"\n  hint:     {self.hint}" if self.hint else "")


class Notices:
    """Collects warnings during compile; each distinct (message, file) is kept once."""

    def __init__(self) -> None:
        self.items: list[Notice] = []
        self._seen: set[tuple[str, str]] = set()

    def add(
        self,
        message: str,
        file: Path | None = None,
        line: int | None = None,
        hint: str | None = None,
        *,
        kind: str | None = None,
        about: str | None = None,
    ) -> None:
        key = (message, str(file))
        if key not in self._seen:
            self._seen.add(key)
            self.items.append(Notice(message, Location(file, line), hint, kind or kind_of(message), about))

    def __iter__(self):  # type: ignore[no-untyped-def]
        return iter(self.items)

    def __len__(self) -> int:
        return len(self.items)


class SourceError(Exception):
    """A mistake inside a file a scenario refers to (xacro, URDF, mesh): where it is, and a hint.
    The compile pass turns it into a `ScenarioError` that also names the scenario line that loaded it."""

    def __init__(self, message: str, file: Path | None, line: int | None = None, hint: str | None = None):
        super().__init__(message)
        self.file = file
        self.line = line
        self.hint = hint


class RunError(Exception):
    """The run could not go on (a process died, a network endpoint could not be opened...)."""
