"""Ground friction as Gazebo's mu1 / mu2 / fdir1 give it: different along and across a direction.

Gazebo (classic ODE, gz-physics dartsim) bounds friction by `mu1` along `fdir1` and by `mu2` across it, each
the smaller of the two surfaces' values. `fdir1` is fixed in the collision's frame (both engines rotate it
with the collision: ODEPhysics::Collide "fdir1 is in body local frame, rotate it into world frame"; DART's
DefaultContactSurfaceHandler::computeWorldFirstFrictionDir), or in gz-sim in the frame of the link that
`gz:expressed_in` names (a mecanum wheel's rollers: fixed in the base frame while the wheel turns).
Skid-steer descriptions rely on it (a low friction along the axle lets the wheels slide sideways so the
robot turns in place), and so do mecanum-by-friction ones (mu 1 along a diagonal, mu2 0 across it).

MuJoCo's friction is isotropic, except in an explicit contact `<pair>`, whose five friction values start with
the two tangent directions of the contact frame. Of MuJoCo's colliders only plane-capsule orients that frame:
its first tangent is the capsule's axis projected on the plane (engine_collision_primitive.c 66-96,
mjc_PlaneCapsule "align contact frames with capsule axis"; engine_util_spatial.c 512-537, mju_makeFrame
orthogonalizes it, or picks world y when none is set); every other pair gets a tangent fixed in the world. So
each round collision (cylinder, sphere) of such a link gets a capsule proxy paired with the ground plane, with
friction (along its axis, across it), seen by no other collision and no camera, and its own geom stops
touching the ground (collision bits) and still meets everything else: - fdir1 along the axle, or across it in
the wheel's plane (a skid steer): a capsule on the axle, as wide as the cylinder, with (mu1, mu2) or (mu2,
mu1): the frame is the same at every wheel angle. - fdir1 at another angle, fixed in the wheel (no
`expressed_in`, or a link fixed to the wheel): one short capsule (a sphere of the wheel's radius, its axis
along fdir1) turning with the wheel, as Gazebo's direction does; said, since a mecanum wheel wants its
direction fixed in the base. - fdir1 at another angle, fixed in a link the wheel turns on
(`gz:expressed_in="base_link"`): a ring of 16 short capsules around the wheel (radius half the wheel's, their
outer points on its circle), each with its axis set so that it lies along fdir1 whenever that capsule is the
one at the bottom. The wheel rolls on a 16-gon of spheres (its centre moves up and down by 0.96 % of its
radius) and the friction direction is off by at most a few degrees between two capsules.

Measured (tests/test_gazebo_parity.py, tests/test_friction_blocks.py): a 4-wheel skid steer with mu1 = 1
along the rolling direction and mu2 = 0.1 turns in place at ~95 % of its command, against ~30 % with
isotropic friction; a mecanum-by-friction robot strafes and turns as its roller kinematics say (see there).
On other surfaces than the ground plane (boxes, meshes) the wheel keeps its isotropic contact.
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


def anisotropic_links(gazebo: GazeboInfo) -> list[str]:
    """The links whose friction differs along and across an fdir1."""
    return [
        link
        for link, p in gazebo.links.items()
        if p.mu1 is not None and p.mu2 is not None and p.mu1 != p.mu2 and p.fdir1 is not None
    ]


def anisotropic_wheels(
    world: mujoco.MjSpec, prefix: str, links: list[str], gazebo: GazeboInfo, notices: Notices
) -> int:
    """Give each round collision of each link with mu1 != mu2 and an fdir1 its capsule-ground pair(s);
    returns how many geoms got them."""
    ground = world.geom("ground")
    count = 0
    for link in links:
        props = gazebo.links.get(link)
        if props is None or props.mu1 is None or props.mu2 is None or props.mu1 == props.mu2:
            continue
        if props.fdir1 is None:
            continue  # Gazebo's directions are then fixed in the world (an artifact): isotropic min(mu)
        body = world.body(prefix + link)
        if body is None:
            continue
        if ground is None:
            notices.add(f"link {link!r}: mu1/mu2 differ, but the world has no ground plane to pair with")
            continue
        round_geoms = [
            g
            for g in body.geoms
            if g.type in (mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_SPHERE)
            and (g.contype or g.conaffinity)
        ]
        if not round_geoms:
            if any(g.contype or g.conaffinity for g in body.geoms):
                file, line = props.fdir1_at
                notices.add(
                    f"link {link!r}: friction mu1={props.mu1:g} along fdir1 and mu2={props.mu2:g} across it "
                    "is simulated only on cylinders and spheres: its collision touches with the smaller, "
                    f"{min(props.mu1, props.mu2):g}, in every direction",
                    file,
                    line,
                )
            continue
        ground.contype, ground.conaffinity = 1, 2
        g = float(ground.friction[0])
        mu1, mu2 = (max(min(v, g), _MIN_MU) for v in (props.mu1, props.mu2))
        frame = _frame_of(world, prefix, body, props.fdir1_frame)
        axle = _axle(body)
        for k, geom in enumerate(round_geoms):
            made = _proxies(
                world, body, geom, f"{prefix}{link}/wheel_contact_{k}", props, frame, axle, mu1, mu2
            )
            if made and made[0] == "turning":
                file, line = props.fdir1_at
                notices.add(
                    f"link {link!r}: fdir1 {_vec(props.fdir1)} is fixed in its collision's frame and turns "
                    "with the wheel, as in Gazebo: the direction of friction mu1 on the ground changes as "
                    "the wheel rolls",
                    file,
                    line,
                    hint="a mecanum wheel's direction stays in the base frame: "
                    '<fdir1 gz:expressed_in="base_link"> (gz-sim)',
                )
            count += 1 if made else 0
    return count


_RING = 16  # capsules around a wheel whose fdir1 is fixed in the base
_RING_RADIUS = 0.5  # their radius / the wheel's
_SHORT = 1e-3  # a near-sphere capsule's half-length / its radius: its axis only orients the contact frame
_ALONG_AXLE = 0.97  # |cos| of fdir1 and the axle above which fdir1 is the axle ...
_ACROSS_AXLE = 0.26  # ... and below which it is across it (in the wheel's plane)


def _proxies(
    world: mujoco.MjSpec,
    body: Any,
    geom: Any,
    name: str,
    props: Any,
    frame: tuple[np.ndarray, bool] | None,
    axle: np.ndarray | None,
    mu1: float,
    mu2: float,
) -> tuple[str, int] | None:
    """The capsule(s) standing for `geom` on the ground, and their pairs: (kind, how many)."""
    fdir = np.array(props.fdir1, dtype=float)
    fdir /= np.linalg.norm(fdir)
    gmat = _mat(geom.quat)
    radius = float(geom.size[0])
    if frame is None:  # the collision's frame: rigid with the geom
        d_body, rigid = gmat @ fdir, True
    else:
        rot, rigid = frame
        d_body = rot @ fdir
    cyl_axis = gmat[:, 2] if geom.type == mujoco.mjtGeom.mjGEOM_CYLINDER else None
    spin = cyl_axis if cyl_axis is not None else axle  # what the geom rolls about
    if not rigid and axle is None:
        rigid = True  # the wheel does not turn relative to that frame: fixed in the body all the same
    half = float(geom.size[1]) if cyl_axis is not None else _SHORT * radius
    pos = np.array(geom.pos, dtype=float)

    def capsule(
        nm: str, at: np.ndarray, axis: np.ndarray, r: float, h: float, friction: tuple[float, float]
    ) -> None:
        quat = np.zeros(4)
        mujoco.mju_quatZ2Vec(quat, axis)
        body.add_geom(
            name=nm,
            type=mujoco.mjtGeom.mjGEOM_CAPSULE,
            size=[r, h, 0],
            pos=list(at),
            quat=list(quat),
            contype=0,
            conaffinity=0,
            group=3,  # with the collision geoms: never drawn
            mass=0,
        )
        world.add_pair(
            geomname1="ground",
            geomname2=nm,
            condim=3,
            friction=[friction[0], friction[1], 0.005, 0.0001, 0.0001],
        )

    geom.contype, geom.conaffinity = 1, 0
    cos = abs(float(d_body @ spin)) if spin is not None else 0.0
    if spin is not None and cos >= _ALONG_AXLE:
        capsule(name, pos, spin, radius, half, (mu1, mu2))
        return ("axle", 1)
    if spin is not None and cos <= _ACROSS_AXLE:
        # in the wheel's plane: on the ground it is the rolling direction, at every wheel angle
        capsule(name, pos, spin, radius, half, (mu2, mu1))
        return ("axle", 1)
    if rigid:
        capsule(name, pos, d_body, radius, _SHORT * radius, (mu1, mu2))
        return ("turning", 1)
    # fixed in a frame the wheel turns in: a ring whose bottom capsule always lies along fdir1
    assert spin is not None and axle is not None
    down = _mat(_world_quat(body)).T @ np.array([0.0, 0.0, -1.0])
    down -= (down @ spin) * spin
    if np.linalg.norm(down) < 0.5:
        down = np.cross(spin, d_body)  # an axle pointing down: no bottom to speak of, any spoke will do
    down /= np.linalg.norm(down)
    r = _RING_RADIUS * radius
    for k in range(_RING):
        rot = np.zeros(9)
        q = np.zeros(4)
        mujoco.mju_axisAngle2Quat(q, axle, 2 * np.pi * k / _RING)
        mujoco.mju_quat2Mat(rot, q)
        turn = rot.reshape(3, 3)
        # about the geom's centre on the wheel's axle (the hinge's axis, through the geom for a wheel)
        capsule(f"{name}_{k}", pos + turn @ down * (radius - r), turn @ d_body, r, _SHORT * r, (mu1, mu2))
    return ("ring", _RING)


def _mat(quat: Any) -> np.ndarray:
    out = np.zeros(9)
    q = np.array(quat, dtype=float)
    mujoco.mju_quat2Mat(out, q / np.linalg.norm(q))
    return out.reshape(3, 3)


def _world_quat(body: Any) -> np.ndarray:
    """The body's orientation in the world at the reference pose (joints at zero)."""
    q = np.array([1.0, 0, 0, 0])
    while body is not None and body.name != "world":
        out = np.zeros(4)
        b = np.array(body.quat, dtype=float)
        mujoco.mju_mulQuat(out, b / np.linalg.norm(b), q)
        q = out
        body = body.parent
    return q


def _frame_of(
    world: mujoco.MjSpec, prefix: str, body: Any, frame: str | None
) -> tuple[np.ndarray, bool] | None:
    """(the rotation from the link `frame` to `body` at the reference pose, whether `frame` turns with the
    body: no joint between them), or None for the collision's own frame."""
    if frame is None:
        return None
    other = world.body(prefix + frame)
    if other is None:
        return None
    rot = _mat(_world_quat(body)).T @ _mat(_world_quat(other))
    return rot, _welded(body, other)


def _welded(a: Any, b: Any) -> bool:
    """No joint on the path between two bodies of the tree."""
    up: dict[str, bool] = {}  # ancestor name -> a joint on the way from `a`
    jointed, x = False, a
    while x is not None and x.name != "world":
        up[x.name] = jointed
        jointed = jointed or bool(x.joints)
        x = x.parent
    jointed, x = False, b
    while x is not None and x.name != "world":
        if x.name in up:
            return not (jointed or up[x.name])
        jointed = jointed or bool(x.joints)
        x = x.parent
    return False


def _axle(body: Any) -> np.ndarray | None:
    """The axis (in the body's frame) of the hinge the body turns on: its own, or that of the link it is
    fixed to (a tyre fixed to a hub that the wheel joint turns)."""
    x = body
    while x is not None and x.name != "world":
        hinges = [j for j in x.joints if j.type == mujoco.mjtJoint.mjJNT_HINGE]
        if hinges:
            a = np.array(hinges[0].axis, dtype=float)
            a = _mat(_world_quat(body)).T @ _mat(_world_quat(x)) @ a
            return a / np.linalg.norm(a)
        if x.joints:
            return None  # a joint of another kind: no single axle
        x = x.parent
    return None


def _vec(v: Any) -> str:
    return " ".join(f"{x:g}" for x in v)


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
