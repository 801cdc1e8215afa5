"""Acceptance run: the unmodified TurtleBot3 burger description from ../shared (skipped, with the reason
shown, when ../shared is not beside the checkout; the project itself never needs it)."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from runner.geometry import quat_to_yaw
from tests.conftest import REPO, read_mcap, run_cli

TB3 = REPO.parent / "shared" / "robots" / "turtlebot3_description"

pytestmark = pytest.mark.skipif(not TB3.is_dir(), reason=f"{TB3} is not present (acceptance data only)")


@pytest.mark.timeout(120)
def test_turtlebot3_burger_runs_unmodified(tmp_path: Path):
    scenario = tmp_path / "turtlebot3.yaml"
    scenario.write_text(
        f"""
name: tb3_world
duration: 10.0
rate: max
packages: {{turtlebot3_description: {TB3}}}
world:
  models:
    - {{name: wall, shape: box, size: [0.1, 4, 0.5], pose: {{xyz: [2.0, 0, 0.25]}}}}
robots:
  - name: tb3
    description: {TB3 / "urdf" / "turtlebot3_burger.urdf.xacro"}
    pose: {{xyz: [0, 0, 0.01]}}
timeline:
  - {{t: 0.5, topic: tb3/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.2}}}}}}
  - {{t: 3.0, topic: tb3/cmd_vel, type: geometry_msgs/msg/Twist, data: {{angular: {{z: 0.5}}}}}}
  - {{t: 6.1416, topic: tb3/cmd_vel, type: geometry_msgs/msg/Twist, data: {{}}}}
"""
    )
    mcap = tmp_path / "tb3.mcap"
    proc = run_cli("run", str(scenario), "--record", str(mcap), timeout=100)
    assert proc.returncode == 0, proc.stderr
    messages = read_mcap(mcap)
    counts = Counter(topic for topic, _, _, _ in messages)
    # declared rates: laser 5 Hz, diff drive (odom, tf, wheel joint states) 30 Hz, imu plugin (0 = every
    # step in Gazebo) at our default 100 Hz; `tf` also carries robot_state_publisher's wheels (30 Hz)
    for topic, rate in (("scan", 5), ("odom", 30), ("tf", 60), ("joint_states", 30), ("imu", 100)):
        n = counts[f"tb3_world/tb3/{topic}"]
        assert abs(n - 10 * rate) <= 0.05 * 10 * rate + 1, (topic, n)
    last = {topic: m for topic, _, _, m in messages}
    scan = last["tb3_world/tb3/scan"]
    assert len(scan.ranges) == 360 and math.isclose(scan.range_min, 0.12, abs_tol=1e-6)
    assert math.isclose(scan.range_max, 3.5, abs_tol=1e-6)
    assert scan.header.frame_id == "tb3/base_scan"
    ranges = np.asarray(scan.ranges)
    assert np.isfinite(ranges).any()  # the wall is in view
    js = last["tb3_world/tb3/joint_states"]
    assert list(js.name) == ["wheel_left_joint", "wheel_right_joint"]
    odom = last["tb3_world/tb3/odom"].pose.pose
    assert abs(odom.position.x - 0.5) < 0.05, odom.position  # 0.2 m/s for 2.5 s
    yaw = quat_to_yaw([odom.orientation.w, odom.orientation.x, odom.orientation.y, odom.orientation.z])
    assert abs(yaw - math.pi / 2) < 0.1 * math.pi / 2, yaw  # 0.5 rad/s for pi s
    assert last["tb3_world/tb3/odom"].child_frame_id == "tb3/base_footprint"
