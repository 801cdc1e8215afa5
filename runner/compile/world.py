"""One world compiled: the `MjSpec` of its ground, physics, SDF file and models, its robots attached, the
whole compiled by MuJoCo (its errors located at the robot or model they are about), and the world's plan:
robots, timeline, assertions' keys, recording, nodes. (Several worlds: `runner.compile.worlds`.)"""

from __future__ import annotations

import re
from typing import Any

import mujoco

from runner.checks import assertion_keys, check_names
from runner.compile.actors import add_actors
from runner.compile.events import compile_events
from runner.compile.nodes import compile_nodes, declared_topics, host_of
from runner.compile.packages import PackageMap, scenario_packages
from runner.compile.record import record_plan
from runner.compile.robots import add_robots
from runner.compile.sanity import check_start_overlaps
from runner.compile.sdf import load_sdf_world
from runner.compile.spawn import spawn_context
from runner.compile.timeline import compile_timeline
from runner.compile.wheels import check_geometry
from runner.errors import Location, Notices, Problem, Problems, ScenarioError, SourceError, missing_file_hint
from runner.geometry import rpy_to_quat
from runner.plan import NodePlan, RecordPlan, RobotPlan, RunPlan, control_services
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import NoCollision, Scenario, WorldModel
from runner.wire import msgs

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


SHADOW_REACH_M = 25.0  # the sun's shadow map reaches this far (m) at least


def compile_world(
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
    packages = scenario_packages(sc, doc, problems)
    world, sdf_rate, actors = mujoco.MjSpec(), None, []
    # the world's name in ros_gz's service names (/world/<name>/control): the SDF file's <world name>,
    # else the scenario's name (with several worlds, the world's own)
    world_name = sc.name.rsplit("/", 1)[-1]
    with problems.each():
        world, sdf_rate, sdf_name = world_spec(sc, doc, packages, notices)
        world_name = sdf_name or world_name
        actors = add_actors(world, sc.world.actors, doc, problems)
    with problems.each():
        models = {m.name for m in sc.world.models} | {a.name for a in sc.world.actors}
        check_names(sc, doc, models, bool(sc.world.sdf))
    robots = add_robots(world, sc, doc, packages, notices, problems, unloaded)
    mjcf, step = "", sc.world.physics.timestep
    if not problems:  # a world with a robot missing, or one that failed, would only add noise
        with problems.each():
            mjcf = compile_model(world, robots, sc, doc, notices)
            step = world.option.timestep
    services = control_services(sc.name, world_name)
    timeline = compile_timeline(sc, doc, robots, problems, services)
    events = compile_events(sc, doc, mjcf, robots, actors, problems, services)
    record = RecordPlan(enabled=False, path="", include=[], exclude=[])
    with problems.each():
        record = record_plan(sc, doc, record_path)
    keys = _assertion_keys(sc, doc, robots, problems, unloaded)
    rate = sc.rate
    if sdf_rate and "rate" not in sc.model_fields_set:
        rate = sdf_rate  # the world file's <real_time_factor>, unless the scenario sets `rate:`
    nodes: list[NodePlan] = []
    with problems.each():
        nodes = compile_nodes(sc, doc, doc.base_dir)
    host = None
    with problems.each():
        host = host_of(sc, doc, sc.world.host, ("world", "host"))
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
        actors=actors,
        events=events,
        notices=[n.render() for n in notices],
        assertions=[a.model_dump(mode="json") for a in sc.assertions],
        assertion_keys=keys,
        contact_watch=sorted({n for a in sc.assertions if isinstance(a, NoCollision) for n in a.between}),
        stop_on=sc.stop_on,
        renderers=sc.renderers,
        nodes=nodes,
        lockstep=list(sc.lockstep),
        hosts={name: h.endpoint for name, h in sc.hosts.items()},
        resources=sc.resources.model_dump() if sc.resources else None,
        host=host,
        world_services=services,
        spawn=spawn_context(sc),
    )


def _assertion_keys(
    sc: Scenario, doc: Document, robots: list[RobotPlan], problems: Problems, unloaded: list[str]
) -> list[str]:
    """The keys the assertions read, checked against what the world's plugins and timeline publish."""
    # what the world publishes, and what someone else does: the topics its plugins take in (a node's
    # cmd_vel) and those nodes say they publish
    published = {t.key: t.type for r in robots for p in r.plugins for t in p.topics}
    published.update(
        {
            f"{sc.name}/{ev.topic.strip('/')}": msgs.normalize_type(ev.type)
            for ev in sc.timeline
            if ev.topic is not None and ev.type is not None
        }
    )
    declared = declared_topics(sc)
    published.update({k: t for k, t in declared.items() if t is not None})
    unloaded = [*unloaded, *(k for k, t in declared.items() if t is None)]  # (the node's mistake, said there)
    keys: list[str] = []
    with problems.each():
        keys = assertion_keys(sc, doc, published, unchecked=unloaded)
    return keys


def compile_model(
    world: mujoco.MjSpec, robots: list[RobotPlan], sc: Scenario, doc: Document, notices: Notices
) -> str:
    """The world with its robots compiled by MuJoCo and checked (start overlaps, wheels): its MJCF."""
    for memory in (*ARENA_RETRIES, None):
        try:
            compiled = world.compile()
            check_start_overlaps(compiled, sc, doc, notices)
            break
        except ValueError as e:
            raise ScenarioError(_compile_problem(e, sc, doc, world)) from None
        except mujoco.FatalError as e:
            # MuJoCo's own abort: its arena (16 MB unless the model says) full at the first step. Its
            # broad phase alone takes a slot for each pair of overlapping bodies, even bodies welded
            # together that never collide: 3,000 links on fixed joints at one place overflow it. The run
            # would end the same way, so the model gets more, or a located error instead of a traceback.
            if memory is None or "stack" not in str(e):
                raise ScenarioError(_fatal_problem(e, sc, doc)) from None
            world.memory = memory
            where = doc.locate(("robots",) if sc.robots else ("world",))
            notices.add(
                f"MuJoCo's memory for this world raised to {memory >> 20} MB: its {len(world.bodies)} bodies "
                "overlap too much for the default 16 MB",
                where.file,
                where.line,
                hint='a description can set its own with <mujoco><size memory="..."/></mujoco>',
            )
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


# MuJoCo's arena sizes tried when its default overflows at the first step (bytes): allocated per MjData,
# touched as used
ARENA_RETRIES = (128 << 20, 512 << 20)


def _fatal_problem(e: Exception, sc: Scenario, doc: Document) -> Problem:
    first = " ".join(str(e).split("\n")[0].split())
    where: PathKey = ("robots",) if sc.robots else ("world",)
    return Problem(
        f"MuJoCo cannot compute this world at t = 0: {first}",
        doc.locate(where),
        where,
        hint="thousands of shapes touching at the start fill MuJoCo's memory: check for links placed inside "
        "each other (with self-collision on) or robots inside each other; a description may give MuJoCo "
        'more with <mujoco><size memory="256M"/></mujoco>',
    )


def _compile_problem(e: ValueError, sc: Scenario, doc: Document, world: mujoco.MjSpec) -> Problem:
    """MuJoCo's compile error ("Error: size 0 must be positive in geom / Element name 'r1/left_wheel'")
    at the robot (by its namespace prefix) or the world model it is about."""

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
            hint = "check the model's size, mass and pose: positive sizes, a positive mass if it moves"
            return Problem(
                f"MuJoCo cannot compile model {m_.name!r}: {first}", doc.locate(where), where, hint=hint
            )
    where = ("world", "sdf") if sc.world.sdf else ("robots",)
    return Problem(
        f"MuJoCo cannot compile the world: {first}" + (f" (at {element!r})" if element else ""),
        doc.locate(where),
        where,
        hint="MuJoCo's message names the element it refused; check its sizes, masses and names",
    )


def world_spec(
    sc: Scenario, doc: Document, packages: PackageMap, notices: Notices
) -> tuple[mujoco.MjSpec, float | None, str | None]:
    """The world without robots, the SDF's real-time factor if it gives one, and its <world name>."""
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
    rate, name = _load_sdf(spec, sc, doc, packages, notices) if sc.world.sdf else (None, None)
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
    return spec, rate, name


def _load_sdf(
    spec: mujoco.MjSpec, sc: Scenario, doc: Document, packages: PackageMap, notices: Notices
) -> tuple[float | None, str | None]:
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
                hint=missing_file_hint(path)
                if not path.is_dir()
                else "name the .sdf or .world file in it: world: {sdf: <folder>/<file>.world}",
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
    return sdf.real_time_factor, sdf.name


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
