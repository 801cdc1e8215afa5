"""Controller parameters as data, as ros2_controllers' generate_parameter_library files
(`<controller>/src/<controller>_parameters.yaml`) and ros_controllers' documented parameters give them: each
type's parameters with their defaults (`TABLES`). A handler reads its controller's parameters with `read`
(defaults filled in) and `check` says, at its own line, each parameter the block gives that the type does
not have (the controller would never read it).

`Block` is a mapping of a controllers file (a plain dict) that also knows the line of each of its keys."""

from __future__ import annotations

import fnmatch
from collections.abc import Iterator
from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, param


class Block(dict):  # type: ignore[type-arg]
    """A YAML mapping of a controllers file, with the 1-based line of each key (`lines`)."""

    lines: dict[Any, int]
    inherited: set[Any]  # keys a wildcard node's block gave it (every node gets them)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.lines = {}
        self.inherited = set()


def line_of(params: Any, dotted: str) -> int | None:
    """The line of a parameter written `a.b.c: v` or nested, when its block knows it."""
    lines = getattr(params, "lines", None)
    if lines is None:
        return None
    if dotted in params:
        return lines.get(dotted)
    head, _, rest = dotted.partition(".")
    if head in params and rest:
        return line_of(params[head], rest) or lines.get(head)
    return lines.get(head)


def flat(params: Any, prefix: str = "") -> Iterator[tuple[str, int | None]]:
    """(dotted name, line) of every leaf parameter of a block (a non-empty mapping is a parameter namespace,
    as in ROS 2 parameter files)."""
    if not isinstance(params, dict):
        return
    lines = getattr(params, "lines", {})
    inherited = getattr(params, "inherited", set())
    for key, value in params.items():
        if key in inherited:
            continue
        name = f"{prefix}{key}"
        if isinstance(value, dict) and value:
            yield from flat(value, name + ".")
        else:
            yield name, lines.get(key)


# controller_interface's own parameters, which every ROS 2 controller has (controller_interface_base.cpp:
# update_rate, is_async, thread_priority), the spawner's (type, params_file, fallback_controllers), rclcpp's
COMMON = ("type", "update_rate", "is_async", "thread_priority", "params_file", "fallback_controllers")
NODE = (
    "use_sim_time",
    "qos_overrides.*",
    "use_global_arguments",
    "enable_rosout",
    "start_type_description_service",
)

# type -> {parameter: default}. ROS 2 from ros2_controllers (Humble and Jazzy), ROS 1 from ros_controllers
# (Noetic). `*` stands for any name (a joint's).
_JSB = {
    "use_local_topics": False,
    "joints": [],
    "extra_joints": [],
    "interfaces": [],
    "map_interface_to_joint_state.position": "position",
    "map_interface_to_joint_state.velocity": "velocity",
    "map_interface_to_joint_state.effort": "effort",
    "use_urdf_to_filter": True,  # Jazzy
    "frame_id": "base_link",
    "publish_dynamic_joint_states": True,
}
_FORWARD = {"joints": [], "interface_name": ""}
_GROUP = {"joints": []}
_ROS1_JOINT = {"joint": ""}
_ROS1_PID = {
    "joint": "",
    "pid.p": 0.0,
    "pid.i": 0.0,
    "pid.d": 0.0,
    "pid.i_clamp": 0.0,
    "pid.i_clamp_min": 0.0,
    "pid.i_clamp_max": 0.0,
    "pid.antiwindup": False,
    "pid.publish_state": False,
}
TABLES: dict[str, dict[str, Any]] = {
    "joint_state_broadcaster/JointStateBroadcaster": _JSB,
    "joint_state_controller/JointStateController": {"publish_rate": None, "extra_joints": []},
    "imu_sensor_broadcaster/IMUSensorBroadcaster": {
        "sensor_name": "",
        "frame_id": "",
        "static_covariance_orientation": [0.0] * 9,
        "static_covariance_angular_velocity": [0.0] * 9,
        "static_covariance_linear_acceleration": [0.0] * 9,
    },
    "force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster": {
        "sensor_name": "",
        "interface_names.force.x": "",
        "interface_names.force.y": "",
        "interface_names.force.z": "",
        "interface_names.torque.x": "",
        "interface_names.torque.y": "",
        "interface_names.torque.z": "",
        "frame_id": "",
    },
    "forward_command_controller/ForwardCommandController": _FORWARD,
    "forward_command_controller/MultiInterfaceForwardCommandController": {"joint": "", "interface_names": []},
    "position_controllers/JointGroupPositionController": _GROUP,
    "velocity_controllers/JointGroupVelocityController": _GROUP,
    "effort_controllers/JointGroupEffortController": _GROUP,
    # ROS 1 (ros_controllers, Noetic): forward_command_controller's families and the PID ones
    "position_controllers/JointPositionController": _ROS1_JOINT,
    "velocity_controllers/JointVelocityController": _ROS1_JOINT,
    "effort_controllers/JointEffortController": _ROS1_JOINT,
    "effort_controllers/JointPositionController": _ROS1_PID,
    "effort_controllers/JointVelocityController": _ROS1_PID,
    "effort_controllers/JointGroupPositionController": {
        "joints": [],
        "*.pid.p": 0.0,
        "*.pid.i": 0.0,
        "*.pid.d": 0.0,
        "*.pid.i_clamp": 0.0,
        "*.pid.i_clamp_min": 0.0,
        "*.pid.i_clamp_max": 0.0,
        "*.pid.antiwindup": False,
    },
}


def known(table: dict[str, Any], name: str, ros1: bool) -> bool:
    patterns = (*table, *COMMON, *NODE) if not ros1 else (*table, "type")
    return any(fnmatch.fnmatchcase(name, p) for p in patterns)


def check(ctx: ControlContext, spec: ControllerSpec, table: dict[str, Any] | None = None) -> None:
    """Say each parameter of the controller's block that its type does not read, at its line."""
    table = TABLES.get(spec.type.replace("::", "/"), {}) if table is None else table
    for name, line in flat(spec.params):
        if not known(table, name, spec.ros1):
            ctx.g.notices.add(
                f"controller {spec.name!r} ({spec.type}): parameter {name!r} is not one of its parameters: "
                "the controller does not read it",
                spec.file,
                line or spec.line,
                hint="its parameters: " + ", ".join(sorted(table)) if table else None,
            )


def read(spec: ControllerSpec, table: dict[str, Any] | None = None) -> dict[str, Any]:
    """The controller's parameters by dotted name, defaults filled in from its table."""
    table = TABLES.get(spec.type.replace("::", "/"), {}) if table is None else table
    out: dict[str, Any] = {}
    for name, default in table.items():
        if "*" in name:
            continue
        value = param(spec.params, name)
        out[name] = default if value is None else value
    return out
