"""A scenario runs no code but its `nodes:`; robot descriptions read only what the scenario trusts."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from runner.cli import app

ROBOT = """<?xml version="1.0"?>
<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  {body}
</robot>
"""


def _validate(tmp_path: Path, body: str, extra: str = "") -> tuple[int, str]:
    (tmp_path / "desc").mkdir(exist_ok=True)
    (tmp_path / "desc" / "robot.xacro").write_text(ROBOT.replace("{body}", body))
    scenario = tmp_path / "s.yaml"
    scenario.write_text(
        "name: s\nduration: 1\nrobots:\n  - {name: r1, description: desc/robot.xacro}\n" + extra
    )
    result = CliRunner().invoke(app, ["validate", str(scenario)])
    text = result.output + (result.stderr if result.stderr_bytes is not None else "")
    assert "Traceback" not in text
    return result.exit_code, " ".join(text.split())


@pytest.mark.parametrize(
    "expr",
    [
        "${__import__('pathlib').Path('MARK').touch()}",
        "${().__class__.__base__.__subclasses__()}",
        "$(eval __import__('pathlib').Path('MARK').touch())",
        "${open('MARK', 'w')}",
    ],
)
def test_xacro_expressions_cannot_run_code(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, expr: str
) -> None:
    monkeypatch.chdir(tmp_path)
    code, text = _validate(tmp_path, f'<link name="{expr}"/>')
    assert code == 1
    assert "robot.xacro" in text and "robots[0].description" in text
    assert not (tmp_path / "MARK").exists()


def test_xacro_reads_only_what_the_scenario_trusts(tmp_path: Path) -> None:
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (outside / "parts.xacro").write_text(
        '<?xml version="1.0"?><robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:property name="w" value="0.5"/></robot>'
    )
    (outside / "params.yaml").write_text("w: 0.5\n")
    scenario_dir = tmp_path / "scenario"
    scenario_dir.mkdir()
    include = f'<xacro:include filename="{outside / "parts.xacro"}"/>'
    code, text = _validate(scenario_dir, include)
    assert code == 1
    assert f"robot.xacro:6: {outside / 'parts.xacro'} is outside the scenario's folder and packages" in text
    assert "allow_paths:" in text
    code, text = _validate(
        scenario_dir,
        f"<link name=\"l${{xacro.load_yaml('{outside / 'params.yaml'}')['w']}}\"/>",
    )
    assert code == 1 and "params.yaml is outside the scenario's folder and packages" in text
    # trusted explicitly: fine
    code, text = _validate(scenario_dir, include, "allow_paths: [../elsewhere]\n")
    assert code == 0, text
