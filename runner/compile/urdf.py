"""URDF text -> MuJoCo `MjSpec` of one robot, with the traps of MuJoCo's URDF import handled.

- `fusestatic`/`discardvisual` are off, so fixed-joint links (lidar_link, imu_link) stay bodies a sensor
  can be mounted on and visuals are kept (group 1, no collision);
- mesh URIs (`package://`, `model://`, `file://`, relative) are rewritten to real paths; Collada (in its
  `<unit>`), ASCII STL and other formats MuJoCo cannot read are converted (runner.compile.meshes);
- a mesh that cannot be had (package or file not found, unreadable, a Git LFS pointer, broken, no
  triangles) is an error when a `<collision>` uses it: the robot would fall through the floor or drive
  through walls. When a `<visual>` uses it, the visual is left out with a warning (file:line), as Gazebo
  goes on without it: visuals only matter to cameras and renders. A flat mesh (no volume) may be drawn but
  not collided with (MuJoCo collides with convex hulls): an error in a `<collision>`;
- `<gazebo>` tags are read (runner.compile.gazebo): materials, friction, contact stiffness, gravity, sensors
  and plugins;
- `<transmission>` (ROS 1 style) and `<ros2_control>` joints are collected so the compiler can give them
  actuators;
- a mobile robot's root link gets a free joint (`<gazebo><static>true` or `fixed: true` welds it).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import mujoco
from lxml import etree

from runner.compile.gazebo import GazeboInfo, parse, read_gazebo
from runner.compile.locate import Locator
from runner.compile.meshes import MeshError, PreparedMesh, prepare_mesh
from runner.compile.packages import PackageMap, resolve_uri
from runner.errors import Notices, SourceError
from runner.plan import ParityLine

# URDF visuals are geom group 1 (MuJoCo's import); collisions go to group 3, which cameras do not draw
# (MuJoCo renders groups 0-2 by default), as in MuJoCo Menagerie models.
COLLISION_GROUP = 3


class DescriptionError(SourceError):
    """The URDF itself is wrong."""


@dataclass
class Transmission:
    joint: str
    interface: Literal["position", "velocity", "effort"]
    reduction: float = 1.0


@dataclass
class RobotModel:
    spec: mujoco.MjSpec
    root: str
    urdf: str
    links: list[str] = field(default_factory=list)
    joints: list[str] = field(default_factory=list)
    gazebo: GazeboInfo = field(default_factory=GazeboInfo)
    transmissions: list[Transmission] = field(default_factory=list)
    adjusted: list[ParityLine] = field(default_factory=list)  # what was changed or left out to load it
    self_collision: list[str] = field(default_factory=list)  # links that collide with the robot's others


_JOINT_TYPES = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"}


def _number(text: str, what: str, where: Any, el: Any) -> float:
    """A number attribute of the URDF, or an error at its line."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise DescriptionError(
            f"{what} {text!r} is not a number",
            *where(el),
            hint="a plain URDF needs plain numbers; ${...} is expanded in files that declare xmlns:xacro",
        )
    return value


# URDF attributes that hold numbers; limits may be infinite (unlimited), nothing may be NaN.
_NUMERIC = {
    "xyz",
    "rpy",
    "value",
    "ixx",
    "ixy",
    "ixz",
    "iyy",
    "iyz",
    "izz",
    "size",
    "radius",
    "length",
    "scale",
    "rgba",
    "damping",
    "friction",
    "multiplier",
    "offset",
    "k_position",
    "k_velocity",
}
_LIMITS = {"lower", "upper", "effort", "velocity", "soft_lower_limit", "soft_upper_limit"}


def _check_numbers(root: Any, where: Any) -> None:
    """NaN (and, but in limits, infinity) in a number attribute: MuJoCo would only print a warning and
    build a model that moves to NaN."""
    for el in root.iter():
        if not isinstance(el.tag, str) or el.tag in ("gazebo", "plugin"):
            continue
        for attr, text in el.attrib.items():
            if attr not in _NUMERIC and attr not in _LIMITS:
                continue
            for token in text.split():
                try:
                    value = float(token)
                except ValueError:
                    continue  # MuJoCo reports what does not parse
                if math.isnan(value) or (math.isinf(value) and attr not in _LIMITS):
                    raise DescriptionError(
                        f'<{el.tag} {attr}="{text}">: {token!r} is not a finite number',
                        *where(el),
                        hint="give a plain number",
                    )


def _check_structure(root: Any, where: Any) -> str:
    """Checks MuJoCo would report badly or not at all; returns the root link's name."""
    link_els = root.findall("link")
    if not link_els:
        raise DescriptionError("the URDF has no <link>", *where(root), hint="a robot needs at least one link")
    links: list[str] = []
    for el in link_els:
        name = el.get("name")
        if not name:
            raise DescriptionError("a <link> has no name", *where(el))
        if name in links:
            raise DescriptionError(
                f"link {name!r} is defined twice",
                *where(el),
                hint="rename one (a xacro macro called twice with the same name or prefix does this)",
            )
        links.append(name)
    children: dict[str, str] = {}
    joint_lines: dict[str, Any] = {}
    for j in root.findall("joint"):
        jname = j.get("name") or "?"
        if jname in joint_lines:
            first = where(joint_lines[jname])[1]
            raise DescriptionError(
                f"joint {jname!r} is defined twice" + (f" (first at line {first})" if first else ""),
                *where(j),
                hint="rename one (a xacro macro called twice with the same name or prefix does this)",
            )
        joint_lines[jname] = j
        jtype = j.get("type")
        if jtype not in _JOINT_TYPES:
            raise DescriptionError(
                f"joint {jname!r} has type {jtype!r}",
                *where(j),
                hint="URDF joint types: " + ", ".join(sorted(_JOINT_TYPES)),
            )
        for tag in ("parent", "child"):
            el = j.find(tag)
            ref = el.get("link") if el is not None else None
            if ref not in links:
                raise DescriptionError(
                    f"joint {jname!r} names {tag} link {ref!r}, which is not defined",
                    *where(j if el is None else el),
                    hint="defined links: " + ", ".join(links),
                )
        child = j.find("child").get("link")
        if child in children:
            raise DescriptionError(
                f"link {child!r} is the child of two joints ({children[child]!r} and {jname!r})", *where(j)
            )
        children[child] = jname
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        raise DescriptionError(
            f"the URDF must form one tree, found {len(roots)} root links: {', '.join(roots)}",
            *where(root),
            hint="every link but one must be the child of a joint",
        )
    return roots[0]


def urdf_to_model(
    urdf: str,
    file: Path | None,
    packages: PackageMap,
    *,
    fixed: bool = False,
    namespace: str = "robot",
    model: str | None = None,
    notices: Notices | None = None,
    sources: list[Path] | None = None,
    expanded: bool = False,
    timestep: float = 0.002,
    controllers: list[Path] | None = None,
) -> RobotModel:
    notices = notices if notices is not None else Notices()
    base_dir = file.parent if file else Path.cwd()
    where = Locator(file, sources or ([file] if file else []), expanded)
    try:
        root = parse(urdf)
    except etree.XMLSyntaxError as e:
        raise DescriptionError(
            f"not well-formed XML: {e.msg}", file, None if expanded else e.lineno
        ) from None
    if root.tag != "robot":
        raise DescriptionError(f"the top element is <{root.tag}>, expected <robot>", *where(root))
    root_link = _check_structure(root, where)
    _check_numbers(root, where)
    adjusted: list[ParityLine] = []
    _repair_inertias(root, where, notices, adjusted)
    _drop_empty_shapes(root, where, notices, adjusted)

    shell: set[str] = set()  # mesh files without a volume (flat or tiny): MuJoCo weighs them as shells
    meshes = [m for m in root.iter("mesh") if m.getparent() is not None and m.getparent().tag == "geometry"]
    for mesh in meshes:  # a list: a mesh that cannot be had takes its <visual> out of the tree
        _rewrite_mesh(mesh, packages, base_dir, where, notices, shell)

    gazebo = read_gazebo(
        root,
        file,
        sources=sources or ([file] if file else []),
        expanded=expanded,
        namespace=namespace,
        model=model or namespace,
        notices=notices,
        controllers=controllers,
    )
    transmissions = _transmissions(root, where, notices)

    # MuJoCo's URDF defaults fuse fixed links away and drop visuals: turn both off.
    for old in root.findall("mujoco"):
        root.remove(old)
    for tag in ("gazebo", "transmission", "ros2_control"):
        for el in root.findall(tag):
            root.remove(el)
    mj = etree.Element("mujoco")
    etree.SubElement(mj, "compiler", discardvisual="false", fusestatic="false", strippath="false")
    root.insert(0, mj)
    _unique_shape_names(root)
    text = etree.tostring(root, encoding="unicode")
    try:
        spec = mujoco.MjSpec.from_string(text)
    except ValueError as e:
        raise _mujoco_error(e, root, text, where, file) from None

    for mesh_asset in spec.meshes:
        if mesh_asset.file in shell:
            # its volume is zero: MuJoCo's default (volume) inertia refuses it, a shell's does not
            mesh_asset.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
    for geom in spec.geoms:
        if geom.contype or geom.conaffinity:
            geom.group = COLLISION_GROUP
    _apply_link_props(spec, gazebo, timestep)
    self_collision = _self_collision(root, spec, gazebo)
    body = spec.body(root_link)
    if not (fixed or gazebo.static):
        body.add_freejoint(name="root")
    links = [b.name for b in spec.bodies if b.name and b.name != "world"]
    joints = [j.name for j in spec.joints if j.name and j.name != "root"]
    for message, (src, line) in gazebo.dropped:
        adjusted.append(ParityLine(kind="dropped", text=message, file=str(src) if src else None, line=line))
    return RobotModel(spec, root_link, urdf, links, joints, gazebo, transmissions, adjusted, self_collision)


def _mujoco_error(e: ValueError, root: Any, text: str, where: Any, file: Path | None) -> DescriptionError:
    """MuJoCo's "XML Error: ... Element 'x', line N" is about the text we gave it: point at the element
    in the user's file instead (the trees are the same, element for element)."""
    message = " ".join(str(e).split("\n")[0].split()).removeprefix("XML Error: ")
    m = re.search(r"Element '([^']*)', line (\d+)", str(e))
    if m:
        tag, line = m.group(1), int(m.group(2))
        ours = [el for el in root.iter() if isinstance(el.tag, str)]
        given = [el for el in etree.fromstring(text.encode()).iter() if isinstance(el.tag, str)]
        for mine, theirs in zip(ours, given, strict=False):
            if theirs.sourceline == line and theirs.tag == tag:
                return DescriptionError(
                    f"MuJoCo cannot load this URDF: {message} (in <{tag}>)",
                    *where(mine),
                    hint="check that element's attributes: names, numbers and required children",
                )
    return DescriptionError(f"MuJoCo cannot load this URDF: {message}", file)


def _apply_link_props(spec: mujoco.MjSpec, gazebo: GazeboInfo, timestep: float) -> None:
    for link, props in gazebo.links.items():
        body = spec.body(link)
        if body is None:
            continue
        if props.gravity_off:
            body.gravcomp = 1.0
        for geom in body.geoms:
            if props.rgba is not None:
                geom.rgba = list(props.rgba)
            if not (geom.contype or geom.conaffinity):
                continue
            if props.friction is not None:
                # MuJoCo takes the larger friction of two touching geoms, Gazebo the smaller: give the
                # geom priority so that its own value is used (a caster's mu1=0 must stay 0).
                geom.friction = [props.friction, geom.friction[1], geom.friction[2]]
                geom.priority = 1
                if props.friction == 0.0:
                    # Frictionless as MuJoCo means it: a normal-only contact. A zero-friction cone
                    # (condim 3) lets a loaded caster jitter until the robot is thrown.
                    geom.condim = 1
            if props.kp:
                # ODE's kp (N/m) as a MuJoCo contact time constant for the link's own mass, never
                # below 2 steps (MuJoCo's stability limit). MuJoCo's direct (-stiffness, -damping) form is
                # per unit mass, not N/m: fed Gazebo's numbers, wheels lose traction.
                mass = max(float(body.mass), 1e-3)
                geom.solref = [max(2.0 * timestep, 2.0 * math.pi * math.sqrt(mass / props.kp)), 1.0]


# The dimensions of each URDF shape (attribute, how many numbers)
_SHAPE_SIZES = {
    "box": ("size", 3),
    "cylinder": ("radius", 1),
    "sphere": ("radius", 1),
    "capsule": ("radius", 1),
}


def _drop_empty_shapes(root: Any, where: Any, notices: Notices, adjusted: list[ParityLine]) -> None:
    """A `<collision>` or `<visual>` whose shape has a zero dimension (`<box size="0 0 0">`, a sphere of
    radius 0: placeholders some descriptions give sensors) loads in Gazebo, where it touches and shows
    nothing; MuJoCo refuses it. It is left out, with a warning at its line."""
    for link in root.findall("link"):
        for el in [*link.findall("collision"), *link.findall("visual")]:
            geometry = el.find("geometry")
            shape = (
                next((g for g in geometry if isinstance(g.tag, str)), None) if geometry is not None else None
            )
            if shape is None or shape.tag not in _SHAPE_SIZES:
                continue
            sizes = [shape.get(_SHAPE_SIZES[shape.tag][0], "")]
            if shape.tag in ("cylinder", "capsule"):
                sizes.append(shape.get("length", ""))
            values = [float(v) for text in sizes for v in text.split() if _is_number(v)]
            if not values or min(values) != 0.0:
                continue
            at = where(shape)
            shown = " ".join(f'{k}="{v}"' for k, v in shape.attrib.items())
            does = "touches" if el.tag == "collision" else "shows"
            message = (
                f"link {link.get('name')!r}: its <{el.tag}> is a <{shape.tag} {shown}>, of zero size: "
                f"left out (Gazebo loads it, and it {does} nothing)"
            )
            notices.add(message, *at, hint=f"remove the <{el.tag}> or give it a size to silence this")
            el.getparent().remove(el)
            file, line = at
            adjusted.append(
                ParityLine(kind="dropped", text=message, file=str(file) if file else None, line=line)
            )


def _unique_shape_names(root: Any) -> None:
    """Every `<visual>`/`<collision>` gets a unique name, as MuJoCo wants for its geoms: an unnamed one is
    named as Gazebo's URDF reader does (`<link>_collision`, `<link>_collision_1`...), a name another link
    already used (macros call them all "base_visual") gets its link's name before it. Left unnamed, MuJoCo's
    URDF reader carries the link's visual name over to its unnamed collision and prints a warning for each.
    """
    taken = {el.get("name") for tag in ("collision", "visual") for el in root.iter(tag) if el.get("name")}
    seen: set[str] = set()
    for link in root.findall("link"):
        lname = link.get("name")
        for tag in ("collision", "visual"):
            for k, el in enumerate(link.findall(tag)):
                given = el.get("name")
                name = given if given and given not in seen else None
                if name is None:
                    stem = f"{lname}/{given}" if given else f"{lname}_{tag}" + (f"_{k}" if k else "")
                    name, n = stem, 1
                    while name in seen or (name in taken and not given):
                        name, n = f"{stem}_{n}", n + 1
                    el.set("name", name)
                seen.add(name)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


# Mass given to a moving link whose mass is zero, negative or next to nothing (MuJoCo refuses those).
MIN_MASS = 1e-3
_NEAR_ZERO_MASS = 1e-5
# MJCF text keeps 6 significant digits: a repaired A + B exceeds C by more than their rounding
_TEXT_ROUNDING = 2e-5
# A principal moment this far below the largest (or not positive) is raised to a thousandth of it.
_MIN_MOMENT_RATIO = 1e-3


def _repair_inertias(root: Any, where: Any, notices: Notices, adjusted: list[ParityLine]) -> None:
    """Masses and inertias Gazebo (ODE) takes and MuJoCo refuses, repaired as a careful user would, with
    one warning per link saying what was changed:

    - a moving link (a revolute, continuous or prismatic joint's child) with a zero, negative or near-zero
      mass gets `MIN_MASS`;
    - an inertia that is not positive definite (a zero or negative principal moment) has those moments
      raised to a thousandth of the largest (a solid 10 cm sphere's when all are zero);
    - principal moments that break the triangle inequality (A + B >= C: no rigid body has them, e.g.
      ixx = iyy = 0.01, izz = 0.5) have the two smaller ones scaled up until A + B = C.

    The orientation of the principal axes is kept: the repaired tensor is written back in the link's frame.
    """
    moving = {
        j.find("child").get("link")
        for j in root.findall("joint")
        if j.get("type") in ("revolute", "continuous", "prismatic") and j.find("child") is not None
    }
    for link in root.findall("link"):
        name = link.get("name")
        inertial = link.find("inertial")
        if inertial is None:
            continue
        changes: list[str] = []
        mass_el = inertial.find("mass")
        mass = (
            _number(mass_el.get("value", "0") or "0", "mass", where, mass_el) if mass_el is not None else 0.0
        )
        if name in moving and mass < _NEAR_ZERO_MASS:
            changes.append(f"mass {mass:g} kg -> {MIN_MASS:g} kg")
            mass = MIN_MASS
            if mass_el is None:
                mass_el = etree.SubElement(inertial, "mass")
            mass_el.set("value", repr(mass))
        el = inertial.find("inertia")
        if el is not None:
            fixed = _repaired_inertia(el, mass, name in moving)
            if fixed is not None:
                tensor, before, after, nudged_only = fixed
                for key, value in zip(("ixx", "iyy", "izz", "ixy", "ixz", "iyz"), tensor, strict=True):
                    el.set(key, repr(value))
                if not nudged_only:
                    changes.append(f"principal moments {before} -> {after} kg·m²")
        if not changes:
            continue
        at = where(el if el is not None else inertial)
        message = f"link {name!r}: its inertia is not one MuJoCo accepts (Gazebo does): " + "; ".join(changes)
        notices.add(
            message,
            *at,
            hint="a rigid body needs a positive mass and principal moments with A + B >= C; fix the "
            "<inertial> to silence this",
        )
        file, line = at
        adjusted.append(ParityLine(kind="changed", text=message, file=str(file) if file else None, line=line))


def _repaired_inertia(el: Any, mass: float, moving: bool) -> tuple[tuple[float, ...], str, str, bool] | None:
    """(ixx, iyy, izz, ixy, ixz, iyz) repaired, the principal moments before and after, and whether it was
    only nudged by the MJCF text's rounding (not worth a warning); None if fine."""
    import numpy as np

    def num(key: str) -> float:
        try:
            return float(el.get(key, "0") or 0)
        except ValueError:
            return 0.0

    ixx, iyy, izz, ixy, ixz, iyz = (num(k) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz"))
    tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    moments, axes = np.linalg.eigh(tensor)
    new = moments.copy()
    largest = float(moments.max())
    if largest <= 0.0:
        if not moving and mass <= 0.0:
            return None  # a massless fixed link: MuJoCo asks nothing of it
        new[:] = 0.4 * max(mass, MIN_MASS) * 0.05**2
    else:
        floor = largest * _MIN_MOMENT_RATIO
        if moving or moments.min() < 0.0:
            new = np.maximum(new, np.where(new <= largest * 1e-9, floor, new))
    raised = not np.array_equal(new, moments)
    order = np.argsort(new)
    a, b, c = (float(new[i]) for i in order)
    margin = 1.0 + _TEXT_ROUNDING
    nudged_only = False
    if a + b < c * margin:
        # A + B = C exactly (a thin plate, or an xacro formula such as m/12 (y² + z²)) holds in floating
        # point but not once the MJCF text keeps 6 digits: such a tensor is nudged by that rounding, silently
        nudged_only = not raised and a + b >= c * (1.0 - 1e-9)
        scale = c * margin / (a + b) if a + b > 0 else None
        a, b = (a * scale, b * scale) if scale else (c / 2.0 * margin, c / 2.0 * margin)
        new[order[0]], new[order[1]] = a, b
    if np.array_equal(new, moments):
        return None
    fixed = axes @ np.diag(new) @ axes.T
    values = (fixed[0, 0], fixed[1, 1], fixed[2, 2], fixed[0, 1], fixed[0, 2], fixed[1, 2])

    def shown(v: Any) -> str:
        return "(" + ", ".join(f"{x:.4g}" for x in sorted(v)) + ")"

    return tuple(float(v) for v in values), shown(moments), shown(new), nudged_only


def _self_collision(root: Any, spec: mujoco.MjSpec, gazebo: GazeboInfo) -> list[str]:
    """Gazebo's rule: links of one model collide with each other only if one of the two has self_collide
    (the link's `<selfCollide>`, else the model's `<self_collide>`, off by default), and never when a joint
    connects them. Gazebo lumps links joined by fixed joints into one link: those never collide with each
    other either, and a joint between two such groups connects all their links. MuJoCo only leaves out
    parent-child pairs, so every other pair that Gazebo would not collide is excluded here. Returns the
    links that self-collide."""
    parent: dict[str, str] = {}
    group = {el.get("name"): el.get("name") for el in root.findall("link")}

    def find(x: str) -> str:
        while group[x] != x:
            group[x] = group[group[x]]
            x = group[x]
        return x

    moving: list[tuple[str, str]] = []
    for j in root.findall("joint"):
        p, c = j.find("parent").get("link"), j.find("child").get("link")
        parent[c] = p
        if j.get("type") == "fixed":
            group[find(c)] = find(p)
        else:
            moving.append((p, c))
    jointed = {frozenset((find(p), find(c))) for p, c in moving}

    def collides(name: str) -> bool:
        props = gazebo.links.get(name)
        if props is not None and props.self_collide is not None:
            return props.self_collide
        return gazebo.self_collide

    bodies = [
        b.name for b in spec.bodies if b.name in group and any(g.contype or g.conaffinity for g in b.geoms)
    ]
    on = [name for name in bodies if collides(name)]
    for i, a in enumerate(bodies):
        for b in bodies[i + 1 :]:
            ga, gb = find(a), find(b)
            if parent.get(a) == b or parent.get(b) == a:
                continue  # MuJoCo leaves parent and child out by itself
            if (collides(a) or collides(b)) and ga != gb and frozenset((ga, gb)) not in jointed:
                continue
            spec.add_exclude(bodyname1=a, bodyname2=b)
    return on


class _NoMesh(Exception):
    """Why a <mesh> cannot be used, and a hint."""

    def __init__(self, message: str, hint: str | None):
        super().__init__(message)
        self.hint = hint


# A mesh whose bounding box (scaled) holds less than this (m^3) has no volume MuJoCo can weigh (it needs
# 1e-15): a 10 um part, or a unit mistake.
_TINY_VOLUME = 1e-12


def _rewrite_mesh(
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


_INTERFACES: dict[str, Literal["position", "velocity", "effort"]] = {
    "position": "position",
    "velocity": "velocity",
    "effort": "effort",
}


def _interface(text: str | None) -> Literal["position", "velocity", "effort"] | None:
    if not text:
        return None
    t = text.strip().split("/")[-1].lower()
    for key, kind in _INTERFACES.items():
        if t.startswith(key):
            return kind
    return None


def _transmissions(root: Any, where: Any, notices: Notices) -> list[Transmission]:
    out: list[Transmission] = []
    for tr in root.findall("transmission"):
        joint = tr.find("joint")
        if joint is None or not joint.get("name"):
            notices.add("a <transmission> without a <joint name=...> is ignored", *where(tr))
            continue
        kinds = [_interface(e.text) for e in tr.iter("hardwareInterface")]
        kind = next((k for k in kinds if k), None)
        if kind is None:
            notices.add(
                f"transmission of joint {joint.get('name')!r} has no velocity/position/effort "
                "interface; ignored",
                *where(tr),
            )
            continue
        reduction = 1.0
        red = tr.find("actuator/mechanicalReduction")
        if red is not None and red.text:
            try:
                reduction = float(red.text)
            except ValueError:
                notices.add(f"mechanicalReduction {red.text!r} is not a number; 1 is used", *where(red))
        out.append(Transmission(joint.get("name"), kind, reduction or 1.0))
    for rc in root.findall("ros2_control"):
        for joint in rc.findall("joint"):
            names = [c.get("name") for c in joint.findall("command_interface")]
            kind = next((_interface(n) for n in names if _interface(n)), None)
            if kind and joint.get("name"):
                out.append(Transmission(joint.get("name"), kind))
    return out
