"""The controller manager (runner.compile.gazebo.controllers): every controllers-file layout in use yields its
controllers, each at its own line; a repeated key is said with both lines and merged as ROS 2 merges it; the
control plugin's `<ros>` remappings and namespace name every controller topic; and the broadcasters and
forward command controllers run (real compile, real MuJoCo, a real Zenoh run)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from runner.wire.transport import free_port
from tests.conftest import read_mcap, scenario_cmd
from tests.helpers import compile_with_notices, declared, messages, simulate

# a two-joint arm on a fixed base: a shoulder turning about z (no gravity load) and an elbow about y
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link">
    <inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.5"/>
      <inertia ixx="0.002" iyy="0.002" izz="0.0005" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.02" length="0.2"/></geometry></collision>
  </link>
  <link name="fore">
    <inertial><origin xyz="0.1 0 0"/><mass value="0.3"/>
      <inertia ixx="0.0003" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base_link"/><child link="upper"/><origin xyz="0 0 0.05"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="50" velocity="3"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/><origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="50" velocity="3"/>
  </joint>
  <ros2_control name="arm" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    <joint name="shoulder"><command_interface name="position"/>
      <state_interface name="position"/><state_interface name="velocity"/></joint>
    <joint name="elbow"><command_interface name="position"/>
      <state_interface name="position"/><state_interface name="velocity"/><state_interface name="effort"/></joint>
  </ros2_control>
  <gazebo>
    <plugin filename="{plugin}" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>{params}</parameters>{ros}
    </plugin>
  </gazebo>
</robot>
"""

SCENARIO = """name: cm
duration: {duration}
rate: max
robots:
  - name: r1
    description: arm.urdf
    fixed: true
    pose: {{xyz: [0, 0, 0.05]}}
    controllers: {controllers}
timeline:
{timeline}
"""


def _write(
    tmp_path: Path,
    files: dict[str, str],
    *,
    params: str = "control.yaml",
    ros: str = "",
    plugin: str = "gz_ros2_control-system",
    controllers: str = "[]",
    duration: float = 0.2,
    timeline: str = "  []",
) -> Path:
    for name, text in files.items():
        (tmp_path / name).write_text(textwrap.dedent(text).lstrip("\n"))
    (tmp_path / "arm.urdf").write_text(ARM.format(plugin=plugin, params=tmp_path / params, ros=ros))
    path = tmp_path / "scenario.yaml"
    path.write_text(
        SCENARIO.format(duration=duration, timeline=timeline, controllers=controllers), encoding="utf-8"
    )
    return path


def _plugins(path: Path) -> tuple[dict[str, object], str]:
    """The controllers' plugins by name (not the controller manager's own: test_controller_services.py)."""
    plan, said = compile_with_notices(path)
    return {p.name: p for p in declared(plan.robots[0]) if p.type != "controller_manager"}, said


def _topics(plugin: object) -> list[str]:
    return sorted(t.key.removeprefix("cm/r1/") for t in plugin.topics)  # type: ignore[attr-defined]


def _line(text: str, needle: str) -> int:
    """The 1-based line of the first line of a dedented file containing `needle`."""
    lines = textwrap.dedent(text).lstrip("\n").splitlines()
    return next(i + 1 for i, line in enumerate(lines) if needle in line)


MANAGER = """
controller_manager:
  ros__parameters:
    update_rate: 200
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    arm_controller: {type: forward_command_controller/ForwardCommandController}
arm_controller:
  ros__parameters:
    joints: [shoulder, elbow]
    interface_name: position
"""
WILDCARD = """
/**:
  controller_manager:
    ros__parameters:
      update_rate: 200
      joint_state_broadcaster:
        type: joint_state_broadcaster/JointStateBroadcaster
      arm_controller:
        type: position_controllers/JointGroupPositionController
  arm_controller:
    ros__parameters:
      joints: [shoulder, elbow]
"""
NAMESPACED = """
/robot1/controller_manager:
  ros__parameters:
    update_rate: 200
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    arm_controller: {type: forward_command_controller/ForwardCommandController}
/robot1/arm_controller:
  ros__parameters: {joints: [shoulder, elbow], interface_name: position}
"""
WILDCARD_PATHS = """
/**/controller_manager:
  ros__parameters:
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    arm_controller: {type: forward_command_controller/ForwardCommandController}
robot1/*:
  ros__parameters:
    update_rate: 200
    publish_frequency: 30.0
/**/arm_controller:
  ros__parameters: {joints: [shoulder, elbow], interface_name: position}
"""
# the spawner's `--param-file` layout: no controller list, `type:` in each controller's own parameters
SPAWNER = """
joint_state_broadcaster:
  ros__parameters:
    type: joint_state_broadcaster/JointStateBroadcaster
arm_controller:
  ros__parameters:
    type: forward_command_controller/ForwardCommandController
    joints: [shoulder, elbow]
    interface_name: position
"""
ROS1 = """
robot1:
  joint_state_controller:
    type: joint_state_controller/JointStateController
    publish_rate: 200
  arm_controller:
    type: position_controllers/JointGroupPositionController
    joints: [shoulder, elbow]
"""


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    ("text", "broadcaster", "rate"),
    [
        (MANAGER, "joint_state_broadcaster", 200),
        (WILDCARD, "joint_state_broadcaster", 200),
        (NAMESPACED, "joint_state_broadcaster", 200),
        (WILDCARD_PATHS, "joint_state_broadcaster", 200),
        (SPAWNER, "joint_state_broadcaster", 100),
        (ROS1, "joint_state_controller", 200),
    ],
    ids=["manager", "wildcard", "namespaced", "wildcard-paths", "spawner", "ros1"],
)
def test_each_controllers_file_layout_yields_its_controllers_at_their_lines(
    tmp_path: Path, text: str, broadcaster: str, rate: float
) -> None:
    """Each layout a launch uses gives the same two controllers: each is run at the line of its entry (its
    name in the controller list, or its own block with its `type:`), the broadcaster at the controller
    manager's update_rate (default 100 Hz)."""
    path = _write(tmp_path, {"control.yaml": text})
    plugins, said = _plugins(path)
    assert "yields no controller" not in said, said
    # a wildcard node's parameters go to every node: not said as unknown to each controller's type
    assert "is not one of its parameters" not in said, said
    assert set(plugins) == {broadcaster, "arm_controller"}, said
    arm, js = plugins["arm_controller"], plugins[broadcaster]
    assert arm.type == "joint_controller" and arm.params["joints"] == ["shoulder", "elbow"]  # type: ignore[attr-defined]
    assert arm.params["mode"] == "position"  # type: ignore[attr-defined]
    ros1 = text is ROS1
    assert _topics(arm) == ["arm_controller/command" if ros1 else "arm_controller/commands"]
    assert js.type == "joint_states" and js.params["rate"] == rate  # type: ignore[attr-defined]
    for name, p in plugins.items():
        assert p.source_file == str(tmp_path / "control.yaml")  # type: ignore[attr-defined]
        needle = f"{name}:"
        if text is SPAWNER:
            needle = "type:"
            first = _line(text, f"{name}:")
            lines = textwrap.dedent(text).lstrip("\n").splitlines()
            expected = next(i + 1 for i in range(first, len(lines)) if "type:" in lines[i])
        elif text in (MANAGER, NAMESPACED, WILDCARD_PATHS, WILDCARD):
            expected = _line(text, needle)
        else:
            expected = _line(text, needle)
        assert p.source_line == expected, (name, p.source_line, expected)  # type: ignore[attr-defined]


DUPLICATE = """
/**:
  controller_manager:
    ros__parameters:
      update_rate: 50
      joint_state_broadcaster:
        type: joint_state_broadcaster/JointStateBroadcaster
/**:
  controller_manager:
    ros__parameters:
      arm_controller:
        type: forward_command_controller/ForwardCommandController
  arm_controller:
    ros__parameters:
      <<: {joints: [elbow], interface_name: effort}
      joints: [shoulder]
      interface_name: velocity
"""


@pytest.mark.timeout(60)
def test_a_repeated_wildcard_key_is_said_with_both_lines_and_keeps_every_controller(tmp_path: Path) -> None:
    """PyYAML keeps only the last of two `/**:` keys; ROS 2's parameter parser merges them: both
    controllers run, the broadcaster at the first block's update_rate, and the repeat is said (and a key
    overriding a YAML merge key's is not a repeat)."""
    path = _write(tmp_path, {"control.yaml": DUPLICATE})
    plugins, said = _plugins(path)
    assert set(plugins) == {"joint_state_broadcaster", "arm_controller"}, said
    assert plugins["joint_state_broadcaster"].params["rate"] == 50  # type: ignore[attr-defined]
    assert plugins["arm_controller"].params["mode"] == "velocity"  # type: ignore[attr-defined]
    assert plugins["arm_controller"].params["joints"] == ["shoulder"]  # type: ignore[attr-defined]
    assert "key 'joints'" not in said  # a key overriding a `<<:` merge key's is no repeat
    assert "key '/**' at line 7 repeats the one at line 1" in said, said
    assert "rcl_yaml_param_parser" in said and "control.yaml:7" in said, said


@pytest.mark.timeout(60)
def test_a_file_without_controllers_and_an_unknown_type_are_said_where_they_are(tmp_path: Path) -> None:
    """A file yielding no controller says so at its path (not that it lacks a broadcaster); a type we do
    not run is said with its type at its own line; a parameter its type lacks at its line; the controller
    manager's parameters are read or said; so are the control plugin's tags."""
    odd = """
    controller_manager:
      ros__parameters:
        update_rate: 100
        enforce_command_limits: true
        joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
        tool_controller: {type: admittance_controller/AdmittanceController}
    joint_state_broadcaster:
      ros__parameters:
        publish_rate: 10
    """
    empty = """
    robot_state_publisher:
      ros__parameters:
        publish_frequency: 30.0
    """
    path = _write(
        tmp_path,
        {"control.yaml": odd, "empty.yaml": empty},
        controllers="[empty.yaml]",
        duration=0.1,
        ros="<hold_joints>true</hold_joints><no_such_tag>1</no_such_tag>",
    )
    plugins, said = _plugins(path)
    assert set(plugins) == {"joint_state_broadcaster"}
    assert (
        f"{tmp_path / 'control.yaml'}:6: ros_control controller 'tool_controller' "
        "(admittance_controller/AdmittanceController) is not run" in said
    ), said
    assert f"{tmp_path / 'control.yaml'}:9:" in said and "'publish_rate' is not one of its parameters" in said
    assert "'enforce_command_limits' is not used" in said
    assert f"controllers file {str(tmp_path / 'empty.yaml')!r} yields no controller" in said, said
    assert "broadcaster" not in said.split("yields no controller")[1].split("\n")[0]
    # the control plugin's own tags: known ones read, any other said as no parameter of it (its catalogue entry)
    assert "<no_such_tag> is not a parameter of 'gz_ros2_control-system': Gazebo ignores it too" in said, said
    assert "hold_joints" not in said


REMAPPED = """
controller_manager:
  ros__parameters:
    joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    arm_controller: {type: forward_command_controller/ForwardCommandController}
    wrist_controller: {type: forward_command_controller/ForwardCommandController}
arm_controller:
  ros__parameters: {joints: [shoulder], interface_name: position}
wrist_controller:
  ros__parameters: {joints: [elbow], interface_name: position}
joint_state_broadcaster:
  ros__parameters: {use_local_topics: true}
"""


@pytest.mark.timeout(60)
def test_the_control_plugins_remappings_and_namespace_name_every_controller_topic(tmp_path: Path) -> None:
    """`<ros><remapping>` as rcl applies it to each controller node: a relative rule, a node's `~/` rule
    (every controller's own name), an absolute one under the plugin's `<namespace>`, and a rule for one
    node only; the scenario's `controllers:` files get them too; a fork's plugin file is read as its parent."""
    ros = """
      <ros>
        <namespace>/robot1</namespace>
        <remapping>arm_controller/commands:=arm_cmd</remapping>
        <remapping>~/joint_states:=/robot1/states</remapping>
        <remapping>wrist_controller:~/commands:=/wrist_cmd</remapping>
        <remapping>~/dynamic_joint_states:=dyn</remapping>
      </ros>"""
    path = _write(
        tmp_path,
        {"control.yaml": REMAPPED, "spare.yaml": "spare:\n  ros__parameters: {}\n"},
        params="spare.yaml",
        ros=ros,
        plugin="libfranka_ign_ros2_control-system.so",
        controllers="[control.yaml]",
    )
    plugins, said = _plugins(path)
    assert "is read as the ros2_control / ros_control plugin it forks" in said, said
    assert _topics(plugins["arm_controller"]) == ["arm_cmd"]
    assert _topics(plugins["wrist_controller"]) == ["wrist_cmd"]
    assert _topics(plugins["joint_state_broadcaster"]) == ["dyn", "states"]


FORWARD = """
/**:
  controller_manager:
    ros__parameters:
      update_rate: 100
      joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
  arm_controller:
    ros__parameters:
      type: position_controllers/JointGroupPositionController
      joints: [shoulder, elbow]
  joint_state_broadcaster:
    ros__parameters:
      extra_joints: [gripper_dummy]
"""


@pytest.mark.timeout(60)
def test_a_forward_position_controller_moves_the_joints_and_states_are_broadcast(tmp_path: Path) -> None:
    """A JointGroupPositionController from the spawner's layout takes `~/commands` (Float64MultiArray) and
    its joints reach the command; joint_state_broadcaster publishes joint_states (NaN effort where the
    hardware has no effort state interface, the extra joint at 0) and dynamic_joint_states at 100 Hz."""
    timeline = (
        "  - {t: 0.2, topic: r1/arm_controller/commands, type: std_msgs/msg/Float64MultiArray, "
        "data: {data: [0.8, -0.5]}}\n"
    )
    path = _write(tmp_path, {"control.yaml": FORWARD}, duration=2.0, timeline=timeline)
    _, bus = simulate(path)
    states = messages(bus, "r1/joint_states")
    assert 195 <= len(states) <= 201, len(states)
    first, last = states[0][1], states[-1][1]
    # the joints by name, as the controller manager hands them over; the extra joint last
    assert list(last.name) == ["elbow", "shoulder", "gripper_dummy"]
    assert np.allclose(first.position[:2], [0.0, 0.0], atol=0.01)
    # the shoulder carries no gravity load; the elbow sags 0.012 rad under its forearm with the hardware's
    # default servo gains (measured; gains are the hardware layer's)
    assert abs(last.position[1] - 0.8) < 0.005 and abs(last.position[0] + 0.5) < 0.02, last.position
    assert last.position[2] == 0.0
    assert np.isnan(last.effort[1]) and np.isfinite(last.effort[0]) and last.effort[2] == 0.0
    dynamic = messages(bus, "r1/dynamic_joint_states")
    assert len(dynamic) == len(states)
    msg = dynamic[-1][1]
    assert list(msg.joint_names) == ["elbow", "shoulder", "gripper_dummy"]
    assert [list(v.interface_names) for v in msg.interface_values] == [
        ["position", "velocity", "effort"],
        ["position", "velocity"],
        ["position", "velocity", "effort"],
    ]
    assert abs(msg.interface_values[1].values[0] - 0.8) < 0.01


CLIENT = textwrap.dedent(
    """
    import sys, time, zenoh
    from runner.wire import msgs
    from runner.wire.transport import encoding_for, make_config

    endpoint = sys.argv[1]
    deadline = time.monotonic() + 30
    while True:
        try:
            session = zenoh.open(make_config("client", connect=[endpoint]))
            break
        except zenoh.ZError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.1)
    last = []
    with session:
        sub = session.declare_subscriber("cm/r1/joint_states", lambda s: last.append(s.payload.to_bytes()))
        while not last and time.monotonic() < deadline:
            time.sleep(0.02)
        kind = "std_msgs/msg/Float64"
        pub = session.declare_publisher("cm/r1/elbow_controller/command", encoding=encoding_for(kind))
        while time.monotonic() < deadline:
            pub.put(msgs.encode(msgs.from_data(kind, {"data": 0.6}), kind))
            time.sleep(0.05)
            js = msgs.decode(last[-1], "sensor_msgs/msg/JointState")
            if abs(js.position[0] - 0.6) < 0.01:
                break
        sub.undeclare()
        pub.undeclare()
    print(f"elbow={js.position[0]:.4f} names={','.join(js.name)}")
    """
)

ROS1_PID = """
joint_state_controller:
  type: joint_state_controller/JointStateController
  publish_rate: 50
elbow_controller:
  type: effort_controllers/JointPositionController
  joint: elbow
  pid: {p: 60.0, i: 0.0, d: 2.0}
"""


@pytest.mark.timeout(120)
def test_a_ros1_pid_position_controller_is_driven_over_zenoh(tmp_path: Path) -> None:
    """A real run: a separate process publishes std_msgs/Float64 on `<name>/command` of a ROS 1
    effort_controllers/JointPositionController and reads joint_states back until the elbow is there."""
    path = _write(tmp_path, {"control.yaml": ROS1_PID}, duration=20.0)
    path.write_text(path.read_text().replace("rate: max", "rate: realtime"))
    plugins, said = _plugins(path)
    assert plugins["elbow_controller"].params["kp"] == 60.0, said  # type: ignore[attr-defined]
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    mcap = tmp_path / "cm.mcap"
    runner = subprocess.Popen(
        scenario_cmd("run", str(path), "--listen", endpoint, "--record", str(mcap), "-q"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        client = subprocess.run(
            [sys.executable, "-c", CLIENT, endpoint], capture_output=True, text=True, timeout=60
        )
        assert client.returncode == 0, client.stderr
        assert "names=elbow,shoulder" in client.stdout  # by name, as ROS 1's hardware interface lists them
        assert abs(float(client.stdout.split("elbow=")[1].split()[0]) - 0.6) < 0.01
    finally:
        runner.terminate()
        runner.communicate(timeout=30)
    commands = [m for topic, _, _, m in read_mcap(mcap) if topic == "cm/r1/elbow_controller/command"]
    assert commands and commands[0].data == 0.6


SENSORS = """
controller_manager:
  ros__parameters:
    update_rate: 50
    arm_controller: {type: position_controllers/JointGroupPositionController}
    imu_broadcaster: {type: imu_sensor_broadcaster/IMUSensorBroadcaster}
    ft_broadcaster: {type: force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster}
arm_controller:
  ros__parameters: {joints: [shoulder, elbow]}
imu_broadcaster:
  ros__parameters: {sensor_name: forearm_imu, frame_id: fore}
ft_broadcaster:
  ros__parameters: {sensor_name: elbow_ft, frame_id: fore}
"""
GAZEBO_SENSORS = """
  <gazebo reference="fore"><sensor name="forearm_imu" type="imu"><update_rate>50</update_rate></sensor></gazebo>
  <gazebo reference="elbow"><sensor name="elbow_ft" type="force_torque"><update_rate>50</update_rate></sensor></gazebo>
"""


@pytest.mark.timeout(60)
def test_imu_and_force_torque_broadcasters_publish_their_sensors(tmp_path: Path) -> None:
    """imu_sensor_broadcaster publishes `<name>/imu` from the IMU its sensor_name names, and
    force_torque_sensor_broadcaster `<name>/wrench` from the force/torque sensor at the elbow: the held
    forearm (0.3 kg, its centre 0.1 m out) weighs 2.94 N and pulls 0.294 N·m about the elbow."""
    path = _write(tmp_path, {"control.yaml": SENSORS}, duration=1.0)
    (tmp_path / "arm.urdf").write_text(
        (tmp_path / "arm.urdf").read_text().replace("</robot>", GAZEBO_SENSORS + "</robot>")
    )
    plugins, said = _plugins(path)
    assert _topics(plugins["imu_broadcaster"]) == ["imu_broadcaster/imu"], said
    assert _topics(plugins["ft_broadcaster"]) == ["ft_broadcaster/wrench"], said
    _, bus = simulate(path)
    imu = messages(bus, "r1/imu_broadcaster/imu")
    assert 49 <= len(imu) <= 51 and imu[-1][1].header.frame_id == "r1/fore"
    assert abs(imu[-1][1].linear_acceleration.z - 9.81) < 0.2  # held still: the accelerometer reads g
    wrench = messages(bus, "r1/ft_broadcaster/wrench")
    assert 49 <= len(wrench) <= 51 and wrench[-1][1].header.frame_id == "r1/fore"
    w = wrench[-1][1].wrench
    assert abs(abs(w.force.z) - 0.3 * 9.81) < 0.1, w
    assert abs(abs(w.torque.y) - 0.3 * 9.81 * 0.1) < 0.02, w
    # the sensor's own direction, as gazebo_ros2_control reads its Force(): gz-sensors' default
    # child_to_parent, and the opposite wrench with parent_to_child
    (tmp_path / "arm.urdf").write_text(
        (tmp_path / "arm.urdf")
        .read_text()
        .replace(
            "<update_rate>50</update_rate></sensor></gazebo>\n</robot>",
            "<update_rate>50</update_rate><force_torque><measure_direction>parent_to_child"
            "</measure_direction></force_torque></sensor></gazebo>\n</robot>",
        )
    )
    assert "parent_to_child" in (tmp_path / "arm.urdf").read_text()
    _, bus = simulate(path)
    flipped = messages(bus, "r1/ft_broadcaster/wrench")[-1][1].wrench
    assert flipped.force.z == pytest.approx(-w.force.z, abs=0.05), (w, flipped)
    assert flipped.torque.y == pytest.approx(-w.torque.y, abs=0.01), (w, flipped)


@pytest.mark.timeout(60)
def test_several_files_are_read_together_the_later_value_winning(tmp_path: Path) -> None:
    """The description's `<parameters>` file lists the controllers; the scenario's `controllers:` file (what
    the launch's spawner loads) gives one of them its parameters and overrides another's, as a later
    parameter file does."""
    description = """
    controller_manager:
      ros__parameters:
        update_rate: 100
        joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
        arm_controller: {type: forward_command_controller/ForwardCommandController}
    arm_controller:
      ros__parameters: {joints: [shoulder, elbow], interface_name: position}
    """
    launch = """
    /**:
      controller_manager:
        ros__parameters:
          update_rate: 25
      arm_controller:
        ros__parameters: {interface_name: velocity}
      joint_state_broadcaster:
        ros__parameters: {use_urdf_to_filter: false}
    """
    path = _write(tmp_path, {"control.yaml": description, "launch.yaml": launch}, controllers="[launch.yaml]")
    plugins, said = _plugins(path)
    assert set(plugins) == {"joint_state_broadcaster", "arm_controller"}, said
    assert plugins["arm_controller"].params["mode"] == "velocity"  # type: ignore[attr-defined]
    assert plugins["arm_controller"].params["joints"] == ["shoulder", "elbow"]  # type: ignore[attr-defined]
    assert plugins["joint_state_broadcaster"].params["rate"] == 25  # type: ignore[attr-defined]
    # without the URDF filter (Jazzy) the joints keep the order the hardware exports them (as on Humble)
    assert plugins["joint_state_broadcaster"].params["joints"] == ["shoulder", "elbow"]  # type: ignore[attr-defined]
    assert "yields no controller" not in said and "no controller is loaded" not in said, said


@pytest.mark.parametrize(
    ("rule", "namespace", "topic", "expected"),
    [
        ("rosbot_base_controller/cmd_vel_unstamped:=cmd_vel", "", "~/cmd_vel_unstamped", "cmd_vel"),
        ("~/cmd_vel_unstamped:=cmd_vel", "", "rosbot_base_controller/cmd_vel_unstamped", "cmd_vel"),
        (
            "/rosbot/rosbot_base_controller/cmd_vel_unstamped:=/rosbot/cmd_vel",
            "/rosbot",
            "~/cmd_vel_unstamped",
            "cmd_vel",
        ),
        ("rosbot_base_controller:~/odom:=~/odometry", "", "~/odom", "rosbot_base_controller/odometry"),
        ("other_controller:~/odom:=odometry", "", "~/odom", "rosbot_base_controller/odom"),
        ("--ros-args -r /tf:=tf_base", "", "/tf", "tf_base"),
        ("cmd_vel:=x", "", "rosbot_base_controller/cmd_vel", "rosbot_base_controller/cmd_vel"),
    ],
)
def test_a_remapping_names_a_controller_topic_as_rcl_expands_it(
    rule: str, namespace: str, topic: str, expected: str
) -> None:
    """Both sides of a rule are expanded for the controller node using the name (`~` is its own
    namespace), under the plugin's namespace; a `node:` rule is that node's only."""
    from lxml import etree

    from runner.compile.gazebo.base import ReaderBase
    from runner.compile.gazebo.control import ControlContext
    from runner.compile.gazebo.controllers import _ros_rules
    from runner.compile.gazebo.tags import TagReader
    from runner.errors import Notices

    tag = "argument" if rule.startswith("--") else "remapping"
    plugin = etree.fromstring(
        f"<plugin><ros><namespace>{namespace}</namespace><{tag}>{rule}</{tag}></ros></plugin>".encode()
    )
    rules, ns = _ros_rules(TagReader(plugin))
    g = ReaderBase(etree.fromstring(b"<robot/>"), None, [], False, "r1", Notices())
    ctx = ControlContext(g, (None, None), {}, rules, ns, node="rosbot_base_controller")
    assert ctx.topic(topic) == expected


def test_ros2_foxys_joint_state_controller_type_runs_as_the_broadcaster(tmp_path: Path) -> None:
    """ROS 2 Foxy named the broadcaster `joint_state_controller/JointStateController` (a public arm's
    controllers file still does): in a ROS 2 file it is the broadcaster, read with its parameters (it was
    read with ROS 1's table, and compile stopped with a KeyError traceback)."""
    control = """
    controller_manager:
      ros__parameters:
        update_rate: 50
        joint_state_controller:
          type: joint_state_controller/JointStateController
    """
    plugins, said = _plugins(_write(tmp_path, {"control.yaml": control}))
    assert plugins["joint_state_controller"].type == "joint_states", said  # type: ignore[attr-defined]
    assert plugins["joint_state_controller"].params["rate"] == 50  # type: ignore[attr-defined]


def test_a_vendors_fork_of_a_controller_runs_as_its_parent_and_is_said(tmp_path: Path) -> None:
    """Vendors copy a controller into a package of their own (Clearpath's
    `clearpath_mecanum_drive_controller/MecanumDriveController`, a copy of ros2_controllers' mecanum
    controller): same class, the parent's package name inside its own. It runs as the parent, said at
    its line; a type that is no fork stays "not run"."""
    control = """
    controller_manager:
      ros__parameters:
        acme_joint_state_broadcaster.type: acme_joint_state_broadcaster/JointStateBroadcaster
        other: {type: acme_controllers/JointStateBroadcasterish}
    """
    plugins, said = _plugins(_write(tmp_path, {"control.yaml": control}))
    assert plugins["acme_joint_state_broadcaster"].type == "joint_states", said  # type: ignore[attr-defined]
    assert "is run as joint_state_broadcaster/JointStateBroadcaster" in said and "control.yaml:3" in said, (
        said
    )
    assert "'other' (acme_controllers/JointStateBroadcasterish) is not run" in said, said


def test_spawn_runs_only_the_controllers_the_launch_spawns_and_controller_types_give_a_spawners_type(
    tmp_path: Path,
) -> None:
    """A launch spawns some of a file's controllers (one `--inactive`, one not at all), and PAL's give a
    controller's type only on the spawner's command line (`-t`): the robot's `spawn:` and
    `controller_types:` say so. The others are said at their lines, a spawned name no file has at its
    scenario line."""
    control = """
    controller_manager:
      ros__parameters:
        joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
        forward_position_controller: {type: position_controllers/JointGroupPositionController}
    forward_position_controller:
      ros__parameters:
        joints: [shoulder, elbow]
    arm_controller:
      ros__parameters:
        joints: [shoulder, elbow]
        command_interfaces: [position]
        state_interfaces: [position, velocity]
    """
    path = _write(tmp_path, {"control.yaml": control}, params="control.yaml")
    text = path.read_text().replace(
        "    controllers: []\n",
        "    spawn: [joint_state_broadcaster, arm_controller, gripper_controller]\n"
        "    controller_types: {arm_controller: joint_trajectory_controller/JointTrajectoryController}\n",
    )
    path.write_text(text)
    plugins, said = _plugins(path)
    assert set(plugins) == {"joint_state_broadcaster", "arm_controller"}, said
    assert plugins["arm_controller"].type == "joint_trajectory_controller"  # type: ignore[attr-defined]
    assert "'forward_position_controller' is not spawned" in said and "control.yaml:4" in said, said
    assert "`spawn:` names controller 'gripper_controller', which no controllers file has" in said, said
    assert f"{path.name}:9" in said, said  # the scenario line of `spawn:`


def test_a_launch_that_spawns_no_controller_is_said_as_such(tmp_path: Path) -> None:
    """A public arm's Gazebo launch spawns no controller (`spawn: []`): its file's controllers are each
    said as not spawned, and the plugin says why none runs (not that its files have none)."""
    control = """
    controller_manager:
      ros__parameters:
        joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
    """
    path = _write(tmp_path, {"control.yaml": control})
    path.write_text(path.read_text().replace("    controllers: []\n", "    spawn: []\n"))
    plugins, said = _plugins(path)
    assert plugins == {}, said
    assert "'joint_state_broadcaster' is not spawned" in said, said
    assert "the robot's `spawn:` starts none of its controllers" in said, said
    assert "yield no controller" not in said, said
