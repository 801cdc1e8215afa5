"""Checks that warn (notices), not fail: what compiles but would make a verdict or a message mean nothing
(an assertion window past the run's end, a goal held at the start, a publisher nothing subscribes to), and
a robot placed inside something at t = 0."""

from __future__ import annotations

import math
from typing import Any

import mujoco

from runner.errors import UNSUBSCRIBED, Notices
from runner.plan import RunPlan
from runner.scenario.loader import Document
from runner.scenario.schema import Scenario

START_OVERLAP_M = 0.03  # a robot this deep inside something at t = 0 is warned about


START_OVERLAP_GROUND_M = 0.1  # ...or this deep in the ground


def window_edge(a: Any) -> tuple[str, float] | None:
    """The latest edge of an assertion's window (`after`, `until`, `by`), as (field, sim s), if it has one
    that a run's duration must reach for the assertion to be decided."""
    edges = [(f, getattr(a, f, None)) for f in ("after", "until", "by")]
    given = [(f, v) for f, v in edges if v]
    return max(given, key=lambda fv: fv[1]) if given else None


def check_vacuous(plan: RunPlan, sc: Scenario, doc: Document, notices: Notices) -> None:
    """What would make a verdict or a message mean nothing: an assertion window past the run's end, a
    `reach` whose goal holds where the robot starts, a timeline entry or bridge that publishes where
    nothing takes it (a typo: `r1/cmd_vell`)."""
    import difflib

    duration = sc.duration
    for i, a in enumerate(sc.assertions):
        edge = window_edge(a)
        if edge is not None and edge[1] > duration:
            where = doc.locate(("assertions", i, edge[0]))
            notices.add(
                f"assertions[{i}] {a.name!r}: its window ({edge[0]}: {edge[1]:g} s) lies past the run's end "
                f"(duration: {duration:g} s): it will not be decided",
                where.file,
                where.line,
                hint=f"make duration at least {edge[1]:g}, or move the window inside the run",
            )
        if a.type == "reach" and a.leave is None and not a.after:
            robot = next((r for r in sc.robots if r.name == a.robot), None)
            if robot is not None:
                x, y = robot.pose.xyz[0], robot.pose.xyz[1]
                at_goal = (
                    a.region.contains(x, y)
                    if a.region is not None
                    else math.hypot(x - a.point[0], y - a.point[1]) <= a.tolerance
                )
                if at_goal:
                    where = doc.locate(("assertions", i))
                    notices.add(
                        f"assertions[{i}] {a.name!r}: robot {a.robot!r} starts at its goal ({x:g}, {y:g}): "
                        "it passes at t=0 without moving",
                        where.file,
                        where.line,
                        hint="to mean 'leave, then come back', add `leave: 1.0` (metres) or `after: <s>`",
                    )
    taken: set[str] = set()
    # who listens on what, with its type: said next to a command that goes nowhere (a drive that listens on
    # `r1/diff_cont/cmd_vel_unstamped` while the timeline publishes on `r1/cmd_vel`)
    listeners: list[tuple[str, str, str]] = []  # (key relative to the run, type, "diff_drive 'base'")
    for part in plan.every_plan():
        for r in part.robots:
            for p in r.plugins:
                for t in p.topics:
                    if t.direction == "sub":
                        taken.add(t.key)
                        listeners.append((t.key[len(plan.name) + 1 :], t.type, f"{p.type} {p.name!r}"))
    taken |= {b.sim_key for b in plan.bridges if b.direction != "ZENOH_TO_SIM"}
    rel = sorted(k[len(plan.name) + 1 :] for k in taken)

    def check(key: str, what: str, where_path: tuple[Any, ...], text: str, type_: str | None) -> None:
        if key in taken:
            return
        near = difflib.get_close_matches(text.lstrip("/"), rel, n=1, cutoff=0.7)
        if plan.nodes and not near:
            return  # a node may take it (its subscriptions are not declared)
        where = doc.locate(where_path)
        notices.add(
            f"{what} publishes on {text!r}, which nothing in the run subscribes to"
            + (" (no plugin; a node may)" if plan.nodes else "")
            + _listening(listeners, type_),
            where.file,
            where.line,
            hint=(f"did you mean {near[0]!r}? " if near else "")
            + (f"topics taken in this run: {', '.join(rel[:8])}" if rel else "no plugin takes messages"),
            kind=UNSUBSCRIBED,
            about=key,
        )

    for i, ev in enumerate(sc.timeline):
        if ev.topic is not None:  # (a `call` names a service: checked by runner.compile.timeline)
            key = f"{sc.name}/{ev.topic.lstrip('/')}"
            check(key, f"timeline[{i}]", ("timeline", i, "topic"), ev.topic, ev.type)
    for i, b in enumerate(plan.bridges):
        if b.direction != "SIM_TO_ZENOH":
            text = b.sim_key[len(plan.name) + 1 :]
            check(b.sim_key, f"bridge {i}", ("bridges", i), text, b.type)


def _listening(listeners: list[tuple[str, str, str]], type_: str | None, limit: int = 3) -> str:
    """ "; diff_drive 'base' listens on 'r1/cmd_vel_unstamped'": who takes messages of the type a command
    is sent as, else of its stamped or unstamped twin (a TwistStamped sent to a drive that takes Twist),
    else anyone who takes messages, each with its type where it is not the command's; so that the warning
    says where the commands should go. "" when no plugin takes messages."""

    def short(t: str | None) -> str:  # geometry_msgs/msg/Twist and geometry_msgs/Twist are one type
        return (t or "").replace("/msg/", "/")

    def twin(t: str | None) -> str:
        return short(t).removesuffix("Stamped")

    same = [ln for ln in listeners if short(ln[1]) == short(type_)]
    same = same or [ln for ln in listeners if twin(ln[1]) == twin(type_)] or listeners
    if not same:
        return ""
    said = [
        f"{who} listens on {key!r}" + ("" if short(t) == short(type_) else f" ({t})")
        for key, t, who in same[:limit]
    ]
    more = f" (and {len(same) - limit} more)" if len(same) > limit else ""
    return "; " + ", ".join(said) + more


def check_start_overlaps(m: mujoco.MjModel, sc: Scenario, doc: Document, notices: Notices) -> None:
    """A robot placed inside something (another robot, a wall, the ground) is shoved out at the first step,
    often somewhere odd (under the floor): say where it starts and what it is inside. A mesh collides as
    its convex hull, so a building's walls made of one mesh are a solid block: the hint says so."""
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    robots = {f"{r.ns}/": i for i, r in enumerate(sc.robots)}

    def owner(geom: int) -> tuple[int | None, str]:
        body = int(m.geom_bodyid[geom])
        root = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.body_rootid[body])) or ""
        what = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, geom) or (
            mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, body) or "the world"
        )
        robot = next((i for prefix, i in robots.items() if root.startswith(prefix)), None)
        return robot, what

    plane = int(mujoco.mjtGeom.mjGEOM_PLANE)
    worst: dict[tuple[int, str], tuple[float, bool]] = {}
    for c in d.contact[: d.ncon]:
        # wheels a few centimetres into the ground (a robot posed at z = 0) just pop up: not worth a word
        on_ground = plane in (int(m.geom_type[c.geom1]), int(m.geom_type[c.geom2]))
        if c.dist > -(START_OVERLAP_GROUND_M if on_ground else START_OVERLAP_M):
            continue
        (r1, w1), (r2, w2) = owner(int(c.geom1)), owner(int(c.geom2))
        if r1 is not None and r1 == r2:
            # two links of one robot touch only where self-collision is on (<selfCollide>): say which
            key = (r1, f"its own {w1!r} and {w2!r} (self-collision is on)")
            if -c.dist > worst.get(key, (0.0, False))[0]:
                worst[key] = (-float(c.dist), False)
            continue
        for robot, other, other_robot, geom in ((r1, w2, r2, int(c.geom2)), (r2, w1, r1, int(c.geom1))):
            if robot is None or other_robot == robot:
                continue
            name = sc.robots[other_robot].name if other_robot is not None else other
            mesh = int(m.geom_type[geom]) == int(mujoco.mjtGeom.mjGEOM_MESH)
            key = (robot, name)
            if -c.dist > worst.get(key, (0.0, False))[0]:
                worst[key] = (-float(c.dist), mesh)
    for (robot, name), (depth, mesh) in sorted(worst.items()):
        where = doc.locate(("robots", robot, "pose"))
        inside = name if name.startswith("its own ") else repr(name)
        notices.add(
            f"robot {sc.robots[robot].name!r} starts {depth:.2f} m inside {inside}: the first step shoves "
            "them apart",
            where.file,
            where.line,
            hint="move the links apart in the description, or set <selfCollide> false for them"
            if name.startswith("its own ")
            else "move the robot's pose"
            + (
                "; a mesh collides as its convex hull (walls made of one mesh are a solid block)"
                if mesh
                else ""
            ),
        )
