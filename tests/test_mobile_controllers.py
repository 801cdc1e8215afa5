"""Mobile-base controllers of ros2_control / ros_control, run from a controllers file as Gazebo runs them
(runner.compile.gazebo.control.drives; plugins diff_drive, skid_steer, mecanum_drive, steering_drive):
wheel torque from the description, encoder odometry, the speed limiter, stamped commands, the mecanum and
steering controllers' kinematics; in process on real MuJoCo, and through a real Zenoh run."""

from __future__ import annotations

import math
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from bench.mobile import (
    ACKERMANN,
    DIFF,
    ackermann_car,
    ackermann_radius,
    at,
    control,
    diffbot,
    mecanum_strafe,
    odom,
    skid_turn,
    stream,
    truth,
    write,
    yaw,
)
from bench.mobile import simulate as simulate_bus
from tests.helpers import compile_with_notices, declared, messages


@pytest.mark.timeout(120)
def test_a_heavy_skid_steer_from_a_controllers_file_turns_with_the_torque_its_description_gives(
    tmp_path: Path,
):
    """The issue's case: a 56 kg four-wheel skid steer whose controllers file runs diff_drive_controller
    with two wheels a side. gz_ros2_control gives its wheels the URDF <limit effort>, none without one:
    it turns (0.40 rad of the 1.75 commanded here, what MuJoCo's isotropic wheel friction gives a skid steer,
    see issue 39), where a 20 N·m cap of ours kept it at 0.036 rad. With <limit effort="20"> in the URDF it
    is held as in Gazebo. Its odometry is the controller's, from the wheel encoders (a skid steer's
    encoders over-report the turn), not the true pose."""
    turned, odom_yaw = skid_turn(tmp_path, None)
    assert turned > 0.3, turned
    assert odom_yaw > 1.5 * turned, (odom_yaw, turned)  # encoder odometry, not ground truth
    assert abs(odom_yaw - 0.5 * 3.5) < 0.15, odom_yaw  # the wheels turned as commanded (+ 0.5 s timeout)
    limited, _ = skid_turn(tmp_path, 20.0)
    assert limited < 0.15, limited


@pytest.mark.timeout(120)
def test_an_ackermann_steering_controller_turns_on_the_radius_its_reference_asks(tmp_path: Path):
    """ackermann_steering_controller from its controllers file: linear.x 0.3 m/s and angular.z 0.3 rad/s
    on `ackermann/reference` (TwistStamped, Jazzy) ask for a 1.0 m turning radius; the car steers its
    front wheels (inner more than outer) and drives its rear wheels, and turns on that radius within 10 %;
    its odometry (from the traction wheels and steering angles) follows the truth; it stops
    `reference_timeout` after the last reference; `controller_state` reports the steering."""
    path = write(tmp_path, ackermann_car(control("CONTROL_YAML")), ACKERMANN, 8.0, "  []", z=0.1)
    plan, said = compile_with_notices(path)
    assert "not run" not in said and "ignored" not in said, said
    topics = {p.name: sorted(t.key.removeprefix("t/r1/") for t in p.topics) for p in declared(plan.robots[0])}
    assert topics["ackermann"] == [
        "ackermann/controller_state",
        "ackermann/odometry",
        "ackermann/reference",
        "ackermann/tf_odometry",
    ], topics
    radius, bus = ackermann_radius(tmp_path)
    assert abs(radius - 1.0) < 0.07, radius  # measured: 1.046
    t, pose = truth(bus)
    assert float(np.linalg.norm(pose[-1, :2] - at(t, pose, 7.2)[:2])) < 0.01  # stopped after the timeout
    to, said = odom(bus, "ackermann/odometry")
    assert abs(float(at(to, said, 6.5)[2]) - float(at(t, pose, 6.5)[2] - pose[0, 2])) < 0.1
    state = messages(bus, "r1/ackermann/controller_state")[-200][1]
    right, left = state.steering_angle_command
    assert left > right > 0.3, (left, right)  # the inner (left) wheel steers more


@pytest.mark.timeout(120)
def test_a_mecanum_drive_controller_strafes(tmp_path: Path):
    """mecanum_drive_controller from its controllers file: linear.y 0.2 m/s on its `reference` from 0.5 s
    to 4.4 s, and for its reference_timeout (0.5 s) after, moves the robot sideways 0.88 m without turning
    or going forward (measured: 0.86 m, on the rollers its wheels get); its odometry (from the wheels'
    velocities) says so too; `controller_state` carries the wheel speeds and the reference."""
    moved, bus = mecanum_strafe(tmp_path)
    assert abs(moved[1] - 0.88) < 0.05 and abs(moved[0]) < 0.03 and abs(moved[2]) < 0.05, moved
    to, said = odom(bus, "mecanum_drive_controller/odometry")
    assert abs(float(at(to, said, 5.5)[1]) - 0.88) < 0.05, said[-1]
    state = messages(bus, "r1/mecanum_drive_controller/controller_state")[200][1]
    assert state.reference_velocity.linear.y == pytest.approx(0.2)
    # strafing left: the front left and rear right wheels turn backward, the others forward (4 rad/s)
    assert state.front_left_wheel_velocity < -3 and state.front_right_wheel_velocity > 3, state


def _join(port: int, run: str, deadline_s: float = 60.0) -> Any:
    """A Zenoh session of the test's own on the run's router, once the world ticks."""
    import zenoh

    from runner.wire.transport import make_config

    session = None
    deadline = time.monotonic() + deadline_s
    while session is None and time.monotonic() < deadline:
        try:
            session = zenoh.open(make_config("client", connect=[f"tcp/127.0.0.1:{port}"]))
        except zenoh.ZError:
            time.sleep(0.1)
    assert session is not None, "the run's router never listened"
    ticking = threading.Event()
    clock = session.declare_subscriber(f"{run}/clock", lambda _s: ticking.set())
    if not ticking.wait(deadline_s):
        session.close()
        raise AssertionError("the world did not start")
    clock.undeclare()
    return session


@pytest.mark.timeout(180)
def test_a_diff_drive_controller_through_zenoh_drives_limited_and_reports_encoder_odometry(tmp_path: Path):
    """A real run: a client session publishes geometry_msgs/TwistStamped (Jazzy's `diff_cont/cmd_vel`,
    zero stamp: taken as its arrival) asking 0.4 m/s and 0.5 rad/s. The controller's speed limiter holds
    linear.x to 0.25 m/s, reached at 0.5 m/s², and passes angular.z (below its 1.0 limit); it publishes
    what it drives at on `diff_cont/cmd_vel_out`; its odometry on `diff_cont/odom` (20 Hz, with its
    covariance) is integrated from the wheel encoders and agrees with the true pose (read back from the
    recording) but for the wheels' slip in the turn."""
    from runner.wire import msgs
    from runner.wire.transport import encoding_for, free_port
    from tests.conftest import read_mcap, scenario_cmd

    port = free_port()
    path = write(tmp_path, diffbot(control("CONTROL_YAML")), DIFF, 6.0, "  []", z=0.1, rate="1")
    mcap = tmp_path / "run.mcap"
    cmd = scenario_cmd(
        "run", str(path), "--no-judge", "--listen", f"tcp/127.0.0.1:{port}", "--record", str(mcap)
    )
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        session = _join(port, "t")
        try:
            kind = "geometry_msgs/msg/TwistStamped"
            pub = session.declare_publisher("t/r1/diff_cont/cmd_vel", encoding=encoding_for(kind))
            data = {"twist": {"linear": {"x": 0.4}, "angular": {"z": 0.5}}}
            payload = msgs.encode(msgs.from_data(kind, data), kind)
            end = time.monotonic() + 3.0
            while time.monotonic() < end:  # a teleop node's 20 Hz
                pub.put(payload)
                time.sleep(0.05)
            pub.undeclare()
        finally:
            session.close()
        out, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 0, out + err
    recorded = read_mcap(mcap)
    truth = [(t / 1e9, m) for topic, _, t, m in recorded if topic == "t/r1/ground_truth"]
    odom = [(t / 1e9, m) for topic, _, t, m in recorded if topic == "t/r1/diff_cont/odom"]
    limited = [m.twist for topic, _, _, m in recorded if topic == "t/r1/diff_cont/cmd_vel_out"]
    assert 5.5 * 20 <= len(odom) <= 6 * 20 + 1
    assert list(odom[-1][1].pose.covariance[::7]) == pytest.approx([0.001] * 5 + [0.01])
    moving = [c for c in limited if c.linear.x > 0]
    assert max(c.linear.x for c in moving) == pytest.approx(0.25)
    steps = np.diff([c.linear.x for c in limited])
    assert steps.max() <= 0.5 * 0.01 + 1e-9  # 0.5 m/s² at the 100 Hz update
    assert max(c.angular.z for c in limited) == pytest.approx(0.5)
    end_truth, end_odom = truth[-1][1].pose.pose, odom[-1][1].pose.pose
    start = truth[0][1].pose.pose.position
    true_xy = np.array([end_truth.position.x - start.x, end_truth.position.y - start.y])
    assert np.linalg.norm(true_xy) > 0.3, true_xy  # it drove
    # encoders over-report the turn by what the wheels slip (measured: 0.12 rad of 1.74, 5.5 cm)
    assert np.linalg.norm(true_xy - [end_odom.position.x, end_odom.position.y]) < 0.1
    assert 0 < yaw(end_odom.orientation) - yaw(end_truth.orientation) < 0.2


ROS1_LIMITED = """
base_controller:
  type: diff_drive_controller/DiffDriveController
  left_wheel: left_wheel_joint
  right_wheel: right_wheel_joint
  publish_cmd: true
  velocity_rolling_window_size: 4
  open_loop: true
  linear:
    x: {has_velocity_limits: true, max_velocity: 1.0, has_acceleration_limits: true, max_acceleration: 0.8,
        min_acceleration: -0.4}
  angular:
    z: {max_velocity: 2.0}
  wheel_bumpiness: 3
  publish_wheel_joint_controller_state: true
"""

ROS1_CONTROL = '\n  <gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so"/></gazebo>'


def _compiled(tmp_path: Path, urdf: str, controllers: str, ros1: bool = False) -> tuple[dict[str, Any], str]:
    """The plugin a controllers file's mobile-base controller compiles to (its type and params), and what
    validate says."""
    path = write(tmp_path, urdf, controllers, 1.0, "  []")
    if ros1:
        text = path.read_text().replace("    plugins: [", "    controllers: [control.yaml]\n    plugins: [")
        path.write_text(text)
    plan, said = compile_with_notices(path)
    mine = [
        p
        for p in declared(plan.robots[0])
        if p.type not in ("ground_truth", "joint_states", "controller_manager")
    ]
    assert len(mine) == 1, [p.type for p in mine]
    return {"type": mine[0].type, "topics": sorted(t.key.removeprefix("t/r1/") for t in mine[0].topics),
            **mine[0].params}, said  # fmt: skip


def _given(limits: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in limits.items() if v is not None}


def test_ros1_diff_drive_limits_publish_cmd_and_what_it_does_not_run_are_read_as_noetic(tmp_path: Path):
    """ROS 1 (ros_controllers Noetic): `publish_cmd` publishes `cmd_vel_out`; a limit counts only with its
    `has_*_limits: true` (angular.z's max_velocity without it is none), min_acceleration bounds every
    decrease; open_loop odometry; a parameter the controller does not have, and one we do not run, are
    said at the file's line."""
    params, said = _compiled(tmp_path, diffbot(ROS1_CONTROL), ROS1_LIMITED, ros1=True)
    assert params["topics"] == [
        "base_controller/cmd_vel",
        "base_controller/cmd_vel_out",
        "base_controller/odom",
        "tf",
    ]
    assert params["cmd_type"] == "twist" and params["odometry_source"] == "command"
    assert params["velocity_rolling_window_size"] == 4 and params["max_wheel_torque"] == "joint"
    assert _given(params["linear_limits"]) == {
        "max_velocity": 1.0, "max_acceleration": 0.8, "max_deceleration": -0.4,
        "max_acceleration_reverse": -0.4, "max_deceleration_reverse": 0.8,
    }  # fmt: skip
    assert params["angular_limits"] is None
    assert "`wheel_bumpiness` is not one of its parameters; ignored" in said, said
    assert "`publish_wheel_joint_controller_state` is not run" in said


JAZZY_OR_HUMBLE = """
controller_manager:
  ros__parameters:
    update_rate: 50
    base: {type: diff_drive_controller/DiffDriveController}
base:
  ros__parameters:
    left_wheel_names: [left_wheel_joint]
    right_wheel_names: [right_wheel_joint]
    wheel_separation: 0.34
    wheel_radius: 0.05
    linear.x.max_velocity: 0.5
    tf_frame_prefix: /robot_a
    position_feedback: false
    twist_covariance_diagonal: [1, 2, 3, 4, 5, 6]
"""


def test_a_ros2_diff_drive_file_is_read_as_jazzy_unless_it_gives_humbles_use_stamped_vel(tmp_path: Path):
    """Jazzy: TwistStamped on `<name>/cmd_vel`, limits on where given (linear.x.max_velocity), frames
    with tf_frame_prefix, odometry from the wheels' velocities (position_feedback: false), control at the
    manager's update_rate. The same file with Humble's `use_stamped_vel: false`: Twist on
    `<name>/cmd_vel_unstamped`, and no limit without `has_velocity_limits: true` (Humble's default)."""
    jazzy, said = _compiled(tmp_path, diffbot(control("CONTROL_YAML")), JAZZY_OR_HUMBLE)
    assert jazzy["topics"] == ["base/cmd_vel", "base/odom", "tf"] and jazzy["cmd_type"] == "twist_stamped"
    assert _given(jazzy["linear_limits"]) == {"max_velocity": 0.5} and jazzy["control_rate"] == 50
    assert jazzy["frame_prefix"] == "robot_a/" and jazzy["odometry_source"] == "velocity"
    assert jazzy["twist_covariance_diagonal"] == [1, 2, 3, 4, 5, 6]
    assert "ignored" not in said and "not run" not in said, said
    humble, _ = _compiled(
        tmp_path, diffbot(control("CONTROL_YAML")), JAZZY_OR_HUMBLE + "    use_stamped_vel: false\n"
    )
    assert humble["topics"] == ["base/cmd_vel_unstamped", "base/odom", "tf"] and humble["cmd_type"] == "twist"
    assert humble["linear_limits"] is None


HUMBLE_BICYCLE = """
controller_manager:
  ros__parameters:
    steer: {type: bicycle_steering_controller/BicycleSteeringController}
    four: {type: four_wheel_steering_controller/FourWheelSteeringController}
steer:
  ros__parameters:
    front_steering: true
    rear_wheels_names: [rear_right_wheel_joint]
    front_wheels_names: [front_right_steer_joint]
    wheelbase: 0.4
    rear_wheel_radius: 0.08
    use_stamped_vel: false
"""


def test_humble_steering_names_map_as_the_library_maps_them_and_a_four_wheel_steering_is_said(tmp_path: Path):
    """Humble's bicycle_steering_controller names (front_steering, rear_wheels_names for traction,
    front_wheels_names for steering, rear_wheel_radius) become Jazzy's; `use_stamped_vel: false` takes
    Twist on `<name>/reference_unstamped`; ROS 1's four_wheel_steering_controller is said with its type."""
    params, said = _compiled(tmp_path, ackermann_car(control("CONTROL_YAML")), HUMBLE_BICYCLE)
    assert params["type"] == "steering_drive" and params["kinematics"] == "bicycle"
    assert params["traction_joints_names"] == ["rear_right_wheel_joint"]
    assert params["steering_joints_names"] == ["front_right_steer_joint"]
    assert params["traction_wheels_radius"] == 0.08 and params["reference_type"] == "twist"
    assert "steer/reference_unstamped" in params["topics"]
    assert "'four' (four_wheel_steering_controller/FourWheelSteeringController) is not run" in said, said


def test_the_speed_limiter_bounds_jerk_then_acceleration_then_velocity():
    """speed_limiter (control_toolbox RateLimiter): from rest toward 1.0 at dt 0.1 with max_jerk 10,
    max_acceleration 2, max_velocity 0.5: the first step is held by jerk (10·2·dt² = 0.2), the next ones by
    acceleration (0.2 a step), then by velocity; going back, max_deceleration -1 gives 0.1 a step."""
    from plugins._mobile import AxisLimits, SpeedLimiter

    lim = SpeedLimiter(
        AxisLimits(max_velocity=0.5, max_acceleration=2.0, max_deceleration=-1.0, max_jerk=10.0)
    )
    out = [round(lim.limit(1.0, 0.1), 6) for _ in range(4)]
    assert out == [0.2, 0.4, 0.5, 0.5], out
    assert round(lim.limit(0.0, 0.1), 6) == 0.4


ROS1_ACKERMANN = """
steer_controller:
  type: ackermann_steering_controller/AckermannSteeringController
  rear_wheel: rear_right_wheel_joint
  front_steer: front_steer_joint
  wheel_separation_h: 0.4
  wheel_radius: 0.08
  publish_rate: 25
  steer_pos_multiplier: 1.0
"""


@pytest.mark.timeout(120)
def test_ros1_ackermann_steering_controller_steers_by_the_angle_cmd_vel_gives(tmp_path: Path):
    """ROS 1's ackermann_steering_controller (the same type name as ROS 2's): `cmd_vel` (Twist) whose
    angular.z its update() sends to the steering joint as an angle: 0.3 m/s with angular.z 0.2 drives on a
    radius of wheelbase / tan(0.2) = 1.97 m; `odom` at its publish_rate; a multiplier it has is said."""
    timeline = stream(0.5, 6.5, "steer_controller/cmd_vel", lin=0.3, ang=0.2)
    urdf = ackermann_car(ROS1_CONTROL, tricycle=True)
    path = write(tmp_path, urdf, ROS1_ACKERMANN, 7.0, timeline, z=0.1)
    path.write_text(
        path.read_text().replace("    plugins: [", "    controllers: [control.yaml]\n    plugins: [")
    )
    plan, said = compile_with_notices(path)
    topics = {p.name: sorted(t.key.removeprefix("t/r1/") for t in p.topics) for p in declared(plan.robots[0])}
    assert topics["steer_controller"] == ["steer_controller/cmd_vel", "steer_controller/odom", "tf"], topics
    assert "`steer_pos_multiplier` is not run: taken as 1" in said, said
    bus = simulate_bus(path)
    t, pose = truth(bus)
    a, b = np.searchsorted(t, 1.5), np.searchsorted(t, 6.5)
    steps = np.linalg.norm(np.diff(pose[a:b, :2], axis=0), axis=1)
    radius = float(steps.sum() / (pose[b, 2] - pose[a, 2]))
    assert abs(radius - 0.4 / math.tan(0.2)) < 0.2, radius  # measured: 2.08 (one rear wheel driven)
    assert 6.5 * 25 <= len(messages(bus, "r1/steer_controller/odom")) <= 7 * 25 + 1


def test_a_controller_drive_reuses_the_hardwares_wheel_actuator_and_keeps_each_joints_own_limit():
    """The contract with the hardware layer (plugins/_actuators.py): a wheel whose ros2_control hardware
    already made a velocity actuator (here, with a 7 N·m limit) is driven through it, limit kept; a wheel
    without one gets an actuator of the drive's with the joint's URDF <limit effort> (3 N·m); a drive
    declared with a torque (gazebo_ros_diff_drive's) puts its own on both."""
    import mujoco

    from plugins.diff_drive import DiffDrive, DiffDriveParams
    from runner.plugin import BuildContext

    urdf = diffbot("").replace(
        '<joint name="right_wheel_joint" type="continuous">',
        '<joint name="right_wheel_joint" type="continuous"><limit effort="3" velocity="10"/>',
    )

    def built(torque: Any) -> dict[str, tuple[float, float]]:
        spec = mujoco.MjSpec.from_string(urdf)
        hw = spec.add_actuator(name="hw/left", target="left_wheel_joint", trntype=mujoco.mjtTrn.mjTRN_JOINT)
        hw.set_to_velocity(kv=5.0)
        hw.forcelimited, hw.forcerange = True, [-7.0, 7.0]
        params = DiffDriveParams(
            left_joint="left_wheel_joint", right_joint="right_wheel_joint", max_wheel_torque=torque
        )
        DiffDrive.build(params, BuildContext(spec, "r1", "r1", "base_link"), "base")
        return {a.name: tuple(a.forcerange) for a in spec.actuators if a.gear[0] != 0}

    assert built("joint") == {"hw/left": (-7.0, 7.0), "base/right": (-3.0, 3.0)}
    assert built(20.0) == {"hw/left": (-20.0, 20.0), "base/right": (-20.0, 20.0)}


TRICYCLE = """
controller_manager:
  ros__parameters:
    update_rate: 100
    tricycle_controller: {type: tricycle_controller/TricycleController}
tricycle_controller:
  ros__parameters:
    traction_joint_name: front_wheel_joint
    steering_joint_name: front_steer_joint
    wheelbase: 0.4
    wheel_radius: 0.08
    cmd_vel_timeout: 0.5
    traction:
      max_velocity: 10.0
"""


@pytest.mark.timeout(120)
def test_a_tricycle_controller_steers_and_drives_its_one_front_wheel(tmp_path: Path):
    """tricycle_controller/TricycleController (not the steering library's tricycle): the front wheel
    steers and drives, the rear wheels roll free. 0.3 m/s and 0.3 rad/s on `tricycle_controller/cmd_vel`
    (TwistStamped) ask for a 1.0 m radius: the front wheel is steered atan(w L / v) and spun
    v / (r cos(alpha)) (twist_to_ackermann); the car turns on that radius within 10 %, its odometry
    (`tricycle_controller/odom`) from the wheel follows it, and its limiter parameters are said."""
    urdf = ackermann_car(control("CONTROL_YAML"), tricycle=True)
    timeline = stream(0.5, 6.5, "tricycle_controller/cmd_vel", lin=0.3, ang=0.3, stamped=True)
    path = write(tmp_path, urdf, TRICYCLE, 7.0, timeline, z=0.1)
    _, said = compile_with_notices(path)
    assert "`traction.max_velocity` is not run" in said, said
    bus = simulate_bus(path)
    t, pose = truth(bus)
    a, b = np.searchsorted(t, 1.5), np.searchsorted(t, 6.5)
    steps = np.linalg.norm(np.diff(pose[a:b, :2], axis=0), axis=1)
    turned = float(pose[b, 2] - pose[a, 2])
    radius = float(steps.sum()) / turned
    assert abs(radius - 1.0) < 0.1, radius
    assert turned > 1.2, turned  # 0.3 rad/s for 5 s: 1.5 rad asked
    od = messages(bus, "r1/tricycle_controller/odom")
    assert abs(yaw(od[-1][1].pose.pose.orientation) - float(pose[-1, 2])) < 0.15


HUSARION_MECANUM = """
/**/controller_manager:
  ros__parameters:
    update_rate: 25
    base_controller: {type: mecanum_drive_controller/MecanumDriveController}
/**/base_controller:
  ros__parameters:
    front_left_wheel_name: front_left_wheel_joint
    front_right_wheel_name: front_right_wheel_joint
    rear_left_wheel_name: rear_left_wheel_joint
    rear_right_wheel_name: rear_right_wheel_joint
    wheel_separation_x: 0.3
    wheel_separation_y: 0.34
    wheel_radius: 0.05
    cmd_vel_timeout: 0.5
    use_stamped_vel: false
    linear:
      y: {has_velocity_limits: true, max_velocity: 0.8}
"""


@pytest.mark.timeout(120)
def test_husarions_mecanum_controller_of_the_same_type_name_is_told_apart_by_its_parameters(tmp_path: Path):
    """Husarion's mecanum_drive_controller (ROSbot XL) has ros2_controllers' package and type name but
    diff-drive-like parameters and topics: `~/cmd_vel_unstamped` (Twist, `use_stamped_vel: false`), `~/odom`.
    Read as ros2_controllers' it failed to configure and the robot stood still; read as Husarion's it
    strafes 0.2 m/s for 4.4 s (and its 0.5 s timeout) as asked."""
    from bench.mobile import mecanum_robot

    timeline = stream(0.5, 4.5, "base_controller/cmd_vel_unstamped", lin_y=0.2)
    path = write(tmp_path, mecanum_robot(control("CONTROL_YAML")), HUSARION_MECANUM, 5.5, timeline, z=0.06)
    _, said = compile_with_notices(path)
    assert "read as Husarion's mecanum_drive_controller" in said, said
    bus = simulate_bus(path)
    t, pose = truth(bus)
    moved = at(t, pose, 5.5) - pose[0]
    assert abs(moved[1] - 0.88) < 0.06 and abs(moved[0]) < 0.03 and abs(moved[2]) < 0.05, moved
    assert messages(bus, "r1/base_controller/odom")


def test_a_four_wheel_diff_drive_controller_with_velocity_or_command_odometry_compiles(tmp_path: Path):
    """diff_drive_controller with two wheels a side becomes our skid_steer, which takes its odometry from
    the wheels' velocities (`position_feedback: false`) or the commands (`open_loop: true`) as the 2-wheel
    diff_drive does (a public robot's valid Humble file failed to validate)."""
    from bench.mobile import SKID_CONTROLLERS, skid_steer

    for extra, source in (
        ("      position_feedback: false\n", "velocity"),
        ("      open_loop: true\n", "command"),
    ):
        plugin, said = _compiled(
            tmp_path, skid_steer(control("CONTROL_YAML"), effort=None), SKID_CONTROLLERS + extra
        )
        assert plugin["type"] == "skid_steer" and plugin["odometry_source"] == source, (plugin, said)
