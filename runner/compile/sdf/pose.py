"""Poses as SDF composes them: a position and a unit quaternion (w, x, y, z), `a @ b` placing `b` in
`a`'s frame, and the few vector helpers the reader needs (rotate, normalise, the rotation of +Z onto a
normal)."""

from __future__ import annotations

import math
from typing import NamedTuple


class Pose(NamedTuple):
    p: tuple[float, float, float] = (0.0, 0.0, 0.0)
    q: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)  # w, x, y, z

    def __matmul__(self, other: Pose) -> Pose:  # type: ignore[override]
        return Pose(vec_add(self.p, rotate(self.q, other.p)), qmul(self.q, other.q))

    def inv(self) -> Pose:
        qc = (self.q[0], -self.q[1], -self.q[2], -self.q[3])
        x, y, z = rotate(qc, self.p)
        return Pose((-x, -y, -z), qc)


IDENTITY = Pose()


def vec_add(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float]:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def qmul(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def rotate(q: tuple[float, ...], v: tuple[float, ...]) -> tuple[float, float, float]:
    w, x, y, z = q
    vx, vy, vz = v
    # v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


def quat_z_to(n: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """The rotation taking +Z onto the unit vector n."""
    nx, ny, nz = n
    if nz < -1 + 1e-12:
        return (0.0, 1.0, 0.0, 0.0)
    w = 1.0 + nz
    ax, ay = -ny, nx  # z x n
    s = math.sqrt(w * w + ax * ax + ay * ay)
    return (w / s, ax / s, ay / s, 0.0)


def unit(v: tuple[float, ...]) -> tuple[float, float, float] | None:
    norm = math.sqrt(sum(c * c for c in v))
    if norm < 1e-12:
        return None
    return (v[0] / norm, v[1] / norm, v[2] / norm)
