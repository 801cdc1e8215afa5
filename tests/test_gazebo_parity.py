"""Robots as people write them for Gazebo behave as in Gazebo: one test robot per class of failure that
public descriptions showed (self-collision, inertias MuJoCo refuses, blocks naming links that xacro
arguments removed, several wheels per side, publish rates that are not control rates, Gazebo's topic
names, skid steer), and the motion each drive type must reproduce.

The robots are written here for these tests, as URDF text; scenarios run in-process on real MuJoCo
(tests/helpers.py).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from runner.errors import ScenarioError
from runner.geometry import quat_to_yaw
from tests.helpers import compile_with_notices, declared, messages, plan_of, simulate

# ------------------------------------------------------------------------------------------ the robots
_INERTIA = '<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/>'


def _wheel(name: str, parent: str, xyz: str, radius: float = 0.05, mass: float = 0.5, extra: str = "") -> str:
    i = mass * radius**2 / 2
    return f"""
  <link name="{name}">
    <inertial><mass value="{mass}"/>{_INERTIA.format(i=i)}</inertial>
    <collision><origin rpy="1.5708 0 0"/><geometry><cylinder radius="{radius}" length="0.03"/></geometry></collision>
    <visual><origin rpy="1.5708 0 0"/><geometry><cylinder radius="{radius}" length="0.03"/></geometry></visual>
  </link>
  <joint name="{name}_joint" type="continuous">
    <parent link="{parent}"/><child link="{name}"/><origin xyz="{xyz}"/><axis xyz="0 1 0"/>
  </joint>
  <gazebo reference="{name}"><mu1>1.0</mu1><mu2>1.0</mu2>{extra}</gazebo>"""


BASE = """
  <link name="base_link">
    <inertial><origin xyz="-0.03 0 0"/><mass value="5"/>
      <inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision>
  </link>"""

# A swivel caster: the ball's top is 4 cm inside the base's box, as in many descriptions whose caster
# meshes overlap the chassis. The ball and the base are not joined to each other (the swivel is between).
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
  <gazebo reference="caster"><mu1>0</mu1><mu2>0</mu2>{extra}</gazebo>"""

CLASSIC_DRIVE = """
  <gazebo>
    <plugin name="diff_drive" filename="libgazebo_ros_diff_drive.so">
      <update_rate>50</update_rate>
      <left_joint>left_wheel_joint</left_joint>
      <right_joint>right_wheel_joint</right_joint>
      <wheel_separation>0.34</wheel_separation>
      <wheel_diameter>0.1</wheel_diameter>
      <max_wheel_torque>20</max_wheel_torque>
      <publish_wheel_tf>true</publish_wheel_tf>
    </plugin>
  </gazebo>"""

GZ_DRIVE = """
  <gazebo>
    <plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">
      <left_joint>left_wheel_joint</left_joint>
      <right_joint>right_wheel_joint</right_joint>
      <wheel_separation>0.34</wheel_separation>
      <wheel_radius>0.05</wheel_radius>
      <odom_publish_frequency>1</odom_publish_frequency>
    </plugin>
  </gazebo>"""


def diffbot(
    drive: str = CLASSIC_DRIVE,
    *,
    inertia: tuple[float, float, float] = (0.05, 0.07, 0.1),
    wheel_mass: float = 0.5,
    caster_extra: str = "",
    extra: str = "",
) -> str:
    """A 5.3 kg differential-drive robot whose wheels carry the weight, with a ball caster behind."""
    ixx, iyy, izz = inertia
    body = BASE.format(ixx=ixx, iyy=iyy, izz=izz)
    wheels = _wheel("left_wheel", "base_link", "0 0.17 -0.05", mass=wheel_mass) + _wheel(
        "right_wheel", "base_link", "0 -0.17 -0.05", mass=wheel_mass
    )
    return f'<?xml version="1.0"?>\n<robot name="testbot">{body}{wheels}{CASTER.format(extra=caster_extra)}{drive}{extra}\n</robot>\n'


SCENARIO = """
name: t
duration: {duration}
rate: max
seed: 3
world:
  models:
    - {{name: wall, shape: box, size: [0.2, 4, 1], pose: {{xyz: [4, 0, 0.5]}}}}
robots:
  - name: r1
    description: robot.urdf
    pose: {{xyz: [0, 0, {z}]}}
    plugins: [{{type: ground_truth, params: {{rate: 100}}}}{plugins}]
timeline:
{timeline}
"""


def _cmd(t: float, topic: str, lin: float = 0.0, ang: float = 0.0) -> str:
    return (
        f"  - {{t: {t}, topic: r1/{topic}, type: geometry_msgs/msg/Twist, "
        f"data: {{linear: {{x: {lin}}}, angular: {{z: {ang}}}}}}}\n"
    )


def _write(
    tmp_path: Path, urdf: str, duration: float, timeline: str = "  []", z: float = 0.1, plugins: str = ""
) -> Path:
    (tmp_path / "robot.urdf").write_text(urdf)
    path = tmp_path / "scenario.yaml"
    path.write_text(SCENARIO.format(duration=duration, timeline=timeline, z=z, plugins=plugins))
    return path


def _truth(bus: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, xyz, yaw) of the robot's true pose, and its tilt, from the ground_truth plugin."""
    samples = messages(bus, "r1/ground_truth")
    t = np.array([s / 1e9 for s, _ in samples])
    pos = np.array(
        [[m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z] for _, m in samples]
    )
    quats = [m.pose.pose.orientation for _, m in samples]
    yaw = np.unwrap([quat_to_yaw([q.w, q.x, q.y, q.z]) for q in quats])
    tilt = np.array([2 * math.asin(min(1.0, math.hypot(q.x, q.y))) for q in quats])
    return t, np.column_stack([pos, yaw]), tilt


def _at(t: np.ndarray, values: np.ndarray, when: float) -> Any:
    return values[int(np.argmin(abs(t - when)))]


def _drive_and_turn(tmp_path: Path, urdf: str, topic: str = "cmd_vel") -> tuple[float, float, float, float]:
    """The issue's protocol: 2 s standing, 0.2 m/s for 5 s, 0.5 rad/s for 3 s. Returns the standing drift
    (m), the standing tilt (rad), the straight distance (m) and the yaw turned (rad)."""
    timeline = _cmd(2.0, topic, lin=0.2) + _cmd(7.0, topic) + _cmd(8.0, topic, ang=0.5) + _cmd(11.0, topic)
    _, bus = simulate(_write(tmp_path, urdf, 12.5, timeline))
    t, pose, tilt = _truth(bus)
    still = t <= 2.0
    drift = float(np.max(np.linalg.norm(pose[still, :2] - pose[0, :2], axis=1)))
    straight = float(np.linalg.norm(_at(t, pose, 8.0)[:2] - _at(t, pose, 2.0)[:2]))
    turned = float(_at(t, pose, 12.5)[3] - _at(t, pose, 8.0)[3])
    return drift, float(np.max(tilt[still])), straight, turned


# ----------------------------------------------------------------------------------- 1. self-collision
@pytest.mark.timeout(60)
def test_links_of_one_robot_do_not_collide_unless_gazebo_says_so(tmp_path: Path):
    """The caster's ball sits 4 cm inside the base's box. Gazebo collides no two links of a model without
    <self_collide>: the robot stands still. With <selfCollide> on the ball, Gazebo (and we) collide them:
    validate says it starts inside itself, and the robot is shoved."""
    _, bus = simulate(_write(tmp_path, diffbot(), 2.0))
    _, pose, tilt = _truth(bus)
    assert np.max(np.linalg.norm(pose[:, :3] - pose[0, :3], axis=1)) < 0.01
    assert np.max(tilt) < 0.01

    on = diffbot(caster_extra="<selfCollide>true</selfCollide>")
    plan, text = compile_with_notices(_write(tmp_path, on, 2.0))
    assert "robot 'r1' starts 0.04 m inside its own 'r1/" in text and "(self-collision is on)" in text, text
    collide = [line for line in plan.robots[0].gazebo if line.kind == "collide"]
    assert "self-collision on for caster" in collide[0].text and collide[0].line, collide
    assert ("r1/base_link", "r1/caster") in _touching(plan.mjcf)
    assert ("r1/base_link", "r1/caster") not in _touching(
        compile_with_notices(_write(tmp_path, diffbot(), 2.0))[0].mjcf
    )


def _touching(mjcf: str) -> set[tuple[str, ...]]:
    """The body pairs in contact at t = 0."""
    import mujoco

    m = mujoco.MjModel.from_xml_string(mjcf)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    return {
        tuple(
            sorted(
                mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g]))
                for g in (c.geom1, c.geom2)
            )
        )
        for c in d.contact[: d.ncon]
    }


def test_model_self_collide_and_joined_links(tmp_path: Path):
    """Model-level <self_collide> switches it on for every link; links joined by a joint (a wheel and the
    base, a wheel and the bumper that a fixed joint lumps into the base) or lumped together (the bumper and
    the base) still never collide; the two wheels do, and so do the ball and the base."""
    bumper = """
  <link name="bumper"><collision><geometry><box size="0.05 0.3 0.05"/></geometry></collision></link>
  <joint name="bumper_joint" type="fixed"><parent link="base_link"/><child link="bumper"/><origin xyz="0.2 0 0"/></joint>
  <gazebo><self_collide>true</self_collide></gazebo>"""
    plan, _ = compile_with_notices(_write(tmp_path, diffbot(extra=bumper), 1.0))
    import mujoco

    m = mujoco.MjModel.from_xml_string(plan.mjcf)
    excluded = {
        frozenset(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) for b in (s >> 16, s & 0xFFFF))
        for s in m.exclude_signature
    }

    def filtered(a: str, b: str) -> bool:
        """MuJoCo leaves the pair out by itself: bodies welded together, or whose welded groups are parent
        and child (its parent filter, engine_collision_driver.c); no exclusion is made for those."""
        wa, wb = (int(m.body_weldid[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, x)]) for x in (a, b))
        pa, pb = (int(m.body_weldid[m.body_parentid[w]]) for w in (wa, wb))
        return wa == wb or (wa != 0 and wb != 0 and (wa == pb or wb == pa))

    # the bumper (welded to the base) and a wheel (the base's child): MuJoCo leaves them out by itself
    assert filtered("r1/bumper", "r1/left_wheel") and filtered("r1/bumper", "r1/base_link")
    assert not filtered("r1/left_wheel", "r1/right_wheel")
    assert frozenset({"r1/left_wheel", "r1/right_wheel"}) not in excluded
    assert frozenset({"r1/caster", "r1/base_link"}) not in excluded
    collide = next(line for line in plan.robots[0].gazebo if line.kind == "collide")
    assert "left_wheel" in collide.text and "right_wheel" in collide.text


# ------------------------------------------------------------------------------------------ 2. inertia
def test_impossible_inertias_and_zero_masses_are_repaired_with_a_warning(tmp_path: Path):
    """ixx = iyy = 0.01, izz = 0.5 breaks A + B >= C and a massless wheel: MuJoCo refuses both, Gazebo
    loads them. We load them, repaired, with one warning per link naming it and what changed."""
    urdf = diffbot(inertia=(0.01, 0.01, 0.5), wheel_mass=0.0)
    path = _write(tmp_path, urdf, 2.0)
    plan, text = compile_with_notices(path)
    urdf_file = tmp_path / "robot.urdf"
    assert f"{urdf_file}:5: link 'base_link': its inertia is not one MuJoCo accepts" in text, text
    assert "(0.01, 0.01, 0.5) -> (0.25, 0.25, 0.5)" in text
    assert "link 'left_wheel'" in text and "mass 0 kg -> 0.001 kg" in text
    changed = [line for line in plan.robots[0].gazebo if line.kind == "changed"]
    assert len(changed) == 3 and all(line.line for line in changed)
    _, bus = simulate(path)
    _, pose, tilt = _truth(bus)
    assert np.max(tilt) < 0.05 and abs(pose[-1, 2] - pose[0, 2]) < 0.02  # it stands


def test_inertias_on_the_triangle_boundary_survive_the_worlds_mjcf_text(tmp_path: Path):
    """A box's inertia about an offset point as a xacro formula gives it (m/12 (z²), m/12 (x² + z²),
    m/12 (x²)): A + B = C exactly, which MuJoCo takes in floating point but not once the world's MJCF text
    has rounded it to 6 digits (the world process refused to load a public robot). Nudged silently."""
    m, x, z = 2.5, -0.14, 0.13
    k = 0.0833333
    battery = f"""
  <link name="battery">
    <inertial><mass value="{m}"/>
      <inertia ixx="{k * m * z * z!r}" iyy="{k * m * (x * x + z * z)!r}" izz="{k * m * x * x!r}" ixy="0" ixz="0" iyz="0"/>
    </inertial>
  </link>
  <joint name="battery_joint" type="fixed"><parent link="base_link"/><child link="battery"/></joint>"""
    _, text = compile_with_notices(_write(tmp_path, diffbot(extra=battery), 1.0))
    assert "'battery'" not in text, text  # not worth a warning: the change is the text's rounding
    world, _ = simulate(tmp_path / "scenario.yaml")  # the world process loads the plan's MJCF text
    moments = sorted(world.model.body_inertia[world.model.body("r1/battery").id])
    assert moments[0] + moments[1] >= moments[2]
    assert moments[0] + moments[1] == pytest.approx(moments[2], rel=1e-4)


def test_zero_size_shapes_load_as_in_gazebo_and_are_said(tmp_path: Path):
    """`<box size="0 0 0">` placeholders (sonar and hubcap links of a public robot): Gazebo loads them and
    they touch and show nothing; MuJoCo refuses them. Left out, with a warning at each."""
    sonar = """
  <link name="sonar">
    <inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0 0 0"/></geometry></visual>
    <collision><geometry><sphere radius="0"/></geometry></collision>
  </link>
  <joint name="sonar_joint" type="fixed"><parent link="base_link"/><child link="sonar"/></joint>"""
    path = _write(tmp_path, diffbot(extra=sonar), 1.0)
    plan, text = compile_with_notices(path)
    urdf = tmp_path / "robot.urdf"
    assert "link 'sonar': its <visual> is a <box size=\"0 0 0\">, of zero size: left out" in text, text
    assert "link 'sonar': its <collision> is a <sphere radius=\"0\">, of zero size: left out" in text
    assert text.count(f"{urdf}:") >= 2
    assert [ln.kind for ln in plan.robots[0].gazebo].count("dropped") == 2
    _, bus = simulate(path)
    _, pose, tilt = _truth(bus)
    assert np.max(tilt) < 0.01 and abs(pose[-1, 2] - pose[0, 2]) < 0.02


# ------------------------------------------------------------------- 3. blocks naming what is not there
XACRO = """<?xml version="1.0"?>
<robot name="argbot" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="use_imu" default="false"/>
  <link name="base_link">
    <inertial><mass value="2"/><inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
  </link>
  <xacro:if value="$(arg use_imu)">
    <link name="imu_link"/>
    <joint name="imu_joint" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>
  </xacro:if>
  <gazebo reference="imu_link">
    <sensor name="imu" type="imu"><update_rate>100</update_rate>
      <plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor.so"><ros><remapping>~/out:=imu</remapping></ros></plugin>
    </sensor>
  </gazebo>
  <gazebo>
    <plugin name="joint_states" filename="libgazebo_ros_joint_state_publisher.so">
      <joint_name>imu_joint</joint_name>
    </plugin>
  </gazebo>
</robot>
"""


@pytest.mark.parametrize("use_imu", [False, True])
def test_blocks_naming_links_the_xacro_args_removed_are_dropped(tmp_path: Path, use_imu: bool):
    (tmp_path / "robot.urdf.xacro").write_text(XACRO)
    (tmp_path / "s.yaml").write_text(
        "name: t\nduration: 1\nrobots:\n  - name: r1\n    description: {file: robot.urdf.xacro, "
        f"args: {{use_imu: {str(use_imu).lower()}}}}}\n"
    )
    plan, text = compile_with_notices(tmp_path / "s.yaml")
    types = [p.type for p in declared(plan.robots[0])]
    xacro = tmp_path / "robot.urdf.xacro"
    if use_imu:  # a fixed joint: Gazebo lumps it away, its joint state publisher finds no such joint either
        assert types == ["imu"], types
        assert f"{xacro}:18: joint_states plugin 'joint_states' names joint 'imu_joint' (fixed" in text, text
        return
    assert types == [], types
    assert (
        f'{xacro}:12: <gazebo reference="imu_link"> names a link or joint the robot does not have: it is left out'
        in text
    )
    assert f"{xacro}:18: joint_states plugin 'joint_states' names joint 'imu_joint'" in text
    dropped = [line for line in plan.robots[0].gazebo if line.kind == "dropped"]
    assert [line.line for line in dropped] == [12, 18]


# ---------------------------------------------------------------------------- 4. several wheels a side
def _four_wheels(plugin: str) -> str:
    wheels = "".join(
        _wheel(f"{side}_{end}_wheel", "base_link", f"{x} {y} -0.05")
        for side, y in (("left", 0.17), ("right", -0.17))
        for end, x in (("front", 0.12), ("rear", -0.12))
    )
    base = BASE.format(ixx=0.05, iyy=0.07, izz=0.1).replace('<origin xyz="-0.03 0 0"/>', "")
    return f'<?xml version="1.0"?>\n<robot name="four">{base}{wheels}<gazebo>{plugin}</gazebo>\n</robot>\n'


ROS2_PAIRS = """
<plugin name="drive" filename="libgazebo_ros_diff_drive.so">
  <num_wheel_pairs>2</num_wheel_pairs>
  <left_joint>left_front_wheel_joint</left_joint><right_joint>right_front_wheel_joint</right_joint>
  <left_joint>left_rear_wheel_joint</left_joint><right_joint>right_rear_wheel_joint</right_joint>
  <wheel_separation>0.34</wheel_separation><wheel_separation>0.34</wheel_separation>
  <wheel_diameter>0.1</wheel_diameter><wheel_diameter>0.1</wheel_diameter>
</plugin>"""


def test_every_declared_wheel_is_driven(tmp_path: Path):
    plan, text = compile_with_notices(_write(tmp_path, _four_wheels(ROS2_PAIRS), 1.0))
    drive = next(p for p in declared(plan.robots[0]) if p.name == "drive")
    assert drive.type == "skid_steer"
    assert drive.params["left_joints"] == ["left_front_wheel_joint", "left_rear_wheel_joint"]
    assert drive.params["right_joints"] == ["right_front_wheel_joint", "right_rear_wheel_joint"]
    assert drive.params["pair_separations"] == [0.34, 0.34] and drive.params["pair_radii"] == [0.05, 0.05]
    assert "ignored" not in text, text
    # a one-value tag given twice is reported, never dropped silently
    twice = ROS2_PAIRS.replace(
        "<num_wheel_pairs>2</num_wheel_pairs>", "<odometry_frame>a</odometry_frame>" * 2
    )
    _, text = compile_with_notices(_write(tmp_path, _four_wheels(twice), 1.0))
    assert "a second <odometry_frame> in <plugin filename='libgazebo_ros_diff_drive.so'> is ignored" in text


# ---------------------------------------------------------------------- 5. publishing is not controlling
def test_a_drive_controls_at_a_high_rate_whatever_it_publishes_at(tmp_path: Path):
    """gz-sim DiffDrive with <odom_publish_frequency>1: odometry once a second, the wheels controlled at
    every update. Publishing at 1 Hz once wound the wheel servo up and flipped the robot."""
    drift, tilt, straight, turned = _drive_and_turn(tmp_path, diffbot(GZ_DRIVE), topic="model/r1/cmd_vel")
    assert drift < 0.01 and tilt < 0.01
    assert abs(straight - 1.0) < 0.05, straight
    assert abs(turned - 1.5) < 0.15, turned
    plan = plan_of(tmp_path / "scenario.yaml")
    drive = next(p for p in declared(plan.robots[0]) if p.type == "diff_drive")
    assert drive.rate == 1 and drive.control_rate == 100


# ------------------------------------------------------------------------------------- 6. topic names
def test_gazebo_default_topic_names(tmp_path: Path):
    plan, _ = compile_with_notices(_write(tmp_path, diffbot(GZ_DRIVE), 1.0))
    keys = {t.key for p in declared(plan.robots[0]) for t in p.topics}
    assert {"t/r1/model/r1/cmd_vel", "t/r1/model/r1/odometry", "t/r1/model/r1/tf"} <= keys, keys
    camera = """
  <link name="cam"/><joint name="cam_joint" type="fixed"><parent link="base_link"/><child link="cam"/></joint>
  <gazebo reference="cam"><sensor name="front" type="camera"><topic>front_camera</topic><update_rate>5</update_rate>
    <camera><image><width>64</width><height>48</height></image></camera></sensor></gazebo>"""
    plan, _ = compile_with_notices(_write(tmp_path, diffbot(GZ_DRIVE, extra=camera), 1.0))
    cam = next(p for p in declared(plan.robots[0]) if p.type == "camera")
    assert {t.key for t in cam.topics} == {"t/r1/front_camera", "t/r1/camera_info"}


def test_harmonic_sensors_publish_where_gz_sensors_does(tmp_path: Path):
    """In a Gazebo Harmonic description (gz-sim systems), a sensor without <topic> publishes on gz-sensors'
    scoped default (world, model, the link it is lumped into, sensor), and every lidar also publishes its
    point cloud on <topic>/points, 2-D ones included. A classic description's lidar does neither."""
    sensors = """
  <link name="laser"/><joint name="laser_joint" type="fixed"><parent link="base_link"/><child link="laser"/>
    <origin xyz="0.1 0 0.1"/></joint>
  <link name="imu_link"/><joint name="imu_joint" type="fixed"><parent link="laser"/><child link="imu_link"/></joint>
  <gazebo reference="laser">
    <sensor name="front" type="gpu_lidar"><topic>scan</topic><update_rate>10</update_rate>
      <lidar><scan><horizontal><samples>90</samples></horizontal></scan><range><min>0.1</min><max>5</max></range></lidar>
    </sensor>
    <sensor name="rear" type="gpu_lidar"><update_rate>10</update_rate>
      <lidar><scan><horizontal><samples>90</samples></horizontal></scan><range><min>0.1</min><max>5</max></range></lidar>
    </sensor>
  </gazebo>
  <gazebo reference="imu_link"><sensor name="imu" type="imu"><update_rate>50</update_rate></sensor></gazebo>"""
    plan, _ = compile_with_notices(_write(tmp_path, diffbot(GZ_DRIVE, extra=sensors), 1.0))
    topics = {p.name: sorted(t.key.removeprefix("t/r1/") for t in p.topics) for p in declared(plan.robots[0])}
    scoped = "world/default/model/r1/link/base_link/sensor"  # laser and imu_link are lumped into base_link
    assert topics["front"] == ["scan", "scan/points"], topics
    assert topics["rear"] == [f"{scoped}/rear/scan", f"{scoped}/rear/scan/points"], topics
    assert topics["imu"] == [f"{scoped}/imu/imu"], topics
    _, bus = simulate(_write(tmp_path, diffbot(GZ_DRIVE, extra=sensors), 0.3))
    clouds = messages(bus, "r1/scan/points")
    assert clouds and clouds[-1][1].width * clouds[-1][1].height == 90
    # the same sensors in a classic description (a gazebo_ros diff drive): no cloud, our short defaults
    plan, _ = compile_with_notices(_write(tmp_path, diffbot(extra=sensors.replace("gpu_lidar", "ray")), 1.0))
    topics = {p.name: sorted(t.key.removeprefix("t/r1/") for t in p.topics) for p in declared(plan.robots[0])}
    assert topics["front"] == ["scan"] and topics["imu"] == ["imu"], topics


def test_classic_publish_wheel_tf(tmp_path: Path):
    _, bus = simulate(_write(tmp_path, diffbot(), 0.5))
    tfs = messages(bus, "r1/tf")
    frames = {(t.header.frame_id, t.child_frame_id) for _, m in tfs for t in m.transforms}
    assert {
        ("r1/base_link", "r1/left_wheel"),
        ("r1/base_link", "r1/right_wheel"),
        ("r1/odom", "r1/base_link"),
    } <= frames
    # the drive's messages (robot_state_publisher's go on `tf` too)
    drive = [m for _, m in tfs if any(t.child_frame_id == "r1/base_link" for t in m.transforms)]
    wheel = next(t for t in drive[-1].transforms if t.child_frame_id == "r1/left_wheel")
    assert (
        abs(wheel.transform.translation.y - 0.17) < 1e-6 and abs(wheel.transform.translation.z + 0.05) < 1e-6
    )
    assert len(drive) == pytest.approx(0.5 * 50, abs=1)  # the drive: one message a cycle


# ------------------------------------------------------------------------------------ motion fidelity
@pytest.mark.timeout(60)
def test_diff_drive_moves_as_commanded(tmp_path: Path):
    """Wheels carrying the weight, a frictionless ball caster: 1 m straight within 5 %, 1.5 rad in place
    within 10 %, and standing still with no jump at the start."""
    drift, tilt, straight, turned = _drive_and_turn(tmp_path, diffbot())
    assert drift < 0.01 and tilt < 0.01, (drift, tilt)
    assert abs(straight - 1.0) < 0.05, straight
    assert abs(turned - 1.5) < 0.15, turned


@pytest.mark.timeout(60)
def test_declared_wheel_geometry_is_obeyed_as_gazebo_does_and_the_mismatch_is_said(tmp_path: Path):
    """A description whose <wheel_separation> (0.40 m) is wider than its wheel joints (0.34 m), and whose
    <wheel_diameter> (0.12 m) is larger than its wheels (0.10 m): Gazebo's drive computes wheel speeds from
    the declared values, so the robot turns at 0.40 / 0.34 of the command and drives at 0.10 / 0.12. We do
    the same, and validate says so with the factor, at the plugin's line."""
    drive = CLASSIC_DRIVE.replace("<wheel_separation>0.34<", "<wheel_separation>0.40<").replace(
        "<wheel_diameter>0.1<", "<wheel_diameter>0.12<"
    )
    urdf = diffbot(drive)
    _, _, straight, turned = _drive_and_turn(tmp_path, urdf)
    assert abs(straight - 0.10 / 0.12) < 0.05, straight
    assert abs(turned - 1.5 * 0.40 / 0.34 * 0.10 / 0.12) < 0.15, (straight, turned)
    plan, notices = compile_with_notices(tmp_path / "scenario.yaml")
    assert "wheel_separation 0.400 m, but its wheel joints are 0.340 m apart: it turns at 1.18x" in notices
    assert "collision radius is 0.050 m: it drives at 0.83x" in notices, notices
    lines = [ln for ln in plan.robots[0].gazebo if ln.kind == "geometry"]
    assert len(lines) == 2 and all(ln.file and ln.file.endswith("robot.urdf") and ln.line for ln in lines)
    # the description as written (declared = built): nothing said
    _, clean = compile_with_notices(_write(tmp_path, diffbot(), 1.0))
    assert "apart:" not in clean and "collision radius" not in clean, clean


@pytest.mark.timeout(60)
def test_left_wheels_on_the_right_turn_the_other_way_as_in_gazebo_and_are_said(tmp_path: Path):
    """ROS 1 descriptions written for the old legacyMode name the right wheel as the left: Gazebo (Noetic,
    which dropped legacyMode) turns them the other way than commanded, and so do we, with a warning."""
    swapped = CLASSIC_DRIVE.replace("<left_joint>left_wheel_joint", "<left_joint>right_wheel_joint").replace(
        "<right_joint>right_wheel_joint", "<right_joint>left_wheel_joint"
    )
    _, _, straight, turned = _drive_and_turn(tmp_path, diffbot(swapped))
    assert abs(straight - 1.0) < 0.05 and abs(turned + 1.5) < 0.15, (straight, turned)
    _, text = compile_with_notices(tmp_path / "scenario.yaml")
    assert "its left wheels (right_wheel_joint) are on the robot's right" in text, text
    assert "swap the left and right joints" in text


@pytest.mark.timeout(60)
def test_a_wheel_joint_moving_a_hub_with_the_tyre_fixed_to_it(tmp_path: Path):
    """The wheel joint moves a hub link with no collision (a zero-size placeholder), the tyre's cylinder is
    on a link fixed to it: Gazebo lumps the two into one link. The drive finds the radius on the tyre."""
    urdf = diffbot("")
    for side in ("left", "right"):
        urdf = urdf.replace(f'<link name="{side}_wheel">', f'<link name="{side}_tyre">').replace(
            f'<joint name="{side}_wheel_joint" type="continuous">',
            f'<link name="{side}_wheel"><collision><geometry><box size="0 0 0"/></geometry></collision>'
            '<inertial><mass value="0.01"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/>'
            f'</inertial></link><joint name="{side}_tyre_joint" type="fixed"><parent link="{side}_wheel"/>'
            f'<child link="{side}_tyre"/></joint>\n  <joint name="{side}_wheel_joint" type="continuous">',
        )
    drive = ", {type: diff_drive, params: {left_joint: left_wheel_joint, right_joint: right_wheel_joint}}"
    timeline = _cmd(0.5, "cmd_vel", lin=0.2) + _cmd(5.5, "cmd_vel")
    path = _write(tmp_path, urdf, 6.0, timeline, plugins=drive)
    _, bus = simulate(path)
    t, pose, _ = _truth(bus)
    assert abs(np.linalg.norm(_at(t, pose, 6.0)[:2] - _at(t, pose, 0.5)[:2]) - 1.0) < 0.05


ROS2_CONTROL = """
  <gazebo>
    <plugin filename="libgz_ros2_control-system.so" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>{yaml}</parameters>
    </plugin>
  </gazebo>"""

CONTROLLERS = """
/**:
  controller_manager:
    ros__parameters:
      update_rate: 100
      joint_state_broadcaster: {type: joint_state_broadcaster/JointStateBroadcaster}
      base_controller: {type: diff_drive_controller/DiffDriveController}
      gripper_controller: {type: position_controllers/GripperActionController}
  base_controller:
    ros__parameters:
      left_wheel_names: [left_wheel_joint]
      right_wheel_names: [right_wheel_joint]
      wheel_separation: 0.34
      wheel_radius: 0.05
      publish_rate: 25.0
      use_stamped_vel: false
      cmd_vel_timeout: 0.5
"""


@pytest.mark.timeout(60)
def test_a_ros2_control_diff_drive_runs_from_its_controllers_file(tmp_path: Path):
    """gz_ros2_control names its controllers file in <parameters>: its DiffDriveController runs as in
    Gazebo (`<name>/cmd_vel_unstamped` in, `<name>/odom` out, stopping 0.5 s after the last command) and
    its joint state broadcaster publishes `joint_states`; a controller we do not run is said."""
    (tmp_path / "control.yaml").write_text(CONTROLLERS)
    urdf = diffbot(ROS2_CONTROL.format(yaml=tmp_path / "control.yaml"))
    timeline = "".join(
        _cmd(round(0.5 + 0.2 * k, 1), "base_controller/cmd_vel_unstamped", lin=0.2) for k in range(26)
    )
    path = _write(tmp_path, urdf, 7.0, timeline)
    plan, text = compile_with_notices(path)
    topics = {p.name: sorted(t.key.removeprefix("t/r1/") for t in p.topics) for p in declared(plan.robots[0])}
    assert topics["base_controller"] == ["base_controller/cmd_vel_unstamped", "base_controller/odom", "tf"]
    assert topics["joint_state_broadcaster"] == ["dynamic_joint_states", "joint_states"]
    assert "gripper_controller: a gripper controller needs `joint` (one joint name); not run" in text
    _, bus = simulate(path)
    t, pose, _ = _truth(bus)
    # commands from 0.5 s to 5.5 s, then none: it stops 0.5 s later (cmd_vel_timeout), having gone ~1.1 m
    moved = float(np.linalg.norm(_at(t, pose, 7.0)[:2] - _at(t, pose, 0.5)[:2]))
    assert abs(moved - 1.1) < 0.06, moved
    assert float(np.linalg.norm(_at(t, pose, 7.0)[:2] - _at(t, pose, 6.3)[:2])) < 0.01  # stopped
    odom = messages(bus, "r1/base_controller/odom")
    assert 6.5 * 25 <= len(odom) <= 7.0 * 25 + 1


ROS1_CONTROL = """
  <gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so"/></gazebo>"""

ROS1_CONTROLLERS = """
joint_publisher:
  type: "joint_state_controller/JointStateController"
  publish_rate: 20
velocity_controller:
  type: "diff_drive_controller/DiffDriveController"
  left_wheel: ['$(arg prefix)left_wheel_joint']
  right_wheel: right_wheel_joint
  publish_rate: 25
  cmd_vel_timeout: 0.25
  enable_odom_tf: false
  wheel_separation_multiplier: 1.5
"""


@pytest.mark.timeout(60)
def test_ros1_gazebo_ros_control_runs_the_controllers_file_the_scenario_names(tmp_path: Path):
    """A ROS 1 robot's diff_drive_controller comes from a YAML file its launch file loads: the scenario
    names it (`controllers:`) and it runs as in Gazebo: `<name>/cmd_vel`, `<name>/odom`, no TF when
    `enable_odom_tf: false`, separation measured from the URDF times its multiplier (1.5: the wheels are
    driven for a wider robot, which turns at 1.5 times the command where wheels do not scrub), stopping `cmd_vel_timeout` after the last command. A file that is not there is
    an error at its line."""
    (tmp_path / "control.yaml").write_text(ROS1_CONTROLLERS)
    urdf = diffbot(ROS1_CONTROL)
    timeline = "".join(
        _cmd(round(0.5 + 0.1 * k, 1), "velocity_controller/cmd_vel", ang=0.5) for k in range(30)
    )
    path = _write(tmp_path, urdf, 4.0, timeline)
    text = path.read_text().replace("    plugins: [", "    controllers: [control.yaml]\n    plugins: [")
    path.write_text(text)
    plan, said = compile_with_notices(path)
    assert "controllers are not run" not in said, said
    assert "launch argument(s) prefix taken as empty" in said  # roslaunch's subst_value, with no value
    topics = {p.name: sorted(t.key.removeprefix("t/r1/") for t in p.topics) for p in declared(plan.robots[0])}
    assert topics["velocity_controller"] == ["velocity_controller/cmd_vel", "velocity_controller/odom"]
    assert topics["joint_publisher"] == ["joint_states"]
    _, bus = simulate(path)
    t, pose, _ = _truth(bus)
    turned = float(_at(t, pose, 4.0)[3] - _at(t, pose, 0.5)[3])
    # 0.5 rad/s for 3.0 s (+ the 0.25 s timeout), at 1.5 times the command: ~2.44 rad
    assert abs(turned - 0.5 * 3.25 * 1.5) < 0.15, turned
    path.write_text(text.replace("[control.yaml]", "[nowhere.yaml]"))
    with pytest.raises(ScenarioError) as err:
        plan_of(path)
    assert "controllers file not found" in str(err.value) and "robots[0].controllers[0]" in str(err.value)


# --------------------------------------------------------------------------------------- 8. skid steer
SKID_DRIVE = """
<plugin name="skid" filename="libgazebo_ros_skid_steer_drive.so">
  <updateRate>50</updateRate>
  <leftFrontJoint>left_front_wheel_joint</leftFrontJoint><rightFrontJoint>right_front_wheel_joint</rightFrontJoint>
  <leftRearJoint>left_rear_wheel_joint</leftRearJoint><rightRearJoint>right_rear_wheel_joint</rightRearJoint>
  <wheelSeparation>0.34</wheelSeparation><wheelDiameter>0.1</wheelDiameter><torque>20</torque>
  <commandTopic>cmd_vel</commandTopic>
</plugin>"""


@pytest.mark.timeout(60)
def test_skid_steer_moves_as_commanded_with_gazebo_friction_directions(tmp_path: Path):
    """Wheels with mu1 = 1 along fdir1 (the rolling direction) and mu2 = 0.1 across it: Gazebo's skid
    steer turns in place because the wheels slide sideways. 1 m straight within 10 %, 1.5 rad within 20 %,
    no drift standing."""
    urdf = _four_wheels(SKID_DRIVE).replace(
        "<mu1>1.0</mu1><mu2>1.0</mu2>", "<mu1>1.0</mu1><mu2>0.1</mu2><fdir1>1 0 0</fdir1>"
    )
    drift, tilt, straight, turned = _drive_and_turn(tmp_path, urdf)
    assert drift < 0.01 and tilt < 0.01, (drift, tilt)
    assert abs(straight - 1.0) < 0.1, straight
    assert abs(turned - 1.5) < 0.3, turned
    plan, _ = compile_with_notices(tmp_path / "scenario.yaml")
    assert plan.mjcf.count("<pair") == 4
    # isotropic wheels (mu1 = mu2, as Gazebo then is): no pair, they scrub and turn much less
    _, _, _, iso = _drive_and_turn(tmp_path, _four_wheels(SKID_DRIVE))
    assert iso < 0.6 * turned, (iso, turned)


def test_a_plugin_parameter_that_is_not_a_number_is_said_at_its_line(tmp_path: Path):
    """`<wheelSeparation>wide</wheelSeparation>` was taken without a word (as no value at all). Gazebo logs
    that it cannot read it and uses its default; we do the same, with a warning at the tag."""
    urdf = _four_wheels(
        SKID_DRIVE.replace(
            "<wheelSeparation>0.34</wheelSeparation>", "<wheelSeparation>wide</wheelSeparation>"
        )
    )
    plan, text = compile_with_notices(_write(tmp_path, urdf, 1.0))
    assert (
        "<wheelSeparation> 'wide' in <plugin filename='libgazebo_ros_skid_steer_drive.so'> is not a number"
        in text
    ), text
    assert "robot.urdf:" in text and "write a plain number" in text
    skid = next(p for p in declared(plan.robots[0]) if p.type == "skid_steer")
    assert skid.params.get("wheel_separation") is None  # its default: measured from the model


def test_the_drives_odometry_covariance_is_gazebos(tmp_path: Path):
    """gazebo_ros_diff_drive (ROS 2: gazebo_ros_diff_drive.cpp:404-406, 651-664) publishes covariance_x,
    covariance_y and covariance_yaw (defaults 1e-5, 1e-5, 1e-3) in the pose's and the twist's diagonal,
    1e12 for z, roll and pitch; it was read and dropped without a word (zeros published)."""
    from tests.helpers import compile_with_notices, declared

    default = [1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3]
    given = CLASSIC_DRIVE.replace(
        "<update_rate>50</update_rate>", "<update_rate>50</update_rate><covariance_x>0.5</covariance_x>"
    )
    for drive, diagonal in ((CLASSIC_DRIVE, default), (given, [0.5, *default[1:]])):
        path = _write(tmp_path, diffbot(drive), 0.1)
        plan, said = compile_with_notices(path)
        (plugin,) = [p for p in declared(plan.robots[0]) if p.type == "diff_drive"]
        assert plugin.params["pose_covariance_diagonal"] == diagonal, said
        assert plugin.params["twist_covariance_diagonal"] == diagonal
