"""What is wrong in a URDF before MuJoCo sees it: its structure (one tree of uniquely named links and
joints of known types), its numbers (no NaN, no infinity but in limits), and shapes of zero size (left out
with a warning, as Gazebo loads them and MuJoCo refuses them). `DescriptionError` is the error of a URDF
that is itself wrong, at the line of the element."""

from __future__ import annotations

import math
from typing import Any

from runner.errors import Notices, SourceError, closest
from runner.plan import ParityLine


class DescriptionError(SourceError):
    """The URDF itself is wrong."""


_JOINT_TYPES = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"}


def number(text: str, what: str, where: Any, el: Any) -> float:
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


def check_numbers(root: Any, where: Any) -> None:
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


def check_structure(root: Any, where: Any) -> str:
    """Checks MuJoCo would report badly or not at all; returns the root link's name."""
    link_els = root.findall("link")
    if not link_els:
        raise DescriptionError("the URDF has no <link>", *where(root), hint="a robot needs at least one link")
    links: list[str] = []
    for el in link_els:
        name = el.get("name")
        if not name:
            raise DescriptionError(
                "a <link> has no name", *where(el), hint='give it one: <link name="base_link">'
            )
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
        if not j.get("name"):
            raise DescriptionError(
                "a <joint> has no name", *where(j), hint='give it one: <joint name="wheel_joint" type="...">'
            )
        jname = j.get("name")
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
            near = closest(jtype, _JOINT_TYPES) if jtype else None
            raise DescriptionError(
                f"joint {jname!r} has type {jtype!r}" if jtype else f"joint {jname!r} has no type",
                *where(j),
                hint=(f"did you mean {near!r}? " if near else "")
                + "URDF joint types: "
                + ", ".join(sorted(_JOINT_TYPES)),
            )
        for tag in ("parent", "child"):
            el = j.find(tag)
            ref = el.get("link") if el is not None else None
            if el is None or not ref:
                raise DescriptionError(
                    f"joint {jname!r} has no <{tag} link=...>"
                    if el is None
                    else f"its <{tag}> names no link",
                    *where(j if el is None else el),
                    hint=f'add <{tag} link="..."/> naming one of: ' + ", ".join(links),
                )
            if ref not in links:
                near = closest(ref, links)
                raise DescriptionError(
                    f"joint {jname!r} names {tag} link {ref!r}, which is not defined",
                    *where(el),
                    hint=(f"did you mean {near!r}? " if near else "") + "defined links: " + ", ".join(links),
                )
        child = j.find("child").get("link")
        if child in children:
            raise DescriptionError(
                f"link {child!r} is the child of two joints ({children[child]!r} and {jname!r})",
                *where(j),
                hint="a link has one parent joint: the robot is a tree; rename one joint's <child> link",
            )
        children[child] = jname
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        raise DescriptionError(
            f"the URDF must form one tree, found {len(roots)} root links: {', '.join(roots)}",
            *where(root),
            hint="every link but one must be the child of a joint",
        )
    check_depth(root, roots[0], children, joint_lines, where)
    return roots[0]


# MuJoCo refuses a kinematic tree deeper than this ("depth limit exceeded in signature computation",
# measured with mujoco 3.17: a chain of 1023 bodies below the world compiles, 1024 does not). Each URDF link
# is a body (fixed links are kept), so this is the longest chain of links. MuJoCo finds it only after its
# compile has gone through the tree's joints: minutes for a few thousand hinges, against milliseconds here.
MAX_TREE_DEPTH = 1023


def check_depth(
    root: Any, root_link: str, children: dict[str, str], joints: dict[str, Any], where: Any
) -> None:
    """The longest chain of links against MuJoCo's depth limit, before MuJoCo is asked."""
    parent_of = {}
    for j in joints.values():
        parent_of[j.find("child").get("link")] = j.find("parent").get("link")
    depth: dict[str, int] = {root_link: 1}
    for link in parent_of:  # each link's depth, the chain above it walked once (iteratively: no recursion)
        chain = []
        x = link
        while x not in depth:
            chain.append(x)
            x = parent_of.get(x)
            if x is None or len(chain) > len(parent_of):
                return  # a loop or a second root: check_structure says so
        d = depth[x]
        for y in reversed(chain):
            d += 1
            depth[y] = d
    deepest = max(depth, key=depth.__getitem__)
    if depth[deepest] > MAX_TREE_DEPTH:
        first = MAX_TREE_DEPTH + 1
        joint = next(j for j in joints.values() if depth.get(j.find("child").get("link")) == first)
        raise DescriptionError(
            f"the chain of links from {root_link!r} to {deepest!r} is {depth[deepest]} links deep; MuJoCo "
            f"compiles a tree at most {MAX_TREE_DEPTH} bodies deep (this joint's child is the first past it)",
            *where(joint),
            hint="join links that never move relative to each other into one link (their shapes as several "
            "<collision>/<visual> of it), or describe the chain as several robots",
        )


# The dimensions of each URDF shape (attribute, how many numbers)
_SHAPE_SIZES = {
    "box": ("size", 3),
    "cylinder": ("radius", 1),
    "sphere": ("radius", 1),
    "capsule": ("radius", 1),
}


def drop_empty_shapes(root: Any, where: Any, notices: Notices, adjusted: list[ParityLine]) -> None:
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


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
