"""Controller actions and the controller manager's services (issue 37, point 2): FollowJointTrajectory and
GripperCommand / ParallelGripperCommand goals sent as a ROS 2 client sends them (the action's services, CDR
requests), and controller_manager/list_controllers, list_hardware_interfaces, switch_controller and the
load / configure / unload lifecycle, on a small gz_ros2_control arm written here (real compile, real
MuJoCo, the world in process on a MemoryBus)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from runner.sim.schedule import Hook
from runner.sim.world import World
from runner.wire import msgs
from runner.wire.transport import MemoryBus
from tests.helpers import compile_with_notices, messages, plan_of

# a yaw shoulder, a pitch elbow (gravity acts on it) and a prismatic finger, all on gz_ros2_control
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link">
    <inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.15"/><mass value="1"/><inertia ixx="0.008" iyy="0.008" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="fore">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.3"/><inertia ixx="0.002" iyy="0.002" izz="0.0003" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <link name="finger">
    <inertial><mass value="0.05"/><inertia ixx="0.00001" iyy="0.00001" izz="0.00001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base_link"/><child link="upper"/><origin xyz="0 0 0.06"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="50" velocity="2"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="2.5" effort="30" velocity="2"/>
  </joint>
  <joint name="finger_joint" type="prismatic">
    <parent link="fore"/><child link="finger"/><origin xyz="0 0 0.2"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.1"/>
  </joint>
  <ros2_control name="arm" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    <joint name="shoulder"><command_interface name="position"/>
      <state_interface name="position"/><state_interface name="velocity"/></joint>
    <joint name="elbow"><command_interface name="position"/>
      <state_interface name="position"/><state_interface name="velocity"/><state_interface name="effort"/></joint>
    <joint name="finger_joint"><command_interface name="position"/>
      <state_interface name="position"/><state_interface name="velocity"/></joint>
  </ros2_control>
  <gazebo>
    <plugin filename="gz_ros2_control-system" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>{params}</parameters>
    </plugin>
  </gazebo>
</robot>
"""

CONTROL = """controller_manager:
  ros__parameters:
    update_rate: 100
    joint_state_broadcaster: {{type: joint_state_broadcaster/JointStateBroadcaster}}
    arm_controller: {{type: joint_trajectory_controller/JointTrajectoryController}}
    gripper_controller: {{type: {gripper}}}
    arm_forward: {{type: position_controllers/JointGroupPositionController}}
arm_controller:
  ros__parameters:
    joints: [shoulder, elbow]
    command_interfaces: [position]
    state_interfaces: [position, velocity]
    constraints:
      stopped_velocity_tolerance: 0.05
      goal_time: 0.5
      shoulder: {{trajectory: 0.2, goal: 0.01}}
      elbow: {{trajectory: 0.2, goal: 0.01}}
{arm_extra}gripper_controller:
  ros__parameters:
    joint: finger_joint
arm_forward:
  ros__parameters:
    joints: [shoulder, elbow]
"""

FJT = "control_msgs/action/FollowJointTrajectory"
GRIP = "control_msgs/action/GripperCommand"
PARALLEL = "control_msgs/action/ParallelGripperCommand"
SRV = "controller_manager_msgs/srv/"
# action_msgs/msg/GoalStatus
SUCCEEDED, CANCELED, ABORTED = 4, 5, 6


def _scenario(
    tmp_path: Path,
    *,
    duration: float = 3.0,
    gripper: str = "position_controllers/GripperActionController",
    spawn: str = "[joint_state_broadcaster, arm_controller, gripper_controller]",
    timeline: str = "",
    arm_extra: str = "",
) -> Path:
    (tmp_path / "control.yaml").write_text(CONTROL.format(gripper=gripper, arm_extra=arm_extra))
    (tmp_path / "arm.urdf").write_text(ARM.format(params=tmp_path / "control.yaml"))
    path = tmp_path / "g.yaml"
    path.write_text(
        f"name: g\nduration: {duration}\nrate: max\nseed: 1\nrobots:\n  - name: bot\n    description: arm.urdf\n"
        f"    fixed: true\n    pose: {{xyz: [0, 0, 0.05]}}\n    spawn: {spawn}\n"
        + (f"timeline:\n{timeline}" if timeline else "")
    )
    return path


class Client:
    """A ROS 2 client's requests, as CDR on the service keys, answered by the world in process."""

    def __init__(self, world: World, bus: MemoryBus):
        self.world, self.bus = world, bus

    def call(self, name: str, srv: str, data: dict[str, Any]) -> _Answer:
        """The request now; the list its decoded response (or the error text) is appended to."""
        payload = msgs.encode(msgs.from_data(f"{srv}_Request", data), f"{srv}_Request")
        raw = self.bus.call(f"g/bot/{name}", payload)
        return _Answer(raw, f"{srv}_Response")

    def goal(self, action: str, kind: str, goal_id: int, goal: dict[str, Any]) -> tuple[_Answer, _Answer]:
        """send_goal, then get_result at once (answered when the goal ends)."""
        uuid = {"uuid": [goal_id] * 16}
        sent = self.call(f"{action}/_action/send_goal", f"{kind}_SendGoal", {"goal_id": uuid, "goal": goal})
        result = self.call(f"{action}/_action/get_result", f"{kind}_GetResult", {"goal_id": uuid})
        return sent, result

    def cancel(self, action: str, goal_id: int) -> _Answer:
        return self.call(
            f"{action}/_action/cancel_goal",
            "action_msgs/srv/CancelGoal",
            {"goal_info": {"goal_id": {"uuid": [goal_id] * 16}}},
        )

    def at(self, t: float, fn: Callable[[], Any]) -> Later:
        """`fn()` once, at the first boundary at or after sim time `t` (its requests are answered at that
        boundary or later); its value lands in the returned `Later`."""
        later = Later()

        def hook(now: int) -> None:
            if not later.done and now >= t * 1e9:
                later.done, later.value = True, fn()

        self.world._after.append(Hook(hook, 10_000_000))
        return later

    def switch(self, on: list[str], off: list[str], strictness: int) -> _Answer:
        return self.call(
            "controller_manager/switch_controller",
            SRV + "SwitchController",
            {"activate_controllers": on, "deactivate_controllers": off, "strictness": strictness},
        )


class Later:
    done = False
    value: Any = None


class _Answer:
    """The decoded answer of one request: `answer[0]` once the world has answered (the error text for an
    error reply)."""

    def __init__(self, raw: list[Any], response: str):
        self.raw, self.response = raw, response

    def __len__(self) -> int:
        return len(self.raw)

    def __getitem__(self, i: Any) -> Any:
        payload, error = self.raw[i]
        return error if payload is None else msgs.decode(payload, self.response)


def _world(path: Path) -> tuple[World, MemoryBus, Client]:
    bus = MemoryBus()
    world = World(plan_of(path), bus)
    world._should_stop = lambda: False
    return world, bus, Client(world, bus)


def _trajectory(
    points: list[tuple[list[float], float]], names: tuple[str, ...] = ("shoulder", "elbow")
) -> dict:
    return {
        "joint_names": list(names),
        "points": [
            {"positions": p, "time_from_start": {"sec": int(t), "nanosec": round((t % 1) * 1e9)}}
            for p, t in points
        ],
    }


def _q(world: World, *joints: str) -> np.ndarray:
    m, r = world.model, world.robots[0]
    return np.array([world.data.qpos[m.jnt_qposadr[r.joint_id(j)]] for j in joints])


# ------------------------------------------------------------------------------- FollowJointTrajectory
@pytest.mark.timeout(60)
def test_a_follow_joint_trajectory_goal_moves_the_arm_and_succeeds_with_feedback(tmp_path: Path) -> None:
    """Accepted, feedback at action_monitor_rate (20 Hz) with the controller's joints and desired / actual
    / error points, then SUCCEEDED with the controller's code and text; the arm is at the goal."""
    world, bus, client = _world(_scenario(tmp_path, duration=2.0))
    sent, result = client.goal(
        "arm_controller/follow_joint_trajectory",
        FJT,
        1,
        {"trajectory": _trajectory([([0.6, 0.4], 1.0)])},
    )
    world.run()
    assert sent[0].accepted
    assert result[0].status == SUCCEEDED
    assert result[0].result.error_code == 0 and result[0].result.error_string == "Goal successfully reached!"
    assert np.allclose(_q(world, "shoulder", "elbow"), [0.6, 0.4], atol=0.01)
    feedback = messages(bus, "arm_controller/follow_joint_trajectory/_action/feedback")
    assert 15 <= len(feedback) <= 30, len(feedback)
    stamp, first = feedback[len(feedback) // 2]
    fb = first.feedback
    assert list(fb.joint_names) == ["shoulder", "elbow"] and bytes(first.goal_id.uuid) == bytes([1] * 16)
    assert fb.header.stamp.sec * 10**9 + fb.header.stamp.nanosec == stamp
    assert len(fb.desired.positions) == len(fb.actual.velocities) == len(fb.error.positions) == 2
    assert np.allclose(np.array(fb.desired.positions) - fb.actual.positions, fb.error.positions)
    assert 0.05 < fb.desired.positions[0] < 0.6  # half-way
    statuses = messages(bus, "arm_controller/follow_joint_trajectory/_action/status")
    assert [s.status_list[0].status for _, s in statuses][-1] == SUCCEEDED


@pytest.mark.timeout(60)
def test_goals_with_joints_the_controller_lacks_or_bad_points_are_rejected_and_the_world_goes_on(
    tmp_path: Path,
) -> None:
    """goal_received_callback: a trajectory that fails validation is rejected (no result ever comes: its
    get_result says UNKNOWN); a request that does not decode gets an error reply; the arm stays."""
    world, bus, client = _world(_scenario(tmp_path, duration=0.5))
    joints, _ = client.goal(
        "arm_controller/follow_joint_trajectory",
        FJT,
        1,
        {"trajectory": _trajectory([([0.5, 0.5], 1.0)], ("shoulder", "wrist"))},
    )
    sizes, _ = client.goal(
        "arm_controller/follow_joint_trajectory", FJT, 2, {"trajectory": _trajectory([([0.5], 1.0)])}
    )
    garbage = bus.call("g/bot/arm_controller/follow_joint_trajectory/_action/send_goal", b"\x00\x01\x02")
    start = _q(world, "shoulder", "elbow")
    world.run()
    assert not joints[0].accepted and not sizes[0].accepted
    assert garbage[0][0] is None and "does not decode" in garbage[0][1]
    unknown = client.call(
        "arm_controller/follow_joint_trajectory/_action/get_result",
        f"{FJT}_GetResult",
        {"goal_id": {"uuid": [1] * 16}},
    )
    world._boundary()
    assert unknown[0].status == 0  # UNKNOWN
    assert np.allclose(_q(world, "shoulder", "elbow"), start, atol=0.01)


@pytest.mark.timeout(60)
def test_a_goal_it_cannot_reach_ends_with_goal_tolerance_violated_after_goal_time_tolerance(
    tmp_path: Path,
) -> None:
    """The shoulder asked past its 2 rad limit, path tolerances erased (-1) and goal_time_tolerance 0.2 s from
    the goal: GOAL_TOLERANCE_VIOLATED, "Aborted due to goal_time_tolerance exceeding by <s> seconds"."""
    world, _bus, client = _world(_scenario(tmp_path, duration=2.0))
    erase = [{"name": j, "position": -1.0} for j in ("shoulder", "elbow")]
    _sent, result = client.goal(
        "arm_controller/follow_joint_trajectory",
        FJT,
        3,
        {
            "trajectory": _trajectory([([2.5, 0.0], 0.5)]),
            "path_tolerance": erase,
            "goal_tolerance": [{"name": "shoulder", "position": 0.01}],
            "goal_time_tolerance": {"nanosec": 200_000_000},
        },
    )
    world.run()
    r = result[0]
    assert r.status == ABORTED and r.result.error_code == -5, r
    assert r.result.error_string.startswith("Aborted due to goal_time_tolerance exceeding by 0.2")
    assert r.result.error_string.endswith(" seconds")


@pytest.mark.timeout(60)
def test_a_new_goal_preempts_the_active_one_and_a_cancel_holds_the_arm(tmp_path: Path) -> None:
    """goal_accepted_callback: the active goal is aborted (INVALID_GOAL, "Current goal preempted by new
    incoming action."), the new one runs to success; goal_cancelled_callback: a canceled goal ends CANCELED
    with an empty result and the arm holds where it was."""
    world, _bus, client = _world(_scenario(tmp_path, duration=3.0))
    action = "arm_controller/follow_joint_trajectory"
    first, first_result = client.goal(action, FJT, 1, {"trajectory": _trajectory([([1.0, 0.0], 2.0)])})
    second = client.at(
        0.5, lambda: client.goal(action, FJT, 2, {"trajectory": _trajectory([([-0.3, 0.2], 1.0)])})
    )
    third = client.at(
        1.7, lambda: client.goal(action, FJT, 3, {"trajectory": _trajectory([([1.5, 0.0], 2.0)])})
    )
    cancel = client.at(2.2, lambda: client.cancel(action, 3))
    held = client.at(2.25, lambda: _q(world, "shoulder")[0])
    world.run()
    (second_sent, second_result), (_third_sent, third_result) = second.value, third.value
    assert first[0].accepted and second_sent[0].accepted
    r = first_result[0]
    assert r.status == ABORTED and r.result.error_code == -1
    assert r.result.error_string == "Current goal preempted by new incoming action."
    assert second_result[0].status == SUCCEEDED
    answer = cancel.value[0]
    assert answer.return_code == 0 and bytes(answer.goals_canceling[0].goal_id.uuid) == bytes([3] * 16)
    r = third_result[0]
    assert r.status == CANCELED and r.result.error_code == 0 and r.result.error_string == ""
    q = _q(world, "shoulder")[0]
    assert -0.3 < q < 1.0 and abs(q - held.value) < 0.05, (q, held.value)  # stopped on the way to 1.5


# ---------------------------------------------------------------------------------------- grippers
@pytest.mark.timeout(60)
def test_gripper_command_goals_reach_or_stall_and_are_preempted_and_canceled(tmp_path: Path) -> None:
    """position_controllers/GripperActionController on `gripper_controller/gripper_cmd`: 0.02 m is reached
    (SUCCEEDED, reached_goal); 0.06 m, past the 0.04 m limit, stalls (ABORTED, stalled, at the limit); a goal
    preempted by the next ends CANCELED, as does a canceled one."""
    world, _bus, client = _world(_scenario(tmp_path, duration=4.0))
    action = "gripper_controller/gripper_cmd"
    _s, reached = client.goal(action, GRIP, 1, {"command": {"position": 0.02, "max_effort": 10.0}})
    stalled = client.at(1.0, lambda: client.goal(action, GRIP, 2, {"command": {"position": 0.06}})[1])
    preempted = client.at(3.0, lambda: client.goal(action, GRIP, 3, {"command": {"position": 0.0}})[1])
    last = client.at(3.05, lambda: client.goal(action, GRIP, 4, {"command": {"position": 0.0}})[1])
    cancel = client.at(3.1, lambda: client.cancel(action, 4))
    world.run()
    r = reached[0]
    assert r.status == SUCCEEDED and r.result.reached_goal and not r.result.stalled
    assert r.result.position == pytest.approx(0.02, abs=0.01)
    r = stalled.value[0]
    assert r.status == ABORTED and r.result.stalled and not r.result.reached_goal
    assert r.result.position == pytest.approx(0.04, abs=0.003)
    assert preempted.value[0].status == CANCELED
    assert cancel.value[0].return_code == 0 and last.value[0].status == CANCELED
    q = _q(world, "finger_joint")[0]
    assert q > 0.03, q  # held near where the cancel found it, not closed to 0


@pytest.mark.timeout(60)
def test_parallel_gripper_takes_one_position_and_rejects_other_sizes(tmp_path: Path) -> None:
    """parallel_gripper_action_controller: ParallelGripperCommand with one position reaches it (the result's
    state names the joint); a command with two positions is rejected (goal_callback)."""
    path = _scenario(
        tmp_path, duration=1.5, gripper="parallel_gripper_action_controller/GripperActionController"
    )
    world, _bus, client = _world(path)
    action = "gripper_controller/gripper_cmd"
    bad, _ = client.goal(action, PARALLEL, 1, {"command": {"position": [0.01, 0.02]}})
    good, result = client.goal(
        action, PARALLEL, 2, {"command": {"name": ["finger_joint"], "position": [0.025]}}
    )
    world.run()
    assert not bad[0].accepted and good[0].accepted
    r = result[0]
    assert r.status == SUCCEEDED and r.result.reached_goal
    assert list(r.result.state.name) == ["finger_joint"]
    assert r.result.state.position[0] == pytest.approx(0.025, abs=0.01)


# ---------------------------------------------------------------------------------- controller manager
def test_the_plan_declares_the_actions_and_the_controller_managers_services(tmp_path: Path) -> None:
    """Both actions and the six services are in the plan; the JTC's deceleration on cancel (Jazzy), which is
    not run, is said, and so is a per-joint constraint the controller does not have."""
    extra = "      decelerate_on_cancel: true\n"
    path = _scenario(tmp_path, arm_extra=extra)
    text = (
        (tmp_path / "control.yaml")
        .read_text()
        .replace(
            "elbow: {trajectory: 0.2, goal: 0.01}",
            "elbow: {trajectory: 0.2, goal: 0.01, max_deceleration_on_cancel: 1.0, goals: 1}",
        )
    )
    (tmp_path / "control.yaml").write_text(text)
    plan, said = compile_with_notices(path)
    assert "arm_controller: constraints.decelerate_on_cancel is not run: a cancel holds at once" in said
    assert "arm_controller: constraints.elbow.goals is not a parameter; ignored" in said
    assert "max_deceleration_on_cancel" not in said
    kinds = {s.key.removeprefix("g/bot/"): s.type for s in plan.services()}
    assert kinds["arm_controller/follow_joint_trajectory"] == FJT
    assert kinds["gripper_controller/gripper_cmd"] == GRIP
    for name, srv in (
        ("list_controllers", "ListControllers"),
        ("list_hardware_interfaces", "ListHardwareInterfaces"),
        ("switch_controller", "SwitchController"),
        ("load_controller", "LoadController"),
        ("configure_controller", "ConfigureController"),
        ("unload_controller", "UnloadController"),
    ):
        assert kinds[f"controller_manager/{name}"] == SRV + srv
    assert "not served" not in said


@pytest.mark.timeout(60)
def test_list_controllers_and_hardware_interfaces_say_what_runs_and_what_it_claims(tmp_path: Path) -> None:
    world, _bus, client = _world(_scenario(tmp_path))
    listed = client.call("controller_manager/list_controllers", SRV + "ListControllers", {})
    hardware = client.call("controller_manager/list_hardware_interfaces", SRV + "ListHardwareInterfaces", {})
    world._boundary()
    states = {c.name: c for c in listed[0].controller}
    assert set(states) == {
        "joint_state_broadcaster",
        "arm_controller",
        "gripper_controller",
    }  # arm_forward: not spawned
    arm = states["arm_controller"]
    assert (arm.state, arm.type, arm.update_rate) == (
        "active",
        "joint_trajectory_controller/JointTrajectoryController",
        100,
    )
    assert (
        list(arm.claimed_interfaces)
        == list(arm.required_command_interfaces)
        == ["shoulder/position", "elbow/position"]
    )
    assert list(arm.required_state_interfaces) == [
        "shoulder/position",
        "elbow/position",
        "shoulder/velocity",
        "elbow/velocity",
    ]
    grip = states["gripper_controller"]
    assert list(grip.claimed_interfaces) == ["finger_joint/position"]
    assert list(grip.required_state_interfaces) == ["finger_joint/position", "finger_joint/velocity"]
    assert states["joint_state_broadcaster"].state == "active"
    assert list(states["joint_state_broadcaster"].claimed_interfaces) == []
    command = {h.name: h for h in hardware[0].command_interfaces}
    assert list(command) == ["shoulder/position", "elbow/position", "finger_joint/position"]
    assert all(h.is_claimed and h.is_available and h.data_type == "double" for h in command.values())
    state = [h.name for h in hardware[0].state_interfaces]
    assert state == [
        "shoulder/position",
        "shoulder/velocity",
        "elbow/position",
        "elbow/velocity",
        "elbow/effort",
        "finger_joint/position",
        "finger_joint/velocity",
    ]


@pytest.mark.timeout(60)
def test_switch_controller_deactivates_a_controller_which_stops_driving_and_reactivates_it(
    tmp_path: Path,
) -> None:
    """Deactivated, the trajectory controller aborts its goal ("Current goal cancelled during deactivate
    transition."), leaves its joints to the hardware (held where they are, not at its goal), refuses goals and
    ignores trajectories; list_controllers says inactive, its interfaces unclaimed. Activated again, it holds
    where the arm is and follows a new goal."""
    traj = "{t: %s, topic: bot/arm_controller/joint_trajectory, type: trajectory_msgs/msg/JointTrajectory, data: %s}"
    later = {
        "joint_names": ["shoulder", "elbow"],
        "points": [{"positions": [-0.5, 0.3], "time_from_start": {"sec": 1}}],
    }
    timeline = f"  - {traj % (1.0, later)}\n"
    world, _bus, client = _world(_scenario(tmp_path, duration=3.0, timeline=timeline))
    action = "arm_controller/follow_joint_trajectory"
    _s, first = client.goal(action, FJT, 1, {"trajectory": _trajectory([([1.2, 0.0], 2.0)])})
    off = client.at(0.5, lambda: client.switch([], ["arm_controller"], 2))
    refused = client.at(
        0.6, lambda: client.goal(action, FJT, 2, {"trajectory": _trajectory([([0.1, 0.1], 1.0)])})
    )
    listed = client.at(
        0.6, lambda: client.call("controller_manager/list_controllers", SRV + "ListControllers", {})
    )
    hw = client.at(
        0.6,
        lambda: client.call(
            "controller_manager/list_hardware_interfaces", SRV + "ListHardwareInterfaces", {}
        ),
    )
    q_switched = client.at(0.6, lambda: _q(world, "shoulder")[0])
    q_off = client.at(1.5, lambda: _q(world, "shoulder")[0])
    on = client.at(1.6, lambda: client.switch(["arm_controller"], [], 1))
    again = client.at(
        1.7, lambda: client.goal(action, FJT, 3, {"trajectory": _trajectory([([0.8, -0.2], 0.8)])})
    )
    world.run()
    assert off.value[0].ok and off.value[0].message == ""
    r = first[0]
    assert r.status == ABORTED and r.result.error_code == -1
    assert r.result.error_string == "Current goal cancelled during deactivate transition."
    assert not refused.value[0][0].accepted
    arm = {c.name: c for c in listed.value[0].controller}["arm_controller"]
    assert arm.state == "inactive" and list(arm.claimed_interfaces) == []
    assert list(arm.required_command_interfaces) == ["shoulder/position", "elbow/position"]
    assert not any(h.is_claimed for h in hw.value[0].command_interfaces if h.name != "finger_joint/position")
    # held where the switch found it (on the way to 1.2), not moved by the trajectory at t=1 (to -0.5)
    assert 0.1 < q_switched.value < 1.0 and abs(q_off.value - q_switched.value) < 0.05, (
        q_switched.value,
        q_off.value,
    )
    assert on.value[0].ok
    r = again.value[1][0]
    assert r.status == SUCCEEDED, r
    assert np.allclose(_q(world, "shoulder", "elbow"), [0.8, -0.2], atol=0.01)


@pytest.mark.timeout(60)
def test_bad_switch_and_lifecycle_requests_get_the_replies_ros_gives(tmp_path: Path) -> None:
    """Unknown names, an active controller activated again, an inactive one deactivated, an interface
    another active controller claims: STRICT fails with the manager's message, BEST_EFFORT leaves them out.
    load / configure / unload: a controller not spawned cannot be loaded; an active one can neither be
    configured nor unloaded; unloaded, it leaves the list, loaded again it is unconfigured, cannot be
    activated until configured."""
    world, _bus, client = _world(_scenario(tmp_path, spawn="[joint_state_broadcaster, arm_controller]"))

    def switch(on: list[str], off: list[str], strictness: int) -> Any:
        answer = client.switch(on, off, strictness)
        world._boundary()
        return answer[0]

    def life(verb: str, srv: str, name: str) -> bool:
        answer = client.call(f"controller_manager/{verb}_controller", SRV + srv, {"name": name})
        world._boundary()
        return bool(answer[0].ok)

    def states() -> dict[str, str]:
        answer = client.call("controller_manager/list_controllers", SRV + "ListControllers", {})
        world._boundary()
        return {c.name: c.state for c in answer[0].controller}

    r = switch(["nope"], [], 2)
    assert (
        not r.ok
        and r.message
        == "Could not activate controller with name 'nope' because no controller with this name exists"
    )
    r = switch(["nope"], [], 1)
    assert not r.ok  # BEST_EFFORT, but nothing left to switch: the manager's ERROR
    r = switch(["arm_controller"], [], 2)
    assert not r.ok and r.message == "Controller with name 'arm_controller' is already active."
    r = switch(["arm_controller"], [], 0)  # 0: the default strictness, BEST_EFFORT
    assert (
        r.ok
        and r.message == "After checking the controllers, no controllers need to be activated or deactivated."
    )
    r = switch([], ["nope", "arm_controller"], 1)
    assert r.ok and states()["arm_controller"] == "inactive"
    r = switch([], ["arm_controller"], 2)
    assert (
        not r.ok
        and r.message
        == "Controller with name 'arm_controller' can not be deactivated since it is not active."
    )
    assert not life("load", "LoadController", "arm_forward")  # in the file, not spawned: not built
    assert not life("load", "LoadController", "arm_controller")  # already loaded
    assert not life("unload", "UnloadController", "joint_state_broadcaster")  # still active
    assert not life("configure", "ConfigureController", "joint_state_broadcaster")  # active
    assert not life("configure", "ConfigureController", "nope")
    assert life("unload", "UnloadController", "arm_controller")
    assert "arm_controller" not in states()
    r = switch(["arm_controller"], [], 2)
    assert not r.ok and "no controller with this name exists" in r.message
    assert life("load", "LoadController", "arm_controller") and states()["arm_controller"] == "unconfigured"
    r = switch(["arm_controller"], [], 2)
    assert not r.ok and "is in 'unconfigured' state" in r.message
    assert (
        life("configure", "ConfigureController", "arm_controller")
        and states()["arm_controller"] == "inactive"
    )
    r = switch(["arm_controller"], ["joint_state_broadcaster"], 2)
    assert r.ok and states() == {"joint_state_broadcaster": "inactive", "arm_controller": "active"}


@pytest.mark.timeout(60)
def test_a_controller_whose_interfaces_another_active_one_claims_is_not_activated(tmp_path: Path) -> None:
    """check_for_interfaces_availability_to_activate: with the forward controller active on the arm's
    position interfaces, the trajectory controller is not activated (STRICT and BEST_EFFORT alike: the
    manager checks interfaces after the per-controller checks); swapped in one request, it is."""
    world, _bus, client = _world(_scenario(tmp_path, spawn="[arm_controller, arm_forward]"))

    def switch(on: list[str], off: list[str], strictness: int) -> Any:
        answer = client.switch(on, off, strictness)
        world._boundary()
        return answer[0]

    assert switch([], ["arm_controller"], 2).ok
    for strictness in (1, 2):
        r = switch(["arm_controller"], [], strictness)
        assert not r.ok and r.message == (
            "Unable to activate controller 'arm_controller' since the command interface 'shoulder/position' "
            "is currently claimed by another controller."
        )
    assert switch(["arm_controller"], ["arm_forward"], 2).ok


@pytest.mark.timeout(60)
def test_a_diff_drive_controller_switched_off_stops_driving_and_publishing_and_drives_again_on(
    tmp_path: Path,
) -> None:
    """diff_drive_controller (bench/mobile.py's diffbot, its controllers file): list_controllers gives its
    wheels' velocity command and position state interfaces; deactivated at 1 s while TwistStamped commands
    stream, it stops publishing odometry and its wheels are held (the robot stops); activated at 2 s, it
    drives again."""
    from bench.mobile import DIFF, control, diffbot, truth, write

    timeline = "".join(
        "  - {t: %.1f, topic: r1/diff_cont/cmd_vel, type: geometry_msgs/msg/TwistStamped, "
        "data: {twist: {linear: {x: 0.2}}}}\n" % (0.1 * k)
        for k in range(1, 30)
    )
    path = write(tmp_path, diffbot(control("CONTROL_YAML")), DIFF, 3.0, timeline)
    bus = MemoryBus()
    world = World(plan_of(path), bus)
    client = Client(world, bus)

    def manager(name: str, srv: str, data: dict[str, Any]) -> _Answer:
        payload = msgs.encode(msgs.from_data(f"{SRV}{srv}_Request", data), f"{SRV}{srv}_Request")
        return _Answer(bus.call(f"t/r1/controller_manager/{name}", payload), f"{SRV}{srv}_Response")

    listed = client.at(0.5, lambda: manager("list_controllers", "ListControllers", {}))
    off = client.at(
        1.0,
        lambda: manager("switch_controller", "SwitchController", {"deactivate_controllers": ["diff_cont"]}),
    )
    on = client.at(
        2.0, lambda: manager("switch_controller", "SwitchController", {"activate_controllers": ["diff_cont"]})
    )
    world.run()
    cont = {c.name: c for c in listed.value[0].controller}["diff_cont"]
    assert list(cont.claimed_interfaces) == ["left_wheel_joint/velocity", "right_wheel_joint/velocity"]
    assert list(cont.required_state_interfaces) == ["left_wheel_joint/position", "right_wheel_joint/position"]
    assert off.value[0].ok and on.value[0].ok
    t, pose = truth(bus)
    x = {round(s, 2): float(p[0]) for s, p in zip(t, pose, strict=True)}
    assert x[1.0] - x[0.5] > 0.05  # driving
    assert abs(x[1.9] - x[1.3]) < 0.005, (x[1.3], x[1.9])  # held while inactive
    assert x[2.9] - x[2.3] > 0.05  # driving again
    stamps = [s / 1e9 for s, _ in messages(bus, "r1/diff_cont/odom")]
    assert not [s for s in stamps if 1.05 < s < 1.95] and [s for s in stamps if s > 2.1]


def test_a_ros1_trajectory_controller_gets_the_action_and_its_robot_the_managers_services(
    tmp_path: Path,
) -> None:
    """ROS 1 (a gazebo_ros_control launch loads the file): position_controllers/JointTrajectoryController
    gets `follow_joint_trajectory` as ros_controllers names it, on ROS 2's wire and type; the controller
    manager's services are ROS 2's too."""
    urdf = ARM.split("  <ros2_control")[0] + "</robot>\n"
    (tmp_path / "arm.urdf").write_text(urdf)
    (tmp_path / "ros1.yaml").write_text(
        "arm_controller:\n  type: position_controllers/JointTrajectoryController\n  joints: [shoulder, elbow]\n"
    )
    path = tmp_path / "g.yaml"
    path.write_text(
        "name: g\nduration: 1\nrate: max\nrobots:\n  - name: bot\n    description: arm.urdf\n    fixed: true\n"
        "    controllers: [ros1.yaml]\n"
    )
    plan, said = compile_with_notices(path)
    kinds = {s.key.removeprefix("g/bot/"): s.type for s in plan.services()}
    assert kinds["arm_controller/follow_joint_trajectory"] == FJT
    assert kinds["controller_manager/switch_controller"] == SRV + "SwitchController"
    assert "follow_joint_trajectory control_msgs/action/FollowJointTrajectory on ROS 2's wire" in said


def _zenoh_call(session: Any, key: str, srv: str, data: dict[str, Any], timeout: float = 30.0) -> Any:
    """A request on the native service wire (a Zenoh query, CDR payload) from a session of the test's own."""
    payload = msgs.encode(msgs.from_data(f"{srv}_Request", data), f"{srv}_Request")
    replies = [r for r in session.get(key, payload=payload, timeout=timeout)]
    assert len(replies) == 1 and replies[0].ok is not None, [r.err for r in replies]
    return msgs.decode(replies[0].ok.payload.to_bytes(), f"{srv}_Response")


@pytest.mark.timeout(120)
def test_a_real_run_answers_the_controller_manager_and_a_goal_over_zenoh(tmp_path: Path) -> None:
    """A real run (real time, its own Zenoh router): a client session queries controller_manager/
    list_controllers, sends a FollowJointTrajectory goal and waits for its result with get_result (answered
    when the arm got there), then switches the controller off."""
    import subprocess
    import threading

    from runner.wire.transport import free_port
    from tests.conftest import read_mcap, scenario_cmd
    from tests.test_trajectory_controllers import _join

    port = free_port()
    path = _scenario(tmp_path, duration=30.0)
    text = path.read_text().replace("name: g\n", "name: zc\n", 1)
    path.write_text(text)
    proc = subprocess.Popen(
        scenario_cmd("run", str(path), "--no-judge", "--rate", "1", "--listen", f"tcp/127.0.0.1:{port}"),
        cwd=tmp_path,  # its recording goes there
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        session = _join(port, "zc")
        try:
            flowing = threading.Event()  # the world steps: its services are declared (before the first step)
            sub = session.declare_subscriber(
                "zc/bot/arm_controller/controller_state", lambda _s: flowing.set()
            )
            assert flowing.wait(40), "the world did not start"
            sub.undeclare()
            listed = _zenoh_call(
                session, "zc/bot/controller_manager/list_controllers", SRV + "ListControllers", {}
            )
            assert {c.name for c in listed.controller} == {
                "joint_state_broadcaster", "arm_controller", "gripper_controller"
            }  # fmt: skip
            uuid = {"uuid": [7] * 16}
            action = "zc/bot/arm_controller/follow_joint_trajectory/_action"
            goal = {"trajectory": _trajectory([([0.5, -0.3], 1.0)])}
            sent = _zenoh_call(
                session, f"{action}/send_goal", f"{FJT}_SendGoal", {"goal_id": uuid, "goal": goal}
            )
            assert sent.accepted
            result = _zenoh_call(session, f"{action}/get_result", f"{FJT}_GetResult", {"goal_id": uuid})
            assert result.status == SUCCEEDED and result.result.error_string == "Goal successfully reached!"
            off = _zenoh_call(
                session,
                "zc/bot/controller_manager/switch_controller",
                SRV + "SwitchController",
                {"deactivate_controllers": ["arm_controller"], "strictness": 2},
            )
            assert off.ok
        finally:
            session.close()
    finally:
        proc.terminate()
        try:
            proc.communicate(timeout=20)
        finally:
            proc.kill()
    # the recording says what was asked and answered: REQUEST_RECEIVED then RESPONSE_SENT
    events = [
        m
        for key, _t, _s, m in read_mcap(tmp_path / "runs" / "zc.mcap")
        if key.endswith("switch_controller/_service_event")
    ]
    assert [e.info.event_type for e in events] == [1, 2]
    assert (
        list(events[0].request[0].deactivate_controllers) == ["arm_controller"] and events[1].response[0].ok
    )
