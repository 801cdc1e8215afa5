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
    # every row measured (which is faster is the bench's to say: one quick round on a loaded machine can
    # see raw physics slowed by a neighbour more than the world)
    assert rates["raw_batched"] > 0 and rates["world_zenoh"] > 0
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
    assert set(actors["steps_per_s"]) == {"raw", "raw bodies", "without", "standing", "with"}
    assert all(v > 0 for v in actors["steps_per_s"].values())
    assert actors["firings"] >= 10 * actors["sim_seconds"]
    assert "+ them walking and 10 events" in proc.stdout
    assert "ours: walking and events, over the bodies standing" in proc.stdout


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


@pytest.mark.timeout(120)
def test_the_readme_bench_tables_describe_what_the_demo_publishes_now(tmp_path: Path) -> None:
    """The README's two_robots table states how many messages the demo records per sim second; when the
    demo publishes more or fewer (a new plugin, a new topic, another rate), the table describes a run that
    no longer exists: regenerate it (`python -m bench --only two_robots --readme`). Every table says the
    machine and day it was measured on."""
    import re

    from bench.common import TWO_ROBOTS, plan_from_file, readme_tables
    from runner.launch.run import run_plan

    text = (REPO / "README.md").read_text()
    block = text[text.index("<!-- bench:begin -->") : text.index("<!-- bench:end -->")]
    tables = readme_tables(block)
    assert {"two_robots", "actors"} <= set(tables)
    for name, table in tables.items():
        assert re.search(r"^_.+\(\d+ cpus\), Python [\d.]+, MuJoCo [\d.]+, \d{4}-\d\d-\d\d_$", table, re.M), (
            name
        )
    stated = re.search(r"(\d+) messages per sim second, (\d+) s sim", tables["two_robots"])
    assert stated, tables["two_robots"].splitlines()[0]
    per_s, seconds = int(stated.group(1)), float(stated.group(2))
    plan = plan_from_file(TWO_ROBOTS, seconds=seconds)  # as the bench runs it
    plan.record.path = str(tmp_path / "demo.mcap")
    result = run_plan(plan, listen=[])
    assert result.reason == "completed", result.error
    now = sum(t.count + t.lost for t in result.topics) / seconds  # (what it published: recorded or not)
    assert round(now) == per_s, (
        f"the README's two_robots table says {per_s} messages per sim second; the demo records {now:.0f} now: "
        "regenerate it with `python -m bench --only two_robots --readme` on a quiet machine"
    )
