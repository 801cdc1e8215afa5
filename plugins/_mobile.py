"""What the mobile-base controllers share (diff_drive / skid_steer, mecanum_drive, steering): the speed
limiter of ros2_controllers / ros_controllers, the planar odometry they integrate, and how a command
(geometry_msgs/Twist or TwistStamped) ages.

Semantics from ros2_controllers (Jazzy) diff_drive_controller/include/diff_drive_controller/speed_limiter.hpp
over control_toolbox's RateLimiter, diff_drive_controller/src/odometry.cpp, and
steering_controllers_library/src/steering_kinematics.cpp; ROS 1's ros_controllers
diff_drive_controller/src/speed_limiter.cpp is the same limiter with one acceleration range.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any, ClassVar, Literal

from pydantic import Field

from plugins._actuators import Lifecycle
from plugins._common import OdometryWriter, TransformWriter
from runner.plugin import Plugin, PluginParams, Topic

CommandType = Literal["twist", "twist_stamped"]
COMMAND_TYPES = {"twist": "geometry_msgs/msg/Twist", "twist_stamped": "geometry_msgs/msg/TwistStamped"}


class AxisLimits(PluginParams):
    """Limits of one axis of the commanded body twist (`linear.x`, `angular.z`...), as the controllers'
    `<axis>.max_velocity`... parameters; None: no limit on that side."""

    max_velocity: float | None = Field(None, ge=0, description="Highest velocity (m/s or rad/s).")
    min_velocity: float | None = Field(None, le=0, description="Lowest velocity (default: -max_velocity).")
    max_acceleration: float | None = Field(None, ge=0, description="Highest acceleration going forward.")
    max_deceleration: float | None = Field(
        None, le=0, description="Lowest acceleration going forward, negative (default: -max_acceleration)."
    )
    max_acceleration_reverse: float | None = Field(
        None, le=0, description="Acceleration limit going backward, negative (default: -max_acceleration)."
    )
    max_deceleration_reverse: float | None = Field(
        None, ge=0, description="Deceleration limit going backward (default: -max_deceleration)."
    )
    max_jerk: float | None = Field(None, ge=0, description="Highest jerk.")
    min_jerk: float | None = Field(None, le=0, description="Lowest jerk (default: -max_jerk).")


def _clamp(v: float, lo: float | None, hi: float | None) -> float:
    if lo is not None and v < lo:
        v = lo
    if hi is not None and v > hi:
        v = hi
    return v


def _neg(v: float | None) -> float | None:
    return None if v is None else -v


class SpeedLimiter:
    """One axis's limiter: jerk, then acceleration, then velocity, on the command given the last two
    limited commands (control_toolbox RateLimiter::limit, as SpeedLimiter::limit calls it)."""

    def __init__(self, limits: AxisLimits):
        L = limits
        self.v_lo = L.min_velocity if L.min_velocity is not None else _neg(L.max_velocity)
        self.v_hi = L.max_velocity
        acc = L.max_acceleration
        dec = L.max_deceleration if L.max_deceleration is not None else _neg(acc)
        self.acc, self.dec = acc, dec
        self.acc_rev = L.max_acceleration_reverse if L.max_acceleration_reverse is not None else _neg(acc)
        self.dec_rev = L.max_deceleration_reverse if L.max_deceleration_reverse is not None else _neg(dec)
        self.j_hi = L.max_jerk
        self.j_lo = L.min_jerk if L.min_jerk is not None else _neg(L.max_jerk)
        self.v0 = self.v1 = 0.0  # the last and second-to-last limited commands

    def limit(self, v: float, dt: float) -> float:
        v0, v1 = self.v0, self.v1
        if dt > 0 and (self.j_lo is not None or self.j_hi is not None):
            dv, dv0, dt2 = v - v0, v0 - v1, 2.0 * dt * dt
            lo = None if self.j_lo is None else self.j_lo * dt2
            hi = None if self.j_hi is None else self.j_hi * dt2
            v = v0 + dv0 + _clamp(dv - dv0, lo, hi)
        if dt > 0:
            if v0 > 0.0:
                lo, hi = self.dec, self.acc
            elif v0 < 0.0:
                lo, hi = self.acc_rev, self.dec_rev
            else:
                lo, hi = self.acc_rev, self.acc
            v = v0 + _clamp(v - v0, None if lo is None else lo * dt, None if hi is None else hi * dt)
        v = _clamp(v, self.v_lo, self.v_hi)
        self.v1, self.v0 = v0, v
        return v


class RollingMean:
    """The mean of the last `size` values (rcppmath::RollingMeanAccumulator)."""

    def __init__(self, size: int):
        self.values: deque[float] = deque(maxlen=max(1, size))
        self.total = 0.0

    def add(self, value: float) -> float:
        if len(self.values) == self.values.maxlen:
            self.total -= self.values[0]
        self.values.append(value)
        self.total += value
        return self.total / len(self.values)


class PlanarOdometry:
    """x, y, heading integrated from body displacements (exact arcs, Runge-Kutta 2 when nearly straight,
    as odometry.cpp's integrateExact), and the body velocities as rolling means."""

    def __init__(self, window: int):
        self.x = self.y = self.heading = 0.0
        self.linear = self.angular = 0.0
        self.linear_y = 0.0
        self._lin, self._ang = RollingMean(window), RollingMean(window)

    def integrate(self, ds: float, dyaw: float) -> None:
        if abs(dyaw) < 1e-6:
            mid = self.heading + dyaw * 0.5
            self.x += ds * math.cos(mid)
            self.y += ds * math.sin(mid)
            self.heading += dyaw
        else:
            old = self.heading
            r = ds / dyaw
            self.heading += dyaw
            self.x += r * (math.sin(self.heading) - math.sin(old))
            self.y -= r * (math.cos(self.heading) - math.cos(old))

    def update(self, ds: float, dyaw: float, dt: float) -> None:
        """A measured displacement over `dt`: integrated, and its velocity averaged."""
        self.integrate(ds, dyaw)
        if dt > 0:
            self.linear = self._lin.add(ds / dt)
            self.angular = self._ang.add(dyaw / dt)

    def open_loop(self, linear: float, angular: float, dt: float) -> None:
        """Odometry from the command (`open_loop: true`): the commanded twist, integrated."""
        self.linear, self.angular = linear, angular
        self.integrate(linear * dt, angular * dt)

    def quat(self) -> tuple[float, float, float, float]:
        half = self.heading / 2.0
        return (math.cos(half), 0.0, 0.0, math.sin(half))


class Command:
    """The last command and when it counts from: its header stamp for a TwistStamped with one (the
    controllers age a stamped command by its stamp, and take a zero stamp as `now`), else its arrival."""

    def __init__(self, stamped: bool):
        self.stamped = stamped
        self.twist: Any = None
        self.time_ns = 0
        self.fresh = False  # not yet used by an update (reference_timeout 0: used once)

    def take(self, msg: Any, arrival_ns: int) -> None:
        if self.stamped:
            stamp = msg.header.stamp
            ns = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
            self.twist, self.time_ns = msg.twist, ns if ns else arrival_ns
        else:
            self.twist, self.time_ns = msg, arrival_ns
        self.fresh = True

    def age_s(self, now_ns: int) -> float:
        return (now_ns - self.time_ns) / 1e9


class ReferenceParams(PluginParams):
    """What mecanum_drive_controller and the steering controllers share: the reference they follow, the
    odometry they publish, their rates and frames."""

    reference_topic: str | None = Field(None, description="Reference topic (default `<name>/reference`).")
    reference_type: CommandType = Field(
        "twist_stamped", description="Reference message: twist_stamped (Jazzy) or twist (Humble unstamped)."
    )
    reference_timeout: float = Field(
        1.0,
        ge=0,
        description="A reference older than this, s, stops the wheels; 0: each reference is used for one "
        "update only (the controllers' reference_timeout).",
    )
    odometry_topic: str | None = Field(None, description="Odometry topic (default `<name>/odometry`).")
    tf_topic: str | None = Field(None, description="Odometry TF topic (default `<name>/tf_odometry`).")
    state_topic: str | None = Field(
        None, description='Controller state topic (default `<name>/controller_state`; "": none).'
    )
    enable_odom_tf: bool = Field(True, description="Publish the odom -> base transform.")
    odom_frame_id: str | None = Field(None, description="Odometry frame (default `<ns>/odom`).")
    base_frame_id: str | None = Field(None, description="Base frame (default `<ns>/base_link`).")
    pose_covariance_diagonal: list[float] | None = Field(
        None, min_length=6, max_length=6, description="Odometry pose covariance diagonal (default: zeros)."
    )
    twist_covariance_diagonal: list[float] | None = Field(
        None, min_length=6, max_length=6, description="Odometry twist covariance diagonal (default: zeros)."
    )
    update_rate: float | None = Field(
        None, gt=0, description="Controller update rate, sim Hz (the controller manager's; default 100)."
    )
    publish_rate: float | None = Field(
        None, gt=0, description="Odometry publish rate, sim Hz (default: every update, as these controllers)."
    )
    max_wheel_torque: float | None = Field(
        None, gt=0, description="Wheel torque limit, N·m (default: the joint's own, unlimited without one)."
    )


def reference_usable(cmd: Command, timeout: float, now_ns: int) -> bool:
    """Whether the last reference drives this update: while not older than `reference_timeout`; with a
    timeout of 0, once (the controllers reset it to NaN after using it)."""
    if cmd.twist is None:
        return False
    if timeout == 0:
        fresh, cmd.fresh = cmd.fresh, False
        return fresh
    return cmd.age_s(now_ns) <= timeout


class ReferenceDrive(Lifecycle, Plugin):
    """What mecanum_drive_controller and the steering controllers run alike (`ReferenceParams`): their rates,
    the reference they subscribe, and the odometry, TF and controller state they publish. A subclass names
    its state message (`STATE_TYPE`) and the covariances it publishes when none are given."""

    STATE_TYPE: ClassVar[str] = ""
    COVARIANCE_DEFAULT: ClassVar[list[float] | None] = None  # None: zeros (OdometryWriter's)

    @classmethod
    def rate_of(cls, params: Any) -> float | None:
        return float(params.publish_rate or params.update_rate or 100.0)

    @classmethod
    def control_rate_of(cls, params: Any) -> float | None:
        return float(params.update_rate or 100.0)

    @classmethod
    def reference_topics(cls, params: Any, name: str) -> list[Topic]:
        """The reference it takes and what it publishes, with their defaults under `<name>/`."""
        rate = cls.rate_of(params)
        topics = [
            Topic(params.reference_topic or f"{name}/reference", COMMAND_TYPES[params.reference_type], "sub"),
            Topic(params.odometry_topic or f"{name}/odometry", "nav_msgs/msg/Odometry", "pub", rate),
        ]
        if params.enable_odom_tf:
            topics.append(
                Topic(params.tf_topic or f"{name}/tf_odometry", "tf2_msgs/msg/TFMessage", "pub", rate)
            )
        if params.state_topic != "":
            topics.append(
                Topic(params.state_topic or f"{name}/controller_state", cls.STATE_TYPE, "pub", rate)
            )
        return topics

    def on_activate(self) -> None:
        """Activated again (the controller_manager plugin): odometry goes on from the next update."""
        self.last_ns = None

    def setup_reference(self) -> None:
        """Subscribe the reference (`self.command`) and make the odometry, TF and state publishers."""
        p, r = self.params, self.ctx.robot  # type: ignore[attr-defined]
        self.command = Command(p.reference_type == "twist_stamped")
        self.ctx.subscribe(
            p.reference_topic or f"{self.name}/reference", COMMAND_TYPES[p.reference_type], self.command.take
        )
        odom, base_frame = p.odom_frame_id or r.frame("odom"), p.base_frame_id or r.frame(r.root_link)
        default = self.COVARIANCE_DEFAULT
        self.odom_out = OdometryWriter(
            self.ctx.publisher(p.odometry_topic or f"{self.name}/odometry", "nav_msgs/msg/Odometry"),
            odom,
            base_frame,
            p.pose_covariance_diagonal or default,
            p.twist_covariance_diagonal or default,
        )
        self.tf_out = (
            TransformWriter(
                self.ctx.publisher(p.tf_topic or f"{self.name}/tf_odometry", "tf2_msgs/msg/TFMessage"),
                odom,
                base_frame,
            )
            if p.enable_odom_tf
            else None
        )
        self.state_pub = (
            self.ctx.publisher(p.state_topic or f"{self.name}/controller_state", self.STATE_TYPE)
            if p.state_topic != ""
            else None
        )
