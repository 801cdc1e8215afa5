"""mecanum_drive_controller and the steering controllers (ackermann, bicycle, tricycle; ROS 1's
ackermann_steering_controller) -> `mecanum_drive` / `steering_drive` (mecanum_drive_controller.yaml,
steering_controllers_library.yaml and each steering controller's yaml, Humble and Jazzy)."""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, Handler, param
from runner.compile.gazebo.control.mobile_params import (
    axis_limits,
    diagonal,
    diff_drive_style_outputs,
    is_humble,
    limit_keys,
    number,
    odometry_params,
    reference,
    unknown,
)
from runner.compile.gazebo.control.params import flat
from runner.compile.gazebo.surface import grips_by_friction

_MECANUM_WHEELS = ("front_left", "front_right", "rear_right", "rear_left")
_MECANUM = (
    {f"{w}_wheel_command_joint_name" for w in _MECANUM_WHEELS}
    | {f"{w}_wheel_state_joint_name" for w in _MECANUM_WHEELS}
    | {
        "reference_timeout",
        "kinematics.base_frame_offset.x",
        "kinematics.base_frame_offset.y",
        "kinematics.base_frame_offset.theta",
        "kinematics.wheels_radius",
        "kinematics.sum_of_robot_center_projection_on_X_Y_axis",
        "tf_frame_prefix_enable",
        "tf_frame_prefix",
        "base_frame_id",
        "odom_frame_id",
        "enable_odom_tf",
        "twist_covariance_diagonal",
        "pose_covariance_diagonal",
        "use_stamped_vel",
    }
    | limit_keys("linear.x")
    | limit_keys("linear.y")
    | limit_keys("angular.z")
)


def mecanum_drive_controller(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """mecanum_drive_controller/MecanumDriveController (ros2_controllers): four wheel joints by name,
    `<name>/reference` in, `<name>/odometry`, `<name>/tf_odometry`, `<name>/controller_state` out at the
    controller manager's rate; wheel odometry from the wheels' velocities."""
    p, name = spec.params, spec.name
    if param(p, "front_left_wheel_name") is not None:
        return _husarion_mecanum(ctx, spec)
    joints = {w: param(p, f"{w}_wheel_command_joint_name") for w in _MECANUM_WHEELS}
    missing = [w for w, j in joints.items() if not j]
    if missing:
        ctx.say(
            spec,
            f"mecanum drive {name!r} names no {', '.join(f'{w}_wheel_command_joint_name' for w in missing)}: "
            "not run, as it fails to configure",
        )
        return False
    states = {w: param(p, f"{w}_wheel_state_joint_name") for w in _MECANUM_WHEELS}
    for w, state in states.items():
        if state and state != joints[w]:
            ctx.say(
                spec,
                f"mecanum drive {name!r}: {w}_wheel_state_joint_name {state!r} is not the commanded joint; "
                "its odometry reads the commanded joint",
            )
    radius = number(param(p, "kinematics.wheels_radius"))
    lxy = number(param(p, "kinematics.sum_of_robot_center_projection_on_X_Y_axis"))
    if not radius or not lxy:
        ctx.say(
            spec,
            f"mecanum drive {name!r}: kinematics.wheels_radius and "
            "sum_of_robot_center_projection_on_X_Y_axis are needed (the controller divides by them); "
            "here measured from the model",
        )
    timeout = number(param(p, "reference_timeout"))
    params: dict[str, Any] = {
        **{f"{w}_wheel_command_joint_name": str(j) for w, j in joints.items()},
        "wheels_radius": radius or None,
        "sum_of_robot_center_projection_on_X_Y_axis": lxy or None,
        "base_frame_offset": [
            number(param(p, f"kinematics.base_frame_offset.{k}")) or 0.0 for k in ("x", "y", "theta")
        ],
        "reference_timeout": timeout if timeout is not None else 0.0,
        "linear_x_limits": axis_limits(p, "linear.x", True),
        "linear_y_limits": axis_limits(p, "linear.y", True),
        "angular_z_limits": axis_limits(p, "angular.z", True),
        **reference(ctx, spec),
        **odometry_params(ctx, spec),
    }
    if grips_by_friction(ctx.g, [str(j) for j in joints.values()]):
        # mecanum by friction (mu2 0 across a diagonal fdir1 on each wheel): Gazebo drives the wheels as
        # described, and so do we (runner.compile.wheels); our rollers would model the same thing twice
        params["rollers"] = False
    unknown(ctx, spec, _MECANUM, {})
    ctx.add(spec, "mecanum_drive", params)
    return True


def _husarion_mecanum(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """Husarion's mecanum_drive_controller (husarion_controllers; ROSbot XL), whose package and type name
    are ros2_controllers' own: told apart by its diff-drive-like parameters (`front_left_wheel_name`,
    `wheel_separation_x`/`_y`, `wheel_radius`). mecanum_drive_controller.cpp: `~/cmd_vel` (TwistStamped) or,
    with `use_stamped_vel: false`, `~/cmd_vel_unstamped` (Twist) :38-39, braking `cmd_vel_timeout` after the
    last; wheel speeds (vx -+ vy -+ (sep_x + sep_y) / 2 * wz) / r :248-253; `~/odom` and `/tf`."""
    p, name = spec.params, spec.name
    ctx.say(
        spec,
        f"mecanum drive {name!r}: read as Husarion's mecanum_drive_controller (same type name as "
        "ros2_controllers'; its parameters are Husarion's)",
    )
    wheels = {
        "front_left": "front_left_wheel_name",
        "front_right": "front_right_wheel_name",
        "rear_right": "rear_right_wheel_name",
        "rear_left": "rear_left_wheel_name",
    }
    joints = {w: param(p, key) for w, key in wheels.items()}
    if not all(joints.values()):
        ctx.say(spec, f"mecanum drive {name!r} does not name its four wheels: not run")
        return False
    sep_x = (number(param(p, "wheel_separation_x")) or 0.0) * (
        number(param(p, "wheel_separation_multiplier_x")) or 1.0
    )
    sep_y = (number(param(p, "wheel_separation_y")) or 0.0) * (
        number(param(p, "wheel_separation_multiplier_y")) or 1.0
    )
    radius = (number(param(p, "wheel_radius")) or 0.0) * (number(param(p, "wheel_radius_multiplier")) or 1.0)
    stamped = bool(param(p, "use_stamped_vel")) if param(p, "use_stamped_vel") is not None else True
    timeout = number(param(p, "cmd_vel_timeout"))
    params: dict[str, Any] = {
        **{f"{w}_wheel_command_joint_name": str(j) for w, j in joints.items()},
        "wheels_radius": radius or None,
        "sum_of_robot_center_projection_on_X_Y_axis": (sep_x + sep_y) / 2 or None,
        "reference_timeout": timeout if timeout is not None else 0.5,
        "linear_x_limits": axis_limits(p, "linear.x", False),
        "linear_y_limits": axis_limits(p, "linear.y", False),
        "angular_z_limits": axis_limits(p, "angular.z", False),
        "reference_topic": ctx.topic(f"{name}/cmd_vel" if stamped else f"{name}/cmd_vel_unstamped"),
        "reference_type": "twist_stamped" if stamped else "twist",
        **diff_drive_style_outputs(ctx, spec),
    }
    known = set(wheels.values()) | {
        "wheel_separation_x", "wheel_separation_y", "wheel_separation_multiplier_x",
        "wheel_separation_multiplier_y", "wheel_radius", "wheel_radius_multiplier", "use_stamped_vel",
        "cmd_vel_timeout", "odom_frame_id", "base_frame_id", "enable_odom_tf", "pose_covariance_diagonal",
        "twist_covariance_diagonal", "publish_rate", "tf_frame_prefix_enable", "tf_frame_prefix",
    } | limit_keys("linear.x") | limit_keys("linear.y") | limit_keys("angular.z")  # fmt: skip
    said = {
        "open_loop": "odometry comes from the wheels",
        "position_feedback": "odometry comes from the wheels' velocities",
        "velocity_rolling_window_size": "the odometry twist is not averaged",
        "publish_limited_velocity": "~/cmd_vel_out is not published",
    }
    unknown(ctx, spec, known, said)
    ctx.add(spec, "mecanum_drive", params)
    return True


_STEERING = {
    "reference_timeout",
    "front_steering",
    "rear_wheels_names",
    "front_wheels_names",
    "traction_joints_names",
    "steering_joints_names",
    "rear_wheels_state_names",
    "front_wheels_state_names",
    "traction_joints_state_names",
    "steering_joints_state_names",
    "open_loop",
    "reduce_wheel_speed_until_steering_reached",
    "velocity_rolling_window_size",
    "base_frame_id",
    "odom_frame_id",
    "enable_odom_tf",
    "twist_covariance_diagonal",
    "pose_covariance_diagonal",
    "position_feedback",
    "use_stamped_vel",
    "tf_frame_prefix_enable",
    "tf_frame_prefix",
    "wheelbase",
}
_STEERING_GEOMETRY = {
    "ackermann": {
        "front_wheel_track",
        "rear_wheel_track",
        "steering_track_width",
        "traction_track_width",
        "traction_wheels_radius",
        "front_wheels_radius",
        "rear_wheels_radius",
    },
    "bicycle": {"traction_wheel_radius", "front_wheel_radius", "rear_wheel_radius"},
    "tricycle": {
        "wheel_track",
        "traction_track_width",
        "traction_wheels_radius",
        "front_wheels_radius",
        "rear_wheels_radius",
    },
}
_STEERING_COUNTS = {"ackermann": (2, 2), "bicycle": (1, 1), "tricycle": (2, 1)}


def _geometry(
    p: dict[str, Any], kinematics: str, front_steering: bool
) -> tuple[float | None, float | None, float | None, float | None]:
    """wheelbase, traction wheels' radius, traction and steering track: Jazzy's names, else Humble's
    (front/rear by `front_steering`), else tricycle's `wheel_track`."""
    front, rear = ("front", "rear") if front_steering else ("rear", "front")

    def first(*keys: str) -> float | None:
        for key in keys:
            value = number(param(p, key))
            if value:
                return value
        return None

    if kinematics == "bicycle":
        return first("wheelbase"), first("traction_wheel_radius", f"{rear}_wheel_radius"), None, None
    radius = first("traction_wheels_radius", f"{rear}_wheels_radius")
    track_t = first("traction_track_width", f"{rear}_wheel_track", "wheel_track")
    track_s = first("steering_track_width", f"{front}_wheel_track", "wheel_track")
    return first("wheelbase"), radius, track_t, track_s


def _steering(kinematics: str) -> Handler:
    def handler(ctx: ControlContext, spec: ControllerSpec) -> bool:
        """The steering controllers (steering_controllers_library): traction joints by velocity, steering
        joints by position, from `<name>/reference` (linear.x, angular.z); odometry from the traction
        wheels and steering angles (`position_feedback`: from the wheels' angles) or the command
        (`open_loop`), on `<name>/odometry` / `<name>/tf_odometry`, and `<name>/controller_state`."""
        if spec.ros1 and kinematics == "ackermann":
            return _ros1_ackermann(ctx, spec)
        p, name = spec.params, spec.name
        front_steering = param(p, "front_steering") is not False

        def names(key: str) -> list[str]:
            value = param(p, key)
            return [str(v) for v in value] if isinstance(value, list) else [str(value)] if value else []

        # steering_controllers_library.cpp: the Humble names map to Jazzy's by front_steering
        traction = names("traction_joints_names") or names(
            "rear_wheels_names" if front_steering else "front_wheels_names"
        )
        steering = names("steering_joints_names") or names(
            "front_wheels_names" if front_steering else "rear_wheels_names"
        )
        n_traction, n_steering = _STEERING_COUNTS[kinematics]
        if len(traction) != n_traction or len(steering) != n_steering:
            ctx.say(
                spec,
                f"{kinematics} steering controller {name!r} needs {n_traction} traction and {n_steering} "
                f"steering joint(s), found {len(traction)} and {len(steering)}: not run, as it fails to "
                "configure",
                hint="traction_joints_names / steering_joints_names (Jazzy), rear_wheels_names / "
                "front_wheels_names (Humble), right wheel first",
            )
            return False
        wheelbase, radius, track_t, track_s = _geometry(p, kinematics, front_steering)
        if not wheelbase or not radius or (kinematics != "bicycle" and not track_t):
            ctx.say(
                spec,
                f"{kinematics} steering controller {name!r}: wheelbase, the traction wheels' radius and "
                "(but for bicycle) track width are needed; those not given are measured from the model",
            )
        timeout = number(param(p, "reference_timeout"))
        window = param(p, "velocity_rolling_window_size")
        params: dict[str, Any] = {
            "kinematics": kinematics,
            "traction_joints_names": traction,
            "steering_joints_names": steering,
            "wheelbase": wheelbase,
            "traction_wheels_radius": radius,
            "traction_track_width": track_t,
            "steering_track_width": track_s or track_t,
            "open_loop": bool(param(p, "open_loop")),
            "position_feedback": bool(param(p, "position_feedback")),
            "reduce_wheel_speed_until_steering_reached": bool(
                param(p, "reduce_wheel_speed_until_steering_reached")
            ),
            "velocity_rolling_window_size": int(window) if window else 10,
            "reference_timeout": timeout if timeout is not None else 1.0,
            **reference(ctx, spec),
            **odometry_params(ctx, spec),
        }
        if param(p, "pose_covariance_diagonal") is None:  # the library's odd default, as it is
            params["pose_covariance_diagonal"] = [0.0, 7.0, 14.0, 21.0, 28.0, 35.0]
        if param(p, "twist_covariance_diagonal") is None:
            params["twist_covariance_diagonal"] = [0.0, 7.0, 14.0, 21.0, 28.0, 35.0]
        unknown(ctx, spec, _STEERING | _STEERING_GEOMETRY[kinematics], {})
        ctx.add(spec, "steering_drive", params)
        return True

    handler.__name__ = f"{kinematics}_steering_controller"
    return handler


def _ros1_ackermann(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """ROS 1's ackermann_steering_controller (ros_controllers, same type name as ROS 2's): one rear
    traction joint (`rear_wheel`) and one steering joint (`front_steer`), a bicycle; `<name>/cmd_vel`
    (Twist: linear.x the speed, angular.z the steering angle itself, as its update() sends it) in,
    `<name>/odom` out at `publish_rate`, `/tf` when `enable_odom_tf`."""
    p, name = spec.params, spec.name
    rear, steer = param(p, "rear_wheel"), param(p, "front_steer")
    if not rear or not steer:
        ctx.say(spec, f"ackermann steering controller {name!r} names no rear_wheel / front_steer: not run")
        return False
    timeout = number(param(p, "cmd_vel_timeout"))
    rate = number(param(p, "publish_rate")) or 50.0
    params: dict[str, Any] = {
        "kinematics": "bicycle",
        "traction_joints_names": [str(rear[0] if isinstance(rear, list) else rear)],
        "steering_joints_names": [str(steer[0] if isinstance(steer, list) else steer)],
        "wheelbase": number(param(p, "wheel_separation_h")),
        "traction_wheels_radius": number(param(p, "wheel_radius")),
        "velocity_rolling_window_size": int(param(p, "velocity_rolling_window_size") or 10),
        "reference_timeout": timeout if timeout is not None else 0.5,
        "reference_topic": ctx.topic(f"{name}/cmd_vel"),
        "reference_type": "twist",
        "odometry_topic": ctx.topic(f"{name}/odom"),
        "tf_topic": ctx.topic("tf"),
        "state_topic": "",  # ROS 1 publishes no state
        "enable_odom_tf": param(p, "enable_odom_tf") is not False,
        "odom_frame_id": ctx.frame(str(param(p, "odom_frame_id") or "odom")),
        "base_frame_id": ctx.frame(str(param(p, "base_frame_id") or "base_link")),
        "pose_covariance_diagonal": diagonal(p, "pose_covariance_diagonal"),
        "twist_covariance_diagonal": diagonal(p, "twist_covariance_diagonal"),
        "open_loop": bool(param(p, "open_loop")),
        "position_feedback": True,
        "publish_rate": rate,
        "angular_is_steering_angle": True,  # its update() sends cmd_vel's angular.z to the steering joint
    }
    known = {
        "rear_wheel",
        "front_steer",
        "wheel_separation_h",
        "wheel_radius",
        "velocity_rolling_window_size",
        "cmd_vel_timeout",
        "publish_rate",
        "enable_odom_tf",
        "odom_frame_id",
        "base_frame_id",
        "pose_covariance_diagonal",
        "twist_covariance_diagonal",
        "open_loop",
    }
    said = {
        k: "the ROS 1 speed limiter of ackermann_steering_controller is not run"
        for k in limit_keys("linear.x") | limit_keys("angular.z")
    }
    said["wheel_separation_h_multiplier"] = "taken as 1"
    said["wheel_radius_multiplier"] = "taken as 1"
    said["steer_pos_multiplier"] = "taken as 1"
    said["allow_multiple_cmd_vel_publishers"] = "every publisher's commands are taken, as with true"
    unknown(ctx, spec, known, said)
    ctx.add(spec, "steering_drive", params)
    return True


def _tricycle_controller(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """tricycle_controller/TricycleController (ros2_controllers, Humble and Jazzy; not the steering library's
    tricycle_steering_controller): one wheel that steers (`steering_joint_name`, position) and drives
    (`traction_joint_name`, velocity), the rear wheels passive; `~/cmd_vel` (TwistStamped; Humble's
    `use_stamped_vel: false`: Twist) in, `~/odom` out and `/tf` when `enable_odom_tf`
    (tricycle_controller.cpp :36-40, twist_to_ackermann :566-583, odometry.cpp update :37-55)."""
    p, name = spec.params, spec.name
    traction, steering = param(p, "traction_joint_name"), param(p, "steering_joint_name")
    if not traction or not steering:
        ctx.say(spec, f"tricycle controller {name!r} names no traction_joint_name / steering_joint_name")
        return False
    stamped = not is_humble(p) or bool(param(p, "use_stamped_vel"))
    timeout = number(param(p, "cmd_vel_timeout"))
    params: dict[str, Any] = {
        "kinematics": "steered_traction",
        "traction_joints_names": [str(traction)],
        "steering_joints_names": [str(steering)],
        "wheelbase": number(param(p, "wheelbase")) or None,
        "traction_wheels_radius": number(param(p, "wheel_radius")) or None,
        "open_loop": bool(param(p, "open_loop")),
        "velocity_rolling_window_size": int(param(p, "velocity_rolling_window_size") or 10),
        "reference_timeout": timeout if timeout is not None else 0.5,
        "reference_topic": ctx.topic(f"{name}/cmd_vel"),
        "reference_type": "twist_stamped" if stamped else "twist",
        **diff_drive_style_outputs(ctx, spec),  # it publishes no controller state
        "publish_rate": number(param(p, "publish_rate")),
    }
    known = {
        "traction_joint_name", "steering_joint_name", "wheelbase", "wheel_radius", "open_loop",
        "use_stamped_vel", "velocity_rolling_window_size", "cmd_vel_timeout", "odom_frame_id",
        "base_frame_id", "enable_odom_tf", "pose_covariance_diagonal", "twist_covariance_diagonal",
        "publish_rate",
    }  # fmt: skip
    said = {
        "publish_ackermann_command": "~/cmd_ackermann (ackermann_msgs/AckermannDrive) is not published",
        "odom_only_twist": "the pose is published too",
    }
    limiter = "the tricycle controller's speed limiter is not run"
    said.update({k: limiter for k, _ in flat(p) if k.startswith(("traction.", "steering."))})
    unknown(ctx, spec, known, said)
    ctx.add(spec, "steering_drive", params)
    return True


def _four_wheel_steering(ctx: ControlContext, spec: ControllerSpec) -> bool:
    ctx.say(
        spec,
        f"ros_control controller {spec.name!r} ({spec.type}) is not run: four-wheel steering (ROS 1 only; "
        "it steers the front and rear axles, which no ROS 2 steering controller does)",
        hint="drive the robot with a `planar_move` plugin, or a ROS 2 ackermann_steering_controller",
    )
    return False


STEERING_HANDLERS: dict[str, Handler] = {
    "mecanum_drive_controller/MecanumDriveController": mecanum_drive_controller,
    "ackermann_steering_controller/AckermannSteeringController": _steering("ackermann"),
    "bicycle_steering_controller/BicycleSteeringController": _steering("bicycle"),
    "tricycle_steering_controller/TricycleSteeringController": _steering("tricycle"),
    "four_wheel_steering_controller/FourWheelSteeringController": _four_wheel_steering,
    "tricycle_controller/TricycleController": _tricycle_controller,
}
