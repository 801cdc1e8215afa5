"""Gazebo's magnetometer, air pressure, altimeter and force/torque sensors as robot descriptions declare them
(`<sensor type=...>` in `<gazebo reference>` blocks): topics and types, and the values against geometry and
physics, the world stepped in-process (real MuJoCo): a magnetometer's field turns with the robot's yaw,
the pressure falls with height as gz-sensors' atmosphere does, an altimeter follows a free fall, an F/T
sensor under a known mass reads its weight and moment."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from plugins.field_sensors import SDF_MAGNETIC_FIELD
from tests.helpers import compile_with_notices, declared, messages, simulate

G = 9.81  # the scenario world's gravity

ROBOT = """<?xml version="1.0"?>
<robot name="t">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <link name="mast">
    <inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial>
  </link>
  <joint name="mast_joint" type="fixed"><parent link="base_link"/><child link="mast"/>
    <origin xyz="0 0 1.0"/></joint>
  <gazebo reference="base_link">
    <sensor name="mag" type="magnetometer">
      <update_rate>50</update_rate>
      <magnetometer>
        <x><noise type="gaussian"><mean>0</mean><stddev>1e-7</stddev></noise></x>
        <y><noise type="gaussian"><mean>0</mean><stddev>1e-7</stddev></noise></y>
        <z><noise type="gaussian"><mean>0</mean><stddev>1e-7</stddev></noise></z>
      </magnetometer>
    </sensor>
    <sensor name="baro_low" type="air_pressure">
      <update_rate>50</update_rate>
      <air_pressure><reference_altitude>500</reference_altitude></air_pressure>
    </sensor>
    <sensor name="alt" type="altimeter">
      <update_rate>100</update_rate>
      <topic>altimeter</topic>
      <altimeter>
        <vertical_position><noise type="gaussian"><mean>0</mean><stddev>0</stddev></noise></vertical_position>
      </altimeter>
    </sensor>
  </gazebo>
  <gazebo reference="mast">
    <sensor name="baro_high" type="air_pressure">
      <update_rate>50</update_rate>
      <topic>baro/high</topic>
      <air_pressure>
        <reference_altitude>500</reference_altitude>
        <pressure><noise type="gaussian"><mean>0</mean><stddev>0.5</stddev></noise></pressure>
      </air_pressure>
    </sensor>
  </gazebo>
</robot>
"""


def _scenario(
    tmp_path: Path, urdf: str, xyz: tuple[float, float, float], yaw: float, duration: float
) -> Path:
    (tmp_path / "t.urdf").write_text(urdf)
    path = tmp_path / "s.yaml"
    path.write_text(
        f"name: g\nduration: {duration}\nrate: max\nseed: 1\nrobots:\n  - name: bot\n    description: t.urdf\n"
        f"    pose: {{xyz: {list(xyz)}, rpy: [0, 0, {yaw}]}}\n    plugins: []\n"
    )
    return path


def _topics(plan) -> dict[str, str]:  # type: ignore[no-untyped-def]
    return {
        t.key.removeprefix("g/bot/"): t.type
        for p in declared(plan.robots[0])
        for t in p.topics
        if t.key.startswith("g/bot/")
    }


def _pressure(h: float) -> float:
    """The 1976 standard atmosphere's troposphere at geopotential height of `h` m (the model gz-sensors
    takes from RotorS): p0 (T0 / (T0 - L h'))^(-g M / (R L))."""
    hg = 6356766.0 * h / (6356766.0 + h)
    return 101325.0 * (1 - 0.0065 * hg / 288.15) ** (9.80665 * 28.9644 / (8314.32 * 0.0065))


def test_magnetometer_pressure_and_altimeter_of_a_falling_yawed_robot(tmp_path: Path):
    """Dropped from 2 m, yawed 0.7 rad: the field in the sensor frame is the world's turned by -yaw; the
    altimeter reads the fall, -g t²/2 and -g t; the pressure rises as it falls, 1 m above reads less."""
    yaw = 0.7
    path = _scenario(tmp_path, ROBOT, (0.0, 0.0, 2.0), yaw, 0.4)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices and "is ignored" not in notices, notices
    assert _topics(plan) == {
        "magnetometer": "sensor_msgs/msg/MagneticField",
        "air_pressure": "sensor_msgs/msg/FluidPressure",
        "baro/high": "sensor_msgs/msg/FluidPressure",
        "altimeter": "ros_gz_interfaces/msg/Altimeter",
    }
    _, bus = simulate(path)
    mag = messages(bus, "bot/magnetometer")
    assert abs(len(mag) - 20) <= 1
    fx, fy, fz = SDF_MAGNETIC_FIELD
    expected = [fx * math.cos(yaw) + fy * math.sin(yaw), -fx * math.sin(yaw) + fy * math.cos(yaw), fz]
    got = np.array([[m.magnetic_field.x, m.magnetic_field.y, m.magnetic_field.z] for _, m in mag])
    assert np.allclose(got.mean(axis=0), expected, atol=5e-8)
    assert abs(got[:, 0].std() / 1e-7 - 1) < 0.4
    assert mag[-1][1].header.frame_id == "bot/base_link"

    alt = messages(bus, "bot/altimeter")
    t, msg = alt[-1]
    ts = t / 1e9
    assert abs(msg.vertical_reference - 2.0) < 1e-6
    assert abs(msg.vertical_position + 0.5 * G * ts**2) < 0.02
    assert abs(msg.vertical_velocity + G * ts) < 0.05

    low = messages(bus, "bot/air_pressure")
    high = messages(bus, "bot/baro/high")
    for t1, lo in low:
        z = 2.0 - 0.5 * G * (t1 / 1e9) ** 2
        assert abs(lo.fluid_pressure - _pressure(500 + z)) < 0.3
        assert lo.variance == 0.0
    # one metre up: ~11.7 Pa less at 500 m (rho g, rho ~1.17 kg/m³), with 0.5 Pa of noise
    diff = np.array(
        [lo.fluid_pressure - hi.fluid_pressure for (_, lo), (_, hi) in zip(low, high, strict=True)]
    )
    assert abs(diff.mean() - (_pressure(500) - _pressure(501))) < 0.3
    assert 11.0 < _pressure(500) - _pressure(501) < 12.0
    assert high[-1][1].variance == math.sqrt(0.5)  # as gz-sensors writes it


FT_LINKS = """<?xml version="1.0"?>
<robot name="t">
  <link name="base_link">
    <collision><geometry><box size="0.4 0.4 0.1"/></geometry></collision>
    <inertial><mass value="5.0"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <link name="payload">
    <inertial><origin xyz="0.1 0 0"/><mass value="1.5"/>
      <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial>
  </link>
  <joint name="ft_joint" type="fixed"><parent link="base_link"/><child link="payload"/>
    <origin xyz="0 0 0.1" rpy="0.4 0 0"/></joint>
  GAZEBO
</robot>
"""
FT_ROBOT = FT_LINKS.replace(
    "GAZEBO",
    """<gazebo reference="ft_joint">
    <preserveFixedJoint>true</preserveFixedJoint>
    <sensor name="ft" type="force_torque">
      <update_rate>100</update_rate>
      FT_BLOCK
    </sensor>
  </gazebo>""",
)


def test_force_torque_reads_the_weight_and_moment_of_its_payload(tmp_path: Path):
    """1.5 kg held 0.1 m out along the child's x, the joint rolled 0.4 rad: Gazebo's defaults (child frame,
    child_to_parent) read the weight the payload puts on the base, in the payload's frame; `parent` and
    `parent_to_child` turn and flip it."""
    results = {}
    for name, block in (
        ("default", ""),
        (
            "parent",
            "<force_torque><frame>parent</frame><measure_direction>parent_to_child</measure_direction>"
            "</force_torque>",
        ),
    ):
        sub = tmp_path / name
        sub.mkdir()
        path = _scenario(sub, FT_ROBOT.replace("FT_BLOCK", block), (0.0, 0.0, 0.05), 0.0, 0.5)
        plan, notices = compile_with_notices(path)
        assert "not supported" not in notices and "left out" not in notices, notices
        assert _topics(plan) == {"ft/forcetorque": "geometry_msgs/msg/WrenchStamped"}
        _, bus = simulate(path)
        wrenches = messages(bus, "bot/ft/forcetorque")
        assert abs(len(wrenches) - 50) <= 1
        w = wrenches[-1][1].wrench
        results[name] = np.array([w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z])
    m, roll = 1.5, 0.4
    weight_world = np.array([0.0, 0.0, -m * G])  # what the payload puts on the base
    r_child = np.array([[1, 0, 0], [0, math.cos(roll), -math.sin(roll)], [0, math.sin(roll), math.cos(roll)]])
    arm_world = r_child @ np.array([0.1, 0.0, 0.0])
    torque_world = np.cross(arm_world, weight_world)  # about the joint's origin
    default = np.concatenate([r_child.T @ weight_world, r_child.T @ torque_world])
    assert np.allclose(results["default"], default, atol=0.02), results["default"]
    # the base lies flat: its frame is the world's; the wrench the base applies on the payload
    assert np.allclose(results["parent"], -np.concatenate([weight_world, torque_world]), atol=0.02)


def test_force_torque_outside_a_joint_is_left_out(tmp_path: Path):
    urdf = FT_ROBOT.replace('<gazebo reference="ft_joint">', '<gazebo reference="payload">').replace(
        "FT_BLOCK", ""
    )
    path = _scenario(tmp_path, urdf, (0.0, 0.0, 0.05), 0.0, 0.1)
    plan, notices = compile_with_notices(path)
    assert "mounts a force_torque sensor on a joint only" in notices
    assert "ft/forcetorque" not in _topics(plan)


HECTOR_MAG = """
  <gazebo>
    <plugin name="magnetometer" filename="libhector_gazebo_ros_magnetic.so">
      <updateRate>20</updateRate>
      <bodyName>base_link</bodyName>
      <topicName>magnetic</topicName>
      <frameId>base_link</frameId>
      <magnitude>0.5</magnitude>
      <referenceHeading>0</referenceHeading>
      <declination>10</declination>
      <inclination>60</inclination>
      <offset>0.01 0 0</offset>
      <gaussianNoise>0.002 0.002 0.002</gaussianNoise>
    </plugin>
  </gazebo>
"""


def test_hector_magnetometer_turns_its_field_with_the_robot(tmp_path: Path):
    """hector's field (magnitude 0.5, inclination 60°, declination 10°) in the yawed body frame, its offset
    and noise, on a geometry_msgs/Vector3Stamped (hector's default message)."""
    yaw = -1.2
    urdf = ROBOT.replace("</robot>", HECTOR_MAG + "</robot>")
    path = _scenario(tmp_path, urdf, (0.0, 0.0, 0.05), yaw, 2.0)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices and "magnetic" not in notices, notices
    assert _topics(plan)["magnetic"] == "geometry_msgs/msg/Vector3Stamped"
    _, bus = simulate(path)
    mag = messages(bus, "bot/magnetic")
    assert abs(len(mag) - 40) <= 1 and mag[-1][1].header.frame_id == "bot/base_link"
    inc, dec = math.radians(60), math.radians(10)
    world = 0.5 * np.array([math.cos(inc) * math.cos(-dec), math.cos(inc) * math.sin(-dec), -math.sin(inc)])
    c, s = math.cos(yaw), math.sin(yaw)
    body = np.array([c * world[0] + s * world[1], -s * world[0] + c * world[1], world[2]]) + np.array(
        [0.01, 0, 0]
    )
    got = np.array([[m.vector.x, m.vector.y, m.vector.z] for _, m in mag])
    assert np.allclose(got.mean(axis=0), body, atol=0.0015)
    assert abs(got.std(axis=0).mean() / 0.002 - 1) < 0.3


def test_gazebo_ros_ft_sensor_plugins_ros1_and_ros2(tmp_path: Path):
    """ROS 1 `<jointName>`/`<topicName>` and ROS 2 `<joint_name>` (topic `wrench`, remapped): the wrench the
    joint applies on the payload (holding it up), in the payload's frame, at their update rates."""
    m, roll = 1.5, 0.4
    r_child = np.array([[1, 0, 0], [0, math.cos(roll), -math.sin(roll)], [0, math.sin(roll), math.cos(roll)]])
    up = np.array([0.0, 0.0, m * G])  # the joint holds the payload up
    torque = np.cross(r_child @ np.array([0.1, 0.0, 0.0]), up)
    expected = np.concatenate([r_child.T @ up, r_child.T @ torque])
    for name, plugin, topic, rate in (
        (
            "ros1",
            "<robotNamespace>/</robotNamespace><jointName>ft_joint</jointName><topicName>ft</topicName>"
            "<updateRate>50</updateRate><gaussianNoise>0.0</gaussianNoise>",
            "ft",
            50,
        ),
        (
            "ros2",
            "<ros><remapping>wrench:=ft_sensor/wrench</remapping></ros><joint_name>ft_joint</joint_name>"
            "<update_rate>20</update_rate>",
            "ft_sensor/wrench",
            20,
        ),
    ):
        sub = tmp_path / name
        sub.mkdir()
        gz = f'<gazebo><plugin name="ft" filename="libgazebo_ros_ft_sensor.so">{plugin}</plugin></gazebo>'
        path = _scenario(sub, FT_LINKS.replace("GAZEBO", gz), (0.0, 0.0, 0.05), 0.0, 0.5)
        plan, notices = compile_with_notices(path)
        assert not notices, notices
        assert _topics(plan) == {topic: "geometry_msgs/msg/WrenchStamped"}
        _, bus = simulate(path)
        wrenches = messages(bus, f"bot/{topic}")
        assert abs(len(wrenches) - rate * 0.5) <= 1
        msg = wrenches[-1][1]
        assert msg.header.frame_id == "bot/payload"
        w = msg.wrench
        got = [w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z]
        assert np.allclose(got, expected, atol=0.02), (name, got)


SILENT = """<?xml version="1.0"?>
<robot name="t">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <link name="p"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
  </inertial></link>
  <joint name="j" type="fixed"><parent link="base_link"/><child link="p"/></joint>
  <gazebo reference="base_link">
    <sensor name="mag" type="magnetometer"><stray1/>
      <magnetometer><x><noise type="gaussian"><stddev>1e-6</stddev></noise><stray2/></x><stray3/></magnetometer>
    </sensor>
    <sensor name="ap" type="air_pressure">
      <air_pressure><pressure><stray4/></pressure><stray5/></air_pressure>
    </sensor>
    <sensor name="al" type="altimeter"><altimeter><vertical_position><stray6/></vertical_position></altimeter>
    </sensor>
    <sensor name="r" type="ray"><ray><range><min>0.1</min><max>3</max></range></ray>
      <plugin name="x" filename="libgazebo_ros_range.so"><stray7/><topicName>r</topicName></plugin>
    </sensor>
    <sensor name="r2" type="ray"><ray><range><min>0.1</min><max>3</max></range></ray>
      <plugin name="x2" filename="libgazebo_ros_ray_sensor.so"><stray8/><output_type>sensor_msgs/Range</output_type>
      </plugin>
    </sensor>
  </gazebo>
  <gazebo reference="j">
    <sensor name="ft" type="force_torque"><force_torque><force><x><stray9/></x></force><stray10/></force_torque>
    </sensor>
  </gazebo>
  <gazebo><plugin name="ft2" filename="libgazebo_ros_ft_sensor.so"><joint_name>j</joint_name><stray11/></plugin>
  </gazebo>
  <gazebo><plugin name="m" filename="libhector_gazebo_ros_magnetic.so"><updateRate>10</updateRate><stray12/></plugin>
  </gazebo>
</robot>"""


def test_what_these_sensors_and_plugins_do_not_read_is_said(tmp_path: Path):
    """A stray element at every level of each sensor and plugin block is said at its own line."""
    path = _scenario(tmp_path, SILENT, (0.0, 0.0, 0.05), 0.0, 0.1)
    _, notices = compile_with_notices(path)
    lines = SILENT.splitlines()
    for n in range(1, 13):
        line = next(i for i, text in enumerate(lines, 1) if f"<stray{n}/>" in text)
        assert any(f"t.urdf:{line}:" in said and f"<stray{n}>" in said for said in notices.splitlines()), (
            n,
            notices,
        )
