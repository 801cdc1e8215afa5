"""Gripper controllers -> our `gripper_action_controller` plugin: ros2_controllers'
position_controllers/GripperActionController and effort_controllers/GripperActionController
(gripper_controllers), parallel_gripper_action_controller/GripperActionController (Jazzy), ROS 1's
position_controllers/ and effort_controllers/GripperActionController (gripper_action_controller).

They take goals as the action `~/gripper_cmd`; our topic of the same name takes the same goal from a
scenario's timeline (plugins/gripper_action_controller.py, docs/ros2_control.md).
"""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, Handler, param

# gripper_action_controller_parameters.yaml (gripper_controllers, Jazzy) and ROS 1's parameters
_COMMON = ("joint", "goal_tolerance", "stall_velocity_threshold", "stall_timeout", "action_monitor_rate")
_ROS2 = (*_COMMON, "max_effort", "allow_stalling")
_PARALLEL = (
    *_COMMON,
    "allow_stalling",
    "max_effort",
    "max_velocity",
    "max_effort_interface",
    "max_velocity_interface",
    "state_interfaces",
)
_IGNORED = {"type", "use_sim_time", "update_rate", "gains", "joints", "hardware_interface"}


def _gripper(ctx: ControlContext, spec: ControllerSpec, *, parallel: bool) -> bool:
    p = spec.params
    joint = param(p, "joint")
    if not isinstance(joint, str) and isinstance(param(p, "joints"), list) and len(param(p, "joints")) == 1:
        joint = param(p, "joints")[0]  # ROS 1 examples write `joints: [name]` too
    if not isinstance(joint, str) or not joint:
        ctx.say(spec, f"{spec.name}: a gripper controller needs `joint` (one joint name); not run")
        return False
    family = spec.type.replace("::", "/").split("/")[0]
    params: dict[str, Any] = {"joint": joint, "parallel": parallel or None, "ros1": spec.ros1 or None}
    if not parallel:
        params["command_interface"] = "effort" if family == "effort_controllers" else "position"
    names = _PARALLEL if parallel else _ROS2
    for key in names:
        value = param(p, key)
        if value is not None and key not in ("joint", "state_interfaces"):
            params[key] = value
    if spec.ros1 and param(p, "stalled_velocity_threshold") is not None:  # ROS 1 docs' spelling
        params["stall_velocity_threshold"] = param(p, "stalled_velocity_threshold")
    if parallel:
        params.setdefault("max_effort", 10.0)  # the parallel gripper's default (Newtons)
    gains = {k: param(p, f"gains.{joint}.{k}") for k in ("p", "i", "d", "i_clamp")}
    gains = {k: float(v) for k, v in gains.items() if isinstance(v, (int, float))}
    if gains:
        params["gains"] = {joint: gains}
        if params.get("command_interface") != "effort":
            ctx.say(spec, f"{spec.name}: gains are used by the effort gripper only; ignored")
    for key in p:
        if key.split(".")[0] not in (*names, *_IGNORED, "stalled_velocity_threshold"):
            ctx.say(spec, f"{spec.name}: {key!r} is not a parameter of the gripper controller; ignored")
    rate = param(p, "update_rate") or spec.update_rate
    params["update_rate"] = float(rate) if isinstance(rate, (int, float)) else None
    # the action `~/gripper_cmd`, and our topic of the same name (a timeline has no action client)
    params["command_topic"] = params["action_name"] = ctx.topic(f"{spec.name}/gripper_cmd")
    ctx.add(spec, "gripper_action_controller", params)
    return True


def gripper_action_controller(ctx: ControlContext, spec: ControllerSpec) -> bool:
    return _gripper(ctx, spec, parallel=False)


def parallel_gripper_action_controller(ctx: ControlContext, spec: ControllerSpec) -> bool:
    return _gripper(ctx, spec, parallel=True)


HANDLERS: dict[str, Handler] = {
    "position_controllers/GripperActionController": gripper_action_controller,
    "effort_controllers/GripperActionController": gripper_action_controller,
    "parallel_gripper_action_controller/GripperActionController": parallel_gripper_action_controller,
}
