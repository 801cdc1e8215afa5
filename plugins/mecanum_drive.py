"""mecanum_drive: ros2_controllers' mecanum_drive_controller.

Subscribes the reference (`<name>/reference`, geometry_msgs/TwistStamped: linear.x, linear.y,
angular.z in the base frame); drives the four wheel joints by velocity with the controller's inverse
kinematics (mecanum_drive_controller.cpp, update_and_write_commands: base_frame_offset, wheels_radius,
sum_of_robot_center_projection_on_X_Y_axis) after its speed limiter; publishes odometry integrated from
the wheels' velocities (mecanum_drive_controller/src/odometry.cpp) on `<name>/odometry` and
`<name>/tf_odometry`, and control_msgs/MecanumDriveControllerState on `<name>/controller_state`, at every
update.

Mecanum wheels roll along their rollers. Gazebo gets that from the description's friction (mu2 = 0 across
an fdir1 at 45°); MuJoCo's friction is isotropic, so with `rollers` (the default) each wheel gets a ring of
passive rollers: spheres on free hinges whose axes lie at 45° to the axle, in the direction the controller's
kinematics assume (the ground contact grips along the roller axis and rolls freely across it), and the
wheel's own collision stops touching anything.
"""

from __future__ import annotations

import math
from typing import Any

import mujoco
import numpy as np
from pydantic import Field, PositiveFloat

from plugins._actuators import claim_actuator, find_actuator
from plugins._mobile import (
    AxisLimits,
    ReferenceDrive,
    ReferenceParams,
    SpeedLimiter,
    reference_usable,
)
from plugins.diff_drive import _auto_gain, _wheel_radius
from runner.geometry import wheel_radius
from runner.plugin import BuildContext, PluginConfigError, Topic
from runner.wire import msgs

WHEELS = ("front_left", "front_right", "rear_right", "rear_left")  # the controller's order
# the roller axis at the ground, from the base's x axis: fl and rr at -45°, fr and rl at +45°, what the
# inverse kinematics' signs say (fl: r·w = vx - vy - k·wz)
_ROLLER_ANGLE = {"front_left": -45.0, "front_right": 45.0, "rear_right": -45.0, "rear_left": 45.0}
_ROLLERS = 16
_ROLLER_SIZE = 0.3  # roller radius / wheel radius


class MecanumDriveParams(ReferenceParams):
    front_left_wheel_command_joint_name: str = Field(
        "front_left_wheel_joint", description="Front left wheel joint."
    )
    front_right_wheel_command_joint_name: str = Field(
        "front_right_wheel_joint", description="Front right wheel joint."
    )
    rear_right_wheel_command_joint_name: str = Field(
        "rear_right_wheel_joint", description="Rear right wheel joint."
    )
    rear_left_wheel_command_joint_name: str = Field(
        "rear_left_wheel_joint", description="Rear left wheel joint."
    )
    wheels_radius: PositiveFloat | None = Field(
        None, description="Wheel radius, m (default: from the wheels' collision geometry)."
    )
    sum_of_robot_center_projection_on_X_Y_axis: PositiveFloat | None = Field(
        None, description="lx + ly, m: half the wheelbase plus half the track (default: measured)."
    )
    base_frame_offset: tuple[float, float, float] = Field(
        (0.0, 0.0, 0.0), description="x, y, theta of the base frame in the wheels' centre frame."
    )
    reference_timeout: float = Field(
        0.0, ge=0, description="As the controller's (default 0: each reference drives one update)."
    )
    linear_x_limits: AxisLimits | None = Field(None, description="Speed limiter of linear.x.")
    linear_y_limits: AxisLimits | None = Field(None, description="Speed limiter of linear.y.")
    angular_z_limits: AxisLimits | None = Field(None, description="Speed limiter of angular.z.")
    rollers: bool = Field(
        True,
        description="Give each wheel passive rollers at 45° (what Gazebo's anisotropic friction does for "
        "a mecanum description); false: the wheels as described.",
    )


def _joints(p: MecanumDriveParams) -> list[str]:
    return [getattr(p, f"{w}_wheel_command_joint_name") for w in WHEELS]


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """`v` rotated about the unit `axis` by `angle` (Rodrigues)."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * float(axis @ v) * (1 - c)


def _quat_z_to(direction: np.ndarray) -> list[float]:
    """A quaternion (w, x, y, z) turning the z axis onto `direction`."""
    z = np.array([0.0, 0.0, 1.0])
    d = direction / np.linalg.norm(direction)
    axis = np.cross(z, d)
    s = float(np.linalg.norm(axis))
    if s < 1e-9:
        return [1.0, 0.0, 0.0, 0.0] if d[2] > 0 else [0.0, 1.0, 0.0, 0.0]
    angle = math.atan2(s, float(z @ d))
    axis /= s
    return [math.cos(angle / 2), *(axis * math.sin(angle / 2)).tolist()]


def _add_rollers(ctx: BuildContext, name: str, joints: list[Any]) -> None:
    """A ring of passive rollers on each wheel, their axes at the controller's 45° at the ground."""
    try:  # the robot as described: where each wheel is, and how it is turned
        model = ctx.spec.compile()
    except ValueError as e:
        raise PluginConfigError(
            f"cannot place rollers on the wheels: the robot does not compile on its own ({e})",
            "rollers",
            hint="set rollers: false to drive the wheels as described",
        ) from None
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    root = model.body(ctx.root).id
    base_rot = data.xmat[root].reshape(3, 3)
    for wheel, joint in zip(WHEELS, joints, strict=True):
        body = joint.parent
        b = model.body(body.name).id
        j = model.joint(joint.name).id
        radius = wheel_radius(model, b)
        if not radius:
            raise PluginConfigError(
                f"cannot find the radius of wheel {body.name!r} for its rollers",
                f"{wheel}_wheel_command_joint_name",
                hint="give the wheel a cylinder or sphere collision, or set rollers: false",
            )
        rot = data.xmat[b].reshape(3, 3)  # wheel frame -> world
        axle = np.array(model.jnt_axis[j], dtype=float)
        axle /= np.linalg.norm(axle)
        centre = np.array(model.jnt_pos[j], dtype=float)
        down = rot.T @ (base_rot @ np.array([0.0, 0.0, -1.0]))
        down -= axle * float(axle @ down)
        down /= np.linalg.norm(down)
        angle = math.radians(_ROLLER_ANGLE[wheel])
        ground_axis = rot.T @ (base_rot @ np.array([math.cos(angle), math.sin(angle), 0.0]))
        size = _ROLLER_SIZE * radius
        # the rollers take a fifth of the wheel's mass from it: the robot weighs what it is described to
        mass = float(model.body_mass[b]) * 0.2 / _ROLLERS
        if mass <= 0:
            mass = 0.001
        elif body.mass > _ROLLERS * mass:
            body.mass = float(body.mass) - _ROLLERS * mass
        inertia = 0.4 * mass * size * size
        conaffinity = 1
        for geom in body.geoms:
            if geom.contype or geom.conaffinity:
                conaffinity = int(geom.conaffinity) or int(geom.contype)
                geom.contype = geom.conaffinity = 0  # the rollers touch the ground instead
        for k in range(_ROLLERS):
            turn = 2 * math.pi * k / _ROLLERS
            at = centre + _rotate(down, axle, turn) * (radius - size)
            roller = body.add_body(
                name=f"{name}/{wheel}_roller{k}",
                pos=at.tolist(),
                quat=_quat_z_to(_rotate(ground_axis, axle, turn)),
                mass=mass,
                inertia=[inertia] * 3,
            )
            roller.add_joint(
                name=f"{name}/{wheel}_roller{k}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1]
            )
            # contype 0: rollers do not touch each other (neighbours overlap) but what the wheel touched
            # (its conaffinity) touches them; nor the link the wheel turns on (MuJoCo's parent filter
            # skips only parent and child)
            if body.parent is not None and body.parent.name:
                ctx.spec.add_exclude(bodyname1=body.parent.name, bodyname2=roller.name)
            roller.add_geom(
                type=mujoco.mjtGeom.mjGEOM_SPHERE,
                size=[size, 0, 0],
                contype=0,
                conaffinity=conaffinity,
                group=3,
                rgba=[0.2, 0.2, 0.2, 1],
            )


class MecanumDrive(ReferenceDrive):
    Params = MecanumDriveParams
    params: MecanumDriveParams
    STATE_TYPE = "control_msgs/msg/MecanumDriveControllerState"
    COVARIANCE_DEFAULT = [0.1] * 6

    @classmethod
    def build(cls, params: MecanumDriveParams, ctx: BuildContext, name: str) -> list[Topic]:
        joints = []
        for wheel, jname in zip(WHEELS, _joints(params), strict=True):
            key = f"{wheel}_wheel_command_joint_name"
            joint = ctx.joint(jname, key)
            if joint.type != mujoco.mjtJoint.mjJNT_HINGE:
                raise PluginConfigError(f"wheel joint {jname!r} is not revolute/continuous", key)
            joints.append(joint)
        if len({j.name for j in joints}) != 4:
            raise PluginConfigError("a wheel joint is named twice", "front_left_wheel_command_joint_name")
        if params.rollers:
            _add_rollers(ctx, name, joints)
        for joint in joints:
            claim_actuator(ctx.spec, name, joint, "velocity", max_effort=params.max_wheel_torque)
        return cls.reference_topics(params, name)

    def setup(self) -> None:
        p = self.params
        m, d, r = self.ctx.model, self.ctx.data, self.ctx.robot
        dt = float(m.opt.timestep)
        names = _joints(p)
        jids = [r.joint_id(j) for j in names]
        self.vadr = [int(m.jnt_dofadr[j]) for j in jids]
        self.act = []
        bodies = [int(m.jnt_bodyid[j]) for j in jids]
        self.radius = p.wheels_radius or float(np.mean([_radius(m, b) for b in bodies]))
        for jname, jid, b in zip(names, jids, bodies, strict=True):
            a, _own = find_actuator(m, r, self.name, jname, jid, "velocity")
            kv = _auto_gain(m, r.body_ids, b, self.radius, 4)
            m.actuator_gainprm[a, 0] = kv
            m.actuator_biasprm[a, 2] = -kv
            dof = int(m.jnt_dofadr[jid])
            m.dof_armature[dof] = max(float(m.dof_armature[dof]), dt * kv)  # see diff_drive's setup
            self.act.append(a)
        base = r.root_body
        rot = d.xmat[base].reshape(3, 3)
        local = np.array([rot.T @ (d.xanchor[j] - d.xpos[base]) for j in jids])
        centre = local.mean(axis=0)
        lx = float(np.mean(np.abs(local[:, 0] - centre[0])))
        ly = float(np.mean(np.abs(local[:, 1] - centre[1])))
        self.lxy = p.sum_of_robot_center_projection_on_X_Y_axis or (lx + ly)
        self.limiters = [
            SpeedLimiter(lim) if lim else None
            for lim in (p.linear_x_limits, p.linear_y_limits, p.angular_z_limits)
        ]
        self.x = self.y = self.heading = 0.0
        self.vel = (0.0, 0.0, 0.0)
        self.reference = (math.nan, math.nan, math.nan)
        self.last_ns: int | None = None
        self.setup_reference()

    def _odometry(self, dt: float) -> None:
        """mecanum_drive_controller's Odometry::update, from the wheels' velocities."""
        if dt < 0.0001:
            return
        qvel = self.ctx.data.qvel
        fl, fr, rr, rl = (float(qvel[v]) for v in self.vadr)
        r, k = self.radius, self.lxy
        vx = 0.25 * r * (fl + rl + rr + fr)
        vy = 0.25 * r * (-fl + rl - rr + fr)
        wz = 0.25 * r / k * (-fl - rl + rr + fr)
        ox, oy, theta = self.params.base_frame_offset
        c, s = math.cos(-theta), math.sin(-theta)
        bx, by = c * vx - s * vy, s * vx + c * vy  # centre -> base rotation
        tx, ty = c * -ox - s * -oy, s * -ox + c * -oy
        bx, by = bx + ty * wz, by - tx * wz
        self.heading += wz * dt
        ch, sh = math.cos(self.heading), math.sin(self.heading)
        self.x += (ch * bx - sh * by) * dt
        self.y += (sh * bx + ch * by) * dt
        self.vel = (bx, by, wz)

    def commanded(self) -> list[int]:
        return list(self.act)

    def before_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        p, d = self.params, self.ctx.data
        last, self.last_ns = self.last_ns, now_ns
        if last is not None:
            self._odometry((now_ns - last) / 1e9)
        dt = 1.0 / float(p.update_rate or 100.0)
        if reference_usable(self.command, p.reference_timeout, now_ns):
            t = self.command.twist
            ref = [float(t.linear.x), float(t.linear.y), float(t.angular.z)]
            self.reference = (ref[0], ref[1], ref[2])
            for i, lim in enumerate(self.limiters):
                if lim is not None:
                    ref[i] = lim.limit(ref[i], dt)
            vx, vy, wz = ref
            ox, oy, theta = p.base_frame_offset
            c, s = math.cos(theta), math.sin(theta)
            cx = c * vx - s * vy + oy * wz
            cy = s * vx + c * vy - ox * wz
            k, inv = self.lxy, 1.0 / self.radius
            wheels = (
                inv * (cx - cy - k * wz),
                inv * (cx + cy + k * wz),
                inv * (cx - cy + k * wz),
                inv * (cx + cy - k * wz),
            )
        else:  # no reference: the controller commands zero
            self.reference = (math.nan, math.nan, math.nan)
            wheels = (0.0, 0.0, 0.0, 0.0)
        for a, w in zip(self.act, wheels, strict=True):
            d.ctrl[a] = w

    def after_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        half = self.heading / 2.0
        quat = (math.cos(half), 0.0, 0.0, math.sin(half))
        pos = (self.x, self.y, 0.0)
        vx, vy, wz = self.vel
        self.odom_out.publish(now_ns, pos, quat, (vx, vy, 0.0), (0.0, 0.0, wz))
        if self.tf_out:
            self.tf_out.publish(now_ns, pos, quat)
        if self.state_pub:
            T, qvel = msgs.T, self.ctx.data.qvel
            fl, fr, rr, rl = (float(qvel[v]) for v in self.vadr)
            rx, ry, rz = self.reference
            self.state_pub.publish(
                T["control_msgs/msg/MecanumDriveControllerState"](
                    header=msgs.header(now_ns, ""),
                    front_left_wheel_velocity=fl,
                    back_left_wheel_velocity=rl,
                    back_right_wheel_velocity=rr,
                    front_right_wheel_velocity=fr,
                    reference_velocity=T["geometry_msgs/msg/Twist"](
                        linear=T["geometry_msgs/msg/Vector3"](x=rx, y=ry, z=0.0),
                        angular=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=rz),
                    ),
                ),
                now_ns,
            )


def _radius(m: mujoco.MjModel, body: int) -> float:
    """A wheel's radius: of its own collision, or (with rollers) of its rollers' outer edge."""
    try:
        return _wheel_radius(m, body)
    except ValueError:
        pass
    rollers = [b for b in range(m.nbody) if int(m.body_parentid[b]) == body]
    if rollers:
        extent = max(
            float(np.linalg.norm(m.body_pos[b])) + float(m.geom_size[m.body_geomadr[b], 0]) for b in rollers
        )
        return extent
    raise ValueError("cannot find the wheel radius from the model; set `wheels_radius`")
