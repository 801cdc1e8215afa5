"""The SDF reader's base: its state (the `MjSpec` built into, names taken, notices gathered), reading an
XML file as Gazebo does (lenient about comments and undeclared prefixes), `SdfError`, and the small tools
every part uses: notices for what is left out, errors at a file and line, numbers, booleans and poses of
elements, unique names."""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from pathlib import Path

import mujoco
from lxml import etree

from runner.compile.filesize import HINT as SIZE_HINT
from runner.compile.filesize import too_large
from runner.compile.packages import PackageMap
from runner.compile.sdf.parts import ModelState, SdfWorld, Src
from runner.compile.sdf.pose import IDENTITY, Pose
from runner.errors import Notices, SourceError
from runner.geometry import rpy_to_quat


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


def combine_errors(errors: list[SdfError]) -> SdfError:
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


PLANE = mujoco.mjtGeom.mjGEOM_PLANE


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
    # a world model's friction direction: the capsule proxies that give robots' wheels Gazebo's anisotropic
    # friction on the ground (runner.compile.wheels) need a round shape on a moving link and the ground plane
    "fdir1": "anisotropic friction of world models is not simulated: the smaller of mu and mu2 is used",
    "slip1": "force-dependent slip is not simulated",
    "slip2": "force-dependent slip is not simulated",
    "axis2": "the second axis of universal/revolute2 joints is not supported",
    "placement_frame": "placement frames are not supported; <pose> places the model's own frame",
}


def xml_bool(text: str | None) -> bool:
    return (text or "").strip().lower() in ("true", "1")


def is_custom(el: etree._Element) -> bool:
    """A custom element (`<gz:policies>`, `<drake:...>`: a namespace prefix), which SDF readers skip."""
    return isinstance(el.tag, str) and (":" in el.tag or el.tag.startswith("{"))


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


class Reader:
    """The reader's state and the tools every part of it uses (the parts are its subclasses)."""

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
        planes = [g for g in spec.worldbody.geoms if g.type == PLANE]
        self.ground_geom: mujoco.MjsGeom | None = next((g for g in planes if g.name == "ground"), None)
        if self.ground_geom is None and planes:
            self.ground_geom = planes[0]
        self.ground_owner: tuple[str, Path, int | None] | None = None
        self.ground_link: str | None = None
        self.missing: list[SdfError] = []  # files not found: reported together at the end
        self.result: SdfWorld | None = None
        self.state: dict[str, ModelState] = {}  # the world's <state>, by top-level model name
        self.deleted: set[str] = set()  # models its <deletions> remove

    def note(
        self,
        message: str,
        src: Src | Path | None,
        el: etree._Element | None = None,
        hint: str | None = None,
    ) -> None:
        file = src.path if isinstance(src, Src) else src
        self.notices.add(message, file, el.sourceline if el is not None else None, hint)

    def skip(self, el: etree._Element, src: Src) -> None:
        tag = el.tag if isinstance(el.tag, str) else str(el.tag)
        if tag in _GUI:
            self.gui.setdefault(tag, (src.path, el.sourceline))
            return
        entry = self.unknown.get(tag)
        if entry is None:
            self.unknown[tag] = [src.path, el.sourceline, 1]
        else:
            entry[2] += 1

    def check(self, el: etree._Element, src: Src, handled: Iterable[str]) -> None:
        handled = set(handled)
        for ch in el:
            if (
                isinstance(ch.tag, str)
                and ch.tag not in handled
                and ch.tag not in _QUIET
                and not is_custom(ch)
            ):
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

    def error(self, message: str, src: Src | Path, el: etree._Element | None = None, hint: str | None = None):
        file = src.path if isinstance(src, Src) else src
        return SdfError(message, file, el.sourceline if el is not None else None, hint)

    def parse(
        self, path: Path, asked_by: tuple[Src, etree._Element] | None = None
    ) -> tuple[etree._Element, Src]:
        path = path.resolve()
        if not path.is_file():
            if asked_by:
                raise self.error(
                    f"SDF file {str(path)!r} not found",
                    asked_by[0],
                    asked_by[1],
                    hint="relative paths are resolved from the file that names it",
                )
            raise SdfError(
                f"SDF file {str(path)!r} not found", path, hint="paths are relative to the scenario"
            )
        oversize = too_large(path)
        if oversize is not None:  # before it is read or parsed
            raise SdfError(oversize, path, hint=SIZE_HINT)
        try:
            data = _xml_bytes(path)
        except OSError as e:
            raise SdfError(
                f"cannot read {str(path)!r}: {e.strerror or e}", path, hint="check the file's permissions"
            ) from None
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
        return root, Src(path, version, tuple(self.stack))

    def floats(self, el: etree._Element, src: Src, n: int | tuple[int, ...]) -> tuple[float, ...]:
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

    def child_float(self, el: etree._Element, tag: str, src: Src, default: float | None = None) -> float:
        c = el.find(tag)
        if c is None:
            if default is None:
                raise self.error(
                    f"<{el.tag}> needs a <{tag}>", src, el, hint=f"add <{tag}>...</{tag}> inside it"
                )
            return default
        return self.floats(c, src, 1)[0]

    def child_bool(self, el: etree._Element, tag: str, src: Src) -> bool | None:
        c = el.find(tag)
        if c is None:
            return None
        text = (c.text or "").strip().lower()
        if text not in ("true", "false", "1", "0"):
            raise self.error(
                f"<{tag}> must be true or false, found {text!r}", src, c, hint="write true, false, 1 or 0"
            )
        return text in ("true", "1")

    def pose_of(self, el: etree._Element, src: Src) -> tuple[Pose, str | None, etree._Element | None]:
        """The `<pose>` child of `el` as a pose, its `relative_to` (or None) and the element."""
        p = el.find("pose")
        if p is None:
            return IDENTITY, None, None
        return self.pose(p, src), (p.get("relative_to") or None), p

    def pose(self, p: etree._Element, src: Src) -> Pose:
        quat_form = (p.get("rotation_format") or "euler_rpy").strip() == "quat_xyzw"
        v = self.floats(p, src, (7,) if quat_form else (6,))
        if quat_form:
            x, y, z, w = v[3:]
            n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
            return Pose(v[:3], (w / n, x / n, y / n, z / n))  # type: ignore[arg-type]
        rpy = v[3:]
        if xml_bool(p.get("degrees")):
            rpy = tuple(math.radians(a) for a in rpy)
        q = rpy_to_quat(list(rpy))
        return Pose(v[:3], (float(q[0]), float(q[1]), float(q[2]), float(q[3])))  # type: ignore[arg-type]

    def need(self, el: etree._Element, tag: str, src: Src) -> etree._Element:
        c = el.find(tag)
        if c is None:
            raise self.error(f"<{el.tag}> needs a <{tag}>", src, el, hint=f"add <{tag}>...</{tag}> inside it")
        return c

    def unique(self, kind: str, name: str) -> str:
        used = self.names[kind]
        out, k = name, 2
        while out in used:
            out = f"{name}#{k}"
            k += 1
        used.add(out)
        return out
