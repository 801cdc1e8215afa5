"""joint_trajectory_controller: ros2_controllers' joint_trajectory_controller/JointTrajectoryController
(Jazzy's semantics; Humble's `state_publish_rate`), and ROS 1 ros_controllers'
position_controllers/velocity_controllers/effort_controllers JointTrajectoryController mapped onto it.

Topics (relative to the robot's namespace; the compile handler applies the control plugin's remappings):
- `<name>/joint_trajectory` (trajectory_msgs/JointTrajectory) in; ROS 1: `<name>/command`;
- `<name>/controller_state` (control_msgs/JointTrajectoryControllerState, Jazzy's layout: reference,
  feedback, error, output) out, every update (Jazzy) or at `state_publish_rate` (Humble); ROS 1:
  `<name>/state`, the same ROS 2 type (ROS 1's desired/actual/error are reference/feedback/error here).

What it does, as joint_trajectory_controller.cpp (Jazzy) does it, at the controller manager's update rate:
- a trajectory is validated (joint names, partial goals, point sizes, strictly increasing times, a last
  point at rest unless `allow_nonzero_velocity_at_trajectory_end`, no end in the past, effort fields only
  with an effort command interface); a rejected one is logged with the controller's reason and ignored;
- missing joints of a partial goal hold their last command, joints are reordered by name;
- a new trajectory replaces the old one entirely: its first segment starts from the measured state (or the
  last command with `open_loop_control` / `interpolate_from_desired_state`, and in ROS 1 mode) at the
  update that first samples it; `header.stamp` 0 means "now", a later stamp waits for it, interpolating
  from that state towards the first point;
- sampling (plugins/_trajectory.py): linear / cubic / quintic splines by the fields the points have,
  `interpolation_method: none` forwards the next waypoint; the command is sampled one update ahead;
- path tolerances (`constraints.<joint>.trajectory`) are checked while moving, goal tolerances
  (`constraints.<joint>.goal`, velocity within `stopped_velocity_tolerance`) after the last point, with
  `goal_time` (0: wait forever; ROS 1: 0 means at the end time); a violation holds the current position;
  after success the last point is held; `cmd_timeout` holds position after the end;
- position command interface: the joint's position servo follows the sampled position; velocity / effort
  only: the sampled velocity × ff_velocity_scale (+ effort) plus a PID on the error per `gains.<joint>`
  (all 0 by default: the joint is not driven, as in ros2_control); position+velocity: the position servo.

Action (plugins/_follow_trajectory.py): `<name>/follow_joint_trajectory` (FollowJointTrajectory; ROS 1 too,
as ros_controllers names it, on ROS 2's wire) runs its goals through `submit_goal(trajectory, path_tolerance=,
goal_tolerance=, goal_time_tolerance=, on_feedback=, on_result=)` (sim loop): a GoalHandle whose `status` is
"rejected" (`reason`: the log text), "active", "succeeded", "aborted" or "canceled"; `on_feedback(Feedback)`
at `action_monitor_rate`, `on_result(TrajectoryResult)` once with the controller's error_code / error_string.
A new goal preempts the active one (INVALID_GOAL); `handle.cancel()` holds the current position. A
trajectory on the topic does not end an active goal (as in ros2_controllers).

Lifecycle (the controller_manager plugin switches it): `deactivate()` aborts the goal, stops commanding and
leaves the joints to the hardware, which holds them where they are (gz_system.cpp:675); while inactive,
trajectories and goals are refused; `activate()` holds the current position (on_activate).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from pydantic import Field, NonNegativeFloat, PositiveFloat

from plugins._actuators import Lifecycle, auto_gains, claim_actuator, find_actuator
from plugins._follow_trajectory import ACTION, FollowJointTrajectoryServer, state_data
from plugins._trajectory import (
    Constraints,
    Gains,
    Point,
    Sample,
    Tol,
    Tolerances,
    Trajectory,
    copy_point,
    goal_tolerances,
    seconds,
    validate_message,
    within,
)
from runner.plugin import BuildContext, Plugin, PluginConfigError, PluginParams, Service, Topic
from runner.wire import msgs

log = logging.getLogger(__name__)

SUCCESSFUL = 0
INVALID_GOAL = -1
INVALID_JOINTS = -2
OLD_HEADER_TIMESTAMP = -3
PATH_TOLERANCE_VIOLATED = -4
GOAL_TOLERANCE_VIOLATED = -5

Interface = Literal["position", "velocity", "acceleration", "effort"]
TRAJECTORY_TYPE = "trajectory_msgs/msg/JointTrajectory"
STATE_TYPE = "control_msgs/msg/JointTrajectoryControllerState"


class JointTrajectoryControllerParams(PluginParams):
    joints: list[str] = Field(min_length=1, description="The joints the trajectories name.")
    command_joints: list[str] = Field(
        default_factory=list, description="The joints commanded (default: `joints`); a subset of `joints`."
    )
    command_interfaces: list[Interface] = Field(
        default_factory=lambda: ["position"], description="position, velocity, effort (acceleration: said)."
    )
    state_interfaces: list[Interface] = Field(
        default_factory=lambda: ["position", "velocity"], description="position, velocity (acceleration)."
    )
    allow_partial_joints_goal: bool = False
    open_loop_control: bool = False
    interpolate_from_desired_state: bool = False
    allow_integration_in_goal_trajectories: bool = False
    interpolation_method: Literal["splines", "none"] = "splines"
    allow_nonzero_velocity_at_trajectory_end: bool = Field(
        False, description="Jazzy's default (Humble's: true)."
    )
    cmd_timeout: NonNegativeFloat = 0.0
    state_publish_rate: PositiveFloat | None = Field(
        None, description="Humble: controller_state rate, Hz (default: every update, as Jazzy)."
    )
    action_monitor_rate: PositiveFloat = Field(20.0, description="Feedback rate of a goal, Hz.")
    constraints: Constraints = Field(default_factory=Constraints)
    gains: dict[str, Gains] = Field(default_factory=dict)
    update_rate: PositiveFloat = Field(100.0, description="The controller manager's update rate, Hz.")
    every_step: bool = Field(
        False,
        description="Update at every physics step instead of at update_rate (gazebo_ros_control's default "
        "control_period, the physics step: ROS 1 controllers).",
    )
    ros1: bool = Field(False, description="ROS 1 JointTrajectoryController (topics command / state).")
    command_topic: str | None = Field(None, description="Default `<name>/joint_trajectory` (ROS 1: command).")
    state_topic: str | None = Field(None, description="Default `<name>/controller_state` (ROS 1: state).")
    action_name: str | None = Field(None, description="Default `<name>/follow_joint_trajectory`.")


@dataclass
class TrajectoryResult:
    error_code: int
    error_string: str


@dataclass
class Feedback:
    stamp_ns: int
    joint_names: list[str]
    desired: Sample
    actual: Point
    error: Point


@dataclass
class GoalHandle:
    """A FollowJointTrajectory goal given to `submit_goal`."""

    controller: JointTrajectoryController | None
    status: str = "active"
    reason: str = ""
    result: TrajectoryResult | None = None
    on_feedback: Callable[[Feedback], None] | None = None
    on_result: Callable[[TrajectoryResult], None] | None = None
    _next_feedback_ns: int = field(default=0, repr=False)

    def cancel(self) -> None:
        if self.controller is not None and self.status == "active":
            self.controller._cancel(self)


class JointTrajectoryController(Lifecycle, Plugin):
    Params = JointTrajectoryControllerParams
    params: JointTrajectoryControllerParams

    @classmethod
    def build(
        cls, params: JointTrajectoryControllerParams, ctx: BuildContext, name: str
    ) -> list[Topic | Service]:
        joints = params.joints
        if len(set(joints)) != len(joints):
            raise PluginConfigError("a joint is named twice", "joints")
        for c in params.command_joints:
            if c not in joints:
                raise PluginConfigError(
                    f"command joint {c!r} is not one of `joints`",
                    "command_joints",
                    hint="command joints of another name (a controller chain) are not run",
                )
        mode = cls._mode(params)
        if mode is None:
            raise PluginConfigError(
                f"command interfaces {params.command_interfaces} drive no joint",
                "command_interfaces",
                hint="use position, velocity or effort",
            )
        for jname in joints:
            ctx.joint(jname, "joints")
        for jname in params.command_joints or joints:
            claim_actuator(ctx.spec, name, ctx.joint(jname, "joints"), mode)
        for jname in params.gains:
            if jname not in joints:
                raise PluginConfigError(f"gains for {jname!r}, not one of `joints`", "gains")
        extra = params.constraints.__pydantic_extra__ or {}
        for jname in extra:
            if jname not in joints:
                raise PluginConfigError(f"constraints for {jname!r}, not one of `joints`", "constraints")
        rate = params.state_publish_rate or params.update_rate
        return [
            Topic(cls._command_topic(params, name), TRAJECTORY_TYPE, "sub"),
            Topic(cls._state_topic(params, name), STATE_TYPE, "pub", rate),
            Service(cls._action_name(params, name), ACTION, kind="action"),
        ]

    @staticmethod
    def _mode(params: JointTrajectoryControllerParams) -> Literal["position", "velocity", "effort"] | None:
        c = params.command_interfaces
        return (
            "position"
            if "position" in c
            else "velocity"
            if "velocity" in c
            else "effort"
            if "effort" in c
            else None
        )

    @staticmethod
    def _command_topic(params: JointTrajectoryControllerParams, name: str) -> str:
        return params.command_topic or f"{name}/{'command' if params.ros1 else 'joint_trajectory'}"

    @staticmethod
    def _state_topic(params: JointTrajectoryControllerParams, name: str) -> str:
        return params.state_topic or f"{name}/{'state' if params.ros1 else 'controller_state'}"

    @staticmethod
    def _action_name(params: JointTrajectoryControllerParams, name: str) -> str:
        return params.action_name or f"{name}/follow_joint_trajectory"

    @classmethod
    def control_rate_of(cls, params: PluginParams) -> float | None:
        return None if params.every_step else float(params.update_rate)  # type: ignore[attr-defined]

    @classmethod
    def rate_of(cls, params: PluginParams) -> float | None:
        return None if params.every_step else float(params.update_rate)  # type: ignore[attr-defined]

    # ------------------------------------------------------------------------------------------ set up
    def setup(self) -> None:
        p = self.params
        m, d, r = self.ctx.model, self.ctx.data, self.ctx.robot
        self.joints = list(p.joints)
        self.n = len(self.joints)
        self.mode = self._mode(p)
        jids = [r.joint_id(j) for j in self.joints]
        self.qadr = np.array([int(m.jnt_qposadr[j]) for j in jids])
        self.dadr = np.array([int(m.jnt_dofadr[j]) for j in jids])
        cmd_names = p.command_joints or self.joints
        self.cmd_index = [self.joints.index(c) for c in cmd_names]
        self.act: list[int] = []
        self.gear: list[float] = []
        dt = float(m.opt.timestep)
        for k in self.cmd_index:
            assert self.mode is not None
            a, own = find_actuator(m, r, self.name, self.joints[k], jids[k], self.mode)
            self.act.append(a)
            self.gear.append(float(m.actuator_gear[a, 0]))
            if own:
                auto_gains(m, a, self.mode, float(m.dof_M0[self.dadr[k]]), dt, None, None)
        ci = p.command_interfaces
        self.has_pos_cmd = "position" in ci
        self.has_vel_cmd = "velocity" in ci
        self.has_acc_cmd = "acceleration" in ci
        self.has_eff_cmd = "effort" in ci
        self.has_vel_state = "velocity" in p.state_interfaces
        self.closed_loop = (self.has_vel_cmd and len(ci) == 1 and not p.open_loop_control) or (
            self.has_eff_cmd and len(ci) == 1
        )
        self.gains = [p.gains.get(self.joints[k], Gains()) for k in self.cmd_index]
        self.integral = np.zeros(len(self.cmd_index))
        self.from_desired = p.interpolate_from_desired_state or p.open_loop_control or p.ros1
        self.period = dt if p.every_step else 1.0 / p.update_rate
        self.default_tol = self._default_tolerances()
        self.active_tol = self.default_tol
        self.goal: GoalHandle | None = None
        self.pending: Trajectory | None = None
        self.holding = True
        self.traj_time = 0.0
        self.last_t: float | None = None
        self.last_cmd: Point | None = None
        self.last_cmd_time = 0.0
        self.output = np.zeros(self.n)
        self.error = Point(0.0, np.zeros(self.n), np.zeros(self.n), np.zeros(self.n))
        self.desired: Sample | None = None
        self.current = self._hold(self._state(0.0).positions)  # on_activate holds the start position
        self.pub = self.ctx.publisher(self._state_topic(p, self.name), STATE_TYPE)
        self.state_every = 1.0 / p.state_publish_rate if p.state_publish_rate else 0.0
        self.next_state = 0.0
        self.ctx.subscribe(
            self._command_topic(p, self.name), TRAJECTORY_TYPE, self._on_trajectory, max_bytes=64 << 20
        )
        self.action = FollowJointTrajectoryServer(self, self._action_name(p, self.name))
        del d

    def on_activate(self) -> None:
        """on_activate: hold the current position, start again from the measured state."""
        self.pending = None
        self.last_cmd = None
        self.last_t = None
        self.integral[:] = 0.0
        self.current = self._hold(self.ctx.data.qpos[self.qadr])

    def deactivate(self) -> None:
        """on_deactivate (joint_trajectory_controller.cpp:1255): the active goal is aborted; the command
        interfaces are released, and gz_ros2_control's system then holds each joint with a zero velocity
        command (gz_system.cpp:675, hold_joints): here its servo holds it where it is."""
        self._finish(
            TrajectoryResult(INVALID_GOAL, "Current goal cancelled during deactivate transition."), "aborted"
        )
        self.pending = None
        super().deactivate()

    def commanded(self) -> list[int]:
        return self.act

    def close(self) -> None:
        self.action.close()

    def _default_tolerances(self) -> Tolerances:
        """tolerances.hpp:get_segment_tolerances (from the parameters)."""
        c = self.params.constraints
        state = [Tol(position=c.joint(j).trajectory) for j in self.joints]
        goal = [Tol(position=c.joint(j).goal, velocity=c.stopped_velocity_tolerance) for j in self.joints]
        return Tolerances(state, goal, c.goal_time)

    def _state(self, t: float) -> Point:
        d = self.ctx.data
        return Point(t, d.qpos[self.qadr].astype(float), d.qvel[self.dadr].astype(float))

    def _hold(self, positions: Any) -> Trajectory:
        """joint_trajectory_controller.cpp:set_hold_position (one point, now, tolerances off)."""
        self.holding = True
        point = Point(
            0.0,
            np.array(positions, dtype=float),
            np.zeros(self.n) if (self.has_vel_cmd or self.has_acc_cmd) else None,
            np.zeros(self.n) if self.has_acc_cmd else None,
            np.zeros(self.n) if self.has_eff_cmd else None,
        )
        return Trajectory([point])

    # -------------------------------------------------------------------------------------- receiving
    def validate(self, msg: Any, now: float) -> str | None:
        """None, or why the controller refuses the trajectory (its log text)."""
        p = self.params
        return validate_message(
            msg,
            self.joints,
            now,
            partial=p.allow_partial_joints_goal,
            nonzero_end=p.allow_nonzero_velocity_at_trajectory_end,
            integration=p.allow_integration_in_goal_trajectories,
            effort=self.has_eff_cmd,
        )

    def _to_trajectory(self, msg: Any) -> Trajectory:
        """fill_partial_goal + sort_to_local_joint_order: the points in the controller's joint order, a
        joint the trajectory leaves out holding its last position command (else its position)."""
        names = list(msg.joint_names)
        index = [self.joints.index(j) for j in names]
        missing = [k for k in range(self.n) if k not in index]
        hold = self.last_cmd.positions if (self.has_pos_cmd and self.last_cmd is not None) else None
        if hold is None:
            hold = self.ctx.data.qpos[self.qadr].astype(float)
        points = []
        for pt in msg.points:

            def order(values: Any, fill: Any) -> np.ndarray | None:
                if len(values) == 0:
                    return None
                out = np.zeros(self.n)
                out[index] = np.asarray(values, dtype=float)
                for k in missing:
                    out[k] = fill[k]
                return out

            zeros = np.zeros(self.n)
            points.append(
                Point(
                    seconds(pt.time_from_start),
                    order(pt.positions, hold),
                    order(pt.velocities, zeros),
                    order(pt.accelerations, zeros),
                    order(pt.effort, zeros),
                )
            )
        start = seconds(msg.header.stamp)
        return Trajectory(points, start if start != 0.0 else None)

    def _now(self) -> float:
        return float(self.ctx.data.time)

    def _on_trajectory(self, msg: Any, stamp_ns: int) -> None:
        """topic_callback: a valid trajectory replaces the current one at the next update."""
        if not self.active:
            log.error("%s: controller is not active: the trajectory is ignored", self.name)
            return
        reason = self.validate(msg, self._now())
        if reason is not None:
            log.error("%s: %s", self.name, reason)
            return
        self.pending = self._to_trajectory(msg)
        self.holding = False

    def submit_goal(
        self,
        trajectory: Any,
        *,
        path_tolerance: Iterable[Any] = (),
        goal_tolerance: Iterable[Any] = (),
        goal_time_tolerance: float = 0.0,
        on_feedback: Callable[[Feedback], None] | None = None,
        on_result: Callable[[TrajectoryResult], None] | None = None,
    ) -> GoalHandle:
        """A FollowJointTrajectory goal (see the module docstring)."""
        reason = self.validate(trajectory, self._now()) if self.active else "Controller is not running."
        if reason is not None:
            log.error("%s: %s", self.name, reason)
            return GoalHandle(None, status="rejected", reason=reason)
        self._finish(
            TrajectoryResult(INVALID_GOAL, "Current goal preempted by new incoming action."), "aborted"
        )
        self.pending = self._to_trajectory(trajectory)
        self.holding = False
        handle = GoalHandle(self, on_feedback=on_feedback, on_result=on_result)
        self.goal = handle
        self.active_tol = self._goal_tolerances(
            list(path_tolerance), list(goal_tolerance), goal_time_tolerance
        )
        return handle

    def _goal_tolerances(self, path: list[Any], goal: list[Any], goal_time: float) -> Tolerances:
        try:
            return goal_tolerances(self.default_tol, self.joints, path, goal, goal_time)
        except ValueError as e:
            log.error("%s: %s: using the default tolerances", self.name, e)
            return self.default_tol

    def _finish(self, result: TrajectoryResult, status: str) -> None:
        goal = self.goal
        if goal is None:
            return
        self.goal = None
        self.active_tol = self.default_tol
        goal.status = status
        goal.result = result
        if goal.on_result is not None:
            goal.on_result(result)

    def _cancel(self, handle: GoalHandle) -> None:
        """goal_cancelled_callback: the active goal is canceled and the current position held."""
        if handle is not self.goal:
            return
        self._finish(TrajectoryResult(SUCCESSFUL, ""), "canceled")
        self.pending = self._hold(self.ctx.data.qpos[self.qadr])

    # ---------------------------------------------------------------------------------------- update
    def before_step(self, now_ns: int) -> None:
        """joint_trajectory_controller.cpp:update (Jazzy lines 239-580)."""
        if not self.active:
            return
        t = now_ns * 1e-9
        period = self.period if self.last_t is None else t - self.last_t
        self.last_t = t
        if self.pending is not None:
            self.current, self.pending = self.pending, None
        actual = self._state(t)
        traj = self.current
        first_sample = not traj.sampled
        if first_sample:
            if self.from_desired and self.last_cmd is not None:
                traj.set_before(self.last_cmd_time or t, self.last_cmd)
            else:
                traj.set_before(t, actual)
            self.traj_time = t
        else:
            self.traj_time += period
        desired = traj.sample(self.traj_time, self.params.interpolation_method == "splines")
        command = traj.sample(self.traj_time + self.period, self.params.interpolation_method == "splines")
        if desired is None or command is None:
            self._publish(now_ns, actual)
            return
        self.desired = desired
        start_idx = max(command.segment - 1, 0)
        before_last = command.segment != len(traj.points)
        time_difference = self.traj_time - ((traj.start or 0.0) + traj.points[start_idx].t)
        err = self.error
        assert err.positions is not None and err.velocities is not None and actual.positions is not None
        err.positions[:] = desired.positions - actual.positions
        if self.has_vel_state and (self.has_vel_cmd or self.has_eff_cmd):
            assert actual.velocities is not None
            err.velocities[:] = desired.velocities - actual.velocities
        timeout = self.params.cmd_timeout
        if not before_last and not self.holding and timeout > 0.0 and time_difference > timeout:
            log.warning("%s: Aborted due to command timeout", self.name)
            self.pending = self._hold(actual.positions)
        violated, outside_goal, within_goal_time = self._check(
            err, before_last, first_sample, time_difference
        )
        if not violated and within_goal_time:
            self._command(command, period)
            self.last_cmd = Point(
                0.0, command.positions, command.velocities, command.accelerations, command.effort
            )
            self.last_cmd_time = t
        goal = self.goal
        if goal is not None:
            if (on_feedback := goal.on_feedback) and now_ns >= goal._next_feedback_ns:
                goal._next_feedback_ns = now_ns + round(1e9 / self.params.action_monitor_rate)
                on_feedback(Feedback(now_ns, list(self.joints), desired, actual, copy_point(err)))
            if violated:
                log.warning("%s: Aborted due to state tolerance violation", self.name)
                self._finish(
                    TrajectoryResult(PATH_TOLERANCE_VIOLATED, "Aborted due to path tolerance violation"),
                    "aborted",
                )
                self.pending = self._hold(actual.positions)
            elif not before_last:
                if not outside_goal:
                    self._finish(TrajectoryResult(SUCCESSFUL, "Goal successfully reached!"), "succeeded")
                    self.pending = self._success(traj)
                elif not within_goal_time:
                    text = f"Aborted due to goal_time_tolerance exceeding by {time_difference:f} seconds"
                    log.warning("%s: %s", self.name, text)
                    self._finish(TrajectoryResult(GOAL_TOLERANCE_VIOLATED, text), "aborted")
                    self.pending = self._hold(actual.positions)
        elif violated:
            log.error("%s: Holding position due to state tolerance violation", self.name)
            self.pending = self._hold(actual.positions)
        elif not before_last and not within_goal_time:
            log.error("%s: Exceeded goal_time_tolerance: holding position...", self.name)
            self.pending = self._hold(actual.positions)
        self._publish(now_ns, actual)

    def _check(
        self, err: Point, before_last: bool, first_sample: bool, time_difference: float
    ) -> tuple[bool, bool, bool]:
        """The tolerance checks of update(): (path tolerance violated, outside the goal tolerance, still
        within goal_time)."""
        tol = self.active_tol
        violated = outside_goal = False
        within_goal_time = True
        for k in range(self.n):
            if (before_last or first_sample) and not self.holding and not within(err, k, tol.state[k]):
                violated = True
            if not before_last and not self.holding and not within(err, k, tol.goal[k]):
                outside_goal = True
                # ROS 2: goal_time 0 waits for the tolerance forever; ROS 1 (JointTrajectoryController's
                # checkGoalTolerances): 0 means the goal must be met at the end time
                if (tol.goal_time != 0.0 or self.params.ros1) and time_difference > tol.goal_time:
                    within_goal_time = False
        return violated, outside_goal, within_goal_time

    def _success(self, traj: Trajectory) -> Trajectory:
        """set_success_trajectory_point: the last point is held, whatever its velocity."""
        last = traj.points[-1]
        held = Trajectory([Point(0.0, last.positions, last.velocities, last.accelerations, last.effort)])
        self.holding = True
        return held

    def _command(self, cmd: Sample, period: float) -> None:
        d = self.ctx.data
        err = self.error
        assert err.positions is not None and err.velocities is not None
        for i, k in enumerate(self.cmd_index):
            if self.mode == "position":
                value = float(cmd.positions[k])
                d.ctrl[self.act[i]] = value * self.gear[i]
            else:
                if self.closed_loop:
                    value = float(cmd.velocities[k]) * self.gains[i].ff_velocity_scale
                    if self.has_eff_cmd:
                        value += float(cmd.effort[k])
                    value += self._pid(i, float(err.positions[k]), float(err.velocities[k]), period)
                elif self.mode == "velocity":
                    value = float(cmd.velocities[k])
                else:
                    value = float(cmd.effort[k])
                d.ctrl[self.act[i]] = value / self.gear[i] if self.mode == "effort" else value * self.gear[i]
            self.output[k] = value

    def _pid(self, i: int, error: float, error_dot: float, dt: float) -> float:
        """control_toolbox::Pid::compute_command (legacy anti-windup: the integral term clamped)."""
        g = self.gains[i]
        lo = -math.inf if g.i_clamp_min is None else g.i_clamp_min
        hi = math.inf if g.i_clamp_max is None else g.i_clamp_max
        if g.i_clamp is not None:
            lo, hi = -abs(g.i_clamp), abs(g.i_clamp)
        self.integral[i] = min(max(self.integral[i] + g.i * error * dt, lo), hi)
        u = g.p * error + self.integral[i] + g.d * error_dot
        if g.u_clamp_min is not None:
            u = max(u, g.u_clamp_min)
        return u if g.u_clamp_max is None else min(u, g.u_clamp_max)

    def _publish(self, now_ns: int, actual: Point) -> None:
        t = now_ns * 1e-9
        if self.state_every and t + 1e-9 < self.next_state:
            return
        self.next_state = t + self.state_every
        self.pub.publish(msgs.from_data(STATE_TYPE, state_data(self, now_ns, actual)), now_ns)
