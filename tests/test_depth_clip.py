"""Depth limits of the gazebo_ros depth plugins, as Gazebo applies them to the depth image and the point
cloud: ROS 2 gazebo_ros_camera's `<min_depth>`/`<max_depth>` (-inf/+inf) and ROS 1 openni_kinect's
`<pointCloudCutoff>`/`<pointCloudCutoffMax>` (NaN). Real MuJoCo rendering (headless EGL), a wall and the
ground at known distances."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import math
from pathlib import Path

import numpy as np
import pytest

from tests.helpers import compile_with_notices, declared, messages, robot_scenario, simulate

W, H, FOV = 64, 48, 1.047
HEIGHT = 0.55  # the camera above the ground: its link 0.5 above base_link, which rests 0.05 up
WALL = "  models:\n    - {name: wall, shape: box, size: [0.2, 6.0, 6.0], pose: {xyz: [3.1, 0, 1.0]}}\n"


def _camera(name: str, plugin: str) -> str:
    return f"""
  <link name="{name}_link">
    <inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial>
  </link>
  <joint name="{name}_joint" type="fixed"><parent link="base_link"/><child link="{name}_link"/>
    <origin xyz="0.15 0 0.5"/></joint>
  <gazebo reference="{name}_link">
    <sensor type="depth" name="{name}">
      <update_rate>10</update_rate>
      <camera>
        <horizontal_fov>{FOV}</horizontal_fov>
        <image><width>{W}</width><height>{H}</height><format>R8G8B8</format></image>
        <clip><near>0.05</near><far>10</far></clip>
      </camera>
      {plugin}
    </sensor>
  </gazebo>"""


ROBOT = """<?xml version="1.0"?>
<robot name="t">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  EXTRA
</robot>
"""

ROS2 = """<plugin name="cam2_plugin" filename="libgazebo_ros_camera.so">
        <camera_name>cam2</camera_name><frame_name>cam2_link</frame_name>
        <min_depth>1.5</min_depth><max_depth>2.5</max_depth>
      </plugin>"""
ROS1 = """<plugin name="kinect_plugin" filename="libgazebo_ros_openni_kinect.so">
        <cameraName>kinect</cameraName><frameName>kinect_link</frameName>
        <imageTopicName>rgb/image_raw</imageTopicName><depthImageTopicName>depth/image_raw</depthImageTopicName>
        <pointCloudTopicName>depth/points</pointCloudTopicName>
        <pointCloudCutoff>1.5</pointCloudCutoff><pointCloudCutoffMax>2.5</pointCloudCutoffMax>
      </plugin>"""


def _depth(msg) -> np.ndarray:  # type: ignore[no-untyped-def]
    return np.asarray(msg.data, dtype=np.uint8).view("<f4").reshape(msg.height, msg.width)


def _points(msg) -> np.ndarray:  # type: ignore[no-untyped-def]
    n = msg.point_step // 4
    return np.asarray(msg.data, dtype=np.uint8).view("<f4").reshape(msg.height, msg.width, n)[..., :3]


def _ground_depth(row: int) -> float:
    """The ground's depth along the optical axis at a row below the centre (pixel centres)."""
    fy = (W / 2) / math.tan(FOV / 2)
    down = (row + 0.5 - H / 2) / fy  # tan of the angle below the axis
    return HEIGHT / down


@pytest.mark.timeout(120)
def test_ros2_min_max_depth_and_ros1_cutoffs(tmp_path: Path):
    extra = _camera("cam2", ROS2) + _camera("kinect", ROS1)
    path = robot_scenario(tmp_path, ROBOT.replace("EXTRA", extra), duration=0.3, world=WALL)
    plan, notices = compile_with_notices(path)
    assert "not applied" not in notices, notices
    cams = {p.name: p for p in declared(plan.robots[0]) if p.type == "depth_camera"}
    assert cams["cam2"].params["min_depth"] == 1.5 and cams["cam2"].params["out_of_range"] == "inf"
    assert cams["kinect"].params["max_depth"] == 2.5 and cams["kinect"].params["out_of_range"] == "nan"
    _, bus = simulate(path)
    near_row = H - 1  # the ground ~1.3 m ahead: below the min
    mid_row = next(r for r in range(H // 2 + 1, H) if 1.6 < _ground_depth(r) < 2.4)  # within
    assert _ground_depth(near_row) < 1.4
    for topic, points, below, beyond in (
        ("cam2/depth/image_raw", "cam2/points", -np.inf, np.inf),
        ("kinect/depth/image_raw", "kinect/depth/points", np.nan, np.nan),
    ):
        depth = _depth(messages(bus, f"bot/{topic}")[-1][1])
        wall = depth[H // 2 - 2, W // 2]  # the wall, 2.85 m: beyond the max
        near = depth[near_row, W // 2]
        np.testing.assert_equal([wall, near], [beyond, below])
        assert abs(depth[mid_row, W // 2] - _ground_depth(mid_row)) < 0.03
        cloud = _points(messages(bus, f"bot/{points}")[-1][1])
        np.testing.assert_equal(cloud[H // 2 - 2, W // 2], [beyond] * 3)
        np.testing.assert_equal(cloud[near_row, W // 2], [below] * 3)
        assert abs(cloud[mid_row, W // 2, 2] - _ground_depth(mid_row)) < 0.03
