"""World-fixed robots as their URDF says (issue 36, point 1): a root link named `world` welds the robot, as
Gazebo's URDF import does; links joined by a joint never collide, also when one is welded to the world; a
moving link with nothing to weigh loads. Real compiles and real MuJoCo runs on small URDFs written here."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from runner.errors import ScenarioError
from tests.helpers import compile_with_notices, messages, plan_of, simulate

INERTIA = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'

# A base box and a first link whose collision boxes overlap at the joint (as a shoulder's housing overlaps
# the base's in public arms); the first joint is horizontal, so the link swings down under gravity.
ARM = f"""<?xml version="1.0"?>
<robot name="arm">
  <link name="world">{{world_extra}}</link>
  <joint name="world_joint" type="fixed">
    <parent link="world"/><child link="base_link"/><origin xyz="0 0 0.1"/>
  </joint>
  <link name="base_link">
    <inertial><mass value="2"/>{INERTIA}</inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base_link"/><child link="link1"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/>
  </joint>
  <link name="link1">
    <inertial><origin xyz="0.1 0 0"/><mass value="1"/>{INERTIA}</inertial>
    <collision><origin xyz="0.1 0 0"/><geometry><box size="0.3 0.1 0.1"/></geometry></collision>
  </link>
</robot>
"""


def _scenario(tmp_path: Path, urdf: str, extra: str = "", plugins: str = "[]", duration: float = 0.5) -> Path:
    (tmp_path / "arm.urdf").write_text(urdf)
    path = tmp_path / "arm.yaml"
    path.write_text(
        f"name: g\nduration: {duration}\nrate: max\nrobots:\n  - name: bot\n    description: arm.urdf\n"
        f"    pose: {{xyz: [1, 2, 0.5], rpy: [0, 0, 0]}}\n    plugins: {plugins}\n{extra}"
    )
    return path


@pytest.mark.timeout(60)
def test_a_world_root_link_welds_the_arm_at_its_pose_and_its_first_joint_swings_free(tmp_path):
    path = _scenario(tmp_path, ARM.format(world_extra=""), plugins="[{type: ground_truth}]")
    world, bus = simulate(path)
    m, d = world.model, world.data
    robot = world.plan.robots[0]
    assert robot.root == "base_link" and robot.fixed
    assert m.njnt == 1  # j1 only: no free joint
    # welded where the scenario puts it, the world joint's origin above that
    np.testing.assert_allclose(d.xpos[m.body("bot/base_link").id], [1, 2, 0.6], atol=1e-9)
    # the base's box overlaps link1's at the joint: with MuJoCo's own rule (it skips parent-child pairs
    # unless the parent is welded to the world) the contacts hold j1 near 0 (measured -0.31 rad);
    # Gazebo never collides links joined by a joint, so the link swings down to its limit
    assert d.qpos[0] > 1.5, d.qpos
    truth = messages(bus, "bot/ground_truth")[-1][1]
    assert truth.child_frame_id == "bot/base_link"
    p = truth.pose.pose.position
    np.testing.assert_allclose([p.x, p.y, p.z], [1, 2, 0.6], atol=1e-6)
    # TF: the scenario's world -> the description's own world link (the robot's pose) -> base -> link1
    static = {
        (t.header.frame_id, t.child_frame_id): t.transform.translation
        for _s, msg in messages(bus, "bot/tf_static")
        for t in msg.transforms
    }
    w, b = static[("world", "bot/world")], static[("bot/world", "bot/base_link")]
    np.testing.assert_allclose([w.x, w.y, w.z], [1, 2, 0.5], atol=1e-9)
    np.testing.assert_allclose([b.x, b.y, b.z], [0, 0, 0.1], atol=1e-9)
    moving = {
        (t.header.frame_id, t.child_frame_id) for _s, msg in messages(bus, "bot/tf") for t in msg.transforms
    }
    assert moving == {("bot/base_link", "bot/link1")}


@pytest.mark.timeout(60)
def test_validate_says_the_description_welds_it_and_warns_at_fixed_false(tmp_path):
    plan, notices = compile_with_notices(
        _scenario(tmp_path, ARM.format(world_extra=""), "    fixed: false\n")
    )
    lines = [line for line in plan.robots[0].gazebo if line.kind == "base"]
    assert len(lines) == 1 and "root link `world` welds 'base_link'" in lines[0].text
    assert lines[0].file and lines[0].file.endswith("arm.urdf") and lines[0].line == 4
    assert "`fixed: false`, but its description's root link `world` welds it" in notices
    assert "arm.yaml:9" in notices  # at the scenario's `fixed:` line
    # without `fixed:` nothing is warned
    plan, notices = compile_with_notices(_scenario(tmp_path, ARM.format(world_extra="")))
    assert "fixed" not in notices and plan.robots[0].fixed


@pytest.mark.timeout(60)
def test_the_world_links_own_shapes_are_left_out_as_gazebo_makes_no_link_of_it(tmp_path):
    extra = f'<inertial><mass value="5"/>{INERTIA}</inertial><collision><geometry><box size="4 4 0.01"/></geometry></collision>'
    plan, notices = compile_with_notices(_scenario(tmp_path, ARM.format(world_extra=extra)))
    assert "link 'world': its <collision>, <inertial> left out" in notices
    import mujoco

    m = mujoco.MjModel.from_xml_string(plan.mjcf)
    assert not any(int(m.geom_bodyid[g]) == 0 and m.geom_size[g][0] == 2.0 for g in range(m.ngeom))


@pytest.mark.timeout(60)
def test_a_link_named_world_below_the_root_is_an_error_at_its_line(tmp_path):
    urdf = ARM.format(world_extra="").replace(
        '<parent link="world"/><child link="base_link"/>', '<parent link="base_link"/><child link="world"/>'
    )
    with pytest.raises(ScenarioError) as e:
        plan_of(_scenario(tmp_path, urdf))
    text = e.value.render()
    assert "a link named 'world' is not the root link" in text and "arm.urdf:3" in text


@pytest.mark.timeout(60)
def test_a_moving_link_with_nothing_to_weigh_gets_a_gram_and_keeps_its_joint(tmp_path):
    # a finger with only a visual (the public Panda's, whose Collada mesh is its only shape): MuJoCo
    # refuses a moving body without mass; Gazebo leaves the link out with its joint
    finger = """
  <joint name="finger_joint" type="prismatic">
    <parent link="link1"/><child link="finger"/><origin xyz="0.2 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="20" velocity="0.2"/>
  </joint>
  <link name="finger"><visual><geometry><box size="0.02 0.02 0.05"/></geometry></visual></link>
</robot>"""
    urdf = ARM.format(world_extra="").replace("</robot>", finger)
    urdf = urdf[: urdf.index('  <link name="world">')] + urdf[urdf.index('  <link name="base_link">') :]
    plan, notices = compile_with_notices(_scenario(tmp_path, urdf, "    fixed: true\n"))
    assert "link 'finger' moves but has no <inertial> and no <collision> to weigh: given 0.001 kg" in notices
    import mujoco

    m = mujoco.MjModel.from_xml_string(plan.mjcf)
    assert m.body("bot/finger").mass[0] == pytest.approx(0.001)
    assert m.joint("bot/finger_joint").id >= 0


@pytest.mark.timeout(60)
def test_the_scene_places_the_world_link_when_the_robots_tf_leaves_the_root_out(tmp_path):
    _, bus = simulate(_scenario(tmp_path, ARM.format(world_extra=""), plugins="[{type: tf}]", duration=0.1))
    scene = {
        (t.header.frame_id, t.child_frame_id): t.transform.translation
        for _s, msg in messages(bus, "g/tf_static")
        for t in msg.transforms
    }
    w = scene[("world", "bot/world")]
    np.testing.assert_allclose([w.x, w.y, w.z], [1, 2, 0.5], atol=1e-9)
    robot = {
        (t.header.frame_id, t.child_frame_id)
        for _s, msg in messages(bus, "bot/tf_static")
        for t in msg.transforms
    }
    assert robot == {("bot/world", "bot/base_link")}
