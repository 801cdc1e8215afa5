"""planar_move: move a mobile robot's base with a commanded planar velocity, like gazebo_ros_planar_move.

Subscribes `cmd_vel` (geometry_msgs/Twist: linear.x, linear.y, angular.z in the robot's heading frame)
and publishes `odom` (nav_msgs/Odometry, the true pose relative to where the robot started, as the Gazebo
plugin does) and the odom -> base transform on `tf`. The wheels need no actuators: they may be passive.

Mechanism: three MuJoCo velocity servos act on a site at the base link's origin, along its x and y axes
and about its z axis (actuators with a site transmission, so the force follows the robot's heading). Their
gain is set from the robot's inertia for a time constant of two physics steps, and an integral term
removes the steady error under load (wheels scrubbing sideways, a caster's drag), so the base moves at
the commanded velocity. Unlike Gazebo's plugin, which overwrites the model's velocity, the base stays a
dynamic body: gravity and contacts still act (it stays on the ground and rests on its wheels, and a wall
stops it), and the servos' force and torque are limited (`max_force`, `max_torque`). The servos run inside
the physics step; the plugin only updates their targets at `rate`, so it costs next to nothing.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
from pydantic import Field, PositiveFloat

from plugins._common import BaseDriveParams, OdometryWriter, TransformWriter, drive_topics
from runner.geometry import quat_to_yaw, yaw_to_quat
from runner.plugin import BuildContext, Plugin, PluginConfigError, Topic

_INTEGRAL_TIME_S = 0.1
_SERVO_STEPS = 2.0  # time constant of the velocity servos, physics steps
_FRICTION_MARGIN = 3.0  # default force limit: this many times the robot's weight
_AXES = ("x", "y", "yaw")


class PlanarMoveParams(BaseDriveParams):
    rate: float = Field(50.0, gt=0, description="Odometry publish rate (and command update rate), sim Hz.")
    max_force: PositiveFloat | None = Field(
        None,
        description="Force limit of the planar motion, N (default: three times the robot's weight, enough "
        "to drag passive wheels sideways).",
    )
    max_torque: PositiveFloat | None = Field(
        None,
        description="Torque limit of the rotation, N·m (default: `max_force` times the robot's horizontal "
        "reach from its base origin).",
    )
    pose_covariance_diagonal: list[float] | None = Field(
        None, min_length=6, max_length=6, description="Odometry pose covariance diagonal (default: zeros)."
    )
    twist_covariance_diagonal: list[float] | None = Field(
        None, min_length=6, max_length=6, description="Odometry twist covariance diagonal (default: zeros)."
    )


class PlanarMove(Plugin):
    Params = PlanarMoveParams
    params: PlanarMoveParams

    @classmethod
    def build(cls, params: PlanarMoveParams, ctx: BuildContext, name: str) -> list[Topic]:
        add_planar_servos(ctx, name)
        return drive_topics(params)

    def setup(self) -> None:
        p = self.params
        m, d = self.ctx.model, self.ctx.data
        r = self.ctx.robot
        self.act = np.array([r.actuator_id(f"{self.name}/{a}") for a in _AXES])
        self.site = r.site_id(f"{self.name}_base")
        self.base = r.root_body
        # Gains: the inertia each servo moves (from the mass matrix), for a 2-step time constant; the
        # servos are velocity-implicit under implicitfast, and still stable under Euler (kv·dt/m = 0.5).
        mujoco.mj_forward(m, d)
        inertia = _servo_inertia(m, d, self.site)
        tau = _SERVO_STEPS * float(m.opt.timestep)
        kv = inertia / tau
        mass = float(sum(m.body_mass[b] for b in r.body_ids))
        weight = mass * float(np.linalg.norm(m.opt.gravity) or 9.81)
        force = p.max_force or _FRICTION_MARGIN * weight
        torque = p.max_torque or force * _reach(m, d, r.geom_ids, self.base)
        limits = np.array([force, force, torque])
        for a, k, lim in zip(self.act, kv, limits, strict=True):
            m.actuator_gainprm[a, 0] = k
            m.actuator_biasprm[a, 2] = -k
            m.actuator_forcerange[a] = (-lim, lim)
        self.integral = np.zeros(3)
        self.integral_max = limits / kv
        self.dt = 1.0 / p.rate
        self.cmd = np.zeros(3)
        self.cmd_time = 0
        # odometry: the pose relative to the start, in the start's heading frame
        self.p0 = d.xpos[self.base].copy()
        self.q0_inv = yaw_to_quat(-quat_to_yaw(d.xquat[self.base]))
        self.vel = np.zeros(6)
        self.base_frame = p.base_frame or r.frame(r.root_link)
        self.odom_frame = r.frame(p.odom_frame)
        self.ctx.subscribe(p.cmd_topic, "geometry_msgs/msg/Twist", self._on_cmd)
        odom_pub = self.ctx.publisher(p.odom_topic, "nav_msgs/msg/Odometry") if p.publish_odom else None
        tf_pub = self.ctx.publisher(p.tf_topic, "tf2_msgs/msg/TFMessage") if p.publish_tf else None
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
        self.tf_out = TransformWriter(tf_pub, self.odom_frame, self.base_frame) if tf_pub else None

    def _on_cmd(self, msg: Any, stamp_ns: int) -> None:
        self.cmd[:] = (float(msg.linear.x), float(msg.linear.y), float(msg.angular.z))
        self.cmd_time = stamp_ns

    def before_step(self, now_ns: int) -> None:
        p = self.params
        target = self.cmd
        if p.cmd_timeout and now_ns - self.cmd_time > p.cmd_timeout * 1e9:
            target = np.zeros(3)
        d = self.ctx.data
        speed = d.actuator_velocity[self.act]
        self.integral += (target - speed) * (self.dt / _INTEGRAL_TIME_S)
        np.clip(self.integral, -self.integral_max, self.integral_max, out=self.integral)
        d.ctrl[self.act] = target + self.integral

    def after_step(self, now_ns: int) -> None:
        m, d = self.ctx.model, self.ctx.data
        pos = _rotate(self.q0_inv, d.xpos[self.base] - self.p0)
        quat = np.empty(4)
        mujoco.mju_mulQuat(quat, self.q0_inv, d.xquat[self.base])
        # XBODY: the link's own frame at its origin (BODY would be its inertial frame, at its centre of mass)
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, self.base, self.vel, 1)
        if self.odom_out:
            self.odom_out.publish(now_ns, pos, quat, self.vel[3:], self.vel[:3])
        if self.tf_out:
            self.tf_out.publish(now_ns, pos, quat)


def add_planar_servos(ctx: BuildContext, name: str) -> None:
    """Three velocity servos on a site at the base link's origin: along its x and y axes and about its z
    axis (`<name>/x`, `<name>/y`, `<name>/yaw`); gains and limits are set in setup(), from the compiled
    model. Also used by plugins.force_based_move."""
    base = ctx.body(ctx.root)
    if not any(j.type == mujoco.mjtJoint.mjJNT_FREE for j in base.joints):
        raise PluginConfigError(
            f"robot {ctx.robot!r} has no free base to move", hint=f"{name} needs `fixed: false`"
        )
    site = f"{name}_base"
    if ctx.spec.site(site) is not None:
        raise PluginConfigError(f"a site named {site!r} already exists", hint="give the plugin a `name:`")
    base.add_site(name=site, size=[0.005, 0.005, 0.005], group=4)
    gears = ([1, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0], [0, 0, 0, 0, 0, 1])
    for axis, gear in zip(_AXES, gears, strict=True):
        act = ctx.spec.add_actuator(name=f"{name}/{axis}", target=site, trntype=mujoco.mjtTrn.mjTRN_SITE)
        act.gear = gear
        act.set_to_velocity(kv=1.0)
        act.forcelimited = True
        act.forcerange = [-1.0, 1.0]


def _servo_inertia(m: mujoco.MjModel, d: mujoco.MjData, site: int) -> np.ndarray:
    """The inertia each servo sees: 1 / (J M⁻¹ Jᵀ) for the site's x, y (translation) and z (rotation)."""
    jacp = np.zeros((3, m.nv))
    jacr = np.zeros((3, m.nv))
    mujoco.mj_jacSite(m, d, jacp, jacr, site)
    rot = d.site_xmat[site].reshape(3, 3)
    jac = np.vstack([rot[:, 0] @ jacp, rot[:, 1] @ jacp, rot[:, 2] @ jacr])
    minv_jt = np.zeros((3, m.nv))
    mujoco.mj_solveM(m, d, minv_jt, jac)
    return 1.0 / np.einsum("ij,ij->i", jac, minv_jt)


def _reach(m: mujoco.MjModel, d: mujoco.MjData, geoms: np.ndarray, base: int) -> float:
    """How far the robot's collision geometry reaches horizontally from the base origin, metres."""
    reach = 0.0
    for g in geoms:
        if m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0:
            continue
        offset = d.geom_xpos[g] - d.xpos[base]
        reach = max(reach, float(np.hypot(offset[0], offset[1]) + m.geom_rbound[g]))
    return reach or 0.1


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    out = np.empty(3)
    mujoco.mju_rotVecQuat(out, v, q)
    return out
