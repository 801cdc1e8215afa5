"""Never silent, for the URDF itself (runner/compile/urdf/ledger.py): every element and attribute of a URDF
is read, or said at its own line with what Gazebo does with it (issue 38).

A URDF holding every element and attribute of the URDF format (urdfdom's model: links, inertials, visuals,
collisions, geometries, materials and textures, joints with calibration, dynamics, limits, mimic and safety
controllers, the robot's version) and a few that are not URDF: each line with something nothing reads must
have a notice at that line, and each line without one must hold only what the ledger says is read. What it
says MuJoCo reads is checked too: changing any such number changes the compiled model."""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

from runner.compile.packages import PackageMap
from runner.compile.urdf import urdf_to_model
from runner.compile.urdf.ledger import READ
from runner.errors import Notices

# one element per line; `#` marks a line whose element or attribute nothing reads
EVERYTHING = """<?xml version="1.0"?>
<robot name="all" version="1.0">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <material name="tex"><texture filename="t.png"/></material>
  <link name="base">
    <inertial>
      <origin xyz="0.01 0 0" rpy="0 0 0"/>
      <mass value="2"/>
      <inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0" ixz="0" iyz="0"/>
    </inertial>
    <visual name="v">
      <origin xyz="0 0 0.01" rpy="0 0 0"/>
      <geometry><box size="0.3 0.2 0.1"/></geometry>
      <material name="grey"/>
    </visual>
    <collision name="c">
      <origin xyz="0 0 0.01" rpy="0 0 0"/>
      <geometry><box size="0.3 0.2 0.1"/></geometry>
    </collision>
    <gravity>0</gravity>
  </link>
  <link name="arm" type="laser">
    <inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.02" length="0.2"/></geometry></collision>
    <visual><geometry><sphere radius="0.03"/></geometry><material name="red"><color rgba="1 0 0 1"/></material></visual>
  </link>
  <link name="tip">
    <inertial><mass value="0.1"/><inertia ixx="0.0001" iyy="0.0001" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="j1" type="revolute">
    <origin xyz="0 0 0.1" rpy="0 0 0"/>
    <parent link="base"/>
    <child link="arm"/>
    <axis xyz="0 1 0" rpy="0 0 0"/>
    <calibration rising="0.1" falling="0.2" reference_position="0"/>
    <dynamics damping="0.3" friction="0.05"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/>
    <safety_controller soft_lower_limit="-0.9" soft_upper_limit="0.9" k_position="10" k_velocity="1"/>
  </joint>
  <joint name="j2" type="revolute">
    <origin xyz="0 0 0.2"/>
    <parent link="arm"/>
    <child link="tip"/>
    <axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/>
    <mimic joint="j1" multiplier="0.5" offset="0.1"/>
  </joint>
  <sensor name="cam" update_rate="10"><parent link="tip"/><camera/></sensor>
</robot>
"""
UNREAD = {  # line (its text's start) -> what of it is said
    '<robot name="all" version="1.0">': "version",
    '  <material name="tex"><texture': "texture",
    "    <gravity>0</gravity>": "gravity",
    '  <link name="arm" type="laser">': "type",
    '    <axis xyz="0 1 0" rpy="0 0 0"/>': "rpy",
    "    <calibration": "calibration",
    "    <safety_controller": "safety_controller",
    '  <sensor name="cam"': "sensor",
}


def _notices(tmp_path: Path, urdf: str) -> tuple[list[str], mujoco.MjModel]:
    notices = Notices()
    path = tmp_path / "all.urdf"
    path.write_text(urdf)
    model = urdf_to_model(urdf, path, PackageMap.for_scenario(tmp_path, {}), notices=notices)
    return [n.render() for n in notices], model.spec.compile()


def test_what_nothing_reads_is_said_at_its_line_and_nothing_else_is(tmp_path: Path) -> None:
    notices, _m = _notices(tmp_path, EVERYTHING)
    lines = EVERYTHING.splitlines()
    said: dict[int, list[str]] = {}
    for n in notices:
        m = re.search(r"all\.urdf:(\d+):", n)
        if m and "is not read" in n:
            said.setdefault(int(m.group(1)), []).append(n)
    expected = {}
    for start, what in UNREAD.items():
        (i,) = [k + 1 for k, line in enumerate(lines) if line.startswith(start)]
        expected[i] = what
    for line, what in expected.items():
        assert any(what in n for n in said.get(line, [])), (line, lines[line - 1], said)
    assert set(said) == set(expected), {k: v for k, v in said.items() if k not in expected}
    # and each says what Gazebo does with it
    assert all("Gazebo" in n or "nothing reads" in n or "not a URDF" in n for v in said.values() for n in v)


# (path of a number MuJoCo reads, its value, another value): the compiled model must change with it
NUMBERS = [
    ('<mass value="2"/>', '<mass value="3"/>'),
    ('ixx="0.02"', 'ixx="0.025"'),
    ('<origin xyz="0.01 0 0" rpy="0 0 0"/>', '<origin xyz="0.02 0 0" rpy="0 0 0"/>'),
    (
        '<box size="0.3 0.2 0.1"/></geometry>\n    </collision>',
        '<box size="0.4 0.2 0.1"/></geometry>\n    </collision>',
    ),
    ('<cylinder radius="0.02"', '<cylinder radius="0.03"'),
    ('<sphere radius="0.03"/>', '<sphere radius="0.04"/>'),
    ('<color rgba="1 0 0 1"/>', '<color rgba="0 1 0 1"/>'),
    ('<origin xyz="0 0 0.1" rpy="0 0 0"/>', '<origin xyz="0 0 0.15" rpy="0 0 0"/>'),
    ('<axis xyz="0 1 0" rpy', '<axis xyz="1 0 0" rpy'),
    ('damping="0.3"', 'damping="0.4"'),
    ('friction="0.05"', 'friction="0.06"'),
    (
        '<limit lower="-1" upper="1" effort="5" velocity="2"/>\n    <safety',
        '<limit lower="-0.5" upper="1" effort="5" velocity="2"/>\n    <safety',
    ),
    ('multiplier="0.5"', 'multiplier="0.7"'),
]


@pytest.mark.parametrize(("old", "new"), NUMBERS)
def test_what_the_ledger_says_is_read_changes_the_model(tmp_path: Path, old: str, new: str) -> None:
    assert EVERYTHING.count(old) == 1, old
    _n, before = _notices(tmp_path, EVERYTHING)
    _n, after = _notices(tmp_path, EVERYTHING.replace(old, new))
    changed = [
        name
        for name in dir(before)
        if not name.startswith("_")
        and isinstance(a := getattr(before, name), np.ndarray)
        and a.shape == getattr(after, name).shape
        and not np.array_equal(a, getattr(after, name))
    ]
    assert changed, f"{old} -> {new} changed nothing in the compiled model"


def test_the_ledger_knows_every_element_it_walks() -> None:
    """(READ's shape: every spec is (attributes, children))."""

    def walk(spec: tuple[frozenset[str], dict]) -> int:
        attrs, children = spec
        assert isinstance(attrs, frozenset)
        return 1 + sum(walk(c) for c in children.values())

    assert walk(READ["robot"]) > 20


def test_a_descriptions_own_mujoco_block_is_kept_and_its_memory_reaches_the_world(tmp_path: Path) -> None:
    from tests.helpers import compile_with_notices, robot_scenario

    urdf = (
        '<robot name="m"><mujoco><size memory="64M"/><option timestep="0.01"/>'
        '<compiler discardvisual="true"/></mujoco>'
        '<link name="a"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link></robot>'
    )
    plan, notices = compile_with_notices(robot_scenario(tmp_path, urdf))
    m = mujoco.MjModel.from_xml_string(plan.mjcf)
    assert m.narena >= 64 << 20
    assert m.ngeom >= 1  # the visual kept, whatever the block's compiler says (said)
    assert "discardvisual" in notices and "<mujoco><option> is not used" in notices
