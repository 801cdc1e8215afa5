"""URDF text -> MuJoCo `MjSpec` of one robot, with the traps of MuJoCo's URDF import handled.

- `fusestatic`/`discardvisual` are off, so fixed-joint links (lidar_link, imu_link) stay bodies a sensor
  can be mounted on and visuals are kept (group 1, no collision);
- mesh URIs (`package://`, `model://`, `file://`, relative) are rewritten to real paths;
- `<gazebo reference="link">` friction (`mu1`/`mu2`) is applied to the link's collision geoms;
- a mobile robot's root link gets a free joint.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import mujoco

from runner.compile.packages import PackageMap, resolve_uri
from runner.errors import SourceError


class DescriptionError(SourceError):
    """The URDF itself is wrong."""


@dataclass
class RobotModel:
    spec: mujoco.MjSpec
    root: str
    urdf: str
    links: list[str] = field(default_factory=list)
    joints: list[str] = field(default_factory=list)


_JOINT_TYPES = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"}


def _float(text: str | None, default: float | None = None) -> float | None:
    try:
        return float(text) if text is not None else default
    except ValueError:
        return default


def _check_structure(root: ET.Element, file: Path | None) -> str:
    """Checks MuJoCo would report badly or not at all; returns the root link's name."""
    links = [el.get("name") for el in root.findall("link")]
    if not links:
        raise DescriptionError("the URDF has no <link>", file, hint="a robot needs at least one link")
    for name in links:
        if not name:
            raise DescriptionError("a <link> has no name", file)
    dupes = {n for n in links if links.count(n) > 1}
    if dupes:
        raise DescriptionError(f"link {sorted(dupes)[0]!r} is defined twice", file)
    children: set[str] = set()
    for j in root.findall("joint"):
        jname = j.get("name") or "?"
        jtype = j.get("type")
        if jtype not in _JOINT_TYPES:
            raise DescriptionError(
                f"joint {jname!r} has type {jtype!r}",
                file,
                hint="URDF joint types: " + ", ".join(sorted(_JOINT_TYPES)),
            )
        for tag in ("parent", "child"):
            el = j.find(tag)
            ref = el.get("link") if el is not None else None
            if ref not in links:
                raise DescriptionError(
                    f"joint {jname!r} names {tag} link {ref!r}, which is not defined",
                    file,
                    hint="defined links: " + ", ".join(n for n in links if n),
                )
        children.add(j.find("child").get("link"))  # type: ignore[union-attr]
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        raise DescriptionError(
            f"the URDF must form one tree, found {len(roots)} root links: {', '.join(map(str, roots))}",
            file,
            hint="every link but one must be the child of a joint",
        )
    return str(roots[0])


def urdf_to_model(urdf: str, file: Path | None, packages: PackageMap, *, fixed: bool = False) -> RobotModel:
    base_dir = file.parent if file else Path.cwd()
    try:
        root = ET.fromstring(urdf)
    except ET.ParseError as e:
        raise DescriptionError(f"not well-formed XML: {e}", file, e.position[0]) from None
    if root.tag != "robot":
        raise DescriptionError(f"the top element is <{root.tag}>, expected <robot>", file)
    root_link = _check_structure(root, file)

    # Meshes: rewrite every filename to an absolute path that exists.
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename", "")
        path = resolve_uri(uri, packages, base_dir)
        if path is None:
            pkg = uri.split("/")[2] if "://" in uri else uri
            raise DescriptionError(
                f"mesh {uri!r}: package {pkg!r} not found",
                file,
                hint="add it under `packages:` in the scenario; searched: " + ", ".join(packages.searched()),
            )
        if not path.is_file():
            raise DescriptionError(f"mesh {uri!r} not found (looked at {path})", file)
        mesh.set("filename", str(path.resolve()))

    # <gazebo reference="link"> friction; MuJoCo ignores <gazebo>, so we read it here.
    friction: dict[str, float] = {}
    for gz in root.findall("gazebo"):
        ref = gz.get("reference")
        if not ref:
            continue
        mu1 = _float(gz.findtext("mu1"))
        mu2 = _float(gz.findtext("mu2"))
        mus = [m for m in (mu1, mu2) if m is not None]
        if mus:
            friction[ref] = min(mus)

    # MuJoCo's URDF defaults fuse fixed links away and drop visuals: turn both off.
    for old in root.findall("mujoco"):
        root.remove(old)
    mj = ET.Element("mujoco")
    ET.SubElement(mj, "compiler", {"discardvisual": "false", "fusestatic": "false", "strippath": "false"})
    root.insert(0, mj)
    text = ET.tostring(root, encoding="unicode")
    try:
        spec = mujoco.MjSpec.from_string(text)
    except ValueError as e:
        raise DescriptionError(f"MuJoCo cannot load this URDF: {e}", file) from None

    for link, mu in friction.items():
        body = spec.body(link)
        if body is None:
            continue
        for geom in body.geoms:
            if geom.contype or geom.conaffinity:
                # MuJoCo takes the larger friction of two touching geoms, Gazebo the smaller: give the
                # geom priority so that its own value is used (a caster's mu1=0 must stay 0).
                geom.friction = [mu, geom.friction[1], geom.friction[2]]
                geom.priority = 1

    body = spec.body(root_link)
    if not fixed:
        body.add_freejoint(name="root")
    links = [b.name for b in spec.bodies if b.name and b.name != "world"]
    joints = [j.name for j in spec.joints if j.name and j.name != "root"]
    return RobotModel(spec, root_link, urdf, links, joints)
