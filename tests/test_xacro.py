from __future__ import annotations

from pathlib import Path

import pytest

from runner.compile.packages import PackageMap
from runner.compile.xacro_expand import MissingPackage, expand


def _package(root: Path, name: str) -> Path:
    pkg = root / "src" / name
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "package.xml").write_text(f"<package format='3'><name>{name}</name></package>")
    return pkg


def test_find_resolves_through_package_xml_without_ros(tmp_path: Path):
    pkg = _package(tmp_path, "my_robot_description")
    (pkg / "urdf" / "parts.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="w" value="0.25"/></robot>'
    )
    main = pkg / "urdf" / "robot.urdf.xacro"
    main.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="prefix" default="x_"/>'
        '<xacro:include filename="$(find my_robot_description)/urdf/parts.xacro"/>'
        '<link name="$(arg prefix)base">'
        '<visual><geometry><box size="${w} ${w*2} 1"/></geometry></visual></link>'
        "</robot>"
    )
    result = expand(main, {"prefix": "p_"}, PackageMap.for_scenario(tmp_path))
    urdf = result.urdf
    assert result.sources == [main, pkg / "urdf" / "parts.xacro"]
    assert 'name="p_base"' in urdf
    assert 'size="0.25 0.5 1"' in urdf


def test_missing_package_names_it_and_where_we_looked(tmp_path: Path):
    main = tmp_path / "r.xacro"
    main.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="$(find ghost_pkg)/x.xacro"/></robot>'
    )
    with pytest.raises(MissingPackage) as e:
        expand(main, {}, PackageMap.for_scenario(tmp_path))
    assert "ghost_pkg" in str(e.value)
    assert str(tmp_path) in (e.value.hint or "")


def test_explicit_package_map_wins(tmp_path: Path):
    _package(tmp_path, "dup")
    other = tmp_path / "elsewhere"
    other.mkdir()
    pm = PackageMap.for_scenario(tmp_path, {"dup": other})
    assert pm.find("dup") == other
    assert pm.find("nope") is None


def test_a_urdf_named_file_that_uses_xacro_is_expanded(tmp_path: Path):
    """Launch files run xacro on `.urdf` files too (nav2's sam_bot): the content decides, not the name."""
    from runner.compile import compile_plan
    from runner.scenario.loader import load_file
    from runner.scenario.validate import validate_scenario

    (tmp_path / "bot.urdf").write_text(
        '<robot name="bot" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="size" default="0.3"/><xacro:property name="w" value="$(arg size)"/>'
        '<link name="base"><collision><geometry><box size="${w} ${w} 0.1"/></geometry></collision>'
        '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
        "</inertial></link></robot>"
    )
    (tmp_path / "s.yaml").write_text(
        "name: s\nrobots:\n  - {name: r1, description: {file: bot.urdf, args: {size: '0.5'}}}\n"
    )
    doc = load_file(tmp_path / "s.yaml")
    plan = compile_plan(validate_scenario(doc), doc)
    import mujoco

    m = mujoco.MjModel.from_xml_string(plan.mjcf)
    box = [g for g in range(m.ngeom) if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX]
    assert [round(float(x), 3) for x in m.geom_size[box[0]]] == [0.25, 0.25, 0.05]  # the arg reached it


def test_a_macro_call_without_its_parameters_and_a_macro_without_end_are_located(tmp_path: Path):
    """xacro said "Undefined parameters [radius]" and "maximum recursion depth exceeded", with no line."""
    from runner.compile.xacro_expand import XacroError

    head = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
    call = tmp_path / "call.urdf.xacro"
    call.write_text(
        head + '  <xacro:macro name="wheel" params="name radius">\n    <link name="${name}"/>\n'
        '  </xacro:macro>\n  <link name="base"/>\n  <xacro:wheel name="w1"/>\n</robot>\n'
    )
    with pytest.raises(XacroError) as err:
        expand(call, {}, PackageMap(roots=[tmp_path]))
    assert err.value.line == 7 and "the call of macro 'wheel' does not give parameters [radius]" in str(
        err.value
    )
    assert "radius:=" in (err.value.hint or "")
    loop = tmp_path / "loop.urdf.xacro"
    loop.write_text(
        head + '  <xacro:macro name="again" params="n">\n    <xacro:again n="${n}"/>\n  </xacro:macro>\n'
        '  <link name="base"/>\n  <xacro:again n="1"/>\n</robot>\n'
    )
    with pytest.raises(XacroError) as err:
        expand(loop, {}, PackageMap(roots=[tmp_path]))
    assert err.value.line == 3 and "macro 'again' calls itself without end" in str(err.value)
    assert "<xacro:if>" in (err.value.hint or "")


@pytest.mark.parametrize("ns", ["", "p."])
def test_a_macro_call_without_its_parameters_is_located_at_that_call(tmp_path: Path, ns: str):
    """The error pointed at the first call of the macro (`<xacro:wheel`), the call before the one that
    lacks a parameter; calls spread over lines and namespaced calls count too."""
    from runner.compile.xacro_expand import XacroError

    parts = tmp_path / "parts.xacro"
    parts.write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:macro name="wheel" params="name radius">\n    <link name="${name}"/>\n'
        "  </xacro:macro>\n</robot>\n"
    )
    main = tmp_path / "robot.urdf.xacro"
    include = (
        '<xacro:include filename="parts.xacro" ns="p"/>' if ns else '<xacro:include filename="parts.xacro"/>'
    )
    main.write_text(
        '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        f"  {include}\n"
        '  <link name="base"/>\n'
        f'  <xacro:{ns}wheel name="w1" radius="0.1"/>\n'
        f'  <xacro:{ns}wheel\n      name="w2"\n      radius="0.1"/>\n'
        f'  <xacro:{ns}wheel name="w3"/>\n'
        f'  <xacro:{ns}wheel name="w4"/>\n'
        "</robot>\n"
    )
    with pytest.raises(XacroError) as err:
        expand(main, {}, PackageMap(roots=[tmp_path]))
    assert err.value.file == main and err.value.line == 9, (err.value.file, err.value.line)
    assert "the call of macro 'wheel' does not give parameters [radius]" in str(err.value)


def test_a_xacro_urdf_with_only_find_substitutions_is_expanded(tmp_path: Path):
    """gz_ros2_control's demo robots (`*.xacro.urdf`) declare no xacro namespace: their only xacro is a
    `$(find pkg)` in the control plugin's <parameters>, which the launch's xacro run resolves. Read as plain
    URDF, the path stayed literal and the controllers file could not be read."""
    from tests.helpers import compile_with_notices

    pkg = _package(tmp_path, "demo_pkg")
    (pkg / "config").mkdir()
    (pkg / "config" / "c.yaml").write_text(
        "controller_manager:\n  ros__parameters:\n    joint_state_broadcaster:\n"
        "      type: joint_state_broadcaster/JointStateBroadcaster\n"
    )
    (tmp_path / "bot.xacro.urdf").write_text(
        '<robot name="bot"><link name="base"><collision><geometry><box size="0.3 0.3 0.1"/></geometry>'
        '</collision><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
        'iyz="0"/></inertial></link><gazebo><plugin filename="libgz_ros2_control-system.so" '
        'name="gz_ros2_control::GazeboSimROS2ControlPlugin"><parameters>$(find demo_pkg)/config/c.yaml'
        "</parameters></plugin></gazebo></robot>"
    )
    (tmp_path / "s.yaml").write_text("name: s\nrobots:\n  - {name: r1, description: bot.xacro.urdf}\n")
    plan, text = compile_with_notices(tmp_path / "s.yaml")
    assert "cannot be read" not in text, text
    assert [p.type for p in plan.robots[0].plugins if p.name == "joint_state_broadcaster"] == ["joint_states"]
