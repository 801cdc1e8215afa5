"""A robot spawned into a running world (gazebo_ros's `/spawn_entity`, ros_gz's `/world/<w>/create`),
compiled as a scenario's robot is: its URDF read (`runner.compile.urdf`: its `<gazebo>` plugins, its
`<ros2_control>` hardware), its plugins built, and the model attached under its namespace to the world as
it stands (the world's MJCF), at the pose asked for. The world then swaps its model for the one returned
(runner.sim.grow).

What the world already had keeps its MuJoCo ids: the robot is attached last, so its bodies, joints,
geoms, actuators and sensors come after every existing one in each list, and so do its degrees of freedom
and sensor values (`check_prefix` holds the compiled model to that: the plugins running hold ids).

The description is untrusted input as any other: no xacro (a spawn request carries URDF or SDF text, as
gazebo_ros's spawn_entity.py sends it), the same size bounds, the same folders for the files it names
(the scenario's `packages:` and `allow_paths:`).
"""

from __future__ import annotations

import math
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from runner.compile.filesize import MAX_DESCRIPTION_BYTES
from runner.compile.packages import scenario_packages
from runner.compile.robots import add_robot
from runner.compile.wheels import check_geometry
from runner.errors import Notices, Problems, ScenarioError
from runner.plan import RobotPlan
from runner.scenario.loader import Document
from runner.scenario.schema import Scenario


class SpawnError(ValueError):
    """A spawn request that cannot be done: the reason, as the reply's status message says it."""


@dataclass
class Spawned:
    mjcf: str  # the world with the robot, as MuJoCo compiles it
    robot: RobotPlan
    notices: list[str] = field(default_factory=list)


def spawn_context(sc: Scenario) -> dict[str, Any]:
    """What of the scenario a robot spawned at run time is compiled against (`RunPlan.spawn`): its name,
    package folders, allowed paths, physics step and Foxglove settings (the transforms a robot gets)."""
    data: dict[str, Any] = sc.model_dump(
        mode="json",
        by_alias=True,
        exclude_unset=True,
        include={"name": True, "packages": True, "allow_paths": True, "foxglove": True, "world": {"physics"}},
    )
    data["name"] = sc.name
    return data


# the robot's own part of MuJoCo's lists: those a plugin or the world holds ids of
_KINDS = (
    ("body", "nbody"),
    ("jnt", "njnt"),
    ("geom", "ngeom"),
    ("site", "nsite"),
    ("cam", "ncam"),
    ("actuator", "nu"),
    ("sensor", "nsensor"),
    ("eq", "neq"),
    ("tendon", "ntendon"),
)


def check_prefix(old: mujoco.MjModel, new: mujoco.MjModel) -> str | None:
    """None when everything of `old` is in `new` at the same ids and addresses (what a spawn must keep),
    else what moved."""
    for kind, count in (*_KINDS, ("mocap", "nmocap")):
        if getattr(new, count) < getattr(old, count):
            return f"the world's {kind} count went from {getattr(old, count)} to {getattr(new, count)}"
    for size in ("nq", "nv", "na", "nsensordata"):
        if getattr(new, size) < getattr(old, size):
            return f"the world's {size} went from {getattr(old, size)} to {getattr(new, size)}"
    obj = mujoco.mjtObj
    named = (
        (obj.mjOBJ_BODY, "nbody"),
        (obj.mjOBJ_JOINT, "njnt"),
        (obj.mjOBJ_GEOM, "ngeom"),
        (obj.mjOBJ_SITE, "nsite"),
        (obj.mjOBJ_CAMERA, "ncam"),
        (obj.mjOBJ_ACTUATOR, "nu"),
        (obj.mjOBJ_SENSOR, "nsensor"),
    )
    for kind, count in named:
        for i in range(getattr(old, count)):
            was, now = mujoco.mj_id2name(old, kind, i), mujoco.mj_id2name(new, kind, i)
            if was != now and now != f"~deleted~{was}":  # (a deleted robot's, renamed: `renamed`)
                return f"{kind.name} {i} is {now!r}, was {was!r}"
    for addr, count in (
        ("jnt_qposadr", "njnt"),
        ("jnt_dofadr", "njnt"),
        ("sensor_adr", "nsensor"),
        ("geom_bodyid", "ngeom"),
        ("body_parentid", "nbody"),
        ("actuator_trnid", "nu"),
    ):
        n = getattr(old, count)
        if not np.array_equal(getattr(old, addr)[:n], getattr(new, addr)[:n]):
            return f"the world's {addr} changed"
    return None


def compile_spawn(
    mjcf: str,
    context: dict[str, Any],
    scenario_file: str | None,
    *,
    name: str,
    xml: str,
    namespace: str | None,
    position: tuple[float, float, float],
    quat: tuple[float, float, float, float],
    hidden: list[str] | None = None,
) -> Spawned:
    """The world `mjcf` with the robot `name` (URDF text `xml`) attached at `position`/`quat` (w x y z) under
    `namespace` (its name when None); `hidden`: names prefixes (`r2/`) of robots deleted before, renamed
    out of the way (their bodies stay, at their ids) so that their names can be taken again."""
    if len(xml.encode("utf-8", "replace")) > MAX_DESCRIPTION_BYTES:
        raise SpawnError(f"the description is larger than {MAX_DESCRIPTION_BYTES:,} bytes")
    if not all(math.isfinite(v) for v in (*position, *quat)):
        raise SpawnError("the pose holds a NaN or Inf")
    text = xml.lstrip()
    if not text:
        raise SpawnError("the description is empty (give URDF text in `xml`)")
    if "<robot" not in text[:4096] and "<sdf" in text[:4096]:
        raise SpawnError(
            "an SDF model: spawning takes a URDF robot (SDF models belong in the scenario's world)"
        )
    robot_data: dict[str, Any] = {"name": name, "description": "spawned.urdf"}
    if namespace:
        robot_data["namespace"] = namespace
    data = {**context, "robots": [robot_data]}
    try:
        sc = Scenario.model_validate(data)
    except Exception as e:  # (pydantic's message names the field: a name with a space, a bad namespace)
        raise SpawnError(_first_line(e)) from None
    robot = sc.robots[0]
    base = Path(scenario_file).parent if scenario_file else Path.cwd()
    for prefix in hidden or ():
        mjcf = renamed(mjcf, prefix)
    spec = mujoco.MjSpec.from_string(mjcf)
    notices = Notices()
    problems = Problems(None)
    with tempfile.TemporaryDirectory(prefix="scenario-spawn-") as tmp:
        path = Path(tmp) / f"{name.replace('/', '_')}.urdf"
        path.write_text(xml, encoding="utf-8")
        robot = robot.model_copy(update={"description": str(path)})
        doc = Document(data=data, file=(base / "spawn.yaml"))
        try:
            packages = scenario_packages(sc, doc, problems)
            plan = add_robot(spec, sc, robot, 0, doc, packages, notices, problems, quat=quat, xyz=position)
            problems.raise_all()
            compiled = spec.compile()
        except ScenarioError as e:
            raise SpawnError(_problems_text(e, str(path))) from None
        except ValueError as e:
            raise SpawnError(f"MuJoCo cannot compile the robot: {_first_line(e)}") from None
    wheelless = check_geometry(compiled, [plan], notices)
    if wheelless:
        raise SpawnError("; ".join(message for _i, message in wheelless))
    plan = plan.model_copy(update={"description_file": f"(spawned: {name})"})
    return Spawned(str(spec.to_xml()), plan, [n.render() for n in notices])


def renamed(mjcf: str, prefix: str) -> str:
    """The MJCF with every name that starts with `prefix` (a deleted robot's: bodies, joints, geoms,
    actuators, sensors, default classes, meshes, materials...), and every reference to one, renamed
    `~deleted~<name>`: the same elements, out of the way of a robot spawned under the same name. File
    paths are left as they are."""
    pattern = re.compile(r'(\s(?!file=)[A-Za-z_][\w:-]*)="' + re.escape(prefix))
    return pattern.sub(lambda m: f'{m.group(1)}="~deleted~{prefix}', mjcf)


def _first_line(e: Exception) -> str:
    text = str(e).strip()
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    return " ".join(lines[:3]).removeprefix("Error: ") if lines else type(e).__name__


def _problems_text(e: ScenarioError, path: str) -> str:
    parts = []
    for p in e.problems:
        where = f" (line {p.location.line})" if p.location.line and str(p.location.file) == path else ""
        parts.append(p.message + where + (f"; hint: {p.hint}" if p.hint else ""))
    return "; ".join(parts) or str(e)
