"""Bad scenarios exit 1 with file:line, the scenario path, what was expected/found, and no traceback."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from typer.testing import CliRunner

from runner.cli import app
from tests.conftest import DIFFBOT, run_cli

GOOD_ROBOT = f"""\
robots:
  - name: r1
    description: {DIFFBOT}
"""

BAD_XACRO = """\
<?xml version="1.0"?>
<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="${undefined_property}"/>
</robot>
"""

MISSING_PKG_XACRO = """\
<?xml version="1.0"?>
<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find no_such_pkg)/urdf/parts.xacro"/>
  <link name="base_link"/>
</robot>
"""

BROKEN_URDF = """\
<?xml version="1.0"?>
<robot name="b">
  <link name="base_link"/>
  <joint name="j" type="revolute">
    <parent link="base_link"/><child link="ghost"/>
  </joint>
</robot>
"""

# (id, scenario text, extra files, [substrings the error must contain])
CASES = [
    (
        "unknown_key",
        "name: x\nduraton: 3\n",
        {},
        [":2:1:", "duraton", "unknown key", "did you mean 'duration'"],
    ),
    (
        "wrong_type",
        "name: x\nduration: long\n",
        {},
        [":2:1:", "duration", "expected: a valid number", "'long'"],
    ),
    ("negative_duration", "name: x\nduration: -1\n", {}, [":2:1:", "duration", "greater than 0"]),
    ("bad_rate", "name: x\nrate: fast\n", {}, [":2:1:", "rate", "realtime", "'fast'"]),
    ("missing_name", "duration: 1\n", {}, ["missing required key 'name'", "hint"]),
    ("bad_run_name", "name: 'a b'\n", {}, [":1:1:", "name", "pattern"]),
    (
        "nested_unknown_key",
        "name: x\nworld:\n  physics:\n    timestep: 0.001\n    gravty: [0, 0, -9.8]\n",
        {},
        [":5:5:", "world.physics.gravty", "did you mean 'gravity'"],
    ),
    (
        "box_size",
        "name: x\nworld:\n  models:\n    - {name: w, shape: box, size: [1, 2]}\n",
        {},
        [":4:", "world.models[0].size", "a box needs 3"],
    ),
    (
        "missing_description_file",
        "name: x\nrobots:\n  - name: r1\n    description: nowhere/robot.urdf\n",
        {},
        [":4:5:", "robots[0].description", "not found", "nowhere/robot.urdf"],
    ),
    (
        "xacro_error",
        "name: x\nrobots:\n  - name: r1\n    description: {file: bad.urdf.xacro}\n",
        {"bad.urdf.xacro": BAD_XACRO},
        ["bad.urdf.xacro", "undefined_property", "robots[0].description.file", ":4:"],
    ),
    (
        "xacro_missing_package",
        "name: x\nrobots:\n  - name: r1\n    description: {file: pkg.urdf.xacro}\n",
        {"pkg.urdf.xacro": MISSING_PKG_XACRO},
        ["no_such_pkg", "not found", "searched", "robots[0].description.file"],
    ),
    (
        "urdf_missing_link",
        "name: x\nrobots:\n  - name: r1\n    description: broken.urdf\n",
        {"broken.urdf": BROKEN_URDF},
        ["broken.urdf", "ghost", "not defined", "robots[0].description"],
    ),
    (
        "unknown_plugin",
        GOOD_ROBOT.replace("robots:", "name: x\nrobots:") + "    plugins:\n      - type: lidr\n",
        {},
        [":6:9:", "robots[0].plugins[0].type", "unknown plugin type 'lidr'", "did you mean 'lidar'"],
    ),
    (
        "plugin_param_type",
        GOOD_ROBOT.replace("robots:", "name: x\nrobots:")
        + "    plugins:\n      - type: lidar\n        params: {samples: many}\n",
        {},
        [":7:", "robots[0].plugins[0].params.samples", "expected: a valid integer", "'many'"],
    ),
    (
        "plugin_unknown_param",
        GOOD_ROBOT.replace("robots:", "name: x\nrobots:")
        + "    plugins:\n      - type: imu\n        params:\n          rat: 10\n",
        {},
        [":8:11:", "robots[0].plugins[0].params.rat", "did you mean 'rate'"],
    ),
    (
        "plugin_missing_link",
        GOOD_ROBOT.replace("robots:", "name: x\nrobots:")
        + "    plugins:\n      - type: lidar\n        params: {link: laser_frame}\n",
        {},
        ["robots[0].plugins[0].params.link", "no link 'laser_frame'", "lidar_link"],
    ),
    (
        "wheel_joint_missing",
        GOOD_ROBOT.replace("robots:", "name: x\nrobots:")
        + "    plugins:\n      - type: diff_drive\n        params: {left_joint: wheel_l}\n",
        {},
        ["robots[0].plugins[0].params.left_joint", "no joint 'wheel_l'", "left_wheel_joint"],
    ),
    (
        "namespace_clash",
        "name: x\nrobots:\n  - {name: a, description: r.urdf}\n"
        "  - {name: b, namespace: a, description: r.urdf}\n",
        {},
        [":4:", "robots[1].namespace", "clashes"],
    ),
    (
        "timeline_bad_type",
        "name: x\ntimeline:\n  - {t: 1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twst}\n",
        {},
        [":3:", "timeline[0].type", "unknown message type", "geometry_msgs/msg/Twist"],
    ),
    (
        "timeline_bad_field",
        "name: x\ntimeline:\n  - t: 1\n    topic: r1/cmd_vel\n    type: geometry_msgs/msg/Twist\n"
        "    data:\n      linear: {x: fast}\n",
        {},
        [":7:", "timeline[0].data.linear.x", "expected a number", "'fast'"],
    ),
    (
        "timeline_after_end",
        "name: x\nduration: 2\ntimeline:\n  - {t: 5, topic: a/b, type: std_msgs/msg/Empty}\n",
        {},
        [":4:", "timeline[0].t", "after the end"],
    ),
    ("not_a_mapping", "- just\n- a list\n", {}, [":1:1:", "must be a mapping"]),
    ("bad_yaml", "name: x\nrobots: [\n", {}, ["not valid YAML"]),
]


@pytest.mark.parametrize(("case", "text", "files", "expect"), CASES, ids=[c[0] for c in CASES])
def test_bad_scenario(tmp_path: Path, case: str, text: str, files: dict[str, str], expect: list[str]) -> None:
    for name, content in files.items():
        (tmp_path / name).write_text(textwrap.dedent(content))
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    result = CliRunner().invoke(app, ["validate", str(path)])
    output = result.output
    assert result.exit_code == 1, output
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in output
    assert f"{path}:" in output or any(f in output for f in files), output
    for piece in expect:
        assert piece in output, f"{piece!r} not in:\n{output}"


@pytest.mark.timeout(60)
def test_real_console_script_exits_1_without_traceback(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("name: x\nrobots:\n  - name: r1\n    descripton: a.urdf\n")
    for verb in ("validate", "run"):
        proc = run_cli(verb, str(path))
        assert proc.returncode == 1, proc.stderr
        assert "Traceback" not in proc.stderr + proc.stdout
        assert f"{path}:4:5: robots[0].descripton: unknown key" in proc.stderr
        assert "did you mean 'description'" in proc.stderr


# Bad robot descriptions: each error names the file and line that caused it and gives a hint.
MESH_URDF = """<?xml version="1.0"?>
<robot name="m">
  <link name="base_link">
    <visual><geometry><mesh filename="{uri}"/></geometry></visual>
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
</robot>
"""

SYNTAX_XACRO = """<?xml version="1.0"?>
<robot name="s" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="w" value="1"/>
  <link name="base_link">
    <visual><geometry><box size="1 1 1"/></geometry>
  </link>
</robot>
"""

UNKNOWN_PLUGIN_URDF = """<?xml version="1.0"?>
<robot name="u">
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <gazebo>
    <plugin name="x" filename="libgazebo_ros_teleporter.so"/>
  </gazebo>
</robot>
"""

DESCRIPTION_CASES = [
    # (id, files, command, substrings)
    (
        "missing_package",
        {"r.urdf": MESH_URDF.format(uri="package://ghost_description/meshes/base.stl")},
        "validate",
        ["r.urdf:4:", "package 'ghost_description' not found", "hint:", "searched"],
    ),
    (
        "missing_mesh",
        {"r.urdf": MESH_URDF.format(uri="meshes/nothing_here.stl")},
        "validate",
        ["r.urdf:4:", "nothing_here.stl", "not found", "hint:"],
    ),
    (
        "xacro_syntax_error",
        {"r.urdf.xacro": SYNTAX_XACRO},
        "validate",
        ["r.urdf.xacro:6:", "not well-formed", "mismatched tag", "hint:"],
    ),
    (
        "unknown_plugin_filename",
        {"r.urdf": UNKNOWN_PLUGIN_URDF},
        "validate",
        ["warning:", "r.urdf:7:", "libgazebo_ros_teleporter.so", "not supported", "hint:"],
    ),
    (
        "joint_missing_link",
        {"r.urdf": BROKEN_URDF},
        "validate",
        ["r.urdf:5:", "ghost", "not defined", "hint:", "defined links: base_link"],
    ),
]


@pytest.mark.parametrize(
    ("case", "files", "verb", "expect"), DESCRIPTION_CASES, ids=[c[0] for c in DESCRIPTION_CASES]
)
def test_bad_description(
    tmp_path: Path, case: str, files: dict[str, str], verb: str, expect: list[str]
) -> None:
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    robot = next(iter(files))
    path = tmp_path / "s.yaml"
    path.write_text(f"name: x\nrobots:\n  - name: r1\n    description: {robot}\n")
    result = CliRunner().invoke(app, [verb, str(path)])
    output = result.output
    assert "Traceback" not in output
    if case == "unknown_plugin_filename":
        assert result.exit_code == 0, output  # a warning, never fatal
    else:
        assert result.exit_code == 1, output
    for piece in expect:
        assert piece in output, f"{piece!r} not in:\n{output}"
