"""compile: Scenario -> RunPlan. The one place where files on disk become a model.

Everything that touches disk or other formats happens here, and fails early with the line in the
scenario that caused it: xacro, URDF, plugin parameters, message data in the timeline, record paths.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
from pydantic import ValidationError

from runner.checks import assertion_keys, check_names, truth_robots
from runner.checks.judge import TRUTH_RATE, TRUTH_TOPIC, contacts_key
from runner.compile.gazebo import DescribedPlugin
from runner.compile.packages import PackageMap
from runner.compile.parity import summarize
from runner.compile.sdf import load_sdf_world
from runner.compile.urdf import RobotModel, urdf_to_model
from runner.compile.wheels import anisotropic_wheels, check_geometry, wheel_links
from runner.compile.xacro_expand import expand
from runner.errors import Location, Notices, Problem, Problems, ScenarioError, SourceError
from runner.geometry import rpy_to_quat
from runner.plan import (
    FoxglovePlan,
    NodePlan,
    PluginPlan,
    RecordPlan,
    RobotPlan,
    RunPlan,
    TimelinePlan,
    TopicPlan,
)
from runner.plugin import BuildContext, PluginConfigError
from runner.plugin.registry import PluginLookupError, drive_frames, load
from runner.scenario.loader import Document, MappedDocument, PathKey
from runner.scenario.schema import NoCollision, PluginEntry, Record, Robot, Scenario, WorldModel
from runner.scenario.validate import validate_model
from runner.wire import msgs
from runner.wire.transport import hidden_topic, topic_key, zenoh_reason

_GEOM = {
    "box": mujoco.mjtGeom.mjGEOM_BOX,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
}
_CONE = {"elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC, "pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL}
_INTEGRATOR = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
}


def load_plan(doc: Document, *, record_path: str | None = None, notices: Notices | None = None) -> RunPlan:
    """A document checked and compiled in one pass that reports every independent mistake at once, in the
    file's order: the schema's, the cross-field rules', and compile's (robots, plugins and their
    parameters, timeline data, expressions, bridges, nodes...). Where the schema refuses part of the
    file, that part is taken out (`runner.scenario.validate.prune`) and the rest is checked all the same; what
    follows from the part taken out (a reference to a robot that was taken out) is not reported."""
    from pydantic import ValidationError

    from runner.scenario.validate import check_document, problems_from_validation, prune

    check_document(doc)
    problems = Problems(doc.file)
    stopped: str | None = None  # why the checks stopped early, if they did
    try:
        sc = Scenario.model_validate(doc.data)
    except ValidationError as err:
        problems.add(problems_from_validation(err, doc.data, doc, Scenario))
        found = prune(Scenario, doc.data)
        if found is None:
            stopped = "the rest of the file is checked once these are fixed"
        else:
            rest, pruned = found
            view = _PrunedView(data=pruned.data, file=doc.file, positions=doc.positions, pruned=pruned)
            later = Problems(doc.file)
            _, stopped = _check_and_compile(rest, view, later, record_path, notices)  # type: ignore[arg-type]
            # a name in the messages' own quoting: 'r2', 'r2/odom', r2/odom, a/r2/b
            names = [re.compile(rf"(?:^|['/ ]){re.escape(n)}(?:$|['/])") for n in pruned.names]
            for group in later.groups:
                if any(n.search(p.message) for p in group for n in names):
                    continue  # about something taken out (a robot the schema refused)
                for p in group:
                    p.path = view.map_path(p.path)
                problems.add(group)
        plan = None
    else:
        plan, stopped = _check_and_compile(sc, doc, problems, record_path, notices)
    problems.raise_all(stopped)
    assert plan is not None  # (no problems: it compiled)
    return plan


@dataclass
class _PrunedView(MappedDocument):
    """The document as the second look at a file the schema refused sees it: the data with the refused
    parts taken out, located in the user's file."""

    pruned: Any = None

    def map_path(self, path: PathKey) -> PathKey:
        return self.pruned.original(path)  # type: ignore[no-any-return]


def _check_and_compile(
    sc: Scenario, doc: Document, problems: Problems, record_path: str | None, notices: Notices | None
) -> tuple[RunPlan | None, str | None]:
    """(the plan or None, why the checks stopped early or None); the problems found go to `problems`.
    Two robots or models of one name stop them before compile: compiling those would only add noise."""
    from runner.scenario.validate import consistency_problems

    rules = consistency_problems(sc, doc)
    problems.add(rules)
    if any(p.path[:1] in (("robots",), ("world",), ("worlds",)) for p in rules):
        return None, "robots, plugins, the timeline and the rest are checked once these are fixed"
    with problems.each():
        return compile_plan(sc, doc, record_path=record_path, notices=notices), None
    return None, None


def compile_plan(
    sc: Scenario, doc: Document, *, record_path: str | None = None, notices: Notices | None = None
) -> RunPlan:
    """The whole run: its world (or each of `worlds:`, compiled on its own), then what spans the run,
    once: the QoS, Foxglove and Zenoh settings every part carries, the bridges, and the checks over all
    of the run's topics and assertions."""
    notices = notices if notices is not None else Notices()
    problems = Problems(doc.file)
    unloaded: list[str] = []  # key prefixes of robots that did not load: their topics are not checked
    if sc.worlds:
        from runner.compile.worlds import compile_worlds

        plan = compile_worlds(sc, doc, record_path, notices, problems, unloaded)
    else:
        plan = _compile_world(sc, doc, record_path, notices, problems, unloaded)
    drop = None
    if sc.qos:
        drop = [_full_expr(sc.name, q.topics) for q in sc.qos if q.reliability == "best_effort"]
        for i, q in enumerate(sc.qos):
            with problems.each():
                _check_expr(_full_expr(sc.name, q.topics), doc, ("qos", i, "topics"), q.topics)
    fox = FoxglovePlan(**sc.foxglove.model_dump())
    zenoh = None
    with problems.each():
        zenoh = _zenoh_settings(sc, doc) if sc.zenoh is not None else None
    for part in plan.every_plan():
        if drop is not None:
            part.best_effort = drop
        part.foxglove = fox
        if sc.zenoh is not None:
            part.zenoh = zenoh
            part.listen = list(sc.zenoh.listen)
    if sc.bridges or sc.ros2 is not None:
        from runner.compile.bridges import attach_bridges

        with problems.each():
            attach_bridges(plan, sc, doc, unchecked=unloaded)
    problems.raise_all()  # every mistake found, in the order of the file
    _check_record_patterns(plan, sc, doc, notices)
    _check_vacuous(plan, sc, doc, notices)
    plan.notices = [n.render() for n in notices]  # (with those of the checks over the whole run)
    own = doc.file.resolve() if doc.file is not None else None
    plan.scenario_warnings = [
        n.render()
        for n in notices
        if own is not None and n.location.file is not None and Path(n.location.file).resolve() == own
    ]
    return plan


def window_edge(a: Any) -> tuple[str, float] | None:
    """The latest edge of an assertion's window (`after`, `until`, `by`), as (field, sim s), if it has one
    that a run's duration must reach for the assertion to be decided."""
    edges = [(f, getattr(a, f, None)) for f in ("after", "until", "by")]
    given = [(f, v) for f, v in edges if v]
    return max(given, key=lambda fv: fv[1]) if given else None


def _check_vacuous(plan: RunPlan, sc: Scenario, doc: Document, notices: Notices) -> None:
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
    for part in plan.every_plan():
        taken |= {t.key for r in part.robots for p in r.plugins for t in p.topics if t.direction == "sub"}
    taken |= {b.sim_key for b in plan.bridges if b.direction != "ZENOH_TO_SIM"}
    rel = sorted(k[len(plan.name) + 1 :] for k in taken)

    def check(key: str, what: str, where_path: tuple[Any, ...], text: str) -> None:
        if key in taken:
            return
        near = difflib.get_close_matches(text.lstrip("/"), rel, n=1, cutoff=0.7)
        if plan.nodes and not near:
            return  # a node may take it (its subscriptions are not declared)
        where = doc.locate(where_path)
        notices.add(
            f"{what} publishes on {text!r}, which nothing in the run subscribes to"
            + (" (no plugin; a node may)" if plan.nodes else ""),
            where.file,
            where.line,
            hint=(f"did you mean {near[0]!r}? " if near else "")
            + (f"topics taken in this run: {', '.join(rel[:8])}" if rel else "no plugin takes messages"),
        )

    for i, ev in enumerate(sc.timeline):
        check(f"{sc.name}/{ev.topic.lstrip('/')}", f"timeline[{i}]", ("timeline", i, "topic"), ev.topic)
    for i, b in enumerate(plan.bridges):
        if b.direction != "SIM_TO_ZENOH":
            text = b.sim_key[len(plan.name) + 1 :]
            check(b.sim_key, f"bridge {i}", ("bridges", i), text)


SHADOW_REACH_M = 25.0  # the sun's shadow map reaches this far (m) at least
START_OVERLAP_M = 0.03  # a robot this deep inside something at t = 0 is warned about
START_OVERLAP_GROUND_M = 0.1  # ...or this deep in the ground


def _check_start_overlaps(m: mujoco.MjModel, sc: Scenario, doc: Document, notices: Notices) -> None:
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


def _check_record_patterns(plan: RunPlan, sc: Scenario, doc: Document, notices: Notices) -> None:
    """A `record.exclude` (or `include`) pattern that matches none of the run's topics is most likely a
    typo, and a costly one (the camera images it was meant to leave out fill the disk): say so."""
    import zenoh

    rec = plan.record
    if not rec.enabled:
        return
    keys = set()
    for part in plan.every_plan():
        keys |= {t.key for t in part.topics()}  # plugins' (the judge's _truth too), timeline's, clock
        # what the world publishes besides (runner.sim.scene, the contacts judge, the launcher's plan)
        keys |= {f"{part.name}/{k}" for k in ("scene", "tf", "tf_static", "_model", "_state", "_plan")}
        keys |= {topic_key(part.name, r.namespace, "robot_description") for r in part.robots}
        keys.add(contacts_key(part.name))
    known = [zenoh.KeyExpr(k) for k in keys]
    nodes = " (or a node publishes it)" if plan.nodes else ""
    rels = (k[len(plan.name) + 1 :] for k in keys)
    sample = ", ".join(sorted(rel for rel in rels if not hidden_topic(rel))[:6])
    for field_name, written, full in (
        ("exclude", sc.record.exclude, rec.exclude),
        ("include", sc.record.include, rec.include),
    ):
        for i, (text, expr) in enumerate(zip(written, full, strict=True)):
            if any(zenoh.KeyExpr(expr).intersects(k) for k in known):
                continue
            where = doc.locate(("record", field_name, i))
            notices.add(
                f"record.{field_name}[{i}] {text!r} matches none of the run's topics{nodes}",
                where.file,
                where.line,
                hint=f"patterns are relative to the run, e.g. r1/camera/** or */camera/**; topics: {sample}",
            )


def _compile_world(
    sc: Scenario,
    doc: Document,
    record_path: str | None,
    notices: Notices,
    problems: Problems,
    unloaded: list[str],
) -> RunPlan:
    """One world and its robots, timeline, assertions, recording and nodes. Each independent item (a
    package folder, a robot, a plugin, a timeline entry...) is checked on its own: its mistakes go to
    `problems` and the pass goes on, so that one `validate` finds them all. The plan returned is then
    partial (robots that did not load are left out, their key prefixes added to `unloaded` so that later
    checks do not report their topics as missing, and there is no model): the caller raises `problems`
    before anything uses it."""
    base = doc.base_dir
    packages = PackageMap.for_scenario(base, {k: (base / v) for k, v in sc.packages.items()})
    packages.allowed = [base / p for p in sc.allow_paths]
    for name, folder in packages.explicit.items():
        if not folder.is_dir():
            problems.add(
                Problem(
                    f"package folder {str(folder)!r} does not exist",
                    doc.locate(("packages", name)),
                    ("packages", name),
                    hint="paths are relative to the scenario's folder",
                )
            )

    world, sdf_rate = mujoco.MjSpec(), None
    with problems.each():
        world, sdf_rate = _world_spec(sc, doc, packages, notices)
    with problems.each():
        check_names(sc, doc, {m.name for m in sc.world.models}, bool(sc.world.sdf))
    watched = truth_robots(sc)
    robots: list[RobotPlan] = []
    for i, robot in enumerate(sc.robots):
        if robot.name in watched:
            # the judge reads the robot's true pose; recorded, so `scenario check` can judge the file
            extra = PluginEntry(
                type="ground_truth", name="_truth", params={"topic": TRUTH_TOPIC, "rate": TRUTH_RATE}
            )
            robot = robot.model_copy(update={"plugins": [*robot.plugins, extra]})
        before, found = len(notices), len(problems)
        with problems.each():
            model = _robot_model(robot, i, doc, packages, notices, sc.world.physics.timestep)
            plugins = _build_plugins(sc, robot, i, model, doc, problems)
            _add_transmissions(model, notices)
            parity = summarize(model, plugins, notices.items[before:], f"{sc.name}/{robot.ns}/")
            pos = robot.pose.xyz
            frame = world.worldbody.add_frame(pos=list(pos), quat=list(rpy_to_quat(robot.pose.rpy)))
            prefix = f"{robot.ns}/"
            wheels = wheel_links(plugins, model.spec)
            world.attach(model.spec, prefix=prefix, frame=frame)
            anisotropic_wheels(world, prefix, wheels, model.gazebo, notices)
            # a robot's camera may have grown its framebuffer: the world's is the one cameras render into
            g, rg = world.visual.global_, model.spec.visual.global_
            g.offwidth, g.offheight = max(g.offwidth, rg.offwidth), max(g.offheight, rg.offheight)
            robots.append(
                RobotPlan(
                    name=robot.name,
                    namespace=robot.ns,
                    prefix=prefix,
                    root=model.root,
                    fixed=robot.fixed,
                    description_file=str(_description_path(robot, base)),
                    links=model.links,
                    joints=model.joints,
                    plugins=plugins,
                    urdf=model.urdf,
                    gazebo=parity,
                )
            )
        if len(problems) > found:  # not loaded, or a plugin left out: which topics it has is not known
            unloaded.append(f"{sc.name}/{robot.ns}/")

    mjcf, step = "", sc.world.physics.timestep
    if not problems:  # a world with a robot missing, or one that failed, would only add noise
        with problems.each():
            mjcf = _compile_model(world, robots, sc, doc, notices)
            step = world.option.timestep

    ordered: list[tuple[int, TimelinePlan]] = []
    for i in range(len(sc.timeline)):
        with problems.each():
            ordered.append((i, _timeline_entry(sc, i, doc)))
    with problems.each():
        _check_timeline_types(ordered, robots, sc, doc)
    timeline = sorted((ev for _, ev in ordered), key=lambda ev: ev.t_ns)

    record = RecordPlan(enabled=False, path="", include=[], exclude=[])
    with problems.each():
        record = _record_plan(sc, doc, record_path)

    published = {t.key: t.type for r in robots for p in r.plugins for t in p.topics if t.direction == "pub"}
    published.update({f"{sc.name}/{ev.topic.strip('/')}": msgs.normalize_type(ev.type) for ev in sc.timeline})
    keys: list[str] = []
    with problems.each():
        keys = assertion_keys(sc, doc, published, unchecked=unloaded)
    contact_watch = sorted({n for a in sc.assertions if isinstance(a, NoCollision) for n in a.between})
    rate = sc.rate
    if sdf_rate and "rate" not in sc.model_fields_set:
        rate = sdf_rate  # the world file's <real_time_factor>, unless the scenario sets `rate:`
    nodes: list[NodePlan] = []
    with problems.each():
        nodes = _nodes(sc, doc, base)
    host = None
    with problems.each():
        host = _host(sc, doc, sc.world.host, ("world", "host"))
    return RunPlan(
        name=sc.name,
        scenario_file=str(doc.file) if doc.file else None,
        duration_ns=round(sc.duration * 1e9),
        rate=rate,
        seed=sc.seed,
        step_ns=round(step * 1e9),
        clock_rate=sc.world.clock_rate,
        mjcf=mjcf,
        robots=robots,
        timeline=timeline,
        record=record,
        notices=[n.render() for n in notices],
        assertions=[a.model_dump(mode="json") for a in sc.assertions],
        assertion_keys=keys,
        contact_watch=contact_watch,
        stop_on=sc.stop_on,
        renderers=sc.renderers,
        nodes=nodes,
        lockstep=list(sc.lockstep),
        hosts={name: h.endpoint for name, h in sc.hosts.items()},
        host=host,
    )


def _compile_model(
    world: mujoco.MjSpec, robots: list[RobotPlan], sc: Scenario, doc: Document, notices: Notices
) -> str:
    """The world with its robots compiled by MuJoCo and checked (start overlaps, wheels): its MJCF."""
    try:
        compiled = world.compile()
    except ValueError as e:
        raise ScenarioError(_compile_problem(e, sc, doc, world)) from None
    _check_start_overlaps(compiled, sc, doc, notices)
    wheelless = check_geometry(compiled, robots, notices)
    if wheelless:
        raise ScenarioError(
            Problem(
                message,
                doc.locate(("robots", i, "description")),
                ("robots", i, "description"),
                hint="give the wheel link a <collision> (a cylinder); with xacro, the `args:` that size it",
            )
            for i, message in wheelless
        )
    # the sun's shadow map covers shadowclip x the model's extent around its centre; at its edge the floor
    # shows shadow acne (black speckles), in camera images and renders of a small world: cover 25 m at least
    extent = float(compiled.stat.extent)
    if extent > 0:
        world.visual.map.shadowclip = max(float(world.visual.map.shadowclip), SHADOW_REACH_M / extent)
    return str(world.to_xml())


def _compile_problem(e: ValueError, sc: Scenario, doc: Document, world: mujoco.MjSpec) -> Problem:
    """MuJoCo's compile error ("Error: size 0 must be positive in geom / Element name 'r1/left_wheel'")
    at the robot (by its namespace prefix) or the world model it is about."""
    import re

    text = str(e)
    first = " ".join(text.split("\n")[0].split()).removeprefix("Error: ")
    m = re.search(r"Element name '([^']*)', id (\d+)", text)
    element = m.group(1) if m else ""
    kind = re.search(r" in (\w+)$", first)
    if m and not element and kind:  # an unnamed geom: named by its body
        found = [
            x for x in getattr(world, kind.group(1) + "s", []) if getattr(x, "id", None) == int(m.group(2))
        ]
        if found:
            parent = getattr(found[0], "parent", None)
            element = found[0].name or (parent.name if parent is not None else "")
    for i, robot in enumerate(sc.robots):
        if element.startswith(f"{robot.ns}/"):
            part = element[len(robot.ns) + 1 :]
            where: PathKey = ("robots", i, "description")
            return Problem(
                f"MuJoCo cannot compile robot {robot.name!r}: {first}" + (f" (at {part!r})" if part else ""),
                doc.locate(where),
                where,
                hint="check that link's <inertial> (positive mass, inertia) and geometry sizes; with xacro, "
                "the `args:` that set them",
            )
    for i, m_ in enumerate(sc.world.models):
        if element == m_.name:
            where = ("world", "models", i)
            return Problem(f"MuJoCo cannot compile model {m_.name!r}: {first}", doc.locate(where), where)
    where = ("world", "sdf") if sc.world.sdf else ("robots",)
    return Problem(
        f"MuJoCo cannot compile the world: {first}" + (f" (at {element!r})" if element else ""),
        doc.locate(where),
        where,
    )


def _host(sc: Scenario, doc: Document, name: str | None, where: PathKey) -> str | None:
    """A `host:` that must name one of `hosts:`."""
    if name is not None and name not in sc.hosts:
        raise ScenarioError(
            Problem(
                f"no host named {name!r}",
                doc.locate(where),
                where,
                expected="one of: " + ", ".join(sc.hosts) if sc.hosts else "a host declared in `hosts:`",
            )
        )
    return name


def _record_plan(sc: Scenario, doc: Document, record_path: str | None) -> RecordPlan:
    rec = sc.record
    if record_path is not None:
        path = Path(record_path)
    elif rec.path is not None:
        path = doc.base_dir / rec.path
        if rec.path.endswith(("/", "\\")) or path.is_dir():  # a folder: the recording goes in it
            path = path / f"{sc.name}.mcap"
    else:
        path = Path("runs") / f"{sc.name}.mcap"
    record = RecordPlan(
        enabled=rec.enabled,
        path=str(path),
        include=[_full_expr(sc.name, e) for e in rec.include],
        exclude=[_full_expr(sc.name, e) for e in rec.exclude],
    )
    _check_key_exprs(record, doc, rec)
    return record


def _nodes(sc: Scenario, doc: Document, base: Path) -> list[NodePlan]:
    """Nodes with their commands resolved; names unique; `lockstep` names nodes of the scenario."""
    import shlex
    import shutil
    import sys

    problems: list[Problem] = []
    out: list[NodePlan] = []
    seen: set[str] = set()
    for i, node in enumerate(sc.nodes):
        if node.name in seen:
            where: PathKey = ("nodes", i, "name")
            problems.append(Problem(f"two nodes named {node.name!r}", doc.locate(where), where))
        seen.add(node.name)
        try:
            argv = shlex.split(node.cmd) if isinstance(node.cmd, str) else list(node.cmd)
        except ValueError as e:
            where = ("nodes", i, "cmd")
            problems.append(Problem(f"cannot split the command: {e}", doc.locate(where), where))
            continue
        if not argv:
            where = ("nodes", i, "cmd")
            problems.append(
                Problem("the command is empty", doc.locate(where), where, hint="cmd: python my_node.py")
            )
            continue
        if argv[0] in ("python", "python3"):
            argv[0] = sys.executable  # the interpreter the runner (and its packages) run in
        cwd = (base / node.cwd) if node.cwd else base
        exe = argv[0]
        if cwd.is_dir() and shutil.which(exe) is None and shutil.which(str(cwd / exe)) is None:
            where = ("nodes", i, "cmd")
            problems.append(
                Problem(
                    f"command {exe!r} not found",
                    doc.locate(where),
                    where,
                    expected="a program on PATH, or an executable file relative to the node's cwd",
                    hint="for a Python script: cmd: python my_node.py",
                )
            )
        if not cwd.is_dir():
            where = ("nodes", i, "cwd")
            problems.append(
                Problem(
                    f"folder {str(cwd)!r} does not exist",
                    doc.locate(where),
                    where,
                    hint="relative to the scenario",
                )
            )
        out.append(
            NodePlan(
                name=node.name,
                argv=argv + list(node.args),
                env=dict(node.env),
                cwd=str(cwd.resolve()),
                namespace=node.namespace,
                respawn=node.respawn,
                respawn_limit=node.respawn_limit,
                required=node.required,
                host=_host(sc, doc, node.host, ("nodes", i, "host")),
            )
        )
    for j, name in enumerate(sc.lockstep):
        if name not in seen:
            where = ("lockstep", j)
            problems.append(
                Problem(
                    f"no node named {name!r}",
                    doc.locate(where),
                    where,
                    expected="one of: " + ", ".join(sorted(seen))
                    if seen
                    else "a node of this scenario (nodes:)",
                )
            )
    if problems:
        raise ScenarioError(problems)
    return out


# ------------------------------------------------------------------------------------------------ world
def _world_spec(
    sc: Scenario, doc: Document, packages: PackageMap, notices: Notices
) -> tuple[mujoco.MjSpec, float | None]:
    """The world without robots, and the SDF's real-time factor if it gives one."""
    spec = mujoco.MjSpec()
    spec.modelname = sc.name
    phys = sc.world.physics
    spec.option.timestep = phys.timestep
    spec.option.gravity = list(phys.gravity)
    spec.option.integrator = _INTEGRATOR[phys.integrator]
    spec.option.cone = _CONE[phys.friction_cone]
    spec.visual.global_.offwidth = 1280
    spec.visual.global_.offheight = 960
    spec.worldbody.add_light(
        name="sun", pos=[0, 0, 10], dir=[0.2, 0.1, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL
    )
    ground = sc.world.ground
    if ground.enabled:
        spec.worldbody.add_geom(
            name="ground",
            type=mujoco.mjtGeom.mjGEOM_PLANE,
            size=[0, 0, 0.05],
            rgba=list(ground.rgba),
            friction=[ground.friction, 0.005, 0.0001],
        )
    rate = _load_sdf(spec, sc, doc, packages, notices) if sc.world.sdf else None
    for i, m in enumerate(sc.world.models):
        try:
            _add_model(spec, m)
        except ValueError as e:  # MuJoCo: "repeated name 'x' in geom" (the ground, a model of the SDF world)
            where: PathKey = ("world", "models", i, "name")
            raise ScenarioError(
                Problem(
                    f"the world already has something named {m.name!r}",
                    doc.locate(where),
                    where,
                    found=str(e).removeprefix("Error: "),
                    hint="give the model another name"
                    + (" (`ground` is the ground plane's)" if m.name == "ground" else ""),
                )
            ) from None
    return spec, rate


def _load_sdf(
    spec: mujoco.MjSpec, sc: Scenario, doc: Document, packages: PackageMap, notices: Notices
) -> float | None:
    assert sc.world.sdf is not None
    path = doc.base_dir / sc.world.sdf
    if not path.is_file():
        raise ScenarioError(
            Problem(
                "world file not found" if not path.is_dir() else "this is a folder, not a world file",
                doc.locate(("world", "sdf")),
                ("world", "sdf"),
                expected="an SDF or .world file (relative to the scenario's folder)",
                found=str(path),
            )
        )
    try:
        sdf = load_sdf_world(spec, path, packages, notices)
    except SourceError as e:
        raise ScenarioError(
            [
                Problem(str(e), Location(e.file, e.line), hint=e.hint),
                Problem("while loading the world file", doc.locate(("world", "sdf")), ("world", "sdf")),
            ]
        ) from None
    if sdf.name is not None and not sdf.has_ground and "ground" not in sc.world.model_fields_set:
        ground = spec.geom("ground")
        if ground is not None:
            # Gazebo adds no ground a world file does not have (its robots would fall): neither do we
            spec.delete(ground)
            notices.add(
                "the world file has no ground plane: none is added, as in Gazebo",
                path,
                None,
                hint="set `world: {ground: {}}` in the scenario to add one",
            )
    explicit = sc.world.physics.model_fields_set  # the scenario's own values win over the file's
    if sdf.timestep and "timestep" not in explicit:
        spec.option.timestep = sdf.timestep
    if sdf.gravity and "gravity" not in explicit:
        spec.option.gravity = list(sdf.gravity)
    return sdf.real_time_factor


def _add_model(spec: mujoco.MjSpec, m: WorldModel) -> None:
    quat = list(rpy_to_quat(m.pose.rpy))
    if m.shape == "box":
        size = [s / 2 for s in m.size]
    elif m.shape == "cylinder":
        size = [m.size[0], m.size[1] / 2, 0]
    else:
        size = [m.size[0], 0, 0]
    geom_kw: dict[str, Any] = {
        "name": m.name,
        "type": _GEOM[m.shape],
        "size": size,
        "rgba": list(m.rgba),
        "friction": [m.friction, 0.005, 0.0001],
    }
    if m.static:
        spec.worldbody.add_geom(pos=list(m.pose.xyz), quat=quat, **geom_kw)
        return
    body = spec.worldbody.add_body(name=m.name, pos=list(m.pose.xyz), quat=quat)
    body.add_freejoint(name=f"{m.name}/root")
    geom_kw["mass"] = m.mass or 1.0
    body.add_geom(**geom_kw)


# ------------------------------------------------------------------------------------------------ robots
def _description_path(robot: Robot, base: Path) -> Path:
    return (base / robot.desc.file).resolve()


def _needs_file(path: Path, doc: Document, where: PathKey, what: str, kind: str) -> None:
    if not path.is_file():
        raise ScenarioError(
            Problem(
                f"{what} file not found",
                doc.locate(where),
                where,
                expected=f"{kind} (relative to the scenario's folder)",
                found=str(path),
            )
        )


def _looks_like_xacro(path: Path) -> bool:
    """A file whatever its name that uses xacro (launch files run xacro on `.urdf` files too: nav2's
    sam_bot is one): it declares the xacro namespace or uses xacro elements."""
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return False
    return "xmlns:xacro" in text or "<xacro:" in text


def _robot_model(
    robot: Robot, i: int, doc: Document, packages: PackageMap, notices: Notices, timestep: float
) -> RobotModel:
    desc_path: PathKey = ("robots", i, "description")
    if isinstance(robot.description, str):
        file_path: PathKey = desc_path
    else:
        file_path = (*desc_path, "file")
    path = _description_path(robot, doc.base_dir)
    _needs_file(path, doc, file_path, "robot description", "a URDF or xacro file")
    controllers = []
    for k, name in enumerate(robot.controllers):
        found = doc.base_dir / name
        _needs_file(found, doc, ("robots", i, "controllers", k), "controllers", "a ros_control YAML file")
        controllers.append(found)
    try:
        if path.suffix == ".xacro" or _looks_like_xacro(path):
            args = {k: _xacro_str(v) for k, v in robot.desc.args.items()}
            result = expand(path, args, packages)
            return urdf_to_model(
                result.urdf,
                path,
                packages,
                fixed=robot.fixed,
                namespace=robot.ns,
                model=robot.name,
                notices=notices,
                sources=result.sources,
                expanded=True,
                timestep=timestep,
                controllers=controllers,
            )
        else:
            if robot.desc.args:
                raise ScenarioError(
                    Problem(
                        "`args` are given but the description is not a xacro file",
                        doc.locate((*desc_path, "args")),
                        (*desc_path, "args"),
                        hint="xacro arguments apply to .xacro files only",
                    )
                )
            urdf = path.read_text(encoding="utf-8")
            return urdf_to_model(
                urdf,
                path,
                packages,
                fixed=robot.fixed,
                namespace=robot.ns,
                model=robot.name,
                notices=notices,
                timestep=timestep,
                controllers=controllers,
            )
    except SourceError as e:
        where = Location(e.file, e.line) if e.file else doc.locate(file_path)
        hint = e.hint
        problems = [Problem(str(e), where, hint=hint)]
        if e.file != doc.file:
            problems.append(
                Problem(
                    f"while loading robot {robot.name!r}",
                    doc.locate(file_path),
                    file_path,
                )
            )
        raise ScenarioError(problems) from None


def _xacro_str(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return str(v)


@dataclass
class _Entry:
    """One plugin to build: from the scenario, from the description, or both merged."""

    type: str
    name: str
    params: dict[str, Any]
    scenario_index: int | None = None  # index in robots[i].plugins, when the scenario names it
    scenario_keys: frozenset[str] = frozenset()  # params the scenario set (the rest came from the file)
    source: DescribedPlugin | None = None
    added: str | None = None  # why the runner adds it, when neither the scenario nor the description has it


def _plugin_entries(robot: Robot, model: RobotModel) -> list[_Entry]:
    """The description's plugins, with the scenario's added, or merged in by name (or by type when the
    description has exactly one of that type): the scenario's params win."""
    entries: list[_Entry] = []
    if robot.plugins_from_description:
        entries = [_Entry(d.type, d.name, dict(d.params), source=d) for d in model.gazebo.plugins]
    for k, p in enumerate(robot.plugins):
        target = None
        if p.name is not None:
            target = next((e for e in entries if e.source and e.name == p.name), None)
        else:
            same = [e for e in entries if e.source and e.type == p.type and e.scenario_index is None]
            target = same[0] if len(same) == 1 else None
        if target is not None and target.type == p.type:
            target.params.update(p.params)
            target.scenario_index = k
            target.scenario_keys = frozenset(p.params)
        else:
            entries.append(_Entry(p.type, p.name or p.type, dict(p.params), k, frozenset(p.params)))
    return entries


STATE_PUBLISHER = "robot_state_publisher"


def _state_publisher(sc: Scenario, entries: list[_Entry]) -> list[_Entry]:
    """With `foxglove.scene` (the default), a robot whose scenario and description have no `tf` plugin gets
    one, as a launch file starts robot_state_publisher beside a Gazebo robot: every link's transform on
    the robot's `tf` (moving) and `tf_static` (fixed, sent again every `1/foxglove.rate` s: the transport
    does not latch, and a viewer seeking into a recording needs them near where it lands). A robot whose
    drive says where it is (odom -> base) is joined to it; any other from `world`. `entries`: the robot's
    own plugins (`_plugin_entries`)."""
    if not sc.foxglove.scene or any(e.type == "tf" for e in entries):
        return []
    driven = any(drive_frames(e.type, e.params) for e in entries)
    taken = {e.name for e in entries}
    name = next(n for n in (STATE_PUBLISHER, f"_{STATE_PUBLISHER}", "_tf") if n not in taken)
    params = {
        "rate": sc.foxglove.tf_rate,
        "static_period": 1.0 / sc.foxglove.rate,
        "include_root": not driven,
    }
    return [_Entry("tf", name, params, added="foxglove.scene")]


def _build_plugins(
    sc: Scenario, robot: Robot, i: int, model: RobotModel, doc: Document, problems: Problems
) -> list[PluginPlan]:
    """The robot's plugins, built; each one's mistakes go to `problems` and it is left out."""
    plans: list[PluginPlan] = []
    ctx = BuildContext(spec=model.spec, robot=robot.name, namespace=robot.ns, root=model.root)
    names: set[str] = set()
    entries = _plugin_entries(robot, model)
    for entry in entries + _state_publisher(sc, entries):
        here: PathKey = ("robots", i, "plugins", entry.scenario_index or 0)
        src = entry.source
        with problems.each():

            def fail(
                message: str, param: str | None, hint: str | None, entry: _Entry = entry
            ) -> ScenarioError:
                return _plugin_error(entry, here, doc, robot, i, message, param, hint)  # noqa: B023

            if entry.name in names:
                raise fail(f"two plugins named {entry.name!r}", None, "give one of them another `name:`")
            names.add(entry.name)
            try:
                cls = load(entry.type)
            except PluginLookupError as e:
                if entry.scenario_index is not None and entry.source is None:
                    where = (*here, "type")
                    raise ScenarioError(Problem(str(e), doc.locate(where), where, hint=e.hint)) from None
                raise fail(str(e), None, e.hint) from None
            _check_finite(entry, doc, here, fail)
            if src is None or entry.scenario_keys >= set(entry.params):
                params = validate_model(cls.Params, entry.params, doc, (*here, "params"))
            else:
                try:
                    params = cls.Params.model_validate(entry.params)
                except ValidationError as e:
                    err = e.errors(include_url=False)[0]
                    param = ".".join(str(x) for x in err["loc"]) or None
                    raise fail(f"{err['msg']} (found {err.get('input')!r})", param, None) from None
            try:
                topics = cls.build(params, ctx, entry.name)
            except PluginConfigError as e:
                raise fail(str(e), e.param, e.hint) from None
            rate = cls.rate_of(params)
            plans.append(
                PluginPlan(
                    type=entry.type,
                    name=entry.name,
                    params=params.model_dump(mode="json"),
                    rate=rate,
                    control_rate=cls.control_rate_of(params),
                    source_file=str(src.file) if src is not None and src.file else None,
                    source_line=src.line if src is not None else None,
                    added=entry.added,
                    topics=[
                        TopicPlan(
                            key=topic_key(sc.name, robot.ns, t.name),
                            type=t.type,
                            rate=t.rate,
                            direction=t.direction,
                            owner=f"{robot.ns}/{entry.name}",
                        )
                        for t in topics
                    ],
                )
            )
    return plans


def _non_finite(value: Any, path: tuple[Any, ...] = ()) -> tuple[tuple[Any, ...], float] | None:
    """(path, value) of the first NaN or infinity in plain data, or None."""
    if isinstance(value, float) and not math.isfinite(value):
        return path, value
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for k, v in items:
        found = _non_finite(v, (*path, k))
        if found is not None:
            return found
    return None


def _check_finite(entry: _Entry, doc: Document, here: PathKey, fail: Any) -> None:
    """NaN and infinity are no parameter's meaning (a plugin's model may let them through): an error at
    the scenario's line when the scenario set it, else at the description's."""
    found = _non_finite(entry.params)
    if found is None:
        return
    path, value = found
    if entry.scenario_index is not None and path[0] in entry.scenario_keys:
        where: PathKey = (*here, "params", *path)
        raise ScenarioError(
            Problem(
                "not a finite number",
                doc.locate(where),
                where,
                expected="a finite number",
                found=repr(value),
                hint="YAML reads .nan, .inf and numbers beyond 1.8e308 as these",
            )
        )
    shown = ".".join(str(p) for p in path)
    raise fail(f"{shown} is {value!r}, not a finite number", None, "give a plain, finite number")


def _plugin_error(
    entry: _Entry,
    here: PathKey,
    doc: Document,
    robot: Robot,
    i: int,
    message: str,
    param: str | None,
    hint: str | None,
) -> ScenarioError:
    """Point at the scenario when it set the parameter, else at the description's line."""
    src = entry.source
    if src is None or (entry.scenario_index is not None and (param is None or param in entry.scenario_keys)):
        where: PathKey = (*here, "params", param) if param else here
        return ScenarioError(Problem(message, doc.locate(where), where, hint=hint))
    what = f"{entry.type} plugin {entry.name!r} from the description"
    return ScenarioError(
        [
            Problem(
                f"{what}: " + (f"{param}: " if param else "") + message,
                Location(src.file, src.line),
                hint=hint,
            ),
            Problem(f"while loading robot {robot.name!r}", doc.locate(("robots", i)), ("robots", i)),
        ]
    )


def _add_transmissions(model: RobotModel, notices: Notices) -> None:
    """`<transmission>` joints get an actuator, unless a plugin already drives them (a diff_drive's
    wheels, a joint_controller's lift). Velocity -> velocity servo, position -> position servo,
    effort -> motor; the mechanical reduction is the gear."""
    spec = model.spec
    driven = {a.target for a in spec.actuators}
    for tr in model.transmissions:
        joint = spec.joint(tr.joint)
        if joint is None:
            notices.add(f"a transmission names joint {tr.joint!r}, which the robot does not have")
            continue
        if tr.joint in driven:
            continue
        act = spec.add_actuator(
            name=f"{tr.joint}/{tr.interface}", target=tr.joint, trntype=mujoco.mjtTrn.mjTRN_JOINT
        )
        if tr.interface == "velocity":
            act.set_to_velocity(kv=1.0)
        elif tr.interface == "position":
            act.set_to_position(kp=100.0, kv=10.0)
        else:
            act.set_to_motor()
        act.gear = [tr.reduction, 0, 0, 0, 0, 0]
        frc = list(joint.actfrcrange)
        if frc[1] > frc[0]:
            act.forcelimited = True
            act.forcerange = frc
        driven.add(tr.joint)


# ---------------------------------------------------------------------------------------------- timeline
def _timeline_entry(sc: Scenario, i: int, doc: Document) -> TimelinePlan:
    ev = sc.timeline[i]
    here: PathKey = ("timeline", i)
    type_name = msgs.normalize_type(ev.type)
    if not msgs.is_known(type_name):
        close = msgs.similar_types(ev.type)
        raise ScenarioError(
            Problem(
                f"unknown message type {ev.type!r}",
                doc.locate((*here, "type")),
                (*here, "type"),
                expected="a ROS 2 message type such as geometry_msgs/msg/Twist",
                hint=f"did you mean {close[0]!r}?" if close else None,
            )
        )
    try:
        msgs.from_data(type_name, ev.data)
    except msgs.MessageDataError as e:
        where: PathKey = (*here, "data", *e.path)
        raise ScenarioError(Problem(str(e), doc.locate(where), where, hint=e.hint)) from None
    topic = ev.topic
    key = f"{sc.name}/{topic.lstrip('/')}"
    return TimelinePlan(t_ns=round(ev.t * 1e9), key=key, type=type_name, data=ev.data)


def _check_timeline_types(
    timeline: list[tuple[int, TimelinePlan]], robots: list[RobotPlan], sc: Scenario, doc: Document
) -> None:
    """A timeline entry must carry the type its topic's subscriber takes: a `std_msgs/msg/String` on a
    drive's `cmd_vel` would reach the world (and a ROS client) as garbage."""
    takes = {
        t.key: (t.type, f"{p.type} {p.name!r} of robot {r.name!r}")
        for r in robots
        for p in r.plugins
        for t in p.topics
        if t.direction == "sub"
    }
    problems = []
    for i, ev in timeline:  # (the index in the scenario, the entry)
        wanted = takes.get(ev.key)
        if wanted is not None and msgs.normalize_type(wanted[0]) != ev.type:
            where: PathKey = ("timeline", i, "type")
            problems.append(
                Problem(
                    f"{sc.timeline[i].topic} is taken by {wanted[1]} as {wanted[0]}",
                    doc.locate(where),
                    where,
                    expected=wanted[0],
                    found=ev.type,
                    hint=f"write `type: {wanted[0]}` (and its fields under `data:`)",
                )
            )
    if problems:
        raise ScenarioError(problems)


def _full_expr(run: str, expr: str) -> str:
    return f"{run}/{expr.lstrip('/')}"


def _check_key_exprs(record: RecordPlan, doc: Document, given: Record | None = None) -> None:
    """Every include/exclude pattern is a key expression; errors show the pattern as the user wrote it
    (`given`), not with the run's name in front."""
    for field_name, exprs in (("include", record.include), ("exclude", record.exclude)):
        written = list(getattr(given, field_name)) if given is not None else exprs
        for j, e in enumerate(exprs):
            _check_expr(e, doc, ("record", field_name, j), written[j])


def _zenoh_settings(sc: Scenario, doc: Document) -> dict[str, Any]:
    """`zenoh:` checked against Zenoh itself (each setting inserted into a config), paths made absolute."""
    import json

    import zenoh

    assert sc.zenoh is not None
    base = doc.base_dir
    file = None
    if sc.zenoh.config is not None:
        path = base / sc.zenoh.config
        where: PathKey = ("zenoh", "config")
        if not path.is_file():
            raise ScenarioError(
                Problem(
                    f"file not found: {sc.zenoh.config}",
                    doc.locate(where),
                    where,
                    hint="relative to the scenario",
                )
            )
        try:
            zenoh.Config.from_file(str(path))
        except Exception as e:
            raise ScenarioError(
                Problem(f"Zenoh cannot read this configuration: {zenoh_reason(e)}", doc.locate(where), where)
            ) from None
        file = str(path.resolve())
    settings: dict[str, Any] = {}
    probe = zenoh.Config()
    for key, value in sc.zenoh.settings.items():
        where = ("zenoh", "settings", key)
        if isinstance(value, str) and (base / value).exists():
            value = str((base / value).resolve())  # a certificate, a key, an ACL file: beside the scenario
        try:
            probe.insert_json5(key, json.dumps(value))
        except Exception as e:
            raise ScenarioError(
                Problem(
                    f"Zenoh refuses the setting {key!r}: {zenoh_reason(e)}",
                    doc.locate(where),
                    where,
                    hint="a path in Zenoh's configuration, e.g. transport/link/tls/root_ca_certificate",
                )
            ) from None
        settings[key] = value
    for i, endpoint in enumerate(sc.zenoh.listen):
        if "/" not in endpoint:
            where = ("zenoh", "listen", i)
            raise ScenarioError(
                Problem(
                    f"{endpoint!r} is not a Zenoh endpoint",
                    doc.locate(where),
                    where,
                    expected="<protocol>/<address>:<port>, e.g. tcp/127.0.0.1:7447 or tls/127.0.0.1:7447",
                )
            )
    return {"file": file, "settings": settings}


def _check_expr(expr: str, doc: Document, where: PathKey, written: str | None = None) -> None:
    """`expr` is a Zenoh key expression; the error quotes `written` (what the user wrote) and Zenoh's
    reason."""
    import re

    import zenoh

    try:
        zenoh.KeyExpr(expr)
    except Exception as err:
        # zenoh's text: "Invalid Key Expr `...`: <why> at <its source file>:<line>."
        why = re.search(r"`: (.*?)(?: at \S+:\d+\.?)?$", str(err).strip())
        raise ScenarioError(
            Problem(
                f"{(written if written is not None else expr)!r} is not a valid key expression"
                + (f": {why.group(1)}" if why else ""),
                doc.locate(where),
                where,
                expected="chunks separated by '/' (none empty), '*' for one chunk, '**' for any number "
                "(e.g. `r1/**`, `*/scan`)",
                hint="patterns are relative to the run: `r1/scan` is the key <run>/r1/scan",
            )
        ) from None
