"""joint_trajectory_controller and the gripper controllers (issue 36, point 4): the spline math without
physics, then a small world-fixed arm (written here) on real MuJoCo, in-process and through a real run's
Zenoh router."""

from __future__ import annotations

import math
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from plugins._trajectory import Point, Trajectory, interpolate
from runner.sim.world import World
from runner.wire import msgs
from runner.wire.transport import MemoryBus, encoding_for
from tests.conftest import scenario_cmd
from tests.helpers import compile_with_notices, messages, plan_of

# A 3-joint arm: a yaw shoulder, a pitch elbow (gravity acts on it) and a prismatic finger
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link">
    <inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.15"/><mass value="1"/><inertia ixx="0.008" iyy="0.008" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.15"/><geometry><cylinder radius="0.03" length="0.3"/></geometry></collision>
  </link>
  <link name="fore">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.3"/><inertia ixx="0.002" iyy="0.002" izz="0.0003" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.02" length="0.2"/></geometry></collision>
  </link>
  <link name="finger">
    <inertial><mass value="0.05"/><inertia ixx="0.00001" iyy="0.00001" izz="0.00001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.02"/><geometry><box size="0.01 0.02 0.04"/></geometry></collision>
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
</robot>
"""

CONTROL = """controller_manager:
  ros__parameters:
    update_rate: 100
    arm_controller:
      type: joint_trajectory_controller/JointTrajectoryController
    gripper_controller:
      type: {gripper_type}
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
arm_controller:
  ros__parameters:
    joints: [shoulder, elbow]
    command_interfaces: [position]
    state_interfaces: [position, velocity]
{arm_extra}    constraints:
      stopped_velocity_tolerance: 0.05
      goal_time: 0.5
      shoulder: {{trajectory: 0.1, goal: 0.01}}
      elbow: {{trajectory: 0.1, goal: 0.01}}
gripper_controller:
  ros__parameters:
    joint: finger_joint
{gripper_extra}"""


def _traj(names: list[str], points: list[tuple[list[float], float]], stamp: float = 0.0) -> str:
    """A JointTrajectory as timeline YAML data."""
    pts = ", ".join(
        f"{{positions: {p}, time_from_start: {{sec: {int(t)}, nanosec: {round((t % 1) * 1e9)}}}}}"
        for p, t in points
    )
    return f"{{header: {{stamp: {{sec: {int(stamp)}}}}}, joint_names: {names}, points: [{pts}]}}"


def _arm(
    tmp_path: Path,
    timeline: list[str],
    *,
    duration: float = 4.0,
    gripper_type: str = "position_controllers/GripperActionController",
    arm_extra: str = "",
    gripper_extra: str = "",
    name: str = "g",
) -> Path:
    (tmp_path / "arm.urdf").write_text(ARM)
    (tmp_path / "control.yaml").write_text(
        CONTROL.format(gripper_type=gripper_type, arm_extra=arm_extra, gripper_extra=gripper_extra)
    )
    path = tmp_path / f"{name}.yaml"
    path.write_text(
        f"name: {name}\nduration: {duration}\nrate: max\nseed: 1\nrobots:\n  - name: bot\n    description: arm.urdf\n"
        "    fixed: true\n    pose: {xyz: [0, 0, 0.05]}\n    controllers: [control.yaml]\n"
        + ("timeline:\n" + "".join(f"  - {e}\n" for e in timeline) if timeline else "")
    )
    return path


def _trajectory_at(t: float, data: str) -> str:
    return f"{{t: {t}, topic: bot/arm_controller/joint_trajectory, type: trajectory_msgs/msg/JointTrajectory, data: {data}}}"


def _gripper_at(t: float, position: float, effort: float = 10.0) -> str:
    return (
        f"{{t: {t}, topic: bot/gripper_controller/gripper_cmd, type: control_msgs/msg/GripperCommand, "
        f"data: {{position: {position}, max_effort: {effort}}}}}"
    )


def _states(bus: MemoryBus) -> list[tuple[float, Any]]:
    return [(s / 1e9, m) for s, m in messages(bus, "bot/arm_controller/controller_state")]


def _run(path: Path) -> tuple[World, MemoryBus]:
    bus = MemoryBus()
    world = World(plan_of(path), bus)
    world.run()
    return world, bus


# ------------------------------------------------------------------------------------------ spline math
def test_interpolation_is_linear_cubic_or_quintic_by_the_fields_the_points_have() -> None:
    """trajectory.cpp's splines at sampled times against their closed forms: positions only -> a straight
    line; zero end velocities -> 3s²-2s³; zero end velocities and accelerations -> 10s³-15s⁴+6s⁵."""
    p0, p1, T = np.array([0.2, -1.0]), np.array([1.2, 1.0]), 2.0
    for s in (0.0, 0.1, 0.37, 0.5, 0.81, 1.0):
        t = s * T
        pos, vel, _, _ = interpolate(0.0, Point(0, p0), T, Point(T, p1), t)
        assert np.allclose(pos, p0 + (p1 - p0) * s) and np.allclose(vel, (p1 - p0) / T)
        z = np.zeros(2)
        pos, vel, acc, _ = interpolate(0.0, Point(0, p0, z), T, Point(T, p1, z), t)
        assert np.allclose(pos, p0 + (p1 - p0) * (3 * s**2 - 2 * s**3))
        assert np.allclose(vel, (p1 - p0) * (6 * s - 6 * s**2) / T)
        assert np.allclose(acc, (p1 - p0) * (6 - 12 * s) / T**2)
        pos, vel, acc, _ = interpolate(0.0, Point(0, p0, z, z), T, Point(T, p1, z, z), t)
        assert np.allclose(pos, p0 + (p1 - p0) * (10 * s**3 - 15 * s**4 + 6 * s**5))
        assert np.allclose(vel, (p1 - p0) * (30 * s**2 - 60 * s**3 + 30 * s**4) / T)
    # a cubic with end velocities meets them at both ends
    v0, v1 = np.array([0.5, -0.3]), np.array([-0.2, 0.4])
    for t, want_p, want_v in ((0.0, p0, v0), (T, p1, v1)):
        pos, vel, _, _ = interpolate(0.0, Point(0, p0, v0), T, Point(T, p1, v1), t - 1e-12 if t else t)
        assert np.allclose(pos, want_p, atol=1e-9) and np.allclose(vel, want_v, atol=1e-9)


def test_sampling_starts_from_the_state_before_and_holds_the_last_point() -> None:
    """Before the first point the trajectory runs from the state it started in (at 1.0 s, the arrival
    time when the stamp is 0); after the last point it gives the last point, at rest."""
    traj = Trajectory([Point(1.0, np.array([1.0])), Point(3.0, np.array([2.0]))])
    traj.set_before(1.0, Point(0.0, np.array([0.0]), np.array([0.0])))
    assert traj.sample(1.0).positions == pytest.approx([0.0])  # first sample: the start becomes "now"
    assert traj.sample(0.5) is None  # before the state it started from
    assert traj.sample(1.5).positions == pytest.approx([0.5])  # linear from 0 at 1 s to 1 at 2 s
    s = traj.sample(3.0)
    assert s.positions == pytest.approx([1.5]) and s.segment == 1  # heading for point 1
    end = traj.sample(10.0)
    assert end.positions == pytest.approx([2.0]) and end.velocities == pytest.approx([0.0])
    assert end.segment == 2 == len(traj.points) and traj.end_time == pytest.approx(4.0)
    # a stamp in the future: the first segment runs from the state before until stamp + first time
    later = Trajectory([Point(1.0, np.array([1.0]))], start=5.0)
    later.set_before(2.0, Point(0.0, np.array([0.0])))
    assert later.sample(4.0).positions == pytest.approx([0.5])  # 0 at 2 s -> 1 at 6 s


# ------------------------------------------------------------------------------------------ arm, physics
@pytest.mark.timeout(60)
def test_a_two_point_trajectory_is_followed_within_its_tolerances(tmp_path: Path) -> None:
    """The issue's acceptance case: a 2-point JointTrajectory on `arm_controller/joint_trajectory`, its
    joints named in another order than the controller's, ends within 0.01 rad and stays within the
    path tolerance (0.1 rad) on the way; controller_state reports reference, feedback and error."""
    data = _traj(["elbow", "shoulder"], [([0.3, 0.4], 1.0), ([0.8, 1.0], 2.0)])
    _, bus = _run(_arm(tmp_path, [_trajectory_at(0.5, data)]))
    states = _states(bus)
    assert len(states) >= 390  # every update, 100 Hz (Jazzy)
    final = states[-1][1]
    assert list(final.joint_names) == ["shoulder", "elbow"]
    assert np.allclose(final.reference.positions, [1.0, 0.8])  # reordered by name
    assert np.max(np.abs(np.asarray(final.feedback.positions) - [1.0, 0.8])) <= 0.01
    path_error = max(np.max(np.abs(m.error.positions)) for _, m in states)
    assert path_error < 0.1, path_error
    # interpolated, not stepped: half-way through the first segment (0.5 s + 0.5 s) the reference is
    # half of the first point
    mid = next(m for t, m in states if t >= 1.0 - 1e-9)
    assert np.allclose(mid.reference.positions, [0.2, 0.15], atol=0.01), mid.reference.positions
    js = messages(bus, "bot/joint_states")[-1][1]
    assert dict(zip(js.name, js.position, strict=True))["shoulder"] == pytest.approx(1.0, abs=0.01)


@pytest.mark.timeout(60)
def test_a_new_trajectory_mid_motion_replaces_the_old_one_from_the_current_state(tmp_path: Path) -> None:
    """A second trajectory at 1.5 s, while the first (to 1.5 rad over 2 s) is half done, replaces it: the
    reference goes on from the measured state without a jump and ends at the second one's point."""
    first = _traj(["shoulder", "elbow"], [([1.5, 0.0], 2.0)])
    second = _traj(["shoulder", "elbow"], [([-0.5, 0.3], 1.0)])
    _, bus = _run(_arm(tmp_path, [_trajectory_at(0.5, first), _trajectory_at(1.5, second)]))
    states = _states(bus)
    before = [m for t, m in states if t < 1.5 - 1e-9][-1]
    after = next(m for t, m in states if t >= 1.5 + 1e-9)
    assert 0.5 < before.reference.positions[0] < 1.0  # half-way along the first
    assert abs(after.reference.positions[0] - before.feedback.positions[0]) < 0.05  # continuous
    final = states[-1][1]
    assert np.allclose(final.reference.positions, [-0.5, 0.3])
    assert np.max(np.abs(np.asarray(final.feedback.positions) - [-0.5, 0.3])) <= 0.01
    # the first trajectory's target was never reached
    assert max(m.feedback.positions[0] for _, m in states) < 1.2


@pytest.mark.timeout(60)
def test_partial_goals_are_refused_unless_allowed_and_then_hold_the_other_joints(tmp_path: Path) -> None:
    data = _traj(["elbow"], [([0.5], 1.0)])
    _, bus = _run(_arm(tmp_path, [_trajectory_at(0.2, data)], duration=2.0))
    assert np.allclose(_states(bus)[-1][1].reference.positions, [0.0, 0.0])  # refused
    both = _traj(["shoulder", "elbow"], [([0.4, 0.0], 0.5)])
    path = _arm(
        tmp_path,
        [_trajectory_at(0.1, both), _trajectory_at(1.0, data)],
        duration=2.5,
        arm_extra="    allow_partial_joints_goal: true\n",
        name="h",
    )
    _, bus = _run(path)
    final = _states(bus)[-1][1]
    assert np.allclose(final.reference.positions, [0.4, 0.5])  # the shoulder holds its last command


def _controller(world: World, type_name: str) -> Any:
    return next(p for p in world.plugins if type(p).__name__ == type_name)


@pytest.mark.timeout(60)
def test_goals_through_the_internal_api_report_success_path_violation_and_preemption(tmp_path: Path) -> None:
    """What the FollowJointTrajectory action server will call: a goal succeeds with the controller's
    text; a goal with a 1 mrad path tolerance on a fast move is aborted with PATH_TOLERANCE_VIOLATED and
    the arm holds where it was; a goal is preempted by the next (INVALID_GOAL); a bad one is rejected."""
    from plugins.joint_trajectory_controller import PATH_TOLERANCE_VIOLATED

    path = _arm(tmp_path, [], duration=2.0)
    world = World(plan_of(path), MemoryBus())
    jtc = _controller(world, "JointTrajectoryController")
    trajectory = msgs.from_data(
        "trajectory_msgs/msg/JointTrajectory",
        {
            "joint_names": ["shoulder", "elbow"],
            "points": [{"positions": [0.6, 0.2], "time_from_start": {"sec": 1}}],
        },
    )
    results: list[Any] = []
    feedback: list[Any] = []
    preempted = jtc.submit_goal(trajectory, on_result=results.append)
    goal = jtc.submit_goal(trajectory, on_result=results.append, on_feedback=feedback.append)
    assert preempted.status == "aborted" and preempted.result.error_code == -1
    assert preempted.result.error_string == "Current goal preempted by new incoming action."
    bad = msgs.from_data(
        "trajectory_msgs/msg/JointTrajectory",
        {"joint_names": ["nope", "elbow"], "points": [{"positions": [0, 0]}]},
    )
    rejected = jtc.submit_goal(bad)
    assert rejected.status == "rejected" and "nope" in rejected.reason
    world.run()
    assert goal.status == "succeeded" and goal.result.error_code == 0
    assert goal.result.error_string == "Goal successfully reached!"
    assert 15 <= len(feedback) <= 30  # 20 Hz action_monitor_rate for about a second
    assert feedback[-1].joint_names == ["shoulder", "elbow"]

    # canceled half-way (from a feedback callback, in the sim loop): the arm holds where it was
    world = World(plan_of(path), MemoryBus())
    jtc = _controller(world, "JointTrajectoryController")
    handles: list[Any] = []

    def cancel_late(f: Any) -> None:
        if f.stamp_ns >= 500_000_000:
            handles[0].cancel()

    handles.append(jtc.submit_goal(trajectory, on_feedback=cancel_late, on_result=results.append))
    world.run()
    assert handles[0].status == "canceled" and results[-1].error_code == 0
    q = world.data.qpos[jtc.qadr]
    assert 0.1 < q[0] < 0.5, q  # stopped on the way to 0.6

    class Tol:
        def __init__(self, name: str) -> None:
            self.name, self.position, self.velocity, self.acceleration = name, 0.001, 0.0, 0.0

    world = World(plan_of(path), MemoryBus())
    jtc = _controller(world, "JointTrajectoryController")
    fast = msgs.from_data(
        "trajectory_msgs/msg/JointTrajectory",
        {
            "joint_names": ["shoulder", "elbow"],
            "points": [{"positions": [1.5, 1.0], "time_from_start": {"nanosec": 300_000_000}}],
        },
    )
    goal = jtc.submit_goal(fast, path_tolerance=[Tol("shoulder"), Tol("elbow")])
    world.run()
    assert goal.status == "aborted" and goal.result.error_code == PATH_TOLERANCE_VIOLATED == -4
    assert goal.result.error_string == "Aborted due to path tolerance violation"
    q = world.data.qpos[jtc.qadr]
    assert q[0] < 0.5, q  # held where the violation was found, well short of 1.5


@pytest.mark.timeout(60)
def test_gripper_opens_and_closes_on_its_command_topic_and_reports_goals(tmp_path: Path) -> None:
    """position_controllers/GripperActionController: `gripper_controller/gripper_cmd` (ours, a
    GripperCommand) opens the finger to 0.03 m, then closes it to 0.005 m."""
    path = _arm(tmp_path, [_gripper_at(0.2, 0.03), _gripper_at(1.2, 0.005)], duration=2.0)
    _, bus = _run(path)
    finger = [
        (s / 1e9, dict(zip(m.name, m.position, strict=True))["finger_joint"])
        for s, m in messages(bus, "bot/joint_states")
    ]
    opened = [q for t, q in finger if 1.0 <= t < 1.2]
    assert opened and all(abs(q - 0.03) < 0.003 for q in opened), opened[-1]
    assert abs(finger[-1][1] - 0.005) < 0.003, finger[-1]
    # the internal API: reached_goal, and a stall against the joint limit (0.04 m) when asked past it
    path = _arm(tmp_path, [], duration=2.0, name="api")
    world = World(plan_of(path), MemoryBus())
    grip = _controller(world, "GripperActionController")
    reached = grip.submit_goal(0.02)
    world.run()
    assert reached.status == "succeeded" and reached.result.reached_goal and not reached.result.stalled
    world = World(plan_of(path), MemoryBus())
    grip = _controller(world, "GripperActionController")
    stalled = grip.submit_goal(0.06)
    world.run()
    assert stalled.status == "aborted" and stalled.result.stalled and not stalled.result.reached_goal
    assert stalled.result.position == pytest.approx(0.04, abs=0.003)


@pytest.mark.timeout(60)
def test_parallel_and_effort_grippers_move_the_finger(tmp_path: Path) -> None:
    """parallel_gripper_action_controller takes a JointState goal on our topic; the effort gripper
    drives its finger with the PID of `gains`, limited by the goal's max_effort."""
    parallel = (
        "{t: 0.2, topic: bot/gripper_controller/gripper_cmd, type: sensor_msgs/msg/JointState, "
        "data: {position: [0.025]}}"
    )
    path = _arm(
        tmp_path,
        [parallel],
        duration=1.5,
        gripper_type="parallel_gripper_action_controller/GripperActionController",
    )
    _, bus = _run(path)
    js = messages(bus, "bot/joint_states")[-1][1]
    assert dict(zip(js.name, js.position, strict=True))["finger_joint"] == pytest.approx(0.025, abs=0.003)
    path = _arm(
        tmp_path,
        [_gripper_at(0.2, 0.03, 20.0)],
        duration=1.5,
        gripper_type="effort_controllers/GripperActionController",
        gripper_extra="    gains:\n      finger_joint: {p: 50.0, d: 1.0}\n",
        name="e",
    )
    _, bus = _run(path)
    js = messages(bus, "bot/joint_states")[-1][1]
    assert dict(zip(js.name, js.position, strict=True))["finger_joint"] == pytest.approx(0.03, abs=0.005)


def test_unknown_and_unrun_parameters_are_said_at_the_controllers_file(tmp_path: Path) -> None:
    path = _arm(
        tmp_path,
        [],
        arm_extra="    bogus_param: 3\n    speed_scaling: {initial_scaling_factor: 0.5}\n"
        "    gains:\n      elbow: {p: 1.0, kp: 2.0}\n",
        gripper_extra="    stall_timeot: 2.0\n",
    )
    plan, said = compile_with_notices(path)
    assert "arm_controller: 'bogus_param' is not a parameter of joint_trajectory_controller; ignored" in said
    assert "arm_controller: speed_scaling speed scaling is not run" in said
    assert "arm_controller: gains.elbow.kp is not a parameter of the controller; ignored" in said
    assert "gripper_controller: 'stall_timeot' is not a parameter of the gripper controller" in said
    assert "gripper_cmd" not in said and "follow_joint_trajectory" not in said  # both actions are served
    types = [p.type for p in plan.robots[0].plugins]
    assert "joint_trajectory_controller" in types and "gripper_action_controller" in types


@pytest.mark.timeout(60)
def test_ros1_joint_trajectory_controller_takes_command_and_publishes_state(tmp_path: Path) -> None:
    (tmp_path / "arm.urdf").write_text(ARM)
    (tmp_path / "ros1.yaml").write_text(
        "arm_controller:\n  type: position_controllers/JointTrajectoryController\n  joints: [shoulder, elbow]\n"
        "  constraints: {goal_time: 0.5, shoulder: {goal: 0.02}}\n"
    )
    path = tmp_path / "r1.yaml"
    data = _traj(["shoulder", "elbow"], [([0.5, 0.2], 1.0)])
    path.write_text(
        "name: r1\nduration: 2\nrate: max\nrobots:\n  - name: bot\n    description: arm.urdf\n    fixed: true\n"
        "    controllers: [ros1.yaml]\ntimeline:\n"
        f"  - {{t: 0.2, topic: bot/arm_controller/command, type: trajectory_msgs/msg/JointTrajectory, data: {data}}}\n"
    )
    _, bus = _run(path)
    states = [m for _, m in messages(bus, "bot/arm_controller/state")]
    assert 90 <= len(states) <= 105  # ROS 1's state_publish_rate default, 50 Hz
    assert np.max(np.abs(np.asarray(states[-1].feedback.positions) - [0.5, 0.2])) <= 0.01


# ------------------------------------------------------------------------------------------- Zenoh run
def _join(port: int, run: str, deadline_s: float = 40.0) -> Any:
    import zenoh

    from runner.wire.transport import make_config

    session = None
    deadline = time.monotonic() + deadline_s
    while session is None and time.monotonic() < deadline:
        try:
            session = zenoh.open(make_config("client", connect=[f"tcp/127.0.0.1:{port}"]))
        except zenoh.ZError:
            time.sleep(0.1)
    assert session is not None, "the run's router never listened"
    return session


@pytest.mark.timeout(120)
def test_a_trajectory_published_through_zenoh_moves_the_arm(tmp_path: Path) -> None:
    """A real run (real time, its own Zenoh router): a client session of the test's own publishes a
    JointTrajectory on <run>/bot/arm_controller/joint_trajectory once controller_state flows, and reads
    joint_states and controller_state back until the arm is at the goal."""
    from runner.wire.transport import free_port

    port = free_port()
    path = _arm(tmp_path, [], duration=30.0, name="zt")
    proc = subprocess.Popen(
        scenario_cmd("run", str(path), "--no-judge", "--rate", "1", "--listen", f"tcp/127.0.0.1:{port}"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        session = _join(port, "zt")
        try:
            latest: dict[str, Any] = {}
            flowing, there = threading.Event(), threading.Event()
            goal = [0.7, -0.4]

            def on_state(sample: Any) -> None:
                m = msgs.decode(sample.payload.to_bytes(), "control_msgs/msg/JointTrajectoryControllerState")
                latest["state"] = m
                flowing.set()

            def on_joints(sample: Any) -> None:
                m = msgs.decode(sample.payload.to_bytes(), "sensor_msgs/msg/JointState")
                q = dict(zip(m.name, m.position, strict=True))
                latest["joints"] = q
                if abs(q["shoulder"] - goal[0]) < 0.01 and abs(q["elbow"] - goal[1]) < 0.01:
                    there.set()

            subs = [
                session.declare_subscriber("zt/bot/arm_controller/controller_state", on_state),
                session.declare_subscriber("zt/bot/joint_states", on_joints),
            ]
            assert flowing.wait(40), "no controller_state"
            ttype = "trajectory_msgs/msg/JointTrajectory"
            msg = msgs.from_data(
                ttype,
                {
                    "joint_names": ["shoulder", "elbow"],
                    "points": [{"positions": goal, "time_from_start": {"sec": 1}}],
                },
            )
            session.put(
                "zt/bot/arm_controller/joint_trajectory",
                msgs.encode(msg, ttype),
                encoding=encoding_for(ttype),
            )
            assert there.wait(20), latest.get("joints")
            state = latest["state"]
            assert np.allclose(state.reference.positions, goal)
            assert math.isfinite(state.error.positions[0])
            for s in subs:
                s.undeclare()
        finally:
            session.close()
    finally:
        proc.terminate()
        try:
            proc.communicate(timeout=20)
        finally:
            proc.kill()


@pytest.mark.timeout(60)
@pytest.mark.parametrize("interface", ["velocity", "effort"])
def test_velocity_and_effort_interfaces_follow_through_the_pid_of_gains_and_not_without(
    tmp_path: Path, interface: str
) -> None:
    """A velocity- or effort-only command interface runs ros2_controllers' PID adapter: the sampled
    velocity × ff_velocity_scale plus a PID of `gains.<joint>` on the error. With gains the arm follows;
    without (all 0, the default) nothing drives it and the shoulder stays where it was."""
    data = _traj(["shoulder", "elbow"], [([0.6, 0.3], 1.0)])
    # gains a 100 Hz loop keeps stable on these small inertias (shoulder 0.0013 kg m², elbow 0.007)
    gains = {
        "velocity": ("{p: 20.0, i: 5.0, ff_velocity_scale: 1.0}",) * 2,
        "effort": ("{p: 1.0, i: 1.0, d: 0.03}", "{p: 5.0, i: 5.0, d: 0.15}"),
    }[interface]
    extra = f"    gains:\n      shoulder: {gains[0]}\n      elbow: {gains[1]}\n"
    control = CONTROL.replace("command_interfaces: [position]", f"command_interfaces: [{interface}]")
    for with_gains, name in ((True, "pid"), (False, "none")):
        path = _arm(tmp_path, [_trajectory_at(0.2, data)], duration=2.5, name=name)
        (tmp_path / "control.yaml").write_text(
            control.format(
                gripper_type="position_controllers/GripperActionController",
                arm_extra=extra if with_gains else "",
                gripper_extra="",
            )
        )
        _, bus = _run(path)
        final = _states(bus)[-1][1]
        error = np.abs(np.asarray(final.feedback.positions) - [0.6, 0.3])
        if with_gains:
            assert error.max() <= 0.01, (interface, error)
        else:
            assert abs(final.feedback.positions[0]) < 0.01, final.feedback.positions  # not driven


def test_ros1_effort_trajectory_controller_updates_every_physics_step_as_gazebo_ros_control(
    tmp_path: Path,
) -> None:
    """gazebo_ros_control updates its controllers every control_period, by default the physics step. A ROS 1
    effort JointTrajectoryController with stiff PID gains (Interbotix' arms use p 100-500 on light links) is
    stable there; run at 100 Hz, the same gains flailed (a public 6-DoF arm's joints swung 5.7 rad before any
    trajectory)."""
    (tmp_path / "arm.urdf").write_text(ARM)
    (tmp_path / "ros1.yaml").write_text(
        "arm_controller:\n  type: effort_controllers/JointTrajectoryController\n  joints: [shoulder, elbow]\n"
        "  gains:\n    shoulder: {p: 100, i: 0, d: 1}\n    elbow: {p: 200, i: 0, d: 2}\n"
        "  constraints: {goal_time: 0.5}\n"
    )
    path = tmp_path / "r1.yaml"
    data = _traj(["shoulder", "elbow"], [([0.5, 0.3], 1.0)])
    path.write_text(
        "name: r1\nduration: 2\nrate: max\nrobots:\n  - name: bot\n    description: arm.urdf\n    fixed: true\n"
        "    controllers: [ros1.yaml]\ntimeline:\n"
        f"  - {{t: 0.5, topic: bot/arm_controller/command, type: trajectory_msgs/msg/JointTrajectory, data: {data}}}\n"
    )
    _, bus = _run(path)
    states = [(s / 1e9, m) for s, m in messages(bus, "bot/arm_controller/state")]
    before = max(float(np.abs(np.asarray(m.feedback.positions)).max()) for t, m in states if t < 0.5)
    assert before < 0.05, f"the arm swung {before:.3f} rad before any trajectory"
    final = np.asarray(states[-1][1].feedback.positions)
    # a PD with gravity on the elbow: p 200 leaves its weight's torque / p of error
    assert np.abs(final - [0.5, 0.3]).max() < 0.05, final
