"""Several worlds in one scenario (`worlds:`): each is compiled as a plan of its own, named `<run>/<world>`
(so every key of it is `<run>/<world>/<ns>/...`), from the robots, timeline entries and assertions that
belong to it; the run's plan holds them and the run-wide parts (recording, nodes, stop_on).

Errors keep pointing at the user's file: each world is compiled against a view of the document that maps
its own indexes back (`robots[0]` of world `b` is the scenario's `robots[2]`; `world` is `worlds[1]`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from runner.compile.nodes import compile_nodes
from runner.compile.record import record_plan
from runner.compile.world import compile_world
from runner.errors import Notices, Problem, Problems, ScenarioError, closest, did_you_mean
from runner.plan import NodePlan, RunPlan
from runner.scenario.loader import Document, MappedDocument, PathKey
from runner.scenario.schema import NoCollision, Scenario, World

_ROBOT_KINDS = ("reach", "stay_within", "max_speed", "max_tilt", "distance_traveled")
_TOPIC_KINDS = ("topic_rate", "message")


@dataclass
class _WorldView(MappedDocument):
    """The document as one world's compile sees it: its indexes mapped to the scenario's."""

    world_index: int = 0
    maps: dict[str, list[int]] = field(default_factory=dict)

    def map_path(self, path: PathKey) -> PathKey:
        p = tuple(path)
        if p and p[0] == "world":
            return ("worlds", self.world_index, *p[1:])
        if len(p) >= 2 and p[0] in self.maps and isinstance(p[1], int) and p[1] < len(self.maps[str(p[0])]):
            return (p[0], self.maps[str(p[0])][p[1]], *p[2:])
        return p


def _split_topic(topic: str) -> tuple[str, str]:
    """`arena/r1/cmd_vel` -> (`arena`, `r1/cmd_vel`)."""
    first, _, rest = topic.strip("/").partition("/")
    return first, rest


@dataclass
class _Placement:
    """Which world each robot, timeline entry, assertion and node belongs to."""

    names: list[str]  # the worlds', in the file's order
    robots: dict[str, str]  # robot name -> world
    timeline: list[str]  # by entry
    assertions: list[str]  # by assertion ("" where none could be told)
    nodes: dict[str, str]  # node name -> world


def compile_worlds(
    sc: Scenario,
    doc: Document,
    record_path: str | None,
    notices: Notices,
    problems_out: Problems,
    unloaded: list[str],
) -> RunPlan:
    """Each of `worlds:` compiled on its own (`compile_world`), joined into one plan; the mistakes of
    each go to `problems_out` (with the paths of the user's file), like those of a single world."""
    placed = _place(sc, doc)
    nodes: list[NodePlan] = []
    with problems_out.each():
        nodes = compile_nodes(sc, doc, doc.base_dir)  # checks the nodes and `lockstep` names
    for n in nodes:
        n.world = placed.nodes[n.name]
    plans = [
        _compile_one(sc, doc, k, placed, record_path, notices, problems_out, unloaded)
        for k in range(len(sc.worlds))
    ]
    first = plans[0]
    record = first.record
    with problems_out.each():  # (said once: each world's compile checked the same settings)
        record = record_plan(sc, doc, record_path)
    return RunPlan(
        name=sc.name,
        scenario_file=str(doc.file) if doc.file else None,
        duration_ns=first.duration_ns,
        rate=first.rate,
        seed=sc.seed,
        step_ns=min(p.step_ns for p in plans),
        clock_rate=first.clock_rate,
        mjcf="",
        robots=[],
        timeline=[],
        record=record,
        notices=[n.render() for n in notices],
        stop_on=sc.stop_on,
        renderers=sc.renderers,
        nodes=nodes,
        hosts={name: h.endpoint for name, h in sc.hosts.items()},
        resources=sc.resources.model_dump() if sc.resources else None,
        lockstep=list(sc.lockstep),
        worlds=plans,
    )


def _compile_one(
    sc: Scenario,
    doc: Document,
    k: int,
    placed: _Placement,
    record_path: str | None,
    notices: Notices,
    problems_out: Problems,
    unloaded: list[str],
) -> RunPlan:
    """World `worlds[k]` compiled as a scenario of its own (`<run>/<world>`) from what belongs to it."""
    world = sc.worlds[k]
    r_idx = [i for i, r in enumerate(sc.robots) if placed.robots[r.name] == world.name]
    t_idx = [i for i, w in enumerate(placed.timeline) if w == world.name]
    a_idx = [i for i, w in enumerate(placed.assertions) if w == world.name]
    sub = sc.model_copy(
        update={
            "name": f"{sc.name}/{world.name}",
            "world": World.model_validate(world.model_dump(exclude={"name"})),
            "worlds": [],
            "robots": [sc.robots[i] for i in r_idx],
            "timeline": [_strip_entry(sc.timeline[i]) for i in t_idx],
            "assertions": [_strip_world(sc.assertions[i]) for i in a_idx],
            "nodes": [],
            "events": [],  # (one world's: refused with several, runner.scenario.validate)
            "lockstep": [],
            "matrix": {},
            "bridges": [],  # run-wide: compiled once, against every world's topics
            "ros2": None,
        }
    )
    view = _WorldView(
        data=doc.data,
        file=doc.file,
        positions=doc.positions,
        world_index=k,
        maps={"robots": r_idx, "timeline": t_idx, "assertions": a_idx},
    )
    # the world alone: what spans the run (settings, bridges, checks) is compile_plan's, once
    own = Problems(doc.file)
    plan = compile_world(sub, view, record_path, notices, own, unloaded)
    for group in own.groups:
        for p in group:
            p.path = view.map_path(p.path)
        problems_out.add(group)
    plan.lockstep = [n for n in sc.lockstep if placed.nodes.get(n) == world.name]
    return plan


def _place(sc: Scenario, doc: Document) -> _Placement:
    """Each robot, timeline entry, assertion and node given its world; every one that names no world of
    the scenario (or cannot be told) is a problem, all raised together."""
    problems: list[Problem] = []
    names = [w.name for w in sc.worlds]
    if "world" in sc.model_fields_set:
        problems.append(
            Problem(
                "both `world:` and `worlds:`",
                doc.locate(("world",)),
                ("world",),
                hint="one world: `world:`; several: `worlds:` with a `name` each",
            )
        )
    for i, name in enumerate(names):
        if name in names[:i]:
            problems.append(
                Problem(
                    f"two worlds named {name!r}",
                    doc.locate(("worlds", i, "name")),
                    ("worlds", i, "name"),
                    hint="give each a `name:` of its own (its topics start with it)",
                )
            )
    expected = "one of: " + ", ".join(names)

    def unknown_world(w: str, where: PathKey) -> Problem:
        return Problem(
            f"no world named {w!r}",
            doc.locate(where),
            where,
            expected=expected,
            hint=did_you_mean(w, names, "worlds"),
        )

    robot_world: dict[str, str] = {}
    for i, robot in enumerate(sc.robots):
        w = robot.world or names[0]
        if w not in names:
            problems.append(unknown_world(w, ("robots", i, "world")))
        robot_world[robot.name] = w
    timeline_world = [_timeline_world(sc, doc, i, names, problems) for i in range(len(sc.timeline))]
    models = {w.name: {m.name for m in w.models} for w in sc.worlds}
    assertion_world = [
        _assertion_world(doc, i, a, names, robot_world, models, problems) or ""
        for i, a in enumerate(sc.assertions)
    ]
    node_world: dict[str, str] = {}
    for i, node in enumerate(sc.nodes):
        by_ns = next(
            (robot_world[r.name] for r in sc.robots if node.namespace and r.ns == node.namespace), None
        )
        w = node.world or by_ns or names[0]
        if w not in names:
            problems.append(unknown_world(w, ("nodes", i, "world")))
        node_world[node.name] = w
    if problems:
        raise ScenarioError(problems)
    return _Placement(names, robot_world, timeline_world, assertion_world, node_world)


def _topic_hint(first: str, names: list[str]) -> str:
    """What to write for a topic of several worlds whose first part is not a world's name."""
    if first in names:
        return f"add the topic after the world's name: {first}/r1/cmd_vel"
    near = closest(first, names)
    if near is not None:
        return f"did you mean {near!r}? a topic starts with its world's name"
    return "start the topic with its world's name: " + ", ".join(names)


def _timeline_world(sc: Scenario, doc: Document, i: int, names: list[str], problems: list[Problem]) -> str:
    """The world of timeline entry `i`: its topic's first part (`arena/r1/cmd_vel`)."""
    entry = sc.timeline[i]
    w, rest = _split_topic(entry.name)
    if w not in names or not rest:
        where: PathKey = ("timeline", i, "topic" if entry.topic is not None else "call")
        problems.append(
            Problem(
                f"{entry.name!r} names no world" if w not in names else f"{entry.name!r} names no topic",
                doc.locate(where),
                where,
                expected=f"a topic starting with its world: {names[0]}/r1/cmd_vel",
                hint=_topic_hint(w, names),
            )
        )
    return w


def _assertion_world(
    doc: Document,
    i: int,
    a: Any,
    names: list[str],
    robot_world: dict[str, str],
    models: dict[str, set[str]],
    problems: list[Problem],
) -> str | None:
    """The world of assertion `i`: its robot's, its topic's first part, or the one world that holds all
    that a `no_collision` names; None (and a problem) when none can be told."""
    w: str | None = None
    if a.type in _ROBOT_KINDS:
        w = robot_world.get(a.robot)
        if w is None:
            where: PathKey = ("assertions", i, "robot")
            problems.append(
                Problem(
                    f"no robot named {a.robot!r}",
                    doc.locate(where),
                    where,
                    hint=did_you_mean(a.robot, robot_world, "robots"),
                )
            )
    elif a.type in _TOPIC_KINDS:
        w, rest = _split_topic(a.topic)
        if w not in names or not rest:
            where = ("assertions", i, "topic")
            problems.append(
                Problem(
                    f"{a.topic!r} names no " + ("world" if w not in names else "topic"),
                    doc.locate(where),
                    where,
                    expected=f"a topic starting with its world: {names[0]}/r1/scan",
                    hint=_topic_hint(w, names),
                )
            )
            w = None
    elif isinstance(a, NoCollision):
        found = {robot_world[n] for n in a.between if n in robot_world}
        found |= {wn for n in a.between for wn, ms in models.items() if n in ms}
        if len(found) == 1:
            w = found.pop()
        else:
            where = ("assertions", i, "between")
            problems.append(
                Problem(
                    "the names are in no one world" if found else "no robot or model of any world is named",
                    doc.locate(where),
                    where,
                    expected="robots and models of one world",
                    hint="name a robot (or model) of each side's world; worlds do not touch each other",
                )
            )
    return w


def _strip_topic(entry: Any) -> Any:
    """A timeline entry or an assertion on a topic, as its world sees it: the topic without the world."""
    return entry.model_copy(update={"topic": _split_topic(entry.topic)[1]})


def _strip_entry(entry: Any) -> Any:
    """A timeline entry as its world sees it: its topic or service without the world."""
    field = "topic" if entry.topic is not None else "call"
    return entry.model_copy(update={field: _split_topic(entry.name)[1]})


def _strip_world(a: Any) -> Any:
    return _strip_topic(a) if a.type in _TOPIC_KINDS else a
