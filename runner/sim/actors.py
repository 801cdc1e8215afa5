"""Actors played in the world: each a mocap body whose pose is set every `TICK_NS` of sim time from a table
of its path sampled at that period (made once, at start), so that moving twenty actors costs two array
copies per tick (the next second of every moving actor's poses is gathered at once), not a Python loop
over their waypoints.

An actor's clock runs only while it moves: `stop` freezes it where it is, `start` resumes from there. At a
tick where an actor moves, its pose is the path's at its own time; the physics from that tick to the next
sees it there (the contacts push robots out of its way)."""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np

from runner.plan import ActorPlan

TICK_NS = 10_000_000  # actors move, and events look at the world, every 10 ms of sim time
MAX_SAMPLES = 360_000  # an hour of a path at TICK_NS: a longer path holds at the hour's point
WINDOW = 100  # ticks of poses gathered at once for the actors that move


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products of (n, 4) (w, x, y, z) arrays."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=1,
    )


def _axis_quat(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    half = angles / 2
    return np.concatenate([np.cos(half)[:, None], np.sin(half)[:, None] * axis[None, :]], axis=1)


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(n, 3) vectors `v` turned by (n, 4) quaternions `q`."""
    w, xyz = q[:, :1], q[:, 1:]
    t = 2 * np.cross(xyz, v)
    return v + w * t + np.cross(xyz, t)


def sample_path(a: ActorPlan) -> tuple[np.ndarray, np.ndarray]:
    """The actor's poses at every tick of its own time, from its start to the end of its path (for a loop:
    one lap, the last sample the lap's first): positions (k, 3) and orientations (k, 4)."""
    dt = TICK_NS / 1e9
    q0 = np.asarray(a.quat, dtype=float)
    if a.hinge is not None:
        h = a.hinge
        k = min(math.ceil(h["duration"] / dt) + 1, MAX_SAMPLES)
        angles = np.minimum(np.arange(k) * dt / h["duration"], 1.0) * h["angle"]
        axis = np.asarray(h["axis"], dtype=float)
        axis = axis / (np.linalg.norm(axis) or 1.0)
        turn = _axis_quat(axis, angles)  # in the model's frame
        quat = _quat_mul(np.repeat(q0[None], k, 0), turn)
        at = np.repeat(np.asarray(h["at"], dtype=float)[None], k, 0)
        # the hinge line stays put: origin + R0 (at - R(theta) at)
        offset = _rotate(np.repeat(q0[None], k, 0), at - _rotate(turn, at))
        return np.asarray(a.pos, dtype=float) + offset, quat
    if len(a.points) < 2:
        pos = np.asarray(a.points[0] if a.points else a.pos, dtype=float)[None]
        return pos, q0[None]
    times = np.asarray(a.times, dtype=float)
    pts = np.asarray(a.points, dtype=float)
    k = min(math.floor(times[-1] / dt + 1e-9) + 1, MAX_SAMPLES)
    if a.loop:
        k = max(round(times[-1] / dt), 1) + 1  # the lap's end is its start again
        k = min(k, MAX_SAMPLES)
    t = np.arange(k) * dt
    pos = np.stack([np.interp(t, times, pts[:, c]) for c in range(3)], axis=1)
    quat = np.repeat(q0[None], k, 0)
    if a.travel:
        seg = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(pts) - 2)
        d = pts[seg + 1] - pts[seg]
        yaw = np.arctan2(d[:, 1], d[:, 0])
        quat = _quat_mul(_axis_quat(np.array([0.0, 0.0, 1.0]), yaw), quat)
    return pos, quat


class Actors:
    """Every actor of the world: `tick(now_ns)` on each tick moves those that move."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, plans: list[ActorPlan]):
        self.data = data
        self.plans = plans
        n = len(plans)
        self.mocap = np.array(
            [
                int(model.body_mocapid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, a.name)])
                for a in plans
            ],
            dtype=np.int64,
        )
        tables = [sample_path(a) for a in plans]
        k = max((len(p) for p, _q in tables), default=1)
        self.pos = np.zeros((n, k, 3))
        self.quat = np.zeros((n, k, 4))
        self.last = np.zeros(n, dtype=np.int64)
        self.lap = np.full(n, np.iinfo(np.int64).max // 4, dtype=np.int64)
        for i, (p, q) in enumerate(tables):
            self.pos[i, : len(p)] = p
            self.quat[i, : len(q)] = q
            self.last[i] = len(p) - 1
            if plans[i].loop and len(p) > 1:
                self.lap[i] = len(p) - 1  # sample `lap` is sample 0 again
        # one table of poses (position, orientation) for all: row i * k + sample of actor i
        self.pose = np.concatenate([self.pos, self.quat], axis=2).reshape(n * k, 7)
        self.base = np.arange(n, dtype=np.int64) * k
        self.ticks = np.zeros(n, dtype=np.int64)  # ticks each actor has moved
        self.moving = np.zeros(n, dtype=bool)
        self.pending = sorted(
            ((a.start_ns, i) for i, a in enumerate(plans) if a.start_ns is not None), reverse=True
        )
        # the poses of the next WINDOW ticks of the actors that move (see `_window`), and how many of them
        # have been played: a tick is two array copies
        self._win: tuple[np.ndarray, Any, np.ndarray, np.ndarray] | None = None
        self._played = 0

    def start(self, i: int) -> None:
        self._commit()
        self.moving[i] = True

    def stop(self, i: int) -> None:
        self._commit()
        self.moving[i] = False

    def place(self, i: int, pos: list[float], quat: list[float]) -> None:
        """Teleported: it stops, and stands there until started again (then it goes on along its path)."""
        self.stop(i)
        self.data.mocap_pos[self.mocap[i]] = pos
        self.data.mocap_quat[self.mocap[i]] = quat

    def _commit(self) -> None:
        """The ticks played from the window counted into each actor's own clock; the window dropped (the
        set of moving actors changes, or it is used up)."""
        if self._win is not None:
            self.ticks[self._win[0]] += self._played
        self._win = None
        self._played = 0

    def _window(self) -> tuple[np.ndarray, Any, np.ndarray, np.ndarray]:
        """The actors that move, where their poses go in the mocap arrays (a slice when their mocap bodies
        are consecutive, as every actor of a world's are, else their indices), and their positions and
        orientations at each of the next WINDOW ticks of their own clocks: one gather for them all."""
        rows = np.flatnonzero(self.moving)
        ids = self.mocap[rows]
        where: Any = ids
        if len(ids) and np.array_equal(ids, np.arange(ids[0], ids[0] + len(ids))):
            where = slice(int(ids[0]), int(ids[0]) + len(ids))
        idx = self.ticks[rows][None, :] + np.arange(WINDOW)[:, None]  # (WINDOW, moving)
        idx %= self.lap[rows]
        np.minimum(idx, self.last[rows], out=idx)
        idx += self.base[rows]
        pose = self.pose[idx]
        self._win = (rows, where, np.ascontiguousarray(pose[..., :3]), np.ascontiguousarray(pose[..., 3:]))
        return self._win

    def tick(self, now_ns: int) -> None:
        while self.pending and self.pending[-1][0] <= now_ns:
            self._commit()
            self.moving[self.pending.pop()[1]] = True
        win = self._win
        if win is None or self._played == WINDOW:
            self._commit()
            win = self._window()
        rows, where, pos, quat = win
        if not len(rows):
            return
        k = self._played
        self.data.mocap_pos[where] = pos[k]
        self.data.mocap_quat[where] = quat[k]
        self._played = k + 1
