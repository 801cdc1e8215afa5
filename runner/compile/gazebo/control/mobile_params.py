"""Reading a mobile-base controller's parameters as ros2_controllers' generated parameter code and ROS 1's
init() read them: dotted or nested names, `.nan` limits, the speed limiter's switches, the odometry frames
and the `~/reference` of the controllers built on steering_controllers_library / mecanum_drive_controller."""

from __future__ import annotations

import math
from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, param


def flat(params: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Every parameter by its dotted name (`linear.x.max_velocity`), nested or written dotted."""
    out: dict[str, Any] = {}
    for key, value in params.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flat(value, name + "."))
        else:
            out[name] = value
    return out


def unknown(ctx: ControlContext, spec: ControllerSpec, known: set[str], said: dict[str, str]) -> None:
    """Say each parameter the controller does not have, and each it has that we do not run (`said`:
    name -> why), once, at the controller's line."""
    params = flat(spec.params)
    for key in sorted(params):
        if key in ("type", "update_rate") or key in known:
            continue
        if key in said:
            ctx.say(spec, f"{spec.type} {spec.name!r}: `{key}` is not run: {said[key]}")
        else:
            ctx.say(spec, f"{spec.type} {spec.name!r}: `{key}` is not one of its parameters; ignored")


def number(value: Any) -> float | None:
    """A limit as the parameter files write it: a number, or `.nan` / missing for none."""
    if value is None or isinstance(value, bool):
        return None
    try:
        out = float(value)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(out) else out


_LIMIT_KEYS = (
    "max_velocity",
    "min_velocity",
    "max_acceleration",
    "min_acceleration",
    "max_deceleration",
    "max_acceleration_reverse",
    "max_deceleration_reverse",
    "max_jerk",
    "min_jerk",
)
_HAS = {"velocity": ("max_velocity", "min_velocity"), "jerk": ("max_jerk", "min_jerk")}


def axis_limits(p: dict[str, Any], axis: str, limits_default_on: bool) -> dict[str, float] | None:
    """The speed limiter of one axis (`linear.x`) as the controller builds it. `has_*_limits` switches a
    kind off (ROS 1, Humble: off unless true; Jazzy: on, and a limit left `.nan` is none). ROS 1's and
    Humble's `min_acceleration` is the lower bound of every change (Jazzy: its deprecated name of
    `max_deceleration`), so it bounds deceleration forward and acceleration backward."""
    values = {k: number(param(p, f"{axis}.{k}")) for k in _LIMIT_KEYS}
    for kind, keys in (
        ("velocity", _HAS["velocity"]),
        ("acceleration", ("max_acceleration", "min_acceleration", "max_deceleration")),
        ("jerk", _HAS["jerk"]),
    ):
        has = param(p, f"{axis}.has_{kind}_limits")
        on = limits_default_on if has is None else bool(has)
        if not on:
            for k in keys:
                values[k] = None
            if kind == "acceleration":
                values["max_acceleration_reverse"] = values["max_deceleration_reverse"] = None
    out: dict[str, float] = {}
    for k in ("max_velocity", "min_velocity", "max_jerk", "min_jerk", "max_acceleration"):
        if values[k] is not None:
            out[k] = values[k]  # type: ignore[assignment]
    dec = values["max_deceleration"] if values["max_deceleration"] is not None else values["min_acceleration"]
    if dec is not None:
        out["max_deceleration"] = dec
        if limits_default_on and values["max_acceleration_reverse"] is None:
            pass  # Jazzy: reverse acceleration defaults to -max_acceleration (the limiter's default)
        elif values["max_acceleration_reverse"] is None:
            out["max_acceleration_reverse"] = dec  # ROS 1 / Humble: one range [min, max] both ways
    for k in ("max_acceleration_reverse", "max_deceleration_reverse"):
        if values[k] is not None:
            out[k] = values[k]  # type: ignore[assignment]
    if not limits_default_on and "max_acceleration" in out and "max_deceleration_reverse" not in out:
        out["max_deceleration_reverse"] = out["max_acceleration"]
    return out or None


def frame_prefix(p: dict[str, Any]) -> str | None:
    """ROS 2's `tf_frame_prefix_enable` / `tf_frame_prefix`: None for the node's namespace (the robot's),
    "" for none, else the prefix without a leading `/` and with a trailing one."""
    if param(p, "tf_frame_prefix_enable") is False:
        return ""
    prefix = str(param(p, "tf_frame_prefix") or "")
    if not prefix:
        return None
    prefix = prefix.lstrip("/")
    return prefix if prefix.endswith("/") else prefix + "/"


def diagonal(p: dict[str, Any], key: str) -> list[float] | None:
    value = param(p, key)
    if isinstance(value, list) and len(value) == 6:
        return [float(v) for v in value]
    return None


def is_humble(p: dict[str, Any]) -> bool:
    return param(p, "use_stamped_vel") is not None


def limit_keys(axis: str) -> set[str]:
    kinds = ("velocity", "acceleration", "jerk")
    return {f"{axis}.{k}" for k in _LIMIT_KEYS} | {f"{axis}.has_{k}_limits" for k in kinds}


def reference(ctx: ControlContext, spec: ControllerSpec) -> dict[str, Any]:
    """The `~/reference` of mecanum_drive_controller and the steering controllers: Jazzy's TwistStamped
    on `<name>/reference`; Humble's Twist on `<name>/reference_unstamped` unless `use_stamped_vel`."""
    p, name = spec.params, spec.name
    stamped = not is_humble(p) or bool(param(p, "use_stamped_vel"))
    topic = f"{name}/reference" if stamped else f"{name}/reference_unstamped"
    return {"reference_topic": ctx.topic(topic), "reference_type": "twist_stamped" if stamped else "twist"}


def odometry_params(ctx: ControlContext, spec: ControllerSpec) -> dict[str, Any]:
    p, name = spec.params, spec.name
    prefix = frame_prefix(p)
    base = str(param(p, "base_frame_id") or "base_link")
    odom = str(param(p, "odom_frame_id") or "odom")
    if prefix is None:
        base, odom = ctx.frame(base) or base, ctx.frame(odom) or odom
    else:
        base, odom = prefix + base, prefix + odom
    return {
        "odometry_topic": ctx.topic(f"{name}/odometry"),
        "tf_topic": ctx.topic(f"{name}/tf_odometry"),
        "state_topic": ctx.topic(f"{name}/controller_state"),
        "enable_odom_tf": param(p, "enable_odom_tf") is not False,
        "odom_frame_id": odom,
        "base_frame_id": base,
        "pose_covariance_diagonal": diagonal(p, "pose_covariance_diagonal"),
        "twist_covariance_diagonal": diagonal(p, "twist_covariance_diagonal"),
        "update_rate": number(spec.update_rate),
    }


def diff_drive_style_outputs(ctx: ControlContext, spec: ControllerSpec) -> dict[str, Any]:
    """`odometry_params` for a controller laid out as diff_drive_controller is (Husarion's mecanum,
    tricycle_controller): `~/odom` and `/tf`, and no controller state."""
    return {
        **odometry_params(ctx, spec),
        "odometry_topic": ctx.topic(f"{spec.name}/odom"),
        "tf_topic": ctx.topic("tf"),
        "state_topic": "",
    }
