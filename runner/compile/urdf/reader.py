"""`urdf_to_model`: URDF text -> MuJoCo `MjSpec` of one robot (`RobotModel`): the URDF is checked and
repaired (.checks, .inertia), its meshes found (.mesh_files), its `<gazebo>` tags read
(runner.compile.gazebo) and its transmissions collected (.transmissions); MuJoCo loads what is left, with
fixed links kept and visuals kept, and the Gazebo link properties are applied to the result
(.link_props)."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
from lxml import etree

from runner.compile.gazebo import GazeboInfo, parse, read_gazebo
from runner.compile.gazebo.info import Spawn
from runner.compile.locate import Locator
from runner.compile.packages import PackageMap
from runner.compile.urdf.checks import DescriptionError, check_numbers, check_structure, drop_empty_shapes
from runner.compile.urdf.inertia import repair_inertias, weigh_massless_links
from runner.compile.urdf.ledger import Ledger
from runner.compile.urdf.link_props import apply_link_props, self_collision
from runner.compile.urdf.mesh_files import rewrite_mesh
from runner.compile.urdf.transmissions import Transmission, read_transmissions, velocity_limits
from runner.compile.urdf.world_link import WorldLink, world_root
from runner.errors import Notices
from runner.plan import ParityLine

# URDF visuals are geom group 1 (MuJoCo's import); collisions go to group 3, which cameras do not draw
# (MuJoCo renders groups 0-2 by default), as in MuJoCo Menagerie models.
COLLISION_GROUP = 3


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
    world: WorldLink | None = None  # the description's root link is `world`: it welds the robot (`root`)
    velocity_limits: dict[str, float] = field(default_factory=dict)  # joint -> URDF <limit velocity>


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
    origins: list[tuple[Path, int] | None] | None = None,
    timestep: float = 0.002,
    controllers: list[Path] | None = None,
    spawn: Spawn | None = None,
) -> RobotModel:
    notices = notices if notices is not None else Notices()
    base_dir = file.parent if file else Path.cwd()
    where = Locator(file, sources or ([file] if file else []), expanded, origins)
    root = _parse(urdf, file, expanded, where)
    where.bind(root)
    root_link = check_structure(root, where)
    check_numbers(root, where)
    Ledger(where, notices).sweep(root)  # what nothing here reads, said at its line
    adjusted: list[ParityLine] = []
    world = world_root(root, root_link, where, notices, adjusted)
    repair_inertias(root, where, notices, adjusted)
    drop_empty_shapes(root, where, notices, adjusted)

    shell: set[str] = set()  # mesh files without a volume (flat or tiny): MuJoCo weighs them as shells
    meshes = [m for m in root.iter("mesh") if m.getparent() is not None and m.getparent().tag == "geometry"]
    for mesh in meshes:  # a list: a mesh that cannot be had takes its <visual> out of the tree
        rewrite_mesh(mesh, packages, base_dir, where, notices, shell)
    weigh_massless_links(root, where, notices, adjusted)

    gazebo = read_gazebo(
        root,
        file,
        sources=sources or ([file] if file else []),
        expanded=expanded,
        namespace=namespace,
        model=model or namespace,
        notices=notices,
        controllers=controllers,
        spawn=spawn,
        where=where,
    )
    transmissions = read_transmissions(root, where, notices, controllers)
    vlimits = velocity_limits(root)
    spec = _load(root, where, file, shell, notices)
    apply_link_props(spec, gazebo, timestep)
    # A root link named `world` is MuJoCo's world body: what hangs from it is welded (or jointed) to the
    # world, whatever `fixed:` says, as in Gazebo (.world_link); the robot's root is its first child.
    welded = fixed or gazebo.static or world is not None
    collide = self_collision(root, spec, gazebo, root_welded=welded, where=where)
    if world is not None:
        root_link = world.root
    elif not welded:
        spec.body(root_link).add_freejoint(name="root")
    links = [b.name for b in spec.bodies if b.name and b.name != "world"]
    joints = [j.name for j in spec.joints if j.name and j.name != "root"]
    for message, (src, line) in gazebo.dropped:
        adjusted.append(ParityLine(kind="dropped", text=message, file=str(src) if src else None, line=line))
    return RobotModel(
        spec, root_link, urdf, links, joints, gazebo, transmissions, adjusted, collide, world, vlimits
    )


def _parse(urdf: str, file: Path | None, expanded: bool, where: Any) -> Any:
    """The URDF's `<robot>` element, or an error at the line of what is not well-formed."""
    try:
        root = parse(urdf)
    except etree.XMLSyntaxError as e:
        raise DescriptionError(
            f"not well-formed XML: {' '.join(str(e.msg).split())}",
            file,
            None if expanded else e.lineno,
            hint=_malformed_hint(str(e.msg)),
        ) from None
    if root.tag != "robot":
        raise DescriptionError(
            f"the top element is <{root.tag}>, expected <robot>",
            *where(root),
            hint="an SDF file is loaded as `world: {sdf: ...}`; a `description:` is a URDF or xacro file"
            if root.tag in ("sdf", "model", "world")
            else 'a URDF starts with <robot name="...">',
        )
    return root


def _malformed_hint(msg: str) -> str:
    """What to look for, by libxml2's message."""
    if "Buffer size limit exceeded" in msg or "Huge input lookup" in msg or "XML_PARSE_HUGE" in msg:
        # (libxml2 refuses one text or attribute value past 10 MB: the file is well-formed but too large)
        return (
            "one attribute or text holds more than 10 MB, the most the XML reader takes: keep meshes and "
            "data in files of their own (a mesh's filename=), or split the generated value"
        )
    if "Document is empty" in msg or "Start tag expected" in msg:
        return 'the file is empty or not XML: a URDF starts with <?xml version="1.0"?> and <robot name="...">'
    if "mismatch" in msg or "Premature end" in msg or "not closed" in msg:
        return "every tag is closed, in order: <link ...> ... </link>, or <link .../> for an empty one"
    if "AttValue" in msg or "attributes construct" in msg or "Specification mandates value" in msg:
        return 'attribute values are quoted: <origin xyz="0 0 1"/>'
    if "Extra content" in msg:
        return "one top element <robot>: everything else goes inside it"
    if "EntityRef" in msg or "entity" in msg.lower():
        return "write & as &amp; and < as &lt; in text and attribute values"
    return "check that every tag is closed and attribute values are quoted"


def _load(root: Any, where: Any, file: Path | None, shell: set[str], notices: Notices) -> mujoco.MjSpec:
    """MuJoCo's spec of the URDF tree, with the tags it does not know taken out, fixed links and visuals
    kept, shell inertia for the meshes without a volume and collisions in `COLLISION_GROUP`. The
    description's own `<mujoco>` block (compiler, option, size: what MuJoCo's URDF reader takes from it) is
    kept, but for the three compiler settings that keep the robot as Gazebo has it."""
    for tag in ("gazebo", "transmission", "ros2_control"):
        for el in root.findall(tag):
            root.remove(el)
    blocks = root.findall("mujoco")
    for extra in blocks[1:]:  # (MuJoCo's reader takes the first)
        notices.add("a second <mujoco> block is not read: MuJoCo reads the first", *where(extra))
        root.remove(extra)
    mj = blocks[0] if blocks else etree.Element("mujoco")
    if blocks:
        root.remove(mj)
    for option in mj.findall("option"):
        notices.add(
            "the description's <mujoco><option> is not used: the world's physics are the scenario's "
            "(`world.physics`), one for every robot",
            *where(option),
        )
    compiler = mj.find("compiler")
    if compiler is None:
        compiler = etree.SubElement(mj, "compiler")
    # MuJoCo's URDF defaults fuse fixed links away and drop visuals: both kept, as Gazebo keeps them
    for key in ("discardvisual", "fusestatic", "strippath"):
        if compiler.get(key) not in (None, "false"):
            notices.add(
                f'<compiler {key}="{compiler.get(key)}"> is not used: links joined by fixed joints, visuals '
                "and mesh paths are kept, as Gazebo keeps them",
                *where(compiler),
            )
        compiler.set(key, "false")
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
    return spec


def _mujoco_error(e: ValueError, root: Any, text: str, where: Any, file: Path | None) -> DescriptionError:
    """MuJoCo's "XML Error: ... Element 'x', line N" is about the text we gave it: point at the element
    in the user's file instead (the trees are the same, element for element)."""
    message = " ".join(str(e).split("\n")[0].split()).removeprefix("XML Error: ")
    m = re.search(r"Element '([^']*)', line (\d+)", str(e))
    if m:
        tag, line = m.group(1), int(m.group(2))
        ours = [el for el in root.iter() if isinstance(el.tag, str)]
        given = [el for el in parse(text).iter() if isinstance(el.tag, str)]  # as the URDF was read
        for mine, theirs in zip(ours, given, strict=False):
            if theirs.sourceline == line and theirs.tag == tag:
                return DescriptionError(
                    f"MuJoCo cannot load this URDF: {message} (in <{tag}>)",
                    *where(mine),
                    hint="check that element's attributes: names, numbers and required children",
                )
    return DescriptionError(
        f"MuJoCo cannot load this URDF: {message}",
        file,
        hint="MuJoCo's message names what it refused; check that element's attributes and children",
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
