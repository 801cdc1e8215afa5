"""Motion plugins against real MuJoCo physics: skid_steer, planar_move, joint_controller.

Scenarios are stepped in-process on a MemoryBus (tests/helpers.py); the robots are under tests/data/.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from plugins.joint_controller import JointController
from runner.errors import ScenarioError
from runner.geometry import quat_to_yaw
from runner.plugin import BuildContext
from tests.conftest import DIFFBOT
from tests.helpers import messages, plan_of, simulate

DATA = Path(__file__).parent / "data"
SKIDBOT = DATA / "skidbot.urdf"
LIFTBOT = DATA / "liftbot.urdf"


def _yaw(q: Any) -> float:
    return quat_to_yaw([q.w, q.x, q.y, q.z])


def _at(samples: list[tuple[int, Any]], t: float) -> Any:
    """The message stamped at sim time t."""
    ns = round(t * 1e9)
    return next(m for s, m in samples if s == ns)


# ---------------------------------------------------------------------------------------------- skid_steer
SKID = """
name: t
duration: {duration}
rate: max
robots:
  - name: r1
    description: "{skidbot}"
    pose: {{xyz: [0, 0, 0.065]}}
    plugins: [{{type: skid_steer}}, {{type: ground_truth}}]
timeline:
  - {{t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {cmd}}}
  - {{t: {stop}, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{}}}}
"""


def _skid(write_scenario: Any, cmd: str, stop: float, duration: float) -> tuple[Any, Any]:
    text = SKID.format(skidbot=SKIDBOT, cmd=cmd, stop=stop, duration=duration)
    _, bus = simulate(write_scenario(text))
    return messages(bus, "r1/ground_truth")[-1][1].pose.pose, messages(bus, "r1/odom")[-1][1].pose.pose


@pytest.mark.timeout(30)
def test_skid_steer_drives_four_wheels_straight(write_scenario):
    truth, odom = _skid(write_scenario, "{linear: {x: 0.3}}", 5.0, 6.0)
    # 0.3 m/s for 5 s: 1.5 m (measured 1.491 m, -0.6 %)
    assert abs(truth.position.x - 1.5) < 0.15, truth.position
    assert abs(truth.position.y) < 0.05 and abs(_yaw(truth.orientation)) < 0.05
    assert abs(odom.position.x - truth.position.x) < 0.05  # encoders agree on a straight line


@pytest.mark.timeout(30)
def test_skid_steer_turns_in_place_with_yaw_rate_feedback(write_scenario):
    text = SKID.format(skidbot=SKIDBOT, cmd="{angular: {z: 0.5}}", stop=math.pi, duration=4.0).replace(
        "{type: skid_steer}", "{type: skid_steer, params: {yaw_rate_feedback: true}}"
    )
    _, bus = simulate(write_scenario(text))
    truth = messages(bus, "r1/ground_truth")[-1][1].pose.pose
    odom = messages(bus, "r1/odom")[-1][1].pose.pose
    commanded = math.pi / 2
    # A skid-steered body with isotropic friction scrubs its wheels sideways and, open loop (the default, as
    # Gazebo's plugins drive), turns at about 30 % of what the wheel speeds say on this robot (wheelbase
    # 0.24 m, track 0.30 m, friction 1). The opt-in yaw-rate feedback closes the loop on the body's yaw
    # rate, so the robot turns as commanded; odometry comes from the world.
    yaw = _yaw(truth.orientation)
    assert abs(yaw - commanded) < 0.1 * commanded, yaw
    assert math.hypot(truth.position.x, truth.position.y) < 0.05, truth.position
    assert abs(_yaw(odom.orientation) - yaw) < 0.01


@pytest.mark.timeout(30)
def test_skid_steer_open_loop_turns_less(write_scenario):
    text = SKID.format(skidbot=SKIDBOT, cmd="{angular: {z: 0.5}}", stop=math.pi, duration=4.0).replace(
        "{type: skid_steer}", "{type: skid_steer}"
    )  # open loop is the default
    _, bus = simulate(write_scenario(text))
    yaw = _yaw(messages(bus, "r1/ground_truth")[-1][1].pose.pose.orientation)
    assert 0.1 * math.pi / 2 < yaw < 0.6 * math.pi / 2, yaw  # physics: the body lags the wheels


@pytest.mark.timeout(30)
def test_skid_steer_names_a_missing_wheel_joint(write_scenario):
    text = SKID.format(skidbot=SKIDBOT, cmd="{}", stop=1, duration=1).replace(
        "{type: skid_steer}", "{type: skid_steer, params: {left_joints: [front_left_wheel_joint, nope]}}"
    )
    with pytest.raises(ScenarioError) as e:
        plan_of(write_scenario(text))
    (problem,) = e.value.problems
    assert "no joint 'nope'" in problem.message
    assert problem.path[-1] == "left_joints"


# --------------------------------------------------------------------------------------------- planar_move
PLANAR = """
name: t
duration: {duration}
rate: max
world:
  models: [{models}]
robots:
  - name: side
    description: "{{diffbot}}"
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{{type: planar_move}}, {{type: ground_truth}}]
  - name: ahead
    description: "{{diffbot}}"
    pose: {{xyz: [0, 2, 0.06]}}
    plugins: [{{type: planar_move}}, {{type: ground_truth}}]
timeline:
  - {{t: 0.0, topic: side/cmd_vel, type: geometry_msgs/msg/Twist, data: {side}}}
  - {{t: 0.0, topic: ahead/cmd_vel, type: geometry_msgs/msg/Twist, data: {ahead}}}
  - {{t: {stop}, topic: side/cmd_vel, type: geometry_msgs/msg/Twist, data: {{}}}}
  - {{t: {stop}, topic: ahead/cmd_vel, type: geometry_msgs/msg/Twist, data: {{}}}}
"""


def _planar(
    write_scenario: Any, side: str, ahead: str, stop: float = 5.0, duration: float = 6.0, models: str = ""
) -> Any:
    text = PLANAR.format(side=side, ahead=ahead, stop=stop, duration=duration, models=models)
    _, bus = simulate(write_scenario(text))
    return bus


def _on_the_ground(truth: list[tuple[int, Any]], after: float = 0.5) -> None:
    """The diffbot rests on its 0.05 m wheels, level, and never leaves the ground."""
    for t, m in truth:
        if t >= after * 1e9:
            assert abs(m.pose.pose.position.z - 0.05) < 0.003, (t, m.pose.pose.position)
            q = m.pose.pose.orientation
            assert abs(q.x) < 0.01 and abs(q.y) < 0.01, (t, q)


@pytest.mark.timeout(30)
def test_planar_move_moves_passive_robot_sideways_and_forward(write_scenario):
    bus = _planar(write_scenario, "{linear: {y: 0.3}}", "{linear: {x: 0.3}}")
    side, ahead = messages(bus, "side/ground_truth"), messages(bus, "ahead/ground_truth")
    # steady velocity over 1..5 s (measured 0.2995 m/s sideways, 0.3000 m/s ahead)
    vy = (_at(side, 5.0).pose.pose.position.y - _at(side, 1.0).pose.pose.position.y) / 4.0
    vx = (_at(ahead, 5.0).pose.pose.position.x - _at(ahead, 1.0).pose.pose.position.x) / 4.0
    assert abs(vy - 0.3) < 0.05 * 0.3, vy
    assert abs(vx - 0.3) < 0.05 * 0.3, vx
    # total distance, start and stop included (measured 1.5029 m and 1.5007 m)
    p_side, p_ahead = side[-1][1].pose.pose.position, ahead[-1][1].pose.pose.position
    assert abs(p_side.y - 1.5) < 0.05 * 1.5 and abs(p_side.x) < 0.02, p_side
    assert abs(p_ahead.x - 1.5) < 0.05 * 1.5 and abs(p_ahead.y - 2.0) < 0.02, p_ahead
    assert abs(_yaw(side[-1][1].pose.pose.orientation)) < 0.05  # no turn while sliding the wheels sideways
    _on_the_ground(side)
    _on_the_ground(ahead)
    # odometry: the true pose relative to the start (the start is 0.06 m up; it settles on its wheels)
    odom = messages(bus, "side/odom")
    assert len(odom) == int(6.0 * 50) + 1
    o = odom[-1][1]
    assert (o.header.frame_id, o.child_frame_id) == ("side/odom", "side/base_link")
    assert abs(o.pose.pose.position.y - p_side.y) < 1e-6 and abs(o.pose.pose.position.x - p_side.x) < 1e-6
    assert abs(o.pose.pose.position.z - (0.05 - 0.06)) < 0.003
    moving = _at(odom, 3.0)
    # the true twist, in the base frame (sliding wheels sideways chatters: about ±0.02 m/s)
    assert abs(moving.twist.twist.linear.y - 0.3) < 0.05 and abs(moving.twist.twist.linear.x) < 0.02
    drive = [
        t for _, m in messages(bus, "side/tf") for t in m.transforms if t.child_frame_id == "side/base_link"
    ]
    tf = drive[-1]
    assert tf.header.frame_id == "side/odom"
    assert abs(tf.transform.translation.y - p_side.y) < 1e-6


@pytest.mark.timeout(30)
def test_planar_move_turns_and_follows_an_arc(write_scenario):
    bus = _planar(
        write_scenario, "{angular: {z: 0.5}}", "{linear: {x: 0.3}, angular: {z: 0.5}}", math.pi, 4.0
    )
    side, ahead = messages(bus, "side/ground_truth")[-1][1], messages(bus, "ahead/ground_truth")[-1][1]
    assert abs(_yaw(side.pose.pose.orientation) - math.pi / 2) < 0.05 * math.pi / 2  # measured 1.5806
    p = side.pose.pose.position
    assert math.hypot(p.x, p.y) < 0.01
    # a quarter circle of radius 0.3 / 0.5 = 0.6 m, in the heading frame: ends at (0.6, 2.6)
    p = ahead.pose.pose.position
    assert math.hypot(p.x - 0.6, p.y - 2.6) < 0.05 * 0.6 * math.pi / 2, p  # measured (0.6006, 2.6047)
    assert abs(_yaw(ahead.pose.pose.orientation) - math.pi / 2) < 0.05 * math.pi / 2


@pytest.mark.timeout(30)
def test_planar_move_is_stopped_by_a_wall(write_scenario):
    wall = "{name: wall, shape: box, size: [0.1, 2, 1], pose: {xyz: [1.05, 0, 0.5]}}"
    bus = _planar(write_scenario, "{linear: {x: 0.3}}", "{linear: {x: 0.3}}", models=wall)
    side = messages(bus, "side/ground_truth")
    # The diffbot's chassis reaches 0.10 m ahead of its base: it touches the wall (face at x = 1.0) at
    # x = 0.90 after 3 s, and pushes against it until the command stops at 5 s (measured 0.9003).
    for t in (4.0, 5.0, 6.0):
        x = _at(side, t).pose.pose.position.x
        assert 0.89 < x < 0.905, (t, x)
    _on_the_ground(side)
    # the other robot, with no wall in its way (the wall ends at y = 1), drove on
    assert abs(messages(bus, "ahead/ground_truth")[-1][1].pose.pose.position.x - 1.5) < 0.05 * 1.5


@pytest.mark.timeout(30)
def test_planar_move_stops_when_commands_time_out(write_scenario):
    text = PLANAR.format(side="{linear: {x: 0.3}}", ahead="{}", stop=2.0, duration=2.0, models="")
    text = text.replace("{type: planar_move}", "{type: planar_move, params: {cmd_timeout: 0.5}}", 1)
    _, bus = simulate(write_scenario(text))
    side = messages(bus, "side/ground_truth")
    x_stop = _at(side, 1.0).pose.pose.position.x
    assert abs(x_stop - 0.15) < 0.02, x_stop  # 0.3 m/s until the timeout at 0.5 s
    assert abs(side[-1][1].pose.pose.position.x - x_stop) < 0.005  # and then it stays put


@pytest.mark.timeout(30)
def test_planar_move_needs_a_free_base(write_scenario):
    text = f"""
    name: t
    duration: 1
    robots:
      - name: r1
        description: "{DIFFBOT}"
        fixed: true
        plugins: [{{type: planar_move}}]
    """
    with pytest.raises(ScenarioError, match="no free base"):
        plan_of(write_scenario(text))


# ---------------------------------------------------------------------------------------- joint_controller
LIFT = """
name: t
duration: {duration}
rate: max
robots:
  - name: r1
    description: "{liftbot}"
    fixed: true
    plugins:
      - {{type: joint_states, params: {{rate: 100}}}}
{plugins}
timeline:
{timeline}
"""


def _lift(write_scenario: Any, plugins: str, timeline: str, duration: float = 4.0) -> list[tuple[int, Any]]:
    text = LIFT.format(liftbot=LIFTBOT, plugins=plugins, timeline=timeline, duration=duration)
    _, bus = simulate(write_scenario(text))
    states = messages(bus, "r1/joint_states")
    assert list(states[0][1].name) == ["lift_joint", "turntable_joint", "arm_joint"]
    return states


@pytest.mark.timeout(30)
def test_joint_controller_lift_position_turntable_velocity_arm_position(write_scenario):
    plugins = """
      - {name: lift, type: joint_controller, params: {joints: [lift_joint]}}
      - {name: table, type: joint_controller, params: {joints: [turntable_joint], mode: velocity}}
      - {name: arm, type: joint_controller, params: {joints: [arm_joint]}}
    """
    timeline = """
      - {t: 0.5, topic: r1/lift/command, type: std_msgs/msg/Float64, data: {data: 0.3}}
      - {t: 0.5, topic: r1/table/command, type: std_msgs/msg/Float64, data: {data: 1.0}}
      - {t: 0.5, topic: r1/arm/command, type: std_msgs/msg/Float64, data: {data: 0.5}}
    """
    states = _lift(write_scenario, plugins, timeline)
    # before the command, every joint holds its start (the lift rests at its lower limit, 0)
    # (the arm sags 8.7 mrad under its own weight with the default gains)
    assert np.allclose(_at(states, 0.4).position, [0.0, 0.0, 0.0], atol=0.01)
    # the 3 kg lift reaches 0.3 m and holds it against gravity (measured sag 1.7 mm)
    for t, js in states:
        if t >= 1.5e9:
            assert abs(js.position[0] - 0.3) < 0.01, (t, js.position[0])
    # the turntable turns at 1 rad/s (measured 1.0000); the gravity-loaded arm holds 0.5 rad (0.4923)
    speed = (_at(states, 3.5).position[1] - _at(states, 1.5).position[1]) / 2.0
    assert abs(speed - 1.0) < 0.01, speed
    assert abs(_at(states, 4.0).position[2] - 0.5) < 0.02


@pytest.mark.timeout(30)
def test_joint_controller_array_and_joint_state_commands_respect_limits(write_scenario):
    plugins = """
      - {name: both, type: joint_controller, params: {joints: [lift_joint, arm_joint], initial: [0.2, 0.0]}}
      - name: table
        type: joint_controller
        params: {joints: [turntable_joint], mode: effort, message: joint_state, topic: /table_effort}
    """
    timeline = """
      - {t: 0.5, topic: r1/both/command, type: std_msgs/msg/Float64MultiArray, data: {data: [0.9, -0.4]}}
      - {t: 1.0, topic: table_effort, type: sensor_msgs/msg/JointState,
         data: {name: [arm_joint, turntable_joint], effort: [5.0, 0.05]}}
      - {t: 2.0, topic: table_effort, type: sensor_msgs/msg/JointState,
         data: {name: [turntable_joint], effort: [0.0]}}
    """
    states = _lift(write_scenario, plugins, timeline, duration=3.0)
    assert abs(states[0][1].position[0] - 0.2) < 1e-9  # `initial` is where the lift starts
    assert abs(_at(states, 0.4).position[0] - 0.2) < 0.01
    final = states[-1][1].position
    assert abs(final[0] - 0.5) < 0.01  # 0.9 is clamped to the lift's upper limit
    assert abs(final[2] + 0.4) < 0.02
    # 0.05 N·m for 1 s on the turntable: ω = τ·t / I, with I the inertia it carries (arm at -0.4 rad)
    inertia = (
        0.0016 + 0.0038 * math.cos(0.4) ** 2 + 0.0001 * math.sin(0.4) ** 2 + 0.5 * (0.15 * math.cos(0.4)) ** 2
    )
    omega = _at(states, 2.5).velocity[1]
    assert abs(omega - 0.05 / inertia) < 0.05 * 0.05 / inertia, (omega, 0.05 / inertia)


MJCF = """
<mujoco>
  <worldbody>
    <body name="base">
      <body name="slider"><joint name="lift" type="slide" axis="0 0 1" range="0 1" actuatorfrcrange="-50 50"/>
        <geom size="0.1" mass="1"/></body>
      <body name="wheel"><joint name="spin" type="hinge" axis="0 0 1"/><geom size="0.1" mass="1"/></body>
    </body>
  </worldbody>
  <actuator>
    <position name="lift_servo" joint="lift" kp="400" kv="20"/>
    <motor name="spin_motor" joint="spin"/>
  </actuator>
</mujoco>
"""


@pytest.mark.timeout(30)
def test_joint_controller_reuses_a_fitting_actuator_and_disables_others():
    spec = mujoco.MjSpec.from_string(MJCF)
    ctx = BuildContext(spec=spec, robot="r", namespace="r", root="base")
    params = JointController.Params.model_validate({"joints": ["lift"], "kp": 900})
    topics = JointController.build(params, ctx, "lifter")
    assert [(t.name, t.type, t.direction) for t in topics] == [
        ("lifter/command", "std_msgs/msg/Float64", "sub")
    ]
    params = JointController.Params.model_validate({"joints": ["spin"], "mode": "velocity", "max_effort": 3})
    JointController.build(params, ctx, "spinner")
    model = spec.compile()
    names = [model.actuator(a).name for a in range(model.nu)]
    assert names == ["lift_servo", "spin_motor", "spinner/spin"]  # the position servo was reused
    assert model.actuator_gainprm[0, 0] == 900 and model.actuator_biasprm[0, 1] == -900  # with the new kp
    assert model.actuator_biasprm[0, 2] == -20  # and its own damping
    assert model.actuator_gear[1, 0] == 0  # the motor would fight the velocity servo: disabled
    assert model.actuator_biastype[2] == mujoco.mjtBias.mjBIAS_AFFINE
    assert list(model.actuator_forcerange[2]) == [-3, 3]

    params = JointController.Params.model_validate({"joints": ["lift"], "mode": "effort"})
    spec = mujoco.MjSpec.from_string(MJCF)
    JointController.build(params, BuildContext(spec=spec, robot="r", namespace="r", root="base"), "push")
    model = spec.compile()
    push = model.actuator("push/lift").id
    assert list(model.actuator_forcerange[push]) == [-50, 50]  # the joint's effort limit


@pytest.mark.timeout(30)
def test_joint_controller_rejects_float64_for_several_joints(write_scenario):
    plugins = "      - {type: joint_controller, params: {joints: [lift_joint, arm_joint], message: float64}}"
    text = LIFT.format(liftbot=LIFTBOT, plugins=plugins, timeline="  []", duration=1)
    with pytest.raises(ScenarioError) as e:
        plan_of(write_scenario(text))
    assert e.value.problems[0].path[-1] == "message"
