"""The plugin catalogue (runner/compile/gazebo/catalogue.py): its page is generated from it, and the readers
take each plugin's parameters from it."""

from __future__ import annotations

from pathlib import Path

from runner.compile.gazebo.catalogue import CATALOGUE, UNSUPPORTED, entry, render, unsupported_reason

DOC = Path(__file__).parents[1] / "docs" / "plugin_catalogue.md"
REGENERATE = (
    "python -c \"from runner.compile.gazebo.catalogue import render; print(render(), end='')\" "
    "> docs/plugin_catalogue.md"
)


def test_the_catalogue_page_is_generated_from_the_table() -> None:
    assert DOC.read_text() == render(), f"docs/plugin_catalogue.md is stale: {REGENERATE}"


def test_every_plugin_is_catalogued_once_with_its_parameters_spelled_once() -> None:
    bases = [b for e in CATALOGUE for b in e.bases]
    assert len(bases) == len(set(bases))
    for e in CATALOGUE:
        names = [n for p in e.params for n in p.names]
        assert len(names) == len(set(names)), e.bases
        assert all(p.how for p in e.params if p.status != "same"), f"{e.bases}: say how or why"


def _mapped() -> set[str]:
    """Every plugin base our readers turn into something (or read as a no-op our world always runs), and
    every sensor type the sensor reader maps, as `sensor:<type>`."""
    from runner.compile.gazebo import model_plugins, sensor_plugins, sensors, tables, thirdparty

    plugins = (
        set(model_plugins._MODEL_PLUGINS) | set(sensor_plugins._SENSOR_PLUGINS) | set(tables.NOOP_PLUGINS)
    )
    return plugins | {f"sensor:{k}" for k in (*sensors._KINDS, *thirdparty.SENSOR_KINDS)}


# read by the reader of a sensor type (Gazebo's GPS sensor, runner.compile.gazebo.thirdparty), not a table
_READ_BY_SENSOR_TYPE = {"gazebo_ros_gps_sensor"}


def test_every_plugin_we_map_is_catalogued() -> None:
    missing = sorted(b for b in _mapped() if entry(b) is None and not b.startswith("sensor:"))
    assert not missing, f"mapped but not in the catalogue: {missing}"


def test_the_catalogue_says_not_supported_exactly_of_what_we_do_not_map() -> None:
    """An entry's `becomes` cannot lie: "not supported" only for what no reader maps, and anything else
    only for what one does (a sensor type, `sensor:<type>`, by the sensor reader's table)."""
    mapped = _mapped() | _READ_BY_SENSOR_TYPE
    for e in CATALOGUE:
        for b in e.bases:
            if e.becomes.startswith(UNSUPPORTED):
                assert b not in mapped, f"{b}: the catalogue says not supported, but a reader maps it"
                assert unsupported_reason(b), f"{b}: say why, and what to use instead"
                assert all(p.status == "ignored" for p in e.params), f"{b}: nothing of it is read"
            else:
                assert b in mapped, f"{b}: the catalogue maps it, no reader does"


def test_an_unsupported_plugin_is_said_with_the_catalogues_reason(tmp_path: Path) -> None:
    """The reader's notice for a plugin we do not map carries the catalogue's reason and what serves
    instead, next to the hint it always had."""
    from tests.helpers import compile_with_notices, robot_scenario

    urdf = """<?xml version="1.0"?>
<robot name="u">
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <gazebo>
    <plugin name="grip" filename="libgazebo_ros_vacuum_gripper.so"><bodyName>base_link</bodyName></plugin>
  </gazebo>
</robot>
"""
    _, notices = compile_with_notices(robot_scenario(tmp_path, urdf))
    reason = unsupported_reason("gazebo_ros_vacuum_gripper")
    assert reason
    assert f"plugin 'libgazebo_ros_vacuum_gripper.so' is not supported and is ignored: {reason}" in notices
    assert "model plugins we map:" in notices  # the hint it always had


def test_the_systems_of_the_sensors_we_read_are_not_said_as_unsupported(tmp_path: Path) -> None:
    """gz-sim's magnetometer, air pressure and altimeter systems only switch on sensors the field-sensor
    reader maps: a description that loads them is told nothing about them."""
    from tests.helpers import compile_with_notices, robot_scenario

    systems = "".join(
        f'<plugin filename="gz-sim-{s}-system" name="gz::sim::systems::X"/>'
        for s in ("magnetometer", "air-pressure", "altimeter")
    )
    urdf = f"""<?xml version="1.0"?>
<robot name="u">
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <gazebo>{systems}</gazebo>
</robot>
"""
    _, notices = compile_with_notices(robot_scenario(tmp_path, urdf))
    assert "not supported" not in notices, notices


def test_what_noetics_ros_control_plugin_does_not_read_is_said(tmp_path: Path) -> None:
    """`<legacyModeNS>` (kinetic's gazebo_ros_control) was accepted without a word; Noetic reads no such tag."""
    from tests.helpers import compile_with_notices, robot_scenario

    urdf = (
        '<robot name="b"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        '<gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so">'
        "<legacyModeNS>true</legacyModeNS></plugin></gazebo></robot>"
    )
    _plan, said = compile_with_notices(robot_scenario(tmp_path, urdf))
    (line,) = [x for x in said.splitlines() if "<legacyModeNS>" in x]
    assert "is ignored" in line, said
