"""A trajectory plot (PNG) of a judged recording: every robot's path from above, the assertions' regions and
goals, and a red cross where a failure happened. Written beside the MCAP when an assertion fails.

Plain numpy drawing and a minimal PNG writer (zlib): no plotting stack to install for a picture this simple.
"""

from __future__ import annotations

import itertools
import math
import struct
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from runner.checks import POSE_KINDS, specs_from_plan
from runner.checks.judge import Result, truth_key

SIZE = 640
MARGIN = 40
COLOURS = [(31, 119, 180), (255, 127, 14), (44, 160, 44), (148, 103, 189), (140, 86, 75), (227, 119, 194)]
RED = (214, 39, 40)
GREY = (150, 150, 150)


def write_png(path: Path, rgb: np.ndarray) -> None:
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].astype(np.uint8).tobytes() for y in range(h))

    def chunk(tag: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
        )

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b"")
    path.write_bytes(png)


class _Canvas:
    def __init__(self, lo: np.ndarray, hi: np.ndarray):
        self.img = np.full((SIZE, SIZE, 3), 255, dtype=np.uint8)
        span = max(float(np.max(hi - lo)), 1e-3)
        self.scale = (SIZE - 2 * MARGIN) / span
        self.lo = lo

    def px(self, x: float, y: float) -> tuple[int, int]:
        u = MARGIN + (x - self.lo[0]) * self.scale
        v = SIZE - MARGIN - (y - self.lo[1]) * self.scale
        return round(u), round(v)

    def dot(self, u: int, v: int, colour: tuple[int, int, int], r: int = 1) -> None:
        self.img[
            max(v - r, 0) : max(min(v + r + 1, SIZE), 0), max(u - r, 0) : max(min(u + r + 1, SIZE), 0)
        ] = colour

    def line(
        self, a: tuple[float, float], b: tuple[float, float], colour: tuple[int, int, int], r: int = 1
    ) -> None:
        (u0, v0), (u1, v1) = self.px(*a), self.px(*b)
        n = max(abs(u1 - u0), abs(v1 - v0), 1)
        for t in np.linspace(0.0, 1.0, n + 1):
            self.dot(round(u0 + (u1 - u0) * t), round(v0 + (v1 - v0) * t), colour, r)

    def circle(self, c: tuple[float, float], radius: float, colour: tuple[int, int, int]) -> None:
        pts = [
            (c[0] + radius * math.cos(a), c[1] + radius * math.sin(a))
            for a in np.linspace(0, 2 * math.pi, 73)
        ]
        for p, q in itertools.pairwise(pts):
            self.line(p, q, colour, 0)

    def box(self, lo: tuple[float, float], hi: tuple[float, float], colour: tuple[int, int, int]) -> None:
        corners = [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1]), (lo[0], lo[1])]
        for p, q in itertools.pairwise(corners):
            self.line(p, q, colour, 0)

    def cross(self, c: tuple[float, float], colour: tuple[int, int, int]) -> None:
        u, v = self.px(*c)
        for d in range(-8, 9):
            self.dot(u + d, v + d, colour, 1)
            self.dot(u + d, v - d, colour, 1)


def trajectory_plot(plan: Any, mcap: Path, results: list[Result], out: Path) -> Path | None:
    """Draw the robots' true paths from `mcap` (their `_truth` topics) with the assertions; None if the
    recording holds no path."""
    from mcap.reader import make_reader

    from runner import msgs

    keys = {truth_key(part.name, r.namespace): r.name for part in plan.worlds or [plan] for r in part.robots}
    paths: dict[str, list[tuple[int, float, float]]] = {}
    with open(mcap, "rb") as f:
        for _s, channel, message in make_reader(f).iter_messages(topics=list(keys)):
            m = msgs.decode(message.data, "nav_msgs/msg/Odometry")
            p = m.pose.pose.position
            paths.setdefault(keys[channel.topic], []).append((message.log_time, float(p.x), float(p.y)))
    if not paths:
        return None
    specs = specs_from_plan([a for part in plan.worlds or [plan] for a in part.assertions])
    pts = [np.array([(x, y) for _, x, y in path]) for path in paths.values()]
    for s in specs:
        region = getattr(s, "region", None)
        if region is not None and region.center is not None:
            c, r = np.array(region.center), region.radius or 0.0
            pts.append(np.array([c - r, c + r]))
        elif region is not None and region.min is not None:
            pts.append(np.array([region.min, region.max]))
        if getattr(s, "point", None) is not None:
            pts.append(np.array([s.point]))
    allpts = np.vstack(pts)
    lo, hi = allpts.min(axis=0) - 0.3, allpts.max(axis=0) + 0.3
    canvas = _Canvas(lo, hi)
    by_name = {r.name: r for r in results}
    for s in specs:
        ok = by_name.get(s.name)
        colour = RED if ok is not None and ok.status == "fail" else GREY
        region = getattr(s, "region", None)
        if region is not None and region.center is not None:
            canvas.circle(tuple(region.center), region.radius or 0.0, colour)
        elif region is not None and region.min is not None:
            canvas.box(tuple(region.min), tuple(region.max), colour)
        if getattr(s, "point", None) is not None:
            canvas.circle(tuple(s.point), getattr(s, "tolerance", 0.1), colour)
    for i, (_name, path) in enumerate(sorted(paths.items())):
        colour = COLOURS[i % len(COLOURS)]
        for (_, x0, y0), (_, x1, y1) in itertools.pairwise(path):
            canvas.line((x0, y0), (x1, y1), colour, 1)
        canvas.dot(*canvas.px(path[0][1], path[0][2]), colour, 4)  # start
    for s in specs:
        r = by_name.get(s.name)
        if r is None or r.status != "fail" or r.t_ns is None or s.type not in POSE_KINDS:
            continue
        path = paths.get(s.robot)
        if path:
            _t, x, y = min(path, key=lambda p: abs(p[0] - r.t_ns))
            canvas.cross((x, y), RED)
    write_png(out, canvas.img)
    return out
