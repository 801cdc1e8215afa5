"""A static collision mesh that is not convex, as convex pieces MuJoCo can collide with.

MuJoCo collides a mesh as its convex hull: a building whose walls are one mesh would be a solid block. Gazebo
collides the real triangles. For static meshes (walls, buildings, terrain pieces) we split the mesh into
pieces that together have the mesh's surface:

1. vertices closer than a micrometre are merged, degenerate triangles dropped;
2. each connected part that is closed and convex (a box, a pillar: most of an architectural mesh) is one
   piece, exactly;
3. any other part is cut into planar patches (edge-connected triangles in one plane); a patch that is convex
   (its area is its outline's) is one piece, any other triangle is one piece on its own; each is given a
   thickness of `THICKNESS` behind its face (into the solid when the part is closed and so has an inside,
   half on each side when it is open), so that the colliding surface is the mesh's own.

The original mesh stays in the world for rays (lidars, sonars) to hit its real faces; the pieces collide and
are seen by nothing. Pieces are cached under the mesh cache, keyed by the mesh's bytes, its scale and this
module's `VERSION`, so a world loads them again in a fraction of a second.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from runner.compile.meshes import mesh_cache

VERSION = 3  # of the algorithm: part of the cache key
THICKNESS = 0.02  # metres behind each face of an open or non-convex part
_MERGE = 1e-6  # vertices closer than this are one
_PLANE_ANGLE = 1e-4  # normals this close (1 - cos) are one plane ...
_PLANE_OFFSET = 1e-4  # ... when their offsets are this close (metres)
_CONVEX_EPS = 1e-6  # how far outside a face's plane a vertex of a convex part may be (relative to its size)
_MAX_CONVEX_CHECK = 4_000_000  # faces x vertices above which a part is not tested for convexity
_FLAT = 1e-4  # a piece thinner than this (relative to its size) is a sheet: it gets a thickness


@dataclass
class Decomposition:
    pieces: list[np.ndarray]  # each an (n, 3) point set; its convex hull is the piece
    triangles: int
    seconds: float
    cached: bool


def _cache_file(path: Path, scale: tuple[float, ...]) -> Path:
    digest = hashlib.sha256()
    digest.update(path.read_bytes())
    digest.update(repr((tuple(float(s) for s in scale), VERSION, THICKNESS)).encode())
    return mesh_cache() / "pieces" / f"{digest.hexdigest()[:32]}.npz"


def cached_decomposition(path: Path, scale: tuple[float, ...]) -> Decomposition | None:
    """The pieces `decompose_file` made of this mesh before, from the cache; None if there are none."""
    return _load(_cache_file(path, scale), time.perf_counter())


def _load(cached: Path, t0: float) -> Decomposition | None:
    if not cached.is_file():
        return None
    try:
        with np.load(cached) as data:
            points, counts, triangles = data["points"], data["counts"], int(data["triangles"])
    except (OSError, ValueError, KeyError):
        return None  # a damaged cache file: made again
    pieces = np.split(points, np.cumsum(counts)[:-1]) if len(counts) else []
    return Decomposition(list(pieces), triangles, time.perf_counter() - t0, True)


def decompose_file(path: Path, scale: tuple[float, ...]) -> Decomposition | None:
    """The pieces of a mesh file as MuJoCo reads it (STL, OBJ: see `runner.compile.meshes`), at `scale`;
    None when MuJoCo cannot read it (the world's compile says why). Cached: see `cached_decomposition`."""
    t0 = time.perf_counter()
    cached = _cache_file(path, scale)
    found = _load(cached, t0)
    if found is not None:
        return found
    mesh = _read(path, scale)
    if mesh is None:
        return None
    vertices, faces = mesh
    pieces = decompose(vertices, faces)
    cached.parent.mkdir(parents=True, exist_ok=True)
    tmp = cached.with_suffix(f".{time.monotonic_ns()}.tmp.npz")
    counts = np.array([len(p) for p in pieces], dtype=np.int64)
    points = np.concatenate(pieces) if pieces else np.zeros((0, 3))
    np.savez(tmp, points=points, counts=counts, triangles=np.array(len(faces)))
    tmp.replace(cached)  # atomic: another run reading the cache never sees half a file
    return Decomposition(pieces, len(faces), time.perf_counter() - t0, False)


def _read(path: Path, scale: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray] | None:
    spec = mujoco.MjSpec()
    mesh = spec.add_mesh(name="m", file=str(path), scale=list(scale))
    # read, not collided nor weighed: a flat mesh (a floor as one sheet) has neither hull nor volume
    mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="m", contype=0, conaffinity=0)
    try:
        m = spec.compile()
    except Exception:  # MuJoCo raises ValueError or its own errors; the world's compile reports them
        return None
    v0, nv = int(m.mesh_vertadr[0]), int(m.mesh_vertnum[0])
    f0, nf = int(m.mesh_faceadr[0]), int(m.mesh_facenum[0])
    # MuJoCo centres a mesh on its centre of mass (geom pos/quat carry it back): undo it here, so that the
    # pieces sit in the mesh file's frame, as the geom that held the mesh does
    pos, quat = m.mesh_pos[0].astype(float), m.mesh_quat[0].astype(float)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, quat)
    v = m.mesh_vert[v0 : v0 + nv].astype(float) @ rot.reshape(3, 3).T + pos
    return v, m.mesh_face[f0 : f0 + nf].astype(np.int64)


# ------------------------------------------------------------------------------------------ geometry
def decompose(vertices: np.ndarray, faces: np.ndarray) -> list[np.ndarray]:
    """Convex pieces (point sets) whose union has the surface of the mesh (see the module's doc)."""
    v, f = _clean(np.asarray(vertices, float), np.asarray(faces, np.int64))
    if len(f) == 0:
        return []
    return [solid for piece in _pieces(v, f) if (solid := _solid(piece)) is not None]


def _solid(points: np.ndarray) -> np.ndarray | None:
    """A piece MuJoCo can hull: at least 4 distinct points, not in one plane. A flat one (a closed part of
    zero thickness, a double-sided sheet) gets `THICKNESS` across its plane; a line or a point is None."""
    keys = np.round(points / _MERGE).astype(np.int64)
    _, first = np.unique(keys, axis=0, return_index=True)
    pts = points[np.sort(first)]
    if len(pts) < 3:
        return None
    _, sv, vt = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)
    size = float(sv[0]) or 1.0
    if len(sv) < 2 or sv[1] <= 1e-9 * size:
        return None  # points on a line
    if len(pts) >= 4 and len(sv) == 3 and sv[2] > _FLAT * size:
        return pts
    normal = vt[2] if len(vt) == 3 else np.cross(vt[0], vt[1])
    return np.concatenate([pts + 0.5 * THICKNESS * normal, pts - 0.5 * THICKNESS * normal])


def _pieces(v: np.ndarray, f: np.ndarray) -> list[np.ndarray]:
    pieces: list[np.ndarray] = []
    for part in _components(f, len(v)):
        pf = f[part]
        closed = _closed(pf)
        if closed and _convex(v, pf):
            pieces.append(v[np.unique(pf)])
            continue
        # an inside to put the slabs in: a closed part whose triangles all wind the same way
        inside = closed and _oriented(pf)
        volume = _signed_volume(v, pf) if inside else 0.0
        inside = inside and volume != 0
        pieces += _patches(v, pf, 1.0 if volume >= 0 else -1.0, inside=inside)
    return pieces


def _clean(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    keys = np.round(v / _MERGE).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    v, f = v[first], inverse.reshape(-1)[f]
    ok = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    f = f[ok]
    area = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    return v, f[area > _MERGE**2]


def _find(parent: np.ndarray, i: int) -> int:
    root = i
    while parent[root] != root:
        root = parent[root]
    while parent[i] != root:
        parent[i], i = root, parent[i]
    return root


def _components(f: np.ndarray, nv: int) -> list[np.ndarray]:
    """Face indices of each part connected through shared vertices."""
    parent = np.arange(nv)
    for a, b, c in f.tolist():
        ra, rb, rc = _find(parent, a), _find(parent, b), _find(parent, c)
        parent[rb] = ra
        parent[_find(parent, rc)] = ra
    roots = np.array([_find(parent, int(a)) for a in f[:, 0]])
    order = np.argsort(roots, kind="stable")
    _, starts = np.unique(roots[order], return_index=True)
    return np.split(order, starts[1:])


def _edges(f: np.ndarray) -> np.ndarray:
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    return np.sort(e, axis=1)


def _closed(f: np.ndarray) -> bool:
    """Every edge shared by exactly two triangles (a watertight part)."""
    _, counts = np.unique(_edges(f), axis=0, return_counts=True)
    return bool(np.all(counts == 2))


def _signed_volume(v: np.ndarray, f: np.ndarray) -> float:
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def _oriented(f: np.ndarray) -> bool:
    """Every triangle winds the same way: no directed edge is used twice."""
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    return len(np.unique(e, axis=0)) == len(e)


def _convex(v: np.ndarray, f: np.ndarray) -> bool:
    """A closed part is convex when all its vertices lie on one side of each of its faces' planes (however
    its triangles wind)."""
    idx = np.unique(f)
    if len(f) * len(idx) > _MAX_CONVEX_CHECK:
        return False
    pts = v[idx]
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    d = np.einsum("ij,ij->i", n, v[f[:, 0]])
    eps = _CONVEX_EPS * (float(np.ptp(pts, axis=0).max()) or 1.0)
    side = pts @ n.T - d  # vertices x faces
    return bool(np.all((side.max(axis=0) <= eps) | (side.min(axis=0) >= -eps)))


def _patches(v: np.ndarray, f: np.ndarray, outward: float, inside: bool) -> list[np.ndarray]:
    """Planar patches of a part, each convex one a slab, every other triangle a slab of its own."""
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    area = np.linalg.norm(n, axis=1) / 2.0
    n = n / (2.0 * area[:, None]) * outward
    d = np.einsum("ij,ij->i", n, v[f[:, 0]])
    plane_keys = np.column_stack([np.round(n / np.sqrt(_PLANE_ANGLE)), np.round(d / _PLANE_OFFSET)]).astype(
        np.int64
    )
    _, plane = np.unique(plane_keys, axis=0, return_inverse=True)
    plane = plane.reshape(-1)
    pieces: list[np.ndarray] = []
    for p in np.unique(plane):
        tris = np.nonzero(plane == p)[0]
        normal = n[tris[0]]
        for patch in _edge_connected(f[tris]):
            faces = f[tris[patch]]
            for region in _convex_regions(v, faces, normal, area[tris[patch]]):
                pieces.append(_slab(v[np.unique(faces[region])], normal, inside))
    return pieces


def _plane_coords(points: np.ndarray, normal: np.ndarray) -> np.ndarray:
    u = np.cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)
    return np.column_stack([points @ u, points @ w])


def _convex_regions(
    v: np.ndarray, faces: np.ndarray, normal: np.ndarray, area: np.ndarray
) -> list[list[int]]:
    """A planar patch cut into convex regions of edge-adjacent triangles, grown greedily: a triangle joins
    a region when the region's outline stays convex (the outline's area is the triangles' area)."""
    if len(faces) == 1:
        return [[0]]
    flat = _plane_coords(v, normal)  # 2-D coordinates of every vertex (only the patch's are used)
    whole = _hull(flat[np.unique(faces)])
    if _polygon_area(whole) <= area.sum() * 1.001:
        return [list(range(len(faces)))]  # convex as it is
    e = _edges(faces)
    owner = np.tile(np.arange(len(faces)), 3)
    order = np.lexsort((e[:, 1], e[:, 0]))
    e, owner = e[order], owner[order]
    same = np.all(e[1:] == e[:-1], axis=1)
    neighbours: list[list[int]] = [[] for _ in faces]
    for a, b in zip(owner[:-1][same].tolist(), owner[1:][same].tolist(), strict=True):
        neighbours[a].append(b)
        neighbours[b].append(a)
    taken = np.zeros(len(faces), dtype=bool)
    regions: list[list[int]] = []
    for seed in range(len(faces)):
        if taken[seed]:
            continue
        taken[seed] = True
        region, outline, total = [seed], _hull(flat[faces[seed]]), float(area[seed])
        queue = list(neighbours[seed])
        while queue:
            t = queue.pop()
            if taken[t]:
                continue
            grown = _hull(np.concatenate([outline, flat[faces[t]]]))
            if _polygon_area(grown) <= (total + area[t]) * 1.001 + 1e-12:
                taken[t] = True
                region.append(t)
                outline, total = grown, total + float(area[t])
                queue += neighbours[t]
        regions.append(region)
    return regions


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex outline of 2-D points (Andrew's monotone chain), counter-clockwise."""
    pts = sorted(set(map(tuple, np.round(points, 9).tolist())))
    if len(pts) < 3:
        return np.array(pts, dtype=float).reshape(-1, 2)

    def cross(o: tuple[float, ...], a: tuple[float, ...], b: tuple[float, ...]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, ...]] = []
    upper: list[tuple[float, ...]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1], dtype=float)


def _polygon_area(poly: np.ndarray) -> float:
    if len(poly) < 3:
        return 0.0
    x, y = poly[:, 0], poly[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2.0)


def _edge_connected(f: np.ndarray) -> list[np.ndarray]:
    """Groups of triangles (indices into f) connected through shared edges."""
    nf = len(f)
    if nf == 1:
        return [np.array([0])]
    e = _edges(f)
    owner = np.tile(np.arange(nf), 3)
    order = np.lexsort((e[:, 1], e[:, 0]))
    e, owner = e[order], owner[order]
    same = np.all(e[1:] == e[:-1], axis=1)
    parent = np.arange(nf)
    for a, b in zip(owner[:-1][same].tolist(), owner[1:][same].tolist(), strict=True):
        parent[_find(parent, b)] = _find(parent, a)
    roots = np.array([_find(parent, i) for i in range(nf)])
    order = np.argsort(roots, kind="stable")
    _, starts = np.unique(roots[order], return_index=True)
    return np.split(order, starts[1:])


def _slab(points: np.ndarray, normal: np.ndarray, inside: bool) -> np.ndarray:
    """The face's points and their copies `THICKNESS` behind it (or half in front, half behind)."""
    if inside:
        return np.concatenate([points, points - THICKNESS * normal])
    return np.concatenate([points + 0.5 * THICKNESS * normal, points - 0.5 * THICKNESS * normal])
