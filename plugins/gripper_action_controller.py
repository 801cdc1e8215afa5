"""gripper_action_controller: ros2_controllers' position_controllers/GripperActionController and
effort_controllers/GripperActionController (gripper_controllers, Humble/Jazzy),
parallel_gripper_action_controller/GripperActionController (Jazzy), and ROS 1 ros_controllers'
position_controllers/ and effort_controllers/GripperActionController, on one joint.

Action: `<name>/gripper_cmd` (control_msgs/action/GripperCommand; the parallel gripper's
ParallelGripperCommand), as gripper_action_controller_impl.hpp (Jazzy) serves `~/gripper_cmd`: every goal is
accepted (the parallel gripper rejects one whose command has not exactly one position), preempts the active
goal (canceled, an empty result: preempt_active_goal), and ends with the result below; a cancel of the active
goal holds the current position with the parameters' max_effort (set_hold_position) and ends it canceled
with an empty result. The controllers send no feedback (their update never sets any), nor do we.

A topic of ours gives a scenario's timeline (which publishes, but has no action client) the same goal:
- `<name>/gripper_cmd` taking control_msgs/msg/GripperCommand (position, max_effort) for
  gripper_action_controller (ROS 1 and 2);
- `<name>/gripper_cmd` taking sensor_msgs/msg/JointState for the parallel gripper (what the
  ParallelGripperCommand goal's `command` is: position[0], and velocity[0] / effort[0] when
  `max_velocity_interface` / `max_effort_interface` are set, else `max_velocity` / `max_effort`).
Each message is a new goal, as an accepted action goal is (it preempts the active one). This topic is not
part of ros2_controllers: it is said where a controllers file runs these controllers.

What it does at the controller manager's update rate (gripper_action_controller_impl.hpp, Jazzy):
- position command interface: the joint's position servo goes to the goal position (`max_effort` is not
  used, as the position adapter only passes it through); effort: a PID on `gains.<joint>` (p, i, d,
  i_clamp) on the position error, clamped to ± the goal's `max_effort` (0 gives no force, as in
  ros2_control); parallel gripper: the position servo, its force limited by the effort command;
- on activation the command is the current position, the effort `max_effort`;
- the result: within `goal_tolerance` -> reached_goal; not moving faster than
  `stall_velocity_threshold` for `stall_timeout` -> stalled (succeeded with `allow_stalling`, else aborted;
  ROS 1: aborted).

Internal API, for the GripperCommand / ParallelGripperCommand action server (sim loop, as for the
trajectory controller): `handle = gripper.submit_goal(position, max_effort=None, max_velocity=None,
on_result=cb)`; `handle.status` "active" / "succeeded" / "aborted" / "canceled"; `handle.result` a
`GripperResult(position, effort, stalled, reached_goal)`; a new goal preempts the active one (canceled);
`handle.cancel()` cancels it (the command stays).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import mujoco
from pydantic import BaseModel, ConfigDict, Field, NonNegativeFloat, PositiveFloat

from plugins._actuators import Lifecycle, auto_gains, claim_actuator, find_actuator
from runner.plugin import BuildContext, Plugin, PluginConfigError, PluginParams, Service, Topic
from runner.plugin.actions import GoalHandle as ActionGoal
from runner.wire import msgs

log = logging.getLogger(__name__)

GRIPPER_TYPE = "control_msgs/msg/GripperCommand"
PARALLEL_TYPE = "sensor_msgs/msg/JointState"
GRIPPER_ACTION = "control_msgs/action/GripperCommand"
PARALLEL_ACTION = "control_msgs/action/ParallelGripperCommand"


class GripperGains(BaseModel):
    model_config = ConfigDict(extra="forbid")
    p: float = 0.0
    i: float = 0.0
    d: float = 0.0
    i_clamp: float = 0.0


class GripperActionControllerParams(PluginParams):
    joint: str = Field(description="The gripper's joint.")
    command_interface: Literal["position", "effort"] = Field(
        "position", description="position_controllers (or the parallel gripper) / effort_controllers."
    )
    parallel: bool = Field(False, description="parallel_gripper_action_controller (JointState commands).")
    goal_tolerance: NonNegativeFloat = 0.01
    max_effort: NonNegativeFloat = Field(
        0.0, description="Effort until the first goal (parallel gripper: every goal's; default 10 there)."
    )
    max_velocity: NonNegativeFloat = Field(0.1, description="Parallel gripper: speed of every goal.")
    max_effort_interface: str = ""
    max_velocity_interface: str = ""
    allow_stalling: bool = False
    stall_velocity_threshold: NonNegativeFloat = 0.001
    stall_timeout: NonNegativeFloat = 1.0
    gains: dict[str, GripperGains] = Field(default_factory=dict, description="Effort interface: PID gains.")
    action_monitor_rate: PositiveFloat = 20.0
    update_rate: PositiveFloat = Field(100.0, description="The controller manager's update rate, Hz.")
    ros1: bool = False
    command_topic: str | None = Field(None, description="Default `<name>/gripper_cmd` (ours, see docs).")
    action_name: str | None = Field(None, description="Default `<name>/gripper_cmd`.")


@dataclass
class GripperResult:
    position: float
    effort: float
    stalled: bool
    reached_goal: bool


@dataclass
class GripperGoalHandle:
    controller: GripperActionController | None
    status: str = "active"
    result: GripperResult | None = None
    on_result: Callable[[GripperResult], None] | None = None
    on_end: Callable[[GripperGoalHandle], None] | None = None  # any end: succeeded, aborted, canceled

    def cancel(self) -> None:
        """cancel_callback: the active goal is canceled and the current position held."""
        c = self.controller
        if c is not None and self.status == "active" and c.goal is self:
            c.position = float(c.ctx.data.qpos[c.qadr])  # set_hold_position
            c.max_effort = c.params.max_effort
            c._end(self, "canceled")


class GripperActionController(Lifecycle, Plugin):
    Params = GripperActionControllerParams
    params: GripperActionControllerParams

    @classmethod
    def build(
        cls, params: GripperActionControllerParams, ctx: BuildContext, name: str
    ) -> list[Topic | Service]:
        joint = ctx.joint(params.joint, "joint")
        if joint.type not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            raise PluginConfigError(f"joint {params.joint!r} is not revolute or prismatic", "joint")
        for jname in params.gains:
            if jname != params.joint:
                raise PluginConfigError(f"gains for {jname!r}, not the controller's joint", "gains")
        claim_actuator(ctx.spec, name, joint, cls._mode(params))
        return [
            Topic(cls._topic(params, name), PARALLEL_TYPE if params.parallel else GRIPPER_TYPE, "sub"),
            Service(cls._action_name(params, name), cls._action_type(params), kind="action"),
        ]

    @staticmethod
    def _action_name(params: GripperActionControllerParams, name: str) -> str:
        return params.action_name or f"{name}/gripper_cmd"

    @staticmethod
    def _action_type(params: GripperActionControllerParams) -> str:
        return PARALLEL_ACTION if params.parallel else GRIPPER_ACTION

    @staticmethod
    def _mode(params: GripperActionControllerParams) -> Literal["position", "effort"]:
        return "position" if params.parallel else params.command_interface

    @staticmethod
    def _topic(params: GripperActionControllerParams, name: str) -> str:
        return params.command_topic or f"{name}/gripper_cmd"

    @classmethod
    def control_rate_of(cls, params: PluginParams) -> float | None:
        return float(params.update_rate)  # type: ignore[attr-defined]

    @classmethod
    def rate_of(cls, params: PluginParams) -> float | None:
        return float(params.update_rate)  # type: ignore[attr-defined]

    def setup(self) -> None:
        p = self.params
        m, d, r = self.ctx.model, self.ctx.data, self.ctx.robot
        jid = r.joint_id(p.joint)
        self.qadr = int(m.jnt_qposadr[jid])
        self.dadr = int(m.jnt_dofadr[jid])
        self.mode = self._mode(p)
        self.act, own = find_actuator(m, r, self.name, p.joint, jid, self.mode)
        self.gear = float(m.actuator_gear[self.act, 0])
        if own:
            auto_gains(m, self.act, self.mode, float(m.dof_M0[self.dadr]), float(m.opt.timestep), None, None)
        # the force range the hardware gave the servo: a parallel gripper's effort command narrows it
        self.force_limited = bool(m.actuator_forcelimited[self.act])
        self.force_range = (
            float(m.actuator_forcerange[self.act, 0]),
            float(m.actuator_forcerange[self.act, 1]),
        )
        self.gain = p.gains.get(p.joint, GripperGains())
        self.integral = 0.0
        # on_activate: command the current position, with the configured effort / speed
        self.position = float(d.qpos[self.qadr])
        self.max_effort = p.max_effort
        self.velocity = p.max_velocity
        self.computed = 0.0
        self.goal: GripperGoalHandle | None = None
        self.last_movement = 0.0
        self.ctx.subscribe(
            self._topic(p, self.name), PARALLEL_TYPE if p.parallel else GRIPPER_TYPE, self._on_command
        )
        self.action = self.ctx.action_server(
            self._action_name(p, self.name), self._action_type(p), self._on_goal, self._on_cancel
        )
        self._goals: dict[bytes, GripperGoalHandle] = {}

    # ------------------------------------------------------------------------------------------ action
    def _on_goal(self, handle: ActionGoal) -> bool:
        """goal_callback + accepted_callback."""
        command = handle.goal.command
        if self.params.parallel:
            if len(command.position) != 1:
                log.error(
                    "%s: Received action goal with wrong number of position values, expects 1, got %d",
                    self.name,
                    len(command.position),
                )
                return False
            ours = self.submit_goal(
                float(command.position[0]),
                max_effort=float(command.effort[0]) if len(command.effort) else None,
                max_velocity=float(command.velocity[0]) if len(command.velocity) else None,
            )
        else:
            ours = self.submit_goal(float(command.position), max_effort=float(command.max_effort))
        ours.on_end = lambda g: self._ended(handle, g)
        self._goals[handle.goal_id] = ours
        return True

    def _on_cancel(self, handle: ActionGoal) -> bool:
        ours = self._goals.get(handle.goal_id)
        if ours is not None:
            ours.cancel()
        return True

    def _ended(self, handle: ActionGoal, goal: GripperGoalHandle) -> None:
        self._goals.pop(handle.goal_id, None)
        kind = self._action_type(self.params)
        r = goal.result
        if r is None:  # canceled or preempted: an empty result
            handle.canceled(msgs.from_data(f"{kind}_Result", {}))
            return
        if self.params.parallel:
            data: dict[str, Any] = {
                "state": {"name": [self.params.joint], "position": [r.position], "effort": [r.effort]}
            }
        else:
            data = {"position": r.position, "effort": r.effort}
        data.update(stalled=r.stalled, reached_goal=r.reached_goal)
        result = msgs.from_data(f"{kind}_Result", data)
        (handle.succeed if goal.status == "succeeded" else handle.abort)(result)

    # ------------------------------------------------------------------------------------- lifecycle
    def on_activate(self) -> None:
        """on_activate: command the current position with the parameters' effort."""
        self.position = float(self.ctx.data.qpos[self.qadr])
        self.max_effort = self.params.max_effort
        self.integral = 0.0

    def commanded(self) -> list[int]:
        """on_deactivate releases the interface (the hardware holds the joint where it is) and leaves a
        goal as it is: it ends with a new goal or a cancel."""
        return [self.act]

    def close(self) -> None:
        self.action.close()

    def _on_command(self, msg: Any, stamp_ns: int) -> None:
        if self.params.parallel:
            if len(msg.position) == 0:
                log.error("%s: a parallel gripper command needs position[0]", self.name)
                return
            self.submit_goal(
                float(msg.position[0]),
                max_effort=float(msg.effort[0]) if len(msg.effort) else None,
                max_velocity=float(msg.velocity[0]) if len(msg.velocity) else None,
            )
        else:
            self.submit_goal(float(msg.position), max_effort=float(msg.max_effort))

    def submit_goal(
        self,
        position: float,
        *,
        max_effort: float | None = None,
        max_velocity: float | None = None,
        on_result: Callable[[GripperResult], None] | None = None,
    ) -> GripperGoalHandle:
        """An accepted GripperCommand / ParallelGripperCommand goal (accepted_callback)."""
        p = self.params
        if self.goal is not None:  # preempt_active_goal: the old goal is canceled
            self._end(self.goal, "canceled")
        self.position = position
        if p.parallel:
            self.max_effort = (
                max_effort if (p.max_effort_interface and max_effort is not None) else p.max_effort
            )
            self.velocity = (
                max_velocity if (p.max_velocity_interface and max_velocity is not None) else p.max_velocity
            )
        else:
            self.max_effort = max_effort if max_effort is not None else self.max_effort
        self.last_movement = float(self.ctx.data.time)
        handle = GripperGoalHandle(self, on_result=on_result)
        self.goal = handle
        return handle

    def before_step(self, now_ns: int) -> None:
        if not self.active:
            return
        d = self.ctx.data
        t = now_ns * 1e-9
        current = float(d.qpos[self.qadr])
        velocity = float(d.qvel[self.dadr])
        error = self.position - current
        self._check(t, error, current, velocity)
        if self.mode == "position":
            d.ctrl[self.act] = self.position * self.gear
            self.computed = self.max_effort
            if self.params.parallel and self.params.max_effort_interface:
                # the effort command interface a parallel gripper's hardware takes: the servo's force limit
                e = abs(self.max_effort)
                self.ctx.model.actuator_forcelimited[self.act] = 1
                self.ctx.model.actuator_forcerange[self.act] = (-e, e)
        else:
            g = self.gain
            dt = 1.0 / self.params.update_rate
            self.integral = min(max(self.integral + g.i * error * dt, -abs(g.i_clamp)), abs(g.i_clamp))
            u = g.p * error + self.integral + g.d * (-velocity)
            limit = abs(self.max_effort)
            u = min(max(u, -limit), limit)
            self.computed = u
            d.ctrl[self.act] = u / self.gear

    def _check(self, t: float, error: float, current: float, velocity: float) -> None:
        """check_for_success (gripper_action_controller_impl.hpp)."""
        goal = self.goal
        if goal is None:
            return
        p = self.params
        if abs(error) < p.goal_tolerance:
            self._finish(goal, GripperResult(current, self.computed, False, True), "succeeded")
        elif abs(velocity) > p.stall_velocity_threshold:
            self.last_movement = t
        elif t - self.last_movement > p.stall_timeout:
            ok = p.allow_stalling and not p.ros1
            self._finish(
                goal, GripperResult(current, self.computed, True, False), "succeeded" if ok else "aborted"
            )

    def _finish(self, goal: GripperGoalHandle, result: GripperResult, status: str) -> None:
        goal.result = result
        self._end(goal, status)

    def _end(self, goal: GripperGoalHandle, status: str) -> None:
        """The goal ends: `on_result` with its result (none when canceled), `on_end` in any case."""
        if self.goal is goal:
            self.goal = None
        goal.status = status
        if goal.on_result is not None and goal.result is not None:
            goal.on_result(goal.result)
        if goal.on_end is not None:
            goal.on_end(goal)
