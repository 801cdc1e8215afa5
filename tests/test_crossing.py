"""The examples of scenarios that happen, run whole as a user runs them: the crossing fails on the collision
when its driver ignores the lidar (time and place said), and the fault-injection run repeats to the byte."""

from __future__ import annotations

import itertools
import json
import shutil
from pathlib import Path

import pytest
from mcap.reader import make_reader

from tests.conftest import SCENARIOS, run_cli


def _messages(path: Path) -> list[tuple[str, int, bytes]]:
    with open(path, "rb") as f:
        return [(c.topic, m.log_time, bytes(m.data)) for _, c, m in make_reader(f).iter_messages()]


@pytest.mark.timeout(120)
def test_a_blind_driver_runs_into_the_person_and_the_report_says_when_and_where(tmp_path: Path):
    # the example as shipped, its driver told to ignore its lidar (as the example's header says to try)
    shutil.copytree(SCENARIOS / "robots", tmp_path / "robots")
    shutil.copytree(SCENARIOS / "nodes", tmp_path / "nodes")
    text = (SCENARIOS / "crossing.yaml").read_text()
    assert "    required: true\n" in text
    blind = tmp_path / "crossing.yaml"
    blind.write_text(
        text.replace("    required: true\n", "    required: true\n    args: [--ignore-lidar]\n", 1)
    )
    results = tmp_path / "results.json"
    proc = run_cli(
        "run", str(blind), "--record", str(tmp_path / "c.mcap"), "-q", "--results-json", str(results)
    )
    assert proc.returncode == 1, proc.stdout + proc.stderr
    got = {r["name"]: r for r in json.loads(results.read_text())["results"]}
    hit = got["no_collision_with_the_person"]
    assert hit["status"] == "fail"
    # the person crosses x = 6.5 +- its radius; r1 drives along y = 0 and starts at x = 0.5
    assert 8.0 < hit["t"] < 16.0, hit
    assert "r1 touched walker at (" in hit["message"], hit
    x = float(hit["message"].split(" at (")[1].split(",")[0])
    assert 6.0 < x < 6.8, hit
    assert got["r1_stops_for_the_person"]["status"] == "fail"  # it never stopped
    # the failed run's picture shows the person's path (dashed grey) across the robot's
    import numpy as np
    from PIL import Image

    from runner.tools.plot import ACTOR_INK

    img = np.asarray(Image.open(tmp_path / "c.trajectory.png").convert("RGB"))
    assert int(np.all(img == ACTOR_INK, axis=2).sum()) > 100
    # its ground truth is recorded for a 3D view: world -> walker on crossing/tf, standing, then walking
    from runner.wire import msgs

    ys = [
        (t, tr.transform.translation.y)
        for topic, t, data in _messages(tmp_path / "c.mcap")
        if topic == "crossing/tf"
        for tr in msgs.decode(data, "tf2_msgs/msg/TFMessage").transforms
        if tr.child_frame_id == "walker"
    ]
    assert ys[0][1] == pytest.approx(3.5) and ys[-1][1] == pytest.approx(-3.5)
    assert all(b[1] <= a[1] + 1e-9 for a, b in itertools.pairwise(ys))
    # the person started when r1 came within 3 m of the doorway: recorded on crossing/_events
    fired = [json.loads(d) for topic, _t, d in _events(tmp_path / "c.mcap")]
    assert [f["event"] for f in fired] == ["person_crosses"] and fired[0]["did"] == ["start walker"]
    assert fired[0]["why"].startswith("r1 within 3 m of [6.5, 1.5]")


def _events(path: Path) -> list[tuple[str, int, str]]:
    from runner.wire import msgs

    return [
        (topic, t, msgs.decode(data, "std_msgs/msg/String").data)
        for topic, t, data in _messages(path)
        if topic.endswith("/_events")
    ]


@pytest.mark.timeout(120)
def test_the_fault_injection_example_passes_and_repeats_to_the_byte(tmp_path: Path):
    runs = []
    for i in range(2):
        mcap = tmp_path / f"run{i}.mcap"
        proc = run_cli("run", str(SCENARIOS / "faults.yaml"), "--record", str(mcap), "-q")
        assert proc.returncode == 0, proc.stdout + proc.stderr
        runs.append(_messages(mcap))
    # every message of every topic (the node's included) at the same sim times, but the run's plan
    # (`_plan`: it names the recording's own path)
    a, b = ([m for m in run if not m[0].endswith("/_plan")] for run in runs)
    assert len(a) > 2000
    assert sorted(a) == sorted(b)
    # the dropout is in the recording: 2 s of scans missing. The fault starts in the events' part of the
    # 4.0 s step (the sensors published before it) and ends in that of 6.0 s: 4.1 .. 6.0 are dropped
    scans = [round(t / 1e8) for topic, t, _d in a if topic == "faults/r1/scan"]  # in tenths of a second
    assert not [t for t in scans if 41 <= t <= 60]
    assert 40 in scans and 61 in scans and len(scans) == 141 - 20
    # the odometry of 8.0..11.0 s went out 0.2 s late, its own stamps unchanged
    from runner.wire import msgs

    late = [
        (t, msgs.decode(d, "nav_msgs/msg/Odometry").header.stamp)
        for topic, t, d in a
        if topic == "faults/r1/odom" and 8.3e9 <= t <= 10.9e9
    ]
    assert late and all(abs(t / 1e9 - (s.sec + s.nanosec / 1e9) - 0.2) < 1e-6 for t, s in late)
