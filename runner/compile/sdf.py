"""SDF (1.4-1.9) or Gazebo classic `.world` file -> bodies, geoms and lights added to a MuJoCo `MjSpec`.

What is read:
- `<world>` (or a bare `<model>`): `<model>`, `<include>`, `<light>`, `<physics>` (`max_step_size`,
  `real_time_factor`, 1.4's `<gravity>`), `<gravity>`;
- `<model>`: `<static>`, `<pose>` (with `relative_to` sibling frames, `<frame>`s), nested `<model>` and
  `<include>` (poses compose), `<link>`, `<joint>` (fixed, revolute, continuous, prismatic, ball);
- `<link>`: `<pose>`, `<inertial>`, `<gravity>`, `<light>`, `<collision>` and `<visual>` with box, cylinder,
  cone (a convex mesh), sphere, capsule, ellipsoid, plane and STL/OBJ mesh geometry, `<material>` colours
  (rgba or the classic `Gazebo/...` script names), `<surface>` friction (`mu`/`mu2`: the smaller), contact
  stiffness (`kp`/`kd`) and collide bitmasks;
- `<include>`: `model://ground_plane` and `model://sun` (and Fuel's OpenRobotics `Ground Plane` and `Sun`)
  are built in; any other `model://NAME` (or Fuel model NAME) is a folder with a `model.config` or a
  `model.sdf` found through the `PackageMap`; `file://`, `package://` and relative paths work too.

Relative paths (`file://models/a.dae`, `meshes/a.stl`) are looked up beside the SDF file, beside the files
that include it, then in the scenario's folder and the package roots; never in the current directory.

The ground: a static horizontal plane at z=0 of the file is the world's ground (the scenario's `ground`
geom takes its friction, collide bitmask and colour where the scenario does not set them), not a second
plane; a second one in the file is left out with a notice.

Names: every body and geom of a model is `<model>/<link>` (nested: `<model>/<sub>/<link>`), geoms
`<model>/<link>/<collision or visual name>`, so they never clash with robots (which live under `<ns>/`).

Anything else is listed once per tag name as a notice (file and line of the first one), never fatal, never
silent; custom elements (`<gz:...>`, whose namespace is seldom declared) are skipped quietly. A visual's
mesh that is missing or unreadable is a notice (the visual is left out); a static collision mesh far from
convex is a notice (MuJoCo collides with its convex hull). Malformed XML, missing required elements and
missing files (included models, collision meshes: all of them, in one error) raise `SdfError` (a
`SourceError`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple
from urllib.parse import unquote

import mujoco
import numpy as np
from lxml import etree

from runner.compile.decompose import cached_decomposition, decompose_file
from runner.compile.materials import gazebo_material
from runner.compile.meshes import MeshError, prepare_mesh
from runner.compile.packages import URI_RE, PackageMap
from runner.compile.urdf import COLLISION_GROUP
from runner.errors import Notices, SourceError
from runner.geometry import rpy_to_quat
from runner.plugin import PIECES_GROUP, RAY_GROUP
from runner.scenario.schema import Ground


class SdfError(SourceError):
    """The SDF/world file itself is wrong, or something it refers to cannot be found. `problems` holds each
    problem (file, line, hint of its own) when one error reports several (every missing model and mesh of
    a world); the message lists them all, with the first one's file and line."""

    def __init__(
        self,
        message: str,
        file: Path | None,
        line: int | None = None,
        hint: str | None = None,
        problems: list[SdfError] | None = None,
    ):
        super().__init__(message, file, line, hint)
        self.problems: list[SdfError] = problems or [self]


@dataclass
class SdfWorld:
    """What the caller must apply after `load_sdf_world` (values are None when the file does not set them)."""

    file: Path
    name: str | None = None  # <world name="...">; None for a bare <model> file
    timestep: float | None = None  # <physics><max_step_size>
    real_time_factor: float | None = None  # <physics><real_time_factor>
    gravity: tuple[float, float, float] | None = None  # <world><gravity> or (1.4) <physics><gravity>
    models: list[str] = field(default_factory=list)  # top-level models added: bodies are `<model>/...`
    free_bodies: list[str] = field(default_factory=list)  # bodies that were given a free joint
    ground: bool = False  # this file added the ground plane (geom `ground`)
    ground_model: str | None = None  # the file's own ground plane (its link) that became the ground geom
    has_ground: bool = False  # the file has a ground plane (model://ground_plane or a plane at z=0)


# ------------------------------------------------------------------------------------------- small maths
class _Pose(NamedTuple):
    p: tuple[float, float, float] = (0.0, 0.0, 0.0)
    q: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)  # w, x, y, z

    def __matmul__(self, other: _Pose) -> _Pose:  # type: ignore[override]
        return _Pose(_add(self.p, _rot(self.q, other.p)), _qmul(self.q, other.q))

    def inv(self) -> _Pose:
        qc = (self.q[0], -self.q[1], -self.q[2], -self.q[3])
        x, y, z = _rot(qc, self.p)
        return _Pose((-x, -y, -z), qc)


_IDENTITY = _Pose()


def _add(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float]:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _qmul(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def _rot(q: tuple[float, ...], v: tuple[float, ...]) -> tuple[float, float, float]:
    w, x, y, z = q
    vx, vy, vz = v
    # v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z)
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return (
        vx + w * tx + (y * tz - z * ty),
        vy + w * ty + (z * tx - x * tz),
        vz + w * tz + (x * ty - y * tx),
    )


def _quat_z_to(n: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """The rotation taking +Z onto the unit vector n."""
    nx, ny, nz = n
    if nz < -1 + 1e-12:
        return (0.0, 1.0, 0.0, 0.0)
    w = 1.0 + nz
    ax, ay = -ny, nx  # z x n
    s = math.sqrt(w * w + ax * ax + ay * ay)
    return (w / s, ax / s, ay / s, 0.0)


def _unit(v: tuple[float, ...]) -> tuple[float, float, float] | None:
    norm = math.sqrt(sum(c * c for c in v))
    if norm < 1e-12:
        return None
    return (v[0] / norm, v[1] / norm, v[2] / norm)


# --------------------------------------------------------------------------------------------- tables
_GREY = (0.7, 0.7, 0.7, 1.0)
_GROUND_RGBA = (0.55, 0.57, 0.6, 1.0)

_PLANE = mujoco.mjtGeom.mjGEOM_PLANE

# Tags read without effect on a MuJoCo model; dropped without a notice.
_QUIET = {
    "allow_auto_disable",
    "cast_shadows",
    "meta",
    "specular",
    "emissive",
    "shininess",
    "lighting",
    "shader",
    "render_order",
    "double_sided",
    "must_be_base_link",
    "visualize",
    "effort",
    "velocity",
    "real_time_update_rate",
}
# Display-only settings: one combined notice.
_GUI = {"gui", "scene"}
# Why a tag is dropped, where there is more to say than "not supported".
_WHY = {
    "plugin": "Gazebo plugins are not run (give robots scenario plugins instead)",
    "sensor": "sensors of world models are not simulated",
    "actor": "actors (animated people) are not simulated",
    "population": "populations are not expanded",
    "audio": "audio is not simulated",
    "audio_source": "audio is not simulated",
    "wind": "wind is not simulated",
    "enable_wind": "wind is not simulated",
    "atmosphere": "the atmosphere model is not simulated",
    "magnetic_field": "the magnetic field is not simulated",
    "spherical_coordinates": "geographic coordinates are not used",
    "road": "roads are not built",
    "ode": "engine-specific physics settings are not used (MuJoCo's solver is)",
    "bullet": "engine-specific physics settings are not used (MuJoCo's solver is)",
    "simbody": "engine-specific physics settings are not used (MuJoCo's solver is)",
    "dart": "engine-specific physics settings are not used (MuJoCo's solver is)",
    "heightmap": "heightmaps are not supported; the geom is left out",
    "polyline": "polyline shapes are not supported; the geom is left out",
    "image": "image shapes are not supported; the geom is left out",
    "self_collide": "MuJoCo lets sibling links of a model collide and skips parent-child pairs",
    "kinematic": "kinematic links are simulated as dynamic",
    "velocity_decay": "velocity decay is not simulated",
    "max_contacts": "MuJoCo sizes its contact buffer itself",
    "laser_retro": "laser retro-reflectivity is not simulated",
    "bounce": "restitution is not simulated",
    "torsional": "torsional friction is not mapped",
    "axis2": "the second axis of universal/revolute2 joints is not supported",
    "placement_frame": "placement frames are not supported; <pose> places the model's own frame",
}

_GEOM_KEYS = {"box", "cylinder", "cone", "sphere", "capsule", "ellipsoid", "plane", "mesh", "empty"}
_CONE_SEGMENTS = 48
_GEOM_SKIPPED = {"heightmap", "polyline", "image"}


@dataclass
class _Src:
    path: Path
    version: tuple[int, int] | None
    chain: tuple[Path, ...] = ()  # the files that included this one, outermost first


@dataclass
class _Link:
    key: str  # scoped name in the top-level model: `link` or `sub::link`
    body: str  # `<model>/<sub>/<link>`
    world: _Pose
    el: etree._Element
    src: _Src
    static: bool
    model_world: _Pose  # pose of the model that holds the link (axes expressed in the model frame)
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)  # the model's scale in the world's <state>


@dataclass
class _Joint:
    name: str
    type: str
    parent: _Link | None  # None: the world
    child: _Link
    world: _Pose
    el: etree._Element
    src: _Src
    model_world: _Pose


@dataclass
class _ModelState:
    """A model in a world's `<state>` (Gazebo classic applies it when it loads the world; worlds saved
    from the GUI keep their true poses there): world poses of the model and its links, its scale."""

    pose: _Pose | None
    scale: tuple[float, float, float] | None
    links: dict[str, _Pose]  # scoped link key (`link`, `sub::link`) -> world pose
    el: etree._Element


@dataclass
class _Collected:
    links: list[_Link] = field(default_factory=list)
    joints: list[_Joint] = field(default_factory=list)


# --------------------------------------------------------------------------------------------- entry
def load_sdf_world(spec: mujoco.MjSpec, path: Path, packages: PackageMap, notices: Notices) -> SdfWorld:
    """Add the world (or the bare model) of the SDF file at `path` to `spec`; see the module docstring."""
    loader = _Loader(spec, packages, notices)
    try:
        return loader.load(Path(path))
    finally:
        loader.flush()


class _Loader:
    def __init__(self, spec: mujoco.MjSpec, packages: PackageMap, notices: Notices):
        self.spec = spec
        self.packages = packages
        self.notices = notices
        self.unknown: dict[str, list] = {}  # tag -> [file, line, count]
        self.gui: dict[str, tuple[Path, int | None]] = {}
        self.no_inertial: list[tuple[str, Path, int | None]] = []
        self.stack: list[Path] = []
        self.timestep = 0.002
        self.names: dict[str, set[str]] = {
            "body": {b.name for b in spec.bodies if b.name},
            "geom": {g.name for g in spec.geoms if g.name},
            "mesh": {m.name for m in spec.meshes if m.name},
            "light": {li.name for li in spec.lights if li.name},
            "joint": {j.name for j in spec.joints if j.name},
        }
        self.meshes: dict[tuple[str, tuple[float, ...]], str] = {}
        # static collision meshes that are not convex: their convex pieces, by (file, scale)
        self.decomposed: dict[tuple[str, tuple[float, ...]], list[str] | None] = {}
        self.last_pieces: list[str] | None = None  # those of the mesh `mesh()` returned last
        # The world's ground so far: the scenario's (`world.ground`), a plane named `ground`; which part of
        # this file is the ground (label, file, line), once one is.
        planes = [g for g in spec.worldbody.geoms if g.type == _PLANE]
        self.ground_geom: mujoco.MjsGeom | None = next((g for g in planes if g.name == "ground"), None)
        if self.ground_geom is None and planes:
            self.ground_geom = planes[0]
        self.ground_owner: tuple[str, Path, int | None] | None = None
        self.ground_link: str | None = None
        self.missing: list[SdfError] = []  # files not found: reported together at the end
        self.result: SdfWorld | None = None
        self.state: dict[str, _ModelState] = {}  # the world's <state>, by top-level model name
        self.deleted: set[str] = set()  # models its <deletions> remove

    # ------------------------------------------------------------------------------------- notices
    def note(
        self,
        message: str,
        src: _Src | Path | None,
        el: etree._Element | None = None,
        hint: str | None = None,
    ) -> None:
        file = src.path if isinstance(src, _Src) else src
        self.notices.add(message, file, el.sourceline if el is not None else None, hint)

    def skip(self, el: etree._Element, src: _Src) -> None:
        tag = el.tag if isinstance(el.tag, str) else str(el.tag)
        if tag in _GUI:
            self.gui.setdefault(tag, (src.path, el.sourceline))
            return
        entry = self.unknown.get(tag)
        if entry is None:
            self.unknown[tag] = [src.path, el.sourceline, 1]
        else:
            entry[2] += 1

    def check(self, el: etree._Element, src: _Src, handled: Iterable[str]) -> None:
        handled = set(handled)
        for ch in el:
            if isinstance(ch.tag, str) and ch.tag not in handled and ch.tag not in _QUIET and not _custom(ch):
                self.skip(ch, src)

    def flush(self) -> None:
        if self.gui:
            file, line = next(iter(self.gui.values()))
            tags = ", ".join(f"<{t}>" for t in self.gui)
            self.notices.add(f"SDF {tags} ignored: display settings only", file, line)
        for tag, (file, line, count) in self.unknown.items():
            why = _WHY.get(tag, "not supported")
            more = f" ({count} times, first here)" if count > 1 else ""
            self.notices.add(f"SDF <{tag}> ignored: {why}{more}", file, line)
        if self.no_inertial:
            body, file, line = self.no_inertial[0]
            n = len(self.no_inertial)
            which = f"link {body!r} has" if n == 1 else f"{n} moving links have (first: {body!r})"
            self.notices.add(
                f"{which} no <inertial>: mass 1 kg and unit inertia assumed, as in Gazebo", file, line
            )
        self.unknown.clear()
        self.gui.clear()
        self.no_inertial.clear()

    def error(
        self, message: str, src: _Src | Path, el: etree._Element | None = None, hint: str | None = None
    ):
        file = src.path if isinstance(src, _Src) else src
        return SdfError(message, file, el.sourceline if el is not None else None, hint)

    # ----------------------------------------------------------------------------------------- parse
    def parse(
        self, path: Path, asked_by: tuple[_Src, etree._Element] | None = None
    ) -> tuple[etree._Element, _Src]:
        path = path.resolve()
        if not path.is_file():
            if asked_by:
                raise self.error(f"SDF file {str(path)!r} not found", asked_by[0], asked_by[1])
            raise SdfError(
                f"SDF file {str(path)!r} not found", path, hint="paths are relative to the scenario"
            )
        try:
            data = _xml_bytes(path)
        except OSError as e:
            raise SdfError(f"cannot read {str(path)!r}: {e.strerror or e}", path) from None
        parser = etree.XMLParser(
            remove_comments=True, remove_pis=True, resolve_entities=False, no_network=True
        )
        try:
            root = etree.fromstring(data, parser, base_url=str(path))
        except etree.XMLSyntaxError as e:
            if "Namespace prefix" not in str(e.msg):
                raise _malformed(e.msg, path, e.lineno) from None
            # An undeclared prefix (`<gz:policies>`, the usual gz-sim extension elements, whose `xmlns:gz`
            # is seldom declared): read the file anyway; prefixed elements are custom elements, which SDF
            # readers skip. Any other error found on the way is still an error.
            parser = etree.XMLParser(
                remove_comments=True, remove_pis=True, resolve_entities=False, no_network=True, recover=True
            )
            root = etree.fromstring(data, parser, base_url=str(path))
            for entry in parser.error_log:
                if entry.type != etree.ErrorTypes.NS_ERR_UNDEFINED_NAMESPACE:
                    raise _malformed(entry.message, path, entry.line) from None
        if root is None or root.tag != "sdf":
            tag = None if root is None else root.tag
            raise SdfError(
                f"the top element is <{tag}>, expected <sdf>",
                path,
                root.sourceline if root is not None else 1,
                hint="an SDF or .world file starts with <sdf version='1.6'>",
            )
        version = None
        text = root.get("version")
        if text:
            m = re.match(r"^\s*(\d+)\.(\d+)", text)
            version = (int(m.group(1)), int(m.group(2))) if m else None
            if version is None or not (1, 0) <= version <= (1, 12):
                self.notices.add(f"SDF version {text!r} is not one this reader knows (1.4-1.9)", path, 1)
        return root, _Src(path, version, tuple(self.stack))

    # ----------------------------------------------------------------------------------------- load
    def load(self, path: Path) -> SdfWorld:
        """Reads the file; files it refers to that are missing are all listed in one error at the end."""
        try:
            result = self.read(path)
        except SdfError as e:
            if self.missing:
                raise _together([*self.missing, e]) from None
            raise
        if self.missing:
            raise _together(self.missing)
        return result

    def read(self, path: Path) -> SdfWorld:
        self.packages.add_package_of(path)  # its package's gazebo_model_path / gazebo_media_path exports
        root, src = self.parse(path)
        self.result = result = SdfWorld(file=src.path)
        self.stack.append(src.path)
        worlds = root.findall("world")
        if worlds:
            if len(worlds) > 1:
                self.note("the file holds several <world>s; only the first is loaded", src, worlds[1])
            self.check(root, src, {"world"})
            self.world(worlds[0], src, result)
        else:
            models = root.findall("model")
            if not models:
                raise self.error(
                    "the file has neither a <world> nor a <model>",
                    src,
                    root,
                    hint="write <sdf version='1.6'><world name='default'>...</world></sdf>",
                )
            self.check(root, src, {"model", "light"})
            for el in root:
                if el.tag == "model":
                    self.top_model(el, src, _IDENTITY, name=None, pose=None, static=None)
                elif el.tag == "light":
                    self.light(el, src, self.spec.worldbody, _IDENTITY, "")
        self.stack.pop()
        result.has_ground = self.ground_owner is not None
        return result

    def world(self, w: etree._Element, src: _Src, result: SdfWorld) -> None:
        result.name = w.get("name")
        self.check(w, src, {"model", "include", "light", "physics", "gravity", "state"})
        states = w.findall("state")
        for extra in states[1:]:
            self.note("only the first <state> is applied", src, extra)
        insertions: list[etree._Element] = []
        if states:
            insertions = self.read_state(states[0], src)
        physics = w.findall("physics")
        if physics:
            chosen = next((p for p in physics if _bool(p.get("default"))), physics[0])
            for p in physics:
                if p is not chosen:
                    self.note("only one <physics> is used (the default one, else the first)", src, p)
            self.physics(chosen, src, result)
        g = w.find("gravity")
        if g is not None:
            result.gravity = self.floats(g, src, 3)  # type: ignore[assignment]
        for el in w:
            if el.tag == "model":
                self.top_model(el, src, _IDENTITY, name=None, pose=None, static=None)
            elif el.tag == "include":
                self.include(el, src, _IDENTITY, [], False, None, top=True)
            elif el.tag == "light":
                self.light(el, src, self.spec.worldbody, _IDENTITY, "")
        for el in insertions:
            self.top_model(el, src, _IDENTITY, name=None, pose=None, static=None)
        unused = [n for n in self.state if n not in result.models]
        if unused:
            self.note(
                f"<state> names model(s) the world does not have: {', '.join(unused[:5])}"
                + (" ..." if len(unused) > 5 else ""),
                src,
                self.state[unused[0]].el,
            )

    def read_state(self, st: etree._Element, src: _Src) -> list[etree._Element]:
        """Reads a world's `<state>` (its models' and links' world poses, model scales, deletions) into
        `self.state`; returns the models its `<insertions>` add. Times, velocities, accelerations, wrenches
        and joint angles are not applied (the world starts at rest, as Gazebo's reset does)."""
        for el in st:
            if el.tag == "model" and el.get("name"):
                self.state[el.get("name")] = self.model_state(el, src, "")
            elif el.tag == "deletions":
                self.deleted |= {(n.text or "").strip() for n in el.findall("name")}
        ins = st.find("insertions")
        return ins.findall("model") if ins is not None else []

    def model_state(self, el: etree._Element, src: _Src, scope: str) -> _ModelState:
        pose_el = el.find("pose")
        scale_el = el.find("scale")
        scale = self.floats(scale_el, src, 3) if scale_el is not None else None
        out = _ModelState(
            pose=self.pose(pose_el, src) if pose_el is not None else None,
            scale=scale,  # type: ignore[arg-type]
            links={},
            el=el,
        )
        for ch in el:
            name = ch.get("name")
            if not name:
                continue
            if ch.tag == "link" and ch.find("pose") is not None:
                out.links[scope + name] = self.pose(ch.find("pose"), src)
            elif ch.tag == "model":  # a nested model's links, scoped as the model's links are
                out.links.update(self.model_state(ch, src, f"{scope}{name}::").links)
        return out

    def physics(self, p: etree._Element, src: _Src, result: SdfWorld) -> None:
        self.check(p, src, {"max_step_size", "real_time_factor", "gravity"})
        for tag in ("max_step_size", "real_time_factor"):
            el = p.find(tag)
            if el is not None:
                value = self.floats(el, src, 1)[0]
                if value <= 0:
                    raise self.error(f"<{tag}> must be positive, found {value}", src, el)
                if tag == "max_step_size":
                    result.timestep = self.timestep = value
                else:
                    result.real_time_factor = value
        g = p.find("gravity")
        if g is not None:
            result.gravity = self.floats(g, src, 3)  # type: ignore[assignment]

    # ------------------------------------------------------------------------------------- values
    def floats(self, el: etree._Element, src: _Src, n: int | tuple[int, ...]) -> tuple[float, ...]:
        counts = (n,) if isinstance(n, int) else n
        text = (el.text or "").split()
        try:
            values = tuple(float(t) for t in text)
        except ValueError:
            values = ()
        if len(values) not in counts or not all(math.isfinite(v) for v in values):
            want = " or ".join(str(c) for c in counts)
            raise self.error(
                f"<{el.tag}> needs {want} number(s), found {(el.text or '').strip()!r}",
                src,
                el,
                hint="numbers are separated by spaces, e.g. <size>1 2 0.5</size>",
            )
        return values

    def child_float(self, el: etree._Element, tag: str, src: _Src, default: float | None = None) -> float:
        c = el.find(tag)
        if c is None:
            if default is None:
                raise self.error(f"<{el.tag}> needs a <{tag}>", src, el)
            return default
        return self.floats(c, src, 1)[0]

    def child_bool(self, el: etree._Element, tag: str, src: _Src) -> bool | None:
        c = el.find(tag)
        if c is None:
            return None
        text = (c.text or "").strip().lower()
        if text not in ("true", "false", "1", "0"):
            raise self.error(f"<{tag}> must be true or false, found {text!r}", src, c)
        return text in ("true", "1")

    def pose_of(self, el: etree._Element, src: _Src) -> tuple[_Pose, str | None, etree._Element | None]:
        """The `<pose>` child of `el` as a pose, its `relative_to` (or None) and the element."""
        p = el.find("pose")
        if p is None:
            return _IDENTITY, None, None
        return self.pose(p, src), (p.get("relative_to") or None), p

    def pose(self, p: etree._Element, src: _Src) -> _Pose:
        quat_form = (p.get("rotation_format") or "euler_rpy").strip() == "quat_xyzw"
        v = self.floats(p, src, (7,) if quat_form else (6,))
        if quat_form:
            x, y, z, w = v[3:]
            n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
            return _Pose(v[:3], (w / n, x / n, y / n, z / n))  # type: ignore[arg-type]
        rpy = v[3:]
        if _bool(p.get("degrees")):
            rpy = tuple(math.radians(a) for a in rpy)
        q = rpy_to_quat(list(rpy))
        return _Pose(v[:3], (float(q[0]), float(q[1]), float(q[2]), float(q[3])))  # type: ignore[arg-type]

    def unique(self, kind: str, name: str) -> str:
        used = self.names[kind]
        out, k = name, 2
        while out in used:
            out = f"{name}#{k}"
            k += 1
        used.add(out)
        return out

    # ------------------------------------------------------------------------------------- models
    def top_model(
        self,
        el: etree._Element,
        src: _Src,
        parent: _Pose,
        *,
        name: str | None,
        pose: _Pose | None,
        static: bool | None,
    ) -> None:
        assert self.result is not None
        model_name = name or el.get("name")
        if not model_name:
            raise self.error("a <model> has no name", src, el, hint="write <model name='...'>")
        if model_name in self.result.models or any(
            b.startswith(model_name + "/") for b in self.names["body"]
        ):
            raise self.error(
                f"the model name {model_name!r} is used twice",
                src,
                el,
                hint="model names must be unique in the world (and differ from robot namespaces); "
                "give each <include> its own <name>",
            )
        if model_name in self.deleted:
            self.note(f"model {model_name!r} is removed by the world's <state> <deletions>", src, el)
            return
        state = self.state.get(model_name)
        if pose is None:
            local, rel, pel = self.pose_of(el, src)
            if rel not in (None, "world", "__model__"):
                self.note(
                    f"pose relative_to {rel!r} of model {model_name!r} is taken relative to the world",
                    src,
                    pel,
                )
            pose = local
        if state is not None and state.pose is not None:
            parent, pose = _IDENTITY, state.pose  # the saved pose is in the world frame
        collected = self.model(el, src, parent @ pose, [model_name], False, static, model_name)
        if state is not None:
            self.apply_state(state, collected, model_name, src)
        self.build(collected)
        self.result.models.append(model_name)

    def apply_state(self, state: _ModelState, c: _Collected, model: str, src: _Src) -> None:
        """Links where the world's <state> saved them (as Gazebo sets each link's world pose), and the
        model's saved scale. A model with joints keeps its links where its joints hold them (its saved
        joint angles are not applied), with a notice when the saved poses differ."""
        moved = []
        for link in c.links:
            if state.scale is not None:
                link.scale = state.scale
            saved = state.links.get(link.key)
            if saved is None:
                continue
            off = math.dist(saved.p, link.world.p) + 2 * math.acos(
                min(1.0, abs(sum(a * b for a, b in zip(saved.q, link.world.q, strict=True))))
            )
            if off < 1e-6:
                continue
            if c.joints:
                moved.append(link.key)
            else:
                link.world = saved
        if moved:
            self.note(
                f"model {model!r} has joints: the poses <state> saved for its links ({', '.join(moved[:3])}) "
                "are not applied; its links are placed from the model's saved pose",
                src,
                state.el,
            )

    def model(
        self,
        el: etree._Element,
        src: _Src,
        world: _Pose,
        path: list[str],
        static_parent: bool,
        static_override: bool | None,
        name: str,
    ) -> _Collected:
        """Reads a model (the pose of its frame given) and its nested models: links and joints."""
        self.check(el, src, {"static", "pose", "link", "joint", "model", "include", "frame"})
        own_static = self.child_bool(el, "static", src)
        static = static_override if static_override is not None else bool(own_static) or static_parent
        out = _Collected()

        # Frames that a `relative_to` may name: links, nested models, <frame>s (positions in the model frame).
        entries: dict[str, etree._Element] = {}
        for ch in el:
            if ch.tag in ("link", "model", "frame", "joint"):
                n = ch.get("name")
                if not n:
                    raise self.error(f"a <{ch.tag}> of model {name!r} has no name", src, ch)
                entries.setdefault(n, ch)
        resolved: dict[str, _Pose] = {}
        busy: set[str] = set()

        def frame(ch: etree._Element, default: str | None = None) -> _Pose:
            n = ch.get("name", "")
            if n in resolved and entries.get(n) is ch:
                return resolved[n]
            local, rel, pel = self.pose_of(ch, src)
            if ch.tag == "frame" and rel is None:
                rel = ch.get("attached_to") or None
            elif ch.tag == "joint" and rel is None:
                rel = (ch.findtext("child") or "").strip() or None
            rel = rel or default
            base = _IDENTITY
            if rel and rel != "__model__":
                target = entries.get(rel)
                if target is None or target is ch or rel in busy:
                    self.note(
                        f"pose relative_to {rel!r} in model {name!r} is not a frame of the model; "
                        "taken relative to the model",
                        src,
                        pel if pel is not None else ch,
                    )
                else:
                    busy.add(n)
                    base = frame(target)
                    busy.discard(n)
            pose = base @ local
            if entries.get(n) is ch:
                resolved[n] = pose
            return pose

        links: dict[str, _Link] = {}
        for ch in el:
            if ch.tag == "link":
                lname = ch.get("name")
                assert lname
                link = _Link(
                    key=lname,
                    body="/".join([*path, lname]),
                    world=world @ frame(ch),
                    el=ch,
                    src=src,
                    static=static,
                    model_world=world,
                )
                links[lname] = link
                out.links.append(link)
            elif ch.tag == "model":
                sub = ch.get("name")
                assert sub
                inner = self.model(ch, src, world @ frame(ch), [*path, sub], static, None, sub)
                self.merge(out, inner, sub, links)
            elif ch.tag == "include":
                sub, inner = self.include(
                    ch,
                    src,
                    world,
                    path,
                    static,
                    frame_of=lambda n: frame(entries[n]) if n in entries else None,
                )
                if inner is not None:
                    self.merge(out, inner, sub, links)

        for ch in el.findall("joint"):
            joint = self.joint(ch, src, links, name, world, frame)
            if joint is not None:
                out.joints.append(joint)
        return out

    @staticmethod
    def merge(out: _Collected, inner: _Collected, sub: str, links: dict[str, _Link]) -> None:
        for link in inner.links:
            link.key = f"{sub}::{link.key}"
            links[link.key] = link
            out.links.append(link)
        out.joints.extend(inner.joints)

    def include(
        self,
        el: etree._Element,
        src: _Src,
        parent: _Pose,
        path: list[str],
        static_parent: bool,
        frame_of: Callable[[str], _Pose | None] | None,
        top: bool = False,
    ) -> tuple[str, _Collected | None]:
        self.check(el, src, {"uri", "name", "pose", "static"})
        uri_el = el.find("uri")
        uri = (uri_el.text or "").strip() if uri_el is not None else ""
        if not uri:
            raise self.error(
                "an <include> has no <uri>", src, el, hint="e.g. <uri>model://ground_plane</uri>"
            )
        name_el = el.find("name")
        name = (name_el.text or "").strip() if name_el is not None else None
        static = self.child_bool(el, "static", src)
        pose: _Pose | None = None
        local, rel, pel = self.pose_of(el, src)
        if pel is not None:
            base = _IDENTITY
            if rel and rel not in ("__model__", "world"):
                found = frame_of(rel) if frame_of else None
                if found is None:
                    self.note(f"include pose relative_to {rel!r} is not a known frame; ignored", src, pel)
                else:
                    base = found
            pose = base @ local

        builtin = _builtin(uri)
        if builtin is not None:
            world_pose = parent @ (pose or _IDENTITY)
            if builtin == "sun":
                self.sun(world_pose)
            else:
                self.ground(world_pose, src, el)
            return name or builtin, None

        try:
            file = self.resolve_include(uri, src, uri_el)
        except SdfError as e:  # listed with every other missing file at the end; the model is left out
            self.missing.append(e)
            return name or uri, None
        if file in self.stack:
            raise self.error(f"include {uri!r} includes itself", src, uri_el)
        root, inc_src = self.parse(file, (src, uri_el))
        model = root.find("model")
        if model is None:
            raise self.error(
                f"include {uri!r}: {file} has no <model>",
                src,
                uri_el,
                hint="an <include> names a model (a world cannot be included)",
            )
        self.check(root, inc_src, {"model"})
        self.stack.append(file)
        try:
            model_name = name or model.get("name")
            if not model_name:
                raise self.error("a <model> has no name", inc_src, model)
            if top:
                self.top_model(model, inc_src, parent, name=model_name, pose=pose, static=static)
                return model_name, None
            if pose is None:
                pose = self.pose_of(model, inc_src)[0]
            inner = self.model(
                model, inc_src, parent @ pose, [*path, model_name], static_parent, static, model_name
            )
            return model_name, inner
        finally:
            self.stack.pop()

    def resolve_include(self, uri: str, src: _Src, at: etree._Element) -> Path:
        searched = ", ".join(self.packages.searched()) or "nothing"
        if uri.startswith(("http://", "https://")):
            # A Fuel model (`https://fuel.gazebosim.org/1.0/<owner>/models/<name>[/<version>]`) is used
            # when a folder of that name is found through the package map; nothing is downloaded.
            name = _download_name(uri)
            for candidate in dict.fromkeys([name, name.lower(), name.lower().replace(" ", "_")]):
                root = self.packages.find(candidate) if candidate else None
                if root is not None:
                    target = self.model_file(root, src, at, uri) if root.is_dir() else root
                    return target.resolve()
            raise self.error(
                f"include {uri!r}: models are not downloaded",
                src,
                at,
                hint=f"download the model (`gz fuel download -u '{uri}'`, or from its web page) and make its "
                f"folder (the one that holds model.sdf) known as {name!r}: `packages: {{{name!r}: "
                f"path/to/folder}}` in the scenario, or a folder named {name!r} under the scenario's folder "
                f"or a folder on SCENARIO_PACKAGE_PATH; searched: {searched}",
            )
        if uri.startswith("model://"):
            name, _, rest = uri[len("model://") :].partition("/")
            root = self.packages.find(name)
            if root is None:
                raise self.error(
                    f"model {uri!r} not found",
                    src,
                    at,
                    hint="a model is a folder named after it holding a model.config or a model.sdf; add its "
                    f"parent folder under `packages:` or to SCENARIO_PACKAGE_PATH; searched: {searched}",
                )
            target = root / rest if rest else root
        else:
            found, looked, hint = self.find_file(uri, src, "include")
            if found is None:
                where = "looked at " + ", ".join(str(p) for p in looked) if looked else "not found"
                raise self.error(f"include {uri!r}: {where}", src, at, hint=hint)
            target = found
        if target.is_dir():
            target = self.model_file(target, src, at, uri)
        if not target.is_file():
            raise self.error(
                f"include {uri!r}: {target} does not exist", src, at, hint=f"searched: {searched}"
            )
        return target.resolve()

    def model_file(self, folder: Path, src: _Src, at: etree._Element, uri: str) -> Path:
        config = folder / "model.config"
        if not config.is_file():
            if (folder / "model.sdf").is_file():
                return folder / "model.sdf"
            raise self.error(
                f"include {uri!r}: {folder} holds neither a model.config nor a model.sdf", src, at
            )
        try:
            root = etree.parse(str(config), etree.XMLParser(remove_comments=True, no_network=True)).getroot()
        except etree.XMLSyntaxError as e:
            # a model.config is metadata (names, authors, descriptions with a bare `&`): TinyXML2 takes what
            # lxml refuses, and Gazebo only wants its <sdf> file names. Read what can be read, and say so.
            parser = etree.XMLParser(remove_comments=True, no_network=True, recover=True)
            root = etree.parse(str(config), parser).getroot()
            if root is None:
                raise SdfError(f"not well-formed XML: {e.msg}", config, e.lineno) from None
            self.notices.add(
                f"not well-formed XML ({e.msg}); read leniently, as Gazebo does", config, e.lineno
            )
        best: tuple[tuple[int, ...], str] | None = None
        for s in root.findall("sdf"):
            text = (s.text or "").strip()
            if not text:
                continue
            v = tuple(int(x) for x in re.findall(r"\d+", s.get("version") or "0"))[:2]
            if v > (1, 9):
                continue
            if best is None or v > best[0]:
                best = (v, text)
        return folder / (best[1] if best else "model.sdf")

    # ------------------------------------------------------------------------------------- joints
    def joint(
        self,
        el: etree._Element,
        src: _Src,
        links: dict[str, _Link],
        model: str,
        model_world: _Pose,
        frame: Callable[..., _Pose],
    ) -> _Joint | None:
        jname = el.get("name", "")
        jtype = (el.get("type") or "").strip()
        self.check(el, src, {"parent", "child", "pose", "axis"})
        ends: list[_Link | None] = []
        for tag in ("parent", "child"):
            c = el.find(tag)
            ref = (c.text or "").strip() if c is not None else ""
            if not ref:
                raise self.error(f"joint {jname!r} has no <{tag}>", src, el)
            if ref == "world" and tag == "parent":
                ends.append(None)
                continue
            ref = ref.removeprefix(f"{model}::")
            if ref not in links:
                raise self.error(
                    f"joint {jname!r} names {tag} link {ref!r}, which is not in model {model!r}",
                    src,
                    c,
                    hint="links of the model: " + ", ".join(links),
                )
            ends.append(links[ref])
        parent, child = ends
        assert child is not None
        local, rel, _ = self.pose_of(el, src)
        world = model_world @ frame(el) if rel and rel != child.key else child.world @ local
        return _Joint(jname, jtype, parent, child, world, el, src, model_world)

    def add_joint(self, body: mujoco.MjsBody, j: _Joint) -> None:
        el, src = j.el, j.src
        name = self.unique("joint", "/".join([*j.child.body.split("/")[:-1], j.name]))
        rel = j.child.world.inv() @ j.world
        if j.type == "ball":
            body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_BALL, pos=list(rel.p))
            return
        kind = {
            "revolute": mujoco.mjtJoint.mjJNT_HINGE,
            "continuous": mujoco.mjtJoint.mjJNT_HINGE,
            "prismatic": mujoco.mjtJoint.mjJNT_SLIDE,
        }[j.type]
        axis_el = el.find("axis")
        if axis_el is None:
            raise self.error(
                f"{j.type} joint {j.name!r} has no <axis>", src, el, hint="e.g. <axis><xyz>0 0 1</xyz></axis>"
            )
        self.check(axis_el, src, {"xyz", "limit", "dynamics", "use_parent_model_frame"})
        xyz_el = axis_el.find("xyz")
        if xyz_el is None:
            raise self.error(f"the <axis> of joint {j.name!r} has no <xyz>", src, axis_el)
        axis = _unit(self.floats(xyz_el, src, 3))
        if axis is None:
            raise self.error(f"the axis of joint {j.name!r} is zero", src, xyz_el)
        # Which frame the axis is expressed in: 1.4 the model; 1.5/1.6 the joint unless
        # use_parent_model_frame; 1.7+ `expressed_in`.
        expressed = xyz_el.get("expressed_in")
        in_model = src.version is not None and src.version < (1, 5)
        if self.child_bool(axis_el, "use_parent_model_frame", src):
            in_model = True
        if expressed:
            in_model = expressed == "__model__"
            if expressed not in ("__model__", j.name):
                self.note(f"axis expressed_in {expressed!r} is taken as the joint frame", src, xyz_el)
        world_axis = _rot(j.model_world.q, axis) if in_model else _rot(j.world.q, axis)
        local_axis = _rot(j.child.world.inv().q, world_axis)
        joint = body.add_joint(name=name, type=kind, pos=list(rel.p), axis=list(local_axis))
        limit = axis_el.find("limit")
        if limit is not None and j.type != "continuous":
            self.check(limit, src, {"lower", "upper", "stiffness", "dissipation"})
            lo = self.child_float(limit, "lower", src, -math.inf)
            hi = self.child_float(limit, "upper", src, math.inf)
            if -1e15 < lo < hi < 1e15:
                if kind == mujoco.mjtJoint.mjJNT_HINGE and self.spec.compiler.degree:
                    lo, hi = math.degrees(lo), math.degrees(hi)
                joint.range = [lo, hi]
                joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        dyn = axis_el.find("dynamics")
        if dyn is not None:
            self.check(dyn, src, {"damping", "friction", "spring_reference", "spring_stiffness"})
            joint.damping = [self.child_float(dyn, "damping", src, 0.0), 0.0, 0.0]  # (linear, ...) terms
            joint.frictionloss = self.child_float(dyn, "friction", src, 0.0)
            stiffness = self.child_float(dyn, "spring_stiffness", src, 0.0)
            if stiffness:
                joint.stiffness = [stiffness, 0.0, 0.0]
                joint.springref = self.child_float(dyn, "spring_reference", src, 0.0)

    # ------------------------------------------------------------------------------------- bodies
    def build(self, c: _Collected) -> None:
        assert self.result is not None
        parent_of: dict[int, _Joint] = {}
        for j in c.joints:
            if j.type not in ("fixed", "revolute", "continuous", "prismatic", "ball"):
                self.note(
                    f"joint type {j.type!r} (joint {j.name!r}) is not supported; its links are held fixed",
                    j.src,
                    j.el,
                )
                j.type = "fixed"
            if j.child.static:
                continue  # a static model's links never move: its joints do nothing
            if id(j.child) in parent_of:
                self.note(
                    f"link {j.child.key!r} is the child of two joints; {j.name!r} is ignored", j.src, j.el
                )
                continue
            parent_of[id(j.child)] = j
        made: dict[int, mujoco.MjsBody] = {}
        visiting: set[int] = set()

        def make(link: _Link) -> mujoco.MjsBody:
            if id(link) in made:
                return made[id(link)]
            j = parent_of.get(id(link))
            if j is not None and id(link) in visiting:
                self.note(f"joint {j.name!r} closes a loop; it is ignored", j.src, j.el)
                parent_of.pop(id(link))
                j = None
            visiting.add(id(link))
            if j is None or j.parent is None:
                parent_body, parent_world = self.spec.worldbody, _IDENTITY
            else:
                parent_body, parent_world = make(j.parent), j.parent.world
                if id(link) in made:  # made while resolving a loop
                    return made[id(link)]
            rel = parent_world.inv() @ link.world
            body = parent_body.add_body(
                name=self.unique("body", link.body), pos=list(rel.p), quat=list(rel.q)
            )
            made[id(link)] = body
            if not link.static:
                if j is None:
                    body.add_freejoint(name=self.unique("joint", f"{link.body}/root"))
                    self.result.free_bodies.append(body.name)  # type: ignore[union-attr]
                elif j.type != "fixed":
                    self.add_joint(body, j)
            self.link(body, link)
            return body

        for link in c.links:
            make(link)

    def link(self, body: mujoco.MjsBody, link: _Link) -> None:
        el, src = link.el, link.src
        self.check(el, src, {"pose", "inertial", "collision", "visual", "light", "gravity"})
        mass = 0.0
        if not link.static:
            mass = self.inertial(body, link)
            if self.child_bool(el, "gravity", src) is False:
                body.gravcomp = 1.0
        visuals = [self.geom(link, v, visual=True, rgba=None, mass=mass) for v in el.findall("visual")]
        first_rgba = next((kw["rgba"] for kw in visuals if kw), None)
        collisions = [
            self.geom(link, c, visual=False, rgba=first_rgba or _GREY, mass=mass)
            for c in el.findall("collision")
        ]
        for kw in collisions + visuals:  # collisions first: they keep their plain name if a visual shares it
            if kw is not None:
                kw["name"] = self.unique("geom", f"{link.body}/{kw['name']}")
                pieces = kw.pop("_pieces", None)
                if pieces:
                    # the mesh itself stays for rays (its real faces), touching nothing; its convex pieces
                    # collide, seen by no ray and no camera
                    for k, mesh in enumerate(pieces):
                        piece = {**kw, "meshname": mesh, "group": PIECES_GROUP}
                        piece["name"] = self.unique("geom", f"{kw['name']}/piece{k}")
                        body.add_geom(**piece)
                    kw.update(contype=0, conaffinity=0, group=RAY_GROUP)
                body.add_geom(**kw)
        for li in el.findall("light"):
            self.light(li, src, body, _IDENTITY, link.body + "/")

    def inertial(self, body: mujoco.MjsBody, link: _Link) -> float:
        el, src = link.el, link.src
        inertial = el.find("inertial")
        if inertial is None:
            self.no_inertial.append((link.body, src.path, el.sourceline))
            mass, full, ipose = 1.0, [1.0, 1.0, 1.0, 0.0, 0.0, 0.0], _IDENTITY
        else:
            self.check(inertial, src, {"mass", "inertia", "pose"})
            mass = self.child_float(inertial, "mass", src, 1.0)
            if mass <= 0:
                raise self.error(
                    f"link {link.body!r} has mass {mass}; a moving link needs a positive mass",
                    src,
                    inertial.find("mass"),
                    hint="give it a <mass> or make the model <static>true</static>",
                )
            ipose = self.pose_of(inertial, src)[0]
            i = inertial.find("inertia")
            if i is None:
                full = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
            else:
                self.check(i, src, {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"})
                full = [
                    self.child_float(i, t, src, d)
                    for t, d in (
                        ("ixx", 1.0),
                        ("iyy", 1.0),
                        ("izz", 1.0),
                        ("ixy", 0.0),
                        ("ixz", 0.0),
                        ("iyz", 0.0),
                    )
                ]
        body.mass = mass
        body.ipos = list(ipose.p)
        body.iquat = list(ipose.q)
        body.fullinertia = full
        body.explicitinertial = True
        return mass

    # ------------------------------------------------------------------------------------- geoms
    def geom(
        self,
        link: _Link,
        el: etree._Element,
        *,
        visual: bool,
        rgba: tuple[float, ...] | None,
        mass: float,
    ) -> dict[str, object] | None:
        """The `add_geom` arguments of a <collision> or <visual> (None: left out); `name` is the SDF name."""
        src = link.src
        kind = "visual" if visual else "collision"
        handled = {"pose", "geometry"} | ({"material", "transparency"} if visual else {"surface"})
        self.check(el, src, handled)
        local, rel, pel = self.pose_of(el, src)
        if rel and rel != link.key.split("::")[-1]:
            self.note(f"{kind} pose relative_to {rel!r} is taken relative to its link", src, pel)
        g = el.find("geometry")
        if g is None:
            raise self.error(f"a <{kind}> of link {link.body!r} has no <geometry>", src, el)
        what = f"{kind} {el.get('name') or kind!r} of {link.body!r}"
        self.last_pieces = None
        kw = self.shape(g, src, link, local, visual, what)
        if kw is None:
            return None
        if self.last_pieces and not visual:
            kw["_pieces"] = self.last_pieces
        kw["name"] = el.get("name") or kind
        if visual:
            kw.update(contype=0, conaffinity=0, group=1, rgba=list(self.colour(el, src)))
        else:
            kw.update(group=COLLISION_GROUP, rgba=list(rgba or _GREY))
            self.surface(el.find("surface"), src, kw, link, mass)
        if kw.pop("_ground", False):
            self.take_ground(kw, visual, src, el)
            return None
        kw["pos"] = list(kw.pop("_pose").p)  # type: ignore[attr-defined]
        return kw

    def shape(
        self, g: etree._Element, src: _Src, link: _Link, local: _Pose, visual: bool, what: str
    ) -> dict[str, object] | None:
        shapes = [c for c in g if isinstance(c.tag, str) and not _custom(c)]
        known = [c for c in shapes if c.tag in _GEOM_KEYS]
        for c in shapes:
            if c.tag not in _GEOM_KEYS:
                self.skip(c, src)
        if not known:
            if any(c.tag in _GEOM_SKIPPED for c in shapes):
                return None
            raise self.error(
                "a <geometry> has no shape",
                src,
                g,
                hint="one of: box, cylinder, cone, sphere, capsule, ellipsoid, plane, mesh",
            )
        s = known[0]
        pose = local
        kw: dict[str, object] = {}
        G = mujoco.mjtGeom
        # a model's saved scale (Gazebo scales each shape: box sizes and mesh axes one by one, a cylinder's
        # radius by the larger of x and y and its length by z, a sphere's radius by the largest)
        sx_, sy_, sz_ = link.scale
        sr = max(sx_, sy_)
        if s.tag == "empty":
            return None
        if s.tag == "box":
            x, y, z = self.floats(self.need(s, "size", src), src, 3)
            kw.update(type=G.mjGEOM_BOX, size=[x * sx_ / 2, y * sy_ / 2, z * sz_ / 2])
        elif s.tag in ("cylinder", "capsule"):
            r = self.child_float(s, "radius", src) * sr
            length = self.child_float(s, "length", src) * sz_
            kind = G.mjGEOM_CYLINDER if s.tag == "cylinder" else G.mjGEOM_CAPSULE
            kw.update(type=kind, size=[r, length / 2, 0])
        elif s.tag == "cone":
            r = self.child_float(s, "radius", src) * sr
            length = self.child_float(s, "length", src) * sz_
            if r <= 0 or length <= 0:
                raise self.error(
                    f"a <cone> needs a positive radius and length, found {r} and {length}", src, s
                )
            kw.update(type=G.mjGEOM_MESH, meshname=self.cone_mesh(r, length))
        elif s.tag == "sphere":
            radius = self.child_float(s, "radius", src) * max(link.scale)
            kw.update(type=G.mjGEOM_SPHERE, size=[radius, 0, 0])
        elif s.tag == "ellipsoid":
            radii = self.floats(self.need(s, "radii", src), src, 3)
            kw.update(type=G.mjGEOM_ELLIPSOID, size=[a * b for a, b in zip(radii, link.scale, strict=True)])
        elif s.tag == "plane":
            n_el = s.find("normal")
            normal = _unit(self.floats(n_el, src, 3)) if n_el is not None else (0.0, 0.0, 1.0)
            if normal is None:
                raise self.error("the <normal> of a plane is zero", src, n_el)
            size_el = s.find("size")
            sx, sy = self.floats(size_el, src, 2) if size_el is not None else (1.0, 1.0)
            sx, sy = sx * sx_, sy * sy_
            pose = _Pose(local.p, _qmul(local.q, _quat_z_to(normal)))
            world = link.world @ pose
            up = _rot(world.q, (0.0, 0.0, 1.0))
            if not link.static:
                self.note("a plane on a moving link is a thin box (MuJoCo planes are static)", src, s)
                kw.update(type=G.mjGEOM_BOX, size=[sx / 2, sy / 2, 0.005])
            else:
                if up[2] < 1 - 1e-9:
                    self.note("this plane is not horizontal; MuJoCo planes are infinite", src, s)
                elif abs(world.p[2]) < 1e-6:
                    role = self.ground_role(link, src, s)
                    if role == "drop":
                        return None
                    kw["_ground"] = role == "ground"
                kw.update(type=_PLANE, size=[sx / 2, sy / 2, 0.05])
        elif s.tag == "mesh":
            mesh = self.mesh(
                s, src, visual=visual, what=what, convex_check=link.static and not visual, scaled=link.scale
            )
            if mesh is None:
                return None
            kw.update(type=G.mjGEOM_MESH, meshname=mesh)
        self.check(s, src, {"size", "radius", "length", "radii", "normal", "uri", "scale", "submesh"})
        kw["quat"] = list(pose.q)
        kw["_pose"] = pose
        return kw

    def cone_mesh(self, radius: float, length: float) -> str:
        """A cone as SDF (and gz-sim) draws it: axis +Z, base at -length/2, apex at +length/2. MuJoCo has no
        cone; the mesh is convex, so colliding with its hull is exact."""
        key = ("<cone>", (radius, length))
        if key in self.meshes:
            return self.meshes[key]
        n = _CONE_SEGMENTS
        angles = [2 * math.pi * i / n for i in range(n)]
        verts = [(radius * math.cos(a), radius * math.sin(a), -length / 2) for a in angles]
        verts += [(0.0, 0.0, length / 2), (0.0, 0.0, -length / 2)]  # apex n, base centre n + 1
        faces: list[int] = []
        for i in range(n):
            j = (i + 1) % n
            faces += [i, j, n, j, i, n + 1]  # side (outward, counter-clockwise), base (facing -Z)
        name = self.unique("mesh", f"sdf/cone_{radius:g}x{length:g}")
        self.spec.add_mesh(name=name, uservert=[c for v in verts for c in v], userface=faces)
        self.meshes[key] = name
        return name

    def need(self, el: etree._Element, tag: str, src: _Src) -> etree._Element:
        c = el.find(tag)
        if c is None:
            raise self.error(f"<{el.tag}> needs a <{tag}>", src, el)
        return c

    def mesh(
        self,
        s: etree._Element,
        src: _Src,
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

        def fail(message: str, hint: str) -> None:
            if visual:
                self.note(f"{message}; the visual is left out", src, uri_el, hint=hint)
            else:
                self.missing.append(self.error(f"{message} ({what})", src, uri_el, hint=hint))

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
        path, looked, hint = self.find_file(uri, src, "mesh")
        if path is None or not path.is_file():
            where = f"looked at {', '.join(str(p) for p in looked)}" if looked else hint
            near = _near_match(looked)
            if near is not None:
                hint = f"{near} differs only in letter case: file names are case-sensitive, fix the <uri>"
            if visual:
                fail(f"mesh {uri!r} not found ({where})", hint)
            else:  # Gazebo logs an error and loads the model without this collision: so do we, warned
                self.note(
                    f"collision mesh {uri!r} not found ({where}); the collision is left out ({what})",
                    src,
                    uri_el,
                    hint=hint,
                )
            return None
        original = path
        flat = False
        try:  # the same checks and conversions as a URDF's meshes (runner.compile.meshes)
            prepared = prepare_mesh(path)
            path, flat = prepared.file, prepared.flat
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
                fail(
                    f"mesh {uri!r}: {e.reason}",
                    e.hint
                    or "convert it to STL or OBJ (e.g. with Blender or trimesh) and point the <uri> at it",
                )
                return None
            self.note(f"{e}; using {alt.name} instead", src, uri_el)
            path = alt
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

    def find_file(self, uri: str, src: _Src, kind: str) -> tuple[Path | None, list[Path], str]:
        """Where `uri` points, the places looked at, and a hint for when it is not there.

        `package://` and `model://` go through the package map. A relative path (`file://models/a.dae`,
        `meshes/a.stl`) is looked up beside the SDF file, beside each file that included it, then in the
        scenario's folder and the package roots (SCENARIO_PACKAGE_PATH, GZ_SIM_RESOURCE_PATH...), never
        in the current directory, so that a world loads the same from anywhere."""
        m = URI_RE.match(uri)
        roots = ", ".join(self.packages.searched()) or "nothing"
        if m:
            root = self.packages.find(m.group(2))
            if root is None:
                what = "model" if m.group(1) == "model" else "package"
                return (
                    None,
                    [],
                    f"no {what} named {m.group(2)!r}: a model is a folder named after it holding a "
                    "model.config or a model.sdf, a package a folder with a package.xml; add its parent "
                    "folder under `packages:` or to SCENARIO_PACKAGE_PATH (GZ_SIM_RESOURCE_PATH and "
                    f"GAZEBO_MODEL_PATH are read too); searched: {roots}",
                )
            target = root / m.group(3)
            return (target if target.exists() else None), [target], f"{m.group(2)!r} is {root}"
        if uri.startswith(("http://", "https://")):
            m = _FUEL_FILE.match(unquote(uri))
            if m is None:
                return None, [], "nothing is downloaded: download the file and point the <uri> at it"
            text = m.group("rest")  # a file of a Fuel model: in the downloaded model folder, beside its SDF
        else:
            text = uri[len("file://") :] if uri.startswith("file://") else uri
        rel = Path(text)
        if rel.is_absolute():
            return (rel if rel.exists() else None), [rel], "the path is absolute"
        looked: list[Path] = []
        bases = [src.path.parent, *(f.parent for f in reversed(src.chain)), *self.packages.media]
        for base in [*bases, *self.packages.roots]:
            candidate = Path(base).resolve() / rel
            if candidate in looked:
                continue
            looked.append(candidate)
            if candidate.exists():
                return candidate, looked, ""
        hint = (
            f"a relative {kind} path is looked up beside the SDF file, beside the files that include it, "
            "then in the packages' gazebo_media_path exports, the scenario's folder and the folders on "
            "SCENARIO_PACKAGE_PATH / GZ_SIM_RESOURCE_PATH / GAZEBO_RESOURCE_PATH"
            + ("; inside a model folder, model://<model>/... is the portable form" if kind == "mesh" else "")
        )
        return None, looked, hint

    def pieces_of(
        self,
        path: Path,
        scale: tuple[float, ...],
        uri: str,
        what: str,
        src: _Src,
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

    def colour(self, v: etree._Element, src: _Src) -> tuple[float, ...]:
        rgba: tuple[float, ...] = _GREY
        mat = v.find("material")
        if mat is not None:
            self.check(mat, src, {"diffuse", "ambient", "script", "pbr"})
            for tag in ("diffuse", "ambient"):
                c = mat.find(tag)
                if c is not None:
                    vals = self.floats(c, src, (3, 4))
                    rgba = (*vals, 1.0) if len(vals) == 3 else vals
                    break
            else:
                script = mat.find("script")
                if script is not None:
                    self.check(script, src, {"name", "uri"})
                    name = (script.findtext("name") or "").strip()
                    found = gazebo_material(name)
                    if found is None:
                        self.note(f"material {name!r} is not known; grey is used", src, script)
                    else:
                        rgba = found
        t = v.find("transparency")
        if t is not None:
            alpha = 1.0 - min(max(self.floats(t, src, 1)[0], 0.0), 1.0)
            rgba = (*rgba[:3], rgba[3] * alpha)
        return tuple(min(max(c, 0.0), 1.0) for c in rgba)

    def surface(
        self, s: etree._Element | None, src: _Src, kw: dict[str, object], link: _Link, mass: float
    ) -> None:
        if s is None:
            return
        self.check(s, src, {"friction", "contact", "bounce"})
        bounce = s.find("bounce")
        if bounce is not None:
            self.check(bounce, src, {"restitution_coefficient", "threshold"})
            if self.child_float(bounce, "restitution_coefficient", src, 0.0) > 0:
                self.skip(bounce, src)  # "restitution is not simulated": only when some is asked for
        fr = s.find("friction")
        if fr is not None:
            self.check(fr, src, {"ode"})
            ode = fr.find("ode")
            if ode is not None:
                self.check(ode, src, {"mu", "mu2"})
                mus = [self.child_float(ode, t, src) for t in ("mu", "mu2") if ode.find(t) is not None]
                if mus:
                    # Gazebo takes the smaller of two surfaces' mu, MuJoCo the larger unless one geom has
                    # priority. As for the ground (`take_ground`): a slippery surface (mu under 1, every
                    # surface's default in both) gets the top priority, so what touches it gets its mu, as the
                    # smaller-of-two would give anything grippier; a grippy one (mu 100 is common) keeps 1 and
                    # no priority, so a robot's wheels and casters keep the mu they state (a caster's 0)
                    # instead of dragging at 100.
                    mu = max(min(mus), 0.0)
                    kw["friction"] = [min(mu, 1.0), 0.005, 0.0001]
                    kw["priority"] = 2 if mu < 1.0 else 0
        ct = s.find("contact")
        if ct is None:
            return
        self.check(ct, src, {"ode", "collide_bitmask", "collide_without_contact", "category_bitmask"})
        if self.child_bool(ct, "collide_without_contact", src):
            kw.update(contype=0, conaffinity=0)
        mask_el = ct.find("collide_bitmask")
        if mask_el is not None:
            try:
                mask = int((mask_el.text or "").strip(), 0)
            except ValueError:
                raise self.error("<collide_bitmask> must be an integer such as 0x01", src, mask_el) from None
            kw.update(contype=mask & 0xFFFFFFFF, conaffinity=mask & 0xFFFFFFFF)
        ode = ct.find("ode")
        if ode is None:
            return
        self.check(ode, src, {"kp", "kd"})
        kp_el = ode.find("kp")
        if kp_el is None:
            return
        kp = self.floats(kp_el, src, 1)[0]
        kd = self.child_float(ode, "kd", src, 1.0)
        if link.static or mass <= 0:
            self.note(
                "contact <kp>/<kd> on a static model is not used (its stiffness needs a mass)", src, kp_el
            )
            return
        if kp <= 0:
            return
        # A mass-spring-damper m x'' + kd x' + kp x = 0 has w = sqrt(kp/m) and zeta = kd / (2 sqrt(kp m));
        # MuJoCo's solref (timeconst, dampratio) gives w = 1/(timeconst dampratio), zeta = dampratio.
        w = math.sqrt(kp / mass)
        if w * 2 * self.timestep >= 1:
            return  # stiffer than a step can resolve: MuJoCo's rigid default is the same thing
        zeta = min(max(kd / (2 * math.sqrt(kp * mass)), 0.01), 10.0)
        kw["solref"] = [1.0 / (w * zeta), zeta]
        kw["priority"] = 1

    # ------------------------------------------------------------------------------------- builtins
    def ground(self, pose: _Pose, src: _Src, el: etree._Element) -> None:
        """`model://ground_plane`: the world's ground as it is (the scenario's), or a plain one."""
        assert self.result is not None
        if self.ground_owner is not None:
            self.duplicate_ground(src, el)
            return
        self.ground_owner = ("model://ground_plane", src.path, el.sourceline)
        if self.ground_geom is not None:
            return
        self.ground_geom = self.spec.worldbody.add_geom(
            name=self.unique("geom", "ground"),
            type=_PLANE,
            size=[0, 0, 0.05],
            pos=list(pose.p),
            quat=list(pose.q),
            rgba=list(_GROUND_RGBA),
            friction=[1.0, 0.005, 0.0001],
        )
        self.result.ground = True

    def duplicate_ground(self, src: _Src, el: etree._Element) -> None:
        assert self.ground_owner is not None
        label, file, line = self.ground_owner
        where = f"line {line}" if file == src.path else f"{file}:{line}"
        self.note(
            f"the world file already has a ground plane ({label}, {where}); this plane at z=0 is left out",
            src,
            el,
        )

    def ground_role(self, link: _Link, src: _Src, el: etree._Element) -> str:
        """What a static horizontal plane at z=0 of `link` is: `ground` (the world's ground: its settings go
        onto the ground geom, no second plane is added), `add` (the scenario has no ground: the plane is
        added as it is) or `drop` (the file has a ground already: a notice, the plane is left out). The
        first such link in the file is the ground."""
        if self.ground_owner is None:
            assert self.result is not None
            self.ground_owner = (f"model {link.body.split('/')[0]!r}", src.path, link.el.sourceline)
            self.ground_link = self.result.ground_model = link.body
        elif self.ground_link != link.body:
            self.duplicate_ground(src, el)
            return "drop"
        return "add" if self.ground_geom is None else "ground"

    def take_ground(self, kw: dict[str, object], visual: bool, src: _Src, el: etree._Element) -> None:
        """The world file's own ground plane is the ground: its surface (friction, collide bitmask) and its
        colour go onto the ground geom, unless the scenario's `world.ground` sets them."""
        assert self.ground_geom is not None
        ground = self.ground_geom
        default = Ground()
        if visual:
            if all(abs(a - b) < 1e-6 for a, b in zip(ground.rgba, default.rgba, strict=True)):
                ground.rgba = list(kw["rgba"])  # type: ignore[call-overload]
            return
        friction = kw.get("friction")
        if isinstance(friction, list):
            mu = float(friction[0])
            if abs(ground.friction[0] - default.friction) > 1e-9:
                self.note(
                    f"the ground plane's friction {mu:g} is not used: the scenario's "
                    f"`world.ground.friction` ({ground.friction[0]:g}) is",
                    src,
                    el,
                )
            else:
                # Gazebo takes the smaller mu of two surfaces, MuJoCo the larger unless one geom has
                # priority. A slippery ground (mu under 1, the default of every surface in both) gets the
                # top priority: its mu is what everything on it gets, as Gazebo's smaller-of-two would
                # give anything grippier. A grippy one (Gazebo's ground_plane says mu 100) leaves every
                # other surface its own friction, as the smaller-of-two does: 1 here, no priority, so
                # geoms that state theirs (robot wheels, a caster's 0: priority 1) keep it.
                ground.friction = [min(mu, 1.0), ground.friction[1], ground.friction[2]]
                ground.priority = 2 if mu < 1.0 else 0
        for k in ("contype", "conaffinity"):  # a collide bitmask
            if k in kw:
                setattr(ground, k, kw[k])

    def sun(self, pose: _Pose) -> None:
        direction = _unit(_rot(pose.q, (-0.5, 0.1, -0.9)))
        existing = self.spec.light("sun")
        if existing is not None:
            return  # the world has its sun already
        self.names["light"].add("sun")
        self.spec.worldbody.add_light(
            name="sun",
            type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
            pos=list(_add(pose.p, (0.0, 0.0, 10.0))),
            dir=list(direction or (0.0, 0.0, -1.0)),
            diffuse=[0.8, 0.8, 0.8],
            specular=[0.2, 0.2, 0.2],
            castshadow=True,
        )

    def light(self, el: etree._Element, src: _Src, body: mujoco.MjsBody, parent: _Pose, prefix: str) -> None:
        self.check(
            el,
            src,
            {"pose", "diffuse", "specular", "attenuation", "direction", "spot", "cast_shadows", "intensity"},
        )
        ltype = (el.get("type") or "point").strip()
        types = {
            "directional": mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
            "point": mujoco.mjtLightType.mjLIGHT_POINT,
            "spot": mujoco.mjtLightType.mjLIGHT_SPOT,
        }
        if ltype not in types:
            self.note(f"light type {ltype!r} is not known; the light is left out", src, el)
            return
        pose = parent @ self.pose_of(el, src)[0]
        d_el = el.find("direction")
        direction = _unit(self.floats(d_el, src, 3)) if d_el is not None else (0.0, 0.0, -1.0)
        direction = _rot(pose.q, direction or (0.0, 0.0, -1.0))
        kw: dict[str, object] = {
            "type": types[ltype],
            "pos": list(pose.p),
            "dir": list(direction),
            "castshadow": bool(self.child_bool(el, "cast_shadows", src)),
        }
        for tag in ("diffuse", "specular"):
            c = el.find(tag)
            if c is not None:
                kw[tag] = list(self.floats(c, src, (3, 4))[:3])
        att = el.find("attenuation")
        if att is not None:
            self.check(att, src, {"range", "constant", "linear", "quadratic"})
            kw["attenuation"] = [
                self.child_float(att, "constant", src, 1.0),
                self.child_float(att, "linear", src, 0.0),
                self.child_float(att, "quadratic", src, 0.0),
            ]
            if att.find("range") is not None:
                kw["range"] = self.child_float(att, "range", src)
        spot = el.find("spot")
        if spot is not None and ltype == "spot":
            self.check(spot, src, {"inner_angle", "outer_angle", "falloff"})
            kw["cutoff"] = math.degrees(self.child_float(spot, "outer_angle", src, math.radians(90))) / 2
            kw["exponent"] = self.child_float(spot, "falloff", src, 1.0)
        name = prefix + (el.get("name") or "light")
        existing = self.spec.light(name) if not prefix else None
        if existing is not None and ltype == "directional" and existing.type == types[ltype]:
            for k, v in kw.items():  # the world's own sun: the file's settings win, no second sun
                setattr(existing, k, v)
            return
        body.add_light(name=self.unique("light", name), **kw)


def _bool(text: str | None) -> bool:
    return (text or "").strip().lower() in ("true", "1")


def _malformed(msg: str, path: Path, line: int | None) -> SdfError:
    return SdfError(
        f"not well-formed XML: {msg}",
        path,
        line,
        hint="check that every tag is closed and attribute values are quoted",
    )


_BEFORE_DECLARATION = re.compile(rb"^(?:\xef\xbb\xbf)?((?:\s|<!--.*?-->)+)(<\?xml\b[^>]*\?>)", re.S)


_COMMENT = re.compile(rb"<!--(.*?)-->", re.DOTALL)


def _blank_double_hyphens(comment: re.Match[bytes]) -> bytes:
    inner = comment.group(1).replace(b"--", b"- ")
    if inner.endswith(b"-"):  # `--->` ends a comment with `-`, which XML forbids too
        inner = inner[:-1] + b" "
    return b"<!--" + inner + b"-->"


def _xml_bytes(path: Path) -> bytes:
    """The file's bytes; a comment (or blank lines) before `<?xml ...?>`, which XML forbids and Gazebo
    accepts (gazebo-classic's cafe.world), is dropped, and `--` inside comments is blanked, keeping every
    line number."""
    data = path.read_bytes()
    if b"--" in data:
        # `--` inside a comment: XML forbids it, TinyXML2 (libsdformat) accepts it (gz-sim's levels.sdf)
        data = _COMMENT.sub(_blank_double_hyphens, data)
    m = _BEFORE_DECLARATION.match(data)
    if m:
        declaration = m.group(2)
        newlines = m.group(1).count(b"\n") + declaration.count(b"\n")
        data = declaration.replace(b"\r", b" ").replace(b"\n", b" ") + b"\n" * newlines + data[m.end() :]
    return data


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


def _custom(el: etree._Element) -> bool:
    """A custom element (`<gz:policies>`, `<drake:...>`: a namespace prefix), which SDF readers skip."""
    return isinstance(el.tag, str) and (":" in el.tag or el.tag.startswith("{"))


# A static collision mesh whose convex hull exceeds its volume this many times (and by this much, m³) is
# reported. Measured: a slab floor (aws warehouse GroundB) 1.0, ordinary rounded or slightly concave
# shapes stay under 2; the same warehouse's four walls in one mesh (WallB) 38.


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


# A static collision mesh is split into convex pieces when its hull is this many times its volume (and
# larger by this much), unless that takes more pieces than this (a curved, detailed mesh: its hull then;
# a thousand slabs already cost a run half its speed)
_NONCONVEX_RATIO = 3.0
_NONCONVEX_MIN_EXCESS = 1e-3
_MAX_PIECES = 1000


_FUEL = re.compile(
    r"^https?://fuel\.(?:gazebosim|ignitionrobotics)\.org/(?:1\.0/)?(?P<owner>[^/]+)/models/(?P<name>[^/]+)"
    r"(?:/(?:\d+|tip))?/?$",
    re.IGNORECASE,
)
# A file of a Fuel model (`.../models/<name>/<version>/files/meshes/a.dae`).
_FUEL_FILE = re.compile(
    r"^https?://fuel\.[^/]+/(?:1\.0/)?[^/]+/models/[^/]+/(?:\d+|tip)/files/(?P<rest>[^?#]+)$", re.IGNORECASE
)
# Fuel models that are the built-in ones (model://ground_plane, model://sun), by their names without
# spaces, dashes and underscores, lower case.
_FUEL_BUILTINS = {"groundplane": "ground_plane", "sun": "sun"}


def _builtin(uri: str) -> str | None:
    """`ground_plane` or `sun` when `uri` names a built-in model: `model://sun`, or Fuel's
    `https://fuel.gazebosim.org/1.0/OpenRobotics/models/Ground Plane` (any case, any version)."""
    bare = uri.strip().rstrip("/")
    if bare in ("model://ground_plane", "model://sun"):
        return bare[len("model://") :]
    m = _FUEL.match(unquote(bare))
    if m and m.group("owner").lower() == "openrobotics":
        return _FUEL_BUILTINS.get(re.sub(r"[\s_-]+", "", m.group("name")).lower())
    return None


def _download_name(uri: str) -> str:
    """The model folder name a downloaded model is expected under: Fuel's model name, else the last part
    of the address."""
    text = unquote(uri.strip().rstrip("/"))
    m = _FUEL.match(text)
    if m:
        return m.group("name")
    last = text.rsplit("/", 1)[-1]
    for ext in (".zip", ".tar.gz", ".tgz", ".tar"):
        last = last.removesuffix(ext)
    return last


def _together(errors: list[SdfError]) -> SdfError:
    """One error listing several: one line per message and file (the lines of its repeats gathered), the
    distinct hints after."""
    if len(errors) == 1:
        return errors[0]
    lines: dict[tuple[str, str], list[int]] = {}
    for e in errors:
        lines.setdefault((str(e), str(e.file)), []).extend([e.line] if e.line is not None else [])
    if len(lines) == 1:
        (message, file), at = next(iter(lines.items()))
        first = errors[0]
        at_text = ", ".join(str(n) for n in at)
        return SdfError(
            f"{message} (lines {at_text})" if len(at) > 1 else message,
            first.file,
            first.line,
            first.hint,
            errors,
        )
    body = [f"{len(lines)} problems loading the world (all listed):"]
    for (message, file), at in lines.items():
        body.append(f"  {file}:{','.join(str(n) for n in at)}: {message}")
    hints = list(dict.fromkeys(e.hint for e in errors if e.hint))
    return SdfError(
        "\n".join(body),
        errors[0].file,
        errors[0].line,
        "\n            ".join(hints) if hints else None,
        errors,
    )
