"""Gazebo tags as third-party robots write them (sam_bot, articubot, TurtleBot3, husky): camera topic names of
the ROS 1 and ROS 2 camera plugins, plugin update rates, IMU noise bias and gaussianNoise, and friction in
the `<mu1 value=".."/>` form. Real compile, world stepped in-process (real MuJoCo, offscreen rendering)."""

from __future__ import annotations

import os

# MuJoCo picks its GL backend when it is first imported: headless EGL unless the user chose one.
os.environ.setdefault("MUJOCO_GL", "egl")

from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from runner.plan import RunPlan
from runner.wire.transport import MemoryBus
from tests.helpers import compile_with_notices, declared, messages, robot_scenario, simulate

IMAGE, INFO, POINTS = "sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo", "sensor_msgs/msg/PointCloud2"

ROBOT = """<?xml version="1.0"?>
<robot name="t">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <link name="cam_link">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
  </link>
  <joint name="cam_joint" type="fixed"><parent link="base_link"/><child link="cam_link"/>
    <origin xyz="0.15 0 0.1"/></joint>
  <link name="imu_link">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
  </link>
  <joint name="imu_joint" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>
  EXTRA
</robot>
"""


def _sensor(name: str, kind: str, plugin: str, rate: float | None = None) -> str:
    """A tiny camera or depth camera on cam_link with its ROS plugin."""
    update = f"<update_rate>{rate}</update_rate>" if rate else ""
    return f"""
  <gazebo reference="cam_link">
    <sensor name="{name}" type="{kind}">{update}
      <camera><horizontal_fov>1.0</horizontal_fov><image><width>16</width><height>12</height></image>
        <clip><near>0.05</near><far>10</far></clip></camera>
      {plugin}
    </sensor>
  </gazebo>"""


def _write(
    tmp_path: Path,
    extra: str,
    duration: float = 0.5,
    seed: int = 1,
    gravity: str = "",
    plugins: str = "[]",
    name: str = "t",
) -> Path:
    """ROBOT with `extra` tags as <name>.urdf, and a scenario that runs it (its path)."""
    return robot_scenario(
        tmp_path,
        ROBOT.replace("EXTRA", extra),
        name=name,
        seed=seed,
        duration=duration,
        world=f"  physics: {{gravity: {gravity}}}" if gravity else "",
        plugins=plugins,
    )


def _camera_topics(plan: RunPlan) -> dict[str, str]:
    """Relative key -> type of what the robot's cameras publish."""
    cams = {t.key.removeprefix("g/bot/"): t.type for t in plan.topics() if t.type in (IMAGE, INFO, POINTS)}
    return cams


ROS2_CAMERAS = (
    # articubot: a ROS 2 camera plugin with only <frame_name>: topics under the sensor's name
    _sensor(
        "front_cam",
        "camera",
        '<plugin name="c" filename="libgazebo_ros_camera.so"><frame_name>cam_link</frame_name></plugin>',
        10,
    )
    # sam_bot: a depth sensor; a remapping names the whole topic (as ROS 2 matches it); ROS 1 leftovers
    + _sensor(
        "depth_camera",
        "depth",
        """<plugin name="d" filename="libgazebo_ros_camera.so">
        <ros><namespace>/demo</namespace><remapping>depth_camera/points:=cloud</remapping></ros>
        <updateRate>0.0</updateRate><pointCloudCutoff>0.5</pointCloudCutoff><hackBaseline>0</hackBaseline>
        <frame_name>cam_link</frame_name></plugin>""",
        10,
    )
    # <camera_name> instead of the sensor's; a bare `image_raw:=` rule matches none of its topics
    + _sensor(
        "named",
        "camera",
        """<plugin name="n" filename="libgazebo_ros_camera.so"><camera_name>custom</camera_name>
        <ros><remapping>image_raw:=ignored</remapping><remapping>custom/camera_info:=custom/info</remapping></ros>
        </plugin>""",
        10,
    )
)


@pytest.mark.timeout(120)
def test_ros2_camera_topics_are_named_after_the_camera_name(tmp_path: Path):
    plan, notes = compile_with_notices(_write(tmp_path, ROS2_CAMERAS))
    assert _camera_topics(plan) == {
        "front_cam/image_raw": IMAGE,
        "front_cam/camera_info": INFO,
        "depth_camera/image_raw": IMAGE,
        "depth_camera/camera_info": INFO,
        "depth_camera/depth/image_raw": IMAGE,
        "depth_camera/depth/camera_info": INFO,
        "cloud": POINTS,
        "custom/image_raw": IMAGE,
        "custom/info": INFO,
    }
    assert "remapping image_raw:=ignored matches none of this camera's topics" in notes
    assert "<pointCloudCutoff> is a ROS 1 parameter" in notes
    assert "hackBaseline" not in notes and "updateRate" not in notes  # zero: they change nothing
    _, bus = simulate(_write(tmp_path, ROS2_CAMERAS))
    for topic in ("front_cam/image_raw", "depth_camera/depth/image_raw", "cloud", "custom/info"):
        assert len(messages(bus, f"bot/{topic}")) in (5, 6), topic
    info = messages(bus, "bot/depth_camera/depth/camera_info")
    assert len(info) in (5, 6) and info[-1][1].width == 16 and info[-1][1].header.frame_id == "bot/cam_link"
    depth = messages(bus, "bot/depth_camera/depth/image_raw")[-1][1]
    assert depth.encoding == "32FC1" and (depth.width, depth.height) == (16, 12)


ROS1_CAMERAS = (
    # classic camera: <cameraName> prefixes relative names; an absolute one is not under it
    _sensor(
        "cam1",
        "camera",
        """<plugin name="c" filename="libgazebo_ros_camera.so"><cameraName>left</cameraName>
        <imageTopicName>image_rect</imageTopicName><cameraInfoTopicName>/left_info</cameraInfoTopicName>
        <frameName>cam_link</frameName></plugin>""",
        10,
    )
    # TurtleBot3 R200 / husky realsense: openni_kinect with every topic named
    + _sensor(
        "kinect",
        "depth",
        """<plugin name="k" filename="libgazebo_ros_openni_kinect.so"><cameraName>camera</cameraName>
        <imageTopicName>rgb/image_raw</imageTopicName><cameraInfoTopicName>rgb/camera_info</cameraInfoTopicName>
        <depthImageTopicName>depth/image_raw</depthImageTopicName>
        <depthImageCameraInfoTopicName>depth/info</depthImageCameraInfoTopicName>
        <pointCloudTopicName>depth/points</pointCloudTopicName>
        <depthImageInfoTopicName>typo/camera_info</depthImageInfoTopicName>
        <frameName>cam_link</frameName></plugin>""",
        10,
    )
    # ROS 1 with no <cameraName>: its defaults, at the robot's namespace
    + _sensor(
        "bare",
        "camera",
        '<plugin name="b" filename="libgazebo_ros_camera.so"><updateRate>0.0</updateRate></plugin>',
        10,
    )
)


@pytest.mark.timeout(120)
def test_ros1_camera_and_openni_topics(tmp_path: Path):
    plan, notes = compile_with_notices(_write(tmp_path, ROS1_CAMERAS))
    assert _camera_topics(plan) == {
        "left/image_rect": IMAGE,
        "left_info": INFO,
        "camera/rgb/image_raw": IMAGE,
        "camera/rgb/camera_info": INFO,
        "camera/depth/image_raw": IMAGE,
        "camera/depth/info": INFO,
        "camera/depth/points": POINTS,
        "image_raw": IMAGE,
        "camera_info": INFO,
    }
    assert "depthImageCameraInfoTopicName" not in notes  # read, and honoured
    assert "<depthImageInfoTopicName> is not a parameter of 'libgazebo_ros_openni_kinect.so'" in notes
    _, bus = simulate(_write(tmp_path, ROS1_CAMERAS))
    info = messages(bus, "bot/camera/depth/info")
    assert len(info) in (5, 6) and (info[-1][1].width, info[-1][1].height) == (16, 12)
    assert len(messages(bus, "bot/left_info")) in (5, 6)
    assert len(messages(bus, "bot/camera/depth/points")) in (5, 6)


RATES = (
    # TurtleBot3 R200: no sensor rate (Gazebo: as fast as it can), the plugin's <updateRate> 30
    _sensor(
        "r200",
        "depth",
        """<plugin name="k" filename="libgazebo_ros_openni_kinect.so"><cameraName>r200</cameraName>
        <updateRate>30.0</updateRate></plugin>""",
    )
    # both: the plugin throttles the sensor's frames, every ceil(30 / 10)-th and ceil(30 / 20)-th
    + _sensor(
        "slow",
        "camera",
        """<plugin name="s" filename="libgazebo_ros_camera.so"><cameraName>slow</cameraName>
        <updateRate>10</updateRate></plugin>""",
        30,
    )
    + _sensor(
        "odd",
        "camera",
        """<plugin name="o" filename="libgazebo_ros_camera.so"><cameraName>odd</cameraName>
        <updateRate>20</updateRate></plugin>""",
        30,
    )
    # the ROS 2 plugin has no <updateRate>: the sensor's rate stands
    + _sensor(
        "ros2",
        "camera",
        """<plugin name="r" filename="libgazebo_ros_camera.so"><frame_name>cam_link</frame_name>
        <updateRate>5</updateRate></plugin>""",
        20,
    )
)


@pytest.mark.timeout(120)
def test_plugin_update_rate_throttles_the_sensor(tmp_path: Path):
    plan, notes = compile_with_notices(_write(tmp_path, RATES, duration=1.0))
    rates = {p.name: p.rate for p in declared(plan.robots[0])}
    assert rates == {"r200": 30, "slow": 10, "odd": 15, "ros2": 20}
    assert "<updateRate> is not read by 'libgazebo_ros_camera.so' (ROS 2)" in notes
    _, bus = simulate(_write(tmp_path, RATES, duration=1.0))
    for topic, rate in (
        ("r200/depth/image_raw", 30),
        ("r200/image_raw", 30),
        ("slow/image_raw", 10),
        ("odd/image_raw", 15),
        ("ros2/image_raw", 20),
    ):
        assert abs(len(messages(bus, f"bot/{topic}")) - rate) <= 1, topic


def _imu_noise(block: str, mean: float, stddev: float, bias_mean: float, bias_stddev: float) -> str:
    noise = (
        f'<noise type="gaussian"><mean>{mean}</mean><stddev>{stddev}</stddev>'
        f"<bias_mean>{bias_mean}</bias_mean><bias_stddev>{bias_stddev}</bias_stddev></noise>"
    )
    return f"<{block}>" + "".join(f"<{a}>{noise}</{a}>" for a in "xyz") + f"</{block}>"


# sam_bot's IMU, with biases large enough to measure, on a robot welded in place without gravity (exact
# readings: zero): a gyro bias of +-0.5 rad/s per axis, a constant accelerometer offset of 0.2 (<mean>)
# plus a bias of +-0.3 m/s².
BIASED_IMU = f"""
  <gazebo><static>true</static></gazebo>
  <gazebo reference="imu_link">
    <sensor name="imu_sensor" type="imu">
      <update_rate>100</update_rate>
      <plugin filename="libgazebo_ros_imu_sensor.so" name="imu_plugin">
        <ros><namespace>/demo</namespace><remapping>~/out:=imu</remapping></ros>
        <initial_orientation_as_reference>false</initial_orientation_as_reference>
      </plugin>
      <imu>{_imu_noise("angular_velocity", 0.0, 0.0, 0.5, 0.01)}{_imu_noise("linear_acceleration", 0.2, 0.0, 0.3, 0.0)}</imu>
    </sensor>
  </gazebo>"""


def _readings(bus: MemoryBus, topic: str, field: Callable[[Any], Any]) -> np.ndarray:
    """x, y, z of a Vector3 field of every message on `topic`, one row each."""
    return np.array([[getattr(field(m), a) for a in "xyz"] for _, m in messages(bus, topic)])


@pytest.mark.timeout(120)
def test_imu_noise_bias_is_drawn_once_with_a_random_sign(tmp_path: Path):
    signs = set()
    for seed in (1, 2, 3):
        _, bus = simulate(_write(tmp_path, BIASED_IMU, duration=0.2, seed=seed, gravity="[0, 0, 0]"))
        gyro = _readings(bus, "bot/imu", lambda m: m.angular_velocity)
        accel = _readings(bus, "bot/imu", lambda m: m.linear_acceleration)
        assert len(gyro) == 21
        assert np.ptp(gyro, axis=0).max() < 1e-9 and np.ptp(accel, axis=0).max() < 1e-9  # fixed for the run
        assert np.all(np.abs(np.abs(gyro[0]) - 0.5) < 0.05), gyro[0]  # N(0.5, 0.01), either sign
        bias = accel[0]
        assert np.allclose(np.abs(bias - 0.2), 0.3, atol=2e-3), bias  # mean 0.2 + (+-0.3)
        signs |= set(np.sign(gyro[0])) | set(np.sign(bias - 0.2))
    assert signs == {-1.0, 1.0}


# TurtleBot3's libgazebo_ros_imu (a model plugin) adds only <gaussianNoise>; the <imu> block in it is not
# read (by Gazebo either). A ROS 1 gazebo_ros_imu_sensor adds its <gaussianNoise> to the sensor's noise and
# publishes at <updateRateHZ>.
CLASSIC_IMU = f"""
  <gazebo><static>true</static></gazebo>
  <gazebo>
    <plugin name="imu_plugin" filename="libgazebo_ros_imu.so">
      <bodyName>imu_link</bodyName><topicName>imu_model</topicName><gaussianNoise>0.05</gaussianNoise>
      <updateRate>200</updateRate>
      <imu><noise><type>gaussian</type><rate><mean>0.0</mean><stddev>2e-4</stddev></rate>
        <accel><mean>0.0</mean><stddev>1.7e-2</stddev></accel></noise></imu>
    </plugin>
  </gazebo>
  <gazebo reference="imu_link">
    <sensor name="imu_sensor" type="imu">
      <update_rate>200</update_rate>
      <imu>{_imu_noise("angular_velocity", 0.0, 0.03, 0.0, 0.0)}</imu>
      <plugin filename="libgazebo_ros_imu_sensor.so" name="imu_sensor_plugin">
        <topicName>imu_sensor</topicName><frameName>imu_link</frameName><updateRateHZ>50</updateRateHZ>
        <gaussianNoise>0.04</gaussianNoise>
      </plugin>
    </sensor>
  </gazebo>"""


@pytest.mark.timeout(120)
def test_classic_imu_gaussian_noise(tmp_path: Path):
    path = _write(tmp_path, CLASSIC_IMU, duration=2.0, gravity="[0, 0, 0]")  # welded, no gravity: readings 0
    plan, notes = compile_with_notices(path)
    assert "<imu> is not a parameter of 'libgazebo_ros_imu.so': Gazebo ignores it too" in notes
    assert {p.name: p.rate for p in declared(plan.robots[0])} == {"imu_plugin": 200, "imu_sensor": 50}
    _, bus = simulate(path)
    model = _readings(bus, "bot/imu_model", lambda m: m.angular_velocity)
    assert len(model) == 401
    assert abs(model.std() - 0.05) < 0.005, model.std()  # <gaussianNoise>, not the <imu> block's 2e-4
    accel = _readings(bus, "bot/imu_model", lambda m: m.linear_acceleration)
    assert abs(accel.std() - 0.05) < 0.005, accel.std()
    sensor = _readings(bus, "bot/imu_sensor", lambda m: m.angular_velocity)
    assert len(sensor) == 101
    assert abs(sensor.std() - 0.05) < 0.0075, sensor.std()  # hypot(0.03, 0.04)


# articubot's caster: friction in the value-attribute form. Gravity tilted 2 m/s² along x: a box with
# mu 0.05 slides (a = 2 - 0.05 g = 1.5 m/s²), one with the default mu 1 stays.
SLIPPERY = """
  <gazebo reference="base_link">
    <mu1 value="0.05"/>
    <mu2 value="0.05"/>
    <kp value="100000.0"/>
    <kd value="1.0"/>
    <material value="Gazebo/Blue"/>
  </gazebo>"""


@pytest.mark.timeout(120)
def test_friction_in_value_attributes(tmp_path: Path):
    path = _write(tmp_path, SLIPPERY, duration=1.0, gravity="[2.0, 0, -9.81]")
    plan, notes = compile_with_notices(path)
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    base = model.body("bot/base_link").id
    geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == base and model.geom_contype[g]]
    assert geoms and all(model.geom_friction[g][0] == pytest.approx(0.05) for g in geoms)
    default_solref = mujoco.MjModel.from_xml_string("<mujoco/>").opt.o_solref
    assert all(not np.allclose(model.geom_solref[g], default_solref) for g in geoms)  # <kp> read
    assert '<kd> in <gazebo reference="base_link"> is ignored' in notes
    rgba = {tuple(model.geom_rgba[g]) for g in range(model.ngeom) if model.geom_bodyid[g] == base}
    assert rgba and all(c[2] > 0.5 and c[0] < 0.5 for c in rgba), rgba  # Gazebo/Blue

    truth = "[{type: ground_truth, params: {rate: 10}}]"
    for extra, name, low, high in ((SLIPPERY, "slippery", 0.5, 0.9), ("", "grippy", -0.02, 0.02)):
        _, bus = simulate(_write(tmp_path, extra, 1.0, gravity="[2.0, 0, -9.81]", plugins=truth, name=name))
        x = messages(bus, "bot/ground_truth")[-1][1].pose.pose.position.x
        assert low < x < high, (name, x)  # slippery: 0.75 m at 1.5 m/s² for 1 s
