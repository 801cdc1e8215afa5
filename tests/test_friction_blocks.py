"""`<collision><surface>` friction blocks in `<gazebo reference="link">` (runner.compile.gazebo.surface) and
the anisotropic friction they mean on the ground (runner.compile.wheels): every element of the block used
or said at its own line; a mecanum-by-friction robot (mu 1 along a diagonal fdir1 fixed in the base, mu2 0
across it, as gz-sim's mecanum demo and public descriptions write it) strafes and turns as its roller
kinematics say; a box slides as far as Coulomb friction with the block's mu says."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from runner.compile.gazebo import parse, read_gazebo
from runner.errors import Notices
from runner.geometry import quat_to_yaw
from tests.helpers import compile_with_notices, messages, simulate

_INERTIA = '<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/>'

# every element SDF 1.11's surface.sdf gives a <surface>, as a <gazebo reference> <collision> blob
FULL_BLOCK = """<gazebo reference="wheel">
  <collision name="wheel_collision">
    <max_contacts>4</max_contacts>
    <laser_retro>100</laser_retro>
    <surface>
      <bounce><restitution_coefficient>0.5</restitution_coefficient><threshold>1</threshold></bounce>
      <friction>
        <torsional>
          <coefficient>0.5</coefficient><use_patch_radius>true</use_patch_radius>
          <patch_radius>0.01</patch_radius><surface_radius>0.1</surface_radius><ode><slip>0.1</slip></ode>
        </torsional>
        <ode>
          <mu>0.9</mu>
          <mu2>0.2</mu2>
          <fdir1 gz:expressed_in="base_link">1 -1 0</fdir1>
          <slip1>0.01</slip1>
          <slip2>0.02</slip2>
        </ode>
        <bullet><friction>1</friction><friction2>1</friction2><fdir1>0 0 0</fdir1><rolling_friction>1</rolling_friction></bullet>
      </friction>
      <contact>
        <collide_without_contact>true</collide_without_contact>
        <collide_without_contact_bitmask>1</collide_without_contact_bitmask>
        <collide_bitmask>0x01</collide_bitmask>
        <category_bitmask>0x02</category_bitmask>
        <poissons_ratio>0.3</poissons_ratio>
        <elastic_modulus>-1</elastic_modulus>
        <ode><soft_cfm>0</soft_cfm><soft_erp>0.2</soft_erp><kp>100000</kp><kd>10</kd>
          <max_vel>0.1</max_vel><min_depth>0.001</min_depth></ode>
        <bullet><soft_cfm>0</soft_cfm><soft_erp>0.2</soft_erp><kp>1e12</kp><kd>1</kd>
          <split_impulse>true</split_impulse><split_impulse_penetration_threshold>-0.01</split_impulse_penetration_threshold></bullet>
      </contact>
      <soft_contact><dart><bone_attachment>100</bone_attachment><stiffness>100</stiffness><damping>10</damping><flesh_mass_fraction>0.05</flesh_mass_fraction></dart></soft_contact>
    </surface>
  </collision>
</gazebo>"""

_ROBOT = """<robot name="r">
  <link name="base_link"><inertial><mass value="1"/>{inertia}</inertial></link>
  <link name="wheel"><inertial><mass value="1"/>{inertia}</inertial>
    <collision><geometry><cylinder radius="0.05" length="0.03"/></geometry></collision></link>
  <joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel"/><axis xyz="0 1 0"/></joint>
{gazebo}
</robot>"""


def _read(gazebo: str) -> tuple[Any, list[tuple[str, int | None]]]:
    text = _ROBOT.format(inertia=_INERTIA.format(i=0.01), gazebo=gazebo)
    notices = Notices()
    info = read_gazebo(parse(text), Path("r.urdf"), namespace="r", notices=notices)
    return info, [(n.message, n.location.line) for n in notices]


def test_every_element_of_a_surface_block_is_used_or_said_at_its_line():
    """mu, mu2, fdir1 with its (undeclared) gz:expressed_in and contact kp are used; each other element of
    SDF's <surface> is said once, at its own line, with what Gazebo does with it."""
    info, said = _read(FULL_BLOCK)
    props = info.links["wheel"]
    assert (props.mu1, props.mu2, props.friction) == (0.9, 0.2, 0.2)
    assert props.fdir1 == (1.0, -1.0, 0.0) and props.fdir1_frame == "base_link"
    lines = _ROBOT.split("{gazebo}")[0].count("\n") + 1  # the block's first line in the file
    assert props.fdir1_at[1] == lines + FULL_BLOCK[: FULL_BLOCK.index("<fdir1 gz")].count("\n")
    assert props.kp == 100000
    where = {
        tag: lines + FULL_BLOCK[: FULL_BLOCK.index(f"<{tag}>")].count("\n")
        for tag in (
            "max_contacts",
            "laser_retro",
            "bounce",
            "torsional",
            "slip1",
            "slip2",
            "collide_without_contact",
            "collide_without_contact_bitmask",
            "collide_bitmask",
            "category_bitmask",
            "poissons_ratio",
            "elastic_modulus",
            "soft_cfm",
            "soft_erp",
            "kd",
            "max_vel",
            "min_depth",
            "soft_contact",
        )
    }
    for tag, line in where.items():
        hits = [(m, n) for m, n in said if m.startswith(f"<{tag}> in ")]
        assert len(hits) == 1, (tag, said)
        assert hits[0][1] == line, (tag, hits, line)
        assert "ignored (" in hits[0][0], hits  # with the reason
    # the second <bullet> (under <contact>) is said too, at its own line
    bullets = [n for m, n in said if m.startswith("<bullet> in ")]
    assert len(bullets) == 2 and len(said) == len(where) + 2, said


def test_urdf_keys_win_over_the_surface_block_and_an_unknown_frame_is_said():
    """sdformat writes the URDF keys (mu1, mu2, fdir1, kp) over the copied <surface> (parser_urdf.cc,
    InsertSDFExtensionCollision); an expressed_in naming no link keeps the collision's frame, said."""
    block = FULL_BLOCK.replace('expressed_in="base_link"', 'expressed_in="chassis"').replace(
        "</gazebo>", "<mu1>0.7</mu1><kp>5000</kp></gazebo>"
    )
    info, said = _read(block)
    props = info.links["wheel"]
    assert (props.mu1, props.mu2, props.friction, props.kp) == (0.7, 0.2, 0.2, 5000)
    assert props.fdir1_frame is None
    assert any("'chassis', which is not a link of the robot" in m for m, _ in said), said
    # <mu> is not a URDF key: Gazebo copies it into the link, where nothing reads it
    info, said = _read('<gazebo reference="wheel"><mu>0.1</mu></gazebo>')
    assert info.links["wheel"].friction is None
    assert said == [('<mu> in <gazebo reference="wheel"> is ignored, as in Gazebo: the keys are <mu1> and <mu2> '
                     "(<mu> belongs in <collision><surface><friction><ode>)", 6)]  # fmt: skip
    # one of mu, mu2 given: the other is SDF's default 1 for mu, mu for mu2 (dartsim)
    info, _ = _read('<gazebo reference="wheel"><collision><surface><friction><ode><mu2>0.3</mu2>'
                    "<fdir1>1 0 0</fdir1></ode></friction></surface></collision></gazebo>")  # fmt: skip
    assert (info.links["wheel"].mu1, info.links["wheel"].mu2) == (1.0, 0.3)
    info, _ = _read('<gazebo reference="wheel"><collision><surface><friction><ode><mu>0.4</mu>'
                    "</ode></friction></surface></collision></gazebo>")  # fmt: skip
    assert (info.links["wheel"].mu1, info.links["wheel"].mu2, info.links["wheel"].friction) == (0.4, 0.4, 0.4)


def test_elements_at_the_values_we_simulate_anyway_are_used_silently():
    """slip 0, no restitution, torsion without a patch, contacts that touch, the default bitmasks: what
    Gazebo does with them is what we do, so nothing is said (only what changes behaviour is)."""
    block = """<gazebo reference="wheel"><collision><surface>
      <bounce><restitution_coefficient>0</restitution_coefficient></bounce>
      <friction><torsional><coefficient>1</coefficient></torsional>
        <ode><mu>1</mu><mu2>1</mu2><slip1>0</slip1><slip2>0.0</slip2></ode></friction>
      <contact><collide_without_contact>false</collide_without_contact><collide_bitmask>0xffff</collide_bitmask>
        <category_bitmask>65535</category_bitmask></contact>
    </surface></collision></gazebo>"""
    info, said = _read(block)
    assert said == [] and info.links["wheel"].friction == 1.0
    # a torsional patch is friction Gazebo applies: said
    _, said = _read(block.replace("<coefficient>1</coefficient>", "<patch_radius>0.02</patch_radius>"))
    assert [m.split(" in ")[0] for m, _ in said] == ["<torsional>"]


# ------------------------------------------------------------------------- a mecanum robot by friction
# gz-sim's mecanum demo and public descriptions: mu 1 along the roller's axis at the ground, mu2 0 across
# it, the direction fixed in the base: FL and RR (1, -1, 0), FR and RL (1, 1, 0)
_DIAGONAL = {"front_left": "1 -1 0", "front_right": "1 1 0", "rear_right": "1 -1 0", "rear_left": "1 1 0"}
_AT = {
    "front_left": (0.12, 0.17),
    "front_right": (0.12, -0.17),
    "rear_right": (-0.12, -0.17),
    "rear_left": (-0.12, 0.17),
}
_RADIUS = 0.05


def _mecanum_wheel(name: str, shape: str, frame: str | None) -> str:
    x, y = _AT[name]
    geometry = (
        f'<origin rpy="1.5708 0 0"/><geometry><cylinder radius="{_RADIUS}" length="0.04"/></geometry>'
        if shape in ("cylinder", "tyre")
        else f'<geometry><sphere radius="{_RADIUS}"/></geometry>'
    )
    expressed = f' gz:expressed_in="{frame}"' if frame else ""
    # "tyre": the collision on a link fixed to the one the wheel joint turns (Gazebo lumps it into the wheel)
    tyre = f"""<link name="{name}_tyre"><inertial><mass value="0.1"/>{_INERTIA.format(i=0.0001)}</inertial>
    <collision>{geometry}</collision></link>
  <joint name="{name}_tyre_joint" type="fixed"><parent link="{name}_wheel"/><child link="{name}_tyre"/></joint>"""
    collision = f'<collision name="{name}_wheel_collision">{geometry}</collision>'
    return f"""
  <link name="{name}_wheel">
    <inertial><mass value="0.3"/>{_INERTIA.format(i=0.0004)}</inertial>
    {collision if shape != "tyre" else ""}
  </link>
  {tyre if shape == "tyre" else ""}
  <joint name="{name}_wheel_joint" type="continuous">
    <parent link="base_link"/><child link="{name}_wheel"/><origin xyz="{x} {y} -0.05"/><axis xyz="0 1 0"/>
  </joint>
  <gazebo reference="{name}_{"tyre" if shape == "tyre" else "wheel"}">
    <collision name="{name}_wheel_collision">
      <surface><friction><ode>
        <mu>1.0</mu><mu2>0.0</mu2><fdir1{expressed}>{_DIAGONAL[name]}</fdir1>
      </ode></friction></surface>
    </collision>
  </gazebo>"""


def mecanum_bot(shape: str = "cylinder", frame: str | None = "base_link", xmlns: bool = False) -> str:
    """Four wheels 0.24 m apart along, 0.34 m across; `xmlns`: with `xmlns:gz` declared (most descriptions
    do not declare it)."""
    base = """
  <link name="base_link">
    <inertial><mass value="6"/><inertia ixx="0.05" iyy="0.08" izz="0.12" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.26 0.08"/></geometry></collision>
  </link>"""
    wheels = "".join(_mecanum_wheel(w, shape, frame) for w in _DIAGONAL)
    ns = ' xmlns:gz="http://gazebosim.org/schema"' if xmlns else ""
    return f'<?xml version="1.0"?>\n<robot name="mecanum"{ns}>{base}{wheels}\n</robot>\n'


SCENARIO = """
name: t
duration: {duration}
rate: max
seed: 3
robots:
  - name: r1
    description: robot.urdf
    pose: {{xyz: [0, 0, 0.11]}}
    plugins:
      - {{type: ground_truth, params: {{rate: 100}}}}
      - type: mecanum_drive
        name: drive
        params: {{rollers: false, wheels_radius: {radius}, sum_of_robot_center_projection_on_X_Y_axis: 0.29,
                  reference_timeout: 0.5}}
timeline:
{timeline}
"""


def _reference(t0: float, t1: float, vx: float = 0.0, vy: float = 0.0, wz: float = 0.0) -> str:
    """The drive's reference every 0.1 s from t0 to t1 (as a teleop node sends it)."""
    data = f"{{twist: {{linear: {{x: {vx}, y: {vy}}}, angular: {{z: {wz}}}}}}}"
    return "".join(
        f"  - {{t: {round(t0 + k * 0.1, 3)}, topic: r1/drive/reference, type: geometry_msgs/msg/TwistStamped, "
        f"data: {data}}}\n"
        for k in range(round((t1 - t0) / 0.1))
    )


def _run(tmp_path: Path, urdf: str, timeline: str, duration: float) -> tuple[np.ndarray, np.ndarray]:
    (tmp_path / "robot.urdf").write_text(urdf)
    path = tmp_path / "scenario.yaml"
    path.write_text(SCENARIO.format(duration=duration, timeline=timeline, radius=_RADIUS))
    return _run_path(path)


def _run_path(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(t, [x, y, yaw]) of robot r1's true pose in the run of a scenario file."""
    _, bus = simulate(path)
    samples = messages(bus, "r1/ground_truth")
    t = np.array([s / 1e9 for s, _ in samples])
    pose = np.array([[m.pose.pose.position.x, m.pose.pose.position.y, _yaw(m)] for _, m in samples])
    pose[:, 2] = np.unwrap(pose[:, 2])
    return t, pose


def _yaw(m: Any) -> float:
    q = m.pose.pose.orientation
    return quat_to_yaw([q.w, q.x, q.y, q.z])


def _at(t: np.ndarray, pose: np.ndarray, when: float) -> np.ndarray:
    return pose[int(np.argmin(abs(t - when)))]


STRAFE_M, TURN_RAD = 0.2 * 3.4, 0.5 * 3.4  # what the kinematics say of mecanum_moves' commands


def mecanum_moves(
    tmp_path: Path, shape: str = "cylinder", frame: str | None = "base_link", xmlns: bool = False
) -> dict[str, float]:
    """Asked 0.2 m/s sideways from 0.5 s, the last reference at 3.4 s and the drive's 0.5 s timeout after
    it (3.4 s: 0.68 m by the roller kinematics), then 0.5 rad/s from 4.5 s likewise (1.7 rad): what the
    robot did (its true pose, from where it started)."""
    timeline = _reference(0.5, 3.5, vy=0.2) + _reference(4.5, 7.5, wz=0.5)
    t, pose = _run(tmp_path, mecanum_bot(shape, frame, xmlns), timeline, 8.5)
    start, strafed, stop = _at(t, pose, 0.4), _at(t, pose, 4.4), _at(t, pose, 8.5)
    return {
        "y_m": float(strafed[1] - start[1]),
        "x_m": float(strafed[0] - start[0]),
        "yaw_while_strafing_rad": float(strafed[2] - start[2]),
        "turned_rad": float(stop[2] - strafed[2]),
        "moved_while_turning_m": float(np.linalg.norm(stop[:2] - strafed[:2])),
    }


@pytest.mark.timeout(120)
@pytest.mark.parametrize(("shape", "xmlns"), [("cylinder", False), ("sphere", True), ("tyre", False)])
def test_a_mecanum_robot_by_friction_strafes_and_turns_as_its_rollers_say(
    tmp_path: Path, shape: str, xmlns: bool
):
    """Wheels with mu 1 along a diagonal fdir1 fixed in the base (gz:expressed_in) and mu2 0 across it,
    driven by mecanum inverse kinematics (no rollers of ours): sideways and turning each within 10 % of the
    kinematics. Ignoring the block (isotropic rubber wheels), the same wheel speeds scrub: no strafing."""
    moved = mecanum_moves(tmp_path, shape, xmlns=xmlns)
    assert abs(moved["y_m"] / STRAFE_M - 1) < 0.1, moved
    assert abs(moved["x_m"]) < 0.05 and abs(moved["yaw_while_strafing_rad"]) < 0.05, moved
    assert abs(moved["turned_rad"] / TURN_RAD - 1) < 0.1, moved
    assert moved["moved_while_turning_m"] < 0.06, moved
    plan, text = compile_with_notices(tmp_path / "scenario.yaml")
    assert plan.mjcf.count("<pair") == 4 * 16  # a ring of 16 per wheel
    assert "ignored" not in text, text


@pytest.mark.timeout(60)
def test_a_diagonal_fdir1_in_the_wheels_own_frame_turns_with_it_as_in_gazebo_and_is_said(tmp_path: Path):
    """Without expressed_in, Gazebo rotates fdir1 with the collision: one capsule per wheel whose axis turns
    with it (not the base-fixed ring), and a warning with the hint at the <fdir1> line. (Spheres: their
    collision frame is the wheel's, so fdir1 1 -1 0 lies between the rolling direction and the axle.)"""
    (tmp_path / "robot.urdf").write_text(mecanum_bot("sphere", frame=None))
    path = tmp_path / "scenario.yaml"
    path.write_text(SCENARIO.format(duration=0.1, timeline="  []", radius=_RADIUS))
    plan, text = compile_with_notices(path)
    assert plan.mjcf.count("<pair") == 4
    assert text.count("turns with the wheel, as in Gazebo") == 4, text
    assert 'gz:expressed_in="base_link"' in text


_CONTROLLERS = """
/**:
  controller_manager:
    ros__parameters:
      update_rate: 100
      base: {type: mecanum_drive_controller/MecanumDriveController}
  base:
    ros__parameters:
      reference_timeout: 0.5
      front_left_wheel_command_joint_name: front_left_wheel_joint
      front_right_wheel_command_joint_name: front_right_wheel_joint
      rear_right_wheel_command_joint_name: rear_right_wheel_joint
      rear_left_wheel_command_joint_name: rear_left_wheel_joint
      kinematics: {wheels_radius: 0.05, sum_of_robot_center_projection_on_X_Y_axis: 0.29}
"""


@pytest.mark.timeout(60)
def test_a_mecanum_controller_drives_wheels_that_grip_by_friction_as_described(tmp_path: Path):
    """ros2_controllers' mecanum_drive_controller from a gz_ros2_control controllers file, on wheels whose
    description gives them mecanum friction: no rollers of ours (Gazebo drives the wheels as described),
    the friction rings instead; it strafes as its kinematics say."""
    (tmp_path / "control.yaml").write_text(_CONTROLLERS)
    control = f"""<gazebo><plugin filename="gz_ros2_control-system" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>{tmp_path / "control.yaml"}</parameters></plugin></gazebo>"""
    (tmp_path / "robot.urdf").write_text(mecanum_bot().replace("\n</robot>", f"{control}\n</robot>"))
    path = tmp_path / "scenario.yaml"
    scenario = SCENARIO.split("      - type: mecanum_drive")[0]
    path.write_text(scenario.format(duration=4.5) + "timeline:\n" + _reference(0.5, 3.5, vy=0.2).replace(
        "r1/drive/reference", "r1/base/reference"))  # fmt: skip
    plan, _ = compile_with_notices(path)
    drive = next(p for p in plan.robots[0].plugins if p.type == "mecanum_drive")
    assert drive.params["rollers"] is False
    assert plan.mjcf.count("<pair") == 4 * 16 and "roller" not in plan.mjcf
    _, bus = simulate(path)
    samples = messages(bus, "r1/ground_truth")
    y = samples[-1][1].pose.pose.position.y - samples[0][1].pose.pose.position.y
    assert abs(y / STRAFE_M - 1) < 0.1, y


GZ_MECANUM = """
  <gazebo>
    <plugin filename="gz-sim-mecanum-drive-system" name="gz::sim::systems::MecanumDrive">
      <front_left_joint>front_left_wheel_joint</front_left_joint>
      <front_right_joint>front_right_wheel_joint</front_right_joint>
      <back_left_joint>rear_left_wheel_joint</back_left_joint>
      <back_right_joint>rear_right_wheel_joint</back_right_joint>
      <wheel_separation>0.34</wheel_separation>
      <wheelbase>0.24</wheelbase>
      <wheel_radius>0.05</wheel_radius>
      <min_acceleration>-5</min_acceleration>
      <max_acceleration>5</max_acceleration>
    </plugin>
  </gazebo>"""


def _twist(t: float, vy: float = 0.0, wz: float = 0.0) -> str:
    return (
        f"  - {{t: {t}, topic: r1/model/r1/cmd_vel, type: geometry_msgs/msg/Twist, "
        f"data: {{linear: {{y: {vy}}}, angular: {{z: {wz}}}}}}}\n"
    )


@pytest.mark.timeout(60)
def test_gz_sims_mecanum_drive_on_wheels_that_grip_by_friction(tmp_path: Path):
    """gz-sim's MecanumDrive system, as its demo and the descriptions using it: a Twist on
    /model/<model>/cmd_vel, held until the next; 0.2 m/s sideways for 3 s (0.6 m), then 0.5 rad/s for 3 s
    (1.5 rad), each within 10 %; its wheels' friction is the rollers (no rollers of ours)."""
    (tmp_path / "robot.urdf").write_text(mecanum_bot().replace("\n</robot>", f"{GZ_MECANUM}\n</robot>"))
    path = tmp_path / "scenario.yaml"
    timeline = _twist(0.5, vy=0.2) + _twist(3.5) + _twist(4.5, wz=0.5) + _twist(7.5)
    path.write_text(
        SCENARIO.split("      - type: mecanum_drive")[0].format(duration=8.5) + "timeline:\n" + timeline
    )
    plan, text = compile_with_notices(path)
    drive = next(p for p in plan.robots[0].plugins if p.type == "mecanum_drive")
    assert drive.params["rollers"] is False and drive.params["reference_topic"] == "model/r1/cmd_vel"
    assert drive.params["sum_of_robot_center_projection_on_X_Y_axis"] == pytest.approx(0.29)
    assert drive.params["linear_y_limits"]["max_acceleration"] == 5, drive.params
    assert "MecanumDrive" not in text, text
    t, pose = _run_path(path)
    strafed = _at(t, pose, 4.4) - _at(t, pose, 0.4)
    turned = _at(t, pose, 8.5)[2] - _at(t, pose, 4.4)[2]
    assert abs(strafed[1] / 0.6 - 1) < 0.1 and abs(strafed[0]) < 0.05, strafed
    assert abs(turned / 1.5 - 1) < 0.1, turned
    # wheels without mecanum friction: Gazebo's would scrub; our rollers stand in, said
    (tmp_path / "robot.urdf").write_text(
        mecanum_bot()
        .replace("<mu2>0.0</mu2>", "<mu2>1.0</mu2>")
        .replace("\n</robot>", f"{GZ_MECANUM}\n</robot>")
    )
    plan, text = compile_with_notices(path)
    drive = next(p for p in plan.robots[0].plugins if p.type == "mecanum_drive")
    assert drive.params["rollers"] is True and "the wheels have no mecanum friction" in text, text


# ------------------------------------------------------------------------------ Coulomb sliding distance
_BOX = """<?xml version="1.0"?>
<robot name="box">
  <link name="base_link">
    <inertial><mass value="2"/>{inertia}</inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <gazebo reference="base_link">
    <collision><surface><friction><ode><mu>{mu}</mu><mu2>{mu}</mu2></ode></friction></surface></collision>
  </gazebo>
</robot>
"""

_SLIDE = """
name: t
duration: 2.0
rate: max
seed: 3
robots:
  - name: r1
    description: robot.urdf
    pose: {xyz: [0, 0, 0.05]}
    plugins: [{type: ground_truth, params: {rate: 200}}]
events:
  - {name: kick, when: {at: 0.5}, do: [{impulse: {body: r1, linear: [2.0, 0, 0]}}]}
"""


@pytest.mark.timeout(60)
@pytest.mark.parametrize("mu", [0.2, 0.5])
def test_a_box_slides_as_far_as_coulomb_friction_with_the_blocks_mu_says(tmp_path: Path, mu: float):
    """Kicked to 1 m/s (2 N·s on 2 kg) on the ground (mu 1): it stops after v²/(2 g mu), Gazebo's smaller
    of the two mu being the block's (without the block: mu 1, 5 cm)."""
    (tmp_path / "robot.urdf").write_text(_BOX.format(inertia=_INERTIA.format(i=0.01), mu=mu))
    path = tmp_path / "scenario.yaml"
    path.write_text(_SLIDE)
    _, bus = simulate(path)
    samples = messages(bus, "r1/ground_truth")
    before = next(m.pose.pose.position.x for s, m in samples if s >= 0.45e9)
    slid = samples[-1][1].pose.pose.position.x - before
    expected = 1.0 / (2 * 9.81 * mu)
    assert math.isclose(slid, expected, rel_tol=0.1), (slid, expected)


# ------------------------------------------------------------------------------------ a world's models
def test_a_world_models_friction_direction_and_slip_are_said_with_why(tmp_path: Path):
    """World SDF (runner.compile.sdf): mu/mu2 are used (the smaller); fdir1, slip1, slip2 are said with
    the reason, at their lines."""
    import mujoco

    from runner.compile.packages import PackageMap
    from runner.compile.sdf import load_sdf_world

    path = tmp_path / "w.sdf"
    path.write_text(
        """<sdf version="1.9"><world name="w"><model name="m"><static>true</static><link name="l">
<collision name="c"><geometry><box><size>1 1 1</size></box></geometry>
<surface><friction><ode><mu>0.6</mu><mu2>0.3</mu2>
<fdir1>1 0 0</fdir1>
<slip1>0.1</slip1><slip2>0.1</slip2></ode></friction></surface></collision>
</link></model></world></sdf>
"""
    )
    notices = Notices()
    spec = mujoco.MjSpec()
    load_sdf_world(spec, path, PackageMap(roots=[tmp_path]), notices)
    assert spec.compile().geom("m/l/c").friction[0] == pytest.approx(0.3)
    said = {n.message: n.location.line for n in notices}
    assert said["SDF <fdir1> ignored: anisotropic friction of world models is not simulated: the smaller "
                "of mu and mu2 is used"] == 4  # fmt: skip
    assert said["SDF <slip1> ignored: force-dependent slip is not simulated"] == 5


def test_robot_description_with_an_undeclared_gz_prefix_gets_its_frames_prefixed():
    """The robot_description the scene publishes names frames as TF does (`r1/base_link`), also for a
    description with `gz:expressed_in` and no `xmlns:gz` (it used to come back unprefixed)."""
    from runner.frames import prefixed_urdf

    out = prefixed_urdf(mecanum_bot(), "r1")
    assert '<link name="r1/base_link">' in out and '<gazebo reference="r1/front_left_wheel">' in out
