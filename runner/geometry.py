"""Small rotation helpers (quaternions are MuJoCo's order: w, x, y, z)."""

from __future__ import annotations

import math

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
