"""URDF <gazebo> tags: sensors and plugins become ours, materials and friction reach MuJoCo, and what is
not understood is a warning that points at its line."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from runner.compile import compile_plan
from runner.errors import Notices
from runner.scenario.loader import load_file
from runner.scenario.validate import validate_scenario
from tests.helpers import declared, messages, simulate

DATA = Path(__file__).parent / "data" / "gazebo"

CLASSIC = f"""
name: g
duration: 4.0
rate: max
robots:
  - name: bot
    description: {DATA / "classic_bot.urdf"}
    pose: {{xyz: [0, 0, 0.06]}}
timeline:
  - {{t: 0.0, topic: bot/base/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.3}}}}}}
  - {{t: 3.0, topic: bot/base/cmd_vel, type: geometry_msgs/msg/Twist, data: {{}}}}
"""


def _compile(path: Path):  # type: ignore[no-untyped-def]
    doc = load_file(path)
    notices = Notices()
    plan = compile_plan(validate_scenario(doc), doc, notices=notices)
    return plan, notices


def test_classic_plugins_and_sensors_are_mapped(write_scenario):
    plan, _ = _compile(write_scenario(CLASSIC))
    plugins = {p.name: p for p in declared(plan.robots[0])}
    assert set(plugins) == {
        "differential_drive_controller",
        "wheel_joint_states",
        "front_laser",
        "imu_sensor",
    }
    dd = plugins["differential_drive_controller"]
    assert dd.type == "diff_drive"
    assert dd.params["left_joint"] == "wheel_l_joint" and dd.params["wheel_radius"] == 0.05
    assert dd.params["max_wheel_acceleration"] == 20.0  # 1 m/s² at a 0.05 m rim
    assert dd.rate == 40
    lidar = plugins["front_laser"]
    assert lidar.type == "lidar" and lidar.params["samples"] == 180 and lidar.rate == 5.5
    assert lidar.params["range_max"] == 8.0 and lidar.params["noise_stddev"] == 0.01
    assert plugins["imu_sensor"].params["angular_velocity_stddev"] == 0.002
    topics = {t.key: t.type for t in plan.topics()}
    # topic names as the plugins say, under the robot's namespace (a leading '/' does not escape it)
    assert topics["g/bot/base/cmd_vel"] == "geometry_msgs/msg/Twist"
    assert topics["g/bot/front/scan"] == "sensor_msgs/msg/LaserScan"
    assert topics["g/bot/imu/data"] == "sensor_msgs/msg/Imu"
    assert topics["g/bot/odom"] == "nav_msgs/msg/Odometry"
    assert topics["g/bot/joint_states"] == "sensor_msgs/msg/JointState"


def test_materials_and_friction_reach_mujoco(write_scenario):
    plan, _ = _compile(write_scenario(CLASSIC))
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    base = model.body("bot/base_link").id
    geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == base]
    assert all(np.allclose(model.geom_rgba[g], [1, 0, 0, 1]) for g in geoms)  # Gazebo/Red
    caster = model.body("bot/caster").id
    cg = [g for g in range(model.ngeom) if model.geom_bodyid[g] == caster]
    assert all(model.geom_friction[g][0] == 0 for g in cg)


def test_unknown_tags_are_warnings_with_lines_and_hints(write_scenario):
    _, notices = _compile(write_scenario(CLASSIC))
    text = "\n".join(n.render() for n in notices)
    urdf = str(DATA / "classic_bot.urdf")
    assert f"{urdf}:101: plugin 'libmy_custom_thing.so' is not supported" in text
    assert "hint:" in text and "model plugins we map" in text
    assert f"{urdf}:58: <rosDebugLevel>" in text and "(ROS debug level)" in text
    assert f"{urdf}:77: <visualize> in <sensor name='front_laser' type='ray'> is ignored (GUI only)" in text
    # understood tags are not reported
    assert "wheelSeparation" not in text and "topicName" not in text and "mu1" not in text


def test_described_robot_drives_and_publishes_at_declared_rates(write_scenario):
    _, bus = simulate(write_scenario(CLASSIC))
    odom = messages(bus, "bot/odom")
    assert abs(len(odom) - 4.0 * 40) <= 2
    scans = messages(bus, "bot/front/scan")
    assert abs(len(scans) - 4.0 * 5.5) <= 1.5
    assert len(scans[-1][1].ranges) == 180
    assert abs(len(messages(bus, "bot/imu/data")) - 4.0 * 50) <= 2
    x = odom[-1][1].pose.pose.position.x
    assert abs(x - 0.9) < 0.09, x  # 0.3 m/s for 3 s


def test_scenario_plugins_override_and_extend_the_description(write_scenario):
    text = CLASSIC.replace(
        "pose: {xyz: [0, 0, 0.06]}",
        "pose: {xyz: [0, 0, 0.06]}\n    plugins:\n      - {type: lidar, params: {samples: 90, rate: 2}}"
        "\n      - {type: ground_truth}",
    )
    plan, _ = _compile(write_scenario(text))
    plugins = {p.name: p for p in declared(plan.robots[0])}
    assert plugins["front_laser"].params["samples"] == 90  # merged by type: the scenario wins
    assert plugins["front_laser"].params["range_max"] == 8.0  # the rest comes from the description
    assert plugins["front_laser"].rate == 2
    assert "ground_truth" in plugins
    off = text.replace("    plugins:\n", "    plugins_from_description: false\n    plugins:\n")
    plan, _ = _compile(write_scenario(off, "off.yaml"))
    assert sorted(p.type for p in declared(plan.robots[0])) == ["ground_truth", "lidar"]


HARMONIC = """<?xml version="1.0"?>
<robot name="h">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  WHEELS
  <link name="lidar_link">
    <inertial><mass value="0.1"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
  </link>
  <joint name="lidar_joint" type="fixed"><parent link="base_link"/><child link="lidar_link"/>
    <origin xyz="0 0 0.1"/></joint>
  <gazebo>
    <plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">
      <left_joint>left_wheel_joint</left_joint>
      <right_joint>right_wheel_joint</right_joint>
      <wheel_separation>0.3</wheel_separation>
      <wheel_radius>0.05</wheel_radius>
      <odom_publish_frequency>25</odom_publish_frequency>
      <topic>cmd_vel</topic>
      <odom_topic>odom</odom_topic>
      <frame_id>odom</frame_id>
      <child_frame_id>base_link</child_frame_id>
    </plugin>
    <plugin filename="gz-sim-joint-state-publisher-system" name="gz::sim::systems::JointStatePublisher">
      <topic>joint_states</topic>
    </plugin>
    <plugin filename="gz-sim-sensors-system" name="gz::sim::systems::Sensors"/>
  </gazebo>
  <gazebo reference="lidar_link">
    <sensor name="lidar" type="gpu_lidar">
      <update_rate>10</update_rate>
      <topic>scan</topic>
      <gz_frame_id>lidar_link</gz_frame_id>
      <lidar><scan><horizontal><samples>360</samples><min_angle>-3.14</min_angle><max_angle>3.14</max_angle>
      </horizontal><vertical><samples>1</samples><min_angle>0</min_angle><max_angle>0</max_angle></vertical>
      </scan><range><min>0.3</min><max>12</max></range></lidar>
    </sensor>
  </gazebo>
</robot>
"""
WHEEL = """
  <link name="{side}_wheel">
    <collision><geometry><cylinder radius="0.05" length="0.03"/></geometry></collision>
    <inertial><mass value="0.2"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="2e-4"/></inertial>
  </link>
  <joint name="{side}_wheel_joint" type="continuous"><parent link="base_link"/><child link="{side}_wheel"/>
    <origin xyz="0.05 {y} -0.02" rpy="-1.5708 0 0"/><axis xyz="0 0 1"/></joint>
  <transmission name="{side}_trans">
    <type>transmission_interface/SimpleTransmission</type>
    <joint name="{side}_wheel_joint"><hardwareInterface>hardware_interface/VelocityJointInterface</hardwareInterface></joint>
    <actuator name="{side}_motor"><mechanicalReduction>1</mechanicalReduction></actuator>
  </transmission>
"""


def test_harmonic_systems_and_sensors(write_scenario, tmp_path: Path):
    wheels = WHEEL.format(side="left", y=0.15) + WHEEL.format(side="right", y=-0.15)
    (tmp_path / "h.urdf").write_text(HARMONIC.replace("WHEELS", wheels))
    plan, notices = _compile(
        write_scenario(
            "name: h\nrobots:\n  - name: h1\n    description: h.urdf\n    pose: {xyz: [0, 0, 0.1]}\n"
        )
    )
    by_type = {p.type: p for p in declared(plan.robots[0])}
    assert by_type["diff_drive"].rate == 25 and by_type["diff_drive"].params["base_frame"] == "h1/base_link"
    assert by_type["lidar"].params["frame_id"] == "h1/lidar_link"
    assert by_type["lidar"].params["min_angle"] == -3.14
    keys = {t.key for t in plan.topics()}
    assert {"h/h1/cmd_vel", "h/h1/odom", "h/h1/scan", "h/h1/joint_states"} <= keys
    assert not [n for n in notices if "Sensors" in n.message]  # systems we always run are not warnings
    # transmissions whose joints the diff drive drives do not get a second actuator
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    targets = [model.actuator_trnid[a][0] for a in range(model.nu)]
    assert len(targets) == len(set(targets)) == 2


def test_transmissions_become_actuators_for_undriven_joints(tmp_path: Path, write_scenario):
    wheels = WHEEL.format(side="left", y=0.15) + WHEEL.format(side="right", y=-0.15)
    urdf = HARMONIC.replace("WHEELS", wheels)
    start, end = urdf.index("<gazebo>"), urdf.index("</gazebo>") + len("</gazebo>")
    (tmp_path / "t.urdf").write_text(urdf[:start] + urdf[end:])
    plan, _ = _compile(write_scenario("name: t\nrobots:\n  - name: a\n    description: t.urdf\n"))
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    names = sorted(model.actuator(a).name for a in range(model.nu))
    assert names == ["a/left_wheel_joint/velocity", "a/right_wheel_joint/velocity"]
    assert all(model.actuator_biasprm[a][2] < 0 for a in range(model.nu))  # velocity servos


def test_collada_meshes_are_converted(tmp_path: Path, write_scenario):
    import trimesh

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "body.dae").write_bytes(
        trimesh.creation.box((0.4, 0.2, 0.1)).export(file_type="dae")
    )
    (tmp_path / "m.urdf").write_text(
        '<robot name="m"><link name="base_link">'
        '<visual><geometry><mesh filename="meshes/body.dae" scale="2 2 2"/></geometry></visual>'
        '<collision><geometry><box size="0.4 0.2 0.1"/></geometry></collision>'
        '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
        "</inertial></link></robot>"
    )
    plan, _ = _compile(write_scenario("name: m\nrobots:\n  - {name: m, description: m.urdf}\n"))
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    assert model.nmesh == 1
    verts = model.mesh_vert[model.mesh_vertadr[0] : model.mesh_vertadr[0] + model.mesh_vertnum[0]]
    extent = verts.max(axis=0) - verts.min(axis=0)
    assert np.allclose(sorted(extent), sorted([0.8, 0.4, 0.2]), atol=1e-3)  # scale 2 applied


BUMPER = """<?xml version="1.0"?>
<robot name="b">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <gazebo reference="base_link">
    <sensor name="bumper_sensor" type="contact">
      <update_rate>15</update_rate>
      <contact><collision>base_link_collision</collision></contact>
      <plugin name="bumper" filename="libgazebo_ros_bumper.so">
        <bumperTopicName>front_bumper</bumperTopicName>
        <frameName>base_link</frameName>
      </plugin>
    </sensor>
  </gazebo>
</robot>
"""


def test_classic_bumper_becomes_a_contact_plugin(write_scenario, tmp_path: Path):
    (tmp_path / "b.urdf").write_text(BUMPER)
    plan, notices = _compile(write_scenario("name: b\nrobots:\n  - {name: b1, description: b.urdf}\n"))
    (bumper,) = declared(plan.robots[0])
    assert bumper.type == "contact" and bumper.rate == 15
    assert bumper.params["link"] == "base_link" and bumper.params["frame_id"] == "b1/base_link"
    assert {t.key for t in plan.topics()} >= {"b/b1/front_bumper"}
    assert not list(notices)
