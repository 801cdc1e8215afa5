"""ros_control and ros2_control: the controllers a description's `gazebo_ros_control`/`gz_ros2_control`
plugin loads from the file its `<parameters>` names (or the scenario's `controllers:`, what a launch file
would load), ROS 1 and ROS 2 layouts: the diff drive controller -> `diff_drive` (or `skid_steer` with
several wheels a side), the joint state broadcaster -> `joint_states`; other controllers are said."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.control import ControlContext, ControllerSpec, handler_for
from runner.compile.gazebo.info import Where
from runner.compile.gazebo.tags import TagReader
from runner.errors import SourceError

_LAUNCH_ARG = re.compile(r"\$\(arg\s+([^)\s]+)\s*\)")


def run_controllers(g: ReaderBase, path: Path, where: Where, remap: dict[str, str] | None = None) -> int:
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
    ctx = ControlContext(g, where, dict(remap or {}))
    count = 0
    for name, kind, params in entries:
        spec = ControllerSpec(name, kind, params, path, None, ros1, update_rate)
        handler = handler_for(kind)
        if handler is None:
            g.notices.add(f"ros_control controller {name!r} ({kind}) is not run", *where)
            continue
        if handler(ctx, spec):
            count += 1
    return count


def ros_control(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> None:
    """gazebo_ros_control (ROS 1): its controllers come from parameters a launch file loads, which the
    description does not name. gz_ros2_control / gazebo_ros2_control (ROS 2): `<parameters>` names the
    controllers file, whose diff drive and joint state broadcaster are run as Gazebo runs them."""
    r.mark(*[c.tag for c in r.el if isinstance(c.tag, str)])
    files = [e for e in r.children("parameters") if (e.text or "").strip().endswith((".yaml", ".yml"))]
    ran = sum(_ros2_controllers(g, r.el, e, remap) for e in files)
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


def _ros2_controllers(g: ReaderBase, plugin: Any, el: Any, remap: dict[str, str]) -> int:
    """The controllers of the ros2_control parameters file a `<parameters>` names; returns how many run."""
    path = Path((el.text or "").strip())
    if not path.is_absolute():
        base = g.where(el)[0]
        path = (base.parent if base else Path.cwd()) / path
    try:
        return run_controllers(g, path, g.where(plugin), remap)
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
