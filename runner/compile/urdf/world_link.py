"""A URDF whose root link is named `world` (joint `world` -> `base_link`, fixed): the robot is welded to the
world, as Gazebo's URDF import does it (sdformat `src/parser_urdf.cc`, `URDF2SDF::InitModelString`: a root
link named "world" is not converted, each of its children is, and `CreateJoint` joins a child to the world
with its joint; the first joint below the world is never lumped, `ReduceFixedJoints`).

MuJoCo's URDF import makes such a link its world body, so the rest of the robot hangs from the world where
the scenario places it. This module finds that case (`world_root`), says what Gazebo leaves out of the world
link (its inertia, visuals and collisions: `CreateSDF` starts at its children) and gives the compiler the
robot's real root (the first child of the world link) and the pose of that child in the world link, from
which the TF frame `<ns>/world` of the description's world link is placed (docs/ros2_control.md, "World-fixed
robots")."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from runner.compile.urdf.checks import DescriptionError
from runner.errors import Notices
from runner.geometry import rpy_to_quat
from runner.plan import ParityLine

WORLD_LINK = "world"


@dataclass
class WorldLink:
    """The description's `world` root link: the link that stands for the world below it."""

    root: str  # the first child of the world link: the robot's base, welded (or jointed) to the world
    joint: str  # the joint from the world link to `root`
    joint_type: str
    origin: list[float]  # `root` in the world link's frame: x, y, z, qw, qx, qy, qz
    file: Any
    line: int | None


def world_root(
    root: Any, root_link: str, where: Any, notices: Notices, adjusted: list[ParityLine]
) -> WorldLink | None:
    """The world link of a description whose root link is `world`, else None. A `world` link anywhere else
    in the tree is an error at its line: MuJoCo would make it its world body (welding the robot by a leaf),
    while Gazebo lumps it into its parent like any fixed child."""
    if root_link != WORLD_LINK:
        inner = next((el for el in root.findall("link") if el.get("name") == WORLD_LINK), None)
        if inner is not None:
            raise DescriptionError(
                f"a link named {WORLD_LINK!r} is not the root link (the root is {root_link!r})",
                *where(inner),
                hint="a URDF fixes a robot to the world with a root link named `world` and a fixed joint "
                'from it to the base (<parent link="world"/><child link="base_link"/>); rename this '
                "link, or reverse that joint, or weld the robot with `fixed: true` in the scenario",
            )
        return None
    below = [j for j in root.findall("joint") if j.find("parent").get("link") == WORLD_LINK]
    link_el = next(el for el in root.findall("link") if el.get("name") == WORLD_LINK)
    if not below:
        raise DescriptionError(
            f"the description has only the link {WORLD_LINK!r}: nothing to simulate",
            *where(link_el),
            hint="the link named `world` stands for the world: join the robot's base to it with a joint",
        )
    _drop_world_contents(link_el, where, notices, adjusted)
    first = below[0]
    origin = first.find("origin")
    xyz = _floats(origin.get("xyz") if origin is not None else None)
    rpy = _floats(origin.get("rpy") if origin is not None else None)
    file, line = where(first)
    return WorldLink(
        root=first.find("child").get("link"),
        joint=first.get("name"),
        joint_type=first.get("type"),
        origin=[*xyz, *(float(q) for q in rpy_to_quat(rpy))],
        file=file,
        line=line,
    )


def _floats(text: str | None) -> list[float]:
    values = [float(v) for v in (text or "").split()]  # (check_numbers has checked them)
    return values if len(values) == 3 else [0.0, 0.0, 0.0]


def _drop_world_contents(link: Any, where: Any, notices: Notices, adjusted: list[ParityLine]) -> None:
    """Gazebo does not make a link of `world` (`CreateSDF` starts at its children): its `<inertial>`,
    `<visual>`s and `<collision>`s are not in the model. MuJoCo would add its shapes to the ground."""
    dropped = [el for el in link if isinstance(el.tag, str) and el.tag in ("inertial", "visual", "collision")]
    if not dropped:
        return
    tags = ", ".join(sorted({f"<{el.tag}>" for el in dropped}))
    at = where(dropped[0])
    message = (
        f"link {WORLD_LINK!r}: its {tags} left out (the root link named `world` is the world: Gazebo's URDF "
        "import makes no link of it)"
    )
    notices.add(message, *at, hint="move them to a link below `world` to have them in the simulation")
    for el in dropped:
        link.remove(el)
    file, line = at
    adjusted.append(ParityLine(kind="dropped", text=message, file=str(file) if file else None, line=line))
