"""An action server as ROS 2 composes one (rcl_action / rclcpp_action): three services and two topics under
`<name>/_action/`, driven from the sim loop.

- `send_goal` (`<Action>_SendGoal`): a new goal id is offered to the plugin's `on_goal(handle)`; accepted,
  it goes straight to EXECUTING (rclcpp_action's `ACCEPT_AND_EXECUTE`); the response carries the
  acceptance and its sim-time stamp. A goal id already known is rejected (rcl_action refuses duplicates).
- `cancel_goal` (`action_msgs/srv/CancelGoal`): the goals the request names, as rcl_action's
  `rcl_action_process_cancel_request` picks them (rcl_action/src/rcl_action/action_server.c): a zero id and
  zero stamp: every goal; a zero id and a stamp: every goal accepted at or before it; an id: that goal (and,
  with a stamp, every goal accepted at or before it). Each ACCEPTED/EXECUTING one is offered to
  `on_cancel(handle)` (default: accept); accepted ones go to CANCELING and are listed in the response. When
  none is: ERROR_UNKNOWN_GOAL_ID for an id never seen, ERROR_GOAL_TERMINATED when it is already done, else
  ERROR_REJECTED.
- `get_result` (`<Action>_GetResult`): answered when the goal ends (at once if it has); an unknown id gets
  status UNKNOWN and an empty result.
- `_action/feedback` (`<Action>_FeedbackMessage`) and `_action/status` (`action_msgs/msg/GoalStatusArray`,
  published on every status change, holding every goal not yet expired).

A plugin ends a goal with `handle.succeed(result)`, `handle.abort(result)` or `handle.canceled(result)`.
Ended goals are kept for `RESULT_TIMEOUT_S` of sim time (rcl_action's default result_timeout, 15 minutes),
at most `MAX_DONE` of them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from runner.wire import interfaces, msgs

if TYPE_CHECKING:
    from runner.plugin import Reply, RuntimeContext

# action_msgs/msg/GoalStatus
UNKNOWN, ACCEPTED, EXECUTING, CANCELING, SUCCEEDED, CANCELED, ABORTED = range(7)
STATUS_NAMES = ("UNKNOWN", "ACCEPTED", "EXECUTING", "CANCELING", "SUCCEEDED", "CANCELED", "ABORTED")
TERMINAL = (SUCCEEDED, CANCELED, ABORTED)
# action_msgs/srv/CancelGoal response codes
ERROR_NONE, ERROR_REJECTED, ERROR_UNKNOWN_GOAL_ID, ERROR_GOAL_TERMINATED = range(4)
RESULT_TIMEOUT_S = 900.0
MAX_DONE = 256
ZERO_ID = bytes(16)


class GoalHandle:
    """One goal of an action server: its id, its goal message, its status; how the plugin answers it."""

    def __init__(self, server: ActionServer, goal_id: bytes, goal: Any, accepted_ns: int):
        self.server = server
        self.goal_id = goal_id
        self.goal = goal
        self.accepted_ns = accepted_ns
        self.status = UNKNOWN  # until `on_goal` accepts it: a rejected goal never becomes active
        self.result: Any = None
        self.ended_ns: int | None = None
        self._waiting: list[Reply] = []  # get_result requests that wait for the end

    @property
    def active(self) -> bool:
        return self.status in (ACCEPTED, EXECUTING, CANCELING)

    @property
    def is_cancel_requested(self) -> bool:
        return self.status == CANCELING

    def publish_feedback(self, feedback: Any) -> None:
        if self.active:
            self.server._feedback(self, feedback)

    def succeed(self, result: Any) -> None:
        self.server._end(self, SUCCEEDED, result)

    def abort(self, result: Any) -> None:
        self.server._end(self, ABORTED, result)

    def canceled(self, result: Any) -> None:
        self.server._end(self, CANCELED, result)


class ActionServer:
    def __init__(
        self,
        ctx: RuntimeContext,
        name: str,
        type_name: str,
        on_goal: Callable[[GoalHandle], bool],
        on_cancel: Callable[[GoalHandle], bool] | None = None,
    ):
        self.ctx = ctx
        self.name = name.rstrip("/")
        self.type = interfaces.action_type(type_name)
        self.on_goal = on_goal
        self.on_cancel = on_cancel or (lambda _h: True)
        self.goals: dict[bytes, GoalHandle] = {}
        services, topics = interfaces.action_parts(self.type)
        (send, send_t), (cancel, cancel_t), (result, result_t) = services
        (feedback, feedback_t), (status, status_t) = topics
        self._feedback_t, self._status_t = feedback_t, status_t
        self._send_t, self._result_t, self._cancel_t = send_t, result_t, cancel_t
        self._feedback_pub = ctx.publisher(f"{self.name}/{feedback}", feedback_t)
        self._status_pub = ctx.publisher(f"{self.name}/{status}", status_t)
        ctx.service(f"{self.name}/{send}", send_t, self._on_send_goal)
        ctx.service(f"{self.name}/{cancel}", cancel_t, self._on_cancel_goal)
        ctx.service(f"{self.name}/{result}", result_t, self._on_get_result)

    # ---------------------------------------------------------------------------------------- helpers
    def _now_ns(self) -> int:
        return round(float(self.ctx.data.time) * 1e9)

    @staticmethod
    def _uuid(goal_id: bytes) -> Any:
        return msgs.T["unique_identifier_msgs/msg/UUID"](uuid=_uint8s(goal_id))

    def _goal_info(self, handle: GoalHandle) -> Any:
        return msgs.T["action_msgs/msg/GoalInfo"](
            goal_id=self._uuid(handle.goal_id), stamp=msgs.time_msg(handle.accepted_ns)
        )

    def _publish_status(self) -> None:
        now = self._now_ns()
        expired = [
            k
            for k, h in self.goals.items()
            if h.ended_ns is not None and now - h.ended_ns > RESULT_TIMEOUT_S * 1e9
        ]
        done = [k for k, h in self.goals.items() if h.ended_ns is not None]
        expired += done[: max(0, len(done) - MAX_DONE)]
        for k in expired:
            self.goals.pop(k, None)
        status = [
            msgs.T["action_msgs/msg/GoalStatus"](goal_info=self._goal_info(h), status=h.status)
            for h in self.goals.values()
        ]
        self._status_pub.publish(msgs.T[self._status_t](status_list=status), now)

    def _feedback(self, handle: GoalHandle, feedback: Any) -> None:
        msg = msgs.T[self._feedback_t](goal_id=self._uuid(handle.goal_id), feedback=feedback)
        self._feedback_pub.publish(msg, self._now_ns())

    def _end(self, handle: GoalHandle, status: int, result: Any) -> None:
        if not handle.active:
            return
        handle.status = status
        handle.result = result
        handle.ended_ns = self._now_ns()
        self._publish_status()
        waiting, handle._waiting = handle._waiting, []
        for reply in waiting:
            reply(self._result_response(handle))

    def _result_response(self, handle: GoalHandle | None) -> Any:
        cls = msgs.T[f"{self._result_t}_Response"]
        if handle is None or handle.result is None:
            empty = msgs.from_data(f"{self.type}_Result", {})
            return cls(status=UNKNOWN if handle is None else handle.status, result=empty)
        return cls(status=handle.status, result=handle.result)

    # --------------------------------------------------------------------------------------- services
    def _on_send_goal(self, request: Any, reply: Reply) -> None:
        goal_id = bytes(request.goal_id.uuid)
        now = self._now_ns()
        response = msgs.T[f"{self._send_t}_Response"]
        if goal_id in self.goals:
            reply(response(accepted=False, stamp=msgs.time_msg(now)))
            return
        handle = GoalHandle(self, goal_id, request.goal, now)
        if not self.on_goal(handle):
            reply(response(accepted=False, stamp=msgs.time_msg(now)))
            return
        handle.status = EXECUTING
        self.goals[goal_id] = handle
        reply(response(accepted=True, stamp=msgs.time_msg(now)))
        self._publish_status()

    def _on_cancel_goal(self, request: Any, reply: Reply) -> None:
        goal_id = bytes(request.goal_info.goal_id.uuid)
        stamp = request.goal_info.stamp
        stamp_ns = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
        picked = [
            h
            for k, h in self.goals.items()
            if (goal_id == ZERO_ID and stamp_ns == 0)
            or k == goal_id
            or (stamp_ns and h.accepted_ns <= stamp_ns)
        ]
        canceling = []
        for h in picked:
            if h.status in (ACCEPTED, EXECUTING) and self.on_cancel(h):
                if h.active:  # (the plugin may have ended it already)
                    h.status = CANCELING
                canceling.append(h)
        response = msgs.T[f"{self._cancel_t}_Response"]
        if canceling:
            code = ERROR_NONE
        elif goal_id != ZERO_ID and goal_id not in self.goals:
            code = ERROR_UNKNOWN_GOAL_ID
        elif goal_id != ZERO_ID and not self.goals[goal_id].active:
            code = ERROR_GOAL_TERMINATED
        else:
            code = ERROR_REJECTED
        reply(response(return_code=code, goals_canceling=[self._goal_info(h) for h in canceling]))
        if canceling:
            self._publish_status()

    def _on_get_result(self, request: Any, reply: Reply) -> None:
        handle = self.goals.get(bytes(request.goal_id.uuid))
        if handle is not None and handle.active:
            handle._waiting.append(reply)
            return
        reply(self._result_response(handle))

    def close(self) -> None:
        """End every goal still going (aborted, empty result), so no get_result waits for ever."""
        for handle in list(self.goals.values()):
            if handle.active:
                self._end(handle, ABORTED, msgs.from_data(f"{self.type}_Result", {}))


def _uint8s(data: bytes) -> Any:
    import numpy as np

    return np.frombuffer(data, dtype=np.uint8).copy()
