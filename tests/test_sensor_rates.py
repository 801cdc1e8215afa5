"""Update rates as Gazebo runs them: a sensor or plugin asked to run faster than the physics step runs once
a step; the plan's rate (what `scenario validate` lists) says so, with a notice at the tag that set it."""

from __future__ import annotations

from pathlib import Path

from tests.helpers import compile_with_notices, declared, messages, robot_scenario, simulate

ROBOT = """<?xml version="1.0"?>
<robot name="t">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <gazebo reference="base_link">
    <sensor name="bumper" type="contact">
      <update_rate>1000</update_rate>
      <contact><collision>base_link_collision</collision></contact>
      <plugin name="bumper_plugin" filename="libgazebo_ros_bumper.so">
        <bumperTopicName>bumper</bumperTopicName>
        <frameName>base_link</frameName>
      </plugin>
    </sensor>
  </gazebo>
</robot>
"""


def test_a_contact_sensor_above_the_step_runs_once_a_step(tmp_path: Path):
    """<update_rate> 1000 with the 2 ms step: 500 Hz in the plan, the topic and the messages, said at the
    sensor's line."""
    path = robot_scenario(tmp_path, ROBOT, duration=1.0)
    plan, notices = compile_with_notices(path)
    bumper = next(p for p in declared(plan.robots[0]) if p.type == "contact")
    assert bumper.rate == 500.0 and bumper.params["rate"] == 500.0
    assert {t.rate for t in bumper.topics} == {500.0}
    line = ROBOT.splitlines().index('    <sensor name="bumper" type="contact">') + 1
    assert f"t.urdf:{line}" in notices
    assert "its rate 1000 Hz is above the physics step's 500 Hz" in notices
    # validate's "as in Gazebo" block lists it as a rate, not as something ignored
    rate_lines = [said for said in plan.robots[0].gazebo if said.kind == "rate"]
    assert len(rate_lines) == 1 and rate_lines[0].line == line
    _, bus = simulate(path)
    assert abs(len(messages(bus, "bot/bumper")) - 500) <= 1


def test_a_scenario_rate_above_the_step_is_said_at_the_scenario(tmp_path: Path):
    """A scenario's own plugin at 2000 Hz with a 1 ms step: 1000 Hz, said at its `rate:`."""
    path = robot_scenario(
        tmp_path,
        ROBOT.replace("<update_rate>1000</update_rate>", "<update_rate>50</update_rate>"),
        world="  physics: {timestep: 0.001}\n",
        plugins="\n      - type: imu\n        params: {link: base_link, rate: 2000}",
        duration=0.5,
    )
    plan, notices = compile_with_notices(path)
    imu = next(p for p in declared(plan.robots[0]) if p.type == "imu")
    assert imu.rate == 1000.0
    bumper = next(p for p in declared(plan.robots[0]) if p.type == "contact")
    assert bumper.rate == 50.0  # below the step: as asked, and nothing said
    assert "its rate 2000 Hz is above the physics step's 1000 Hz" in notices
    assert "t1.yaml:" in notices and "its rate 50 Hz" not in notices
    _, bus = simulate(path)
    assert abs(len(messages(bus, "bot/imu")) - 500) <= 1
