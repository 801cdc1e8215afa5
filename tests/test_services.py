"""Services and actions in the world process, in-process (real MuJoCo on a MemoryBus): the service types and
their hashes, the world's request handling (decoding, bad requests, failing handlers, service events) and
the action server's goal state machine (rclcpp_action / rcl_action semantics)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from runner.plugin.actions import (
    ABORTED,
    CANCELED,
    ERROR_GOAL_TERMINATED,
    ERROR_NONE,
    ERROR_UNKNOWN_GOAL_ID,
    EXECUTING,
    SUCCEEDED,
    UNKNOWN,
    ActionServer,
    GoalHandle,
)
from runner.sim.world import World
from runner.wire import interfaces, msgs, ros2
from runner.wire.transport import MemoryBus
from tests.helpers import plan_of, robot_scenario

BOX = """<robot name="b"><link name="base"><inertial><mass value="1"/>
<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>"""
GRIP = "control_msgs/action/GripperCommand"


# ------------------------------------------------------------------------------------------- types
def test_service_hashes_are_those_ros2_jazzy_publishes() -> None:
    """Two hashes seen on the wire of ROS 2 Jazzy systems (rmw_zenoh keys in public projects): a service
    with an empty request (the dummy member rosidl adds) and one without, both through
    service_msgs/ServiceEventInfo, whose `char[16]` rosidl hashes as uint8."""
    assert interfaces.service_hash("std_srvs/srv/Trigger") == (
        "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"
    )
    from runner.wire.msgs import TYPESTORE

    TYPESTORE.register(
        interfaces._service_types(
            "example_interfaces/srv/SetBool", "bool data\n", "bool success\nstring message\n"
        )
    )
    assert str(TYPESTORE.hash_rihs01("example_interfaces/srv/SetBool")) == (
        "RIHS01_a69782e5631b12e15c8e218410de1685bbf13e382718295adad14037a24afbe8"
    )


def test_service_keys_and_tokens_as_rmw_zenoh_writes_them() -> None:
    """rmw_zenoh_cpp/src/detail/liveliness_utils.cpp (rolling, 2025): a service's key is
    `<domain>/<name>/<pkg>::srv::dds_::<Name>_/<service hash>`; its server's token is kind `SS` with the
    same name, DDS type and hash and the services' default QoS (reliable, volatile, keep last 10)."""
    h = interfaces.service_hash("std_srvs/srv/Trigger")
    assert (
        ros2.topic_key(0, "/r1/reset", "std_srvs/srv/Trigger")
        == f"0/r1/reset/std_srvs::srv::dds_::Trigger_/{h}"
    )
    token = ros2.entity_token(0, "abc", 0, 3, "SS", "/", "sim", "/r1/reset", "std_srvs/srv/Trigger")
    assert token == f"@ros2_lv/0/abc/0/3/SS/%/%/sim/%r1%reset/std_srvs::srv::dds_::Trigger_/{h}/::,10:,:,:,,"
    info = ros2.parse_token(token)
    assert info is not None and info.kind == "SS" and info.topic == "/r1/reset"
    send = f"{GRIP}_SendGoal"
    key = ros2.topic_key(0, "/g/_action/send_goal", send)
    assert key.startswith(
        "0/g/_action/send_goal/control_msgs::action::dds_::GripperCommand_SendGoal_/RIHS01_"
    )
    with pytest.raises(ValueError):
        ros2.entity_token(0, "abc", 0, 3, "XX", "/", "sim", "/a", "std_srvs/srv/Trigger")


def test_unknown_types_are_refused_with_the_known_ones() -> None:
    with pytest.raises(KeyError, match="std_srvs/srv/Empty"):
        interfaces.service_type("std_srvs/srv/Nope")
    with pytest.raises(KeyError, match="FollowJointTrajectory"):
        interfaces.action_type("control_msgs/action/Nope")
    assert interfaces.service_type("std_srvs/Empty").request == "std_srvs/srv/Empty_Request"


# ------------------------------------------------------------------------------------------- world
def _world(tmp_path: Path) -> tuple[World, MemoryBus]:
    bus = MemoryBus()
    world = World(plan_of(robot_scenario(tmp_path, BOX)), bus)
    world._should_stop = lambda: False  # type: ignore[method-assign]
    return world, bus


def _req(srv: str, data: dict[str, Any]) -> bytes:
    return msgs.encode(msgs.from_data(f"{srv}_Request", data), f"{srv}_Request")


def test_requests_are_answered_at_the_next_boundary_and_recorded_as_service_events(tmp_path: Path) -> None:
    world, bus = _world(tmp_path)
    srv = "std_srvs/srv/SetBool"
    seen: list[bool] = []

    def handler(request: Any, reply: Any) -> None:
        seen.append(bool(request.data))
        reply(msgs.T[f"{srv}_Response"](success=not request.data, message="flipped"))

    world.serve("g/bot/flip", srv, handler)
    gid = bytes(range(16))
    answers = bus.call("g/bot/flip", _req(srv, {"data": True}), ros2.pack_attachment(7, 123, gid))
    assert answers == [] and seen == []  # nothing happens between boundaries
    world._boundary()
    assert seen == [True]
    payload, error = answers[0]
    assert error is None and payload is not None
    assert msgs.decode(payload, f"{srv}_Response").message == "flipped"
    events = [(k, msgs.decode(p, t)) for k, t, p, _a in bus.sent if k == "g/bot/flip/_service_event"]
    kinds = [(e.info.event_type, len(e.request), len(e.response)) for _k, e in events]
    assert kinds == [(1, 1, 0), (2, 0, 1)]  # REQUEST_RECEIVED with the request, RESPONSE_SENT with the answer
    assert all(bytes(e.info.client_gid) == gid and e.info.sequence_number == 7 for _k, e in events)


def test_bad_requests_and_failing_handlers_get_errors_and_the_world_goes_on(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    world, bus = _world(tmp_path)
    calls: list[Any] = []

    def boom(request: Any, reply: Any) -> None:
        calls.append(request)
        raise RuntimeError("plugin bug")

    world.serve("g/bot/boom", "std_srvs/srv/Trigger", boom)
    world.serve(
        "g/bot/pose",
        "gazebo_msgs/srv/SetEntityState",
        lambda req, reply: reply(msgs.T["gazebo_msgs/srv/SetEntityState_Response"](success=True)),
    )
    garbage = bus.call("g/bot/pose", b"\x00\x01\x02")
    nan = bus.call(
        "g/bot/pose",
        _req(
            "gazebo_msgs/srv/SetEntityState",
            {"state": {"name": "bot", "pose": {"position": {"x": float("nan")}}}},
        ),
    )
    failed = bus.call("g/bot/boom", _req("std_srvs/srv/Trigger", {}))
    world._boundary()
    assert garbage[0][0] is None and "does not decode" in (garbage[0][1] or "")
    assert nan[0][0] is None and "state.pose.position.x is not a finite number" in (nan[0][1] or "")
    assert failed[0][0] is None and "plugin bug" in (failed[0][1] or "")
    again = bus.call("g/bot/boom", _req("std_srvs/srv/Trigger", {}))
    world._boundary()
    assert again[0][0] is None and len(calls) == 2
    assert capsys.readouterr().err.count("plugin bug") == 1  # said once per service
    stats = world.run()
    assert stats.error is None and stats.sim_ns > 0


# ------------------------------------------------------------------------------------------- actions
class _Grip:
    """An action server as a plugin would hold one: accepts positive positions."""

    def __init__(self, world: World, cancel_ok: bool = True):
        ctx = world._context(world.robots[0], 0)
        self.handles: list[GoalHandle] = []
        self.server = ActionServer(ctx, "grip", GRIP, self.on_goal, lambda _h: cancel_ok)

    def on_goal(self, handle: GoalHandle) -> bool:
        self.handles.append(handle)
        return float(handle.goal.command.position) >= 0


def _uuid(n: int) -> list[int]:
    return [n] * 16


def _send(bus: MemoryBus, n: int, position: float) -> list[Any]:
    return bus.call(
        "g/bot/grip/_action/send_goal",
        _req(
            f"{GRIP}_SendGoal", {"goal_id": {"uuid": _uuid(n)}, "goal": {"command": {"position": position}}}
        ),
    )


def _answer(answers: list[Any], srv: str) -> Any:
    payload, error = answers[0]
    assert error is None, error
    return msgs.decode(payload, f"{srv}_Response")


def _statuses(bus: MemoryBus) -> list[list[int]]:
    return [
        [int(s.status) for s in msgs.decode(p, t).status_list]
        for k, t, p, _a in bus.sent
        if k == "g/bot/grip/_action/status"
    ]


def test_a_goal_is_accepted_gets_feedback_and_its_result_waits_for_the_end(tmp_path: Path) -> None:
    world, bus = _world(tmp_path)
    grip = _Grip(world)
    sent = _send(bus, 1, 0.2)
    result = bus.call(
        "g/bot/grip/_action/get_result", _req(f"{GRIP}_GetResult", {"goal_id": {"uuid": _uuid(1)}})
    )
    world._boundary()
    assert _answer(sent, f"{GRIP}_SendGoal").accepted
    handle = grip.handles[0]
    assert handle.status == EXECUTING and result == []  # get_result waits
    handle.publish_feedback(msgs.from_data(f"{GRIP}_Feedback", {"position": 0.1}))
    handle.succeed(msgs.from_data(f"{GRIP}_Result", {"position": 0.2, "reached_goal": True}))
    done = _answer(result, f"{GRIP}_GetResult")
    assert done.status == SUCCEEDED and done.result.reached_goal
    fb = [msgs.decode(p, t) for k, t, p, _a in bus.sent if k.endswith("_action/feedback")]
    assert len(fb) == 1 and bytes(fb[0].goal_id.uuid) == bytes(_uuid(1))
    assert _statuses(bus) == [[EXECUTING], [SUCCEEDED]]
    handle.publish_feedback(msgs.from_data(f"{GRIP}_Feedback", {}))  # ended: nothing more
    assert len([k for k, *_ in bus.sent if k.endswith("_action/feedback")]) == 1
    late = bus.call(
        "g/bot/grip/_action/get_result", _req(f"{GRIP}_GetResult", {"goal_id": {"uuid": _uuid(1)}})
    )
    unknown = bus.call(
        "g/bot/grip/_action/get_result", _req(f"{GRIP}_GetResult", {"goal_id": {"uuid": _uuid(9)}})
    )
    world._boundary()
    assert _answer(late, f"{GRIP}_GetResult").status == SUCCEEDED
    assert _answer(unknown, f"{GRIP}_GetResult").status == UNKNOWN


def test_rejected_and_duplicate_goals(tmp_path: Path) -> None:
    world, bus = _world(tmp_path)
    grip = _Grip(world)
    rejected = _send(bus, 1, -1.0)
    first = _send(bus, 2, 0.1)
    world._boundary()
    again = _send(bus, 2, 0.1)  # the same goal id once more: rcl_action refuses it
    world._boundary()
    assert not _answer(rejected, f"{GRIP}_SendGoal").accepted
    assert grip.handles[0].status == UNKNOWN and not grip.handles[0].active
    assert _answer(first, f"{GRIP}_SendGoal").accepted
    assert not _answer(again, f"{GRIP}_SendGoal").accepted
    assert len(grip.handles) == 2  # the duplicate never reached the plugin


def test_cancel_requests_as_rcl_action_picks_goals(tmp_path: Path) -> None:
    world, bus = _world(tmp_path)
    grip = _Grip(world)
    for n in (1, 2, 3):
        _send(bus, n, 0.1)
    world._boundary()
    grip.handles[2].abort(msgs.from_data(f"{GRIP}_Result", {}))

    def cancel(n: int, sec: int = 0) -> list[Any]:
        info = {"goal_id": {"uuid": _uuid(n)}, "stamp": {"sec": sec, "nanosec": 0}}
        return bus.call(
            "g/bot/grip/_action/cancel_goal", _req("action_msgs/srv/CancelGoal", {"goal_info": info})
        )

    one, terminated, unknown = cancel(1), cancel(3), cancel(7)
    world._boundary()
    ok = _answer(one, "action_msgs/srv/CancelGoal")
    assert ok.return_code == ERROR_NONE and [bytes(g.goal_id.uuid) for g in ok.goals_canceling] == [
        bytes(_uuid(1))
    ]
    assert grip.handles[0].is_cancel_requested and grip.handles[1].status == EXECUTING
    assert _answer(terminated, "action_msgs/srv/CancelGoal").return_code == ERROR_GOAL_TERMINATED
    assert _answer(unknown, "action_msgs/srv/CancelGoal").return_code == ERROR_UNKNOWN_GOAL_ID
    every = cancel(0)  # zero id and zero stamp: every goal
    world._boundary()
    assert len(_answer(every, "action_msgs/srv/CancelGoal").goals_canceling) == 1  # goal 2 (1 is canceling)
    grip.handles[0].canceled(msgs.from_data(f"{GRIP}_Result", {}))
    assert grip.handles[0].status == CANCELED
    grip.server.close()
    assert grip.handles[1].status == ABORTED  # nothing waits for ever at the end of the run
