"""force_based_move: push a mobile robot's base with a force and a torque that track a commanded planar
velocity through P (and optionally I) gains, like hector_gazebo_plugins' `gazebo_ros_force_based_move`
and its forks (Robotnik's `robotnik_force_based_move`, a ROS 2 port in the gazebo_plugins namespace).

Subscribes `cmd_vel` (geometry_msgs/Twist: linear.x, linear.y, angular.z in the robot's heading frame),
publishes `odom` (nav_msgs/Odometry) and the odom -> base transform on `tf` at `rate`.

Unlike `planar_move` (whose servos are stiff, with an integral term, so the base moves at the commanded
velocity within a few physics steps), the force here is what the Gazebo plugin applies: F = kp·(v_cmd - v)
along the base's x and y and τ = kp_yaw·(ω_cmd - ω) about z, each clamped to its limit when one is given
(hector's ROS 1 plugin has none: gazebo_ros_force_based_move.cpp:208-218 of melodic-devel). The base
therefore accelerates as a first-order lag of time constant m / kp and settles short of the command where
friction or drag resists (the steady error is resisting force / kp), as in Gazebo. The P term runs inside
MuJoCo's step (a velocity actuator with gain kp: integrated implicitly, so a gain that an explicit 1 ms
step would make ring stays stable); the optional integral term (the ROS 2 port's `vel_i_gain`) is
updated at `rate`.

Odometry (`odometry`):
- `integrated` (hector, Robotnik; gazebo_ros_force_based_move.cpp:285-360 and :363-398): at each
  publish the base's own velocity (x, y, yaw rate in its frame) is integrated over the time since the
  last publish along a circular arc, starting from the identity: dead reckoning from the true velocity.
  The twist is the base's velocity in its own frame. The yaw covariance is 0.01 while the base does not
  turn (|ω| < 1e-4 rad/s) and 100 while it does, as the plugin sets them.
- `world` (the ROS 2 port's UpdateOdometry): the base's true world pose; the twist's linear part rotated
  into the base's heading, the angular part the world yaw rate.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import mujoco
import numpy as np
from pydantic import Field, NonNegativeFloat, PositiveFloat

from plugins._common import BaseDriveParams, OdometryWriter, TransformWriter, drive_topics
from plugins.planar_move import add_planar_servos
from runner.geometry import quat_to_yaw
from runner.plugin import BuildContext, Plugin, Topic

_AXES = ("x", "y", "yaw")
_STILL = 1e-4  # rad/s: below it hector's odometry counts the base as not turning
_BIG = 1e12  # hector's covariance of what planar odometry does not measure
# Gazebo controls at every physics step (1 kHz by default): so do we, at most at the physics rate
_CONTROL_HZ = 1000.0


class ForceBasedMoveParams(BaseDriveParams):
    rate: float = Field(20.0, gt=0, description="Odometry publish rate, sim Hz (hector's odometryRate).")
    p_gains: tuple[PositiveFloat, PositiveFloat, PositiveFloat] = Field(
        (10000.0, 10000.0, 100.0),
        description="Velocity P gains [x N/(m/s), y N/(m/s), yaw N·m/(rad/s)] (hector's defaults).",
    )
    i_gains: tuple[NonNegativeFloat, NonNegativeFloat, NonNegativeFloat] = Field(
        (0.0, 0.0, 0.0),
        description="Velocity I gains [x, y, yaw] (the ROS 2 port's vel_i_gain, omega_i_gain).",
    )
    i_limits: tuple[PositiveFloat, PositiveFloat, PositiveFloat] = Field(
        (1.0, 1.0, 1.0), description="Limits of the integrated velocity errors [x m, y m, yaw rad]."
    )
    max_force: PositiveFloat | None = Field(
        None,
        description="Force limit along x and y, N (none: unlimited).",
    )
    max_torque: PositiveFloat | None = Field(
        None,
        description="Torque limit about z, N·m (none: unlimited).",
    )
    allow_lateral: bool = Field(
        True,
        description="Follow linear.y of the command (hector's allowLateralMotion).",
    )
    hold_on_timeout: bool = Field(
        False,
        description="When no command came for `cmd_timeout`, stop pushing and hold the base where it was "
        "(Robotnik's commandWatchdog); otherwise the command just becomes zero.",
    )
    odometry: Literal["integrated", "world"] = Field(
        "integrated",
        description="`integrated`: the base's velocity integrated from the start (hector); `world`: its true "
        "world pose (the ROS 2 port).",
    )


class ForceBasedMove(Plugin):
    Params = ForceBasedMoveParams
    params: ForceBasedMoveParams

    @classmethod
    def build(cls, params: ForceBasedMoveParams, ctx: BuildContext, name: str) -> list[Topic]:
        add_planar_servos(ctx, name)
        return drive_topics(params)

    def setup(self) -> None:
        p = self.params
        m = self.ctx.model
        r = self.ctx.robot
        self.act = np.array([r.actuator_id(f"{self.name}/{a}") for a in _AXES])
        self.base = r.root_body
        self.kp = np.array(p.p_gains, dtype=float)
        self.ki = np.array(p.i_gains, dtype=float)
        self.i_lim = np.array(p.i_limits, dtype=float)
        limits = [p.max_force, p.max_force, p.max_torque]
        for a, k, lim in zip(self.act, self.kp, limits, strict=True):
            m.actuator_gainprm[a, 0] = k
            m.actuator_biasprm[a, 2] = -k
            m.actuator_forcelimited[a] = lim is not None
            if lim is not None:
                m.actuator_forcerange[a] = (-lim, lim)
        self.integral = np.zeros(3)
        self.control_ns: int | None = None
        self.dt = 1.0 / p.rate
        self.cmd = np.zeros(3)
        self.cmd_time = 0
        self.held: np.ndarray | None = None
        jnt = next(j for j in range(m.njnt) if m.jnt_bodyid[j] == self.base)
        self.qadr, self.vadr = int(m.jnt_qposadr[jnt]), int(m.jnt_dofadr[jnt])
        # integrated odometry: planar pose (x, y, yaw) from the identity, and when it was last published
        self.odom = np.zeros(3)
        self.last_ns: int | None = None
        self.vel = np.zeros(6)
        self.base_frame = p.base_frame or r.frame(r.root_link)
        self.odom_frame = r.frame(p.odom_frame)
        self.ctx.subscribe(p.cmd_topic, "geometry_msgs/msg/Twist", self._on_cmd)
        self.odom_out: tuple[OdometryWriter, OdometryWriter] | None = None
        if p.publish_odom:
            pub = self.ctx.publisher(p.odom_topic, "nav_msgs/msg/Odometry")
            self.odom_out = (
                OdometryWriter(pub, self.odom_frame, self.base_frame, *_covariance(0.01)),
                OdometryWriter(pub, self.odom_frame, self.base_frame, *_covariance(100.0)),
            )
        tf_pub = self.ctx.publisher(p.tf_topic, "tf2_msgs/msg/TFMessage") if p.publish_tf else None
        self.tf_out = TransformWriter(tf_pub, self.odom_frame, self.base_frame) if tf_pub else None

    def _on_cmd(self, msg: Any, stamp_ns: int) -> None:
        lateral = float(msg.linear.y) if self.params.allow_lateral else self.cmd[1]
        self.cmd[:] = (float(msg.linear.x), lateral, float(msg.angular.z))
        self.cmd_time = stamp_ns
        self.held = None

    @classmethod
    def control_rate_of(cls, params: Any) -> float | None:
        return _CONTROL_HZ

    def before_step(self, now_ns: int) -> None:
        p = self.params
        d = self.ctx.data
        timed_out = p.cmd_timeout > 0 and now_ns - self.cmd_time > p.cmd_timeout * 1e9
        if timed_out and p.hold_on_timeout:
            # Robotnik's watchdog (robotnik_force_based_move.cpp:215-221, 278-299): no force, and the
            # model put back where it was when the watchdog fired, its velocity zeroed, at every step
            if self.held is None:
                self.held = d.qpos[self.qadr : self.qadr + 7].copy()
            d.qpos[self.qadr : self.qadr + 7] = self.held
            d.qvel[self.vadr : self.vadr + 6] = 0.0
            d.ctrl[self.act] = 0.0
            self.integral[:] = 0.0
            return
        target = np.zeros(3) if timed_out else self.cmd
        if self.ki.any():  # the ROS 2 port's integral term, anti-windup clamped (its OnUpdate)
            dt = (now_ns - self.control_ns) / 1e9 if self.control_ns is not None else 0.0
            self.integral += (target - d.actuator_velocity[self.act]) * dt
            np.clip(self.integral, -self.i_lim, self.i_lim, out=self.integral)
            d.ctrl[self.act] = target + self.ki * self.integral / self.kp
        else:
            d.ctrl[self.act] = target
        self.control_ns = now_ns

    def after_step(self, now_ns: int) -> None:
        m, d = self.ctx.model, self.ctx.data
        # the base's velocity in its own frame at its origin (Gazebo's RelativeLinearVel/RelativeAngularVel)
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, self.base, self.vel, 1)
        lin, ang = self.vel[3:], self.vel[:3]
        if self.params.odometry == "world":
            pos, quat = d.xpos[self.base], d.xquat[self.base]
            yaw = quat_to_yaw(quat)
            world = np.empty(6)
            mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, self.base, world, 0)
            c, s = math.cos(yaw), math.sin(yaw)
            lin = np.array([c * world[3] + s * world[4], c * world[4] - s * world[3], 0.0])
            ang = np.array([0.0, 0.0, world[2]])
        else:
            # the first publish integrates over the period since the plugin started
            elapsed = self.dt if self.last_ns is None else (now_ns - self.last_ns) / 1e9
            self.odom = _arc(self.odom, lin[0], lin[1], ang[2], elapsed)
            x, y, yaw = self.odom
            pos = np.array([x, y, 0.0])
            quat = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
            lin = np.array([lin[0], lin[1], 0.0])
            ang = np.array([0.0, 0.0, ang[2]])
        self.last_ns = now_ns
        if self.odom_out:
            still, turning = self.odom_out
            (still if abs(ang[2]) < _STILL else turning).publish(now_ns, pos, quat, lin, ang)
        if self.tf_out:
            self.tf_out.publish(now_ns, pos, quat)


def _arc(pose: np.ndarray, vx: float, vy: float, w: float, t: float) -> np.ndarray:
    """The planar pose after moving for `t` s at (vx, vy) in the body frame turning at `w`: a straight line
    below 1e-4 rad/s, a turn on the spot when the distance is under 0.1 mm, a circular arc otherwise
    (hector's getTransformForMotion, gazebo_ros_force_based_move.cpp:363-398 of melodic-devel)."""
    x, y, yaw = pose
    dx, dy, dyaw = vx * t, vy * t, 0.0
    if abs(w) >= _STILL:
        dyaw = w * t
        if abs(dx) < 1e-4 and abs(dy) < 1e-4:
            dx = dy = 0.0
        else:
            dist, heading = math.hypot(dx, dy), math.atan2(dy, dx)
            radius = dist / dyaw
            ex, ey = math.sin(dyaw) * radius, radius - math.cos(dyaw) * radius
            dx = math.cos(heading) * ex - math.sin(heading) * ey
            dy = math.sin(heading) * ex + math.cos(heading) * ey
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([x + c * dx - s * dy, y + s * dx + c * dy, yaw + dyaw])


def _covariance(yaw: float) -> tuple[list[float], list[float]]:
    """hector's covariance diagonals (gazebo_ros_force_based_move.cpp:325-355): pose x, y 0.001, z, roll,
    pitch 1e12; twist x, y, z 0.001, roll, pitch 1e12; the yaw's 0.01 while still, 100 while turning."""
    return [0.001, 0.001, _BIG, _BIG, _BIG, yaw], [0.001, 0.001, 0.001, _BIG, _BIG, yaw]
