"""The messages of the joint_trajectory_controller plugin: its controller_state (`state_data`) and its
FollowJointTrajectory action server. The action's goals
turned into the controller's goals (`submit_goal`) and their feedback and results into the action's
messages, as ros2_controllers' JointTrajectoryController serves `~/follow_joint_trajectory` (Jazzy,
joint_trajectory_controller.cpp at ed360c97):

- goal_received_callback (:1401): a goal is rejected while the controller is not active ("Can't accept new
  action goals. Controller is not running.") and when its trajectory fails validate_trajectory_msg (joints
  the controller does not have, sizes, times...; the reason is logged, the client sees only the rejection:
  rclcpp_action carries no text); else accepted and executed at once (ACCEPT_AND_EXECUTE);
- goal_accepted_callback (:1455): the active goal is preempted (preempt_active_goal, :1824: aborted with
  INVALID_GOAL "Current goal preempted by new incoming action."), the trajectory replaces the current one,
  the goal's path / goal tolerances and goal_time_tolerance replace the parameters' for this goal
  (tolerances.hpp get_segment_tolerances);
- update (:456-525): feedback (header.stamp, joint_names, desired / actual / error) each update, published
  at action_monitor_rate (RealtimeServerGoalHandle::runNonRealtime on its timer); the goal ends SUCCESSFUL
  "Goal successfully reached!", PATH_TOLERANCE_VIOLATED "Aborted due to path tolerance violation" or
  GOAL_TOLERANCE_VIOLATED "Aborted due to goal_time_tolerance exceeding by <s> seconds";
- goal_cancelled_callback (:1423): a cancel is always accepted; the active goal is canceled with an empty
  result (error_code 0, no text) and the current position is held;
- on_deactivate (:1255): the active goal is aborted with INVALID_GOAL "Current goal cancelled during
  deactivate transition.".
INVALID_JOINTS and OLD_HEADER_TIMESTAMP are never sent: the Jazzy controller rejects such goals instead.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

import numpy as np

from plugins._trajectory import Point, Sample, seconds
from runner.plugin.actions import GoalHandle as ActionGoal
from runner.wire import msgs

if TYPE_CHECKING:
    # (not the controller's module: it imports this one) the controller, its goals, results and feedback
    JointTrajectoryController = Any
    ControllerGoal = Any
    TrajectoryResult = Any
    Feedback = Any

log = logging.getLogger(__name__)

ACTION = "control_msgs/action/FollowJointTrajectory"


class FollowJointTrajectoryServer:
    """`<controller>/follow_joint_trajectory` for one controller (made in its `setup`)."""

    def __init__(self, controller: JointTrajectoryController, name: str):
        self.controller = controller
        self.goals: dict[bytes, ControllerGoal] = {}
        self.server = controller.ctx.action_server(name, ACTION, self._on_goal, self._on_cancel)

    def _on_goal(self, handle: ActionGoal) -> bool:
        c = self.controller
        if not c.active:
            log.error("%s: Can't accept new action goals. Controller is not running.", c.name)
            return False
        goal = handle.goal
        if len(goal.multi_dof_trajectory.joint_names) or len(goal.multi_dof_trajectory.points):
            log.error(
                "%s: a multi_dof_trajectory is not followed (the controller reads `trajectory`)", c.name
            )
        ours = c.submit_goal(
            goal.trajectory,
            path_tolerance=goal.path_tolerance,
            goal_tolerance=goal.goal_tolerance,
            goal_time_tolerance=seconds(goal.goal_time_tolerance),
            on_feedback=lambda fb: handle.publish_feedback(self._feedback(fb)),
            on_result=lambda result: self._end(handle, ours, result),
        )
        if ours.status == "rejected":
            return False
        self.goals[handle.goal_id] = ours
        return True

    def _on_cancel(self, handle: ActionGoal) -> bool:
        ours = self.goals.get(handle.goal_id)
        if ours is not None:
            ours.cancel()  # the active one: canceled (an empty result) and the position held
        return True

    def _end(self, handle: ActionGoal, ours: ControllerGoal, result: TrajectoryResult) -> None:
        self.goals.pop(handle.goal_id, None)
        if ours.status == "canceled":
            handle.canceled(msgs.from_data(f"{ACTION}_Result", {}))
            return
        msg = msgs.from_data(
            f"{ACTION}_Result", {"error_code": result.error_code, "error_string": result.error_string}
        )
        if ours.status == "succeeded":
            handle.succeed(msg)
        else:
            handle.abort(msg)

    def _feedback(self, fb: Feedback) -> Any:
        """control_msgs/action/FollowJointTrajectory_Feedback: points sized as resize_joint_trajectory_point
        (:1960) sizes them: positions, velocities with a velocity state interface, effort zeros."""
        vel = self.controller.has_vel_state
        n = len(fb.joint_names)

        def point(p: Point | Sample) -> dict[str, Any]:
            out: dict[str, Any] = {"positions": _floats(p.positions), "effort": [0.0] * n}
            if vel:
                out["velocities"] = _floats(p.velocities, n)
            return out

        return msgs.from_data(
            f"{ACTION}_Feedback",
            {
                "header": {
                    "stamp": {"sec": fb.stamp_ns // 1_000_000_000, "nanosec": fb.stamp_ns % 1_000_000_000}
                },
                "joint_names": fb.joint_names,
                "desired": point(fb.desired),
                "actual": point(fb.actual),
                "error": point(fb.error),
            },
        )

    def close(self) -> None:
        self.server.close()


def _floats(values: np.ndarray | None, n: int = 0) -> list[float]:
    return [0.0] * n if values is None else [float(v) for v in values]


def state_data(c: JointTrajectoryController, now_ns: int, actual: Point) -> dict[str, Any]:
    """control_msgs/msg/JointTrajectoryControllerState (Jazzy's layout) as data, as the controller's
    publish_state fills it: reference, feedback, error, output (the command interface's)."""
    n = c.n
    zeros = np.zeros(n)
    ref = c.desired or Sample(actual.positions, zeros, zeros, zeros, 0)  # type: ignore[arg-type]
    err = c.error
    assert actual.positions is not None and err.positions is not None and err.velocities is not None
    data: dict[str, Any] = {
        "header": {"stamp": {"sec": now_ns // 1_000_000_000, "nanosec": now_ns % 1_000_000_000}},
        "joint_names": list(c.joints),
        "reference": {
            "positions": ref.positions.tolist(),
            "velocities": ref.velocities.tolist(),
            "accelerations": ref.accelerations.tolist(),
        },
        "feedback": {"positions": actual.positions.tolist()},
        "error": {"positions": err.positions.tolist()},
        "output": {"effort": c.output.tolist()},
        "speed_scaling_factor": 1.0,
    }
    if c.mode == "position":
        data["output"] = {"positions": c.output.tolist()}
    elif c.mode == "velocity":
        data["output"] = {"velocities": c.output.tolist()}
    if c.has_vel_state:
        assert actual.velocities is not None
        data["feedback"]["velocities"] = actual.velocities.tolist()
        data["error"]["velocities"] = err.velocities.tolist()
    return data
