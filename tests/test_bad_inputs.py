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
