"""A trajectory plot (PNG) of a judged recording: the world from above (its models as grey shapes), every
robot's true path in the robot's own colour, the assertions' regions and goals, and a cross where a
failure happened; axes in metres, equal aspect, and a legend. Written beside the MCAP when an assertion
fails, and shown at the top of `scenario report`'s page.

Drawn with Pillow (twice the size, then halved: smooth lines and text); the world comes from the compiled
model the recording carries (its `_plan`), each robot's colour from `runner.tools.pictures` (the same as in
the report's plots and in `scenario render`). With several worlds, one panel each.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from runner.checks import POSE_KINDS, specs_from_plan
from runner.checks.judge import Result, truth_key
from runner.tools.pictures import RGB, Footprint, footprints, reach, rgb255, robot_bodies, run_colours

SS = 2  # drawn at this many times the size, then reduced
PLOT_W, PLOT_H = 760, 600  # the largest plot area of one world (pixels); several worlds share the width
MAX_ASPECT = 2.5  # a long, thin world gets room around it rather than a plot one pixel high
LEFT, TOP, BOTTOM, GAP, LEGEND_PAD = 62, 40, 52, 64, 28

INK = (40, 40, 46)
AXIS = (120, 120, 128)
GRID = (228, 228, 234)
PAPER = (255, 255, 255)
FIELD = (251, 251, 253)
SOLID = (168, 170, 178)  # world models
SOLID_EDGE = (118, 120, 128)
LOOSE = (212, 214, 220)  # models that can move, where they start
REGION = (84, 88, 100)
FAILED = (207, 34, 46)
# where a no_collision failure says the bodies touched (runner.checks.judge: "r1 touched walker at (x, y, z)")
_TOUCHED = re.compile(r" at \((-?[0-9.]+), (-?[0-9.]+), -?[0-9.]+\)$")


ACTOR_INK = (150, 150, 150)  # actors' paths: grey, dashed (robots have the colours)


def _fonts() -> dict[str, Any]:
    from PIL import ImageFont

    return {k: ImageFont.load_default(size=s * SS) for k, s in (("title", 15), ("label", 13), ("small", 11))}


@dataclass
class _Panel:
    title: str
    shapes: list[Footprint]
    paths: dict[str, np.ndarray]  # robot -> rows of (t ns, x, y)
    specs: list[Any]
    left_out: list[str] = field(default_factory=list)
    actors: dict[str, np.ndarray] = field(default_factory=dict)  # actor -> rows of (t ns, x, y)
    lo: np.ndarray = field(default_factory=lambda: np.zeros(2))
    hi: np.ndarray = field(default_factory=lambda: np.ones(2))
    scale: float = 1.0  # pixels (final) per metre
    origin: tuple[float, float] = (0.0, 0.0)  # top-left corner of the plot area (final pixels)

    @property
    def size(self) -> tuple[float, float]:
        return float(self.hi[0] - self.lo[0]) * self.scale, float(self.hi[1] - self.lo[1]) * self.scale

    def px(self, x: float, y: float) -> tuple[float, float]:
        """Drawing pixel (at SS) of a point in metres."""
        return (
            (self.origin[0] + (x - self.lo[0]) * self.scale) * SS,
            (self.origin[1] + (self.hi[1] - y) * self.scale) * SS,
        )


def _region_points(s: Any) -> list[np.ndarray]:
    region = getattr(s, "region", None)
    out = []
    if region is not None and region.center is not None:
        c, r = np.array(region.center, dtype=float), float(region.radius or 0.0)
        out.append(np.array([c - r, c + r]))
    elif region is not None and region.min is not None:
        out.append(np.array([region.min, region.max], dtype=float))
    if getattr(s, "point", None) is not None:
        tol = float(getattr(s, "tolerance", 0.1) or 0.1)
        out.append(np.array([np.array(s.point) - tol, np.array(s.point) + tol], dtype=float))
    return out


def _bounds(panel: _Panel) -> None:
    """The panel's extent: the whole world (but what lies far beyond the robots), the paths, the regions;
    with a margin, and no thinner than MAX_ASPECT."""
    path_pts = [p[:, 1:3] for p in panel.paths.values() if len(p)]
    subject = np.vstack(path_pts) if path_pts else np.zeros((1, 2))
    centre, radius = reach(subject)
    kept = []
    for f in panel.shapes:
        if np.max(np.linalg.norm(f.points() - centre, axis=1)) > radius:
            if f.model not in panel.left_out:
                panel.left_out.append(f.model)
        else:
            kept.append(f)
    panel.shapes = kept
    pts = [subject, *(f.points() for f in kept)]
    # actors' paths where they come near the robots' (a crowd far away does not shrink the picture)
    pts += [a[np.linalg.norm(a[:, 1:3] - centre, axis=1) <= radius, 1:3] for a in panel.actors.values()]
    for s in panel.specs:
        pts += _region_points(s)
    allpts = np.vstack(pts)
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    pad = max(0.3, 0.04 * float(np.max(hi - lo)))
    lo, hi = lo - pad, hi + pad
    span = hi - lo
    for a, b in ((0, 1), (1, 0)):  # widen the thin side
        if span[b] * MAX_ASPECT < span[a]:
            grow = span[a] / MAX_ASPECT - span[b]
            lo[b], hi[b] = lo[b] - grow / 2, hi[b] + grow / 2
    panel.lo, panel.hi = lo, hi


def _nice_step(span: float, ticks: int = 8) -> float:
    raw = span / ticks
    mag = 10 ** math.floor(math.log10(raw))
    return next(m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw)


def _tick_label(v: float) -> str:
    text = f"{round(v, 6):g}"
    return "0" if text == "-0" else text


def _dashed(draw: Any, pts: list[tuple[float, float]], fill: tuple[int, int, int], width: int) -> None:
    on, off = 7 * SS, 5 * SS
    carry, drawing = 0.0, True
    for (x0, y0), (x1, y1) in itertools.pairwise(pts):
        length = math.hypot(x1 - x0, y1 - y0)
        t = 0.0
        while t < length:
            run = min((on if drawing else off) - carry, length - t)
            if drawing:
                a, b = t / length, (t + run) / length
                draw.line(
                    [(x0 + (x1 - x0) * a, y0 + (y1 - y0) * a), (x0 + (x1 - x0) * b, y0 + (y1 - y0) * b)],
                    fill=fill,
                    width=width,
                )
            t += run
            carry += run
            if carry >= (on if drawing else off) - 1e-9:
                carry, drawing = 0.0, not drawing


def _circle_pts(c: tuple[float, float], r: float, n: int = 72) -> list[tuple[float, float]]:
    return [(c[0] + r * math.cos(a), c[1] + r * math.sin(a)) for a in np.linspace(0, 2 * math.pi, n + 1)]


def _cross(draw: Any, u: float, v: float) -> None:
    k = 7 * SS
    for width, colour in ((6 * SS, PAPER), (3 * SS, INK)):
        draw.line([(u - k, v - k), (u + k, v + k)], fill=colour, width=width)
        draw.line([(u - k, v + k), (u + k, v - k)], fill=colour, width=width)


def _panels(plan: Any, mcap: Path) -> tuple[list[_Panel], dict[str, RGB]]:
    import mujoco
    from mcap.reader import make_reader

    from runner.wire import msgs

    parts = plan.parts()
    keys = {truth_key(part.name, r.namespace): r.name for part in parts for r in part.robots}
    # actors: where the world's transforms put them (world -> actor, at the scene's tf rate)
    actor_tf = {f"{part.name}/tf": {a.name for a in part.actors} for part in parts if part.actors}
    rows: dict[str, list[tuple[int, float, float]]] = {}
    walked: dict[str, list[tuple[int, float, float]]] = {}
    with open(mcap, "rb") as f:
        for _s, channel, message in make_reader(f).iter_messages(topics=[*keys, *actor_tf]):
            if channel.topic in actor_tf:
                for tr in msgs.decode(message.data, "tf2_msgs/msg/TFMessage").transforms:
                    if tr.child_frame_id in actor_tf[channel.topic]:
                        at = tr.transform.translation
                        walked.setdefault(tr.child_frame_id, []).append((message.log_time, at.x, at.y))
                continue
            m = msgs.decode(message.data, "nav_msgs/msg/Odometry")
            p = m.pose.pose.position
            rows.setdefault(keys[channel.topic], []).append((message.log_time, float(p.x), float(p.y)))
    if not rows:
        return [], {}
    models: dict[str, Any] = {}
    panels = []
    for part in parts:
        names = [r.name for r in part.robots]
        try:
            model = mujoco.MjModel.from_xml_string(part.mjcf)
            models[part.name] = model
            moving = [b for b in range(model.nbody) if int(model.body_mocapid[b]) >= 0]  # actors: their paths
            shapes = footprints(model, skip_roots=[*(b for _n, b in robot_bodies(model, names)), *moving])
        except Exception:  # a model that no longer compiles (its meshes moved): paths only
            shapes = []
        specs = [
            s
            for s in specs_from_plan(part.assertions)
            if getattr(s, "robot", None) in names or s.type not in POSE_KINDS
        ]
        paths = {n: np.array(rows[n], dtype=float) for n in names if n in rows}
        if paths:
            title = part.name if plan.worlds else f"{plan.name}: paths from above"
            actors = {a.name: np.array(walked[a.name], dtype=float) for a in part.actors if a.name in walked}
            panels.append(_Panel(title, shapes, paths, specs, actors=actors))
    return panels, run_colours(plan, models)


def trajectory_plot(plan: Any, mcap: Path, results: list[Result], out: Path) -> Path | None:
    """Draw the robots' true paths from `mcap` (their `_truth` topics) over the world, with the
    assertions; None if the recording holds no path."""
    from PIL import Image, ImageDraw

    panels, colours = _panels(plan, mcap)
    if not panels:
        return None
    fonts = _fonts()
    by_name = {r.name: r for r in results}
    failed = {r.name for r in results if r.status == "fail"}
    # sizes: one world gets the whole plot area; several share its width
    each_w = PLOT_W if len(panels) == 1 else max(320, (PLOT_W + 240) // len(panels))
    for p in panels:
        _bounds(p)
        span = p.hi - p.lo
        p.scale = min(each_w / span[0], PLOT_H / span[1])
    robots = [n for p in panels for n in p.paths]
    legend = [(n, "robot") for n in robots] + [("start", "start"), ("end", "end")]
    if any(not f.moving for p in panels for f in p.shapes):
        legend.append(("world model", "solid"))
    if any(f.moving for p in panels for f in p.shapes):
        legend.append(("movable model, at start", "loose"))
    if any(p.actors for p in panels):
        legend.append(("actor's path", "actor"))
    if any(_region_points(s) for p in panels for s in p.specs):
        legend.append(("assertion region, goal", "region"))
    if failed:
        legend.append(("failed assertion", "failed"))
        legend.append(("where it failed", "cross"))
    legend_w = 44 + max(fonts["label"].getlength(t) / SS for t, _ in legend)
    x = LEFT
    for p in panels:
        p.origin = (x, TOP)
        x += p.size[0] + GAP
    plot_bottom = TOP + max(p.size[1] for p in panels)
    width = round(x - GAP + LEGEND_PAD + legend_w + 16)
    height = round(
        max(
            plot_bottom + BOTTOM + (16 if any(p.left_out for p in panels) else 0), TOP + 24 * len(legend) + 20
        )
    )
    img = Image.new("RGB", (width * SS, height * SS), PAPER)
    draw = ImageDraw.Draw(img)
    for p in panels:
        _draw_panel(img, draw, p, fonts, colours, by_name, failed)
    _draw_legend(draw, legend, colours, fonts, ((x - GAP + LEGEND_PAD) * SS, (TOP + 4) * SS))
    img = img.reduce(SS)
    out.parent.mkdir(parents=True, exist_ok=True)
    img.save(out, optimize=True)
    return out


def _draw_legend(
    draw: Any,
    legend: list[tuple[str, str]],
    colours: dict[str, RGB],
    fonts: dict[str, Any],
    at: tuple[float, float],
) -> None:
    """The legend, right of the plots, from its top-left corner `at` (drawing pixels)."""
    lx, ly = at
    for text, kind in legend:
        cy = ly + 8 * SS
        sw = (lx, cy, lx + 28 * SS, cy)
        ink = INK
        if kind == "robot":
            ink = rgb255(colours[text])
            draw.line([sw[:2], sw[2:]], fill=ink, width=4 * SS)
        elif kind in ("start", "end"):
            c = (lx + 14 * SS, cy)
            r = 5 * SS
            box = [c[0] - r, c[1] - r, c[0] + r, c[1] + r]
            draw.ellipse(box, fill=INK if kind == "end" else PAPER, outline=INK, width=2 * SS)
        elif kind in ("solid", "loose"):
            draw.rectangle(
                [lx + 4 * SS, cy - 6 * SS, lx + 24 * SS, cy + 6 * SS],
                fill=SOLID if kind == "solid" else LOOSE,
                outline=SOLID_EDGE,
                width=SS,
            )
        elif kind == "actor":
            _dashed(draw, [(lx + 2 * SS, cy), (lx + 26 * SS, cy)], ACTOR_INK, 2 * SS)
        elif kind in ("region", "failed"):
            edge = REGION if kind == "region" else FAILED
            corners = [(lx + 2 * SS, cy - 6 * SS), (lx + 26 * SS, cy - 6 * SS), (lx + 26 * SS, cy + 6 * SS)]
            corners += [(lx + 2 * SS, cy + 6 * SS), (lx + 2 * SS, cy - 6 * SS)]
            _dashed(draw, corners, edge, 2 * SS)
            ink = FAILED if kind == "failed" else INK
        elif kind == "cross":
            _cross(draw, lx + 14 * SS, cy)
        draw.text((lx + 38 * SS, cy), text, fill=ink, font=fonts["label"], anchor="lm")
        ly += 24 * SS


def _draw_panel(
    img: Any,
    draw: Any,
    p: _Panel,
    fonts: dict[str, Any],
    colours: dict[str, RGB],
    by_name: dict[str, Result],
    failed: set[str],
) -> None:
    (x0, y0), (w, h) = p.origin, p.size
    frame = [x0 * SS, y0 * SS, (x0 + w) * SS, (y0 + h) * SS]
    draw.rectangle(frame, fill=FIELD)
    _draw_axes(img, draw, p, fonts, frame)
    _draw_world(draw, p)
    _draw_regions(draw, p, fonts["small"], failed)
    _draw_paths(draw, p, colours)
    # where pose assertions failed: the robot's place at that time; a collision: where the bodies touched
    for s in p.specs:
        r = by_name.get(s.name)
        if r is None or r.status != "fail" or r.t_ns is None:
            continue
        touched = _TOUCHED.search(r.value) if s.type == "no_collision" else None
        if touched is not None:
            _cross(draw, *p.px(float(touched[1]), float(touched[2])))
        if s.type not in POSE_KINDS:
            continue
        path = p.paths.get(s.robot)
        if path is not None and len(path):
            row = path[int(np.argmin(np.abs(path[:, 0] - r.t_ns)))]
            _cross(draw, *p.px(float(row[1]), float(row[2])))
    draw.rectangle(frame, outline=AXIS, width=SS)


def _draw_axes(img: Any, draw: Any, p: _Panel, fonts: dict[str, Any], frame: list[float]) -> None:
    """The grid and ticks on both axes, the axes' labels, the panel's title, and what was left out."""
    from PIL import Image, ImageDraw

    (x0, y0), (w, h) = p.origin, p.size
    step = _nice_step(float(max(p.hi - p.lo)))
    small = fonts["small"]
    for axis in (0, 1):
        first = math.ceil(p.lo[axis] / step - 1e-9)
        for i in itertools.count(first):
            v = i * step
            if v > p.hi[axis] + 1e-9:
                break
            label = _tick_label(v)
            if axis == 0:
                u, _ = p.px(v, 0)
                draw.line([(u, frame[1]), (u, frame[3])], fill=GRID, width=SS)
                draw.line([(u, frame[3]), (u, frame[3] + 5 * SS)], fill=AXIS, width=SS)
                draw.text((u, frame[3] + 7 * SS), label, fill=INK, font=small, anchor="mt")
            else:
                _, vv = p.px(0, v)
                draw.line([(frame[0], vv), (frame[2], vv)], fill=GRID, width=SS)
                draw.line([(frame[0] - 5 * SS, vv), (frame[0], vv)], fill=AXIS, width=SS)
                draw.text((frame[0] - 8 * SS, vv), label, fill=INK, font=small, anchor="rm")
    label = fonts["label"]
    draw.text(((x0 + w / 2) * SS, frame[3] + 26 * SS), "x [m]", fill=INK, font=label, anchor="mt")
    ylab = Image.new("RGB", (round(label.getlength("y [m]")) + 4 * SS, 18 * SS), PAPER)
    ImageDraw.Draw(ylab).text((2 * SS, 9 * SS), "y [m]", fill=INK, font=label, anchor="lm")
    ylab = ylab.rotate(90, expand=True)
    img.paste(ylab, (round((x0 - 58) * SS), round((y0 + h / 2) * SS - ylab.height / 2)))
    draw.text((x0 * SS, (y0 - 10) * SS), p.title, fill=INK, font=fonts["title"], anchor="ls")
    if p.left_out:
        note = (
            "left out, far beyond the robots: "
            + ", ".join(p.left_out[:4])
            + (" ..." if len(p.left_out) > 4 else "")
        )
        draw.text((x0 * SS, frame[3] + 46 * SS), note, fill=AXIS, font=small, anchor="lt")


def _draw_world(draw: Any, p: _Panel) -> None:
    """The world's models: fixed ones solid, those that can move paler (where they start)."""
    for f in sorted(p.shapes, key=lambda f: f.moving):
        for poly in f.polygons:
            pts = [p.px(float(x), float(y)) for x, y in poly]
            fill, edge = (LOOSE, SOLID_EDGE) if f.moving else (SOLID, SOLID_EDGE)
            if len(f.polygons) > 1:  # a mesh's faces: no edges between them
                draw.polygon(pts, fill=fill)
            else:
                draw.polygon(pts, fill=fill, outline=edge, width=SS)


def _draw_regions(draw: Any, p: _Panel, small: Any, failed: set[str]) -> None:
    """The assertions' regions (circles, boxes) and goals (a point and its tolerance), dashed, named; red
    for a failed assertion."""
    for s in p.specs:
        edge = FAILED if s.name in failed else REGION
        region = getattr(s, "region", None)
        corner = None
        if region is not None and region.center is not None:
            c = p.px(*region.center)
            r = float(region.radius or 0.0) * p.scale * SS
            _dashed(draw, _circle_pts(c, r), edge, 2 * SS)
            corner = (c[0] - r * 0.71, c[1] - r * 0.71)
        elif region is not None and region.min is not None:
            (ax, ay), (bx, by) = p.px(*region.min), p.px(*region.max)
            _dashed(draw, [(ax, ay), (bx, ay), (bx, by), (ax, by), (ax, ay)], edge, 2 * SS)
            corner = (ax, by)
        if getattr(s, "point", None) is not None:
            c = p.px(*s.point)
            r = float(getattr(s, "tolerance", 0.1) or 0.1) * p.scale * SS
            _dashed(draw, _circle_pts(c, r), edge, 2 * SS)
            k = 5 * SS
            draw.line([(c[0] - k, c[1]), (c[0] + k, c[1])], fill=edge, width=2 * SS)
            draw.line([(c[0], c[1] - k), (c[0], c[1] + k)], fill=edge, width=2 * SS)
            corner = (c[0] + r * 0.71, c[1] - r * 0.71)
        if corner is not None:
            anchor = "lb"
            draw.text((corner[0] + 3 * SS, corner[1] - 2 * SS), s.name, fill=edge, font=small, anchor=anchor)


def _draw_paths(draw: Any, p: _Panel, colours: dict[str, RGB]) -> None:
    """Each actor's path, dashed grey, and each robot's path in its colour: start (open circle), end
    (filled)."""
    for path in p.actors.values():
        pts = [p.px(x, y) for _t, x, y in path]
        if len(pts) > 1:
            _dashed(draw, pts, ACTOR_INK, 2 * SS)
        u, v = pts[-1]
        r = 4 * SS
        draw.ellipse([u - r, v - r, u + r, v + r], fill=ACTOR_INK)
    for name, path in p.paths.items():
        ink = rgb255(colours[name])
        pts = [p.px(x, y) for _t, x, y in path]
        if len(pts) > 1:
            draw.line(pts, fill=ink, width=3 * SS, joint="curve")
        r = 5 * SS
        for (u, v), filled in ((pts[0], False), (pts[-1], True)):
            draw.ellipse(
                [u - r, v - r, u + r, v + r], fill=ink if filled else PAPER, outline=ink, width=2 * SS
            )
