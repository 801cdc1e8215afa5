"""SDF (1.4-1.9) or Gazebo classic `.world` file -> bodies, geoms and lights added to a MuJoCo `MjSpec`.

What is read:
- `<world>` (or a bare `<model>`): `<model>`, `<include>`, `<light>`, `<physics>` (`max_step_size`,
  `real_time_factor`, 1.4's `<gravity>`), `<gravity>`;
- `<model>`: `<static>`, `<pose>` (with `relative_to` sibling frames, `<frame>`s), nested `<model>` and
  `<include>` (poses compose), `<link>`, `<joint>` (fixed, revolute, continuous, prismatic, ball);
- `<link>`: `<pose>`, `<inertial>`, `<gravity>`, `<light>`, `<collision>` and `<visual>` with box, cylinder,
  sphere, capsule, ellipsoid, plane and STL/OBJ mesh geometry, `<material>` colours (rgba or the classic
  `Gazebo/...` script names), `<surface>` friction (`mu`/`mu2`: the smaller), contact stiffness (`kp`/`kd`)
  and collide bitmasks;
- `<include>`: `model://ground_plane` and `model://sun` are built in; any other `model://NAME` is a folder
  with a `model.config` found through the `PackageMap`; `file://`, `package://` and relative paths work too.

Names: every body and geom of a model is `<model>/<link>` (nested: `<model>/<sub>/<link>`), geoms
`<model>/<link>/<collision or visual name>`, so they never clash with robots (which live under `<ns>/`).

Anything else is listed once per tag name as a notice (file and line of the first one), never fatal, never
silent. Malformed XML and missing required elements raise `SdfError` (a `SourceError`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import NamedTuple

import mujoco
from lxml import etree

from runner.compile.materials import gazebo_material
from runner.compile.meshes import MeshError, convert_mesh
from runner.compile.packages import PackageMap, resolve_uri
from runner.compile.urdf import COLLISION_GROUP
from runner.errors import Notices, SourceError
from runner.geometry import rpy_to_quat


class SdfError(SourceError):
    """The SDF/world file itself is wrong, or something it refers to cannot be found."""


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
_MESH_FORMATS = {".stl", ".obj"}

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
    "state": "a saved world state is not applied; models start at their <pose>",
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

_GEOM_KEYS = {"box", "cylinder", "sphere", "capsule", "ellipsoid", "plane", "mesh", "empty"}
_GEOM_SKIPPED = {"heightmap", "polyline", "image"}


@dataclass
class _Src:
    path: Path
    version: tuple[int, int] | None


@dataclass
class _Link:
    key: str  # scoped name in the top-level model: `link` or `sub::link`
    body: str  # `<model>/<sub>/<link>`
    world: _Pose
    el: etree._Element
    src: _Src
    static: bool
    model_world: _Pose  # pose of the model that holds the link (axes expressed in the model frame)


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
        self.had_ground = any(g.type == _PLANE for g in spec.worldbody.geoms)
        self.result: SdfWorld | None = None

    # ------------------------------------------------------------------------------------- notices
    def note(self, message: str, src: _Src | Path | None, el: etree._Element | None = None) -> None:
        file = src.path if isinstance(src, _Src) else src
        self.notices.add(message, file, el.sourceline if el is not None else None)

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
            if isinstance(ch.tag, str) and ch.tag not in handled and ch.tag not in _QUIET:
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
        parser = etree.XMLParser(
            remove_comments=True, remove_pis=True, resolve_entities=False, no_network=True
        )
        try:
            root = etree.parse(str(path), parser).getroot()
        except etree.XMLSyntaxError as e:
            if "Namespace prefix" not in str(e.msg):
                raise SdfError(
                    f"not well-formed XML: {e.msg}",
                    path,
                    e.lineno,
                    hint="check that every tag is closed and attribute values are quoted",
                ) from None
            # An undeclared prefix (`<gz:...>`): read the file anyway, the element is dropped later.
            self.notices.add(f"XML: {e.msg}; read anyway", path, e.lineno)
            parser = etree.XMLParser(remove_comments=True, remove_pis=True, recover=True, no_network=True)
            root = etree.parse(str(path), parser).getroot()
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
        return root, _Src(path, version)

    # ----------------------------------------------------------------------------------------- load
    def load(self, path: Path) -> SdfWorld:
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
        return result

    def world(self, w: etree._Element, src: _Src, result: SdfWorld) -> None:
        result.name = w.get("name")
        self.check(w, src, {"model", "include", "light", "physics", "gravity"})
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
        if pose is None:
            local, rel, pel = self.pose_of(el, src)
            if rel not in (None, "world", "__model__"):
                self.note(
                    f"pose relative_to {rel!r} of model {model_name!r} is taken relative to the world",
                    src,
                    pel,
                )
            pose = local
        collected = self.model(el, src, parent @ pose, [model_name], False, static, model_name)
        self.build(collected)
        self.result.models.append(model_name)

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

        bare = uri.rstrip("/")
        if bare in ("model://ground_plane", "model://sun"):
            world_pose = parent @ (pose or _IDENTITY)
            if bare.endswith("sun"):
                self.sun(world_pose)
            else:
                self.ground(world_pose, src, el)
            return name or bare[len("model://") :], None

        file = self.resolve_include(uri, src, uri_el)
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
        searched = "; searched: " + (", ".join(self.packages.searched()) or "nothing")
        if uri.startswith(("http://", "https://")):
            raise self.error(
                f"include {uri!r}: models are not downloaded",
                src,
                at,
                hint="download the model folder and put it under a folder listed in `packages:`",
            )
        if uri.startswith("model://"):
            name, _, rest = uri[len("model://") :].partition("/")
            root = self.packages.find(name)
            if root is None:
                raise self.error(
                    f"model {uri!r} not found",
                    src,
                    at,
                    hint="a model is a folder named after it holding a model.config; add its parent folder "
                    "under `packages:` or to GZ_SIM_RESOURCE_PATH" + searched,
                )
            target = root / rest if rest else root
        else:
            found = resolve_uri(uri, self.packages, src.path.parent)
            if found is None:
                raise self.error(f"include {uri!r}: package not found", src, at, hint=searched.lstrip("; "))
            target = found
        if target.is_dir():
            target = self.model_file(target, src, at, uri)
        if not target.is_file():
            raise self.error(f"include {uri!r}: {target} does not exist", src, at, hint=searched.lstrip("; "))
        return target.resolve()

    def model_file(self, folder: Path, src: _Src, at: etree._Element, uri: str) -> Path:
        config = folder / "model.config"
        if not config.is_file():
            if (folder / "model.sdf").is_file():
                return folder / "model.sdf"
            raise self.error(f"include {uri!r}: {folder} has no model.config", src, at)
        try:
            root = etree.parse(str(config), etree.XMLParser(remove_comments=True, no_network=True)).getroot()
        except etree.XMLSyntaxError as e:
            raise SdfError(f"not well-formed XML: {e.msg}", config, e.lineno) from None
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
        kw = self.shape(g, src, link, local, visual)
        if kw is None:
            return None
        kw["name"] = el.get("name") or kind
        if visual:
            kw.update(contype=0, conaffinity=0, group=1, rgba=list(self.colour(el, src)))
        else:
            kw.update(group=COLLISION_GROUP, rgba=list(rgba or _GREY))
            self.surface(el.find("surface"), src, kw, link, mass)
        kw["pos"] = list(kw.pop("_pose").p)  # type: ignore[attr-defined]
        return kw

    def shape(
        self, g: etree._Element, src: _Src, link: _Link, local: _Pose, visual: bool
    ) -> dict[str, object] | None:
        shapes = [c for c in g if isinstance(c.tag, str)]
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
                hint="one of: box, cylinder, sphere, capsule, ellipsoid, plane, mesh",
            )
        s = known[0]
        pose = local
        kw: dict[str, object] = {}
        G = mujoco.mjtGeom
        if s.tag == "empty":
            return None
        if s.tag == "box":
            x, y, z = self.floats(self.need(s, "size", src), src, 3)
            kw.update(type=G.mjGEOM_BOX, size=[x / 2, y / 2, z / 2])
        elif s.tag in ("cylinder", "capsule"):
            r = self.child_float(s, "radius", src)
            length = self.child_float(s, "length", src)
            kind = G.mjGEOM_CYLINDER if s.tag == "cylinder" else G.mjGEOM_CAPSULE
            kw.update(type=kind, size=[r, length / 2, 0])
        elif s.tag == "sphere":
            kw.update(type=G.mjGEOM_SPHERE, size=[self.child_float(s, "radius", src), 0, 0])
        elif s.tag == "ellipsoid":
            kw.update(type=G.mjGEOM_ELLIPSOID, size=list(self.floats(self.need(s, "radii", src), src, 3)))
        elif s.tag == "plane":
            n_el = s.find("normal")
            normal = _unit(self.floats(n_el, src, 3)) if n_el is not None else (0.0, 0.0, 1.0)
            if normal is None:
                raise self.error("the <normal> of a plane is zero", src, n_el)
            size_el = s.find("size")
            sx, sy = self.floats(size_el, src, 2) if size_el is not None else (1.0, 1.0)
            pose = _Pose(local.p, _qmul(local.q, _quat_z_to(normal)))
            world = link.world @ pose
            up = _rot(world.q, (0.0, 0.0, 1.0))
            if not link.static:
                self.note("a plane on a moving link is a thin box (MuJoCo planes are static)", src, s)
                kw.update(type=G.mjGEOM_BOX, size=[sx / 2, sy / 2, 0.005])
            else:
                if up[2] < 1 - 1e-9:
                    self.note("this plane is not horizontal; MuJoCo planes are infinite", src, s)
                elif self.had_ground and abs(world.p[2]) < 1e-6:
                    self.note("the world already has a ground plane; this plane at z=0 is left out", src, s)
                    return None
                kw.update(type=_PLANE, size=[sx / 2, sy / 2, 0.05])
        elif s.tag == "mesh":
            mesh = self.mesh(s, src)
            if mesh is None:
                return None
            kw.update(type=G.mjGEOM_MESH, meshname=mesh)
        self.check(s, src, {"size", "radius", "length", "radii", "normal", "uri", "scale", "submesh"})
        kw["quat"] = list(pose.q)
        kw["_pose"] = pose
        return kw

    def need(self, el: etree._Element, tag: str, src: _Src) -> etree._Element:
        c = el.find(tag)
        if c is None:
            raise self.error(f"<{el.tag}> needs a <{tag}>", src, el)
        return c

    def mesh(self, s: etree._Element, src: _Src) -> str | None:
        uri_el = self.need(s, "uri", src)
        uri = (uri_el.text or "").strip()
        scale_el = s.find("scale")
        scale = self.floats(scale_el, src, 3) if scale_el is not None else (1.0, 1.0, 1.0)
        if s.find("submesh") is not None:
            self.note("<submesh> is not supported; the whole mesh is used", src, s.find("submesh"))
        path = resolve_uri(uri, self.packages, src.path.parent)
        if path is None or not path.is_file():
            raise self.error(
                f"mesh {uri!r} not found" + (f" (looked at {path})" if path else ""),
                src,
                uri_el,
                hint="searched: " + ", ".join(self.packages.searched()),
            )
        if path.suffix.lower() not in _MESH_FORMATS:
            try:
                path = convert_mesh(path)
            except MeshError as e:
                alt = next(
                    (
                        path.with_suffix(x)
                        for x in (".stl", ".STL", ".obj", ".OBJ")
                        if path.with_suffix(x).is_file()
                    ),
                    None,
                )
                if alt is None:
                    self.note(f"{e}; left out", src, uri_el)
                    return None
                self.note(f"{e}; using {alt.name} instead", src, uri_el)
                path = alt
        key = (str(path.resolve()), tuple(scale))
        if key in self.meshes:
            return self.meshes[key]
        name = self.unique("mesh", f"sdf/{path.stem}")
        self.spec.add_mesh(name=name, file=key[0], scale=list(scale))
        self.meshes[key] = name
        return name

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
        self.check(s, src, {"friction", "contact"})
        fr = s.find("friction")
        if fr is not None:
            self.check(fr, src, {"ode"})
            ode = fr.find("ode")
            if ode is not None:
                self.check(ode, src, {"mu", "mu2"})
                mus = [self.child_float(ode, t, src) for t in ("mu", "mu2") if ode.find(t) is not None]
                if mus:
                    # Gazebo takes the smaller of two surfaces' mu, MuJoCo the larger: priority makes this
                    # geom's own friction win against plain geoms (the ground, robot bodies).
                    kw["friction"] = [max(min(mus), 0.0), 0.005, 0.0001]
                    kw["priority"] = 1
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
        assert self.result is not None
        if self.had_ground:
            return
        self.spec.worldbody.add_geom(
            name=self.unique("geom", "ground"),
            type=_PLANE,
            size=[0, 0, 0.05],
            pos=list(pose.p),
            quat=list(pose.q),
            rgba=list(_GROUND_RGBA),
            friction=[1.0, 0.005, 0.0001],
        )
        self.had_ground = True
        self.result.ground = True

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
