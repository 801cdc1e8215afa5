"""Issue 36's arm acceptance, end to end on the example arm (scenarios/robots/bench_arm, made for the
project): a URDF whose root link is `world` welds it; it starts at its <ros2_control> initial_values and
holds them for 10 s; a 2-point JointTrajectory on the controller's topic is followed within the controller's
path tolerance and ends within 0.01 rad; the gripper opens and closes, its mimic twin with it. Real MuJoCo,
the world stepped in process (tests/helpers.py)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from tests.conftest import SCENARIOS
from tests.helpers import messages, simulate

ROBOT = SCENARIOS / "robots" / "bench_arm"
ARM = ["pan", "shoulder", "elbow", "wrist"]


def _scenario(tmp_path: Path) -> Path:
    path = tmp_path / "arm.yaml"
    path.write_text(
        f"""
name: acc
duration: 16.0
rate: max
seed: 1
robots:
  - name: arm
    description: {ROBOT / "urdf" / "bench_arm.urdf"}
    controllers: [{ROBOT / "config" / "controllers.yaml"}]
timeline:
  - t: 10.0
    topic: arm/arm_controller/joint_trajectory
    type: trajectory_msgs/msg/JointTrajectory
    data:
      joint_names: [elbow, pan, wrist, shoulder]
      points:
        - {{positions: [0.9, 0.5, 0.3, -0.4], time_from_start: {{sec: 1}}}}
        - {{positions: [1.2, 1.0, -0.2, -0.7], velocities: [0, 0, 0, 0], time_from_start: {{sec: 2}}}}
  - {{t: 13.0, topic: arm/gripper_controller/gripper_cmd, type: control_msgs/msg/GripperCommand,
      data: {{position: 0.035, max_effort: 10.0}}}}
  - {{t: 14.5, topic: arm/gripper_controller/gripper_cmd, type: control_msgs/msg/GripperCommand,
      data: {{position: 0.002, max_effort: 10.0}}}}
"""
    )
    return path


def _positions(states: list[tuple[int, Any]], names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """(times s, positions [n, joints]) of `names` in JointState messages."""
    order = list(states[0][1].name)
    idx = [order.index(n) for n in names]
    t = np.array([s / 1e9 for s, _ in states])
    q = np.array([[float(m.position[i]) for i in idx] for _, m in states])
    return t, q


def test_world_rooted_arm_holds_follows_a_trajectory_and_grips(tmp_path: Path) -> None:
    world, bus = simulate(_scenario(tmp_path))
    robot = world.plan.robots[0]
    assert robot.fixed and robot.root == "base_link"  # welded by its `world` root link, no `fixed:`

    states = messages(bus, "/arm/joint_states")
    t, q = _positions(states, [*ARM, "jaw_joint", "jaw_right_joint"])
    start = np.array([0.0, 0.2, 0.4, 0.0])  # the <ros2_control> initial_values (pan, wrist: 0)
    held = q[t < 10.0, :4]
    assert len(held) > 900
    drift = np.abs(held - start).max()
    assert drift <= 0.005, f"the arm drifted {drift:.4f} rad from its initial_values in 10 s"

    # the trajectory: final error, and the path within the controller's tolerance (0.1 rad each joint)
    goal = np.array([1.0, -0.7, 1.2, -0.2])  # pan, shoulder, elbow, wrist (sent in another order)
    final = q[(t > 12.8) & (t < 13.0), :4]
    assert np.abs(final - goal).max() <= 0.01, f"final error {np.abs(final - goal).max(axis=0)}"
    ctrl = messages(bus, "/arm/arm_controller/controller_state")
    during = [m for s, m in ctrl if 10.0 < s / 1e9 < 12.5]
    assert during, "no controller_state during the trajectory"
    path_error = max(float(np.abs(np.asarray(m.error.positions)).max()) for m in during)
    assert path_error < 0.1, f"path error {path_error:.4f} rad beyond the 0.1 rad trajectory tolerance"
    moved = max(float(np.abs(np.asarray(m.reference.positions) - start[[0, 1, 2, 3]]).max()) for m in during)
    assert moved > 0.5  # the reference did travel: the check above is about a moving arm

    # the gripper opens and closes; its mimic twin follows it within a millimetre all along
    opened = q[(t > 14.2) & (t < 14.5), 4]
    closed = q[t > 15.7, 4]
    assert np.all(np.abs(opened - 0.035) < 0.003), opened
    assert np.all(np.abs(closed - 0.002) < 0.003), closed
    assert np.abs(q[:, 5] - q[:, 4]).max() < 0.001
    assert not any(math.isnan(v) for v in q.ravel())
