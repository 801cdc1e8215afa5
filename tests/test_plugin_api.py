"""The public plugin API: a third-party package registers a plugin through the entry-point group and a
scenario uses it, in a real run; registry rules (duplicates, broken imports) hold."""

from __future__ import annotations

import subprocess
import sys
from importlib.metadata import EntryPoint
from pathlib import Path

import pytest

from runner.plugin import registry
from tests.conftest import read_mcap, run_cli

PACKAGE = Path(__file__).parent / "thirdparty_plugin"

SCENARIO = """
name: tp
duration: 2.0
rate: max
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive}
      - {type: beacon, params: {point: [3.0, 0.0, 0.05], rate: 5}}
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.5}}}
"""


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory):
    """The package installed as pip installs it (its .dist-info and entry points), but into a folder of
    this test's, put on PYTHONPATH for the processes it starts: the user's environment is not touched."""
    import os

    target = tmp_path_factory.mktemp("site")
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target",
         str(target), str(PACKAGE)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    before = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join([str(target), *([before] if before else [])])
    yield target
    if before is None:
        os.environ.pop("PYTHONPATH", None)
    else:
        os.environ["PYTHONPATH"] = before


@pytest.mark.timeout(180)
def test_a_third_party_plugin_runs_in_a_scenario(installed, write_scenario, tmp_path: Path):
    path = write_scenario(SCENARIO)
    proc = run_cli("validate", str(path))
    assert proc.returncode == 0, proc.stderr
    assert "tp/r1/beacon/distance" in proc.stdout and "std_msgs/msg/Float64" in proc.stdout
    mcap = tmp_path / "tp.mcap"
    proc = run_cli("run", str(path), "--record", str(mcap))
    assert proc.returncode == 0, proc.stderr
    distances = [m.data for topic, _, _, m in read_mcap(mcap) if topic == "tp/r1/beacon/distance"]
    assert len(distances) == 11  # 5 Hz for 2 s, t = 0 included
    assert distances[0] == pytest.approx(3.0, abs=0.02)
    assert distances[-1] < distances[0] - 0.5  # the robot drove towards the beacon


@pytest.mark.timeout(180)
def test_a_broken_plugin_is_reported_only_when_used(installed, write_scenario):
    ok = write_scenario(SCENARIO.replace("duration: 2.0", "duration: 0.2"))
    assert run_cli("validate", str(ok)).returncode == 0  # beacon_broken is installed, but unused
    bad = write_scenario(SCENARIO.replace("type: beacon,", "type: beacon_broken,"), "bad.yaml")
    proc = run_cli("validate", str(bad))
    assert proc.returncode == 1
    assert "plugin 'beacon_broken'" in proc.stderr and "failed to import" in proc.stderr
    assert "a_module_that_does_not_exist" in proc.stderr and "Traceback" not in proc.stderr


def test_a_name_registered_twice_is_an_error(monkeypatch: pytest.MonkeyPatch):
    group = registry.GROUP
    eps = [
        EntryPoint(name="twin", value="pkg_a:Twin", group=group),
        EntryPoint(name="twin", value="pkg_b:Twin", group=group),
    ]
    monkeypatch.setattr(registry, "entry_points", lambda group: eps)
    registry._entry_points.cache_clear()
    registry.load.cache_clear()
    try:
        with pytest.raises(registry.PluginLookupError, match="registered more than once"):
            registry.load("twin")
    finally:
        registry._entry_points.cache_clear()
        registry.load.cache_clear()


def test_builtins_are_registered_through_the_entry_point_group():
    for name in (
        "diff_drive",
        "skid_steer",
        "planar_move",
        "joint_controller",
        "joint_trajectory_controller",
        "gripper_action_controller",
        "lidar",
        "camera",
        "depth_camera",
        "imu",
        "joint_states",
        "ground_truth",
    ):
        assert name in registry.available()
        assert registry.load(name).type_name == name
