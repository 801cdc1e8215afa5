"""The robots' ros2_control / ros_control hardware at the start of a run, before any plugin's setup
(runner.compile.hardware built its actuators): the joints put at their `initial_value`s, the servo gains set
from the inertia each joint moves, each servo holding the start state until a controller commands it; and at
each boundary, position commands kept within the joint's velocity limit (every step while one is held back).

Gains. Gazebo's servo is a velocity constraint (DART): the joint reaches the commanded velocity within one
step unless that takes more than the effort limit, so an arm holds its pose against gravity with no sag. The
MuJoCo stand-in is a servo whose damping is `SERVO_STEPS` times, per timestep, the inertia the joint meets
with the others free (`1 / (M^-1)_ii` at the start pose): with the implicitfast integrator that damping is
integrated implicitly; the position servo's stiffness is `loop_gain * kv`, the same velocity loop on the
position error (gz_system.cpp write(): `-position_proportional_gain * update_rate * error`), stable while
`loop_gain * dt < 2`. The weight of the links the servos hold goes through them (runner.compile.hardware's
`_gravity`); the sag left under other loads is `torque / kp`: bench/hardware.py measures both.
"""

from __future__ import annotations

import mujoco
import numpy as np

from runner.plan import HardwareJoint, RobotPlan

# kv = SERVO_STEPS * inertia / timestep (bench/hardware.py): the force DART's servo constraint would apply
# to reach its velocity setpoint within a step. With an effort limit, a servo pushed to it overshoots by up to
# limit * timestep / inertia in a step; past 1 its correction hits the opposite limit and it chatters
# (measured: 28 rad/s against a 3.14 limit at 10). Without one the implicit damping would stay stable
# however high, but the position term stays explicit: at 50 x, a public tricycle's 1 rad steering step put
# kp * error = 129 kN·m into one step, which the contact solver met in full (the robot was flung off the
# ground at 12 m/s); at 1 x the steering turns at the loop's rate and the car drives off as in Gazebo. The
# weight the servos hold goes through gravity compensation or feed-forward, not through their stiffness.
SERVO_STEPS = 1.0
SERVO_STEPS_UNLIMITED = 1.0
PLACEHOLDER = 1e-9  # runner.compile.hardware's placeholder gains


class Hardware:
    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, robots: list[RobotPlan]):
        self.m, self.d = model, data
        self._limited: list[tuple[int, int, float, float]] = []  # (actuator, qpos adr, loop gain, vmax)
        self._acts: np.ndarray = np.zeros(0, dtype=int)
        self._adr: np.ndarray = np.zeros(0, dtype=int)
        self._window: np.ndarray = np.zeros(0)
        self._target: np.ndarray = np.zeros(0)
        self._written: np.ndarray = np.zeros(0)
        self._ff_dofs: np.ndarray = np.zeros(0, dtype=int)  # free-base held joints (`_feedforward`)
        self._ff_limit: np.ndarray = np.zeros(0)
        self.active = False  # a position setpoint is held back by a velocity limit
        joints: list[tuple[RobotPlan, HardwareJoint, int]] = []
        for rp in robots:
            for hj in rp.hardware:
                jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, rp.prefix + hj.joint)
                if jid >= 0:
                    joints.append((rp, hj, jid))
        if not joints:
            return
        self._start(joints)
        mujoco.mj_forward(model, data)
        self._gains(joints)
        self._feedforward(joints)

    # -------------------------------------------------------------- a robot spawned or deleted mid-run
    def rebind(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """The world's new model and data (a robot spawned): every id held is still valid."""
        self.m, self.d = model, data

    def add(self, robots: list[RobotPlan]) -> None:
        """A spawned robot's hardware: its start state, gains and feed-forward, as at a run's start, then
        kept at each boundary with the others'."""
        other = Hardware(self.m, self.d, robots)
        self._limited += other._limited
        for name in ("_acts", "_adr", "_window", "_target", "_written", "_ff_dofs", "_ff_limit"):
            setattr(self, name, np.concatenate([getattr(self, name), getattr(other, name)]))
        self.active = self.active or other.active

    def drop(self, actuators: set[int], dofs: set[int]) -> None:
        """A deleted robot's actuators and joints, no longer kept (its feed-forward torques taken off)."""
        keep = np.array([a not in actuators for a in self._acts.tolist()], dtype=bool)
        self._limited = [x for x, k in zip(self._limited, keep.tolist(), strict=True) if k]
        for name in ("_acts", "_adr", "_window", "_target", "_written"):
            setattr(self, name, getattr(self, name)[keep])
        gone = np.array([int(v) in dofs for v in self._ff_dofs.tolist()], dtype=bool)
        self.d.qfrc_applied[self._ff_dofs[gone]] = 0.0
        self._ff_dofs, self._ff_limit = self._ff_dofs[~gone], self._ff_limit[~gone]

    def _start(self, joints: list[tuple[RobotPlan, HardwareJoint, int]]) -> None:
        """gz_system.cpp: JointPositionReset / JointVelocityReset with the `initial_value`s."""
        m, d = self.m, self.d
        for _rp, hj, jid in joints:
            if hj.initial_position is not None:
                d.qpos[m.jnt_qposadr[jid]] = hj.initial_position
            if hj.initial_velocity is not None:
                d.qvel[m.jnt_dofadr[jid]] = hj.initial_velocity
        # a mimic joint starts where its equality puts it
        for e in range(m.neq):
            if int(m.eq_type[e]) == int(mujoco.mjtEq.mjEQ_JOINT) and m.eq_active0[e] and m.eq_obj2id[e] >= 0:
                j1, j2 = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
                c = m.eq_data[e]
                q2 = float(d.qpos[m.jnt_qposadr[j2]] - m.qpos0[m.jnt_qposadr[j2]])
                d.qpos[m.jnt_qposadr[j1]] = m.qpos0[m.jnt_qposadr[j1]] + c[0] + c[1] * q2 + c[2] * q2**2

    def _gains(self, joints: list[tuple[RobotPlan, HardwareJoint, int]]) -> None:
        m, d = self.m, self.d
        dt = float(m.opt.timestep)
        limited: list[tuple[int, int, float, float]] = []
        unit, column = np.zeros(m.nv), np.zeros(m.nv)
        for rp, hj, jid in joints:
            dof = int(m.jnt_dofadr[jid])
            unit[dof] = 1.0
            # the inertia this joint meets with the others free (1 / (M^-1)_ii): the least it can see, so a
            # saturated neighbour cannot make it overshoot into the opposite limit
            mujoco.mj_solveM(m, d, column.reshape(1, -1), unit.reshape(1, -1))
            unit[dof] = 0.0
            inertia = 1.0 / float(column[dof])
            for mode, name in hj.actuators.items():
                a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, rp.prefix + name)
                if a < 0:
                    continue
                capped = bool(m.actuator_forcelimited[a]) or bool(m.jnt_actfrclimited[jid])
                # the joint's own damping (URDF <dynamics damping>) is added: a servo weaker than it moves
                # the joint at a fraction of its setpoint (an LBR wrist, damping 10 N·m·s on a light link,
                # crept to 0.098 of a 0.3 rad goal in 4 s), where DART's velocity constraint overrides it.
                # kv = d + inertia/dt at most halves the velocity loop's speed, and stays below the
                # saturation bound above (kv <= inertia/dt + d, the damping being integrated implicitly too)
                damping_own = float(m.dof_damping[dof])
                kv = (SERVO_STEPS if capped else SERVO_STEPS_UNLIMITED) * inertia / dt + damping_own
                placeholder = m.actuator_gainprm[a, 0] == PLACEHOLDER
                if mode == "position":
                    if placeholder:
                        if hj.pid is not None:  # gazebo_ros_control's PID on the effort: P and D
                            kp, damp = hj.pid.get("p", 0.0), hj.pid.get("d", 0.0)
                        else:
                            kp, damp = (hj.loop_gain or 0.5 / dt) * kv, kv
                        m.actuator_gainprm[a, 0] = kp
                        m.actuator_biasprm[a, 1] = -kp
                        m.actuator_biasprm[a, 2] = -damp
                    # hold the start position (hold_joints) until a controller commands it
                    d.ctrl[a] = d.qpos[m.jnt_qposadr[jid]]
                    damping = -float(m.actuator_biasprm[a, 2])
                    # a servo without damping (a controller's pure P) is no velocity loop: nothing to clip
                    if (
                        hj.velocity_limit is not None
                        and m.actuator_gear[a, 0] != 0
                        and hj.pid is None
                        and damping > 0
                    ):
                        gain = float(m.actuator_gainprm[a, 0]) / damping
                        limited.append((a, int(m.jnt_qposadr[jid]), gain, hj.velocity_limit))
                elif mode == "velocity":
                    if placeholder:
                        gain = hj.pid.get("p", kv) if hj.pid is not None else kv
                        m.actuator_gainprm[a, 0] = gain
                        m.actuator_biasprm[a, 2] = -gain
                    d.ctrl[a] = hj.initial_velocity or 0.0
                elif mode == "effort":
                    d.ctrl[a] = hj.initial_effort or 0.0  # gz_system.cpp: joint_effort_cmd = initial_value
        self._limited = limited
        self._acts = np.array([a for a, *_ in limited], dtype=int)
        self._adr = np.array([adr for _a, adr, _g, _v in limited], dtype=int)
        self._window = np.array([v / g if g > 0 else np.inf for _a, _adr, g, v in limited])
        self._target = d.ctrl[self._acts].copy()
        self._written = self._target.copy()

    def _feedforward(self, joints: list[tuple[RobotPlan, HardwareJoint, int]]) -> None:
        """The position-held joints of a robot on a free base (a mobile manipulator; an arm Gazebo spawns
        standing free). Their links' weight cannot go through MuJoCo's gravity compensation, which would
        lift the base too (runner.compile.hardware's `_gravity` leaves them out); DART's servo constraint
        holds them all the same. So their bias forces (gravity, and the arm's Coriolis terms) are applied
        as joint torques on those joints only, within their effort limits, refreshed at every boundary:
        the base carries the arm's weight through its joints as in Gazebo."""
        m = self.m
        dofs: list[int] = []
        limits: list[float] = []
        for rp, hj, jid in joints:
            if rp.fixed or bool(m.jnt_actgravcomp[jid]) or "position" not in hj.actuators:
                continue
            if hj.pid is not None and not hj.pid.get("i", 0.0) > 0:
                continue  # a PID without an integral term sags in Gazebo too
            a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, rp.prefix + hj.actuators["position"])
            if a < 0 or m.actuator_gear[a, 0] == 0:
                continue
            dofs.append(int(m.jnt_dofadr[jid]))
            limited = bool(m.jnt_actfrclimited[jid]) or bool(m.actuator_forcelimited[a])
            lim = (
                float(m.jnt_actfrcrange[jid, 1])
                if m.jnt_actfrclimited[jid]
                else float(m.actuator_forcerange[a, 1])
            )
            limits.append(lim if limited else np.inf)
        self._ff_dofs = np.array(dofs, dtype=int)
        self._ff_limit = np.array(limits)
        if dofs:
            self._apply_feedforward()

    def _apply_feedforward(self) -> None:
        d = self.d
        d.qfrc_applied[self._ff_dofs] = np.clip(d.qfrc_bias[self._ff_dofs], -self._ff_limit, self._ff_limit)

    def boundary(self, _now: int) -> None:
        """At every boundary, after the controllers' hooks (controls change only there): DART clips a servo's
        velocity setpoint to the joint's velocity limits, so a position servo's setpoint is kept within
        `vmax / loop_gain` of the joint and never asks for more. A control that differs from what this wrote
        last is a controller's new command. While a setpoint is held back, every step is a boundary."""
        if len(self._ff_dofs):
            self._apply_feedforward()
        if not self._limited:
            return
        d, acts = self.d, self._acts
        c = d.ctrl[acts]
        new = c != self._written
        self._target[new] = c[new]
        q = d.qpos[self._adr]
        err = self._target - q
        sp = q + np.clip(err, -self._window, self._window)
        d.ctrl[acts] = sp
        self._written = sp
        self.active = bool(np.any(np.abs(err) > self._window))

    def next_ns(self, now: int) -> int:
        """When the next boundary is needed: the next step while a setpoint is held back, else none."""
        return now + 1 if self.active else 1 << 62
