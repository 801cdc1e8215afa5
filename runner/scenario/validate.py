"""Checking a scenario document against the format: `validate_scenario` (the model of a document, or a
`ScenarioError` naming every problem with its file and line), the checks before the schema
(`check_document`: a mapping, no NUL in any text) and after it (`consistency_problems`: unique names and
namespaces, a timeline within the run), and `prune`, which takes out what the schema refused so that the
rest of a file can still be checked in the same pass.

How a pydantic error becomes a `Problem` is `runner.scenario.problems`.
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from runner.errors import Problem, ScenarioError
from runner.scenario.loader import Document, PathKey
from runner.scenario.model_paths import resolve
from runner.scenario.problems import problems_from_validation, short
from runner.scenario.schema import Scenario

__all__ = [
    "Pruned",
    "check_consistency",
    "check_document",
    "consistency_problems",
    "problems_from_validation",
    "prune",
    "validate_model",
    "validate_scenario",
]

M = TypeVar("M", bound=BaseModel)


def validate_model(model: type[M], data: Any, doc: Document, prefix: PathKey = ()) -> M:
    try:
        return model.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(problems_from_validation(err, data, doc, model, prefix)) from None


def validate_scenario(doc: Document) -> Scenario:
    """The scenario model of a document, or a ScenarioError (schema and cross-field rules). To find every
    mistake of a file at once, compile included, use `runner.compile.load_plan`."""
    check_document(doc)
    sc = validate_model(Scenario, doc.data, doc)
    check_consistency(sc, doc)
    return sc


def check_document(doc: Document) -> None:
    """What must hold before anything else can be read: a mapping, and no NUL in any text."""
    if not isinstance(doc.data, dict):
        raise ScenarioError(
            Problem(
                "a scenario must be a mapping of keys (name:, robots:, ...)",
                doc.locate(()),
                found=type(doc.data).__name__,
                hint="start the file with `name: my_scenario`",
            )
        )
    # repr shows a NUL as `\x00` (a written backslash as `\\`): a scenario without that text has none,
    # found in C at once rather than by a walk over every value of a long timeline
    if "\\x00" in repr(doc.data):
        _check_text(doc.data, doc, ())


def _check_text(value: Any, doc: Document, path: PathKey) -> None:
    """No text in a scenario holds a NUL character: no name, path or command can (the OS refuses it)."""
    bad = isinstance(value, str) and "\x00" in value
    if bad:
        raise ScenarioError(
            Problem(
                "this text holds a NUL character",
                doc.locate(path),
                path,
                found=short(value),
                hint="remove the \\0 (or \\x00) escape",
            )
        )
    if isinstance(value, dict):
        for k, v in value.items():
            _check_text(k, doc, (*path, k))
            _check_text(v, doc, (*path, k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _check_text(v, doc, (*path, i))


def check_consistency(sc: Scenario, doc: Document) -> None:
    """Rules that span several fields: unique names and namespaces, timeline within the run."""
    problems = consistency_problems(sc, doc)
    if problems:
        raise ScenarioError(problems)


def consistency_problems(sc: Scenario, doc: Document) -> list[Problem]:
    problems: list[Problem] = []
    seen_names: dict[str, int] = {}
    seen_ns: dict[str, int] = {}
    for i, robot in enumerate(sc.robots):
        if robot.name in seen_names:
            problems.append(
                Problem(
                    f"robot name {robot.name!r} is used twice",
                    doc.locate(("robots", i, "name")),
                    ("robots", i, "name"),
                    hint=f"robots[{seen_names[robot.name]}] has the same name; names must be unique",
                )
            )
        seen_names.setdefault(robot.name, i)
        ns = robot.ns
        for other, j in seen_ns.items():
            if robot.namespace is None and sc.robots[j].name == robot.name:
                continue  # already reported as a duplicate name
            if ns == other or ns.startswith(other + "/") or other.startswith(ns + "/"):
                where = ("robots", i, "namespace") if robot.namespace else ("robots", i, "name")
                problems.append(
                    Problem(
                        f"namespace {ns!r} clashes with {other!r} of robots[{j}]",
                        doc.locate(where),
                        where,
                        hint="give each robot its own namespace (`namespace: r2`)",
                    )
                )
        seen_ns.setdefault(ns, i)
        plugin_names: dict[str, int] = {}
        for k, p in enumerate(robot.plugins):
            pname = p.name or p.type
            if pname in plugin_names:
                where = ("robots", i, "plugins", k)
                problems.append(
                    Problem(
                        f"two plugins named {pname!r} on robot {robot.name!r}",
                        doc.locate(where),
                        where,
                        hint="give the second one a `name:`",
                    )
                )
            plugin_names.setdefault(pname, k)
    worlds: list[tuple[PathKey, Any]] = [(("world",), sc.world)]
    worlds += [(("worlds", k), w) for k, w in enumerate(sc.worlds)]
    for at, world in worlds:
        model_names: dict[str, int] = {}
        for i, m in enumerate(world.models):
            where: PathKey = (*at, "models", i, "name")
            if m.name in model_names or m.name in seen_names:
                problems.append(
                    Problem(
                        f"model name {m.name!r} is already used",
                        doc.locate(where),
                        where,
                        hint="names of models and robots must be unique",
                    )
                )
            model_names.setdefault(m.name, i)
    return problems + _timeline_problems(sc, doc) + _event_problems(sc, doc)


def _timeline_problems(sc: Scenario, doc: Document) -> list[Problem]:
    problems = []
    for i, ev in enumerate(sc.timeline):
        if ev.t > sc.duration:
            problems.append(
                Problem(
                    f"this entry is at t={ev.t} s, after the end of the run",
                    doc.locate(("timeline", i, "t")),
                    ("timeline", i, "t"),
                    expected=f"a time within the duration (0..{sc.duration} s)",
                    found=str(ev.t),
                    hint="raise `duration:` or move the entry earlier",
                )
            )
    return problems


def _event_problems(sc: Scenario, doc: Document) -> list[Problem]:
    """Events act in one world (its bodies, its topics, its step): with several worlds, none."""
    if not (sc.worlds and sc.events):
        return []
    where: PathKey = ("events",)
    return [
        Problem(
            f"events run in a single world: with `worlds:` ({len(sc.worlds)} of them) there is no one "
            "world for them to act in",
            doc.locate(where),
            where,
            hint="drop `worlds:` (one `world:`), or leave the events out: each world runs on its own "
            "process and step, and an event cannot yet say which world it belongs to",
        )
    ]


@dataclasses.dataclass
class Pruned:
    """A scenario's data with what the schema refused taken out, so that the rest can still be checked in
    the same pass (`runner.compile.load_plan`): unknown keys and refused values are dropped (a default
    takes their place); an item of a list that still does not validate is removed whole. `removed` lists
    those removals, to map the paths of later problems back to the user's file, and `names` the names
    of removed items (robots, nodes...): a problem that names one of them is a consequence, not news."""

    data: Any
    removed: list[tuple[PathKey, int]] = dataclasses.field(default_factory=list)  # (list, index), in order
    names: set[str] = dataclasses.field(default_factory=set)

    def original(self, path: PathKey) -> PathKey:
        """A path in the pruned data -> the same place in the user's file."""
        p = list(path)
        for lpath, index in reversed(self.removed):
            n = len(lpath)
            if len(p) > n and tuple(p[:n]) == lpath and isinstance(p[n], int) and p[n] >= index:
                p[n] += 1
        return tuple(p)


# lists whose items others name (a robot in an assertion, a node in `lockstep`, a world in `world:`)
_REFERRED = ("robots", "nodes", "worlds", "models")


def prune(model: type[BaseModel], data: Any, rounds: int = 6) -> tuple[BaseModel, Pruned] | None:
    """`data` (which `model` refuses) with the refused parts taken out until it validates, or None when
    that would take out more than list items and optional keys (a required top-level key, say)."""
    pruned = Pruned(copy.deepcopy(data))
    for _ in range(rounds):
        try:
            return model.model_validate(pruned.data), pruned
        except ValidationError as err:
            cut: dict[PathKey, str] = {}  # data path -> "key" (drop the key) or "item" (drop the list item)
            for e in err.errors(include_url=False):
                about_keys = e["type"] in ("missing", "extra_forbidden")
                path, _value, missing = resolve(pruned.data, tuple(e["loc"]), about_keys)
                short = e["type"] == "missing" and isinstance(e["loc"][-1], int)  # a list too short
                if (short or e["type"] != "missing") and path and not missing and isinstance(path[-1], str):
                    cut[path] = "key"  # (a default, if the field has one; else "missing" next round)
                    continue
                items = [k for k, el in enumerate(path) if isinstance(el, int)]
                if path == ("name",) and missing and isinstance(pruned.data, dict):
                    pruned.data["name"] = "scenario"  # the run's name only labels what follows
                    continue
                if not items:
                    return None
                cut[path[: items[-1] + 1]] = "item"
            # deepest first, and list items from the back, so that earlier cuts do not move later ones
            order = sorted(cut, key=lambda p: (len(p), p[-1] if isinstance(p[-1], int) else 0), reverse=True)
            for path in order:
                if any(len(o) < len(path) and path[: len(o)] == o for o in cut):
                    continue  # inside something that goes anyway
                parent = pruned.data
                for el in path[:-1]:
                    parent = parent[el]
                if cut[path] == "item":
                    item = parent[path[-1]]
                    name = item.get("name") if isinstance(item, dict) else None
                    if isinstance(name, str) and path[-2] in _REFERRED:
                        pruned.names.add(name)
                        if isinstance(item.get("namespace"), str):
                            pruned.names.add(item["namespace"])
                    del parent[path[-1]]
                    pruned.removed.append((path[:-1], int(path[-1])))
                else:
                    del parent[path[-1]]
    return None
