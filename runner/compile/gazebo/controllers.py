"""ros_control and ros2_control: the controllers a description's `gazebo_ros_control`/`gz_ros2_control`
plugin loads from the file its `<parameters>` names (or the scenario's `controllers:`, what a launch file
would load), ROS 1 and ROS 2 layouts: the diff drive controller -> `diff_drive` (or `skid_steer` with
several wheels a side), the joint state broadcaster -> `joint_states`; other controllers are said."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.info import DescribedPlugin, Where
from runner.compile.gazebo.tags import TagReader
from runner.errors import SourceError

_LAUNCH_ARG = re.compile(r"\$\(arg\s+([^)\s]+)\s*\)")


def run_controllers(g: ReaderBase, path: Path, where: Where) -> int:
    """Run the diff drive and joint state controllers of a ros_control / ros2_control controllers file
    (as `<parameters>` names it, or the scenario's `controllers:`); returns how many. Other controllers
    are said, with their type."""
    import yaml

    try:
        text = path.read_text()
    except OSError as e:
        hint = "check the path (`controllers:` in the scenario, or the description's <parameters>)"
        raise SourceError(
            f"controllers file {str(path)!r} cannot be read: {e.strerror or e}", path, hint=hint
        ) from None
    # `<rosparam subst_value="true">` substitutes launch arguments in such files: with none given here,
    # each `$(arg name)` is empty (the usual default of a `prefix`), and said
    args = sorted(set(_LAUNCH_ARG.findall(text)))
    if args:
        text = _LAUNCH_ARG.sub("", text)
        g.notices.add(
            f"controllers file: launch argument(s) {', '.join(args)} taken as empty",
            path,
            None,
            hint="write the values into a copy of the file if the robot is launched with others",
        )
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        raise SourceError(
            f"controllers file {str(path)!r} is not valid YAML: {getattr(e, 'problem', e)}",
            path,
            mark.line + 1 if mark else None,
            hint="check the indentation and the `:` after each key at this line",
        ) from None
    entries, update_rate = _controller_entries(doc)
    ros1 = not _ros_parameters(doc)
    count = 0
    for name, kind, params in entries:
        if kind.endswith("DiffDriveController"):
            type_name, drive = _diff_drive_controller(g, name, params, ros1, where)
            g.info.plugins.append(
                DescribedPlugin(
                    type_name,
                    g.unique(name),
                    {k: v for k, v in drive.items() if v is not None},
                    *where,
                )
            )
        elif kind.endswith(("JointStateBroadcaster", "JointStateController")):
            rate = params.get("publish_rate") if ros1 else update_rate
            js = {"topic": "joint_states", "joints": params.get("joints") or None, "rate": rate}
            g.info.plugins.append(
                DescribedPlugin("joint_states", g.unique(name), {k: v for k, v in js.items() if v}, *where)
            )
        else:
            g.notices.add(f"ros_control controller {name!r} ({kind}) is not run", *where)
            continue
        count += 1
    return count


def ros_control(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> None:
    """gazebo_ros_control (ROS 1): its controllers come from parameters a launch file loads, which the
    description does not name. gz_ros2_control / gazebo_ros2_control (ROS 2): `<parameters>` names the
    controllers file, whose diff drive and joint state broadcaster are run as Gazebo runs them."""
    r.mark(*[c.tag for c in r.el if isinstance(c.tag, str)])
    files = [e for e in r.children("parameters") if (e.text or "").strip().endswith((".yaml", ".yml"))]
    ran = sum(_ros2_controllers(g, r.el, e) for e in files)
    if ran or g.controller_files:  # the scenario's `controllers:` are run (read at the end)
        return None
    g.note(
        r.el,
        f"{r.el.get('filename')!r}: ros_control controllers are not run"
        + (" (no diff drive or joint state broadcaster in its <parameters>)" if files else "")
        + "; transmissions became MuJoCo actuators",
        hint="command joints with a `joint_controller` plugin in the scenario, or give the robot a "
        "`diff_drive` plugin with the controller's wheels and topics",
    )
    return None


def by_wheels(params: dict[str, Any], lefts: list[str], rights: list[str]) -> tuple[str, dict[str, Any]]:
    """A drive with one wheel a side is a diff_drive; with several, a skid_steer driving them all."""
    if len(lefts) > 1 or len(rights) > 1:
        params["left_joints"], params["right_joints"] = lefts, rights
        return "skid_steer", params
    params["left_joint"] = lefts[0] if lefts else None
    params["right_joint"] = rights[0] if rights else None
    return "diff_drive", params


def _ros_parameters(doc: Any, path: tuple[str, ...] = ()) -> dict[str, dict[str, Any]]:
    """Node name -> its `ros__parameters` in a ROS 2 parameters file (under `/**`, namespaces, or plain)."""
    out: dict[str, dict[str, Any]] = {}
    if not isinstance(doc, dict):
        return out
    for key, value in doc.items():
        if key == "ros__parameters" and isinstance(value, dict) and path:
            out[path[-1].strip("/").split("/")[-1]] = value
        elif isinstance(value, dict):
            out.update(_ros_parameters(value, (*path, str(key))))
    return out


def _param(params: dict[str, Any], dotted: str) -> Any:
    """A parameter written `a.b.c: v` or nested (`a: {b: {c: v}}`)."""
    if dotted in params:
        return params[dotted]
    node: Any = params
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _ros2_controllers(g: ReaderBase, plugin: Any, el: Any) -> int:
    """The controllers of the ros2_control parameters file a `<parameters>` names; returns how many run."""
    path = Path((el.text or "").strip())
    if not path.is_absolute():
        base = g.where(el)[0]
        path = (base.parent if base else Path.cwd()) / path
    try:
        return run_controllers(g, path, g.where(plugin))
    except SourceError as e:
        g.note(el, f"{e}; its controllers are not run")
        return 0


def _controller_entries(doc: Any) -> tuple[list[tuple[str, str, dict[str, Any]]], Any]:
    """(name, type, parameters) of each controller in a controllers file, and the update rate: ROS 2's
    (`controller_manager: ros__parameters: <name>: {type}` and `<name>: ros__parameters: {...}`, under
    `/**` or namespaces) or ROS 1's (`<name>: {type: ..., ...}`, at the top or under namespaces)."""
    nodes = _ros_parameters(doc)
    if nodes:
        manager = nodes.get("controller_manager", {})
        found = [
            (name, str(spec["type"]), nodes.get(name, {}))
            for name, spec in manager.items()
            if isinstance(spec, dict) and "type" in spec
        ]
        return found, manager.get("update_rate")
    found = []

    def walk(node: Any) -> None:
        if not isinstance(node, dict):
            return
        for key, value in node.items():
            if isinstance(value, dict) and isinstance(value.get("type"), str):
                found.append((str(key), value["type"], value))
            elif isinstance(value, dict):
                walk(value)

    walk(doc)
    return found, None


def _diff_drive_controller(
    g: ReaderBase, name: str, p: dict[str, Any], ros1: bool, where: Where
) -> tuple[str, dict[str, Any]]:
    """diff_drive_controller/DiffDriveController as it runs in Gazebo. ROS 1: `left_wheel`/`right_wheel`
    (a joint or a list), `<name>/cmd_vel` (Twist); separation and radius from the URDF unless given. ROS 2
    (Humble to Jazzy): `left_wheel_names`/`right_wheel_names`, `<name>/cmd_vel` (TwistStamped) or, with
    `use_stamped_vel: false`, `<name>/cmd_vel_unstamped` (Twist). Both: `<name>/odom` at `publish_rate`,
    `/tf` when `enable_odom_tf`, stopping `cmd_vel_timeout` (0.5 s) after the last command, multipliers."""

    def names(*keys: str) -> list[str]:
        for key in keys:
            value = _param(p, key)
            if value:
                return [str(v) for v in value] if isinstance(value, list) else [str(value)]
        return []

    lefts, rights = names("left_wheel_names", "left_wheel"), names("right_wheel_names", "right_wheel")
    sep, radius = _param(p, "wheel_separation"), _param(p, "wheel_radius")
    stamped = False if ros1 else _param(p, "use_stamped_vel") is not False
    if stamped:
        g.notices.add(
            f"ros2_control diff drive {name!r} takes geometry_msgs/TwistStamped on {name}/cmd_vel; here it "
            "takes geometry_msgs/Twist there",
            *where,
            hint="set use_stamped_vel: false in the controllers file to have it as Gazebo then has it "
            f"({name}/cmd_vel_unstamped, Twist)",
        )
    params: dict[str, Any] = {
        "wheel_separation": float(sep) if sep else None,
        "wheel_radius": float(radius) if radius else None,
        "wheel_separation_multiplier": float(_param(p, "wheel_separation_multiplier") or 1.0),
        "wheel_radius_multiplier": float(
            _param(p, "wheel_radius_multiplier") or _param(p, "left_wheel_radius_multiplier") or 1.0
        ),
        "rate": float(_param(p, "publish_rate") or 50.0),
        "cmd_topic": f"{name}/cmd_vel_unstamped" if not ros1 and not stamped else f"{name}/cmd_vel",
        "odom_topic": f"{name}/odom",
        "tf_topic": "tf",
        "publish_tf": _param(p, "enable_odom_tf") is not False,
        "odom_frame": _param(p, "odom_frame_id") or "odom",
        "base_frame": g.frame(_param(p, "base_frame_id") or "base_link"),
        "cmd_timeout": float(_param(p, "cmd_vel_timeout") or 0.5),
    }
    accel = _param(p, "linear.x.max_acceleration")
    if accel and radius and _param(p, "linear.x.has_acceleration_limits"):
        params["max_wheel_acceleration"] = float(accel) / float(radius)
    return by_wheels(params, lefts, rights)
