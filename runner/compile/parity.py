"""A robot "as in Gazebo": what its description's Gazebo tags became, for `scenario validate`.

Per robot, one line each: the drives and the wheels they drive, the sensors with their topics and rates,
self-collision (Gazebo's rule, off unless the description says so), and what had to be changed or was left
out to load it (repaired inertias, blocks naming links the expanded URDF lacks, tags we do not act on), each
with the file and line it comes from.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from runner.compile.wheels import wheel_joints
from runner.errors import RATE_CAPPED, Notice
from runner.plan import ParityLine, PluginPlan

if TYPE_CHECKING:
    from runner.compile.urdf import RobotModel

_DRIVES = {"diff_drive", "skid_steer", "planar_move"}
_SENSORS = {
    "lidar",
    "camera",
    "depth_camera",
    "imu",
    "contact",
    "gps",
    "magnetometer",
    "air_pressure",
    "altimeter",
    "force_torque",
}


def _line(kind: str, text: str, where: tuple[str | None, int | None] = (None, None)) -> ParityLine:
    return ParityLine(kind=kind, text=text, file=where[0], line=where[1])


def _hz(rate: float | None) -> str:
    return f" @ {rate:g} Hz" if rate else ""


def _topics(p: PluginPlan, direction: str, ns_prefix: str) -> list[str]:
    out = []
    for t in p.topics:
        if t.direction == direction:
            out.append(t.key.split(ns_prefix, 1)[-1] if ns_prefix in t.key else t.key)
    return out


def _wheels(params: dict[str, Any]) -> str:
    left, right = wheel_joints(params)
    return f"left {', '.join(left)}; right {', '.join(right)}"


def summarize(
    model: RobotModel, plugins: list[PluginPlan], robot_notices: list[Notice], ns_prefix: str
) -> list[ParityLine]:
    """The "as in Gazebo" lines of one robot (`ns_prefix`: `<run>/<ns>/`, cut from topic keys)."""
    out: list[ParityLine] = []
    for p in plugins:
        if p.type not in _DRIVES and p.type not in _SENSORS:
            continue
        where = (p.source_file, p.source_line)
        subs, pubs = _topics(p, "sub", ns_prefix), _topics(p, "pub", ns_prefix)
        flow = (", ".join(subs) + " -> " if subs else "") + ", ".join(pubs)
        if p.type in _DRIVES:
            wheels = f"wheels {_wheels(p.params)}; " if p.type != "planar_move" else ""
            control = (
                f" (control {p.control_rate:g} Hz)" if p.control_rate and p.control_rate != p.rate else ""
            )
            feedback = "; yaw-rate feedback on" if p.params.get("yaw_rate_feedback") else ""
            out.append(
                _line("drive", f"{p.type} {p.name!r}: {wheels}{flow}{_hz(p.rate)}{control}{feedback}", where)
            )
        else:
            link = p.params.get("link")
            out.append(
                _line(
                    "sensor",
                    f"{p.type} {p.name!r}" + (f" on {link}" if link else "") + f": {flow}{_hz(p.rate)}",
                    where,
                )
            )
    gz = model.gazebo
    if model.self_collision:
        at = (
            gz.self_collide_at
            if gz.self_collide
            else next(
                (gz.links[n].self_collide_at for n in model.self_collision if n in gz.links), (None, None)
            )
        )
        out.append(
            _line(
                "collide",
                "self-collision on for "
                + ", ".join(model.self_collision)
                + " (links joined by a joint, or by "
                "fixed joints into one Gazebo link, never collide)",
                (str(at[0]) if at[0] else None, at[1]),
            )
        )
    else:
        out.append(_line("collide", "self-collision off: Gazebo's default (no <self_collide>/<selfCollide>)"))
    out += model.adjusted  # their warnings are among the robot's notices: not listed twice
    shown = {line.text for line in model.adjusted}
    for n in robot_notices:
        if n.message in shown:
            continue
        file = str(n.location.file) if n.location.file else None
        label = "rate" if n.kind == RATE_CAPPED else "ignored"
        out.append(_line(label, n.message, (file, n.location.line)))
    return out
