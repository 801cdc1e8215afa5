"""Meshes MuJoCo cannot read (Collada, PLY, ...) converted to binary STL with trimesh, cached by content."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

MUJOCO_MESH_FORMATS = {".stl", ".obj", ".msh"}


class MeshError(Exception):
    pass


def mesh_cache() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "scenario-runner" / "meshes"


def convert_mesh(path: Path) -> Path:
    """A file MuJoCo reads with the same geometry as `path`: `path` itself, or a cached STL conversion."""
    if path.suffix.lower() in MUJOCO_MESH_FORMATS:
        return path
    data = path.read_bytes()
    out = mesh_cache() / f"{hashlib.sha256(data).hexdigest()[:20]}.stl"
    if out.is_file():
        return out
    try:
        import trimesh

        loaded = trimesh.load(path, force="mesh")
        if loaded.is_empty:
            raise ValueError("no triangles")
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = out.with_suffix(f".{os.getpid()}.tmp")
        loaded.export(tmp, file_type="stl")
        tmp.replace(out)
    except Exception as e:
        raise MeshError(
            f"mesh {path.name}: cannot convert {path.suffix} to a format MuJoCo reads "
            f"({type(e).__name__}: {e})"
        ) from None
    return out
