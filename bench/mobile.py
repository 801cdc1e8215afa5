"""Mobile-base controllers from a controllers file (issue 36): what the physics gives them, measured.

- a 56 kg four-wheel skid steer (0.25 m wheels) running diff_drive_controller, asked 0.5 rad/s for 3.5 s:
  the yaw it turns with its wheels' torque unlimited (the URDF without <limit effort>, as gz_ros2_control
  runs it) and held to 20 N·m (`<limit effort="20">`, the cap our drives had), and what its encoder
  odometry says;
- an Ackermann car (ackermann_steering_controller) asked 0.3 m/s and 0.3 rad/s: its turning radius
  against the 1.0 m asked;
- a mecanum robot (mecanum_drive_controller) asked 0.2 m/s sideways: the distance it strafes against the
  command, and its drift forward and in yaw.

The robots and controllers files are used by tests/test_mobile_controllers.py too."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from runner.geometry import quat_to_yaw
from runner.wire import msgs
from runner.wire.transport import MemoryBus, unpack_attachment


def simulate(path: Path) -> MemoryBus:
    """Compile a scenario file and run it in process (real MuJoCo), every message kept on the bus."""
    from runner.compile import compile_plan
    from runner.scenario.loader import load_file
    from runner.scenario.validate import validate_scenario
    from runner.sim.world import World

    doc = load_file(path)
    bus = MemoryBus()
    World(compile_plan(validate_scenario(doc), doc), bus).run()
    return bus


def messages(bus: MemoryBus, key_suffix: str) -> list[tuple[int, Any]]:
    """(sim time ns, decoded message) of everything published on keys ending with `key_suffix`."""
    out = []
    for key, type_name, payload, att in bus.sent:
        if key.endswith(key_suffix):
            parsed = unpack_attachment(att)
            if parsed is not None:
                out.append((parsed[1], msgs.decode(payload, type_name)))
    return out


INERTIA = '<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/>'


def wheel(name: str, xyz: str, radius: float, mass: float, effort: float | None = None) -> str:
    i = mass * radius**2 / 2
    limit = f'<limit effort="{effort}" velocity="50"/>' if effort else ""
    return f"""
  <link name="{name}">
    <inertial><mass value="{mass}"/>{INERTIA.format(i=i)}</inertial>
    <collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="{radius}" length="0.06"/></geometry></collision>
  </link>
  <joint name="{name}_joint" type="continuous">
    <parent link="base_link"/><child link="{name}"/><origin xyz="{xyz}"/><axis xyz="0 1 0"/>{limit}
  </joint>"""


def base(mass: float, size: str, com: float = 0.0) -> str:
    return f"""
  <link name="base_link">
    <inertial><origin xyz="{com} 0 0"/><mass value="{mass}"/><inertia ixx="{mass * 0.02}" iyy="{mass * 0.03}" izz="{mass * 0.04}" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="{size}"/></geometry></collision>
  </link>"""


def control(yaml_path: Path) -> str:
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
        wheel(f"{end}_{side}_wheel", f"{x} {y} -0.06", 0.25, 1.5, effort)
        for end, x in (("front", 0.3), ("rear", -0.3))
        for side, y in (("left", 0.3), ("right", -0.3))
    )
    return f'<?xml version="1.0"?>\n<robot name="skid">{base(mass - 6.0, "0.6 0.4 0.15")}{wheels}{control}\n</robot>\n'


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


def write(tmp_path: Path, urdf: str, controllers: str, duration: float, timeline: str, z: float = 0.12,
           rate: str = "max") -> Path:  # fmt: skip
    (tmp_path / "control.yaml").write_text(controllers)
    (tmp_path / "robot.urdf").write_text(urdf.replace("CONTROL_YAML", str(tmp_path / "control.yaml")))
    path = tmp_path / "scenario.yaml"
    path.write_text(SCENARIO.format(duration=duration, timeline=timeline or "  []", z=z, rate=rate))
    return path


def twist(t: float, topic: str, lin: float = 0.0, ang: float = 0.0, lin_y: float = 0.0,
           stamped: bool = False) -> str:  # fmt: skip
    data = f"{{linear: {{x: {lin}, y: {lin_y}}}, angular: {{z: {ang}}}}}"
    if stamped:
        return f"  - {{t: {t}, topic: r1/{topic}, type: geometry_msgs/msg/TwistStamped, data: {{twist: {data}}}}}\n"
    return f"  - {{t: {t}, topic: r1/{topic}, type: geometry_msgs/msg/Twist, data: {data}}}\n"


def stream(t0: float, t1: float, topic: str, every: float = 0.1, **kw: Any) -> str:
    """A command repeated every `every` s from t0 to t1 (as a teleop node sends it)."""
    n = round((t1 - t0) / every)
    return "".join(twist(round(t0 + k * every, 3), topic, **kw) for k in range(n))


def truth(bus: Any) -> tuple[np.ndarray, np.ndarray]:
    """(t, [x, y, yaw]) of the robot's true pose."""
    samples = messages(bus, "r1/ground_truth")
    t = np.array([s / 1e9 for s, _ in samples])
    pose = np.array(
        [[m.pose.pose.position.x, m.pose.pose.position.y, yaw(m.pose.pose.orientation)] for _, m in samples]
    )
    pose[:, 2] = np.unwrap(pose[:, 2])
    return t, pose


def yaw(q: Any) -> float:
    return quat_to_yaw([q.w, q.x, q.y, q.z])


def odom(bus: Any, topic: str) -> tuple[np.ndarray, np.ndarray]:
    samples = messages(bus, f"r1/{topic}")
    t = np.array([s / 1e9 for s, _ in samples])
    pose = np.array(
        [[m.pose.pose.position.x, m.pose.pose.position.y, yaw(m.pose.pose.orientation)] for _, m in samples]
    )
    pose[:, 2] = np.unwrap(pose[:, 2])
    return t, pose


def at(t: np.ndarray, values: np.ndarray, when: float) -> Any:
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


def skid_turn(tmp_path: Path, effort: float | None) -> tuple[float, float]:
    """The yaw the heavy skid steer turns (true, and as its odometry says) for 0.5 rad/s over 3 s."""
    timeline = stream(0.5, 3.5, "diff_cont/cmd_vel_unstamped", ang=0.5)
    urdf = skid_steer(control("CONTROL_YAML"), effort=effort)
    bus = simulate(write(tmp_path, urdf, SKID_CONTROLLERS, 4.5, timeline, z=0.3))
    t, pose = truth(bus)
    to, said = odom(bus, "diff_cont/odom")
    return float(at(t, pose, 4.5)[2] - pose[0, 2]), float(at(to, said, 4.5)[2])


def steered(name: str, xyz: str, radius: float) -> str:
    """A steering knuckle (revolute about z) carrying a free-rolling wheel."""
    return f"""
  <link name="{name}_steer">
    <inertial><mass value="0.2"/>{INERTIA.format(i=0.0005)}</inertial>
  </link>
  <joint name="{name}_steer_joint" type="revolute">
    <parent link="base_link"/><child link="{name}_steer"/><origin xyz="{xyz}"/><axis xyz="0 0 1"/>
    <limit lower="-0.7" upper="0.7" effort="50" velocity="5"/>
  </joint>
  <link name="{name}_wheel">
    <inertial><mass value="0.5"/>{INERTIA.format(i=0.5 * radius**2 / 2)}</inertial>
    <collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="{radius}" length="0.04"/></geometry></collision>
  </link>
  <joint name="{name}_wheel_joint" type="continuous">
    <parent link="{name}_steer"/><child link="{name}_wheel"/><axis xyz="0 1 0"/>
  </joint>"""


def ackermann_car(control: str, tricycle: bool = False) -> str:
    """A 12 kg car: rear traction wheels 0.3 m apart, front wheels steered, 0.4 m wheelbase (`tricycle`:
    one steered front wheel, `front`, in the middle)."""
    rear = wheel("rear_left_wheel", "-0.2 0.15 -0.04", 0.08, 0.5) + wheel(
        "rear_right_wheel", "-0.2 -0.15 -0.04", 0.08, 0.5
    )
    front = steered("front_left", "0.2 0.15 -0.04", 0.08) + steered("front_right", "0.2 -0.15 -0.04", 0.08)
    if tricycle:
        front = steered("front", "0.2 0 -0.04", 0.08)
    return f'<?xml version="1.0"?>\n<robot name="car">{base(10.0, "0.5 0.25 0.08")}{rear}{front}{control}\n</robot>\n'


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


def mecanum_robot(control: str) -> str:
    """An 8 kg mecanum robot: wheels of 0.05 m radius, 0.3 m apart along and 0.34 m across."""
    wheels = "".join(
        wheel(f"{end}_{side}_wheel", f"{x} {y} -0.03", 0.05, 0.4)
        for end, x in (("front", 0.15), ("rear", -0.15))
        for side, y in (("left", 0.17), ("right", -0.17))
    )
    return f'<?xml version="1.0"?>\n<robot name="mecanum">{base(6.4, "0.4 0.26 0.06")}{wheels}{control}\n</robot>\n'


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
    wheels = wheel("left_wheel", "0 0.17 -0.05", 0.05, 0.5) + wheel("right_wheel", "0 -0.17 -0.05", 0.05, 0.5)
    return f'<?xml version="1.0"?>\n<robot name="diffbot">{base(5.0, "0.4 0.3 0.1", com=-0.05)}{wheels}{CASTER}{control}\n</robot>\n'


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


def ackermann_radius(tmp_path: Path) -> tuple[float, Any]:
    """The radius the Ackermann car turns on, asked for 1.0 m (0.3 m/s, 0.3 rad/s from 0.5 s to 6.5 s),
    and the bus of the run."""
    timeline = stream(0.5, 6.5, "ackermann/reference", lin=0.3, ang=0.3, stamped=True)
    bus = simulate(write(tmp_path, ackermann_car(control("CONTROL_YAML")), ACKERMANN, 8.0, timeline, z=0.1))
    t, pose = truth(bus)
    a, b = np.searchsorted(t, 1.5), np.searchsorted(t, 6.5)
    steps = np.linalg.norm(np.diff(pose[a:b, :2], axis=0), axis=1)
    return float(steps.sum() / (pose[b, 2] - pose[a, 2])), bus


def mecanum_strafe(tmp_path: Path) -> tuple[np.ndarray, Any]:
    """[x, y, yaw] the mecanum robot moves asked 0.2 m/s sideways from 0.5 s to 4.4 s (and its 0.5 s
    reference_timeout after: 0.88 m), and the bus of the run."""
    timeline = stream(0.5, 4.5, "mecanum_drive_controller/reference", lin_y=0.2, stamped=True)
    bus = simulate(write(tmp_path, mecanum_robot(control("CONTROL_YAML")), MECANUM, 5.5, timeline, z=0.06))
    t, pose = truth(bus)
    return at(t, pose, 5.5) - pose[0], bus


def run(quick: bool) -> tuple[dict[str, Any], str]:
    doc: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        for name in ("free", "capped", "ackermann", "mecanum"):
            (root / name).mkdir()
        free, free_odom = skid_turn(root / "free", None)
        capped, _ = skid_turn(root / "capped", 20.0)
        radius, _ = ackermann_radius(root / "ackermann")
        moved, _ = mecanum_strafe(root / "mecanum")
    doc["skid_steer_56kg"] = {"asked_rad": 1.75, "unlimited_rad": free, "odometry_rad": free_odom,
                              "effort_20_rad": capped}  # fmt: skip
    doc["ackermann"] = {"asked_radius_m": 1.0, "radius_m": radius}
    doc["mecanum"] = {
        "asked_y_m": 0.88,
        "x_m": float(moved[0]),
        "y_m": float(moved[1]),
        "yaw_rad": float(moved[2]),
    }
    rows = [
        ("56 kg skid steer, no <limit effort>: yaw turned", f"{free:.2f} rad of 1.75"),
        ("  its encoder odometry says", f"{free_odom:.2f} rad"),
        ('  with <limit effort="20"> (our cap before)', f"{capped:.3f} rad"),
        ("Ackermann car, asked 1.0 m: turning radius", f"{radius:.3f} m"),
        (
            "mecanum, asked 0.88 m sideways: y, x, yaw",
            f"{moved[1]:.3f} m, {moved[0]:.3f} m, {moved[2]:.3f} rad",
        ),
    ]
    text = "### Mobile-base controllers (bench/mobile.py)\n\n| run | measured |\n|---|---|\n" + "\n".join(
        f"| {a} | {b} |" for a, b in rows
    )
    return doc, text
