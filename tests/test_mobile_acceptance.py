"""Issue 36's mobile acceptance, all in one robot as public ones combine them: a diff drive whose
`<ros2_control>` gives its wheels velocity interfaces, whose control plugin remaps the controller's command
topic onto `cmd_vel` (`<ros><remapping>`), and whose controllers file is in the spawner's `--param-file`
layout (no `controller_manager:` list; `type:` in each controller's own parameters) with its `/**:` key
written twice. It drives and turns as its controller is commanded on the remapped topic, and publishes its
controllers' topics. (The heavy skid steer without effort limits: tests/test_mobile_controllers.py.)"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bench.mobile import CASTER, base, simulate, stream, truth, wheel, yaw
from tests.helpers import compile_with_notices, messages

URDF = """<?xml version="1.0"?>
<robot name="diffbot">{base}{wheels}{caster}
  <ros2_control name="Base" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    <joint name="left_wheel_joint"><command_interface name="velocity"/><state_interface name="position"/><state_interface name="velocity"/></joint>
    <joint name="right_wheel_joint"><command_interface name="velocity"/><state_interface name="position"/><state_interface name="velocity"/></joint>
  </ros2_control>
  <gazebo>
    <plugin filename="libgz_ros2_control-system.so" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>{yaml}</parameters>
      <ros><remapping>base_controller/cmd_vel:=cmd_vel</remapping></ros>
    </plugin>
  </gazebo>
</robot>
"""

# the spawner's layout, and `/**:` twice (PyYAML alone would keep only the second block: no broadcaster)
CONTROLLERS = """\
/**:
  joint_state_broadcaster:
    ros__parameters:
      type: joint_state_broadcaster/JointStateBroadcaster

/**:
  base_controller:
    ros__parameters:
      type: diff_drive_controller/DiffDriveController
      left_wheel_names: [left_wheel_joint]
      right_wheel_names: [right_wheel_joint]
      wheel_separation: 0.34
      wheel_radius: 0.05
      publish_rate: 50.0
"""

SCENARIO = """
name: t
duration: 8.0
rate: max
seed: 3
robots:
  - name: r1
    description: robot.urdf
    pose: {{xyz: [0, 0, 0.12]}}
    plugins: [{{type: ground_truth, params: {{rate: 100}}}}]
timeline:
{timeline}"""


def _write(tmp_path: Path) -> Path:
    (tmp_path / "control.yaml").write_text(CONTROLLERS)
    wheels = wheel("left_wheel", "0 0.17 -0.05", 0.05, 0.5) + wheel("right_wheel", "0 -0.17 -0.05", 0.05, 0.5)
    (tmp_path / "robot.urdf").write_text(
        URDF.format(
            base=base(5.0, "0.4 0.3 0.1", com=-0.05),
            wheels=wheels,
            caster=CASTER,
            yaml=tmp_path / "control.yaml",
        )
    )
    # Jazzy's diff_drive_controller takes TwistStamped on ~/cmd_vel: 0.2 m/s for 3 s, then 0.5 rad/s for 3 s
    timeline = stream(0.5, 3.5, "cmd_vel", lin=0.2, stamped=True) + stream(
        4.0, 7.0, "cmd_vel", ang=0.5, stamped=True
    )
    path = tmp_path / "scenario.yaml"
    path.write_text(SCENARIO.format(timeline=timeline))
    return path


@pytest.mark.timeout(120)
def test_a_remapped_spawner_layout_diff_drive_with_a_repeated_key_drives_turns_and_publishes(tmp_path: Path):
    path = _write(tmp_path)
    plan, text = compile_with_notices(path)
    keys = {t.key.removeprefix("t/r1/") for p in plan.robots[0].plugins for t in p.topics}
    assert {"cmd_vel", "base_controller/odom", "joint_states", "dynamic_joint_states", "tf"} <= keys, keys
    assert "base_controller/cmd_vel" not in keys  # remapped, as rcl remaps it
    assert "control.yaml:6" in text and "line 1" in text, text  # the repeated key, both lines

    bus = simulate(path)
    t, pose = truth(bus)
    at = lambda s: pose[np.searchsorted(t, s)]  # noqa: E731
    straight = float(np.linalg.norm(at(4.0)[:2] - at(0.4)[:2]))
    turned = float(at(7.9)[2] - at(4.0)[2])
    # the last command of each stream (3.4 s, 6.9 s) holds until cmd_vel_timeout (0.5 s) stops the robot:
    # 0.2 m/s for 3.4 s = 0.68 m, then 0.5 rad/s for 3.4 s = 1.7 rad. The wheels turn exactly that (the
    # encoder odometry below); the body turns 0.93 of it on this swivel caster, the wheels slipping in
    # MuJoCo's soft contacts (measured 1.58 rad; DART's figures for two wheels on a caster, 0.98-1.00, are
    # issue 39's to meet)
    assert 0.64 < straight < 0.70, straight
    assert 1.45 < turned < 1.75, turned
    odom = messages(bus, "r1/base_controller/odom")
    assert len(odom) > 300  # 50 Hz for 8 s
    last = odom[-1][1].pose.pose
    assert abs(float(np.hypot(last.position.x, last.position.y)) - straight) < 0.05  # encoders, straight
    assert abs(yaw(last.orientation) - 1.7) < 0.05  # and turning: the controller did as commanded
    assert len(messages(bus, "r1/joint_states")) > 700  # the broadcaster of the first `/**:` block runs
    assert messages(bus, "r1/dynamic_joint_states")
