"""steering_drive: ros2_controllers' steering controllers (ackermann_steering_controller,
bicycle_steering_controller, tricycle_steering_controller, over steering_controllers_library), and ROS 1's
ackermann_steering_controller as a bicycle.

Subscribes the reference (`<name>/reference`, geometry_msgs/TwistStamped: linear.x, angular.z); drives the
traction joints by velocity and the steering joints by position as steering_kinematics.cpp's get_commands
computes them (traction joints and steering joints right first); publishes odometry (`<name>/odometry`,
`<name>/tf_odometry`) integrated from the traction wheels and the steering angles (or the reference, with
`open_loop`) and control_msgs/SteeringControllerStatus on `<name>/controller_state`, at every update.

The joints are commanded through the robot's hardware actuators when its ros2_control gave them (their
URDF effort limits kept), else through actuators of ours with the joint's own limit.
"""

from __future__ import annotations

import math
from typing import Literal

import mujoco
import numpy as np
from pydantic import Field, PositiveFloat

from plugins._actuators import auto_gains, claim_actuator, find_actuator
from plugins._mobile import PlanarOdometry, ReferenceDrive, ReferenceParams, reference_usable
from plugins.diff_drive import _auto_gain, _wheel_radius
from runner.plugin import BuildContext, PluginConfigError, Topic
from runner.wire import msgs

Kinematics = Literal["ackermann", "bicycle", "tricycle", "steered_traction"]
# steered_traction: tricycle_controller's one wheel that both steers and drives (rear wheels passive)
_COUNTS = {"ackermann": (2, 2), "bicycle": (1, 1), "tricycle": (2, 1), "steered_traction": (1, 1)}
_MIN_PHI_DELTA = math.pi / 6.0  # reduce_wheel_speed_until_steering_reached (steering_kinematics.cpp)
_MAX_PHI_DELTA = 1.5608


class SteeringDriveParams(ReferenceParams):
    kinematics: Kinematics = Field(
        "ackermann",
        description="ackermann, bicycle or tricycle (steering_controllers_library), or steered_traction "
        "(tricycle_controller: one front wheel steers and drives, the rear wheels roll free).",
    )
    traction_joints_names: list[str] = Field(
        ["rear_right_wheel_joint", "rear_left_wheel_joint"],
        min_length=1,
        description="Traction joints (ackermann / tricycle: right, left).",
    )
    steering_joints_names: list[str] = Field(
        ["front_right_steering_joint", "front_left_steering_joint"],
        min_length=1,
        description="Steering joints (ackermann: right, left).",
    )
    wheelbase: PositiveFloat | None = Field(
        None, description="Distance between the axles, m (default: measured between the joints)."
    )
    traction_wheels_radius: PositiveFloat | None = Field(
        None, description="Traction wheels' radius, m (default: from their collision geometry)."
    )
    traction_track_width: PositiveFloat | None = Field(
        None, description="Distance between the traction wheels, m (default: measured)."
    )
    steering_track_width: PositiveFloat | None = Field(
        None, description="Distance between the steered wheels, m (default: the traction track)."
    )
    open_loop: bool = Field(False, description="Odometry from the reference instead of the joints.")
    position_feedback: bool = Field(
        False, description="Odometry from the traction wheels' angles (else their velocities)."
    )
    reduce_wheel_speed_until_steering_reached: bool = Field(
        False, description="Slow the traction wheels while the steering is far from its target."
    )
    velocity_rolling_window_size: int = Field(10, ge=1, description="Odometry twist: mean of this many.")
    angular_is_steering_angle: bool = Field(
        False,
        description="The reference's angular.z is the steering angle itself, and a stale reference steers "
        "straight (ROS 1 ackermann_steering_controller, a bicycle).",
    )


class SteeringDrive(ReferenceDrive):
    Params = SteeringDriveParams
    params: SteeringDriveParams
    STATE_TYPE = "control_msgs/msg/SteeringControllerStatus"

    @classmethod
    def build(cls, params: SteeringDriveParams, ctx: BuildContext, name: str) -> list[Topic]:
        n_t, n_s = _COUNTS[params.kinematics]
        if len(params.traction_joints_names) != n_t or len(params.steering_joints_names) != n_s:
            raise PluginConfigError(
                f"{params.kinematics} steering needs {n_t} traction and {n_s} steering joint(s), got "
                f"{len(params.traction_joints_names)} and {len(params.steering_joints_names)}",
                "traction_joints_names",
            )
        for key, mode in (("traction_joints_names", "velocity"), ("steering_joints_names", "position")):
            for jname in getattr(params, key):
                joint = ctx.joint(jname, key)
                if joint.type != mujoco.mjtJoint.mjJNT_HINGE:
                    raise PluginConfigError(f"joint {jname!r} is not revolute/continuous", key)
                max_effort = params.max_wheel_torque if mode == "velocity" else None
                claim_actuator(ctx.spec, name, joint, mode, max_effort=max_effort)  # type: ignore[arg-type]
        return cls.reference_topics(params, name)

    def setup(self) -> None:
        p = self.params
        m, d, r = self.ctx.model, self.ctx.data, self.ctx.robot
        dt = float(m.opt.timestep)
        self.t_joints = [r.joint_id(j) for j in p.traction_joints_names]
        self.s_joints = [r.joint_id(j) for j in p.steering_joints_names]
        self.t_act, self.s_act = [], []
        for jname, jid in zip(p.traction_joints_names, self.t_joints, strict=True):
            a, _own = find_actuator(m, r, self.name, jname, jid, "velocity")
            wheel = int(m.jnt_bodyid[jid])
            kv = _auto_gain(
                m, r.body_ids, wheel, _wheel_radius(m, wheel), len(self.t_joints) + len(self.s_joints)
            )
            m.actuator_gainprm[a, 0] = kv
            m.actuator_biasprm[a, 2] = -kv
            dof = int(m.jnt_dofadr[jid])
            m.dof_armature[dof] = max(float(m.dof_armature[dof]), dt * kv)  # see diff_drive's setup
            self.t_act.append(a)
        # A steering servo's load is the tyres' scrub about the kingpin, which its own small inertia says
        # nothing of: gains as for the inertia of a traction wheel's share of the robot at the rim hold the
        # angle within a few mrad (from the knuckle's inertia alone the car steered 12 % short), close to
        # gz_ros2_control's position interface, which sets the joint where it is told.
        rim = _wheel_radius(m, int(m.jnt_bodyid[self.t_joints[0]]))
        load = float(sum(m.body_mass[b] for b in r.body_ids)) / 4.0 * rim * rim
        for jname, jid in zip(p.steering_joints_names, self.s_joints, strict=True):
            a, own = find_actuator(m, r, self.name, jname, jid, "position")
            dof = int(m.jnt_dofadr[jid])
            if own:
                auto_gains(m, a, "position", max(float(m.dof_M0[dof]), load), dt, None, None)
                m.dof_armature[dof] = max(float(m.dof_armature[dof]), dt * float(-m.actuator_biasprm[a, 2]))
            self.s_act.append(a)
        self.t_q = [int(m.jnt_qposadr[j]) for j in self.t_joints]
        self.t_v = [int(m.jnt_dofadr[j]) for j in self.t_joints]
        self.s_q = [int(m.jnt_qposadr[j]) for j in self.s_joints]
        base = r.root_body
        rot = d.xmat[base].reshape(3, 3)

        def local(jids: list[int]) -> np.ndarray:
            return np.array([rot.T @ (d.xanchor[j] - d.xpos[base]) for j in jids])

        t_pos, s_pos = local(self.t_joints), local(self.s_joints)
        self.wheelbase = p.wheelbase or float(abs(t_pos[:, 0].mean() - s_pos[:, 0].mean()))
        self.radius = p.traction_wheels_radius or float(
            np.mean([_wheel_radius(m, int(m.jnt_bodyid[j])) for j in self.t_joints])
        )
        track = float(abs(t_pos[0, 1] - t_pos[-1, 1])) if len(t_pos) == 2 else 0.0
        self.track_t = p.traction_track_width or track
        s_track = float(abs(s_pos[0, 1] - s_pos[-1, 1])) if len(s_pos) == 2 else self.track_t
        self.track_s = p.steering_track_width or (s_track if len(s_pos) == 2 else self.track_t)
        self.steer_pos = 0.0
        self.last_t_q = [float(d.qpos[q]) for q in self.t_q]
        self.odom = PlanarOdometry(p.velocity_rolling_window_size)
        self.last_ns: int | None = None
        self.traction_cmd = [0.0] * len(self.t_joints)
        self.steering_cmd = [float(d.qpos[q]) for q in self.s_q]
        for a, q in zip(self.s_act, self.steering_cmd, strict=True):
            d.ctrl[a] = q
        self.setup_reference()

    def _odometry(self, dt: float, v_ref: float, w_ref: float) -> None:
        """update_odometry of each steering controller (steering_kinematics.cpp)."""
        p, d = self.params, self.ctx.data
        if p.open_loop:
            self.odom.open_loop(v_ref, w_ref, dt)
            return
        if dt < 0.0001:
            return
        if p.position_feedback:
            q = [float(d.qpos[a]) for a in self.t_q]
            vel = [(qi - qo) / dt for qi, qo in zip(q, self.last_t_q, strict=True)]
            self.last_t_q = q
        else:
            vel = [float(d.qvel[a]) for a in self.t_v]
        steer = [float(d.qpos[a]) for a in self.s_q]
        L = self.wheelbase
        if p.kinematics == "ackermann":
            right = math.atan(L * math.tan(steer[0]) / (L - self.track_s / 2 * math.tan(steer[0])))
            left = math.atan(L * math.tan(steer[1]) / (L + self.track_s / 2 * math.tan(steer[1])))
            self.steer_pos = (right + left) * 0.5
        else:
            self.steer_pos = steer[0]
        if p.kinematics == "steered_traction":  # tricycle_controller odometry.cpp update()
            vs = vel[0] * self.radius
            self.odom.update(vs * math.cos(self.steer_pos) * dt, vs * math.sin(self.steer_pos) / L * dt, dt)
            return
        one = len(vel) == 1
        linear = vel[0] * self.radius if one else self._double_axle(vel[0], vel[1], self.steer_pos)
        angular = math.tan(self.steer_pos) * linear / L
        self.odom.update(linear * dt, angular * dt, dt)

    def _double_axle(self, right_vel: float, left_vel: float, steer: float) -> float:
        vr, vl = right_vel * self.radius, left_vel * self.radius
        tan = math.tan(steer)
        if tan == 0.0:
            return (vr + vl) * 0.5
        turning = self.wheelbase / tan
        half = self.track_t * 0.5
        return (vr * turning / (turning + half) + vl * turning / (turning - half)) * 0.5

    def _commands(self, v: float, w: float) -> tuple[list[float], list[float]]:
        """get_commands of steering_kinematics.cpp: traction wheel speeds and steering angles."""
        p = self.params
        L = self.wheelbase
        if p.angular_is_steering_angle:  # ackermann_steering_controller.cpp (Noetic) update()
            return [v / self.radius], [w]
        if p.kinematics == "steered_traction":
            return self._steered_traction(v, w)
        phi = math.atan(w * L / v) if v != 0 else 0.0
        if not math.isfinite(phi):
            phi = 0.0
        phi_ik = phi if p.open_loop else self.steer_pos
        ws = v / self.radius
        if not p.open_loop and p.reduce_wheel_speed_until_steering_reached:
            delta = abs(self.steer_pos - phi)
            if delta >= _MIN_PHI_DELTA:
                ws *= math.cos(min(delta, _MAX_PHI_DELTA)) / math.cos(_MIN_PHI_DELTA)
        if p.kinematics == "bicycle":
            return [ws], [phi]
        if abs(phi_ik) < 1e-6:
            traction = [ws, ws]
        else:
            turning = L / math.tan(phi_ik)
            half = self.track_t * 0.5
            traction = [ws * (turning + half) / turning, ws * (turning - half) / turning]
        if p.kinematics == "tricycle":
            return traction, [phi]
        if abs(phi_ik) < 1e-6:
            return traction, [phi, phi]
        num, den = 2 * L * math.sin(phi), 2 * L * math.cos(phi)
        side = self.track_s * math.sin(phi)
        return traction, [math.atan2(num, den + side), math.atan2(num, den - side)]

    def _steered_traction(self, v: float, w: float) -> tuple[list[float], list[float]]:
        """tricycle_controller.cpp twist_to_ackermann() and its speed reduction: the steered wheel's angle
        and speed for (v, w), slowed while the wheel is far from that angle (cos of the error past 30°,
        0.01 past 90°)."""
        L = self.wheelbase
        if v == 0.0:
            if w == 0.0:  # convert_trans_rot_vel_to_steering_angle gives 0: it steers straight
                return [0.0], [0.0]
            alpha, ws = math.copysign(math.pi / 2, w), abs(w) * L / self.radius
        else:
            alpha = math.atan(w * L / v)
            ws = v / (self.radius * math.cos(alpha))
        delta = abs(alpha - self.steer_pos)
        scale = 1.0 if delta < math.pi / 6 else 0.01 if delta > math.pi / 2 else math.cos(delta)
        return [ws * scale], [alpha]

    def commanded(self) -> list[int]:
        return [*self.t_act, *self.s_act]

    def before_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        p, d = self.params, self.ctx.data
        usable = reference_usable(self.command, p.reference_timeout, now_ns)
        twist = self.command.twist
        v, w = (float(twist.linear.x), float(twist.angular.z)) if usable else (0.0, 0.0)
        last, self.last_ns = self.last_ns, now_ns
        if last is not None:
            self._odometry((now_ns - last) / 1e9, v, w)
        if usable:
            self.traction_cmd, self.steering_cmd = self._commands(v, w)
        elif p.angular_is_steering_angle or p.kinematics == "steered_traction":
            # ROS 1, and tricycle_controller ("brake if cmd_vel has timeout"): a stale command is zero,
            # steering straight
            self.traction_cmd, self.steering_cmd = [0.0] * len(self.t_act), [0.0] * len(self.s_act)
        else:  # no reference: the traction wheels stop, the steering stays where it was sent
            self.traction_cmd = [0.0] * len(self.t_act)
        for a, c in zip(self.t_act, self.traction_cmd, strict=True):
            d.ctrl[a] = c
        for a, c in zip(self.s_act, self.steering_cmd, strict=True):
            d.ctrl[a] = c

    def after_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        o = self.odom
        pos, quat = (o.x, o.y, 0.0), o.quat()
        self.odom_out.publish(now_ns, pos, quat, (o.linear, 0.0, 0.0), (0.0, 0.0, o.angular))
        if self.tf_out:
            self.tf_out.publish(now_ns, pos, quat)
        if self.state_pub:
            d, T = self.ctx.data, msgs.T
            feedback = self.params.position_feedback
            self.state_pub.publish(
                T["control_msgs/msg/SteeringControllerStatus"](
                    header=msgs.header(now_ns, ""),
                    traction_wheels_position=np.array([d.qpos[q] for q in self.t_q] if feedback else []),
                    traction_wheels_velocity=np.array([] if feedback else [d.qvel[v] for v in self.t_v]),
                    steer_positions=np.array([d.qpos[q] for q in self.s_q]),
                    linear_velocity_command=np.array(self.traction_cmd, dtype=float),
                    steering_angle_command=np.array(self.steering_cmd, dtype=float),
                ),
                now_ns,
            )
