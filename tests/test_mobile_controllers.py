"""Mobile-base controllers of ros2_control / ros_control, run from a controllers file as Gazebo runs them
(runner.compile.gazebo.control.drives; plugins diff_drive, skid_steer, mecanum_drive, steering_drive):
wheel torque from the description, encoder odometry, the speed limiter, stamped commands, the mecanum and
steering controllers' kinematics; in process on real MuJoCo, and through a real Zenoh run."""

from __future__ import annotations

import subprocess
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from runner.geometry import quat_to_yaw
from tests.helpers import compile_with_notices, declared, messages, simulate

_INERTIA = '<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/>'


def _wheel(name: str, xyz: str, radius: float, mass: float, effort: float | None = None) -> str:
    i = mass * radius**2 / 2
    limit = f'<limit effort="{effort}" velocity="50"/>' if effort else ""
    return f"""
  <link name="{name}">
    <inertial><mass value="{mass}"/>{_INERTIA.format(i=i)}</inertial>
    <collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="{radius}" length="0.06"/></geometry></collision>
  </link>
  <joint name="{name}_joint" type="continuous">
    <parent link="base_link"/><child link="{name}"/><origin xyz="{xyz}"/><axis xyz="0 1 0"/>{limit}
  </joint>"""


def _base(mass: float, size: str, com: float = 0.0) -> str:
    return f"""
  <link name="base_link">
    <inertial><origin xyz="{com} 0 0"/><mass value="{mass}"/><inertia ixx="{mass * 0.02}" iyy="{mass * 0.03}" izz="{mass * 0.04}" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="{size}"/></geometry></collision>
  </link>"""


def _control(yaml_path: Path) -> str:
    return f"""
  <gazebo>
    <plugin filename="libgz_ros2_control-system.so" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>{yaml_path}</parameters>
    </plugin>
  </gazebo>"""


def skid_steer(control: str, mass: float = 56.0, effort: float | None = None) -> str:
    """A heavy four-wheel skid steer (56 kg with its wheels, as the issue's), wheels of 0.25 m radius
    0.6 m apart along and across, no <limit effort> unless `effort`."""
    wheels = "".join(
        _wheel(f"{end}_{side}_wheel", f"{x} {y} -0.06", 0.25, 1.5, effort)
        for end, x in (("front", 0.3), ("rear", -0.3))
        for side, y in (("left", 0.3), ("right", -0.3))
    )
    return f'<?xml version="1.0"?>\n<robot name="skid">{_base(mass - 6.0, "0.6 0.4 0.15")}{wheels}{control}\n</robot>\n'


SCENARIO = """
name: t
duration: {duration}
rate: {rate}
seed: 3
robots:
  - name: r1
    description: robot.urdf
    pose: {{xyz: [0, 0, {z}]}}
    plugins: [{{type: ground_truth, params: {{rate: 100}}}}]
timeline:
{timeline}
"""


def _write(tmp_path: Path, urdf: str, controllers: str, duration: float, timeline: str, z: float = 0.12,
           rate: str = "max") -> Path:  # fmt: skip
    (tmp_path / "control.yaml").write_text(controllers)
    (tmp_path / "robot.urdf").write_text(urdf.replace("CONTROL_YAML", str(tmp_path / "control.yaml")))
    path = tmp_path / "scenario.yaml"
    path.write_text(SCENARIO.format(duration=duration, timeline=timeline or "  []", z=z, rate=rate))
    return path


def _twist(t: float, topic: str, lin: float = 0.0, ang: float = 0.0, lin_y: float = 0.0,
           stamped: bool = False) -> str:  # fmt: skip
    data = f"{{linear: {{x: {lin}, y: {lin_y}}}, angular: {{z: {ang}}}}}"
    if stamped:
        return f"  - {{t: {t}, topic: r1/{topic}, type: geometry_msgs/msg/TwistStamped, data: {{twist: {data}}}}}\n"
    return f"  - {{t: {t}, topic: r1/{topic}, type: geometry_msgs/msg/Twist, data: {data}}}\n"


def _stream(t0: float, t1: float, topic: str, every: float = 0.1, **kw: Any) -> str:
    """A command repeated every `every` s from t0 to t1 (as a teleop node sends it)."""
    n = round((t1 - t0) / every)
    return "".join(_twist(round(t0 + k * every, 3), topic, **kw) for k in range(n))


def _truth(bus: Any) -> tuple[np.ndarray, np.ndarray]:
    """(t, [x, y, yaw]) of the robot's true pose."""
    samples = messages(bus, "r1/ground_truth")
    t = np.array([s / 1e9 for s, _ in samples])
    pose = np.array(
        [[m.pose.pose.position.x, m.pose.pose.position.y, _yaw(m.pose.pose.orientation)] for _, m in samples]
    )
    pose[:, 2] = np.unwrap(pose[:, 2])
    return t, pose


def _yaw(q: Any) -> float:
    return quat_to_yaw([q.w, q.x, q.y, q.z])


def _odom(bus: Any, topic: str) -> tuple[np.ndarray, np.ndarray]:
    samples = messages(bus, f"r1/{topic}")
    t = np.array([s / 1e9 for s, _ in samples])
    pose = np.array(
        [[m.pose.pose.position.x, m.pose.pose.position.y, _yaw(m.pose.pose.orientation)] for _, m in samples]
    )
    pose[:, 2] = np.unwrap(pose[:, 2])
    return t, pose


def _at(t: np.ndarray, values: np.ndarray, when: float) -> Any:
    return values[int(np.argmin(abs(t - when)))]


SKID_CONTROLLERS = """
/**:
  controller_manager:
    ros__parameters:
      update_rate: 100
      diff_cont: {type: diff_drive_controller/DiffDriveController}
  diff_cont:
    ros__parameters:
      left_wheel_names: [front_left_wheel_joint, rear_left_wheel_joint]
      right_wheel_names: [front_right_wheel_joint, rear_right_wheel_joint]
      wheel_separation: 0.6
      wheel_radius: 0.25
      use_stamped_vel: false
      publish_rate: 50.0
"""


def _skid_turn(tmp_path: Path, effort: float | None) -> tuple[float, float]:
    """The yaw the heavy skid steer turns (true, and as its odometry says) for 0.5 rad/s over 3 s."""
    timeline = _stream(0.5, 3.5, "diff_cont/cmd_vel_unstamped", ang=0.5)
    urdf = skid_steer(_control("CONTROL_YAML"), effort=effort)
    _, bus = simulate(_write(tmp_path, urdf, SKID_CONTROLLERS, 4.5, timeline, z=0.3))
    t, pose = _truth(bus)
    to, odom = _odom(bus, "diff_cont/odom")
    return float(_at(t, pose, 4.5)[2] - pose[0, 2]), float(_at(to, odom, 4.5)[2])


@pytest.mark.timeout(120)
def test_a_heavy_skid_steer_from_a_controllers_file_turns_with_the_torque_its_description_gives(
    tmp_path: Path,
):
    """The issue's case: a 56 kg four-wheel skid steer whose controllers file runs diff_drive_controller
    with two wheels a side. gz_ros2_control gives its wheels the URDF <limit effort>, none without one:
    it turns (0.43 rad of the 1.75 commanded here, what MuJoCo's isotropic wheel friction gives a skid steer,
    see issue 39), where a 20 N·m cap of ours kept it at 0.04 rad. With <limit effort="20"> in the URDF it
    is held as in Gazebo. Its odometry is the controller's, from the wheel encoders (a skid steer's
    encoders over-report the turn), not the true pose."""
    turned, odom_yaw = _skid_turn(tmp_path, None)
    assert turned > 0.3, turned
    assert odom_yaw > 1.5 * turned, (odom_yaw, turned)  # encoder odometry, not ground truth
    assert abs(odom_yaw - 0.5 * 3.5) < 0.15, odom_yaw  # the wheels turned as commanded (+ 0.5 s timeout)
    limited, _ = _skid_turn(tmp_path, 20.0)
    assert limited < 0.15, limited


def _steered(name: str, xyz: str, radius: float) -> str:
    """A steering knuckle (revolute about z) carrying a free-rolling wheel."""
    return f"""
  <link name="{name}_steer">
    <inertial><mass value="0.2"/>{_INERTIA.format(i=0.0005)}</inertial>
  </link>
  <joint name="{name}_steer_joint" type="revolute">
    <parent link="base_link"/><child link="{name}_steer"/><origin xyz="{xyz}"/><axis xyz="0 0 1"/>
    <limit lower="-0.7" upper="0.7" effort="50" velocity="5"/>
  </joint>
  <link name="{name}_wheel">
    <inertial><mass value="0.5"/>{_INERTIA.format(i=0.5 * radius**2 / 2)}</inertial>
    <collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="{radius}" length="0.04"/></geometry></collision>
  </link>
  <joint name="{name}_wheel_joint" type="continuous">
    <parent link="{name}_steer"/><child link="{name}_wheel"/><axis xyz="0 1 0"/>
  </joint>"""


def ackermann_car(control: str) -> str:
    """A 12 kg car: rear traction wheels 0.3 m apart, front wheels steered, 0.4 m wheelbase."""
    rear = _wheel("rear_left_wheel", "-0.2 0.15 -0.04", 0.08, 0.5) + _wheel(
        "rear_right_wheel", "-0.2 -0.15 -0.04", 0.08, 0.5
    )
    front = _steered("front_left", "0.2 0.15 -0.04", 0.08) + _steered("front_right", "0.2 -0.15 -0.04", 0.08)
    return f'<?xml version="1.0"?>\n<robot name="car">{_base(10.0, "0.5 0.25 0.08")}{rear}{front}{control}\n</robot>\n'


ACKERMANN = """
controller_manager:
  ros__parameters:
    update_rate: 100
    ackermann: {type: ackermann_steering_controller/AckermannSteeringController}
ackermann:
  ros__parameters:
    traction_joints_names: [rear_right_wheel_joint, rear_left_wheel_joint]
    steering_joints_names: [front_right_steer_joint, front_left_steer_joint]
    wheelbase: 0.4
    traction_track_width: 0.3
    steering_track_width: 0.3
    traction_wheels_radius: 0.08
    reference_timeout: 0.5
"""


@pytest.mark.timeout(120)
def test_an_ackermann_steering_controller_turns_on_the_radius_its_reference_asks(tmp_path: Path):
    """ackermann_steering_controller from its controllers file: linear.x 0.3 m/s and angular.z 0.3 rad/s
    on `ackermann/reference` (TwistStamped, Jazzy) ask for a 1.0 m turning radius; the car steers its
    front wheels (inner more than outer) and drives its rear wheels, and turns on that radius within 10 %;
    its odometry (from the traction wheels and steering angles) follows the truth; it stops
    `reference_timeout` after the last reference; `controller_state` reports the steering."""
    timeline = _stream(0.5, 6.5, "ackermann/reference", lin=0.3, ang=0.3, stamped=True)
    path = _write(tmp_path, ackermann_car(_control("CONTROL_YAML")), ACKERMANN, 8.0, timeline, z=0.1)
    plan, said = compile_with_notices(path)
    assert "not run" not in said and "ignored" not in said, said
    topics = {p.name: sorted(t.key.removeprefix("t/r1/") for t in p.topics) for p in declared(plan.robots[0])}
    assert topics["ackermann"] == [
        "ackermann/controller_state",
        "ackermann/odometry",
        "ackermann/reference",
        "ackermann/tf_odometry",
    ], topics
    _, bus = simulate(path)
    t, pose = _truth(bus)
    a, b = np.searchsorted(t, 1.5), np.searchsorted(t, 6.5)
    steps = np.linalg.norm(np.diff(pose[a:b, :2], axis=0), axis=1)
    radius = float(steps.sum() / (pose[b, 2] - pose[a, 2]))
    assert abs(radius - 1.0) < 0.07, radius  # measured: 1.046
    assert float(np.linalg.norm(pose[-1, :2] - _at(t, pose, 7.2)[:2])) < 0.01  # stopped after the timeout
    to, odom = _odom(bus, "ackermann/odometry")
    assert abs(float(_at(to, odom, 6.5)[2]) - float(_at(t, pose, 6.5)[2] - pose[0, 2])) < 0.1
    state = messages(bus, "r1/ackermann/controller_state")[-200][1]
    right, left = state.steering_angle_command
    assert left > right > 0.3, (left, right)  # the inner (left) wheel steers more


def mecanum_robot(control: str) -> str:
    """An 8 kg mecanum robot: wheels of 0.05 m radius, 0.3 m apart along and 0.34 m across."""
    wheels = "".join(
        _wheel(f"{end}_{side}_wheel", f"{x} {y} -0.03", 0.05, 0.4)
        for end, x in (("front", 0.15), ("rear", -0.15))
        for side, y in (("left", 0.17), ("right", -0.17))
    )
    return f'<?xml version="1.0"?>\n<robot name="mecanum">{_base(6.4, "0.4 0.26 0.06")}{wheels}{control}\n</robot>\n'


MECANUM = """
/**:
  controller_manager:
    ros__parameters:
      update_rate: 100
      mecanum_drive_controller: {type: mecanum_drive_controller/MecanumDriveController}
  mecanum_drive_controller:
    ros__parameters:
      reference_timeout: 0.5
      front_left_wheel_command_joint_name: front_left_wheel_joint
      front_right_wheel_command_joint_name: front_right_wheel_joint
      rear_right_wheel_command_joint_name: rear_right_wheel_joint
      rear_left_wheel_command_joint_name: rear_left_wheel_joint
      kinematics:
        wheels_radius: 0.05
        sum_of_robot_center_projection_on_X_Y_axis: 0.32
      base_frame_id: base_link
      odom_frame_id: odom
"""


@pytest.mark.timeout(120)
def test_a_mecanum_drive_controller_strafes(tmp_path: Path):
    """mecanum_drive_controller from its controllers file: linear.y 0.2 m/s on its `reference` from 0.5 s
    to 4.4 s, and for its reference_timeout (0.5 s) after, moves the robot sideways 0.88 m without turning
    or going forward (measured: 0.86 m, on the rollers its wheels get); its odometry (from the wheels'
    velocities) says so too; `controller_state` carries the wheel speeds and the reference."""
    topic = "mecanum_drive_controller/reference"
    timeline = _stream(0.5, 4.5, topic, lin_y=0.2, stamped=True)
    path = _write(tmp_path, mecanum_robot(_control("CONTROL_YAML")), MECANUM, 5.5, timeline, z=0.06)
    _, bus = simulate(path)
    t, pose = _truth(bus)
    moved = _at(t, pose, 5.5) - pose[0]
    assert abs(moved[1] - 0.88) < 0.05 and abs(moved[0]) < 0.03 and abs(moved[2]) < 0.05, moved
    to, odom = _odom(bus, "mecanum_drive_controller/odometry")
    assert abs(float(_at(to, odom, 5.5)[1]) - 0.88) < 0.05, odom[-1]
    state = messages(bus, "r1/mecanum_drive_controller/controller_state")[200][1]
    assert state.reference_velocity.linear.y == pytest.approx(0.2)
    # strafing left: the front left and rear right wheels turn backward, the others forward (4 rad/s)
    assert state.front_left_wheel_velocity < -3 and state.front_right_wheel_velocity > 3, state


CASTER = """
  <link name="caster_mount">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="caster_swivel" type="continuous">
    <parent link="base_link"/><child link="caster_mount"/><origin xyz="-0.15 0 -0.055"/><axis xyz="0 0 1"/>
  </joint>
  <link name="caster">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.045"/></geometry></collision>
  </link>
  <joint name="caster_joint" type="continuous">
    <parent link="caster_mount"/><child link="caster"/><axis xyz="0 1 0"/>
  </joint>
  <gazebo reference="caster"><mu1>0</mu1><mu2>0</mu2></gazebo>"""


def diffbot(control: str) -> str:
    """A 6 kg two-wheel robot on a ball caster behind (its centre of mass 5 cm behind the axle): wheels of
    0.05 m radius, 0.34 m apart."""
    wheels = _wheel("left_wheel", "0 0.17 -0.05", 0.05, 0.5) + _wheel(
        "right_wheel", "0 -0.17 -0.05", 0.05, 0.5
    )
    return f'<?xml version="1.0"?>\n<robot name="diffbot">{_base(5.0, "0.4 0.3 0.1", com=-0.05)}{wheels}{CASTER}{control}\n</robot>\n'


DIFF = """
/**:
  controller_manager:
    ros__parameters:
      update_rate: 100
      diff_cont: {type: diff_drive_controller/DiffDriveController}
  diff_cont:
    ros__parameters:
      left_wheel_names: [left_wheel_joint]
      right_wheel_names: [right_wheel_joint]
      wheel_separation: 0.34
      wheel_radius: 0.05
      publish_rate: 20.0
      publish_limited_velocity: true
      pose_covariance_diagonal: [0.001, 0.001, 0.001, 0.001, 0.001, 0.01]
      linear.x.max_velocity: 0.25
      linear.x.max_acceleration: 0.5
      angular:
        z:
          max_velocity: 1.0
"""


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
    path = _write(tmp_path, diffbot(_control("CONTROL_YAML")), DIFF, 6.0, "  []", z=0.1, rate="1")
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
    assert 0 < _yaw(end_odom.orientation) - _yaw(end_truth.orientation) < 0.2


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
    path = _write(tmp_path, urdf, controllers, 1.0, "  []")
    if ros1:
        text = path.read_text().replace("    plugins: [", "    controllers: [control.yaml]\n    plugins: [")
        path.write_text(text)
    plan, said = compile_with_notices(path)
    mine = [p for p in declared(plan.robots[0]) if p.type not in ("ground_truth", "joint_states")]
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
    jazzy, said = _compiled(tmp_path, diffbot(_control("CONTROL_YAML")), JAZZY_OR_HUMBLE)
    assert jazzy["topics"] == ["base/cmd_vel", "base/odom", "tf"] and jazzy["cmd_type"] == "twist_stamped"
    assert _given(jazzy["linear_limits"]) == {"max_velocity": 0.5} and jazzy["control_rate"] == 50
    assert jazzy["frame_prefix"] == "robot_a/" and jazzy["odometry_source"] == "velocity"
    assert jazzy["twist_covariance_diagonal"] == [1, 2, 3, 4, 5, 6]
    assert "ignored" not in said and "not run" not in said, said
    humble, _ = _compiled(
        tmp_path, diffbot(_control("CONTROL_YAML")), JAZZY_OR_HUMBLE + "    use_stamped_vel: false\n"
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
    params, said = _compiled(tmp_path, ackermann_car(_control("CONTROL_YAML")), HUMBLE_BICYCLE)
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
