"""What of a URDF is read, and what is said: every element and attribute of the robot's own URDF (links,
joints, materials, the `<mujoco>` block) is read by MuJoCo's URDF reader or by ours, or it is reported at
its own file:line with what Gazebo does with it. `<gazebo>`, `<transmission>` and `<ros2_control>` blocks
belong to their own readers (runner.compile.gazebo, runner.compile.urdf.transmissions), which report what
they leave.

`READ` is the URDF as it is read here, element by element: MuJoCo's reader (mujoco src/xml/xml_urdf.cc at
a7255075: `<mujoco>` 94-105, `<robot name>` 115, links 234-362, joints 383-520 (`velocity` commented out
at 511: MuJoCo has no velocity limit), geometry 530-600, origins 658-670, materials 748-760) and ours
(`limit velocity`: the hardware's velocity limits; `mimic`: an equality constraint, both in
runner.compile.urdf.transmissions; shape names: runner.compile.urdf.reader). A reader that starts reading
something new adds it here, beside the reason it was said before.
"""

from __future__ import annotations

from typing import Any

from runner.errors import Notices

# element -> (its attributes read, its child elements read)
Spec = tuple[frozenset[str], dict[str, Any]]


def _s(attrs: str = "", children: dict[str, Any] | None = None) -> Spec:
    return frozenset(attrs.split()), children or {}


_ORIGIN = _s("xyz rpy")
_GEOMETRY = _s(
    "",
    {
        "box": _s("size"),
        "cylinder": _s("radius length"),
        "sphere": _s("radius"),
        "capsule": _s("radius length"),  # (not URDF's, but MuJoCo's reader and Gazebo's read it)
        "mesh": _s("filename scale"),
    },
)
_MATERIAL = _s("name", {"color": _s("rgba")})
READ: dict[str, Spec] = {
    "robot": _s(
        "name",
        {
            "link": _s(
                "name",
                {
                    "inertial": _s(
                        "",
                        {
                            "origin": _ORIGIN,
                            "mass": _s("value"),
                            "inertia": _s("ixx iyy izz ixy ixz iyz"),
                        },
                    ),
                    "visual": _s("name", {"origin": _ORIGIN, "geometry": _GEOMETRY, "material": _MATERIAL}),
                    "collision": _s("name", {"origin": _ORIGIN, "geometry": _GEOMETRY}),
                },
            ),
            "joint": _s(
                "name type",
                {
                    "origin": _ORIGIN,
                    "parent": _s("link"),
                    "child": _s("link"),
                    "axis": _s("xyz"),
                    "dynamics": _s("damping friction"),
                    "limit": _s("lower upper effort velocity"),
                    "mimic": _s("joint multiplier offset"),
                },
            ),
            "material": _MATERIAL,
            "mujoco": _s("", {"compiler": _s("*"), "option": _s("*"), "size": _s("*")}),
        },
    )
}

# blocks that have readers of their own, which say what they leave
OWN_READERS = {"gazebo", "transmission", "ros2_control"}

# What Gazebo (its URDF reader, sdformat's parser_urdf.cc, and gazebo_ros) does with what is not read here
GAZEBO_DOES = {
    "safety_controller": "Gazebo ignores it too (a real robot's controller limits; sdformat does not read "
    "it)",
    "calibration": "Gazebo ignores it too (sdformat does not read it)",
    "texture": "Gazebo does not read a URDF material's texture either: textures come from <gazebo><material>",
    "version": "the URDF format version: nothing reads it",
    "type": "not a URDF attribute of this element",
    "sensor": "URDF <sensor> elements are not read by Gazebo either: a sensor goes in a <gazebo "
    "reference> block",
}


class Ledger:
    """Walks the URDF as `READ` says it is read, and says what nothing reads."""

    def __init__(self, where: Any, notices: Notices):
        self.where = where
        self.notices = notices
        self.said = 0

    def sweep(self, root: Any) -> None:
        self._walk(root, READ["robot"], "robot")

    def _walk(self, el: Any, spec: Spec, path: str) -> None:
        attrs, children = spec
        if "*" not in attrs:
            for name in el.attrib:
                if name not in attrs and not name.startswith("{"):  # (xmlns declarations, xacro's own)
                    self._say(el, f'the attribute {name}="{el.get(name)}" of <{el.tag}> ({path})', name)
        for child in el:
            if not isinstance(child.tag, str):
                continue
            tag = child.tag
            if path == "robot" and tag in OWN_READERS:
                continue
            sub = children.get(tag)
            if sub is None:
                self._say(child, f"<{tag}> in <{el.tag}> ({path})", tag)
                continue
            self._walk(child, sub, f"{path}/{tag}")

    def _say(self, el: Any, what: str, key: str) -> None:
        reason = GAZEBO_DOES.get(key, "Gazebo's URDF reader does not read it either")
        file, line = self.where(el)
        self.notices.add(f"{what} is not read: {reason}", file, line)
        self.said += 1
