"""Joint actuators shared by the plugins that command joints (joint_controller, the ros2_control
controllers): which mode an actuator serves, finding or adding the one a controller claims, default gains.

The contract with the hardware layer (runner.compile: `<ros2_control>` / `<transmission>`): the hardware adds,
before any plugin is built, one actuator per (joint, command interface) — position servo, velocity servo or
motor — with its gains, force limit and gear. A controller's `build` claims a joint's interface with
`claim_actuator`: the hardware's actuator of that kind is reused (its gains left alone unless the controller
gives its own), or one is added; actuators of other kinds on that joint are disabled (gear 0), as a claimed
command interface excludes the others in ros2_control. At run time `find_actuator` gives its index.

A controller plugin's lifecycle (`Lifecycle`, switched by the controller_manager plugin): inactive, its
hooks do nothing and its actuators are `release`d to the hardware's hold, as gz_ros2_control's system holds
a joint no active controller commands.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import mujoco

Mode = Literal["position", "velocity", "effort"]

OMEGA_STEPS = 0.15  # position servo: natural frequency × timestep
VELOCITY_STEPS = 2.0  # velocity servo: time constant in physics steps


def kind(gaintype: int, biastype: int, dyntype: int, gain0: float, bias: Any) -> str | None:
    """The mode a joint actuator serves: effort (motor), position or velocity (servo), else None."""
    if int(dyntype) != int(mujoco.mjtDyn.mjDYN_NONE) or int(gaintype) != int(mujoco.mjtGain.mjGAIN_FIXED):
        return None
    if int(biastype) == int(mujoco.mjtBias.mjBIAS_NONE):
        return "effort" if gain0 != 0 else None
    if int(biastype) == int(mujoco.mjtBias.mjBIAS_AFFINE) and bias[0] == 0:
        if bias[1] != 0 and math.isclose(-bias[1], gain0):
            return "position"
        if bias[1] == 0 and bias[2] != 0 and math.isclose(-bias[2], gain0):
            return "velocity"
    return None


def spec_kind(act: Any) -> str | None:
    """The mode an actuator of an MjSpec serves (None when disabled or of no mode)."""
    if act.gear[0] == 0:
        return None
    return kind(act.gaintype, act.biastype, act.dyntype, act.gainprm[0], act.biasprm)


def _kind_of(act: Any) -> str | None:
    return kind(act.gaintype, act.biastype, act.dyntype, act.gainprm[0], act.biasprm)


def claim_actuator(
    spec: mujoco.MjSpec,
    name: str,
    joint: Any,
    mode: Mode,
    *,
    kp: float | None = None,
    kv: float | None = None,
    max_effort: float | None = None,
) -> Any:
    """The actuator `name` (a controller, prefix of the actuator it adds) drives `joint` (an MjSpec joint)
    with, in `mode`: reused when one of that kind targets the joint, else added as `<name>/<joint>`
    (placeholder gains when none are given: `auto_gains` sets them at setup from the compiled inertia).
    Other kinds on the joint are disabled. Returns the spec actuator."""
    jname = joint.name
    existing = [a for a in spec.actuators if a.trntype == mujoco.mjtTrn.mjTRN_JOINT and a.target == jname]
    act = next((a for a in existing if spec_kind(a) == mode), None)
    if act is None:
        # the hardware's actuator of this kind, disabled until claimed (a joint with position and velocity
        # command interfaces is held by the position one): claiming the interface enables it
        act = next((a for a in existing if a.gear[0] == 0 and _kind_of(a) == mode), None)
        if act is not None:
            act.gear = [1.0, 0, 0, 0, 0, 0]
    for other in existing:
        if other is not act and other.gear[0] != 0:
            other.gear = [0.0] * 6  # another kind of actuator on this joint would fight ours
    if act is None:
        act = spec.add_actuator(name=f"{name}/{jname}", target=jname, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        if mode == "position":
            act.set_to_position(kp=kp or 1.0, kv=kv or 0.0)
        elif mode == "velocity":
            act.set_to_velocity(kv=kv or 1.0)
        else:
            act.set_to_motor()
        limited = joint.actfrclimited == mujoco.mjtLimited.mjLIMITED_TRUE or (
            joint.actfrclimited == mujoco.mjtLimited.mjLIMITED_AUTO
            and joint.actfrcrange[0] < joint.actfrcrange[1]
        )
        if limited and max_effort is None:
            act.forcelimited = True
            act.forcerange = list(joint.actfrcrange)
    else:  # reused: change only what was asked for
        if mode == "position" and kp is not None:
            act.gainprm[0] = kp
            act.biasprm[1] = -kp
        if kv is not None and mode == "position":
            act.biasprm[2] = -kv
        if kv is not None and mode == "velocity":
            act.gainprm[0] = kv
            act.biasprm[2] = -kv
    if max_effort is not None:
        act.forcelimited = True
        act.forcerange = [-max_effort, max_effort]
    return act


def find_actuator(
    m: mujoco.MjModel, robot: Any, name: str, jname: str, jid: int, mode: str
) -> tuple[int, bool]:
    """The actuator driving `jname` in `mode` at run time: (index, True) for the one `name` added in build,
    (index, False) for one that was reused (the hardware's)."""
    try:
        return robot.actuator_id(f"{name}/{jname}"), True
    except KeyError:
        pass
    for a in range(m.nu):
        if int(m.actuator_trntype[a]) != int(mujoco.mjtTrn.mjTRN_JOINT) or int(m.actuator_trnid[a, 0]) != jid:
            continue
        found = kind(
            m.actuator_gaintype[a],
            m.actuator_biastype[a],
            m.actuator_dyntype[a],
            m.actuator_gainprm[a, 0],
            m.actuator_biasprm[a],
        )
        if found == mode and m.actuator_gear[a, 0] != 0:
            return a, False
    raise KeyError(f"no {mode} actuator drives joint {jname!r}")


def auto_gains(
    m: mujoco.MjModel, a: int, mode: str, inertia: float, dt: float, kp: float | None, kv: float | None
) -> None:
    """Default gains of an actuator a plugin added, from the inertia the joint moves: position, a critically
    damped servo at 0.15/timestep rad/s; velocity, a time constant of 2 physics steps."""
    if mode == "position":
        if kp is None:
            omega = OMEGA_STEPS / dt
            gain = inertia * omega**2
            m.actuator_gainprm[a, 0] = gain
            m.actuator_biasprm[a, 1] = -gain
        if kv is None:
            gain = float(m.actuator_gainprm[a, 0])
            m.actuator_biasprm[a, 2] = -2.0 * math.sqrt(gain * inertia)
    elif mode == "velocity" and kv is None:
        gain = inertia / (VELOCITY_STEPS * dt)
        m.actuator_gainprm[a, 0] = gain
        m.actuator_biasprm[a, 2] = -gain


def velocity_limit(m: mujoco.MjModel, jid: int) -> float | None:
    """The joint's URDF `<limit velocity>` as the hardware carries it (runner.compile.hardware: the control
    range of its velocity actuator, enabled or not), at run time; None when it has none."""
    for a in range(m.nu):
        if int(m.actuator_trntype[a]) != int(mujoco.mjtTrn.mjTRN_JOINT) or int(m.actuator_trnid[a, 0]) != jid:
            continue
        bias = m.actuator_biasprm[a]
        velocity = (
            int(m.actuator_biastype[a]) == int(mujoco.mjtBias.mjBIAS_AFFINE) and bias[1] == 0 and bias[2] != 0
        )
        if velocity and m.actuator_ctrllimited[a]:
            return float(min(-m.actuator_ctrlrange[a, 0], m.actuator_ctrlrange[a, 1]))
    return None


def spec_velocity_limit(spec: mujoco.MjSpec, joint: str) -> float | None:
    """`velocity_limit` at build time, from the robot's MjSpec."""
    for a in spec.actuators:
        if a.trntype != mujoco.mjtTrn.mjTRN_JOINT or a.target != joint:
            continue
        velocity = a.biastype == mujoco.mjtBias.mjBIAS_AFFINE and a.biasprm[1] == 0 and a.biasprm[2] != 0
        if velocity and a.ctrllimited == mujoco.mjtLimited.mjLIMITED_TRUE:
            return float(min(-a.ctrlrange[0], a.ctrlrange[1]))
    return None


def release(m: mujoco.MjModel, d: mujoco.MjData, a: int) -> None:
    """A deactivated controller's command interface, released: gz_ros2_control's system stops that command
    (perform_command_mode_switch, gz_system.cpp:572) and, with `hold_joints` (default true), sends the joint a
    zero velocity command (write(), :675), which holds it where it is. A position servo's setpoint becomes
    the joint's position now; a velocity servo's, zero; a motor's effort, zero (gz would hold that joint
    with a velocity command; a motor has none: the joint is left free)."""
    found = kind(
        m.actuator_gaintype[a],
        m.actuator_biastype[a],
        m.actuator_dyntype[a],
        m.actuator_gainprm[a, 0],
        m.actuator_biasprm[a],
    )
    position = float(d.qpos[m.jnt_qposadr[int(m.actuator_trnid[a, 0])]])
    d.ctrl[a] = position * (float(m.actuator_gear[a, 0]) or 1.0) if found == "position" else 0.0


class Lifecycle:
    """The active / inactive state of a ros2_control controller plugin, which the controller_manager plugin
    switches (plugins/controller_manager.py). A controller starts active (the spawner activates it); its
    hooks do nothing while inactive; `deactivate` releases the actuators `commanded()` names to the
    hardware's hold (`release`); `on_activate` resets what the controller's on_activate resets."""

    active: bool = True
    ctx: Any

    def commanded(self) -> list[int]:
        """The actuators (command interfaces) the controller writes."""
        return []

    def on_activate(self) -> None:
        """What the controller does when activated again (default: nothing)."""

    def activate(self) -> None:
        self.active = True
        self.on_activate()

    def deactivate(self) -> None:
        self.active = False
        for a in self.commanded():
            release(self.ctx.model, self.ctx.data, int(a))
