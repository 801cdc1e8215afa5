"""A URDF `<mesh>`'s file: its URI (`package://`, `model://`, `file://`, relative) resolved and the file
prepared for MuJoCo (runner.compile.meshes); a mesh that cannot be had is an error in a `<collision>` and
a warning in a `<visual>`, which is then left out (runner.compile.urdf says why)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from runner.compile.meshes import MeshError, PreparedMesh, budget_hint, mesh_budget, prepare_mesh
from runner.compile.packages import PackageMap, resolve_uri
from runner.compile.urdf.checks import DescriptionError
from runner.errors import Notices


class _NoMesh(Exception):
    """Why a <mesh> cannot be used, and a hint."""

    def __init__(self, message: str, hint: str | None):
        super().__init__(message)
        self.hint = hint


# A mesh whose bounding box (scaled) holds less than this (m^3) has no volume MuJoCo can weigh (it needs
# 1e-15): a 10 um part, or a unit mistake.
_TINY_VOLUME = 1e-12


def rewrite_mesh(
    mesh: Any, packages: PackageMap, base_dir: Path, where: Any, notices: Notices, shell: set[str]
) -> None:
    """Point `mesh` at a file MuJoCo reads. What cannot be had is an error in a <collision>, a warning
    in a <visual>, which is then left out (the module's docstring says why)."""
    role_el = mesh.getparent().getparent()  # <visual> or <collision>
    visual = role_el is not None and role_el.tag == "visual"
    uri = mesh.get("filename", "")
    location = where(mesh)  # before the filename is rewritten: xacro sources are searched for it
    try:
        prepared = _find_mesh(uri, packages, base_dir)
    except _NoMesh as e:
        if not visual:
            raise DescriptionError(str(e), *location, hint=e.hint) from None
        notices.add(f"visual {e}; the visual is left out", *location, hint=e.hint)
        link = role_el.getparent()
        if link is not None:
            link.remove(role_el)
        return
    if prepared.simplified:
        notices.add(
            f"{'visual' if visual else 'collision'} mesh {uri!r} has {prepared.simplified} triangles, over "
            f"the budget of {mesh_budget()}: simplified to {prepared.triangles} for MuJoCo (vertex "
            "clustering: "
            "its shape to within a grid cell, its details lost)",
            *location,
            hint=budget_hint(prepared.simplified),
        )
    scale = _scale(mesh)
    flat = prepared.flat or 0.0 in scale
    if flat and not visual:
        raise DescriptionError(
            f"collision mesh {uri!r} is flat (all its vertices lie in one plane): MuJoCo collides with a "
            "mesh's convex hull, which needs a volume",
            *location,
            hint="give this <collision> a thin <box> instead (Gazebo takes flat meshes, MuJoCo does not)",
        )
    volume = math.prod(abs(x * k) for x, k in zip(prepared.extent, scale, strict=True))
    if flat or (prepared.triangles and volume < _TINY_VOLUME):
        shell.add(str(prepared.file))
    mesh.set("filename", str(prepared.file))


def _find_mesh(uri: str, packages: PackageMap, base_dir: Path) -> PreparedMesh:
    path = resolve_uri(uri, packages, base_dir)
    if path is None:
        pkg = uri.split("/")[2] if "://" in uri else uri
        raise _NoMesh(
            f"mesh {uri!r}: package {pkg!r} not found",
            "add it under `packages:` in the scenario; searched: " + ", ".join(packages.searched()),
        )
    if not path.is_file():
        raise _NoMesh(
            f"mesh {uri!r} not found (looked at {path})",
            "check the file name and its case; package:// paths are relative to the package folder",
        )
    try:
        return prepare_mesh(path.resolve())
    except MeshError as e:
        raise _NoMesh(f"mesh {uri!r}: {e.reason}", e.hint or "export it as binary STL or OBJ") from None


def _scale(mesh: Any) -> tuple[float, float, float]:
    """The <mesh scale="x y z">; MuJoCo reports a malformed one."""
    try:
        values = [float(v) for v in (mesh.get("scale") or "1 1 1").split()]
    except ValueError:
        return (1.0, 1.0, 1.0)
    return (values[0], values[1], values[2]) if len(values) == 3 else (1.0, 1.0, 1.0)
