"""Plugins against physics and geometry (issue 4's acceptance): each check compares with an analytic
value or with MuJoCo's ground truth, never with the plugin's own numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from runner.geometry import quat_to_yaw
from tests.helpers import messages, simulate

ROBOT = """
name: f
duration: {duration}
rate: max
world:
  models: [{models}]
robots:
  - name: r1
    description: {{file: "{{diffbot}}", args: {{color: "0.1 0.1 0.9 1"}}}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{plugins}]
timeline:
{timeline}
"""


def _scenario(write_scenario, duration, plugins, timeline="", models=""):  # type: ignore[no-untyped-def]
    return simulate(
        write_scenario(
            ROBOT.format(duration=duration, plugins=plugins, timeline=timeline or "  []", models=models)
        )
    )[1]


def _cmd(t: float, lin: float = 0.0, ang: float = 0.0, lat: float = 0.0) -> str:
    return (
        f"  - {{t: {t}, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, "
        f"data: {{linear: {{x: {lin}, y: {lat}}}, angular: {{z: {ang}}}}}}}\n"
    )


def _yaw(msg) -> float:  # type: ignore[no-untyped-def]
    q = msg.pose.pose.orientation
    return quat_to_yaw([q.w, q.x, q.y, q.z])


# ------------------------------------------------------------------------------------------- drives
@pytest.mark.timeout(60)
@pytest.mark.parametrize("drive", ["diff_drive", "planar_move"])
def test_drive_straight_0_2_m_s_for_5_s(write_scenario, drive):
    bus = _scenario(
        write_scenario, 6.0, f"{{type: {drive}}}, {{type: ground_truth}}", _cmd(0.0, 0.2) + _cmd(5.0)
    )
    truth = messages(bus, "r1/ground_truth")[-1][1].pose.pose.position
    assert abs(math.hypot(truth.x, truth.y) - 1.0) < 0.05, truth
    odom = messages(bus, "r1/odom")[-1][1].pose.pose.position
    assert abs(odom.x - truth.x) < 0.02 * 1.0  # odometry within 2 % of the distance


@pytest.mark.timeout(60)
@pytest.mark.parametrize("drive", ["diff_drive", "planar_move"])
def test_drive_turns_0_5_rad_s_for_4_s(write_scenario, drive):
    bus = _scenario(
        write_scenario, 5.0, f"{{type: {drive}}}, {{type: ground_truth}}", _cmd(0.0, ang=0.5) + _cmd(4.0)
    )
    yaws = np.unwrap([_yaw(m) for _, m in messages(bus, "r1/ground_truth")])
    assert abs((yaws[-1] - yaws[0]) - 2.0) < 0.1, yaws[-1]
    odom = np.unwrap([_yaw(m) for _, m in messages(bus, "r1/odom")])
    if drive == "planar_move":  # odometry from the true pose, as libgazebo_ros_planar_move
        assert abs(odom[-1] - yaws[-1]) < 0.02 * 2.0
    else:  # wheel encoders: a turn in place scrubs the tyres, so they over-report it a little
        assert abs(odom[-1] - yaws[-1]) < 0.06 * 2.0


@pytest.mark.timeout(60)
def test_diff_drive_world_odometry_is_the_truth(write_scenario):
    bus = _scenario(
        write_scenario,
        3.0,
        # wheels said to be 1.5x their size: they turn slower than the command needs, and would claim it
        "{type: diff_drive, params: {odometry_source: world, wheel_radius: 0.075}}, {type: ground_truth}",
        _cmd(0.0, 0.2, ang=0.5),
    )
    (_, odom), (_, truth) = messages(bus, "r1/odom")[-1], messages(bus, "r1/ground_truth")[-1]
    assert odom.pose.pose.position.x == pytest.approx(truth.pose.pose.position.x, abs=1e-9)
    assert _yaw(odom) == pytest.approx(_yaw(truth), abs=1e-9)
    # the twist is the truth too (body frame), not the wheels' claim of 0.2 m/s and 0.5 rad/s
    tw, true_tw = odom.twist.twist, truth.twist.twist
    speed = math.hypot(true_tw.linear.x, true_tw.linear.y)
    assert speed < 0.2 / 1.3  # the robot really is slower than commanded
    assert math.hypot(tw.linear.x, tw.linear.y) == pytest.approx(speed, rel=0.02)
    assert tw.angular.z == pytest.approx(true_tw.angular.z, rel=0.02)


@pytest.mark.timeout(60)
def test_diff_drive_wheel_acceleration_limit_is_respected(write_scenario):
    bus = _scenario(
        write_scenario,
        2.0,
        "{type: diff_drive, params: {max_wheel_acceleration: 4.0}}, {type: joint_states, params: {rate: 100}}",
        _cmd(0.0, 0.3),
    )
    js = messages(bus, "r1/joint_states")
    t = np.array([s for s, _ in js]) / 1e9
    v = np.array([m.velocity[0] for _, m in js])
    # the wheel is never faster than a 4 rad/s² ramp from rest allows; the drive raises its target once per
    # control period (50 Hz), at the period's start
    assert np.all(v <= 4.0 * (t + 0.02) + 0.01), (v - 4.0 * (t + 0.02)).max()
    assert v[-1] == pytest.approx(0.3 / 0.05, rel=0.03)  # and it does reach the commanded speed
    reach = t[np.argmax(v > 0.95 * 6.0)]
    assert reach > 0.95 * 6.0 / 4.0  # not sooner than the limit allows


@pytest.mark.timeout(60)
def test_planar_move_sideways(write_scenario):
    bus = _scenario(
        write_scenario, 4.0, "{type: planar_move}, {type: ground_truth}", _cmd(0.0, lat=0.25) + _cmd(3.0)
    )
    p = messages(bus, "r1/ground_truth")[-1][1].pose.pose.position
    assert abs(p.y - 0.75) < 0.05 * 0.75 and abs(p.x) < 0.02


# -------------------------------------------------------------------------------------------- lidar
SHAPES = (
    "{name: box, shape: box, size: [0.4, 2.0, 1.0], pose: {xyz: [3.2, 0, 0.5]}}, "
    "{name: drum, shape: cylinder, size: [0.3, 1.0], pose: {xyz: [0, 2.5, 0.5]}}"
)


@pytest.mark.timeout(60)
def test_lidar_ranges_match_boxes_and_cylinders(write_scenario):
    sigma = 0.01
    bus = _scenario(
        write_scenario,
        1.0,
        f"{{type: lidar, params: {{link: lidar_link, samples: 720, range_max: 6.0, noise_stddev: {sigma}}}}}",
        models=SHAPES,
    )
    angles = np.linspace(-math.pi, math.pi, 720)
    scans = np.array([np.asarray(m.ranges, dtype=float) for _, m in messages(bus, "r1/scan")])
    # box face at x = 3.0 (the lidar is at the base origin, x = 0): r = 3 / cos(a) while |y| < 1
    box = np.abs(angles) < math.atan(0.95 / 3.0)
    err = scans[:, box] - 3.0 / np.cos(angles[box])
    assert (np.abs(err) < 3 * sigma).mean() > 0.99
    # cylinder (radius 0.3) centred at (0, 2.5): the beam at +90° hits at 2.2
    up = np.argmin(np.abs(angles - math.pi / 2))
    assert np.all(np.abs(scans[:, up] - 2.2) < 3 * sigma)
    # analytic ray-circle distance for beams that graze the cylinder
    near = np.abs(angles - math.pi / 2) < 0.1
    d = 2.5 * np.sin(angles[near])
    h = np.sqrt(np.maximum(0.3**2 - (2.5 * np.cos(angles[near])) ** 2, 0))
    hit = h > 0.02
    assert np.all(np.abs(scans[:, near][:, hit] - (d - h)[hit]) < 3 * sigma + 1e-3)
    # beyond range_max (behind the robot, nothing within 6 m): +inf, the REP 117 convention
    assert np.isinf(scans[:, 0]).all() and np.isinf(scans[:, -1]).all()


# ------------------------------------------------------------------------------------------- camera
@pytest.mark.timeout(60)
def test_red_box_appears_where_the_intrinsics_say(write_scenario):
    # A small red cube 3 m ahead, 0.5 m to the left, at the camera's height (the lidar link, 0.15 m).
    models = (
        "{name: target, shape: box, size: [0.1, 0.1, 0.1], pose: {xyz: [3.0, 0.5, 0.15]}, rgba: [1, 0, 0, 1]}"
    )
    bus = _scenario(
        write_scenario,
        0.1,
        "{type: camera, params: {link: lidar_link, width: 320, height: 240, fov: 1.2, rate: 10}}, "
        "{type: depth_camera, params: {link: lidar_link, width: 160, height: 120, fov: 1.2, rate: 10, "
        "image_topic: d/image, info_topic: d/info, depth_topic: d/depth, depth_info_topic: d/dinfo, points_topic: null}}",
        models=models
        + ", {name: wall, shape: box, size: [0.1, 8, 3], pose: {xyz: [4.05, 0, 1.5]}, rgba: [0.8, 0.8, 0.8, 1]}",
    )
    img = messages(bus, "r1/camera/image_raw")[-1][1]
    px = np.asarray(img.data).reshape(240, 320, 3).astype(int)
    red = (px[..., 0] > 150) & (px[..., 1] < 80) & (px[..., 2] < 80)
    assert red.sum() > 20
    v, u = np.nonzero(red)
    fx = 320 / (2 * math.tan(0.6))
    # face of the cube at x = 2.95; optical frame: x right = -y world, y down = -z world
    u_expected = 160 + fx * (-0.5 / 2.95)
    v_expected = 120 + fx * (0.0 / 2.95)
    assert abs(u.mean() - u_expected) < 3 and abs(v.mean() - v_expected) < 3
    info = messages(bus, "r1/camera/camera_info")[-1][1]
    assert np.allclose(info.k, [fx, 0, 160, 0, fx, 120, 0, 0, 1])
    depth = messages(bus, "r1/d/depth")[-1][1]
    arr = np.frombuffer(np.asarray(depth.data).tobytes(), dtype=np.float32).reshape(120, 160)
    assert abs(float(arr[60, 80]) - 4.0) < 0.01 * 4.0  # the wall face at x = 4.0


# ---------------------------------------------------------------------------------------------- imu
@pytest.mark.timeout(60)
def test_imu_at_rest_and_turning(write_scenario):
    bus = _scenario(
        write_scenario,
        5.0,
        "{type: diff_drive}, {type: imu, params: {link: imu_link}}, {type: ground_truth}",
        _cmd(2.0, ang=0.5),
    )
    imu = messages(bus, "r1/imu")
    rest = [m for t, m in imu if 1.0 <= t / 1e9 <= 1.9]
    acc = np.array(
        [[m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z] for m in rest]
    )
    gyro = np.array([[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for m in rest])
    assert np.all(np.abs(np.linalg.norm(acc, axis=1) - 9.81) < 0.05)
    assert np.all(np.abs(gyro) < 1e-3)
    turning = [m.angular_velocity.z for t, m in imu if 3.5 <= t / 1e9 <= 5.0]
    assert abs(np.mean(turning) - 0.5) < 0.02 * 0.5


SKID = """
name: s
duration: {duration}
rate: max
robots:
  - name: r1
    description: "{skidbot}"
    pose: {{xyz: [0, 0, 0.065]}}
    plugins: [{{type: skid_steer, params: {{yaw_rate_feedback: true}}}}, {{type: ground_truth}}]
timeline:
{timeline}
"""


@pytest.mark.timeout(60)
def test_skid_steer_straight_and_turning(write_scenario):
    from tests.test_motion import SKIDBOT

    text = SKID.format(duration=6.0, skidbot=SKIDBOT, timeline=_cmd(0.0, 0.2) + _cmd(5.0))
    _, bus = simulate(write_scenario(text))
    p = messages(bus, "r1/ground_truth")[-1][1].pose.pose.position
    assert abs(math.hypot(p.x, p.y) - 1.0) < 0.05, p
    text = SKID.format(duration=5.0, skidbot=SKIDBOT, timeline=_cmd(0.0, ang=0.5) + _cmd(4.0))
    _, bus = simulate(write_scenario(text, "turn.yaml"))
    yaws = np.unwrap([_yaw(m) for _, m in messages(bus, "r1/ground_truth")])
    assert abs((yaws[-1] - yaws[0]) - 2.0) < 0.1, yaws[-1]
