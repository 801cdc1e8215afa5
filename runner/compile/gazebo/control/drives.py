"""Mobile-base controllers: diff_drive_controller (ROS 1 and ROS 2) -> `diff_drive`, or `skid_steer` with
several wheels a side."""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, Handler, param


def by_wheels(params: dict[str, Any], lefts: list[str], rights: list[str]) -> tuple[str, dict[str, Any]]:
    """A drive with one wheel a side is a diff_drive; with several, a skid_steer driving them all."""
    if len(lefts) > 1 or len(rights) > 1:
        params["left_joints"], params["right_joints"] = lefts, rights
        return "skid_steer", params
    params["left_joint"] = lefts[0] if lefts else None
    params["right_joint"] = rights[0] if rights else None
    return "diff_drive", params


def diff_drive_controller(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """diff_drive_controller/DiffDriveController as it runs in Gazebo. ROS 1: `left_wheel`/`right_wheel`
    (a joint or a list), `<name>/cmd_vel` (Twist); separation and radius from the URDF unless given. ROS 2
    (Humble to Jazzy): `left_wheel_names`/`right_wheel_names`, `<name>/cmd_vel` (TwistStamped) or, with
    `use_stamped_vel: false`, `<name>/cmd_vel_unstamped` (Twist). Both: `<name>/odom` at `publish_rate`,
    `/tf` when `enable_odom_tf`, stopping `cmd_vel_timeout` (0.5 s) after the last command, multipliers."""

    p, name, ros1 = spec.params, spec.name, spec.ros1

    def names(*keys: str) -> list[str]:
        for key in keys:
            value = param(p, key)
            if value:
                return [str(v) for v in value] if isinstance(value, list) else [str(value)]
        return []

    lefts, rights = names("left_wheel_names", "left_wheel"), names("right_wheel_names", "right_wheel")
    sep, radius = param(p, "wheel_separation"), param(p, "wheel_radius")
    stamped = False if ros1 else param(p, "use_stamped_vel") is not False
    if stamped:
        ctx.say(
            spec,
            f"ros2_control diff drive {name!r} takes geometry_msgs/TwistStamped on {name}/cmd_vel; here it "
            "takes geometry_msgs/Twist there",
            hint="set use_stamped_vel: false in the controllers file to have it as Gazebo then has it "
            f"({name}/cmd_vel_unstamped, Twist)",
        )
    params: dict[str, Any] = {
        "wheel_separation": float(sep) if sep else None,
        "wheel_radius": float(radius) if radius else None,
        "wheel_separation_multiplier": float(param(p, "wheel_separation_multiplier") or 1.0),
        "wheel_radius_multiplier": float(
            param(p, "wheel_radius_multiplier") or param(p, "left_wheel_radius_multiplier") or 1.0
        ),
        "rate": float(param(p, "publish_rate") or 50.0),
        "cmd_topic": ctx.topic(
            f"{name}/cmd_vel_unstamped" if not ros1 and not stamped else f"{name}/cmd_vel"
        ),
        "odom_topic": ctx.topic(f"{name}/odom"),
        "tf_topic": ctx.topic("tf"),
        "publish_tf": param(p, "enable_odom_tf") is not False,
        "odom_frame": param(p, "odom_frame_id") or "odom",
        "base_frame": ctx.frame(param(p, "base_frame_id") or "base_link"),
        "cmd_timeout": float(param(p, "cmd_vel_timeout") or 0.5),
    }
    accel = param(p, "linear.x.max_acceleration")
    if accel and radius and param(p, "linear.x.has_acceleration_limits"):
        params["max_wheel_acceleration"] = float(accel) / float(radius)
    type_name, drive = by_wheels(params, lefts, rights)
    ctx.add(spec, type_name, drive)
    return True


HANDLERS: dict[str, Handler] = {
    "diff_drive_controller/DiffDriveController": diff_drive_controller,
}
