"""An SDF `<mesh>`: found, checked and converted as a URDF's meshes are (`runner.compile.meshes`), scaled,
added to the spec once per file and scale; a static collision mesh far from convex is split into convex
pieces (`runner.compile.decompose`), as MuJoCo collides a mesh as its convex hull."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
from lxml import etree

from runner.compile.decompose import cached_decomposition, decompose_file
from runner.compile.meshes import MeshError, budget_hint, mesh_budget, prepare_mesh
from runner.compile.sdf.parts import Src
from runner.compile.sdf.reader import Reader

# A static collision mesh is split into convex pieces when its hull is this many times its volume (and
# larger by this much), unless that takes more pieces than this (a curved, detailed mesh: its hull then;
# a thousand slabs already cost a run half its speed). Measured: a slab floor (aws warehouse GroundB) 1.0,
# ordinary rounded or slightly concave shapes stay under 2; the same warehouse's four walls in one mesh
# (WallB) 38.
_NONCONVEX_RATIO = 3.0
_NONCONVEX_MIN_EXCESS = 1e-3
_MAX_PIECES = 1000


def _near_match(looked: list[Path]) -> Path | None:
    """A file whose name differs only in letter case from one of the paths looked at (Gazebo, like the file
    system, does not take it: a description written on a case-insensitive file system)."""
    for path in looked:
        try:
            folder = path.parent
            if not folder.is_dir():
                continue
            for candidate in folder.iterdir():
                if candidate.name.lower() == path.name.lower() and candidate.name != path.name:
                    return candidate
        except OSError:
            continue
    return None


def _hull_and_volume(path: Path, scale: tuple[float, ...]) -> tuple[float, float] | None:
    """The volume of the convex hull MuJoCo makes of a mesh file, and the mesh's own (enclosed) volume;
    None when MuJoCo cannot build it (the world's compile says why)."""
    spec = mujoco.MjSpec()
    spec.add_mesh(name="m", file=str(path), scale=list(scale))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="m")
    try:
        m = spec.compile()
    except Exception:  # MuJoCo raises ValueError or its own errors; the world's compile reports them
        return None
    adr = int(m.mesh_graphadr[0])
    if adr < 0:
        return None
    v = m.mesh_vert[m.mesh_vertadr[0] : m.mesh_vertadr[0] + m.mesh_vertnum[0]].astype(float)
    faces = m.mesh_face[m.mesh_faceadr[0] : m.mesh_faceadr[0] + m.mesh_facenum[0]]
    # mesh_graph: numvert, numface, vert_edgeadr[nv], vert_globalid[nv], edge_localid[nv + 3 nf],
    # face_globalid[3 nf] (indexes into the mesh's vertices).
    nv, nf = int(m.mesh_graph[adr]), int(m.mesh_graph[adr + 1])
    start = adr + 2 + 3 * nv + 3 * nf
    hull_faces = m.mesh_graph[start : start + 3 * nf].reshape(-1, 3)
    return abs(_signed_volume(v, hull_faces)), abs(_signed_volume(v, faces))


def _signed_volume(v: np.ndarray, faces: np.ndarray) -> float:
    a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


@dataclass
class _MeshUse:
    """One `<mesh>` being read: its URI and `<uri>` element (where messages point), whether a visual or a
    collision uses it, and the geom it belongs to (`what`, for messages)."""

    uri: str
    at: etree._Element
    src: Src
    visual: bool
    what: str


class MeshReader(Reader):
    """Adds the meshes of `<mesh>` shapes, and the convex pieces of non-convex static ones."""

    def mesh(
        self,
        s: etree._Element,
        src: Src,
        *,
        visual: bool,
        what: str,
        convex_check: bool,
        scaled: tuple[float, float, float] = (1.0, 1.0, 1.0),
    ) -> str | None:
        """The MuJoCo mesh of a <mesh> (None: left out). A visual's mesh that is missing or unreadable is
        a notice (the visual is left out, as Gazebo goes on); a collision's is an error, collected so that
        one run lists them all. `what` names the geom in messages."""
        uri_el = self.need(s, "uri", src)
        uri = (uri_el.text or "").strip()
        scale_el = s.find("scale")
        scale = self.floats(scale_el, src, 3) if scale_el is not None else (1.0, 1.0, 1.0)
        scale = tuple(a * b for a, b in zip(scale, scaled, strict=True))
        if s.find("submesh") is not None:
            self.note("<submesh> is not supported; the whole mesh is used", src, s.find("submesh"))
        if any(abs(x) < 1e-12 for x in scale):
            # Gazebo loads a mesh flattened to nothing and goes on; MuJoCo refuses it
            self.note(
                f"mesh {uri!r} is scaled by {' '.join(f'{x:g}' for x in scale)}: it has no volume and is "
                f"left out ({what}), as it touches and shows nothing in Gazebo",
                src,
                scale_el if scale_el is not None else uri_el,
                hint="give every axis a non-zero scale",
            )
            return None
        found = self.mesh_file(_MeshUse(uri, uri_el, src, visual, what))
        if found is None:
            return None
        path, original, flat = found
        key = (str(path.resolve()), tuple(scale))
        if convex_check:
            self.last_pieces = self.pieces_of(Path(key[0]), scale, uri, what, src, uri_el, flat=flat)
        if key in self.meshes:
            return self.meshes[key]
        # named after the user's file (a converted mesh's cache file is named by a hash), so that MuJoCo's
        # messages name something the user knows
        name = self.unique("mesh", f"sdf/{original.stem}")
        mesh = self.spec.add_mesh(name=name, file=key[0], scale=list(scale))
        if flat:
            # no volume (a floor or a sticker as a single sheet): MuJoCo refuses a volume inertia; a
            # shell's it takes (static world meshes weigh nothing anyway)
            mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
        self.meshes[key] = name
        return name

    def mesh_file(self, use: _MeshUse) -> tuple[Path, Path, bool] | None:
        """(the file MuJoCo is to read, the user's file, whether the mesh is flat) for a mesh's URI; None
        when it is left out (not found, or unreadable: said by `mesh_failed`)."""
        path, looked, hint = self.find_file(use.uri, use.src, "mesh")
        if path is None or not path.is_file():
            where = f"looked at {', '.join(str(p) for p in looked)}" if looked else hint
            near = _near_match(looked)
            if near is not None:
                hint = f"{near} differs only in letter case: file names are case-sensitive, fix the <uri>"
            if use.visual:
                self.mesh_failed(use, f"mesh {use.uri!r} not found ({where})", hint)
            else:  # Gazebo logs an error and loads the model without this collision: so do we, warned
                self.note(
                    f"collision mesh {use.uri!r} not found ({where}); the collision is left out ({use.what})",
                    use.src,
                    use.at,
                    hint=hint,
                )
            return None
        original = path
        flat = False
        try:  # the same checks and conversions as a URDF's meshes (runner.compile.meshes)
            prepared = prepare_mesh(path)
            path, flat = prepared.file, prepared.flat
            if prepared.simplified:
                self.note(
                    f"mesh {use.uri!r} has {prepared.simplified} triangles, over the budget of "
                    f"{mesh_budget()}: simplified to {prepared.triangles} for MuJoCo (vertex clustering: its "
                    "shape to within a grid cell, its details lost)",
                    use.src,
                    use.at,
                    hint=budget_hint(prepared.simplified)
                    + " (SCENARIO_MAX_MESH_TRIANGLES raises the budget)",
                )
        except MeshError as e:
            # a format that cannot be converted may have an STL or OBJ export beside it
            alt = next(
                (
                    path.with_suffix(x)
                    for x in (".stl", ".STL", ".obj", ".OBJ")
                    if path.with_suffix(x).is_file()
                ),
                None,
            )
            if not e.converting or alt is None:
                self.mesh_failed(
                    use,
                    f"mesh {use.uri!r}: {e.reason}",
                    e.hint
                    or "convert it to STL or OBJ (e.g. with Blender or trimesh) and point the <uri> at it",
                )
                return None
            self.note(f"{e}; using {alt.name} instead", use.src, use.at)
            path = alt
        return path, original, flat

    def mesh_failed(self, use: _MeshUse, message: str, hint: str) -> None:
        """A visual's mesh that cannot be used is a notice; a collision's an error, collected."""
        if use.visual:
            self.note(f"{message}; the visual is left out", use.src, use.at, hint=hint)
        else:
            self.missing.append(self.error(f"{message} ({use.what})", use.src, use.at, hint=hint))

    def pieces_of(
        self,
        path: Path,
        scale: tuple[float, ...],
        uri: str,
        what: str,
        src: Src,
        at: etree._Element,
        *,
        flat: bool = False,
    ) -> list[str] | None:
        """The MuJoCo meshes of a static collision mesh's convex pieces, None when it is convex (MuJoCo
        collides a mesh as its convex hull: a building's walls in one mesh would be a solid block). Said
        once per mesh, with how many pieces and how long they took (`runner.compile.decompose`)."""
        key = (str(path), tuple(scale))
        if key in self.decomposed:
            return self.decomposed[key]
        self.decomposed[key] = None
        # pieces in the cache were made for a mesh that passed the test below: it need not be made again
        found = cached_decomposition(path, scale)
        if found is None:
            stats = None if flat else _hull_and_volume(path, scale)
            if stats is None and not flat:
                return None
            if stats is not None:
                hull, volume = stats
                if hull - volume < _NONCONVEX_MIN_EXCESS or hull < _NONCONVEX_RATIO * volume:
                    return None  # near enough to convex: its hull, as MuJoCo takes a mesh (cheap, smooth)
            found = decompose_file(path, scale)
        # a flat mesh (a floor as one sheet) has no hull MuJoCo can make: it always collides as its pieces
        if found is None or (len(found.pieces) <= 1 and not flat) or not found.pieces:
            return None
        if len(found.pieces) > _MAX_PIECES:
            self.note(
                f"collision mesh {uri!r} ({what}) is far from convex, and too curved to split "
                f"({len(found.pieces)} pieces, more than {_MAX_PIECES}): it collides as its convex hull",
                src,
                at,
                hint="give the model primitive collision shapes, or a simpler collision mesh",
            )
            return None
        names = []
        for k, points in enumerate(found.pieces):
            name = self.unique("mesh", f"sdf/{Path(uri).stem}/piece{k}")
            self.spec.add_mesh(name=name, uservert=points.ravel().tolist())
            names.append(name)
        self.decomposed[key] = names
        how = "from the cache" if found.cached else "decomposed"
        self.note(
            f"collision mesh {uri!r} ({what}) is not convex: it collides as {len(names)} convex pieces "
            f"({found.triangles} triangles, {how} in {found.seconds:.2f} s); rays still hit its own faces",
            src,
            at,
        )
        return names
