"""gazebo_plugins' Range publishers as public robots declare them: ROS 1 `libgazebo_ros_range.so` (sonar and
IR) and ROS 2 `libgazebo_ros_ray_sensor.so` with each `<output_type>`. Inline URDFs, real compile, the world
stepped in-process (real MuJoCo): topics, types, rates, frames, fields, and the range against a wall at a
known distance."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from runner.plan import RunPlan
from tests.helpers import compile_with_notices, declared, messages, robot_scenario, simulate

ROBOT = """<?xml version="1.0"?>
<robot name="t">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  EXTRA
</robot>
"""

# the wall's face is at x = 3.0; a sensor 0.15 m ahead of the base's centre sees it 2.85 m away
WALL = "  models:\n    - {name: wall, shape: box, size: [0.2, 4.0, 6.0], pose: {xyz: [3.1, 0, 1.0]}}\n"


def _sensor(name: str, yaw: float, plugin: str, rate: float = 50.0, vertical: bool = True) -> str:
    """A sonar link 0.15 m from the centre at `yaw`, 0.5 m up, its ray sensor a 3x3 cone of ±0.1 rad."""
    v = (
        "<vertical><samples>3</samples><min_angle>-0.1</min_angle><max_angle>0.1</max_angle></vertical>"
        if vertical
        else ""
    )
    return f"""
  <link name="{name}_link">
    <inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial>
  </link>
  <joint name="{name}_joint" type="fixed"><parent link="base_link"/><child link="{name}_link"/>
    <origin xyz="{0.15 * math.cos(yaw):.6f} {0.15 * math.sin(yaw):.6f} 0.5" rpy="0 0 {yaw}"/></joint>
  <gazebo reference="{name}_link">
    <sensor type="ray" name="{name}">
      <update_rate>{rate}</update_rate>
      <ray>
        <scan>
          <horizontal><samples>3</samples><min_angle>-0.1</min_angle><max_angle>0.1</max_angle></horizontal>
          {v}
        </scan>
        <range><min>0.02</min><max>4.0</max><resolution>0.01</resolution></range>
      </ray>
      {plugin}
    </sensor>
  </gazebo>"""


def _ros1(name: str, extra: str = "") -> str:
    return f"""<plugin name="{name}_plugin" filename="libgazebo_ros_range.so">
        <robotNamespace>/</robotNamespace>
        <topicName>sonar/{name}</topicName>
        <frameName>{name}_link</frameName>
        {extra}
      </plugin>"""


def _write(tmp_path: Path, extra: str, duration: float = 2.0, world: str = WALL) -> Path:
    return robot_scenario(tmp_path, ROBOT.replace("EXTRA", extra), duration=duration, world=world)


def _topics(plan: RunPlan) -> dict[str, str]:
    return {
        t.key.removeprefix("g/bot/"): t.type
        for plugin in declared(plan.robots[0])
        for t in plugin.topics
        if t.key.startswith("g/bot/")
    }


def test_ros1_gazebo_ros_range_sonar_and_ir(tmp_path: Path):
    """Two sonars (front at the wall, back at nothing) and an IR: one Range each, nothing else."""
    front = _sensor(
        "front",
        0.0,
        _ros1(
            "front",
            "<radiation>ultrasound</radiation><fov>0.5</fov><updateRate>20</updateRate>"
            "<gaussianNoise>0.01</gaussianNoise>",
        ),
    )
    back = _sensor("back", math.pi, _ros1("back", "<radiation>ultrasound</radiation>"))
    ir = _sensor("ir", 0.0, _ros1("ir", "<radiation>infrared</radiation><fov>0.02</fov>"), vertical=False)
    path = _write(tmp_path, front + back + ir, duration=5.0)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices and "is ignored" not in notices, notices
    # only the Ranges: no LaserScan, no points (gazebo_ros_range publishes one topic)
    assert _topics(plan) == {
        "sonar/front": "sensor_msgs/msg/Range",
        "sonar/back": "sensor_msgs/msg/Range",
        "sonar/ir": "sensor_msgs/msg/Range",
    }
    rates = {t.key.removeprefix("g/bot/"): t.rate for p in declared(plan.robots[0]) for t in p.topics}
    assert rates["sonar/front"] == 50 / 3  # <updateRate> 20 throttles the sensor's 50 Hz: every 3rd
    assert rates["sonar/back"] == 50.0  # no <updateRate>: every sensor update
    _, bus = simulate(path)
    f = messages(bus, "bot/sonar/front")
    assert abs(len(f) - 5.0 * 50 / 3) <= 1
    msg = f[-1][1]
    assert msg.header.frame_id == "bot/front_link"
    assert msg.radiation_type == 0 and abs(msg.field_of_view - 0.5) < 1e-6  # <fov>, not the cone
    assert abs(msg.min_range - 0.02) < 1e-6 and abs(msg.max_range - 4.0) < 1e-6
    ranges = np.array([m.range for _, m in f])
    # the nearest (central) ray: 2.85 m, with the plugin's <gaussianNoise> 0.01 (the sensor's resolution
    # is not applied: the plugin reads the ray shape, not the scan)
    assert abs(ranges.mean() - 2.85) < 0.004 and abs(ranges.std() / 0.01 - 1) < 0.25
    # nothing behind within 4 m: max_range
    assert {m.range for _, m in messages(bus, "bot/sonar/back")} == {np.float32(4.0)}
    ir_msg = messages(bus, "bot/sonar/ir")[-1][1]
    assert ir_msg.radiation_type == 1 and abs(ir_msg.field_of_view - 0.02) < 1e-6
    assert abs(ir_msg.range - 2.85) < 1e-4  # noise-free


def test_ros1_gazebo_ros_range_defaults(tmp_path: Path):
    """No tags: topic `/range` (under the robot's namespace), frame `/world`, ultrasound, fov 0.05."""
    plugin = '<plugin name="r" filename="libgazebo_ros_range.so"/>'
    path = _write(tmp_path, _sensor("s", 0.0, plugin), duration=0.5)
    plan, _ = compile_with_notices(path)
    assert _topics(plan) == {"range": "sensor_msgs/msg/Range"}
    _, bus = simulate(path)
    msg = messages(bus, "bot/range")[-1][1]
    assert msg.header.frame_id == "world" and msg.radiation_type == 0
    assert abs(msg.field_of_view - 0.05) < 1e-6


def _ros2(name: str, body: str) -> str:
    return f"""<plugin name="{name}" filename="libgazebo_ros_ray_sensor.so">{body}</plugin>"""


def test_ros2_ray_sensor_range_output(tmp_path: Path):
    """`<output_type>sensor_msgs/Range</output_type>`: only a Range on `~/out` (remapped), infrared by
    default, field of view the wider span, +inf when nothing is within range."""
    front = _sensor(
        "front",
        0.0,
        _ros2(
            "front_sonar",
            "<ros><namespace>/</namespace><remapping>~/out:=sonar_front</remapping></ros>"
            "<output_type>sensor_msgs/Range</output_type><radiation_type>ultrasound</radiation_type>"
            "<frame_name>front_link</frame_name>",
        ),
    )
    back = _sensor(
        "back", math.pi, _ros2("back_ir", "<output_type>sensor_msgs/Range</output_type>"), vertical=False
    )
    path = _write(tmp_path, front + back)
    plan, notices = compile_with_notices(path)
    assert "is ignored" not in notices and "LaserScan" not in notices, notices
    assert _topics(plan) == {"sonar_front": "sensor_msgs/msg/Range", "back_ir/out": "sensor_msgs/msg/Range"}
    _, bus = simulate(path)
    f = messages(bus, "bot/sonar_front")
    assert abs(len(f) - 100) <= 1  # the sensor's <update_rate>
    msg = f[-1][1]
    assert msg.header.frame_id == "bot/front_link" and msg.radiation_type == 0
    assert abs(msg.field_of_view - 0.2) < 1e-6
    assert abs(msg.range - 2.85) < 0.006  # the scan's <resolution> 0.01 applies here
    b = messages(bus, "bot/back_ir/out")[-1][1]
    assert b.radiation_type == 1 and b.header.frame_id == "bot/back_link"
    assert b.range == math.inf  # REP 117: nothing within max_range
    assert abs(b.field_of_view - 0.2) < 1e-6  # horizontal 0.2, no vertical span


def test_ros2_ray_sensor_other_outputs(tmp_path: Path):
    """No `<output_type>` is a PointCloud2 on `~/out` (said); LaserScan on `~/out`; a bad one: nothing."""
    a = _sensor("a", 0.0, _ros2("a_ray", ""))
    b = _sensor("b", 0.0, _ros2("b_ray", "<output_type>sensor_msgs/LaserScan</output_type>"))
    c = _sensor("c", 0.0, _ros2("c_ray", "<output_type>sensor_msgs/Bogus</output_type>"))
    path = _write(tmp_path, a + b + c, duration=0.2)
    plan, notices = compile_with_notices(path)
    assert _topics(plan) == {
        "a_ray/out": "sensor_msgs/msg/PointCloud2",
        "b_ray/out": "sensor_msgs/msg/LaserScan",
    }
    assert "has no <output_type>" in notices and "'sensor_msgs/Bogus'" in notices
    _, bus = simulate(path)
    cloud = messages(bus, "bot/a_ray/out")[-1][1]
    assert cloud.height == 1 and cloud.width == 9  # every ray meets the wall: 3 x 3 points


def test_ros1_gazebo_ros_range_needs_a_cpu_ray_sensor(tmp_path: Path):
    """On a gpu_ray sensor Gazebo refuses the plugin: nothing is published, as said."""
    extra = _sensor("s", 0.0, _ros1("s")).replace('type="ray"', 'type="gpu_ray"')
    path = _write(tmp_path, extra, duration=0.1)
    plan, notices = compile_with_notices(path)
    assert "needs a sensor of type 'ray'" in notices
    assert _topics(plan) == {}
