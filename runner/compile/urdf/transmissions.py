"""Joints that get actuators: `<transmission>` (ROS 1 style, with its hardware interface and mechanical
reduction) and `<ros2_control>` joints (by their command interface)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

from runner.errors import Notices


@dataclass
class Transmission:
    joint: str
    interface: Literal["position", "velocity", "effort"]
    reduction: float = 1.0


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


def read_transmissions(root: Any, where: Any, notices: Notices) -> list[Transmission]:
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
