"""Third-party force-based planar drives and world-odometry plugins as public descriptions declare them
(hector's and Robotnik's `force_based_move`, its ROS 2 port; gazebo_plugins' p3d, PAL's world odometry,
Robotnik's ground truth): inline URDFs, real compile, the world stepped in-process (real MuJoCo). A base
on frictionless wheels is driven by the plugin's force alone: its velocity follows the P-gain dynamics
the source gives (a first-order lag of time constant m / kp), its odometry is published on the source's
topic, frames and rate; a world-odometry plugin publishes the true pose with its offsets, frame and noise."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from runner.geometry import quat_to_yaw
from tests.helpers import compile_with_notices, declared, messages, robot_scenario, simulate

MASS = 20.0  # the base's mass; the wheels add 4 × 0.5 kg

ROBOT = """<?xml version="1.0"?>
<robot name="fb">
  <link name="base_footprint"/>
  <joint name="footprint_joint" type="fixed"><parent link="base_footprint"/><child link="base_link"/>
    <origin xyz="0 0 0.1"/></joint>
  <link name="base_link">
    <collision><geometry><box size="0.6 0.4 0.1"/></geometry></collision>
    <inertial><mass value="MASS"/><inertia ixx="0.3" ixy="0" ixz="0" iyy="0.6" iyz="0" izz="0.8"/></inertial>
  </link>
  WHEELS
  EXTRA
</robot>
"""


def _wheel(name: str, xyz: str) -> str:
    """A passive wheel; Gazebo's <mu1>/<mu2> 0 make it frictionless, as such robots declare it."""
    return f"""
  <link name="{name}">
    <collision><geometry><sphere radius="0.05"/></geometry></collision>
    <inertial><mass value="0.5"/><inertia ixx="5e-4" ixy="0" ixz="0" iyy="5e-4" iyz="0" izz="5e-4"/></inertial>
  </link>
  <joint name="{name}_joint" type="continuous"><parent link="base_link"/><child link="{name}"/>
    <origin xyz="{xyz}"/><axis xyz="0 1 0"/></joint>
  <gazebo reference="{name}"><mu1>0.0</mu1><mu2>0.0</mu2></gazebo>"""


WHEELS = "".join(
    _wheel(n, xyz)
    for n, xyz in (
        ("fl", "0.2 0.2 -0.05"),
        ("fr", "0.2 -0.2 -0.05"),
        ("rl", "-0.2 0.2 -0.05"),
        ("rr", "-0.2 -0.2 -0.05"),
    )
)

HECTOR = """
  <gazebo>
    <plugin name="base_controller" filename="libgazebo_ros_force_based_move.so">
      <commandTopic>base/cmd_vel</commandTopic>
      <odometryTopic>base/odom</odometryTopic>
      <odometryFrame>odom</odometryFrame>
      <odometryRate>25.0</odometryRate>
      <robotBaseFrame>base_footprint</robotBaseFrame>
      <publishOdometryTf>true</publishOdometryTf>
      <x_velocity_p_gain>KP</x_velocity_p_gain>
      <y_velocity_p_gain>KP</y_velocity_p_gain>
      <yaw_velocity_p_gain>KYAW</yaw_velocity_p_gain>
    </plugin>
  </gazebo>"""


def _write(tmp_path: Path, extra: str, duration: float, timeline: str = "", name: str = "fb") -> Path:
    urdf = ROBOT.replace("MASS", str(MASS)).replace("WHEELS", WHEELS).replace("EXTRA", extra)
    return robot_scenario(
        tmp_path,
        urdf,
        name=name,
        duration=duration,
        xyz=(0.0, 0.0, 0.0),
        plugins="[{type: ground_truth, params: {rate: 500, topic: truth}}]",
        timeline=timeline,
    )


def _cmd(t: float, topic: str, x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> str:
    return (
        f"  - {{t: {t}, topic: bot/{topic}, type: geometry_msgs/msg/Twist, "
        f"data: {{linear: {{x: {x}, y: {y}}}, angular: {{z: {yaw}}}}}}}\n"
    )


def _truth(bus: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, [x, y, yaw], body-frame [vx, vy, wz]) of the base from the scenario's own ground_truth."""
    samples = messages(bus, "bot/truth")
    t = np.array([s / 1e9 for s, _ in samples])
    pose, vel = [], []
    for _, m in samples:
        q = m.pose.pose.orientation
        yaw = quat_to_yaw([q.w, q.x, q.y, q.z])
        v = m.twist.twist.linear
        c, s = math.cos(yaw), math.sin(yaw)
        pose.append([m.pose.pose.position.x, m.pose.pose.position.y, yaw])
        vel.append([c * v.x + s * v.y, -s * v.x + c * v.y, m.twist.twist.angular.z])
    return t, np.array(pose), np.array(vel)


def test_hector_force_based_move_follows_its_p_gain_dynamics(tmp_path: Path):
    """kp 200 N/(m/s) on a 22 kg base: 0.4 m/s is reached as 0.4·(1 - exp(-t/τ)), τ = m / kp = 0.11 s,
    on wheels Gazebo makes frictionless; the odometry integrates the base's velocity at 25 Hz on the
    plugin's topic, in its frames, with the plugin's covariances."""
    kp, kyaw = 200.0, 20.0
    extra = HECTOR.replace("KYAW", str(kyaw)).replace("KP", str(kp))
    timeline = (
        _cmd(0.5, "base/cmd_vel", x=0.4) + _cmd(2.5, "base/cmd_vel", y=-0.3) + _cmd(4.0, "base/cmd_vel")
    )
    path = _write(tmp_path, extra, duration=4.5, timeline=timeline)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    (drive,) = [p for p in plan.robots[0].plugins if p.type == "force_based_move"]
    assert list(drive.params["p_gains"]) == [kp, kp, kyaw] and drive.rate == 25.0
    topics = {t.key.removeprefix("g/bot/"): t.type for p in declared(plan.robots[0]) for t in p.topics}
    assert topics["base/cmd_vel"] == "geometry_msgs/msg/Twist"
    assert topics["base/odom"] == "nav_msgs/msg/Odometry"
    _, bus = simulate(path)
    t, pose, vel = _truth(bus)
    mass = MASS + 4 * 0.5
    tau = mass / kp
    # the lag: the speed at 1 τ, 2 τ and 3 τ after the command, against 1 - exp(-t/τ)
    for k in (1.0, 2.0, 3.0):
        i = int(np.argmin(abs(t - (0.5 + k * tau))))
        expected = 0.4 * (1 - math.exp(-(t[i] - 0.5) / tau))
        assert abs(vel[i, 0] - expected) < 0.03, (k, vel[i, 0], expected)
    cruising = (t > 1.5) & (t < 2.5)
    assert np.allclose(vel[cruising, 0], 0.4, atol=0.01) and np.allclose(vel[cruising, 1], 0.0, atol=0.01)
    sideways = (t > 3.3) & (t < 4.0)
    assert np.allclose(vel[sideways, 1], -0.3, atol=0.01) and np.allclose(vel[sideways, 0], 0.0, atol=0.01)
    assert abs(pose[-1, 2]) < 0.02  # the yaw P gain holds the heading
    odom = messages(bus, "bot/base/odom")
    assert abs(len(odom) - 4.5 * 25) <= 1  # <odometryRate> 25
    first = odom[0][1]
    assert first.header.frame_id == "bot/odom" and first.child_frame_id == "bot/base_footprint"
    assert first.pose.covariance[0] == 0.001 and first.pose.covariance[14] == 1e12
    assert first.pose.covariance[35] == 0.01  # not turning
    # dead reckoning from the identity: the base's velocity at each publish times the time since the last
    # one (hector's rectangle rule; it runs ahead of the true travel while the base accelerates)
    stamps = np.array([s / 1e9 for s, _ in odom])
    at = [int(np.argmin(abs(t - s))) for s in stamps]
    expected = np.cumsum(vel[at, :2] * np.diff(stamps, prepend=0.0)[:, None], axis=0)
    got = np.array([[m.pose.pose.position.x, m.pose.pose.position.y] for _, m in odom])
    assert np.allclose(got, expected, atol=1e-3)
    assert np.allclose(got[-1], pose[at[-1], :2] - pose[0, :2], atol=0.01)  # and near the true travel
    assert np.allclose([m.twist.twist.linear.x for _, m in odom], vel[at, 0], atol=1e-6)
    tf = [m for _, m in messages(bus, "bot/tf") if m.transforms[0].child_frame_id == "bot/base_footprint"]
    assert len(tf) == len(odom) and tf[0].transforms[0].header.frame_id == "bot/odom"
