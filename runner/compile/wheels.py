"""Wheel-ground friction as Gazebo's mu1 / mu2 / fdir1 give it: different along and across the wheel.

Gazebo (ODE) bounds friction by `mu1` along `fdir1` (a direction in the collision's frame) and by `mu2`
across it. Skid-steer descriptions rely on it: a low friction along the axle lets the wheels slide sideways
so the robot turns in place. MuJoCo's friction is isotropic, except in an explicit contact `<pair>` whose
collider orients the contact frame along the geom: the plane-capsule collider does, with the first
friction value along the capsule's axis. So a wheel whose link has `mu1 != mu2` and an `fdir1` gets a
capsule on its axle (same radius and width as its cylinder, seen by no other collision and no camera),
paired with the ground plane with friction (along the axle, along the rolling direction); its cylinder
stops touching the ground (collision bits) and still meets everything else.

Measured (tests/test_gazebo_parity.py): a 4-wheel skid steer with mu1 = 1 along the rolling direction and
mu2 = 0.1 turns in place at ~95 % of its command, against ~30 % with isotropic friction. On other surfaces
than the ground plane (boxes, meshes) the wheel keeps its isotropic cylinder contact.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from runner.compile.gazebo import GazeboInfo
from runner.errors import DRIVE_GEOMETRY, Notices
from runner.geometry import colliding_geoms, wheel_radius
from runner.plan import ParityLine, PluginPlan, RobotPlan

_DRIVES = ("diff_drive", "skid_steer")
_MIN_MU = 0.01  # MuJoCo clamps a zero pair friction to 1e-5, and the pyramidal cone then diverges
_GEOMETRY_TOLERANCE = 0.05  # declared and built wheel geometry further apart than this get a warning


def wheel_joints(params: dict[str, Any]) -> tuple[list[str], list[str]]:
    """The left and the right wheel joints of a diff_drive's or skid_steer's (compiled) params."""
    left = params.get("left_joints") or [params.get("left_joint")]
    right = params.get("right_joints") or [params.get("right_joint")]
    return [j for j in left if j], [j for j in right if j]


def wheel_links(plugins: list[Any], spec: mujoco.MjSpec) -> list[str]:
    """The links that a drive's wheel joints move."""
    out = []
    for p in plugins:
        if p.type not in _DRIVES:
            continue
        left, right = wheel_joints(p.params)
        for j in left + right:
            joint = spec.joint(j)
            if joint is not None:
                out.append(joint.parent.name)
    return out


def anisotropic_wheels(
    world: mujoco.MjSpec, prefix: str, links: list[str], gazebo: GazeboInfo, notices: Notices
) -> int:
    """Give each wheel link with mu1 != mu2 and an fdir1 its capsule-ground pair; returns how many."""
    ground = world.geom("ground")
    count = 0
    for link in links:
        props = gazebo.links.get(link)
        if props is None or props.mu1 is None or props.mu2 is None or props.mu1 == props.mu2:
            continue
        if props.fdir1 is None:
            continue  # Gazebo's directions are then fixed in the world (an artifact): isotropic min(mu)
        if ground is None:
            notices.add(f"wheel {link!r}: mu1/mu2 differ, but the world has no ground plane to pair with")
            continue
        body = world.body(prefix + link)
        if body is None:
            continue
        ground.contype, ground.conaffinity = 1, 2
        fdir = np.array(props.fdir1, dtype=float)
        fdir /= np.linalg.norm(fdir)
        along_axle = abs(fdir[2]) >= 0.7  # the cylinder's axis (its local z) is the axle
        axle, rolling = (props.mu1, props.mu2) if along_axle else (props.mu2, props.mu1)
        g = float(ground.friction[0])
        axle, rolling = max(min(axle, g), _MIN_MU), max(min(rolling, g), _MIN_MU)
        for k, geom in enumerate(list(body.geoms)):
            if geom.type != mujoco.mjtGeom.mjGEOM_CYLINDER or not (geom.contype or geom.conaffinity):
                continue
            name = f"{prefix}{link}/wheel_contact_{k}"
            body.add_geom(
                name=name,
                type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                size=[geom.size[0], geom.size[1], 0],
                pos=list(geom.pos),
                quat=list(geom.quat),
                contype=0,
                conaffinity=0,
                group=3,  # with the collision geoms: never drawn
                mass=0,
            )
            geom.contype, geom.conaffinity = 1, 0
            world.add_pair(
                geomname1="ground",
                geomname2=name,
                condim=3,
                friction=[axle, rolling, 0.005, 0.0001, 0.0001],
            )
            count += 1
    return count


def check_geometry(m: mujoco.MjModel, robots: list[RobotPlan], notices: Notices) -> list[tuple[int, str]]:
    """Warn where a drive's declared wheel separation or radius is not the robot's, or its left wheels are
    on the right; returns (robot index, message) for each drive wheel with nothing to roll on (no
    collision shape: a zero-size one is left out), which no drive can move a robot with.

    Gazebo's drives turn wheel speeds with the declared values whatever the links say, so a description
    whose `<wheel_separation>` is wider than its wheel joints makes the robot turn faster than commanded,
    in Gazebo as here. We keep that (parity) and say so, with the factor, at the plugin's line; the
    robot's "as in Gazebo" summary gets the same line."""
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    fatal = []
    for i, robot in enumerate(robots):
        for p in robot.plugins:
            if p.type not in _DRIVES:
                continue
            left, right = wheel_joints(p.params)
            for j in left + right:
                jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, robot.prefix + j)
                if jid >= 0 and not colliding_geoms(m, int(m.jnt_bodyid[jid])):
                    link = m.body(int(m.jnt_bodyid[jid])).name.removeprefix(robot.prefix)
                    fatal.append((i, f"{p.type} {p.name!r}: its wheel {link!r} ({j}) has no collision shape"))
            file = Path(p.source_file) if p.source_file else None
            for message, hint in _geometry_mismatches(m, d, robot.prefix + robot.root, robot.prefix, p):
                notices.add(message, file, p.source_line, hint=hint, kind=DRIVE_GEOMETRY, about=p.name)
                robot.gazebo.append(
                    ParityLine(kind="geometry", text=message, file=p.source_file, line=p.source_line)
                )
    return fatal


def _geometry_mismatches(
    m: mujoco.MjModel, d: mujoco.MjData, root: str, prefix: str, p: PluginPlan
) -> list[tuple[str, str]]:
    """(message, hint) for left wheels on the robot's right, and for each declared wheel value more than
    5 % off the built robot's."""
    left, right = wheel_joints(p.params)
    ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, prefix + j) for j in left + right]
    base = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, root)
    if not left or not right or min(ids) < 0 or base < 0:
        return []
    bodies = [int(m.jnt_bodyid[j]) for j in ids]
    out = []
    parity = "as in Gazebo (whose drive uses the declared value)"
    # the left wheels' centre seen from the right wheels', in the robot's frame (x ahead, y to the left)
    across = d.xmat[base].reshape(3, 3).T @ (
        np.mean(d.xpos[bodies[: len(left)]], axis=0) - np.mean(d.xpos[bodies[len(left) :]], axis=0)
    )
    if across[1] < 0 and abs(across[1]) > abs(across[0]):
        out.append(
            (
                f"{p.type} {p.name!r}: its left wheels ({', '.join(left)}) are on the robot's right (y < 0 "
                f"in {root.removeprefix(prefix)}): it turns the other way than commanded, as in Gazebo",
                "swap the left and right joints in the plugin (ROS 1's old legacyMode swapped them)",
            )
        )
    declared = p.params.get("wheel_separation")
    if declared and p.type == "diff_drive":
        built = float(np.linalg.norm(d.xpos[bodies[0]] - d.xpos[bodies[1]]))
        if built > 0 and abs(declared / built - 1) > _GEOMETRY_TOLERANCE:
            out.append(
                (
                    f"{p.type} {p.name!r}: wheel_separation {declared:.3f} m, but its wheel joints are "
                    f"{built:.3f} m apart: it turns at {declared / built:.2f}x the commanded rate, {parity}",
                    f"if the joints are where the wheels are, set wheel_separation to {built:.3f}",
                )
            )
    declared = p.params.get("wheel_radius")
    radii = [r for r in (wheel_radius(m, b, round_only=True) for b in bodies) if r]
    if declared and radii and not p.params.get("pair_radii"):
        built = float(np.mean(radii))
        if abs(built / declared - 1) > _GEOMETRY_TOLERANCE:
            out.append(
                (
                    f"{p.type} {p.name!r}: wheel radius {declared:.3f} m, but its wheels' collision radius "
                    f"is {built:.3f} m: it drives at {built / declared:.2f}x the commanded speed, {parity}",
                    f"if the collision is the wheel, set the wheel radius to {built:.3f} "
                    f"(diameter {2 * built:.3f})",
                )
            )
    return out
