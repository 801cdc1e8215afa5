"""joint_trajectory_controller (ROS 2, ros2_controllers Humble/Jazzy) and ROS 1's
position/velocity/effort_controllers JointTrajectoryController -> our `joint_trajectory_controller` plugin.

The parameters are read as joint_trajectory_controller_parameters.yaml declares them (defaults included:
Jazzy's), flat (`constraints.goal_time`) or nested; any other parameter is said at the controller's line.
"""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, Handler, param

# ROS 2 parameters (Jazzy's joint_trajectory_controller_parameters.yaml, Humble's `state_publish_rate`)
# the plugin runs, by name -> the plugin parameter
_RUN = (
    "joints",
    "command_joints",
    "command_interfaces",
    "state_interfaces",
    "allow_partial_joints_goal",
    "open_loop_control",
    "interpolate_from_desired_state",
    "allow_integration_in_goal_trajectories",
    "interpolation_method",
    "allow_nonzero_velocity_at_trajectory_end",
    "cmd_timeout",
    "state_publish_rate",
    "action_monitor_rate",
)
# read and said: what the plugin does instead
_SAID = {
    "speed_scaling": "speed scaling is not run (the factor stays 1)",
    "set_last_command_interface_value_as_state_on_activation": "the controller starts from the measured "
    "state, which is the command the hardware starts with here",
    "update_rate": None,  # a controller's own update_rate: taken (below)
    "type": None,
    "use_sim_time": None,
}
_GAIN_KEYS = (
    "p",
    "i",
    "d",
    "i_clamp",
    "i_clamp_max",
    "i_clamp_min",
    "ff_velocity_scale",
    "u_clamp_max",
    "u_clamp_min",
)
_GAIN_SAID = (
    "angle_wraparound",
    "normalize_error",
    "antiwindup_strategy",
    "tracking_time_constant",
    "error_deadband",
)

# ROS 1: `<family>/JointTrajectoryController` -> the command interfaces
_ROS1_FAMILY = {
    "position_controllers": ["position"],
    "velocity_controllers": ["velocity"],
    "effort_controllers": ["effort"],
    "pos_vel_controllers": ["position", "velocity"],
    "pos_vel_acc_controllers": ["position", "velocity", "acceleration"],
}
_ROS1_KNOWN = {
    "type",
    "joints",
    "constraints",
    "gains",
    "velocity_ff",
    "state_publish_rate",
    "action_monitor_rate",
    "stop_trajectory_duration",
    "allow_partial_joints_goal",
}


def _float(value: Any) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _constraints(ctx: ControlContext, spec: ControllerSpec, joints: list[str]) -> dict[str, Any]:
    p = spec.params
    out: dict[str, Any] = {}
    for key in ("stopped_velocity_tolerance", "goal_time"):
        v = _float(param(p, f"constraints.{key}"))
        if v is not None:
            out[key] = v
    for j in joints:
        c = {k: _float(param(p, f"constraints.{j}.{k}")) for k in ("trajectory", "goal")}
        c = {k: v for k, v in c.items() if v is not None}
        if c:
            out[j] = c
    known = {"stopped_velocity_tolerance", "goal_time", "decelerate_on_cancel", *joints}
    if param(p, "constraints.decelerate_on_cancel") is True:  # (Jazzy) with max_deceleration_on_cancel
        ctx.say(spec, f"{spec.name}: constraints.decelerate_on_cancel is not run: a cancel holds at once")
    block = param(p, "constraints")
    if isinstance(block, dict):
        for k, v in block.items():
            if k not in known:
                ctx.say(spec, f"{spec.name}: constraints.{k} is not a parameter of the controller; ignored")
            elif k in joints and isinstance(v, dict):
                for jk in v:
                    if jk not in ("trajectory", "goal", "max_deceleration_on_cancel"):
                        ctx.say(spec, f"{spec.name}: constraints.{k}.{jk} is not a parameter; ignored")
    return out


def _gains(ctx: ControlContext, spec: ControllerSpec, joints: list[str]) -> dict[str, Any]:
    p = spec.params
    out: dict[str, Any] = {}
    for j in joints:
        g: dict[str, Any] = {}
        for k in _GAIN_KEYS:
            v = _float(param(p, f"gains.{j}.{k}"))
            if v is not None:
                g[k] = v
        if spec.ros1:  # ROS 1: `velocity_ff/<joint>` is the velocity feed-forward scale
            ff = _float(param(p, f"velocity_ff.{j}"))
            if ff is not None:
                g["ff_velocity_scale"] = ff
        for k in _GAIN_SAID:
            if param(p, f"gains.{j}.{k}") is not None:
                ctx.say(spec, f"{spec.name}: gains.{j}.{k} is not run (error taken as desired - measured)")
        if g:
            out[j] = g
    block = param(p, "gains")
    if isinstance(block, dict):
        for j, entry in block.items():
            if j not in joints:
                ctx.say(spec, f"{spec.name}: gains.{j}: {j!r} is not one of its joints; ignored")
            elif isinstance(entry, dict):
                for k in entry:
                    if k not in (*_GAIN_KEYS, *_GAIN_SAID):
                        ctx.say(
                            spec, f"{spec.name}: gains.{j}.{k} is not a parameter of the controller; ignored"
                        )
    return out


def joint_trajectory_controller(ctx: ControlContext, spec: ControllerSpec) -> bool:
    p = spec.params
    joints = param(p, "joints")
    if not isinstance(joints, list) or not joints or not all(isinstance(j, str) for j in joints):
        ctx.say(spec, f"{spec.name}: a joint_trajectory_controller needs `joints` (a list of names); not run")
        return False
    params: dict[str, Any] = {"joints": joints, "constraints": _constraints(ctx, spec, joints)}
    params["gains"] = _gains(ctx, spec, joints)
    rate = _float(param(p, "update_rate")) or _float(spec.update_rate)
    params["update_rate"] = rate
    if spec.ros1:
        family = spec.type.replace("::", "/").split("/")[0]
        params["ros1"] = True
        params["command_interfaces"] = _ROS1_FAMILY[family]
        # gazebo_ros_control updates its controllers every `control_period`, by default each physics step
        # (gazebo_ros_control_plugin.cpp: control_period_ = the physics update period): so here. An effort
        # PID tuned for that (Interbotix' p 100-500 on light links) flails at 100 Hz
        params["update_rate"] = None
        params["every_step"] = True
        for key in ("state_publish_rate", "action_monitor_rate", "allow_partial_joints_goal"):
            if param(p, key) is not None:
                params[key] = param(p, key)
        params.setdefault("state_publish_rate", 50.0)  # ROS 1 JointTrajectoryController's default
        if param(p, "stop_trajectory_duration"):
            ctx.say(spec, f"{spec.name}: stop_trajectory_duration is not run (a stop holds at once)")
        for key in p:
            if key not in _ROS1_KNOWN and key != "hardware_interface":
                ctx.say(spec, f"{spec.name}: {key!r} is not a parameter of the controller; ignored")
        params["command_topic"] = ctx.topic(f"{spec.name}/command")
        params["state_topic"] = ctx.topic(f"{spec.name}/state")
        ctx.say(
            spec,
            f"{spec.name}: ROS 1 JointTrajectoryController runs as ros2_controllers' (the state topic "
            "carries control_msgs/JointTrajectoryControllerState of ROS 2 Jazzy, follow_joint_trajectory "
            "control_msgs/action/FollowJointTrajectory on ROS 2's wire)",
        )
    else:
        for key in _RUN:
            value = param(p, key)
            if value is not None:
                params[key] = value
        interfaces = params.get("command_interfaces") or ["position"]
        if "acceleration" in interfaces:
            ctx.say(spec, f"{spec.name}: the acceleration command interface is not run (MuJoCo has none)")
        if "position" in interfaces and "velocity" in interfaces:
            ctx.say(
                spec,
                f"{spec.name}: position+velocity command: the position servo follows the position; the "
                "velocity command is not sent (the servo's damping works towards zero velocity)",
            )
        for key, text in _SAID.items():
            if text and param(p, key) is not None:
                ctx.say(spec, f"{spec.name}: {key} {text}")
        known = {*_RUN, *(k.split(".")[0] for k in _SAID), "constraints", "gains"}
        for key in p:
            if key.split(".")[0] not in known:
                ctx.say(
                    spec, f"{spec.name}: {key!r} is not a parameter of joint_trajectory_controller; ignored"
                )
        params["command_topic"] = ctx.topic(f"{spec.name}/joint_trajectory")
        params["state_topic"] = ctx.topic(f"{spec.name}/controller_state")
    params["action_name"] = ctx.topic(f"{spec.name}/follow_joint_trajectory")
    interfaces = params.get("command_interfaces") or ["position"]
    closed_loop = len(interfaces) == 1 and interfaces[0] in ("velocity", "effort")
    if params["gains"] and not closed_loop:
        ctx.say(
            spec,
            f"{spec.name}: gains are not used with command interfaces {interfaces} (ros2_controllers uses "
            "them for a velocity-only or effort-only command); ignored",
        )
    ctx.add(spec, "joint_trajectory_controller", params)
    return True


HANDLERS: dict[str, Handler] = {
    "joint_trajectory_controller/JointTrajectoryController": joint_trajectory_controller,
    **{f"{family}/JointTrajectoryController": joint_trajectory_controller for family in _ROS1_FAMILY},
}
