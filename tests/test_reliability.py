"""Nothing lost under load or faults: unstable physics, killed processes, lost messages, a long run."""

from __future__ import annotations

import subprocess

import pytest

from tests.conftest import REPO, read_mcap, scenario_cmd

WOBBLY = REPO / "tests" / "data" / "unstable" / "wobbly.urdf"  # a hinge with negative damping: it blows up


@pytest.mark.timeout(60)
def test_unstable_physics_stops_the_run_naming_the_joint_and_keeps_the_recording(write_scenario, tmp_path):
    path = write_scenario(
        f"""
        name: wobble
        duration: 5
        rate: max
        robots:
          - {{name: w1, description: {WOBBLY}, pose: {{xyz: [0, 0, 0.1]}}, fixed: true}}
        """
    )
    mcap = tmp_path / "w.mcap"
    r = subprocess.run(
        scenario_cmd("run", str(path), "--record", str(mcap)), capture_output=True, text=True, timeout=50
    )
    assert r.returncode == 1, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    err = " ".join(r.stderr.split())
    assert "the physics went unstable between t = 0.4" in err
    assert "accelerations of joint w1/spin (robot w1)" in err and "smaller world.physics.timestep" in err
    clock = [t for topic, _type, t, _m in read_mcap(mcap) if topic == "wobble/clock"]
    assert clock and 0.4e9 <= clock[-1] <= 0.5e9  # everything up to the blow-up, nothing after
