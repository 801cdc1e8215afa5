"""diff_drive: a differential drive like gazebo_ros_diff_drive / gz-sim DiffDrive.

Subscribes `cmd_vel` (geometry_msgs/Twist); drives the two wheel joints with MuJoCo velocity actuators
(torque-limited, with an optional wheel acceleration limit); publishes `odom` (nav_msgs/Odometry) and the
odom -> base transform on `tf`. Odometry comes from the wheel encoders (integrated joint angles, so it
drifts when wheels slip, as on a real robot) or from the world (the true pose, as Gazebo's
`odometrySource: world`).

The implementation (`WheelDrive`) drives any number of wheel joints per side; `skid_steer` is the same
drive with lists of joints (plugins/skid_steer.py).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar, Literal

import mujoco
import numpy as np
from pydantic import Field, PositiveFloat

from plugins._actuators import Lifecycle, claim_actuator, find_actuator
from plugins._common import BaseDriveParams, OdometryWriter, TransformWriter, drive_topics, tf_transforms
from plugins._mobile import COMMAND_TYPES, AxisLimits, Command, CommandType, PlanarOdometry, SpeedLimiter
from runner.geometry import quat_to_yaw, wheel_radius
from runner.plugin import BuildContext, Plugin, PluginConfigError, Topic
from runner.wire import msgs

_INTEGRAL_TIME_S = 0.2
_YAW_INTEGRAL_TIME_S = 0.05
_UNLIMITED_INTEGRAL = 5.0  # rad/s: the integral's bound on a wheel with no torque limit (a stuck wheel)
OdometrySource = Literal["encoders", "velocity", "command", "world"]


class WheelDriveParams(BaseDriveParams):
    """Parameters shared by `diff_drive` and `skid_steer` (everything but the wheel joints)."""

    rate: float = Field(50.0, gt=0, description="Odometry and TF publishing rate, sim Hz.")
    control_rate: float = Field(
        100.0,
        gt=0,
        description="How often the drive updates its wheel targets, sim Hz (at most every physics step), "
        "whatever it publishes at: the wheel servos act at every physics step, as Gazebo's joint motors do.",
    )
    wheel_separation: PositiveFloat | None = Field(
        None, description="Distance between the wheels, metres (default: measured from the model)."
    )
    wheel_radius: PositiveFloat | None = Field(
        None, description="Wheel radius, metres (default: from the wheel's collision geometry)."
    )
    wheel_separation_multiplier: PositiveFloat = Field(
        1.0,
        description="Factor on the wheel separation, given or measured (diff_drive_controller's "
        "wheel_separation_multiplier): the wheels are driven as for a robot this much wider, as for skid "
        "steers that turn less than their geometry says.",
    )
    wheel_radius_multiplier: PositiveFloat = Field(
        1.0, description="Factor on the wheel radius, given or measured (diff_drive_controller's)."
    )
    max_wheel_torque: PositiveFloat | Literal["joint"] | None = Field(
        20.0,
        description="Torque limit of each wheel, N·m. `joint` (or null): the wheel joint's own limit (the "
        "URDF <limit effort>, or the one of the actuator the robot's ros2_control / transmission hardware "
        "gives the joint), unlimited without one, as gazebo_ros_control and gz_ros2_control drive a "
        "controller's wheels.",
    )
    left_wheel_radius_multiplier: PositiveFloat = Field(
        1.0, description="Factor on the left wheels' radius (diff_drive_controller's)."
    )
    right_wheel_radius_multiplier: PositiveFloat = Field(
        1.0, description="Factor on the right wheels' radius (diff_drive_controller's)."
    )
    cmd_type: CommandType = Field(
        "twist",
        description="Command message: twist (geometry_msgs/Twist) or twist_stamped (geometry_msgs/"
        "TwistStamped, aged by its header stamp when it has one, as ros2_control's diff_drive_controller).",
    )
    cmd_out_topic: str | None = Field(
        None,
        description="Publish the command as limited, as geometry_msgs/TwistStamped, on this topic at "
        "`control_rate` (diff_drive_controller's `publish_limited_velocity` / ROS 1 `publish_cmd`).",
    )
    linear_limits: AxisLimits | None = Field(
        None, description="Limits on the commanded linear.x (diff_drive_controller's speed limiter)."
    )
    angular_limits: AxisLimits | None = Field(
        None, description="Limits on the commanded angular.z (diff_drive_controller's speed limiter)."
    )
    velocity_rolling_window_size: int = Field(
        1, ge=1, description="Odometry twist: the mean of this many control periods' velocities."
    )
    pose_covariance_diagonal: list[float] | None = Field(
        None, min_length=6, max_length=6, description="Odometry pose covariance diagonal (default: zeros)."
    )
    twist_covariance_diagonal: list[float] | None = Field(
        None, min_length=6, max_length=6, description="Odometry twist covariance diagonal (default: zeros)."
    )
    frame_prefix: str | None = Field(
        None,
        description="Prefix of the odometry and base frames (diff_drive_controller's tf_frame_prefix): "
        'null, the robot\'s namespace; "", none.',
    )
    max_wheel_acceleration: float = Field(
        0.0, ge=0, description="Wheel acceleration limit, rad/s² (0: none)."
    )
    gain: PositiveFloat | None = Field(
        None,
        description="Velocity servo gain of the wheel actuators, N·m per rad/s (default: from the robot's "
        "mass and wheel inertia, for a 5-step time constant; too stiff a servo makes the robot hop).",
    )
    odometry_source: OdometrySource = Field(
        "encoders",
        description="encoders: integrate the wheel joints' angles; velocity: their velocities "
        "(diff_drive_controller's position_feedback: false); command: the limited command (open_loop); "
        "world: report the true pose.",
    )
    yaw_rate_feedback: bool = Field(
        False,
        description="Close the loop on the body's yaw rate (as a gyro-stabilised drive does): when casters "
        "drag or wheels scrub, the wheels turn faster until the body turns at the commanded rate. Off (the "
        "default, as in Gazebo's plugins): the wheel speeds alone follow the command.",
    )
    publish_wheel_tf: bool = Field(
        False,
        description="Also publish each wheel's transform from its parent link on the TF topic "
        "(gazebo_ros_diff_drive's publishWheelTF / publish_wheel_tf).",
    )
    pair_separations: list[PositiveFloat] | None = Field(
        None,
        description="Per wheel pair (left_joints[i], right_joints[i]): its separation, metres, as "
        "gazebo_ros_diff_drive's repeated <wheel_separation> (default: `wheel_separation` for every pair).",
    )
    pair_radii: list[PositiveFloat] | None = Field(
        None,
        description="Per wheel pair: its wheel radius, metres (default: `wheel_radius` for every pair).",
    )


class DiffDriveParams(WheelDriveParams):
    left_joint: str = Field("left_wheel_joint", description="Left wheel joint.")
    right_joint: str = Field("right_wheel_joint", description="Right wheel joint.")


class WheelDrive(Lifecycle, Plugin):
    """A drive with one or more wheel joints per side, each with its own velocity servo.

    Subclasses say which joints form each side (`sides`). Every wheel of a side gets the same target
    speed; encoder odometry uses the mean angle of each side's wheels (as diff_drive_controller averages
    its `wheels_per_side`).
    """

    Params: ClassVar[type[WheelDriveParams]] = WheelDriveParams
    params: WheelDriveParams

    @classmethod
    def sides(cls, params: Any) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
        """(joint name, parameter naming it) of the left and of the right wheels."""
        raise NotImplementedError

    @classmethod
    def _actuator_names(cls, params: Any, name: str) -> list[str]:
        left, right = cls.sides(params)
        out = []
        for side, joints in (("left", left), ("right", right)):
            for jname, _param in joints:
                out.append(f"{name}/{side}" if len(joints) == 1 else f"{name}/{jname}")
        return out

    @classmethod
    def build(cls, params: WheelDriveParams, ctx: BuildContext, name: str) -> list[Topic]:
        left, right = cls.sides(params)
        seen: set[str] = set()
        for (jname, param), act_name in zip(left + right, cls._actuator_names(params, name), strict=True):
            joint = ctx.joint(jname, param)
            if joint.type != mujoco.mjtJoint.mjJNT_HINGE:
                raise PluginConfigError(f"wheel joint {jname!r} is not revolute/continuous", param)
            if jname in seen:
                raise PluginConfigError(f"wheel joint {jname!r} is named twice", param)
            seen.add(jname)
            # The wheel's velocity interface: the hardware's actuator on the joint when the robot's
            # ros2_control / transmission gave it one (its force limit, from the URDF <limit effort>, kept
            # unless the drive has its own torque), else one of ours with the joint's own limit or ours.
            torque = params.max_wheel_torque
            act = claim_actuator(
                ctx.spec,
                name,
                joint,
                "velocity",
                kv=params.gain,
                max_effort=None if torque == "joint" else torque,
            )
            if act.name == f"{name}/{jname}":
                act.name = act_name  # ours: named by side, as before the hardware layer
        pairs = max(len(left), len(right))
        for key in ("pair_separations", "pair_radii"):
            values = getattr(params, key)
            if values is not None and len(values) != pairs:
                raise PluginConfigError(
                    f"{key} has {len(values)} value(s) for {pairs} wheel pair(s)",
                    key,
                    hint="one value per pair of left/right joints, in their order",
                )
        topics = drive_topics(params)
        topics[0] = Topic(params.cmd_topic, COMMAND_TYPES[params.cmd_type], "sub")
        if params.publish_wheel_tf and not params.publish_tf:
            topics.append(Topic(params.tf_topic, "tf2_msgs/msg/TFMessage", "pub", params.rate))
        if params.cmd_out_topic:
            topics.append(
                Topic(params.cmd_out_topic, "geometry_msgs/msg/TwistStamped", "pub", params.control_rate)
            )
        return topics

    @classmethod
    def control_rate_of(cls, params: Any) -> float | None:
        return float(params.control_rate)

    def setup(self) -> None:
        p = self.params
        m, d = self.ctx.model, self.ctx.data
        r = self.ctx.robot
        left, right = self.sides(p)
        self.nleft = len(left)
        joints = [r.joint_id(j) for j, _ in left + right]
        names = self._actuator_names(p, self.name)
        acts = []
        for (jname, _), jid, act_name in zip(left + right, joints, names, strict=True):
            try:
                acts.append(r.actuator_id(act_name))
            except KeyError:  # the hardware's, reused
                acts.append(find_actuator(m, r, self.name, jname, jid, "velocity")[0])
        self.act = np.array(acts)
        self.qadr = np.array([int(m.jnt_qposadr[j]) for j in joints])
        self.vadr = np.array([int(m.jnt_dofadr[j]) for j in joints])
        wheel_bodies = [int(m.jnt_bodyid[j]) for j in joints]
        left_centre = np.mean([d.xpos[b] for b in wheel_bodies[: self.nleft]], axis=0)
        right_centre = np.mean([d.xpos[b] for b in wheel_bodies[self.nleft :]], axis=0)
        self.sep = p.wheel_separation_multiplier * (
            p.wheel_separation or float(np.linalg.norm(left_centre - right_centre))
        )
        self.radius = p.wheel_radius_multiplier * (
            p.wheel_radius or float(np.mean([_wheel_radius(m, b) for b in wheel_bodies]))
        )
        self.radius_l = self.radius * p.left_wheel_radius_multiplier
        self.radius_r = self.radius * p.right_wheel_radius_multiplier
        self.base = r.root_body
        self._servo_gains(wheel_bodies)
        self._wheel_targets(len(joints))
        self._setup_odometry(len(joints))
        self._setup_io(wheel_bodies)

    def _servo_gains(self, wheel_bodies: list[int]) -> None:
        p, m, r = self.params, self.ctx.model, self.ctx.robot
        for a, wheel in zip(self.act, wheel_bodies, strict=True):
            kv = p.gain or _auto_gain(m, r.body_ids, wheel, self.radius, len(wheel_bodies))
            m.actuator_gainprm[a, 0] = kv
            m.actuator_biasprm[a, 2] = -kv
        # A velocity servo stiffer than the wheel's inertia allows (timestep x kv > inertia) upsets the
        # wheel's contacts under the implicit integrators: MuJoCo computes contact forces without the
        # servo's implicit damping, so a wheel scrubbing sideways loses its grip (a skid-steer robot turned at
        # a quarter of its command). Armature (rotor inertia, as a geared motor has) of timestep x kv keeps
        # the two consistent.
        for a, dof in zip(self.act, self.vadr, strict=True):
            m.dof_armature[dof] = max(
                float(m.dof_armature[dof]), float(m.opt.timestep) * float(m.actuator_gainprm[a, 0])
            )

    def _setup_io(self, wheel_bodies: list[int]) -> None:
        """Frames, the command subscription and the publishers."""
        p, m, d, r = self.params, self.ctx.model, self.ctx.data, self.ctx.robot
        if p.frame_prefix is None:
            self.base_frame = p.base_frame or r.frame(r.root_link)
            self.odom_frame = r.frame(p.odom_frame)
        else:  # diff_drive_controller's tf_frame_prefix: the frames as the controller names them
            self.base_frame = p.frame_prefix + (p.base_frame or r.root_link)
            self.odom_frame = p.frame_prefix + p.odom_frame
        self.command = Command(p.cmd_type == "twist_stamped")
        self.ctx.subscribe(p.cmd_topic, COMMAND_TYPES[p.cmd_type], self.command.take)
        self.cmd_out = (
            self.ctx.publisher(p.cmd_out_topic, "geometry_msgs/msg/TwistStamped") if p.cmd_out_topic else None
        )
        odom_pub = self.ctx.publisher(p.odom_topic, "nav_msgs/msg/Odometry") if p.publish_odom else None
        wants_tf = p.publish_tf or p.publish_wheel_tf
        tf_pub = self.ctx.publisher(p.tf_topic, "tf2_msgs/msg/TFMessage") if wants_tf else None
        self.odom_out = (
            OdometryWriter(
                odom_pub,
                self.odom_frame,
                self.base_frame,
                p.pose_covariance_diagonal,
                p.twist_covariance_diagonal,
            )
            if odom_pub
            else None
        )
        # with wheel transforms, one TFMessage a cycle carries them and odom -> base together
        only_odom = tf_pub is not None and p.publish_tf and not p.publish_wheel_tf
        self.tf_out = TransformWriter(tf_pub, self.odom_frame, self.base_frame) if only_odom else None
        self.wheel_tf: WheelTransforms | None = None
        if tf_pub is not None and p.publish_wheel_tf:
            self.wheel_tf = WheelTransforms(tf_pub, m, d, r, wheel_bodies)

    def _wheel_targets(self, n: int) -> None:
        """Each wheel's share of a command, and the state of its speed integral."""
        p, m = self.params, self.ctx.model
        self.limiters = [SpeedLimiter(lim) if lim else None for lim in (p.linear_limits, p.angular_limits)]
        # each wheel's share of the turn (-half its pair's separation on the left, + on the right) and the
        # radius its speed is divided by
        nright = n - self.nleft
        pair = list(range(self.nleft)) + list(range(nright))
        seps = p.pair_separations or [self.sep] * max(self.nleft, nright)
        radii = p.pair_radii or [self.radius] * max(self.nleft, nright)
        side_mult = [p.left_wheel_radius_multiplier] * self.nleft + [p.right_wheel_radius_multiplier] * nright
        wheel_radii = [radii[pair[i]] * side_mult[i] for i in range(n)]
        turn_sign = [
            (-1.0 if i < self.nleft else 1.0) * seps[pair[i]] / 2.0 / wheel_radii[i] for i in range(n)
        ]
        self._inv_radius = [1.0 / rad for rad in wheel_radii]
        self.ctrl = [0.0] * n
        # Integral of the wheel-speed error: a velocity servo alone lags under load (tyre scrub when
        # turning, slopes); Gazebo's diff drive holds the commanded wheel speed up to the torque limit.
        self.integral = [0.0] * n
        self.integral_max = [
            float(m.actuator_forcerange[a, 1]) / float(m.actuator_gainprm[a, 0])
            if m.actuator_forcelimited[a] and m.actuator_forcerange[a, 1] > 0
            else _UNLIMITED_INTEGRAL
            for a in self.act
        ]
        self._wheels = list(
            zip(turn_sign, self._inv_radius, self.vadr.tolist(), self.act.tolist(), strict=True)
        )
        self.dt = max(1.0 / p.control_rate, float(m.opt.timestep))
        self.yaw_integral = 0.0
        self.settled = True

    def _setup_odometry(self, n: int) -> None:
        p, d = self.params, self.ctx.data
        self._vel = np.zeros(6)
        self.odom = PlanarOdometry(p.velocity_rolling_window_size)
        self.yaw = 0.0
        self._means = np.zeros((2, n))  # row 0 averages the left wheels, row 1 the right
        self._means[0, : self.nleft] = 1.0 / self.nleft
        self._means[1, self.nleft :] = 1.0 / (n - self.nleft)
        self.last_q = tuple(self._side_means(d.qpos[self.qadr]).tolist())
        self.last_ns: int | None = None
        self.qpos, self.qvel, self.actuator_ctrl = d.qpos, d.qvel, d.ctrl  # views, looked up once

    def rebind(self) -> None:
        d = self.ctx.data
        self.qpos, self.qvel, self.actuator_ctrl = d.qpos, d.qvel, d.ctrl  # (the new data's)

    def _side_means(self, values: np.ndarray) -> np.ndarray:
        return self._means @ values

    def _commanded(self, now_ns: int) -> tuple[float, float]:
        """The body twist to drive at: the last command, zero once `cmd_timeout` passed since it (or before
        any), limited by the speed limiter at the control period."""
        p, c = self.params, self.command
        v = w = 0.0
        if c.twist is not None and not (p.cmd_timeout and c.age_s(now_ns) > p.cmd_timeout):
            v, w = float(c.twist.linear.x), float(c.twist.angular.z)
        lin, ang = self.limiters
        if lin is not None:
            v = lin.limit(v, self.dt)
        if ang is not None:
            w = ang.limit(w, self.dt)
        if self.cmd_out is not None:
            T = msgs.T
            self.cmd_out.publish(
                T["geometry_msgs/msg/TwistStamped"](
                    header=msgs.header(now_ns, ""),
                    twist=T["geometry_msgs/msg/Twist"](
                        linear=T["geometry_msgs/msg/Vector3"](x=v, y=0.0, z=0.0),
                        angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=w),
                    ),
                ),
                now_ns,
            )
        return v, w

    def commanded(self) -> list[int]:
        """diff_drive_controller deactivated (the controller_manager plugin): its wheels are released."""
        return self.act.tolist()

    def on_activate(self) -> None:
        """on_activate: odometry goes on from here; the wheels' ramps and integrals start from zero."""
        self.last_ns = None
        self.last_q = tuple(self._side_means(self.qpos[self.qadr]).tolist())
        self.ctrl[:] = [0.0] * len(self.ctrl)
        self.integral[:] = [0.0] * len(self.integral)
        self.yaw_integral = 0.0

    def before_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        # A few wheels: plain floats beat numpy's per-call overhead by 3x here.
        p = self.params
        v, w = self._commanded(now_ns)
        self._odometry(now_ns, v, w)
        if p.yaw_rate_feedback:
            w = self._yaw_feedback(w)
        step = p.max_wheel_acceleration * self.dt if p.max_wheel_acceleration > 0 else None
        gain = self.dt / _INTEGRAL_TIME_S
        qvel, out = self.qvel, self.actuator_ctrl
        ctrl, integral, limits = self.ctrl, self.integral, self.integral_max
        settled_all = True
        for i, (turn, inv_radius, dof, act) in enumerate(self._wheels):
            target = turn * w + v * inv_radius
            c = ctrl[i]
            if step is None:
                c = target
            else:
                delta = target - c
                c += step if delta > step else -step if delta < -step else delta
            ctrl[i] = c
            acc = integral[i]
            # Integrate only where the target has settled: during an acceleration ramp the servo's lag
            # is expected, and integrating it would overshoot the limit (conditional integration).
            if c == target:
                acc += (c - qvel[dof]) * gain
                lim = limits[i]
                acc = lim if acc > lim else -lim if acc < -lim else acc
                integral[i] = acc
            else:
                settled_all = False
            out[act] = c + acc
        self.settled = settled_all

    def _odometry(self, now_ns: int, v: float, w: float) -> None:
        """The controller's odometry at each control update (diff_drive_controller odometry.cpp): from
        the wheels' mean angles (encoders), their mean velocities (velocity) or the command (command)."""
        source = self.params.odometry_source
        last, self.last_ns = self.last_ns, now_ns
        if source == "world" or last is None:
            return
        dt = (now_ns - last) / 1e9
        if source == "command":
            self.odom.open_loop(v, w, dt)
            return
        if source == "encoders":
            ql, qr = (self._means @ self.qpos[self.qadr]).tolist()
            dl, dr = (ql - self.last_q[0]) * self.radius_l, (qr - self.last_q[1]) * self.radius_r
            self.last_q = (ql, qr)
        else:
            wl, wr = (self._means @ self.qvel[self.vadr]).tolist()
            dl, dr = wl * self.radius_l * dt, wr * self.radius_r * dt
        self.odom.update((dl + dr) / 2.0, (dr - dl) / self.sep, dt)

    def _yaw_feedback(self, w: float) -> float:
        """The turn command that makes the body yaw at `w`: an integral on the yaw-rate error, reset when
        no turn is asked (a skid-steered body scrubs its wheels and turns slower than they say)."""
        if w == 0.0:
            self.yaw_integral = 0.0
            return w
        mujoco.mj_objectVelocity(
            self.ctx.model, self.ctx.data, mujoco.mjtObj.mjOBJ_XBODY, self.base, self._vel, 0
        )
        error = w - float(self._vel[2])
        if self.settled:  # not while the wheels still ramp (anti-windup)
            self.yaw_integral += error * (self.dt / _YAW_INTEGRAL_TIME_S)
        limit = 4.0 * abs(w)
        self.yaw_integral = min(max(self.yaw_integral, -limit), limit)
        return w + self.yaw_integral

    def after_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        if self.params.odometry_source != "world":
            o = self.odom
            self.yaw = o.heading
            pos: Sequence[float] = (o.x, o.y, 0.0)
            quat: Sequence[float] = o.quat()
            linear: Sequence[float] = (o.linear, 0.0, 0.0)  # what the wheels (or the command) say
            angular: Sequence[float] = (0.0, 0.0, o.angular)
        else:
            d = self.ctx.data
            pos = d.xpos[self.base].tolist()
            quat = d.xquat[self.base].tolist()
            self.yaw = quat_to_yaw(quat)
            # the twist is the true one too (in the body's frame, as gazebo_ros_diff_drive's WORLD source
            # gives it), not the wheels' claim: a skidding or dragging robot reports what it does
            mujoco.mj_objectVelocity(self.ctx.model, d, mujoco.mjtObj.mjOBJ_XBODY, self.base, self._vel, 1)
            ang, lin = self._vel[:3], self._vel[3:]
            linear = (float(lin[0]), float(lin[1]), 0.0)
            angular = (0.0, 0.0, float(ang[2]))
        if self.odom_out:
            self.odom_out.publish(now_ns, pos, quat, linear, angular)
        if self.tf_out:
            self.tf_out.publish(now_ns, pos, quat)
        if self.wheel_tf:
            odom_tf = (self.odom_frame, self.base_frame, pos, quat) if self.params.publish_tf else None
            self.wheel_tf.publish(now_ns, odom_tf)


class WheelTransforms:
    """Each wheel link's pose in its parent link's frame, on TF: what gazebo_ros_diff_drive's
    publishWheelTF sends (parent link -> wheel link, with the robot's namespace)."""

    def __init__(self, pub: Any, m: mujoco.MjModel, d: mujoco.MjData, robot: Any, wheels: list[int]):
        self.pub, self.d = pub, d
        self.pairs = [(int(m.body_parentid[b]), b) for b in wheels]
        self.frames = [
            (
                robot.frame(m.body(p).name.removeprefix(robot.prefix)),
                robot.frame(m.body(c).name.removeprefix(robot.prefix)),
            )
            for p, c in self.pairs
        ]
        self._q = np.zeros(4)
        self._qp = np.zeros(4)

    def publish(self, now_ns: int, first: tuple[str, str, Sequence[float], Sequence[float]] | None) -> None:
        d = self.d
        entries = [first] if first is not None else []
        for (parent, child), (pf, cf) in zip(self.pairs, self.frames, strict=True):
            rel = d.xmat[parent].reshape(3, 3).T @ (d.xpos[child] - d.xpos[parent])
            mujoco.mju_negQuat(self._qp, d.xquat[parent])
            mujoco.mju_mulQuat(self._q, self._qp, d.xquat[child])
            entries.append((pf, cf, rel.tolist(), self._q.tolist()))
        self.pub.publish(tf_transforms(now_ns, entries), now_ns)


class DiffDrive(WheelDrive):
    Params = DiffDriveParams
    params: DiffDriveParams

    @classmethod
    def sides(cls, params: DiffDriveParams) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
        return [(params.left_joint, "left_joint")], [(params.right_joint, "right_joint")]


def _wheel_radius(m: mujoco.MjModel, body: int) -> float:
    """Radius of the wheel's collision geometry (with the links fixed to it), see `wheel_radius`."""
    radius = wheel_radius(m, body)
    if not radius:
        raise ValueError("cannot find the wheel radius from the model; set `wheel_radius`")
    return radius


def _auto_gain(
    m: mujoco.MjModel, robot_bodies: set[int], wheel: int, radius: float, nwheels: int = 2
) -> float:
    """A servo gain giving a time constant of 5 physics steps (at least 10 ms) for the inertia one wheel
    sees: its own inertia plus its share of the robot's mass at the rim."""
    mass = float(sum(m.body_mass[b] for b in robot_bodies))
    inertia = float(max(m.body_inertia[wheel])) + mass / nwheels * radius**2
    tau = max(5.0 * float(m.opt.timestep), 0.01)
    return inertia / tau
