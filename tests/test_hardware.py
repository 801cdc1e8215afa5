"""The robot's hardware from `<ros2_control>` / `<transmission>` (issue 36, runner.compile.hardware and
runner.sim.hardware): real compiles and short real runs of small arms written here (bench/hardware.py's
generator), on a MemoryBus."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from bench.hardware import arm_scenario, arm_urdf, hold_drift, step_peak_speed
from plugins._actuators import spec_velocity_limit, velocity_limit
from runner.compile.hardware import add_hardware
from runner.compile.packages import PackageMap
from runner.compile.urdf import urdf_to_model
from runner.errors import Notices
from runner.sim.world import World
from runner.wire.transport import MemoryBus
from tests.helpers import compile_with_notices, messages, plan_of

pytestmark = pytest.mark.timeout(120)


def _line(text: str, needle: str) -> int:
    return next(i for i, row in enumerate(text.split("\n"), 1) if needle in row)


def _positions(bus: MemoryBus) -> np.ndarray:
    """Every joint_states message's positions, in order (j0, j1, j2)."""
    rows = [np.array(msg.position, dtype=float) for _t, msg in messages(bus, "arm/joint_states")]
    assert rows, "no joint_states published"
    return np.array(rows)


def test_an_arm_starts_at_its_initial_values_and_holds_them(tmp_path: Path) -> None:
    """gz_system.cpp resets each joint to its state interface's `initial_value`, and its position servo
    holds it there against gravity: a heavy arm held out sideways drifts no more than 0.005 rad."""
    start = (0.3, -0.5, 0.2)
    path = arm_scenario(
        tmp_path,
        arm_urdf(initial=start),
        duration=2.0,
        plugins="[{type: joint_states, params: {rate: 50}}]",
    )
    bus = MemoryBus()
    world = World(plan_of(path), bus)
    world.run()
    q = _positions(bus)
    assert np.allclose(q[0], start, atol=1e-6), q[0]
    drift = float(np.max(np.abs(q - np.array(start))))
    assert drift <= 0.005, f"drifted {drift:.4f} rad from the initial values"


def test_an_initial_value_outside_the_limits_starts_at_the_limit_and_is_said(tmp_path: Path) -> None:
    urdf = arm_urdf(initial=(3.5, 0.0, 0.0))
    path = arm_scenario(tmp_path, urdf, duration=1.0, plugins="[{type: joint_states, params: {rate: 50}}]")
    plan, text = compile_with_notices(path)
    line = _line(urdf, '<joint name="j0"><command_interface')
    assert f"arm.urdf:{line}" in text and "initial_value 3.5 is outside its limits [-3, 3]" in text, text
    bus = MemoryBus()
    World(plan, bus).run()
    q = _positions(bus)
    # it starts at the limit and stays there: not thrown back through the joint
    assert abs(q[0][0] - 3.0) < 1e-6 and float(np.max(np.abs(q[:, 0] - 3.0))) < 0.01, q[:, 0]


def test_the_effort_limit_bounds_what_holds_the_arm(tmp_path: Path) -> None:
    """Within its URDF effort limit the servo holds the arm's weight; with a limit below what the weight
    takes (~200 N·m at the shoulder) the arm falls, as Gazebo's servo gives no more than the limit."""
    strong, _ = hold_drift(arm_scenario(tmp_path, arm_urdf(effort=1000.0), duration=1.0), 1.0)
    assert strong <= 0.005
    path = arm_scenario(tmp_path, arm_urdf(effort=60.0), duration=1.0)
    weak, _ = hold_drift(path, 1.0)
    assert weak > 0.5, f"an arm whose joints give 60 N·m held its 200 N·m weight (drift {weak:.3f})"
    plan = plan_of(path)
    world = World(plan, MemoryBus())
    m = world.model
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "arm/j0/position")
    assert list(m.actuator_forcerange[a]) == [-60.0, 60.0]
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "arm/j0")
    assert list(m.jnt_actfrcrange[j]) == [-60.0, 60.0]


def test_a_step_command_stays_within_the_velocity_limit(tmp_path: Path) -> None:
    """DART clips a servo's velocity setpoint to the joint's URDF velocity limit (π here): a 2 rad step
    sent to a controller that claims the position interface is followed at π rad/s, no faster (in the
    world's own loop), and reaches its target."""
    plugins = (
        "[{type: joint_controller, name: ctl, params: {joints: [j2], mode: position}},"
        " {type: joint_states, params: {rate: 500}}]"
    )
    timeline = "  - {t: 0.1, topic: arm/ctl/command, type: std_msgs/msg/Float64, data: {data: 2.0}}\n"
    path = arm_scenario(tmp_path, arm_urdf(), duration=1.5, plugins=plugins, timeline=timeline)
    bus = MemoryBus()
    World(plan_of(path), bus).run()
    states = [msg for _t, msg in messages(bus, "arm/joint_states")]
    speed = max(abs(float(m.velocity[2])) for m in states)
    assert 0.9 * math.pi < speed <= 1.02 * math.pi, speed
    assert abs(float(states[-1].position[2]) - 2.0) < 0.01
    # and with the bench's own loop, stepping the hardware every step
    peak = step_peak_speed(arm_scenario(tmp_path, arm_urdf(), duration=1.0), 1.0)
    assert 0.9 * math.pi < peak <= 1.02 * math.pi, peak


GRIPPER = """<?xml version="1.0"?>
<robot name="grip">
  <link name="palm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
  </inertial><collision><geometry><box size="0.1 0.1 0.02"/></geometry></collision></link>
  <link name="left"><inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
  <link name="right"><inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
  <joint name="finger_left" type="prismatic"><parent link="palm"/><child link="left"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.2"/></joint>
  <joint name="finger_right" type="prismatic"><parent link="palm"/><child link="right"/><axis xyz="0 1 0"/>
    <limit lower="-0.04" upper="0" effort="20" velocity="0.2"/>
    <mimic joint="finger_left" multiplier="-1" offset="0"/></joint>
  <ros2_control name="grip_hw" type="system">
    <hardware><plugin>ign_ros2_control/IgnitionSystem</plugin></hardware>
    <joint name="finger_left"><command_interface name="position"/><state_interface name="position"/></joint>
    <joint name="finger_right">
      <param name="mimic">finger_left</param><param name="multiplier">-1</param>
      <command_interface name="position"/><state_interface name="position"/>
    </joint>
  </ros2_control>
</robot>
"""


@pytest.mark.parametrize("urdf_mimic", [True, False], ids=["urdf-mimic", "ros2_control-param-only"])
def test_a_mimic_finger_follows_its_twin_and_has_no_actuator(tmp_path: Path, urdf_mimic: bool) -> None:
    """A URDF `<mimic>` or ign_system's `<param name="mimic">` (with `multiplier`): the follower moves with its
    twin through an equality and has no actuator of its own, even with a command interface."""
    urdf = (
        GRIPPER
        if urdf_mimic
        else GRIPPER.replace('<mimic joint="finger_left" multiplier="-1" offset="0"/>', "")
    )
    (tmp_path / "grip.urdf").write_text(urdf)
    path = tmp_path / "grip.yaml"
    path.write_text(
        "name: g\nduration: 1.0\nrate: max\nseed: 1\nworld:\n  physics: {timestep: 0.001}\n"
        "robots:\n  - name: grip\n    description: grip.urdf\n    fixed: true\n    pose: {xyz: [0, 0, 0.5]}\n"
    )
    world = World(plan_of(path), MemoryBus())
    m, d = world.model, world.data
    targets = {m.joint(int(m.actuator_trnid[a, 0])).name for a in range(m.nu) if m.actuator_gear[a, 0] != 0}
    assert targets == {"grip/finger_left"}
    d.ctrl[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "grip/finger_left/position")] = 0.03
    world.run()
    left, right = (
        float(d.qpos[m.jnt_qposadr[m.joint(f"grip/{j}").id]]) for j in ("finger_left", "finger_right")
    )
    assert abs(left - 0.03) < 0.002 and abs(right + left) < 0.001, (left, right)


def test_a_forked_hardware_plugin_runs_as_its_parent(tmp_path: Path) -> None:
    urdf = arm_urdf(plugin="franka_ign_ros2_control/IgnitionSystem", initial=(0.4, 0.0, 0.0))
    plan, text = compile_with_notices(arm_scenario(tmp_path, urdf, duration=0.1))
    line = _line(urdf, "<plugin>franka_ign_ros2_control")
    assert f"arm.urdf:{line}" in text
    assert "'franka_ign_ros2_control/IgnitionSystem' is run as gz_ros2_control/GazeboSimSystem" in text
    hw = {h.joint: h for h in plan.robots[0].hardware}
    assert hw["j0"].initial_position == 0.4 and hw["j0"].actuators == {"position": "j0/position"}
    lines = [p.text for p in plan.robots[0].gazebo if p.kind == "hardware"]
    assert lines == [
        "gz_ros2_control: j0 (position), j1 (position), j2 (position); 3 start at their "
        "initial_value; position loop 10/s"
    ]


def test_a_hardware_plugin_gazebo_cannot_load_is_said_at_its_line(tmp_path: Path) -> None:
    urdf = arm_urdf(plugin="mock_components/GenericSystem", initial=(0.4, 0.0, 0.0))
    plan, text = compile_with_notices(arm_scenario(tmp_path, urdf, duration=0.1))
    line = _line(urdf, "<plugin>mock_components")
    assert (
        f"arm.urdf:{line}: <ros2_control name='arm_hw'>: hardware plugin 'mock_components/GenericSystem'"
        in text
    )
    assert "its joints get no hardware" in text
    assert plan.robots[0].hardware == []
    world = World(plan, MemoryBus())
    assert world.model.nu == 0


def test_sensors_gpio_and_hardware_params_are_said(tmp_path: Path) -> None:
    extra = '<link name="tool"/><joint name="tool_fix" type="fixed"><parent link="l2"/><child link="tool"/></joint>'
    urdf = arm_urdf(extra=extra, hardware_params='<param name="robot_ip">10.0.0.2</param>').replace(
        "</ros2_control>",
        '<sensor name="tcp_fts"><state_interface name="force.x"/><param name="frame_id">tool</param></sensor>\n'
        '<gpio name="tool_io"><command_interface name="out0"/><state_interface name="in0"/></gpio>\n'
        "</ros2_control>",
    )
    _plan, text = compile_with_notices(arm_scenario(tmp_path, urdf, duration=0.1))
    assert f"arm.urdf:{_line(urdf, '<sensor name=')}: ros2_control sensor 'tcp_fts'" in text, text
    assert f"arm.urdf:{_line(urdf, '<gpio name=')}: ros2_control gpio 'tool_io'" in text
    assert "hardware <param name='robot_ip'> of 'arm_hw' is not read" in text


def test_gains_come_from_the_description_and_the_controllers_file(tmp_path: Path) -> None:
    """gz_ros2_control's `<position_proportional_gain>` and the controller manager's update rate set the
    position loop; ROS 1's `gazebo_ros_control/pid_gains` set a transmission joint's P and D."""
    gazebo = (
        '<gazebo><plugin filename="gz_ros2_control-system" name="gz_ros2_control::GazeboSimROS2ControlPlugin">'
        "<position_proportional_gain>0.5</position_proportional_gain></plugin></gazebo>"
    )
    controllers = "controller_manager:\n  ros__parameters:\n    update_rate: 40\n"
    path = arm_scenario(tmp_path, arm_urdf(gazebo=gazebo), duration=0.1, controllers=controllers)
    plan = plan_of(path)
    assert {h.loop_gain for h in plan.robots[0].hardware} == {20.0}
    world = World(plan, MemoryBus())
    m = world.model
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "arm/j1/position")
    assert m.actuator_gainprm[a, 0] == pytest.approx(-20.0 * m.actuator_biasprm[a, 2])

    ros1 = arm_urdf().split("<ros2_control")[0] + (
        '<transmission name="t1"><type>transmission_interface/SimpleTransmission</type>'
        '<joint name="j1"><hardwareInterface>hardware_interface/PositionJointInterface</hardwareInterface>'
        '</joint><actuator name="m1"><mechanicalReduction>50</mechanicalReduction></actuator></transmission>'
        '<gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so">'
        "<robotSimType>vendor_hw/VendorRobotHWSim</robotSimType></plugin></gazebo>"
        "</robot>"
    )
    controllers = "arm:\n  gazebo_ros_control:\n    pid_gains:\n      j1: {p: 3000.0, i: 0.0, d: 40.0}\n"
    path = arm_scenario(tmp_path, ros1, duration=0.1, controllers=controllers)
    plan, text = compile_with_notices(path)
    assert "mechanicalReduction 50 is not applied" in text
    assert "robotSimType 'vendor_hw/VendorRobotHWSim' is run as gazebo_ros_control/DefaultRobotHWSim" in text
    world = World(plan, MemoryBus())
    m = world.model
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "arm/j1/position")
    assert (m.actuator_gainprm[a, 0], m.actuator_biasprm[a, 2], m.actuator_gear[a, 0]) == (3000.0, -40.0, 1.0)


def test_a_controller_claims_the_hardware_actuator(tmp_path: Path) -> None:
    """plugins/_actuators.py's contract: the hardware's actuators exist before plugins are built, so a
    controller reuses `<joint>/<interface>` instead of adding its own (and its commands move the arm)."""
    plugins = "[{type: joint_controller, name: arm_ctl, params: {joints: [j2], mode: position}}]"
    path = arm_scenario(
        tmp_path,
        arm_urdf(),
        duration=1.5,
        plugins=plugins,
        timeline="  - {t: 0.1, topic: arm/arm_ctl/command, type: std_msgs/msg/Float64, data: {data: 0.5}}\n",
    )
    world = World(plan_of(path), MemoryBus())
    m, d = world.model, world.data
    names = [m.actuator(a).name for a in range(m.nu)]
    assert names == ["arm/j0/position", "arm/j1/position", "arm/j2/position"]
    world.run()
    assert abs(float(d.qpos[m.jnt_qposadr[m.joint("arm/j2").id]]) - 0.5) < 0.01


def test_a_joint_with_two_command_interfaces_is_held_by_its_position_one_until_claimed(
    tmp_path: Path,
) -> None:
    """ros2_control lets a controller claim one of a joint's command interfaces: the hardware's velocity
    actuator waits disabled (its position one holds the joint) and is the one a velocity controller gets."""
    urdf = arm_urdf().replace(
        '<joint name="j2"><command_interface name="position"/>',
        '<joint name="j2"><command_interface name="velocity"/><command_interface name="position"/>',
    )
    plugins = "[{type: joint_controller, name: spin, params: {joints: [j2], mode: velocity}}]"
    timeline = "  - {t: 0.1, topic: arm/spin/command, type: std_msgs/msg/Float64, data: {data: 0.5}}\n"
    path = arm_scenario(tmp_path, urdf, duration=1.1, plugins=plugins, timeline=timeline)
    world = World(plan_of(path), MemoryBus())
    m, d = world.model, world.data
    gears = {m.actuator(a).name: float(m.actuator_gear[a, 0]) for a in range(m.nu)}
    assert gears == {
        "arm/j0/position": 1.0,
        "arm/j1/position": 1.0,
        "arm/j2/velocity": 1.0,
        "arm/j2/position": 0.0,
    }
    # the URDF velocity limit, as a drive reads it (plugins/_actuators.py)
    assert velocity_limit(m, m.joint("arm/j2").id) == pytest.approx(math.pi)
    assert velocity_limit(m, m.joint("arm/j1").id) is None  # a position interface only: not carried
    world.run()
    dof = m.jnt_dofadr[m.joint("arm/j2").id]
    assert abs(float(d.qvel[dof]) - 0.5) < 0.01


def test_mistakes_in_a_ros2_control_block_are_said_at_their_lines_and_the_rest_runs(tmp_path: Path) -> None:
    urdf = arm_urdf(initial=None).replace(
        '<joint name="j0"><command_interface name="position"/>',
        '<joint name="j0"><param name="mimic">nothere</param>'
        '<command_interface name="position"><param name="min">abc</param></command_interface>'
        '<state_interface name="position"><param name="initial_value">abc</param></state_interface>',
    )
    urdf = urdf.replace(
        '<joint name="j1"><command_interface name="position"/>',
        '<joint name="j1"><command_interface name="foo"/><command_interface name="position"/>',
    )
    plan, text = compile_with_notices(arm_scenario(tmp_path, urdf, duration=0.2))
    j0, j1 = (
        _line(urdf, '<joint name="j0"><param'),
        _line(urdf, '<joint name="j1"><command_interface name="foo"'),
    )
    for said in (
        f"arm.urdf:{j0}: joint 'j0': position <param name='min'> 'abc' is not a number; ignored",
        f"arm.urdf:{j0}: joint 'j0': initial_value 'abc' of 'position' is not a number; ignored",
        f"arm.urdf:{j0}: joint 'j0' mimics 'nothere', which the robot does not have",
        f"arm.urdf:{j1}: joint 'j1': command interface 'foo' is not one Gazebo's system has",
    ):
        assert said in text, text
    hw = {h.joint: h.actuators for h in plan.robots[0].hardware}
    assert hw == {
        "j0": {"position": "j0/position"},
        "j1": {"position": "j1/position"},
        "j2": {"position": "j2/position"},
    }
    World(plan, MemoryBus()).run()


def test_a_drive_reads_the_velocity_limit_from_the_hardware_at_build_time(tmp_path: Path) -> None:
    """A controller's `build` sees the robot's MjSpec only: the hardware's velocity actuator carries the URDF
    velocity limit there (its control range), for `spec_velocity_limit`."""
    urdf = arm_urdf(interface="velocity", velocity=2.5)
    model = urdf_to_model(urdf, None, PackageMap.for_scenario(tmp_path, {}))
    add_hardware(model, Notices(), 0.001)
    assert spec_velocity_limit(model.spec, "j1") == 2.5
    assert spec_velocity_limit(model.spec, "l1") is None


def test_a_damped_light_joint_follows_its_servo_as_gazebos_velocity_constraint_does(tmp_path: Path) -> None:
    """A light distal link on a joint with URDF <dynamics damping="50">: DART's servo is a velocity
    constraint, which overrides the damping within the effort limit; a servo whose damping came from the
    link's inertia alone was weaker than the joint's own damping (a public 7-DoF arm's wrist crept to 0.098
    of a 0.3 rad goal in 4 s). The joint's damping is added to the servo's: a 0.3 rad step is reached."""
    urdf = arm_urdf(masses=(10.0, 8.0, 0.05))
    at = urdf.index('<joint name="j2" type="revolute">')
    end = urdf.index("</joint>", at)
    urdf = urdf[:end] + '<dynamics damping="50"/>' + urdf[end:]
    plugins = (
        "[{type: joint_controller, name: ctl, params: {joints: [j2], mode: position}},"
        " {type: joint_states, params: {rate: 100}}]"
    )
    timeline = "  - {t: 0.1, topic: arm/ctl/command, type: std_msgs/msg/Float64, data: {data: 0.3}}\n"
    path = arm_scenario(tmp_path, urdf, duration=1.5, plugins=plugins, timeline=timeline)
    bus = MemoryBus()
    World(plan_of(path), bus).run()
    states = [(t / 1e9, msg) for t, msg in messages(bus, "arm/joint_states")]
    at_1s = next(float(m.position[2]) for t, m in states if t >= 1.1)
    assert abs(at_1s - 0.3) < 0.01, f"the damped joint was at {at_1s:.3f} of 0.3 rad 1 s after the step"


def test_gazebo_classic_sets_position_and_velocity_without_the_effort_limit(tmp_path: Path) -> None:
    """gazebo_ros2_control (Gazebo classic) writes position commands with Joint::SetPosition and velocity
    commands with Joint::SetVelocity (SetVelocityMaximal: no force, no force limit), where gz_ros2_control's
    DART servo stops at the effort limit: the arm whose 60 N·m joints cannot hold its 200 N·m weight under
    gz_ros2_control (test above) is held under the classic plugin, and its effort actuator keeps the limit."""
    urdf = arm_urdf(effort=60.0, plugin="gazebo_ros2_control/GazeboSystem")
    held, _ = hold_drift(arm_scenario(tmp_path, urdf, duration=1.0), 1.0)
    assert held <= 0.005, f"the classic plugin's arm drifted {held:.3f} rad"
    urdf = arm_urdf(effort=60.0, plugin="gazebo_ros2_control/GazeboSystem", interface="effort")
    plan = plan_of(arm_scenario(tmp_path, urdf, duration=0.1))
    m = World(plan, MemoryBus()).model
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "arm/j0/effort")
    assert list(m.actuator_forcerange[a]) == [-60.0, 60.0]  # SetForce is clamped to the limit there too


def test_command_interface_min_max_apply_only_where_ros2_control_enforces_them(tmp_path: Path) -> None:
    """Gazebo's systems never read a command interface's `min`/`max`; ros2_control clamps commands to them
    only with the controller manager's `enforce_command_limits` (false by default on Humble and Jazzy). A
    public base's wheels (max 1 rad/s) crawled at 0.09 m/s with them applied, where Gazebo drives them at
    3 rad/s: not applied, said at their line; applied when the manager enforces them."""
    urdf = arm_urdf(interface="velocity").replace(
        '<joint name="j0"><command_interface name="velocity"/>',
        '<joint name="j0"><command_interface name="velocity"><param name="min">-1</param>'
        '<param name="max">1</param></command_interface>',
    )
    manager = "controller_manager:\n  ros__parameters:\n    update_rate: 100\n"
    for enforce, expected in ((None, False), ("true", True)):
        text = manager + (f"    enforce_command_limits: {enforce}\n" if enforce else "")
        path = arm_scenario(tmp_path, urdf, duration=0.1, controllers=text)
        plan, said = compile_with_notices(path)
        m = World(plan, MemoryBus()).model
        a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "arm/j0/velocity")
        limited = bool(m.actuator_ctrllimited[a]) and list(m.actuator_ctrlrange[a]) == [-1.0, 1.0]
        assert limited == expected, (enforce, list(m.actuator_ctrlrange[a]), said)
        assert ("command min/max are not applied" in said) != expected, said


def test_an_arm_on_a_free_base_holds_its_pose_and_the_base_carries_its_weight(tmp_path: Path) -> None:
    """A mobile manipulator (or an arm Gazebo spawns standing free): its links' weight cannot go through
    MuJoCo's gravity compensation, which would lift the base too; DART's servo holds them all the same.
    Their bias torques are applied on the arm's joints only: the arm holds its initial_values within
    0.005 rad (a public 7-DoF arm standing free missed a trajectory's goal by 0.031 rad), and the ground
    still carries the whole robot's weight."""
    urdf = arm_urdf(masses=(4.0, 3.0, 2.0), initial=(-0.3, 0.4, 0.2)).replace(
        '<inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>',
        '<inertial><mass value="300"/><inertia ixx="30" iyy="30" izz="30" ixy="0" ixz="0" iyz="0"/>'
        '</inertial><collision><geometry><box size="1.4 1.4 0.1"/></geometry></collision>',
    )
    path = arm_scenario(tmp_path, urdf, duration=2.0, plugins="[{type: joint_states, params: {rate: 50}}]")
    path.write_text(path.read_text().replace("    fixed: true\n", "").replace("[0, 0, 1.5]", "[0, 0, 0.06]"))
    bus = MemoryBus()
    world = World(plan_of(path), bus)
    world.run()
    q = _positions(bus)
    drift = float(np.max(np.abs(q[10:] - np.array([-0.3, 0.4, 0.2]))))
    assert drift <= 0.005, f"the arm on a free base drifted {drift:.4f} rad"
    m, d = world.model, world.data
    support = 0.0
    force = np.zeros(6)
    for i in range(d.ncon):
        mujoco.mj_contactForce(m, d, i, force)
        support += force[0]
    weight = float(sum(m.body_mass)) * 9.81
    assert abs(support / weight - 1.0) < 0.01, support / weight  # nothing lifts the base


TRIKE = """<?xml version="1.0"?>
<robot name="trike">
  <link name="chassis">
    <inertial><mass value="1"/><inertia ixx="0.1" iyy="0.4" izz="0.48" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="2 1 0.5"/></geometry></collision>
  </link>
  {rear}
  <link name="steering_link">
    <inertial><mass value="0.005"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="steering_joint" type="continuous">
    <parent link="chassis"/><child link="steering_link"/><origin xyz="0.9 0 -0.2"/><axis xyz="0 0 1"/>
  </joint>
  <link name="front_wheel">
    <inertial><mass value="15"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="0.3" length="0.08"/></geometry></collision>
  </link>
  <joint name="traction_joint" type="continuous">
    <parent link="steering_link"/><child link="front_wheel"/><axis xyz="0 1 0"/>
  </joint>
  <ros2_control name="trike" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    <joint name="steering_joint"><command_interface name="position"/><state_interface name="position"/></joint>
    <joint name="traction_joint"><command_interface name="velocity"/><state_interface name="velocity"/></joint>
  </ros2_control>
</robot>
"""


def test_a_steering_step_without_an_effort_limit_turns_the_wheel_without_flinging_the_robot(
    tmp_path: Path,
) -> None:
    """gz_ros2_control's demo tricycle: a 1 kg chassis, a 15 kg steered front wheel, no effort limits. A
    1 rad steering command: DART's servo turns the wheel at its velocity setpoint (loop gain x error), the
    force that takes within a step. A servo 50 times stiffer put kp x error = 129 kN·m into one step, which
    the contact solver met in full: the robot was flung off the ground spinning at 10 rad/s."""
    rear = "".join(
        f'<link name="{s}_wheel"><inertial><mass value="2"/><inertia ixx="0.15" iyy="0.15" izz="0.125" '
        'ixy="0" ixz="0" iyz="0"/></inertial><collision><origin rpy="1.5708 0 0"/><geometry>'
        '<cylinder radius="0.3" length="0.08"/></geometry></collision></link>'
        f'<joint name="{s}_wheel_joint" type="continuous"><parent link="chassis"/><child link="{s}_wheel"/>'
        f'<origin xyz="-0.8 {y} -0.2"/><axis xyz="0 1 0"/></joint>'
        for s, y in (("left", 0.5), ("right", -0.5))
    )
    (tmp_path / "trike.urdf").write_text(TRIKE.format(rear=rear))
    path = tmp_path / "trike.yaml"
    path.write_text(
        "name: trike\nduration: 2.0\nrate: max\nrobots:\n  - name: r1\n    description: trike.urdf\n"
        "    pose: {xyz: [0, 0, 0.52]}\n"
        "    plugins: [{type: joint_controller, name: steer, params: {joints: [steering_joint]}},"
        " {type: ground_truth, params: {rate: 100}}]\n"
        "timeline:\n  - {t: 0.5, topic: r1/steer/command, type: std_msgs/msg/Float64, data: {data: 1.03}}\n"
    )
    bus = MemoryBus()
    World(plan_of(path), bus).run()
    truth = [m for _t, m in messages(bus, "r1/ground_truth")]
    spin = max(abs(float(m.twist.twist.angular.z)) for m in truth)
    lift = max(float(m.pose.pose.position.z) for m in truth[60:])
    assert spin < 2.0, f"the chassis spun at {spin:.2f} rad/s"
    assert lift < 0.6, f"the robot was thrown {lift:.2f} m up"
