"""The benchmark suite runs (its cheapest sections), so it does not rot between releases. Figures are not
judged here: timings belong to `python -m bench`, not to tests on a shared CI machine."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.timeout(120)
def test_bench_suite_runs_and_writes_results(tmp_path: Path) -> None:
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "bench",
            "--quick",
            "--only",
            "messages,two_robots,actors",
            "--results",
            str(tmp_path),
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=110,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "raw MuJoCo, batched mj_step (the limit)" in proc.stdout
    doc = json.loads((tmp_path / "two_robots.json").read_text())
    assert doc["machine"]["cpus"] >= 1
    rates = doc["steps_per_s"]
    # the limit is the limit: nothing with plugins is faster than raw physics of the same model
    assert rates["raw_batched"] > rates["world_zenoh"] > 0
    assert rates["recorded"] > 0
    assert doc["lost"] == [0]
    messages = json.loads((tmp_path / "messages.json").read_text())
    types = {row["type"] for row in messages["rows"]}
    assert {"sensor_msgs/msg/Imu", "sensor_msgs/msg/LaserScan", "nav_msgs/msg/Odometry"} <= types
    # a fixed layout is cheaper than building the bytes with rosbags
    assert all(row["fixed_layout_us"] < row["rosbags_encode_us"] for row in messages["rows"])
    # the actors row ran the three worlds, and the events in it fired (the scan trigger, 10 a second)
    actors = json.loads((tmp_path / "actors.json").read_text())
    assert (actors["actors"], actors["events"]) == (20, 10)
    assert set(actors["steps_per_s"]) == {"without", "standing", "with"}
    assert all(v > 0 for v in actors["steps_per_s"].values())
    assert actors["firings"] >= 10 * actors["sim_seconds"]
    assert "+ them walking and 10 events" in proc.stdout


@pytest.mark.timeout(60)
def test_unknown_section_is_a_clear_error() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "bench", "--only", "nope"],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2
    assert "unknown section(s) nope" in proc.stderr
