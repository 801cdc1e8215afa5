"""What the pictures of a run share: each robot's colour, the world seen from above, and what is near
enough to the robots to be framed.

Three pictures show a run's robots: the trajectory plot (`runner.tools.plot`), the report's signal plots
(`runner.tools.html`) and `scenario render` (`runner.tools.replay`). Each robot has one colour in all three:
its own, as MuJoCo renders it (the colour of the largest part of the first body of the robot that has a
sizeable one: its base link), unless that colour says nothing (grey, black, white: a URDF without a
material renders grey) or is the colour an earlier robot already has (two robots from one xacro file);
then a colour of a fixed palette, taken by the robot's place in the scenario. A colour too light to read
on white paper (yellow) is darkened, its hue kept. `run_colours` decides, for all of them.
"""

from __future__ import annotations

import colorsys
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np

RGB = tuple[float, float, float]

# Saturated colours that read on white paper and on MuJoCo's grey floor, far enough from one another.
PALETTE: tuple[RGB, ...] = (
    (0.15, 0.42, 0.82),  # blue
    (0.90, 0.45, 0.05),  # orange
    (0.16, 0.60, 0.22),  # green
    (0.55, 0.30, 0.75),  # violet
    (0.85, 0.15, 0.45),  # crimson pink
    (0.05, 0.60, 0.62),  # teal
    (0.60, 0.40, 0.15),  # brown
    (0.66, 0.60, 0.05),  # mustard
)
_CLOSE = 0.35  # two colours nearer than this (RGB, 0..1 each) are too alike to tell two robots apart
NEUTRAL: RGB = (0.27, 0.27, 0.27)  # what belongs to no robot (a topic of the run itself)


def _vivid(c: RGB) -> bool:
    """A colour that says something: not grey, black or white."""
    _h, s, v = colorsys.rgb_to_hsv(*c)
    return s >= 0.3 and v >= 0.25


MAX_LUMA = 0.6  # a lighter colour is darkened to this (its hue kept): a yellow line is lost on white paper


def _readable(c: RGB) -> RGB:
    luma = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    if luma <= MAX_LUMA:
        return c
    k = MAX_LUMA / luma
    return (c[0] * k, c[1] * k, c[2] * k)


def _close(a: RGB, b: RGB) -> bool:
    return math.dist(a, b) < _CLOSE


def assign_colours(own: Sequence[tuple[str, RGB | None]]) -> dict[str, RGB]:
    """One colour per robot, in the scenario's order: (name, its own colour or None) -> name -> colour.
    A robot keeps its own colour (darkened if too light) when it is vivid and no earlier robot's; otherwise
    it takes the first palette colour, from its own place in the scenario on, that is not near a colour
    already taken."""
    taken: dict[str, RGB] = {}
    for i, (name, colour) in enumerate(own):
        colour = None if colour is None else _readable(colour)
        if colour is None or not _vivid(colour) or any(_close(colour, t) for t in taken.values()):
            turn = [PALETTE[(i + k) % len(PALETTE)] for k in range(len(PALETTE))]
            colour = next((p for p in turn if not any(_close(p, t) for t in taken.values())), turn[0])
        taken[name] = colour
    return taken


def robot_bodies(m: mujoco.MjModel, names: Iterable[str] | None = None) -> list[tuple[str, int]]:
    """(robot name, root body) of each robot: the world's top bodies named `<robot>/...`; with the
    scenario's robot names known, only theirs (an SDF world's models are named `<model>/...` too)."""
    wanted = None if names is None else set(names)
    out = []
    for b in range(1, m.nbody):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) or ""
        if int(m.body_parentid[b]) == 0 and "/" in name:
            robot = name.split("/", 1)[0]
            if wanted is None or robot in wanted:
                out.append((robot, b))
    return out


def rendered_rgba(m: mujoco.MjModel, d: mujoco.MjData | None = None) -> dict[int, np.ndarray]:
    """geom id -> the RGBA MuJoCo draws it with (material or geom colour, MuJoCo's own rule), for every
    geom its default view shows (collision-only groups are not drawn)."""
    d = d if d is not None else mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    scene = mujoco.MjvScene(m, maxgeom=max(1000, 2 * m.ngeom))
    mujoco.mjv_updateScene(
        m, d, mujoco.MjvOption(), None, mujoco.MjvCamera(), int(mujoco.mjtCatBit.mjCAT_ALL), scene
    )
    out: dict[int, np.ndarray] = {}
    for i in range(scene.ngeom):
        g = scene.geoms[i]
        if int(g.objtype) == int(mujoco.mjtObj.mjOBJ_GEOM) and g.objid >= 0:
            out[int(g.objid)] = np.array(g.rgba, dtype=float)
    return out


def own_colour(m: mujoco.MjModel, root: int, drawn: dict[int, np.ndarray]) -> RGB | None:
    """The colour a robot is seen in: that of the largest drawn geom of its first body (root first, then
    its children, breadth first) that has a sizeable one (a quarter of the robot's largest part at least:
    not a base_footprint's millimetre marker); None if nothing of it is drawn."""
    children: dict[int, list[int]] = {}
    for b in range(1, m.nbody):
        children.setdefault(int(m.body_parentid[b]), []).append(b)
    order, queue = [], [root]
    while queue:
        body = queue.pop(0)
        order.append(body)
        queue += children.get(body, [])
    seen = [g for g in drawn if int(m.geom_bodyid[g]) in set(order) and drawn[g][3] > 0.05]
    if not seen:
        return None
    sizeable = 0.25 * max(float(m.geom_rbound[g]) for g in seen)
    for body in order:
        geoms = [g for g in seen if int(m.geom_bodyid[g]) == body and float(m.geom_rbound[g]) >= sizeable]
        if geoms:
            big = max(geoms, key=lambda g: float(m.geom_rbound[g]))
            r, gr, b = (float(v) for v in drawn[big][:3])
            return (r, gr, b)
    return None


def run_colours(plan: Any, models: dict[str, mujoco.MjModel] | None = None) -> dict[str, RGB]:
    """Each robot of a compiled run (a RunPlan, every world of it) -> its colour in every picture.
    `models`: world name (a plan part's `name`) -> its compiled model, where the caller has it already."""
    own: list[tuple[str, RGB | None]] = []
    for part in plan.parts():
        names = [r.name for r in part.robots]
        m = (models or {}).get(part.name)
        if m is None:
            try:
                m = mujoco.MjModel.from_xml_string(part.mjcf)
            except Exception:  # a model that no longer compiles (moved meshes): palette colours
                own += [(n, None) for n in names]
                continue
        drawn = rendered_rgba(m)
        roots = dict(robot_bodies(m, names))
        own += [(n, own_colour(m, roots[n], drawn) if n in roots else None) for n in names]
    return assign_colours(own)


def model_colours(m: mujoco.MjModel, names: Iterable[str] | None = None) -> dict[str, RGB]:
    """Without a plan (an older recording): the robots of one model, in their order in it."""
    drawn = rendered_rgba(m)
    return assign_colours([(n, own_colour(m, b, drawn)) for n, b in robot_bodies(m, names)])


def rgb255(c: RGB) -> tuple[int, int, int]:
    return (round(c[0] * 255), round(c[1] * 255), round(c[2] * 255))


def hex_colour(c: RGB) -> str:
    return "#{:02x}{:02x}{:02x}".format(*rgb255(c))


# What a picture of the world frames: everything within this many metres of what moves (robots and the
# bodies that move), or within this many times what moves spans, whichever is larger; farther models are
# left out (a world model posed hundreds of kilometres away would shrink the rest to nothing).
FRAME_REACH_M = 100.0
FRAME_REACH_SPANS = 20.0


def reach(subject: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre and radius of what is near enough to `subject` (points, one a row) to be framed with it."""
    lo, hi = subject.min(axis=0), subject.max(axis=0)
    return (lo + hi) / 2, max(FRAME_REACH_M, FRAME_REACH_SPANS * float(np.max(hi - lo)))


def model_of(m: mujoco.MjModel, g: int) -> str:
    """The name of the model a geom belongs to: a scenario's world model is a geom of the world body; an
    SDF model or a robot, bodies `<name>/...`."""
    root = int(m.body_rootid[int(m.geom_bodyid[g])])
    return (m.body(root).name if root else m.geom(g).name or "a world geom").split("/")[0]


@dataclass
class Footprint:
    """What a model's geom covers, seen from above: polygons (x, y, one a row) in metres."""

    model: str
    polygons: list[np.ndarray] = field(default_factory=list)
    moving: bool = False  # a body that can move (drawn where it starts)

    def points(self) -> np.ndarray:
        return np.vstack(self.polygons)


def convex_hull(points: np.ndarray) -> np.ndarray:
    """The convex hull of 2-D points, counter-clockwise (Andrew's monotone chain)."""
    pts = sorted({(round(float(x), 6), round(float(y), 6)) for x, y in points})
    if len(pts) < 3:
        return np.array(pts, dtype=float).reshape(-1, 2)

    def turn(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in seq:
            while len(out) >= 2 and turn(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1], dtype=float)


def _ring(n: int = 32) -> np.ndarray:
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.stack([np.cos(a), np.sin(a)], axis=1)


# geoms lower than this (their top, in metres) are the floor, not something on it
FLOOR_TOP_M = 0.02


def _geom_outline(m: mujoco.MjModel, d: mujoco.MjData, g: int) -> tuple[list[np.ndarray], float] | None:
    """A geom's outline from above (polygons) and its top (z); None for what has none (planes, height
    fields)."""
    t = int(m.geom_type[g])
    size = m.geom_size[g]
    pos, rot = d.geom_xpos[g], d.geom_xmat[g].reshape(3, 3)
    G = mujoco.mjtGeom

    def world(local: np.ndarray) -> np.ndarray:
        return pos + local @ rot.T

    if t == G.mjGEOM_BOX:
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * size
        pts = world(corners)
        return [convex_hull(pts[:, :2])], float(pts[:, 2].max())
    if t == G.mjGEOM_SPHERE:
        r = float(size[0])
        return [pos[:2] + r * _ring(48)], float(pos[2] + r)
    if t in (G.mjGEOM_CYLINDER, G.mjGEOM_CAPSULE):
        r, h = float(size[0]), float(size[1])
        ends = world(np.array([[0, 0, -h], [0, 0, h]]))
        if t == G.mjGEOM_CAPSULE:  # two spheres and what joins them: two discs from above
            pts = np.vstack([e[:2] + r * _ring(48) for e in ends])
            return [convex_hull(pts)], float(ends[:, 2].max() + r)
        rim = np.hstack([r * _ring(48), np.zeros((48, 1))])
        pts = np.vstack([world(rim + np.array([0.0, 0.0, z])) for z in (-h, h)])
        return [convex_hull(pts[:, :2])], float(pts[:, 2].max())
    if t == G.mjGEOM_ELLIPSOID:
        lat = np.linspace(-np.pi / 2, np.pi / 2, 9)
        pts = np.vstack([np.hstack([np.cos(a) * _ring(24), np.full((24, 1), np.sin(a))]) * size for a in lat])
        w = world(pts)
        return [convex_hull(w[:, :2])], float(w[:, 2].max())
    if t == G.mjGEOM_MESH:
        mesh = int(m.geom_dataid[g])
        if mesh < 0:
            return None
        va, vn = int(m.mesh_vertadr[mesh]), int(m.mesh_vertnum[mesh])
        fa, fn = int(m.mesh_faceadr[mesh]), int(m.mesh_facenum[mesh])
        verts = world(np.asarray(m.mesh_vert[va : va + vn], dtype=float))
        faces = np.asarray(m.mesh_face[fa : fa + fn])
        flat = verts[:, :2]
        tris = [flat[f] for f in faces]
        # a closed mesh's faces cover its outline; the ones seen edge-on add nothing
        tris = [t3 for t3 in tris if abs(np.cross(t3[1] - t3[0], t3[2] - t3[0])) > 1e-10]
        return (tris or [convex_hull(flat)]), float(verts[:, 2].max())
    return None


def footprints(
    m: mujoco.MjModel, d: mujoco.MjData | None = None, skip_roots: Iterable[int] = ()
) -> list[Footprint]:
    """The world from above: each drawn geom of every model but the robots (their root bodies in
    `skip_roots`) and the floor, posed as in `d` (by default, where the model starts)."""
    if d is None:
        d = mujoco.MjData(m)
        mujoco.mj_kinematics(m, d)
    skip = set(skip_roots)
    drawn = rendered_rgba(m, d)
    out: list[Footprint] = []
    for g in sorted(drawn):
        root = int(m.body_rootid[int(m.geom_bodyid[g])])
        if root in skip or drawn[g][3] < 0.05:
            continue
        outline = _geom_outline(m, d, g)
        if outline is None or outline[1] < FLOOR_TOP_M:
            continue
        out.append(Footprint(model_of(m, g), outline[0], moving=int(m.body_jntnum[root]) > 0))
    return out


def free_camera_axes(azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MuJoCo's free camera: (forward, up, right) for an azimuth and elevation in degrees."""
    a, e = math.radians(azimuth), math.radians(elevation)
    forward = np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])
    up = np.array([-math.sin(e) * math.cos(a), -math.sin(e) * math.sin(a), math.cos(e)])
    return forward, up, np.cross(forward, up)


def fit_camera(
    points: np.ndarray,
    *,
    azimuth: float,
    elevation: float,
    fovy: float,
    aspect: float,
    margin: float = 0.05,
) -> tuple[np.ndarray, float]:
    """Where a free camera looks and how far it stands so that every point (one a row) is in the picture
    with `margin` (a fraction of the half-frame) to spare, and the points fill it: (lookat, distance)."""
    forward, up, right = free_camera_axes(azimuth, elevation)
    tan_v = math.tan(math.radians(fovy) / 2) * (1 - margin)
    tan_h = tan_v * aspect
    lookat = (points.min(axis=0) + points.max(axis=0)) / 2

    def distance(at: np.ndarray) -> float:
        rel = points - at
        depth = rel @ forward
        need = np.maximum(np.abs(rel @ right) / tan_h, np.abs(rel @ up) / tan_v) - depth
        return max(float(need.max()), 1e-3)

    for _ in range(30):  # centre the points in the frame: move the lookat across the view
        dist = distance(lookat)
        rel = points - lookat
        z = rel @ forward + dist
        u, v = (rel @ right) / (z * tan_h), (rel @ up) / (z * tan_v)
        du, dv = (u.max() + u.min()) / 2, (v.max() + v.min()) / 2
        if abs(du) < 1e-4 and abs(dv) < 1e-4:
            break
        lookat = lookat + 0.5 * (
            du * float(np.median(z)) * tan_h * right + dv * float(np.median(z)) * tan_v * up
        )
    return lookat, distance(lookat)


def project(
    points: np.ndarray,
    *,
    lookat: np.ndarray,
    distance: float,
    azimuth: float,
    elevation: float,
    fovy: float,
    width: int,
    height: int,
) -> np.ndarray:
    """Pixel (column, row) of each point in a free camera's picture."""
    forward, up, right = free_camera_axes(azimuth, elevation)
    rel = points - (np.asarray(lookat) - distance * forward)
    z = rel @ forward
    tan_v = math.tan(math.radians(fovy) / 2)
    u = (rel @ right) / (z * tan_v * width / height)
    v = (rel @ up) / (z * tan_v)
    return np.stack([(u + 1) / 2 * width, (1 - v) / 2 * height], axis=1)
