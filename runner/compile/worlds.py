"""Several worlds in one scenario (`worlds:`): each is compiled as a plan of its own, named `<run>/<world>`
(so every key of it is `<run>/<world>/<ns>/...`), from the robots, timeline entries and assertions that
belong to it; the run's plan holds them and the run-wide parts (recording, nodes, stop_on).

Errors keep pointing at the user's file: each world is compiled against a view of the document that maps
its own indexes back (`robots[0]` of world `b` is the scenario's `robots[2]`; `world` is `worlds[1]`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from runner.errors import Notices, Problem, Problems, ScenarioError
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


def compile_worlds(
    sc: Scenario,
    doc: Document,
    record_path: str | None,
    notices: Notices,
    problems_out: Problems,
    unloaded: list[str],
) -> RunPlan:
    """Each of `worlds:` compiled on its own (`_compile_world`), joined into one plan; the mistakes of
    each go to `problems_out` (with the paths of the user's file), like those of a single world."""
    from runner.compile import _compile_world, _nodes, _record_plan

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
                    f"two worlds named {name!r}", doc.locate(("worlds", i, "name")), ("worlds", i, "name")
                )
            )
    expected = "one of: " + ", ".join(names)

    robot_world: dict[str, str] = {}
    for i, robot in enumerate(sc.robots):
        w = robot.world or names[0]
        if w not in names:
            where: PathKey = ("robots", i, "world")
            problems.append(Problem(f"no world named {w!r}", doc.locate(where), where, expected=expected))
        robot_world[robot.name] = w

    timeline_world: list[str] = []
    for i, entry in enumerate(sc.timeline):
        w, rest = _split_topic(entry.topic)
        timeline_world.append(w)
        if w not in names or not rest:
            where = ("timeline", i, "topic")
            problems.append(
                Problem(
                    f"{entry.topic!r} names no world"
                    if w not in names
                    else f"{entry.topic!r} names no topic",
                    doc.locate(where),
                    where,
                    expected=f"a topic starting with its world: {names[0]}/r1/cmd_vel",
                )
            )

    models = {w.name: {m.name for m in w.models} for w in sc.worlds}
    assertion_world: list[str] = []
    for i, a in enumerate(sc.assertions):
        w: str | None = None
        where = ("assertions", i)
        if a.type in _ROBOT_KINDS:
            w = robot_world.get(a.robot)  # type: ignore[union-attr]
            if w is None:
                where = ("assertions", i, "robot")
                problems.append(
                    Problem(f"no robot named {a.robot!r}", doc.locate(where), where)  # type: ignore[union-attr]
                )
        elif a.type in _TOPIC_KINDS:
            w, rest = _split_topic(a.topic)  # type: ignore[union-attr]
            if w not in names or not rest:
                where = ("assertions", i, "topic")
                problems.append(
                    Problem(
                        f"{a.topic!r} names no " + ("world" if w not in names else "topic"),  # type: ignore[union-attr]
                        doc.locate(where),
                        where,
                        expected=f"a topic starting with its world: {names[0]}/r1/scan",
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
                        "the names are in no one world"
                        if found
                        else "no robot or model of any world is named",
                        doc.locate(where),
                        where,
                        expected="robots and models of one world",
                    )
                )
        assertion_world.append(w or "")

    node_world: dict[str, str] = {}
    for i, node in enumerate(sc.nodes):
        by_ns = next(
            (robot_world[r.name] for r in sc.robots if node.namespace and r.ns == node.namespace), None
        )
        w = node.world or by_ns or names[0]
        if w not in names:
            where = ("nodes", i, "world")
            problems.append(Problem(f"no world named {w!r}", doc.locate(where), where, expected=expected))
        node_world[node.name] = w
    if problems:
        raise ScenarioError(problems)

    nodes: list[NodePlan] = []
    with problems_out.each():
        nodes = _nodes(sc, doc, doc.base_dir)  # checks the nodes and `lockstep` names
    for n in nodes:
        n.world = node_world[n.name]
    plans: list[RunPlan] = []
    for k, world in enumerate(sc.worlds):
        r_idx = [i for i, r in enumerate(sc.robots) if robot_world[r.name] == world.name]
        t_idx = [i for i, w in enumerate(timeline_world) if w == world.name]
        a_idx = [i for i, w in enumerate(assertion_world) if w == world.name]
        sub = sc.model_copy(
            update={
                "name": f"{sc.name}/{world.name}",
                "world": World.model_validate(world.model_dump(exclude={"name"})),
                "worlds": [],
                "robots": [sc.robots[i] for i in r_idx],
                "timeline": [
                    sc.timeline[i].model_copy(update={"topic": _split_topic(sc.timeline[i].topic)[1]})
                    for i in t_idx
                ],
                "assertions": [_strip_world(sc.assertions[i]) for i in a_idx],
                "nodes": [],
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
        plan = _compile_world(sub, view, record_path, notices, own, unloaded)
        for group in own.groups:
            for p in group:
                p.path = view.map_path(p.path)
            problems_out.add(group)
        plan.lockstep = [n for n in sc.lockstep if node_world.get(n) == world.name]
        plans.append(plan)

    first = plans[0]
    record = first.record
    with problems_out.each():  # (said once: each world's compile checked the same settings)
        record = _record_plan(sc, doc, record_path)
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
        lockstep=list(sc.lockstep),
        worlds=plans,
    )


def _strip_topic(entry: Any) -> Any:
    """A timeline entry or an assertion on a topic, as its world sees it: the topic without the world."""
    return entry.model_copy(update={"topic": _split_topic(entry.topic)[1]})


def _strip_world(a: Any) -> Any:
    return _strip_topic(a) if a.type in _TOPIC_KINDS else a
