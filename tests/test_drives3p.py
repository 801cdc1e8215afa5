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


def _write(
    tmp_path: Path,
    extra: str,
    duration: float,
    timeline: str = "",
    name: str = "fb",
    link: str = "base_footprint",
) -> Path:
    urdf = ROBOT.replace("MASS", str(MASS)).replace("WHEELS", WHEELS).replace("EXTRA", extra)
    return robot_scenario(
        tmp_path,
        urdf,
        name=name,
        duration=duration,
        xyz=(0.0, 0.0, 0.0),
        plugins=f"[{{type: ground_truth, params: {{rate: 500, topic: truth, link: {link}}}}}]",
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


def test_robotnik_watchdog_stops_and_holds_the_base(tmp_path: Path):
    """Robotnik's fork: hector's drive, and once no command came for <commandWatchdog> s it stops
    pushing and puts the base back where it was, at rest, at every step."""
    extra = """
  <gazebo>
    <plugin name="ros_force_based_move" filename="librobotnik_force_based_move.so">
      <commandTopic>robotnik_base_control/cmd_vel</commandTopic>
      <odometryTopic>robotnik_base_control/odom</odometryTopic>
      <robotBaseFrame>base_footprint</robotBaseFrame>
      <commandWatchdog>0.5</commandWatchdog>
      <odometryRate>50.0</odometryRate>
    </plugin>
  </gazebo>"""
    timeline = _cmd(0.2, "robotnik_base_control/cmd_vel", x=0.3)
    path = _write(tmp_path, extra, duration=1.5, timeline=timeline)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    (drive,) = [p for p in plan.robots[0].plugins if p.type == "force_based_move"]
    assert drive.params["cmd_timeout"] == 0.5 and drive.params["hold_on_timeout"] is True
    _, bus = simulate(path)
    t, pose, vel = _truth(bus)
    moving = (t > 0.3) & (t < 0.7)
    assert np.allclose(vel[moving, 0], 0.3, atol=0.01)  # kp 10000: at the command within a few steps
    held = t > 0.75  # (the first steps after it show the one step of gravity and contact it lets act)
    assert np.ptp(pose[held, 0]) < 1e-4 and np.abs(vel[held]).max() < 1e-3
    assert pose[held, 0].mean() > 0.1  # where the watchdog fired, ~0.5 s × 0.3 m/s from the start
    assert len(messages(bus, "bot/robotnik_base_control/odom")) > 0


def test_ros2_port_force_limit_and_world_odometry(tmp_path: Path):
    """The ROS 2 port: a PI controller clamped to <force_lim> (5 N on 22 kg: 0.227 m/s² at most), the
    odometry the base's world pose on the (remapped) `odom` topic at <publish_rate>."""
    extra = """
  <gazebo>
    <plugin name="force_based_move" filename="libgazebo_ros_force_based_move.so">
      <ros><remapping>odom:=wheel_odom</remapping></ros>
      <odometry_frame>odom</odometry_frame>
      <robot_base_frame>base_footprint</robot_base_frame>
      <publish_rate>10</publish_rate>
      <vel_p_gain>1000</vel_p_gain>
      <force_lim>5</force_lim>
      <torque_lim>5</torque_lim>
    </plugin>
  </gazebo>"""
    path = _write(tmp_path, extra, duration=2.0, timeline=_cmd(0.5, "cmd_vel", x=1.0))
    _plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    _, bus = simulate(path)
    t, pose, vel = _truth(bus)
    ramp = (t > 0.6) & (t < 1.9)
    slope = np.polyfit(t[ramp], vel[ramp, 0], 1)[0]
    assert abs(slope - 5.0 / (MASS + 2.0)) < 0.01, slope
    odom = messages(bus, "bot/wheel_odom")
    assert abs(len(odom) - 20) <= 1
    stamp, last = odom[-1]
    i = int(np.argmin(abs(t - stamp / 1e9)))
    assert abs(last.pose.pose.position.x - pose[i, 0]) < 1e-6  # the world pose, not integrated
    assert last.header.frame_id == "bot/odom" and last.child_frame_id == "bot/base_footprint"


WORLD_ODOMETRY = """
  <gazebo>
    <plugin name="p3d_base_controller" filename="libgazebo_ros_p3d.so">
      <alwaysOn>true</alwaysOn>
      <updateRate>100.0</updateRate>
      <bodyName>base_link</bodyName>
      <topicName>ground_truth/state</topicName>
      <gaussianNoise>0.02</gaussianNoise>
      <frameName>world</frameName>
      <xyzOffset>1 2 0</xyzOffset>
      <rpyOffset>0 0 0.5</rpyOffset>
    </plugin>
  </gazebo>
  <gazebo>
    <plugin name="world_odometry" filename="libgazebo_world_odometry.so">
      <frameName>world</frameName>
      <bodyName>base_link</bodyName>
      <topicName>floating_base_pose_simulated</topicName>
      <updateRate>50</updateRate>
    </plugin>
  </gazebo>
  <gazebo>
    <plugin name="ground_truth_controller" filename="librobotnik_gazebo_ground_truth_odom.so">
      <updateRate>50.0</updateRate>
      <bodyName>base_link</bodyName>
      <frameName>base_link_gt</frameName>
      <worldFrameName>odom</worldFrameName>
      <topicName>odom_gt</topicName>
      <broadcastTF>true</broadcastTF>
    </plugin>
  </gazebo>"""


def test_world_odometry_plugins_publish_the_true_pose(tmp_path: Path):
    """p3d (ROS 1), PAL's world odometry, Robotnik's ground truth on a base that drives forward while
    turning: each on its topic, at its rate, in its frames; p3d's pose offset and twist noise, the twist
    in the world frame (p3d), linear world / angular body (PAL), all body (Robotnik)."""
    drive = HECTOR.replace("KYAW", "100").replace("KP", "10000")
    timeline = _cmd(0.2, "base/cmd_vel", x=0.4, yaw=0.8)
    path = _write(tmp_path, drive + WORLD_ODOMETRY, duration=2.0, timeline=timeline, link="base_link")
    _plan, notices = compile_with_notices(path)
    assert "not supported" not in notices and "xyzOffset" not in notices
    _, bus = simulate(path)
    truth = messages(bus, "bot/truth")
    by_time = {s: m for s, m in truth}

    def true_at(stamp: int) -> Any:
        return by_time[stamp]

    p3d = messages(bus, "bot/ground_truth/state")
    assert abs(len(p3d) - 200) <= 1
    assert p3d[0][1].header.frame_id == "world" and p3d[0][1].child_frame_id == "bot/base_link"
    stamp, m = p3d[-1]
    ref = true_at(stamp)
    assert abs(m.pose.pose.position.x - (ref.pose.pose.position.x + 1.0)) < 1e-9
    assert abs(m.pose.pose.position.y - (ref.pose.pose.position.y + 2.0)) < 1e-9
    q, qr = m.pose.pose.orientation, ref.pose.pose.orientation
    yaw = quat_to_yaw([q.w, q.x, q.y, q.z])
    assert abs(math.remainder(yaw - quat_to_yaw([qr.w, qr.x, qr.y, qr.z]) - 0.5, 2 * math.pi)) < 1e-6
    # twist: the world-frame velocity plus N(0, 0.02) on each component
    errors = np.array(
        [
            [m.twist.twist.linear.x - true_at(s).twist.twist.linear.x, m.twist.twist.angular.z - 0.8]
            for s, m in p3d
            if s > 1.0e9
        ]
    )
    assert abs(errors[:, 0].std() - 0.02) < 0.004 and abs(errors[:, 0].mean()) < 0.006
    assert m.twist.covariance[0] == 0.02**2

    pal = messages(bus, "bot/floating_base_pose_simulated")
    assert abs(len(pal) - 100) <= 1
    stamp, m = pal[-1]
    ref = true_at(stamp)
    assert m.header.frame_id == "world" and m.child_frame_id == "bot/base_link"
    assert abs(m.pose.pose.position.x - ref.pose.pose.position.x) < 1e-9
    assert abs(m.twist.twist.linear.y - ref.twist.twist.linear.y) < 1e-9  # world frame
    assert abs(ref.twist.twist.linear.y) > 0.1  # (the heading has turned: world and body differ)

    gt = messages(bus, "bot/odom_gt")
    stamp, m = gt[-1]
    assert m.header.frame_id == "bot/odom" and m.child_frame_id == "bot/base_link_gt"
    assert abs(m.twist.twist.linear.x - 0.4) < 0.01 and abs(m.twist.twist.linear.y) < 0.01  # body frame
    tf = [x for _, x in messages(bus, "bot/tf") if x.transforms[0].child_frame_id == "bot/base_link_gt"]
    assert len(tf) == len(gt) and tf[0].transforms[0].header.frame_id == "bot/odom"


def test_what_the_plugins_do_not_read_is_said_at_its_line(tmp_path: Path):
    """A p3d without <topicName> stops loading (said, nothing published); ROS 1 p3d reads `xyzOffset`, so
    the plural is said as no parameter of it; the ROS 2 port's <update_rate> and covariances are said as
    ignored; a base frame the robot lacks is said at its tag."""
    extra = """
  <gazebo>
    <plugin name="p3d_a" filename="libgazebo_ros_p3d.so">
      <bodyName>base_link</bodyName>
    </plugin>
  </gazebo>
  <gazebo>
    <plugin name="p3d_b" filename="libgazebo_ros_p3d.so">
      <bodyName>base_link</bodyName>
      <topicName>gt</topicName>
      <xyzOffsets>1 1 1</xyzOffsets>
    </plugin>
  </gazebo>
  <gazebo>
    <plugin name="fbm" filename="libgazebo_ros_force_based_move.so">
      <update_rate>50</update_rate>
      <covariance_x>0.1</covariance_x>
      <robot_base_frame>chassis</robot_base_frame>
    </plugin>
  </gazebo>"""
    path = _write(tmp_path, extra, duration=0.1)
    plan, notices = compile_with_notices(path)
    text = (tmp_path / "fb.urdf").read_text().splitlines()

    def line_of(snippet: str) -> int:
        return next(i + 1 for i, t in enumerate(text) if snippet in t)

    assert f"fb.urdf:{line_of('p3d_a')}: 'libgazebo_ros_p3d.so' has no <topicName>" in notices
    assert f"fb.urdf:{line_of('<xyzOffsets>')}: <xyzOffsets> is not a parameter" in notices
    assert f"fb.urdf:{line_of('<update_rate>')}: <update_rate> in" in notices
    assert f"fb.urdf:{line_of('<covariance_x>')}: <covariance_x> in" in notices
    assert (
        f"fb.urdf:{line_of('<robot_base_frame>')}: 'libgazebo_ros_force_based_move.so' pushes link" in notices
    )
    # the p3d without a topic adds nothing; the other one is a ground_truth (the scenario's own merges into it)
    assert [p.name for p in plan.robots[0].plugins if p.type == "ground_truth"] == ["p3d_b"]
