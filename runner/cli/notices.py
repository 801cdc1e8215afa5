"""The warnings of compile as a terminal says them: what changes the run first, then the rest, one line per
kind of warning (a tag ignored in forty sensors is one line with "and 39 more: file:line, ...").

Across public robots, validate said 3 to 140 warnings each, one line per ignored `<always_on>` or per
timeline entry, and the one that matters ("your commands go to X, the drive listens on Y") was lost among
them. Grouping is only how they are printed: `--all` prints every one, `--json` keeps every one with its
kind, and `--strict` counts each."""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

from runner.cli.console import err
from runner.errors import (
    DRIVE_GEOMETRY,
    NO_PUBLISHER,
    PLUGIN_UNSUPPORTED,
    UNSUBSCRIBED,
    kind_of,
    varying_parts,
)
from runner.plan import NoticePlan

# The kinds of warning that change what the run does, in the order they are said: a command that reaches
# nothing (the robot does not move at all), a drive scaled by its declared geometry (it moves, at another
# rate than commanded), a Gazebo plugin or sensor left out (its topics are missing, or a drive's motion),
# a sensor that publishes nothing. The rest are things read and not acted on, as Gazebo does not either
# (a tag of the GUI, an ODE contact setting): worth knowing, not first.
LEADING = (UNSUBSCRIBED, DRIVE_GEOMETRY, PLUGIN_UNSUPPORTED, NO_PUBLISHER)
LEADING_HEADING = (
    "what changes the run, most first (commands that reach nothing, drives scaled by their declared wheels, "
    "plugins and sensors left out, sensors that publish nothing):"
)
GROUP_FROM = 3  # a kind said this many times or more is one line (two are said as they are)
MORE_SHOWN = 8  # locations listed after "and N more"


@dataclass
class NoticeGroup:
    """Warnings of one kind about one thing: the first (said whole) and the others (their locations)."""

    first: NoticePlan
    more: list[NoticePlan] = field(default_factory=list)

    def __len__(self) -> int:
        return 1 + len(self.more)


def _key(n: NoticePlan) -> tuple[str, str, str]:
    # the message's own shape too: a drive's separation and its radius are one kind, not one warning
    return (n.kind, n.about or "", kind_of(n.message))


def group_notices(
    items: Iterable[NoticePlan], every: bool = False
) -> tuple[list[NoticeGroup], list[NoticeGroup]]:
    """(what changes the run, the rest): each a list of groups, in the order of LEADING and then of the
    first warning of each group. A kind said fewer than GROUP_FROM times, or any with `every`, is a group
    per warning."""
    groups: dict[tuple[str, str, str], list[NoticePlan]] = {}
    for n in items:
        groups.setdefault(_key(n), []).append(n)
    leading: list[NoticeGroup] = []
    rest: list[NoticeGroup] = []
    for members in groups.values():
        split = every or len(members) < GROUP_FROM
        made = [NoticeGroup(n) for n in members] if split else [NoticeGroup(members[0], members[1:])]
        (leading if members[0].kind in LEADING else rest).extend(made)
    leading.sort(key=lambda g: LEADING.index(g.first.kind))  # (stable: file order within a kind)
    return leading, rest


def _differs(first: NoticePlan, other: NoticePlan) -> str:
    """What names `other` apart from `first`, where it is short enough to say beside its line: the first of
    its varying parts (runner.errors.varying_parts) that differs from the first's, when that is a bare
    <tag> or a short quoted name (`<broadcastTF>`, `'wheel_2'`); "" otherwise (a number, a long name)."""
    mine, theirs = varying_parts(first.message), varying_parts(other.message)
    for a, b in zip(mine, theirs, strict=False):
        if a != b:
            return b if _TAG.fullmatch(b) or (b[:1] in "'\"`" and len(b) <= _NAME_SAID) else ""
    return ""


_TAG = re.compile(r"</?[A-Za-z_][\w:.-]*/?>")
_NAME_SAID = 34  # a quoted name longer than this is not said beside its line


def more_text(first: NoticePlan, more: list[NoticePlan], shown: int = MORE_SHOWN) -> str:
    """ "(and 12 more: 40 <x>, 52 (x3), wheel.xacro:3, ...)": the others' locations in order, each with
    what names it apart where that is short (`_differs`), a file's path said where it changes (the
    first's file is said on its own line), one said several times once with how many, up to `shown`."""
    places: dict[tuple[str | None, int | None, str], int] = {}
    for m in more:
        at = (m.file, m.line, _differs(first, m))
        places[at] = places.get(at, 0) + 1
    parts, file = [], first.file
    for (f, line, what), times in list(places.items())[:shown]:
        where = "" if line is None else str(line)
        if f != file:
            where = f"{f or '<scenario>'}" + (f":{where}" if where else "")
            file = f
        parts.append((where or "?") + (f" {what}" if what else "") + (f" (x{times})" if times > 1 else ""))
    tail = ", ..." if len(places) > shown else ""
    return f"(and {len(more)} more: {', '.join(parts)}{tail})"


def _say(group: NoticeGroup) -> None:
    n = group.first
    head, _, hint = n.text.partition("\n")
    err.print("warning: " + head, markup=False, style="yellow")
    if group.more:
        err.print("  " + more_text(n, group.more), markup=False)
    if hint:
        err.print(hint, markup=False)


def print_notices(items: list[NoticePlan], verbose: bool, every: bool = False) -> None:
    """The warnings compiling the scenario gave. `verbose` (validate): those that change the run, then the
    rest, a line per kind (`every`: each warning). Not verbose (run): those that change the run, and how
    many there are in all."""
    if not items:
        return
    leading, rest = group_notices(items, every)
    lines = len(leading) + len(rest)
    if not verbose:
        if leading:
            err.print(LEADING_HEADING, markup=False, style="bold")
            for g in leading:
                _say(g)
        err.print(f"{len(items)} warning(s): `scenario validate` lists them", markup=False)
        return
    if lines < len(items):
        err.print(
            f"{len(items)} warning(s), said once per kind ({lines} lines; `scenario validate --all` says "
            "every one):",
            markup=False,
        )
    else:
        err.print(f"{len(items)} warning(s):", markup=False)
    if leading:
        err.print(LEADING_HEADING, markup=False, style="bold")
        for g in leading:
            _say(g)
        if rest:
            err.print("the rest:", markup=False, style="bold")
    for g in rest:
        _say(g)
