"""flipper: a test plugin that offers a std_srvs/srv/SetBool service (`flip`) and a
control_msgs/action/GripperCommand action (`grip`), for the tests of `scenario call`, `scenario action`
and runner.node's clients (tests/test_service_tools.py registers it through the entry-point group, as a
third-party package would be).

`flip` answers `success = data` and says how many times it was called and at what sim time (ns); `fail` (std_srvs/srv/Trigger)
raises (the world answers with an error reply); `hang` (std_srvs/srv/Empty) never answers. A `grip` goal with a negative
position is rejected; an accepted one runs for `command.position` seconds of sim time, publishing feedback
(`position`: the seconds gone) every 0.1 s, then succeeds with `reached_goal`; a cancel request ends it
at the next step, as canceled.
"""

from __future__ import annotations

from typing import Any

from runner.plugin import BuildContext, Plugin, PluginParams, Service
from runner.plugin.actions import GoalHandle
from runner.wire import msgs

GRIP = "control_msgs/action/GripperCommand"


class Flipper(Plugin):
    Params = PluginParams

    @classmethod
    def build(cls, params: PluginParams, ctx: BuildContext, name: str) -> list[Any]:
        return [
            Service("flip", "std_srvs/srv/SetBool"),
            Service("fail", "std_srvs/srv/Trigger"),
            Service("hang", "std_srvs/srv/Empty"),
            Service("grip", GRIP, kind="action"),
        ]

    def setup(self) -> None:
        self.calls = 0
        self.goals: list[tuple[GoalHandle, int]] = []  # (goal, next feedback's sim time)
        self.ctx.service("flip", "std_srvs/srv/SetBool", self.on_flip)
        self.ctx.service("fail", "std_srvs/srv/Trigger", self.on_fail)
        self.held: list[Any] = []  # `hang`'s replies, kept (a reply dropped ends the request unanswered)
        self.ctx.service("hang", "std_srvs/srv/Empty", lambda _request, reply: self.held.append(reply))
        self.ctx.action_server("grip", GRIP, self.on_goal)

    def on_flip(self, request: Any, reply: Any) -> None:
        self.calls += 1
        reply(
            msgs.T["std_srvs/srv/SetBool_Response"](
                success=bool(request.data),
                message=f"call {self.calls} at {round(float(self.ctx.data.time) * 1e9)}: data={bool(request.data)}",
            )
        )

    def on_fail(self, request: Any, reply: Any) -> None:
        raise RuntimeError("asked to fail")

    def on_goal(self, handle: GoalHandle) -> bool:
        if handle.goal.command.position < 0:
            return False
        self.goals.append((handle, handle.accepted_ns))
        return True

    def before_step(self, now_ns: int) -> None:
        kept = []
        for handle, next_ns in self.goals:
            gone = (now_ns - handle.accepted_ns) / 1e9
            result = msgs.from_data(f"{GRIP}_Result", {"position": gone})
            if handle.is_cancel_requested:
                handle.canceled(result)
                continue
            if gone >= handle.goal.command.position:
                result.reached_goal = True
                handle.succeed(result)
                continue
            if now_ns >= next_ns:
                handle.publish_feedback(msgs.from_data(f"{GRIP}_Feedback", {"position": gone}))
                next_ns += 100_000_000
            kept.append((handle, next_ns))
        self.goals = kept
