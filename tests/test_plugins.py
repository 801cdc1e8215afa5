"""Plugins against real MuJoCo physics (the world stepped in-process; transport is tested elsewhere)."""

from __future__ import annotations

import math

import numpy as np

from runner.geometry import quat_to_yaw
from tests.helpers import messages, simulate

WALL = """
name: t
duration: {duration}
rate: max
world:
  models:
    - {{name: wall, shape: box, size: [0.1, 6, 1], pose: {{xyz: [2.05, 0, 0.5]}}}}
robots:
  - name: r1
    description: "{{diffbot}}"
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - type: lidar
        params: {{link: lidar_link, samples: 361, rate: 10, range_max: 10, noise_stddev: {noise}}}
"""


def _scans(write_scenario, noise: float, duration: float = 1.0) -> list[np.ndarray]:
    _world, bus = simulate(write_scenario(WALL.format(duration=duration, noise=noise)))
    return [np.asarray(m.ranges, dtype=float) for _, m in messages(bus, "r1/scan")]


def test_lidar_reads_wall_distance_exactly_without_noise(write_scenario):
    scans = _scans(write_scenario, 0.0)
    angles = np.linspace(-math.pi, math.pi, 361)
    front = np.abs(angles) < 0.9
    expected = 2.0 / np.cos(angles[front])
    assert np.allclose(scans[-1][front], expected, atol=2e-3)


def test_lidar_facing_a_wall_reads_it_within_3_sigma(write_scenario):
    sigma = 0.02
    scans = _scans(write_scenario, sigma, duration=2.0)
    angles = np.linspace(-math.pi, math.pi, 361)
    front = np.abs(angles) < 0.9
    errors = np.concatenate([s[front] - 2.0 / np.cos(angles[front]) for s in scans])
    assert np.mean(np.abs(errors) < 3 * sigma) > 0.99
    assert abs(errors.mean()) < 3 * sigma / math.sqrt(len(errors)) + 2e-3
    assert 0.8 * sigma < errors.std() < 1.2 * sigma  # the noise is really there


def test_lidar_never_sees_its_own_robot_and_reports_inf_for_no_return(write_scenario):
    scan = _scans(write_scenario, 0.0)[-1]
    assert np.all(scan > 0.5)  # the chassis and wheels are right there, but excluded
    assert np.isinf(scan[0]) and np.isinf(scan[-1])  # behind: nothing within 10 m


DRIVE = """
name: t
duration: 6.0
rate: max
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins: [{type: diff_drive}, {type: ground_truth}, {type: imu}, {type: joint_states}]
  - name: r2
    description: "{diffbot}"
    pose: {xyz: [0, 2, 0.06]}
    plugins: [{type: diff_drive}, {type: ground_truth}]
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.3}}}
  - {t: 5.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {}}
"""


def test_diff_drive_moves_the_commanded_robot_only(write_scenario):
    _, bus = simulate(write_scenario(DRIVE))
    r1 = messages(bus, "r1/ground_truth")
    r2 = messages(bus, "r2/ground_truth")
    p1 = r1[-1][1].pose.pose.position
    p2 = r2[-1][1].pose.pose.position
    assert abs(p1.x - 1.5) < 0.15, p1  # 0.3 m/s for 5 s, along its heading (+x)
    assert abs(p1.y) < 0.05
    assert math.hypot(p2.x - 0.0, p2.y - 2.0) < 0.01, p2  # r2 got no command
    odom = messages(bus, "r1/odom")[-1][1].pose.pose.position
    assert abs(odom.x - p1.x) < 0.05  # encoder odometry agrees with the truth on flat ground


def test_diff_drive_turns_in_place(write_scenario):
    text = DRIVE.replace("linear: {x: 0.3}", "angular: {z: 0.5}").replace("t: 5.0", "t: 3.14159")
    _, bus = simulate(write_scenario(text))
    q = messages(bus, "r1/ground_truth")[-1][1].pose.pose.orientation
    yaw = quat_to_yaw([q.w, q.x, q.y, q.z])
    assert abs(yaw - math.pi / 2) < 0.1 * math.pi / 2, yaw


def test_rates_are_exact_in_sim_time(write_scenario):
    _, bus = simulate(write_scenario(DRIVE))
    for suffix, rate in (("r1/imu", 100), ("r1/joint_states", 50), ("r1/odom", 50), ("t/clock", 100)):
        stamps = [t for t, _ in messages(bus, suffix)]
        assert len(stamps) == int(6.0 * rate) + 1, suffix
        assert np.allclose(np.diff(stamps), 1e9 / rate), suffix


def test_imu_at_rest_reads_gravity(write_scenario):
    text = DRIVE.replace("data: {linear: {x: 0.3}}", "data: {}")
    _, bus = simulate(write_scenario(text))
    t, imu = messages(bus, "r1/imu")[-1]
    assert abs(imu.linear_acceleration.z - 9.81) < 0.05
    assert abs(imu.angular_velocity.z) < 1e-3
    assert abs(imu.orientation.w) > 0.999
    assert imu.header.frame_id == "r1/imu_link"
    assert t == 6_000_000_000 and imu.header.stamp.sec == 6


def test_joint_states_use_urdf_joint_names(write_scenario):
    _, bus = simulate(write_scenario(DRIVE))
    _, js = messages(bus, "r1/joint_states")[-1]
    assert list(js.name) == ["left_wheel_joint", "right_wheel_joint"]
    # 0.3 m/s on 0.05 m wheels for ~5 s: about 30 rad each
    assert 25 < js.position[0] < 32


def test_3d_lidar_publishes_a_point_cloud_on_the_wall(write_scenario):
    text = WALL.format(duration=0.2, noise=0.0).replace(
        "range_max: 10,",
        "range_max: 10, vertical_samples: 9, vertical_min_angle: 0.0, vertical_max_angle: 0.2,",
    )
    _, bus = simulate(write_scenario(text))
    _, cloud = messages(bus, "r1/scan/points")[-1]
    assert (cloud.height, cloud.width, cloud.point_step) == (9, 361, 12)
    xyz = np.frombuffer(cloud.data.tobytes(), dtype=np.float32).reshape(9, 361, 3)
    ahead = xyz[:, 180]  # azimuth 0, every elevation
    assert np.allclose(ahead[:, 0], 2.0, atol=2e-3)  # all rows hit the wall 2 m ahead
    assert np.allclose(ahead[:, 2], 2.0 * np.tan(np.linspace(0.0, 0.2, 9)), atol=3e-3)
    assert np.isnan(xyz[4, 0]).all()  # behind: no return (the ground is below every beam)
    _, scan = messages(bus, "r1/scan")[-1]  # the horizontal row is still a LaserScan
    assert abs(scan.ranges[180] - 2.0) < 2e-3
