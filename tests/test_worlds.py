"""Several worlds in one scenario (`worlds:`): each a process and a key space of its own, one router, one
recording, one judge; errors point at the user's lines; a world that dies ends the run."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import time
from pathlib import Path

import pytest

from runner.record import read_summary
from tests.conftest import SCENARIOS, processes_of, read_mcap, run_cli, scenario_cmd

TWO = """
name: pair
duration: {duration}
rate: {rate}
worlds:
  - name: a
    models:
      - {{name: wall, shape: box, size: [0.2, 4, 0.5], pose: {{xyz: [3, 0, 0.25]}}}}
  - name: b
robots:
  - name: r1
    world: a
    description: "{{diffbot}}"
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{{type: diff_drive}}, {{type: lidar, params: {{link: lidar_link, samples: 36, rate: 10}}}}]
  - name: r2
    world: b
    description: "{{diffbot}}"
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{{type: diff_drive, params: {{rate: 50}}}}]
timeline:
  - {{t: 0.0, topic: a/r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.5}}}}}}
  - {{t: 0.0, topic: b/r2/cmd_vel, type: geometry_msgs/msg/Twist, data: {{angular: {{z: 1.0}}}}}}
assertions:
  - {{name: r1_goes_forward, type: distance_traveled, robot: r1, min: 0.5}}
  - {{name: b_clock, type: topic_rate, topic: b/r2/odom, min: 45, max: 55}}
  - {{name: r2_turns_in_place, type: max_speed, robot: r2, max: 0.1}}
"""


@pytest.mark.timeout(120)
def test_two_worlds_run_apart_and_are_recorded_together(write_scenario, tmp_path: Path) -> None:
    path = write_scenario(TWO.format(duration=2.0, rate="max"))
    mcap = tmp_path / "pair.mcap"
    proc = run_cli("run", str(path), "--record", str(mcap), "--junit", str(tmp_path / "j.xml"), timeout=100)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    msgs = read_mcap(mcap)
    topics = {topic for topic, _, _, _ in msgs}
    assert {"pair/a/clock", "pair/b/clock", "pair/a/r1/scan", "pair/a/r1/odom", "pair/b/r2/odom"} <= topics
    assert not any(t.startswith("pair/a/r2") or t.startswith("pair/b/r1") for t in topics)
    last = {}
    for topic, _, _t, m in msgs:
        if topic.endswith("/_truth"):
            last[topic] = m.pose.pose
    # r1 drove forward in world a; r2 turned on the spot in world b: each world simulated its own robot
    assert last["pair/a/r1/_truth"].position.x > 0.7
    assert (
        abs(last["pair/b/r2/_truth"].position.x) < 0.05 and abs(last["pair/b/r2/_truth"].orientation.z) > 0.3
    )
    # the recording re-judged offline agrees with the live verdicts
    check = run_cli("check", str(mcap), "--scenario", str(path), timeout=60)
    assert check.returncode == 0, check.stdout + check.stderr
    assert "3 passed" in check.stdout and "3 passed" in proc.stdout


@pytest.mark.timeout(60)
def test_warnings_over_the_whole_run_are_said_once_with_the_users_index(write_scenario) -> None:
    """Checks that span the run (assertion windows, timeline topics) run once over all worlds, not once
    per world too (then each said twice, with the world's own index)."""
    from tests.helpers import compile_with_notices

    text = TWO.format(duration=2.0, rate="max").replace(
        "topic: b/r2/odom, min: 45", "topic: b/r2/odom, after: 40, min: 45"
    )
    text = text.replace("topic: b/r2/cmd_vel", "topic: b/r2/cmd_vell")
    _plan, warnings = compile_with_notices(write_scenario(text))
    assert warnings.count("lies past the run's end") == 1, warnings
    assert "assertions[1] 'b_clock': its window (after: 40 s)" in warnings
    assert warnings.count("which nothing in the run subscribes to") == 1, warnings
    assert (
        "timeline[1] publishes on 'b/r2/cmd_vell'" in warnings and "did you mean 'b/r2/cmd_vel'?" in warnings
    )


def test_world_mistakes_point_at_the_users_lines(write_scenario) -> None:
    text = TWO.format(duration=1.0, rate="max")
    cases = {
        # a plugin mistake of the second world's robot: robots[1], as the user wrote it
        text.replace("{type: diff_drive, params: {rate: 50}}", "{type: diff_drive, params: {rate: -5}}"): (
            r"robots\[1\]\.plugins\[0\]\.params\.rate"
        ),
        text.replace(
            "topic: b/r2/cmd_vel", "topic: r2/cmd_vel"
        ): r"timeline\[1\]\.topic: 'r2/cmd_vel' names no world",
        text.replace("world: b\n", "world: c\n"): r"robots\[1\]\.world: no world named 'c'",
        text.replace("worlds:", "world: {}\nworlds:"): r"world: both `world:` and `worlds:`",
        text.replace(
            "topic: b/r2/odom", "topic: r2/odom"
        ): r"assertions\[1\]\.topic: 'r2/odom' names no world",
    }
    for i, (scenario, pattern) in enumerate(cases.items()):
        path = write_scenario(scenario, f"bad{i}.yaml")
        proc = run_cli("validate", str(path))
        said = proc.stdout + proc.stderr
        assert proc.returncode != 0, scenario
        assert re.search(rf"bad{i}\.yaml:\d+:\d+: {pattern}", said), said
        assert "Traceback" not in said


@pytest.mark.timeout(60)
def _clocks_recorded(mcap: Path) -> bool:
    if not mcap.exists():
        return False
    counts = {t["topic"]: t["count"] for t in read_summary(mcap)["topics"]}
    return counts.get("pair/a/clock", 0) > 0 and counts.get("pair/b/clock", 0) > 0


def test_a_world_that_dies_ends_the_run(write_scenario, tmp_path: Path) -> None:
    path = write_scenario(TWO.format(duration=600, rate="realtime"))
    mcap = tmp_path / "run.mcap"
    proc = subprocess.Popen(
        scenario_cmd("run", str(path), "--record", str(mcap), "--no-judge"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
        start_new_session=True,
    )
    try:
        worlds: list[int] = []
        deadline = time.monotonic() + 30
        while len(worlds) < 2 and time.monotonic() < deadline:
            time.sleep(0.2)
            worlds = processes_of(proc.pid, r"runner\.sim /", direct=True)  # this run's, not a helper's fork
        assert len(worlds) == 2, "two world processes"
        # both worlds running and recorded (a loaded machine starts them slowly): the recorder hands a
        # chunk to the OS at least every second, readable while the file is being written
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and not _clocks_recorded(mcap):
            time.sleep(0.2)
        killed = time.monotonic()
        os.kill(worlds[0], signal.SIGKILL)
        assert proc.stderr is not None
        said = None
        for line in proc.stderr:  # the report comes at once, before the other world is stopped
            if "process died; stopping the run" in line:
                said = time.monotonic() - killed
                break
        _out, rest = proc.communicate(timeout=30)
        err = (line or "") + rest
        took = time.monotonic() - killed
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 1
    assert re.search(r"the world [ab] process exited with code -9", err), err
    assert said is not None and said < 1.0, said  # reported within a second
    assert took < 5.0, took  # the other world stopped in order, the recording finished
    assert "Traceback" not in err
    topics = {topic for topic, _, _, _ in read_mcap(mcap)}  # finished and readable
    assert {"pair/a/clock", "pair/b/clock"} <= topics


@pytest.mark.timeout(120)
def test_the_two_worlds_example_passes(tmp_path: Path) -> None:
    proc = run_cli(
        "run", str(SCENARIOS / "two_worlds.yaml"), "--record", str(tmp_path / "w.mcap"), timeout=100
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "[controller] arrived at" in proc.stderr
    assert "3 passed, 0 failed" in proc.stdout
