"""Mobile-base controllers, read as ros2_controllers (Humble, Jazzy) and ros_controllers (Noetic) read their
parameters, run as our plugins:

- diff_drive_controller/DiffDriveController (ROS 1 and 2) -> `diff_drive`, or `skid_steer` with several
  wheels a side (diff_drive_controller_parameter.yaml; ROS 1 diff_drive_controller.cpp's init);
- mecanum_drive_controller/MecanumDriveController -> `mecanum_drive` (mecanum_drive_controller.yaml);
- ackermann_steering_controller/AckermannSteeringController, bicycle_steering_controller/
  BicycleSteeringController, tricycle_steering_controller/TricycleSteeringController -> `steering_drive`
  (steering_controllers_library.yaml and each controller's yaml).

Which ROS 2 distribution a controllers file is for cannot be known from it. Where Humble and Jazzy differ
we take Jazzy (the distribution gz_ros2_control targets now), except that a file giving `use_stamped_vel`
(a Humble parameter Jazzy dropped) is taken as Humble's. The wheel joints keep the torque the description
gives them (the URDF <limit effort>, unlimited without one), as gz_ros2_control and gazebo_ros_control do.
"""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, Handler, param
from runner.compile.gazebo.control.mobile_params import (
    axis_limits,
    diagonal,
    frame_prefix,
    is_humble,
    limit_keys,
    number,
    unknown,
)
from runner.compile.gazebo.control.steering import STEERING_HANDLERS


def by_wheels(params: dict[str, Any], lefts: list[str], rights: list[str]) -> tuple[str, dict[str, Any]]:
    """A drive with one wheel a side is a diff_drive; with several, a skid_steer driving them all."""
    if len(lefts) > 1 or len(rights) > 1:
        params["left_joints"], params["right_joints"] = lefts, rights
        return "skid_steer", params
    params["left_joint"] = lefts[0] if lefts else None
    params["right_joint"] = rights[0] if rights else None
    return "diff_drive", params


_DIFF_ROS2 = {
    "left_wheel_names",
    "right_wheel_names",
    "wheel_separation",
    "wheel_radius",
    "wheel_separation_multiplier",
    "left_wheel_radius_multiplier",
    "right_wheel_radius_multiplier",
    "tf_frame_prefix_enable",
    "tf_frame_prefix",
    "odom_frame_id",
    "base_frame_id",
    "pose_covariance_diagonal",
    "twist_covariance_diagonal",
    "open_loop",
    "position_feedback",
    "enable_odom_tf",
    "cmd_vel_timeout",
    "publish_limited_velocity",
    "velocity_rolling_window_size",
    "use_stamped_vel",
    "publish_rate",
    "wheels_per_side",
}
_DIFF_ROS1 = {
    "left_wheel",
    "right_wheel",
    "wheel_separation",
    "wheel_radius",
    "wheel_separation_multiplier",
    "wheel_radius_multiplier",
    "left_wheel_radius_multiplier",
    "right_wheel_radius_multiplier",
    "odom_frame_id",
    "base_frame_id",
    "pose_covariance_diagonal",
    "twist_covariance_diagonal",
    "open_loop",
    "enable_odom_tf",
    "cmd_vel_timeout",
    "publish_cmd",
    "velocity_rolling_window_size",
    "publish_rate",
}
_DIFF_SAID = {
    "publish_wheel_joint_controller_state": "the wheels' JointTrajectoryControllerState is not published",
    "allow_multiple_cmd_vel_publishers": "every publisher's commands are taken, as with true",
    "estimate_velocity_from_position": "the wheel velocity comes from the joint's velocity state",
    "odom_to_tf": "not a diff_drive_controller parameter (enable_odom_tf is)",
}


def _diff_checks(ctx: ControlContext, spec: ControllerSpec, per_side: int, geometry: bool) -> None:
    """What a ROS 2 diff_drive_controller would refuse or take otherwise, said at its line."""
    p, name = spec.params, spec.name
    if spec.ros1:
        return
    if not geometry:
        ctx.say(
            spec,
            f"diff drive {name!r}: wheel_separation and wheel_radius are required by ros2_control's "
            "diff_drive_controller (it fails to configure without them); here measured from the model",
        )
    if param(p, "wheels_per_side") and int(param(p, "wheels_per_side")) != per_side:
        ctx.say(
            spec,
            f"diff drive {name!r}: wheels_per_side {param(p, 'wheels_per_side')} taken as "
            f"{per_side}, the number of left_wheel_names (as Jazzy does)",
        )


def diff_drive_controller(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """diff_drive_controller/DiffDriveController as it runs under gazebo_ros_control (ROS 1) or
    gz_ros2_control / gazebo_ros2_control (ROS 2). ROS 1: `left_wheel`/`right_wheel` (a joint or a list),
    `<name>/cmd_vel` (Twist), `publish_cmd` -> `<name>/cmd_vel_out`; separation and radius from the URDF
    unless given. ROS 2: `left_wheel_names`/`right_wheel_names`, `<name>/cmd_vel` (TwistStamped) or, with
    Humble's `use_stamped_vel: false`, `<name>/cmd_vel_unstamped` (Twist); `publish_limited_velocity` ->
    `<name>/cmd_vel_out`. Both: encoder odometry (`open_loop`, `position_feedback`) on `<name>/odom` at
    `publish_rate`, `/tf` when `enable_odom_tf`, braking `cmd_vel_timeout` after the last command, the
    speed limiter, multipliers, covariances."""
    p, name, ros1 = spec.params, spec.name, spec.ros1

    def names(*keys: str) -> list[str]:
        for key in keys:
            value = param(p, key)
            if value:
                return [str(v) for v in value] if isinstance(value, list) else [str(value)]
        return []

    lefts = names("left_wheel") if ros1 else names("left_wheel_names")
    rights = names("right_wheel") if ros1 else names("right_wheel_names")
    if not lefts or not rights:
        key = "left_wheel/right_wheel" if ros1 else "left_wheel_names/right_wheel_names"
        ctx.say(spec, f"diff drive {name!r} names no wheels ({key}): not run, as it fails to configure")
        return False
    humble = not ros1 and is_humble(p)
    stamped = not ros1 and param(p, "use_stamped_vel") is not False
    sep, radius = number(param(p, "wheel_separation")), number(param(p, "wheel_radius"))
    _diff_checks(ctx, spec, len(lefts), bool(sep and radius))
    mult = number(param(p, "wheel_radius_multiplier")) if ros1 else None
    open_loop = bool(param(p, "open_loop"))
    velocity_feedback = not ros1 and param(p, "position_feedback") is False
    limits_on = not ros1 and not humble  # Jazzy: has_*_limits default true
    cmd_out = param(p, "publish_cmd") if ros1 else param(p, "publish_limited_velocity")
    window = param(p, "velocity_rolling_window_size")
    params: dict[str, Any] = {
        "wheel_separation": sep or None,
        "wheel_radius": radius or None,
        "wheel_separation_multiplier": number(param(p, "wheel_separation_multiplier")) or 1.0,
        "wheel_radius_multiplier": mult or 1.0,
        "left_wheel_radius_multiplier": number(param(p, "left_wheel_radius_multiplier")) or 1.0,
        "right_wheel_radius_multiplier": number(param(p, "right_wheel_radius_multiplier")) or 1.0,
        "rate": number(param(p, "publish_rate")) or 50.0,
        "control_rate": None if ros1 else number(spec.update_rate),
        "cmd_topic": ctx.topic(
            f"{name}/cmd_vel_unstamped" if not ros1 and not stamped else f"{name}/cmd_vel"
        ),
        "cmd_type": "twist_stamped" if stamped else "twist",
        "cmd_out_topic": ctx.topic(f"{name}/cmd_vel_out") if cmd_out else None,
        "odom_topic": ctx.topic(f"{name}/odom"),
        "tf_topic": ctx.topic("tf"),
        "publish_tf": param(p, "enable_odom_tf") is not False,
        "odom_frame": param(p, "odom_frame_id") or "odom",
        "base_frame": param(p, "base_frame_id") or "base_link",
        "frame_prefix": None if ros1 else frame_prefix(p),
        "cmd_timeout": number(param(p, "cmd_vel_timeout"))
        if param(p, "cmd_vel_timeout") is not None
        else 0.5,
        "linear_limits": axis_limits(p, "linear.x", limits_on),
        "angular_limits": axis_limits(p, "angular.z", limits_on),
        "odometry_source": "command" if open_loop else "velocity" if velocity_feedback else "encoders",
        "velocity_rolling_window_size": int(window) if window else 10,
        "pose_covariance_diagonal": diagonal(p, "pose_covariance_diagonal"),
        "twist_covariance_diagonal": diagonal(p, "twist_covariance_diagonal"),
        # the wheels' torque is the joints' own (URDF <limit effort>), unlimited without one
        "max_wheel_torque": "joint",
    }
    if params["frame_prefix"] is None:
        params["base_frame"] = ctx.frame(params["base_frame"])
    known = (_DIFF_ROS1 if ros1 else _DIFF_ROS2) | limit_keys("linear.x") | limit_keys("angular.z")
    unknown(ctx, spec, known, _DIFF_SAID)
    type_name, drive = by_wheels(params, lefts, rights)
    if type_name == "skid_steer":
        drive["odometry_source"] = params["odometry_source"]  # the controller's, not the plugin's default
    ctx.add(spec, type_name, drive)
    return True


HANDLERS: dict[str, Handler] = {
    "diff_drive_controller/DiffDriveController": diff_drive_controller,
    **STEERING_HANDLERS,
}
