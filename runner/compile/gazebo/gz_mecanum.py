"""gz-sim's MecanumDrive system (`gz-sim-mecanum-drive-system`) -> our `mecanum_drive`.

As gz-sim's src/systems/mecanum_drive/MecanumDrive.cc (Harmonic) reads and runs it: `<front_left_joint>`,
`<front_right_joint>`, `<back_left_joint>`, `<back_right_joint>` (each repeatable), `<wheel_separation>`
(default 1), `<wheelbase>` (1), `<wheel_radius>` (0.2); a gz Twist on `<topic>` (default
/model/<model>/cmd_vel), held until the next one; wheel speeds (lin ∓ lat ∓ ang·(separation + wheelbase)/2)
/ radius, the same inverse kinematics as ros2_controllers' mecanum_drive_controller with lx + ly =
(separation + wheelbase)/2; its speed limiter (math::SpeedLimiter: `<[min|max]_[linear_|angular_]velocity|
acceleration|jerk>`, the linear one applied to x and y); mecanum odometry from the wheel angles on
`<odom_topic>` (/model/<model>/odometry) and `<tf_topic>` (/model/<model>/tf) at `<odom_publish_frequency>`
(50 Hz), in `<frame_id>`/`<child_frame_id>`.

The system has no rollers: gz-sim's mecanum demo and the descriptions that use it give their wheels
friction mu 1 along a diagonal `fdir1` fixed in the base and mu2 0 across it, which runner.compile.wheels
simulates. Where the wheels have no such friction, our mecanum_drive's rollers stand in for it (said).
"""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.surface import grips_by_friction
from runner.compile.gazebo.tags import TagReader, ros_topic

_CORNERS = (  # gz-sim's tags -> our plugin's (the controller's) corner names
    ("front_left_joint", "front_left"),
    ("front_right_joint", "front_right"),
    ("back_right_joint", "rear_right"),
    ("back_left_joint", "rear_left"),
)
_HELD = 1e9  # s: gz-sim keeps driving with the last command until another comes


def _limits(r: TagReader, axis: str) -> dict[str, float] | None:
    """math::SpeedLimiter of one axis: `<min|max>_<axis>_<quantity>` over the shared `<min|max>_<quantity>`
    (Configure reads the shared one first, then the axis's own), as our limiter's fields: its acceleration
    bounds every change, forward or backward."""
    out: dict[str, float] = {}

    def value(bound: str, quantity: str) -> float | None:
        own = r.float(f"{bound}_{axis}_{quantity}")
        shared = r.float(f"{bound}_{quantity}")
        return own if own is not None else shared

    # a lower bound above 0 or an upper one below (which would stop the axis) is left out: ours must hold 0
    for quantity in ("velocity", "jerk"):
        hi, lo = value("max", quantity), value("min", quantity)
        if hi is not None and hi >= 0:
            out[f"max_{quantity}"] = hi
        if lo is not None and lo <= 0:
            out[f"min_{quantity}"] = lo
    hi, lo = value("max", "acceleration"), value("min", "acceleration")
    if hi is not None and hi >= 0:
        out["max_acceleration"] = hi
        out["max_deceleration_reverse"] = hi
    if lo is not None and lo <= 0:
        out["max_deceleration"] = lo
        out["max_acceleration_reverse"] = lo
    return out or None


def mecanum_drive_gz(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]] | None:
    joints: dict[str, str] = {}
    for tag, corner in _CORNERS:
        given = [e for e in r.children(tag) if e.text and e.text.strip()]
        if not given:
            g.note(
                r.el,
                f"gz-sim MecanumDrive names no <{tag}>: it drives nothing, as in Gazebo (it waits for "
                "its four wheels)",
                hint=f"name the {corner.replace('_', ' ')} wheel joint in <{tag}>",
            )
            return None
        joints[corner] = given[0].text.strip()
        for extra in given[1:]:
            g.note(extra, f"a second <{tag}> is not driven: our mecanum drive turns one joint per corner")
    separation = r.float("wheel_separation") or 1.0
    wheelbase = r.float("wheelbase") or 1.0
    model = f"model/{g.model}"
    params: dict[str, Any] = {
        **{f"{corner}_wheel_command_joint_name": joint for corner, joint in joints.items()},
        "wheels_radius": r.float("wheel_radius") or 0.2,
        "sum_of_robot_center_projection_on_X_Y_axis": 0.5 * (separation + wheelbase),
        "reference_topic": ros_topic(r.text("topic")) or f"{model}/cmd_vel",
        "reference_type": "twist",
        "reference_timeout": _HELD,
        "odometry_topic": ros_topic(r.text("odom_topic")) or f"{model}/odometry",
        "tf_topic": ros_topic(r.text("tf_topic")) or f"{model}/tf",
        "state_topic": "",
        "publish_rate": r.float("odom_publish_frequency") or 50.0,
        "odom_frame_id": r.text("frame_id"),
        "base_frame_id": g.frame(r.text("child_frame_id")),
        "linear_x_limits": _limits(r, "linear"),
        "linear_y_limits": _limits(r, "linear"),
        "angular_z_limits": _limits(r, "angular"),
    }
    if grips_by_friction(g, list(joints.values())):
        params["rollers"] = False  # the description's friction is its rollers (runner.compile.wheels)
    else:
        g.note(
            r.el,
            "gz-sim MecanumDrive: the wheels have no mecanum friction (mu2 0 across a diagonal <fdir1>): in "
            "Gazebo they would scrub instead of rolling sideways; passive rollers at 45° stand in here",
            hint="give each wheel <collision><surface><friction><ode><mu>1</mu><mu2>0</mu2><fdir1 "
            'gz:expressed_in="base_link">1 -1 0</fdir1> (1 1 0 on the front right and back left)',
        )
    return "mecanum_drive", {k: v for k, v in params.items() if v is not None}


MODEL_PLUGINS = {
    "gz-sim-mecanum-drive-system": mecanum_drive_gz,
}
