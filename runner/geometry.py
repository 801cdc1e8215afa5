"""Small rotation helpers (quaternions are MuJoCo's order: w, x, y, z), and what a robot's wheels are in a
compiled MuJoCo model."""

from __future__ import annotations

import math

import mujoco
import numpy as np


def rpy_to_quat(rpy: tuple[float, float, float] | list[float]) -> np.ndarray:
    """URDF/SDF roll-pitch-yaw (fixed axes X, Y, Z) -> quaternion [w, x, y, z]."""
    r, p, y = (float(a) / 2.0 for a in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array(
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ]
    )


def quat_to_yaw(q: np.ndarray | list[float]) -> float:
    w, x, y, z = (float(v) for v in q)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def yaw_to_quat(yaw: float) -> np.ndarray:
    return np.array([math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0)])


_ROUND = {
    int(mujoco.mjtGeom.mjGEOM_CYLINDER),
    int(mujoco.mjtGeom.mjGEOM_SPHERE),
    int(mujoco.mjtGeom.mjGEOM_ELLIPSOID),
    int(mujoco.mjtGeom.mjGEOM_CAPSULE),
}


def welded(m: mujoco.MjModel, body: int) -> list[int]:
    """The body and the bodies rigidly attached below it (URDF fixed joints: bodies with no joint), which
    Gazebo lumps into one link: a wheel joint's hub link and the tyre link fixed to it."""
    out = [body]
    for b in range(body + 1, m.nbody):  # MuJoCo numbers bodies depth first: children after parents
        if int(m.body_parentid[b]) in out and int(m.body_jntnum[b]) == 0:
            out.append(b)
    return out


def colliding_geoms(m: mujoco.MjModel, body: int) -> list[int]:
    """The colliding geoms of a body and of what is welded to it."""
    bodies = set(welded(m, body))
    return [
        g
        for g in range(m.ngeom)
        if int(m.geom_bodyid[g]) in bodies and (m.geom_contype[g] or m.geom_conaffinity[g])
    ]


def wheel_radius(m: mujoco.MjModel, body: int, *, round_only: bool = False) -> float | None:
    """The radius of a wheel's collision (its largest cylinder, sphere, ellipsoid or capsule; else, unless
    `round_only`, its largest bounding radius), None when it has no collision at all."""
    geoms = colliding_geoms(m, body)
    round_ = [float(m.geom_size[g][0]) for g in geoms if int(m.geom_type[g]) in _ROUND]
    if round_:
        return max(round_)
    if round_only or not geoms:
        return None
    return max(float(m.geom_rbound[g]) for g in geoms)
