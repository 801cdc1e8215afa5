"""Cameras rendered by MuJoCo offscreen (EGL on the CPU here): what they see, their intrinsics, depth."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.helpers import messages, simulate

SCENE = """
name: cam
duration: {duration}
rate: max
world:
  ground: {{rgba: [0.1, 0.6, 0.1, 1]}}
  models:
    - {{name: red_box, shape: box, size: [0.5, 1.0, 1.0], pose: {{xyz: [2.25, 0, 0.5]}}, rgba: [1, 0, 0, 1]}}
robots:
  - name: r1
    description: {{file: "{{diffbot}}", args: {{color: "0.1 0.1 0.9 1"}}}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive}}
      - type: camera
        params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 64, height: 48, rate: 10, format: {fmt}}}
      - type: depth_camera
        params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 64, height: 48, rate: 5,
                  image_topic: rgbd/image, info_topic: rgbd/info, depth_topic: rgbd/depth,
                  depth_info_topic: rgbd/depth_info, points_topic: rgbd/points}}
timeline:
  - {{t: {go}, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{angular: {{z: 1.0}}}}}}
"""


@pytest.mark.timeout(60)
def test_camera_sees_the_red_box_ahead_and_the_ground_below(write_scenario):
    _, bus = simulate(write_scenario(SCENE.format(duration=0.5, fmt="rgb8", go=0.5)))
    frames = messages(bus, "r1/camera/image_raw")
    assert len(frames) == 6  # 10 Hz over 0.5 s, t = 0 included
    img = frames[-1][1]
    assert (img.width, img.height, img.encoding, img.step) == (64, 48, "rgb8", 192)
    px = np.asarray(img.data).reshape(48, 64, 3).astype(int)
    centre = px[20:28, 28:36].reshape(-1, 3)
    assert (centre[:, 0] > 2 * centre[:, 1] + 30).all()  # red
    bottom = px[-3:, :].reshape(-1, 3)
    assert (bottom[:, 0] < np.maximum(bottom[:, 1], bottom[:, 2])).all()  # green ground or our blue chassis
    assert (
        px[:, :4].reshape(-1, 3)[:, 1] > px[:, :4].reshape(-1, 3)[:, 0]
    ).mean() > 0.3  # ground at the side


@pytest.mark.timeout(60)
def test_bgr8_swaps_channels(write_scenario):
    _, bus = simulate(write_scenario(SCENE.format(duration=0.1, fmt="bgr8", go=0.1)))
    img = messages(bus, "r1/camera/image_raw")[-1][1]
    px = np.asarray(img.data).reshape(48, 64, 3).astype(int)
    assert img.encoding == "bgr8"
    assert px[24, 32, 2] > px[24, 32, 0] + 50  # red is the last channel


@pytest.mark.timeout(60)
def test_camera_info_intrinsics_from_fov(write_scenario):
    _, bus = simulate(write_scenario(SCENE.format(duration=0.1, fmt="rgb8", go=0.1)))
    info = messages(bus, "r1/camera/camera_info")[-1][1]
    fx = 64 / (2 * math.tan(1.047 / 2))
    assert np.allclose(info.k, [fx, 0, 32, 0, fx, 24, 0, 0, 1])
    assert info.distortion_model == "plumb_bob" and (info.width, info.height) == (64, 48)
    assert info.header.frame_id == "r1/lidar_link"


@pytest.mark.timeout(60)
def test_depth_reads_the_box_distance_and_points_match(write_scenario):
    _, bus = simulate(write_scenario(SCENE.format(duration=0.4, fmt="rgb8", go=0.4)))
    depth = messages(bus, "r1/rgbd/depth")
    assert len(depth) == 3  # 5 Hz
    d = depth[-1][1]
    assert d.encoding == "32FC1"
    arr = np.frombuffer(np.asarray(d.data).tobytes(), dtype=np.float32).reshape(48, 64)
    # the box face is at x = 2.0; the camera at x = 0.04 (its link is at the base origin)
    assert abs(float(arr[24, 32]) - 1.96) < 0.01
    assert np.isinf(arr[0, 0]) or arr[0, 0] > 1.9  # top corner: the sky, or the box's edge
    cloud = messages(bus, "r1/rgbd/points")[-1][1]
    assert (cloud.height, cloud.width) == (48, 64)
    names = [f.name for f in cloud.fields]
    assert names[:3] == ["x", "y", "z"]
    step = cloud.point_step
    raw = np.frombuffer(np.asarray(cloud.data).tobytes(), dtype=np.uint8).reshape(48 * 64, step)
    centre = raw[24 * 64 + 32]
    z = np.frombuffer(centre[8:12].tobytes(), dtype=np.float32)[0]
    assert abs(float(z) - float(arr[24, 32])) < 1e-4
    assert messages(bus, "r1/rgbd/image")  # colour too


@pytest.mark.timeout(60)
def test_images_change_when_the_robot_turns(write_scenario):
    _, bus = simulate(write_scenario(SCENE.format(duration=1.5, fmt="rgb8", go=0.2)))
    frames = dict(messages(bus, "r1/camera/image_raw"))
    first, last = frames[0], frames[1_500_000_000]
    a = np.asarray(first.data).reshape(48, 64, 3)
    b = np.asarray(last.data).reshape(48, 64, 3)
    assert np.abs(a.astype(int) - b.astype(int)).mean() > 10  # turned ~1.3 rad: the box left the view
