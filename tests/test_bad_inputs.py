"""Bad scenarios exit 1 with file:line, the scenario path, what was expected/found, and no traceback.

The one-mistake scenario cases live in tests/bad_inputs/ (tests/test_bad_input_corpus.py); here: the real
console script, and bad robot descriptions.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from runner.cli import app
from tests.conftest import run_cli

# The scenario cases that were here are files in tests/bad_inputs/ now (tests/test_bad_input_corpus.py).

BROKEN_URDF = """\
<?xml version="1.0"?>
<robot name="b">
  <link name="base_link"/>
  <joint name="j" type="revolute">
    <parent link="base_link"/><child link="ghost"/>
  </joint>
</robot>
"""


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
    <collision><geometry><mesh filename="{uri}"/></geometry></collision>
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


# Seven independent mistakes of seven kinds, one per line, in an order the checks do not run in (the
# schema's own first, then compile's): one `validate` says all seven, in the file's order.
SEVEN = """\
name: seven
duration: 10
nodes:
  - {name: n1, cmd: "no_such_program_here --x"}
robots:
  - name: r1
    description: "{diffbot}"
    plugins:
      - {type: diff_drvie}
      - {type: lidar, params: {samples: many}}
  - name: r2
    description: "{diffbot}"
    pose: {xyz: [1, 2], rpy: [0, 0, 0]}
timeline:
  - {t: 1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {xx: 1}}}
bridges:
  - {ros_topic: /cmd, topic: r2/cmd_vel, type: geometry_msgs/msg/Twis, direction: ZENOH_TO_SIM}
assertions:
  - {name: a, type: reach, robot: r3, point: [1, 0], tolerance: 0.2, by: 8}
  - {name: b, type: message, topic: r1/odom, expr: "pose.pose.position.x >> 1"}
  - {name: c, type: reach, robot: r2, point: [1, 0], tolerance: 0.2, by: 8}
"""


@pytest.mark.timeout(60)
def test_every_independent_mistake_is_said_in_one_pass_in_line_order(write_scenario) -> None:
    path = write_scenario(SEVEN)
    proc = run_cli("validate", str(path))
    assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
    said = [ln for ln in proc.stderr.splitlines() if ln.startswith(f"{path}:")]
    expected = [
        (4, "nodes[0].cmd: command 'no_such_program_here' not found"),
        (9, "robots[0].plugins[0].type: unknown plugin type 'diff_drvie'"),
        (10, "robots[0].plugins[1].params.samples: wrong value"),
        (13, "robots[1].pose.xyz: expected 3 items, found 2"),
        (15, "timeline[0].data.linear.xx: geometry_msgs/msg/Vector3 has no field 'xx'"),
        (17, "bridges[0].type: unknown message type 'geometry_msgs/msg/Twis'"),
        (19, "assertions[0].robot: no robot named 'r3'"),
        (20, "assertions[1].expr: in `pose.pose.position.x >> 1` (column 22): the operator '>>'"),
    ]
    assert len(said) == len(expected), proc.stderr
    for (line, text), got in zip(expected, said, strict=True):
        assert got.startswith(f"{path}:{line}:") and text in got, (line, text, got)
    assert proc.stderr.startswith(f"error: {len(expected)} problems:"), proc.stderr


@pytest.mark.timeout(60)
def test_what_follows_from_a_refused_robot_is_not_reported(write_scenario) -> None:
    """A robot the schema refuses is taken out for the rest of the checks: an assertion or bridge on it is
    not reported as naming an unknown robot or topic, while a later item's mistake still is, at its own
    path (indexes past the refused item map back to the file)."""
    path = write_scenario(
        """
        name: refused
        duration: 5
        robots:
          - {name: r0, descripton: "{diffbot}"}
          - {name: r1, description: "{diffbot}", plugins: [{type: lidar, params: {samples: many}}]}
        bridges:
          - {topic: r0/cmd_vel, type: geometry_msgs/msg/Twist, direction: ZENOH_TO_SIM}
        assertions:
          - {name: a, type: reach, robot: r0, point: [1, 0], tolerance: 0.2}
          - {name: b, type: topic_rate, topic: r0/odom, min: 5}
        """
    )
    proc = run_cli("validate", str(path))
    assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
    said = [ln for ln in proc.stderr.splitlines() if ln.startswith(f"{path}:")]
    assert len(said) == 2, proc.stderr
    assert said[0].startswith(f"{path}:4:") and "robots[0].descripton: unknown key" in said[0]
    assert said[1].startswith(f"{path}:5:") and "robots[1].plugins[0].params.samples" in said[1]


@pytest.mark.timeout(60)
def test_checks_that_stop_early_say_so(write_scenario) -> None:
    """A mistake that makes later checks meaningless stops them, and the message says what waits."""
    cases = {
        "name: x\nrobots: [\n": "(nothing else is checked until the file reads as YAML)",
        "name: x\nrobots:\n  - {name: r1, description: a.urdf}\n  - {name: r1, description: a.urdf}\n": (
            "(robots, plugins, the timeline and the rest are checked once these are fixed)"
        ),
    }
    for k, (text, note) in enumerate(cases.items()):
        path = write_scenario(text, name=f"case{k}.yaml")
        proc = run_cli("validate", str(path))
        assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
        assert proc.stderr.rstrip().endswith(note), proc.stderr
