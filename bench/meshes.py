"""Static non-convex collision meshes (runner.compile.decompose): a building of 3 x 3 rooms whose walls and
doorways are one mesh, subdivided to the triangle counts asked for, and a bumpy open terrain (no two
triangles in one plane: the worst case, a piece per triangle). For each: the decomposition the first time
and from the cache, the pieces, and MuJoCo's compile of the pieces against its compile of the mesh alone
(the limit: what loading the mesh costs without decomposing it)."""

from __future__ import annotations

import os
import struct
import tempfile
import time
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from runner.compile.decompose import decompose_file


def _stl(path: Path, v: np.ndarray, f: np.ndarray) -> Path:
    tri = v[f].astype("<f4")
    with path.open("wb") as out:
        out.write(b"\0" * 80 + struct.pack("<I", len(f)))
        for t in tri:
            out.write(b"\0" * 12 + t.tobytes() + b"\0\0")
    return path


def _box(lo: tuple[float, ...], hi: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    v = np.array(
        [[(lo, hi)[x][0], (lo, hi)[y][1], (lo, hi)[z][2]] for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    )
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return v.astype(float), np.array(f)


def _subdivide(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each triangle into four (midpoints shared through a dictionary of edges)."""
    verts = [tuple(x) for x in v]
    mid: dict[tuple[int, int], int] = {}

    def m(a: int, b: int) -> int:
        key = (min(a, b), max(a, b))
        if key not in mid:
            mid[key] = len(verts)
            verts.append(tuple((np.array(verts[a]) + np.array(verts[b])) / 2))
        return mid[key]

    out = []
    for a, b, c in f.tolist():
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return np.array(verts), np.array(out)


def building(min_triangles: int) -> tuple[np.ndarray, np.ndarray]:
    parts = []
    for i in range(4):
        c = -6 + 4 * i
        for j in range(3):
            y0 = -6 + 4 * j
            parts += [
                ((c - 0.05, y0, 0), (c + 0.05, y0 + 1.5, 2.5)),
                ((c - 0.05, y0 + 2.5, 0), (c + 0.05, y0 + 4, 2.5)),
            ]
            parts += [
                ((y0, c - 0.05, 0), (y0 + 1.5, c + 0.05, 2.5)),
                ((y0 + 2.5, c - 0.05, 0), (y0 + 4, c + 0.05, 2.5)),
            ]
    vs, fs, n = [], [], 0
    for lo, hi in parts:
        v, f = _box(lo, hi)
        vs.append(v)
        fs.append(f + n)
        n += len(v)
    v, f = np.concatenate(vs), np.concatenate(fs)
    while len(f) < min_triangles:
        v, f = _subdivide(v, f)
    return v, f


def terrain(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, y = np.meshgrid(np.linspace(-8, 8, n + 1), np.linspace(-8, 8, n + 1))
    z = 0.3 * np.sin(1.3 * x) * np.cos(0.7 * y)
    v = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    f = np.concatenate([np.column_stack([a, a + 1, a + n + 2]), np.column_stack([a, a + n + 2, a + n + 1])])
    return v, f


def _compile(meshes: list[dict[str, Any]]) -> float:
    spec = mujoco.MjSpec()
    for k, kw in enumerate(meshes):
        spec.add_mesh(name=f"m{k}", **kw)
        spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"m{k}")
    t0 = time.perf_counter()
    spec.compile()
    return time.perf_counter() - t0


def run(quick: bool) -> dict[str, Any]:
    rows = []
    cases = [("building", building(12_000 if quick else 50_000))]
    if not quick:
        cases.append(("terrain (worst case)", terrain(40)))
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["XDG_CACHE_HOME"] = str(Path(tmp) / "cache")  # a cold cache, ours only
        for name, (v, f) in cases:
            path = _stl(Path(tmp) / f"{name.split()[0]}.stl", v, f)
            first = decompose_file(path, (1, 1, 1))
            again = decompose_file(path, (1, 1, 1))
            assert first is not None and again is not None and again.cached
            mesh_alone = _compile([{"file": str(path)}])
            pieces = _compile([{"uservert": p.ravel().tolist()} for p in first.pieces])
            rows.append(
                {
                    "mesh": name,
                    "triangles": first.triangles,
                    "pieces": len(first.pieces),
                    "first_s": round(first.seconds, 3),
                    "cached_s": round(again.seconds, 4),
                    "compile_mesh_s": round(mesh_alone, 3),
                    "compile_pieces_s": round(pieces, 3),
                    "ready_first_s": round(first.seconds + pieces, 3),
                    "ready_cached_s": round(again.seconds + pieces, 3),
                }
            )
    return {"rows": rows}
