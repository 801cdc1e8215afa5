"""A robot's description into the world: the URDF or xacro file found and read (`runner.compile.urdf`),
its hardware (`<ros2_control>` / `<transmission>`) given actuators, its plugins built, its Gazebo parity
summed up, and the model attached under the robot's namespace at its pose."""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from runner.checks import truth_robots
from runner.checks.judge import TRUTH_RATE, TRUTH_TOPIC
from runner.compile.filesize import HINT as SIZE_HINT
from runner.compile.filesize import too_large
from runner.compile.gazebo.info import Spawn
from runner.compile.hardware import add_hardware, release_hardware, summary
from runner.compile.packages import PackageMap
from runner.compile.parity import summarize
from runner.compile.plugins import build_plugins
from runner.compile.urdf import RobotModel, urdf_to_model
from runner.compile.wheels import anisotropic_links, anisotropic_wheels
from runner.compile.xacro_expand import expand
from runner.errors import Location, Notices, Problem, Problems, ScenarioError, SourceError, missing_file_hint
from runner.geometry import rpy_to_quat
from runner.plan import ParityLine, RobotPlan
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import PluginEntry, Robot, Scenario


def add_robots(
    world: mujoco.MjSpec,
    sc: Scenario,
    doc: Document,
    packages: PackageMap,
    notices: Notices,
    problems: Problems,
    unloaded: list[str],
) -> list[RobotPlan]:
    """The scenario's robots loaded and attached to `world`, each on its own: the mistakes of one go to
    `problems`, and its key prefix to `unloaded` (which topics it has is then not known)."""
    watched = truth_robots(sc)
    robots: list[RobotPlan] = []
    for i, robot in enumerate(sc.robots):
        if robot.name in watched:
            # the judge reads the robot's true pose; recorded, so `scenario check` can judge the file
            extra = PluginEntry(
                type="ground_truth", name="_truth", params={"topic": TRUTH_TOPIC, "rate": TRUTH_RATE}
            )
            robot = robot.model_copy(update={"plugins": [*robot.plugins, extra]})
        found = len(problems)
        with problems.each():
            robots.append(add_robot(world, sc, robot, i, doc, packages, notices, problems))
        if len(problems) > found:  # not loaded, or a plugin left out: which topics it has is not known
            unloaded.append(f"{sc.name}/{robot.ns}/")
    return robots


def add_robot(
    world: mujoco.MjSpec,
    sc: Scenario,
    robot: Robot,
    i: int,
    doc: Document,
    packages: PackageMap,
    notices: Notices,
    problems: Problems,
    *,
    xyz: Sequence[float] | None = None,
    quat: Sequence[float] | None = None,
) -> RobotPlan:
    """Robot `i` (`robots[i]`) read, its plugins built (each one's mistakes to `problems`, left out),
    attached to `world` under `<ns>/` at its pose (or at `xyz` / `quat` (w x y z): a robot spawned at run
    time, runner.compile.spawn)."""
    before = len(notices)
    model = robot_model(robot, i, doc, packages, notices, sc.world.physics.timestep)
    # the hardware first: a controller's build claims the actuators it made (plugins/_actuators.py)
    hardware, rate = add_hardware(model, notices, sc.world.physics.timestep)
    plugins = build_plugins(sc, robot, i, model, doc, problems, notices)
    release_hardware(model.spec, hardware)
    if model.world is not None:
        _welded_by_description(model, robot, i, doc, notices)
    parity = summary(model, hardware) + summarize(
        model, plugins, notices.items[before:], f"{sc.name}/{robot.ns}/"
    )
    pos = list(robot.pose.xyz if xyz is None else xyz)
    rot = list(rpy_to_quat(robot.pose.rpy) if quat is None else quat)
    frame = world.worldbody.add_frame(pos=pos, quat=rot)
    prefix = f"{robot.ns}/"
    # the description's own <mujoco><size memory="..."/>: the world gets at least that much; its other
    # settings (<option>: said by the URDF reader) are the world's, which MuJoCo keeps with a warning each
    world.memory = max(int(world.memory), int(model.spec.memory))
    model.spec.memory = world.memory
    for name in dir(world.option):  # (MuJoCo would warn of each difference as it compiles the world)
        value = getattr(world.option, name)
        if not name.startswith("_") and isinstance(value, int | float | np.ndarray):
            setattr(model.spec.option, name, value)
    world.attach(model.spec, prefix=prefix, frame=frame)
    # every link with friction differing along and across an fdir1: drive wheels, mecanum wheels by friction
    anisotropic_wheels(world, prefix, anisotropic_links(model.gazebo), model.gazebo, notices)
    # a robot's camera may have grown its framebuffer: the world's is the one cameras render into
    g, rg = world.visual.global_, model.spec.visual.global_
    g.offwidth, g.offheight = max(g.offwidth, rg.offwidth), max(g.offheight, rg.offheight)
    return RobotPlan(
        name=robot.name,
        namespace=robot.ns,
        prefix=prefix,
        root=model.root,
        fixed=robot.fixed or model.world is not None,
        description_file=str(description_path(robot, doc.base_dir)),
        links=model.links,
        joints=model.joints,
        plugins=plugins,
        urdf=model.urdf,
        gazebo=parity,
        world_origin=model.world.origin if model.world is not None else None,
        hardware=hardware,
        hardware_rate=rate,
    )


def _welded_by_description(model: RobotModel, robot: Robot, i: int, doc: Document, notices: Notices) -> None:
    """Say that the description welds the robot (validate's "as in Gazebo" lines), and warn where the
    scenario says `fixed: false`: Gazebo welds such a robot whatever its spawner is told."""
    world = model.world
    assert world is not None
    how = "welds" if world.joint_type == "fixed" else f"joins ({world.joint_type} joint)"
    text = (
        f"the description's root link `world` {how} {world.root!r} to the world at the robot's pose "
        f"(joint {world.joint!r}), as Gazebo does: `fixed:` is not needed"
    )
    model.adjusted.append(
        ParityLine(kind="base", text=text, file=str(world.file) if world.file else None, line=world.line)
    )
    if "fixed" in robot.model_fields_set and not robot.fixed:
        where = doc.locate(("robots", i, "fixed"))
        notices.add(
            f"robot {robot.name!r}: `fixed: false`, but its description's root link `world` welds it to the "
            "world (Gazebo welds it whatever the spawner says): welded",
            where.file,
            where.line,
            hint="remove `fixed: false`; to have a free robot, load a description without the `world` link",
        )


def _spawn(robot: Robot, i: int, doc: Document) -> Spawn:
    """The robot's `spawn:` and `controller_types:`, with where each name is written (for notices)."""
    where: dict[str, tuple[Path | None, int | None]] = {}
    for k, name in enumerate(robot.spawn or []):
        loc = doc.locate(("robots", i, "spawn", k))
        where[name] = (loc.file, loc.line)
    for name in robot.controller_types:
        loc = doc.locate(("robots", i, "controller_types", name))
        where.setdefault(name, (loc.file, loc.line))
    return Spawn(robot.spawn, dict(robot.controller_types), where)


def description_path(robot: Robot, base: Path) -> Path:
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
                hint=missing_file_hint(path),
            )
        )


_SUBSTITUTION = re.compile(r"\$\((find|arg|env|optenv|eval|dirname|find-pkg-share)\b")


def _looks_like_xacro(path: Path) -> bool:
    """A file whatever its name that uses xacro (launch files run xacro on `.urdf` files too: nav2's
    sam_bot is one): it declares the xacro namespace, uses xacro elements, is named `*.xacro.*`, or uses
    xacro's substitutions alone (gz_ros2_control's demo `*.xacro.urdf` files have only `$(find ...)` in a
    <parameters>, which its launch's xacro run resolves). A bare `${...}` does not count: in a plain URDF it
    is more likely a value left unexpanded, said as such at its line."""
    if ".xacro" in path.name:
        return True
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return False
    return "xmlns:xacro" in text or "<xacro:" in text or _SUBSTITUTION.search(text) is not None


def robot_model(
    robot: Robot, i: int, doc: Document, packages: PackageMap, notices: Notices, timestep: float
) -> RobotModel:
    desc_path: PathKey = ("robots", i, "description")
    if isinstance(robot.description, str):
        file_path: PathKey = desc_path
    else:
        file_path = (*desc_path, "file")
    path = description_path(robot, doc.base_dir)
    _needs_file(path, doc, file_path, "robot description", "a URDF or xacro file")
    controllers = []
    for k, name in enumerate(robot.controllers):
        found = doc.base_dir / name
        _needs_file(found, doc, ("robots", i, "controllers", k), "controllers", "a ros_control YAML file")
        controllers.append(found)
    spawn = _spawn(robot, i, doc)
    try:
        oversize = too_large(path)
        if oversize is not None:  # (before it is read or parsed; its includes: xacro_expand._cycle_guard)
            raise SourceError(oversize, path, hint=SIZE_HINT)
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
                origins=result.origins,
                timestep=timestep,
                controllers=controllers,
                spawn=spawn,
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
                spawn=spawn,
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
