"""joint_controller: drive one or more joints by position, velocity or effort (like gz-sim
JointPositionController / JointController, or a ros2_control forward command controller).

Subscribes one command topic (default `<plugin name>/command`):
- `float64` (std_msgs/Float64) for one joint;
- `float64_array` (std_msgs/Float64MultiArray), one value per joint in the order of `joints`;
- `joint_state` (sensor_msgs/JointState), matched by joint name, using its position, velocity or effort
  field according to `mode` (joints it does not name keep their command).

Each joint is driven by a MuJoCo actuator, so the control runs inside the physics step and the plugin costs
nothing between commands. An actuator that already targets the joint (e.g. one made from a URDF
`<transmission>`) is reused when it fits the mode; otherwise a position, velocity or motor actuator is
added, and an actuator of another kind on that joint is disabled (its gear set to 0) so that the two do not
fight. Position targets are clamped to the joint's limits. Force limits come from `max_effort`, else from
the URDF `<limit effort>`.

Default gains (from the inertia the joint moves, `dof_M0`): position mode, a critically damped servo with
a natural frequency of 0.15/timestep (75 rad/s at 2 ms: a lift sags g/ω² ≈ 1.7 mm under its own weight);
velocity mode, a time constant of 2 physics steps (the steady error under a load is load/kv).
"""

from __future__ import annotations

import logging
import math
from typing import Any, Literal

import mujoco
import numpy as np
from pydantic import Field, NonNegativeFloat, PositiveFloat

from plugins._actuators import Lifecycle, auto_gains, claim_actuator, find_actuator
from runner.plugin import BuildContext, Plugin, PluginConfigError, PluginParams, Topic

log = logging.getLogger(__name__)

_MESSAGE_TYPES = {
    "float64": "std_msgs/msg/Float64",
    "float64_array": "std_msgs/msg/Float64MultiArray",
    "joint_state": "sensor_msgs/msg/JointState",
}
Mode = Literal["position", "velocity", "effort"]


class JointControllerParams(PluginParams):
    joints: list[str] = Field(min_length=1, description="Joints to drive (revolute, continuous, prismatic).")
    mode: Mode = Field("position", description="What a command sets: position, velocity or effort.")
    topic: str | None = Field(None, description="Command topic (default: `<plugin name>/command`).")
    message: Literal["float64", "float64_array", "joint_state"] | None = Field(
        None,
        description="Command message: float64 (std_msgs/Float64), float64_array "
        "(std_msgs/Float64MultiArray, in the order of `joints`) or joint_state (sensor_msgs/JointState, by "
        "name). Default: float64 for one joint, float64_array for several.",
    )
    kp: PositiveFloat | None = Field(
        None, description="Position gain, N/m or N·m/rad (default: from the joint's inertia)."
    )
    kv: NonNegativeFloat | None = Field(
        None,
        description="Velocity gain, N per m/s or N·m per rad/s: the damping of a position servo, the gain "
        "of a velocity servo (default: from the joint's inertia).",
    )
    max_effort: PositiveFloat | None = Field(
        None, description="Force or torque limit, N or N·m (default: the URDF's <limit effort>, if any)."
    )
    initial: list[float] | None = Field(
        None,
        description="Command until the first message, one value per joint (default: hold the starting "
        "position, or zero velocity / effort). In position mode the joints also start there.",
    )


def _message_of(params: JointControllerParams) -> str:
    return params.message or ("float64" if len(params.joints) == 1 else "float64_array")


class JointController(Lifecycle, Plugin):
    Params = JointControllerParams
    params: JointControllerParams

    @classmethod
    def build(cls, params: JointControllerParams, ctx: BuildContext, name: str) -> list[Topic]:
        joints = params.joints
        if len(set(joints)) != len(joints):
            raise PluginConfigError("a joint is named twice", "joints")
        if params.initial is not None and len(params.initial) != len(joints):
            raise PluginConfigError(
                f"`initial` has {len(params.initial)} values for {len(joints)} joints", "initial"
            )
        if params.mode == "velocity" and params.kv == 0:
            raise PluginConfigError("a velocity servo needs a gain above 0", "kv")
        message = _message_of(params)
        if message == "float64" and len(joints) > 1:
            raise PluginConfigError(
                "a float64 command drives one joint", "message", hint="use float64_array or joint_state"
            )
        for jname in joints:
            joint = ctx.joint(jname, "joints")
            if joint.type not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
                raise PluginConfigError(f"joint {jname!r} is not revolute, continuous or prismatic", "joints")
            claim_actuator(
                ctx.spec, name, joint, params.mode, kp=params.kp, kv=params.kv, max_effort=params.max_effort
            )
        topic = params.topic or f"{name}/command"
        return [Topic(topic, _MESSAGE_TYPES[message], "sub")]

    def setup(self) -> None:
        p = self.params
        m, d = self.ctx.model, self.ctx.data
        r = self.ctx.robot
        n = len(p.joints)
        self.index = {j: k for k, j in enumerate(p.joints)}
        jids = [r.joint_id(j) for j in p.joints]
        self.qadr = np.array([int(m.jnt_qposadr[j]) for j in jids])
        dofs = [int(m.jnt_dofadr[j]) for j in jids]
        self.act = np.zeros(n, dtype=int)
        self.gear = np.ones(n)
        self.lo = np.full(n, -np.inf)
        self.hi = np.full(n, np.inf)
        self.warned: set[str] = set()
        dt = float(m.opt.timestep)
        for k, (jname, jid, dof) in enumerate(zip(p.joints, jids, dofs, strict=True)):
            a, own = find_actuator(m, r, self.name, jname, jid, p.mode)
            self.act[k] = a
            self.gear[k] = float(m.actuator_gear[a, 0])
            if m.jnt_limited[jid]:
                self.lo[k], self.hi[k] = m.jnt_range[jid]
            if own:
                auto_gains(m, a, p.mode, float(m.dof_M0[dof]), dt, p.kp, p.kv)
        if p.mode == "position":
            start = np.clip(np.array(p.initial) if p.initial else d.qpos[self.qadr], self.lo, self.hi)
            if p.initial:
                d.qpos[self.qadr] = start
                d.qvel[dofs] = 0.0
                mujoco.mj_forward(m, d)
            self.target = start
        else:
            self.target = np.array(p.initial, dtype=float) if p.initial else np.zeros(n)
        for k in range(n):
            self._set(k, float(self.target[k]))
        message = _message_of(p)
        topic = p.topic or f"{self.name}/command"
        callback = {"float64": self._on_float, "float64_array": self._on_array, "joint_state": self._on_state}
        self.ctx.subscribe(topic, _MESSAGE_TYPES[message], callback[message])

    def on_activate(self) -> None:
        """A forward command controller activated again (the controller_manager plugin): its command
        interfaces still hold its last command, which gz_ros2_control's system follows again."""
        for k in range(len(self.params.joints)):
            self._set(k, float(self.target[k]))

    def commanded(self) -> list[int]:
        """Deactivated, commands are ignored and the hardware holds the joints where they are."""
        return self.act.tolist()

    def _set(self, k: int, value: float) -> None:
        if not math.isfinite(value):
            self._warn("nan", f"{self.name}: ignoring a non-finite command for {self.params.joints[k]!r}")
            return
        if not self.active:
            return
        mode = self.params.mode
        if mode == "position":
            value = min(max(value, self.lo[k]), self.hi[k])
        self.target[k] = value
        ctrl = value / self.gear[k] if mode == "effort" else value * self.gear[k]
        self.ctx.data.ctrl[self.act[k]] = ctrl

    def _warn(self, key: str, text: str) -> None:
        if key not in self.warned:
            self.warned.add(key)
            log.warning(text)

    def _on_float(self, msg: Any, stamp_ns: int) -> None:
        self._set(0, float(msg.data))

    def _on_array(self, msg: Any, stamp_ns: int) -> None:
        values = np.asarray(msg.data, dtype=float)
        if len(values) != len(self.params.joints):
            self._warn(
                "len",
                f"{self.name}: ignoring a command of {len(values)} values "
                f"for {len(self.params.joints)} joints",
            )
            return
        for k, v in enumerate(values):
            self._set(k, float(v))

    def _on_state(self, msg: Any, stamp_ns: int) -> None:
        values = {"position": msg.position, "velocity": msg.velocity, "effort": msg.effort}[self.params.mode]
        for i, jname in enumerate(msg.name):
            k = self.index.get(jname)
            if k is not None and i < len(values):
                self._set(k, float(values[i]))
