"""Node processes (`nodes:`, runner.node): they drive robots, are recorded with the run, are watched
(a required node's death ends the run within a second, exit 1, the MCAP readable), restarted on failure,
and with `lockstep:` a `rate: max` run with a node is repeatable to the byte."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest
from mcap.reader import make_reader

from tests.conftest import SCENARIOS, processes_of, read_mcap, run_cli, scenario_cmd, wait_recorded

NODE = """
import sys
from runner.node import Node

with Node() as node:
    cmd = node.publisher("cmd_vel", "geometry_msgs/msg/Twist")
    seen = []
    node.subscribe("odom", "nav_msgs/msg/Odometry", lambda m: seen.append(m.pose.pose.position.x))
    while node.ok():
        # the command depends on what the node has heard: any message early or late shows in the physics
        cmd.publish({"linear": {"x": 0.3}, "angular": {"z": 0.2 * (seen[-1] if seen else -1.0)}})
        if len(sys.argv) > 1 and node.now > float(sys.argv[1]):
            sys.exit(3)  # a crash, on purpose
        node.sleep(0.1)
    print(f"heard {len(seen)} odometry messages, last x {seen[-1]:.2f}", flush=True)
"""

SCENE = """
name: with_node
duration: {duration}
rate: {rate}
seed: 2
robots:
  - name: r1
    description: {{file: "{{diffbot}}"}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive, params: {{rate: 50, odometry_source: world}}}}
      - {{type: imu, params: {{rate: 100}}}}
nodes:
  - name: driver
    cmd: python node.py
    args: {args}
    namespace: r1
    required: {required}
    respawn: {respawn}
lockstep: {lockstep}
"""


def _scene(
    write_scenario,
    tmp_path: Path,
    *,
    duration: float = 3.0,
    rate: str = "max",
    args: str = "[]",
    required: bool = False,
    respawn: str = "never",
    lockstep: str = "[driver]",
) -> Path:
    (tmp_path / "node.py").write_text(NODE)
    text = SCENE.format(
        duration=duration,
        rate=rate,
        args=args,
        required=str(required).lower(),
        respawn=respawn,
        lockstep=lockstep,
    )
    return write_scenario(text)


def _physics(path: Path) -> dict[str, list[tuple[int, bytes]]]:
    out: dict[str, list[tuple[int, bytes]]] = {}
    with open(path, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages():
            out.setdefault(channel.topic, []).append((message.log_time, bytes(message.data)))
    return out


@pytest.mark.timeout(120)
def test_a_node_drives_its_robot_and_everything_is_recorded(write_scenario, tmp_path: Path) -> None:
    path = _scene(write_scenario, tmp_path)
    mcap = tmp_path / "run.mcap"
    proc = run_cli("run", str(path), "--record", str(mcap), timeout=100)
    assert proc.returncode == 0, proc.stderr
    assert re.search(r"\[driver\] heard \d+ odometry messages, last x 0\.[6-9]", proc.stderr), proc.stderr
    msgs = read_mcap(mcap)
    cmds = [(t, m) for topic, _, t, m in msgs if topic == "with_node/r1/cmd_vel"]
    # one command per 0.1 s of sim time, stamped with the sim time the node saw
    assert len(cmds) == 31, len(cmds)
    assert [t for t, _ in cmds] == [i * 100_000_000 for i in range(31)]
    x = [m.pose.pose.position.x for topic, _, _, m in msgs if topic == "with_node/r1/odom"]
    assert 0.7 < x[-1] < 0.95  # 0.3 m/s for 3 s (on a gentle curve), from the very first step


@pytest.mark.timeout(120)
def test_lockstep_runs_with_a_node_are_identical(write_scenario, tmp_path: Path) -> None:
    path = _scene(write_scenario, tmp_path)
    runs = []
    for i in range(2):
        mcap = tmp_path / f"run{i}.mcap"
        proc = run_cli("run", str(path), "--record", str(mcap), "-q", timeout=100)
        assert proc.returncode == 0, proc.stderr
        runs.append(_physics(mcap))
    assert set(runs[0]) == set(runs[1])
    for topic in runs[0]:
        if topic.endswith("/_plan"):
            continue  # the compiled scenario names its recording's path, which differs by design
        assert runs[0][topic] == runs[1][topic], topic
    assert len(runs[0]["with_node/r1/odom"]) == 151


@pytest.mark.timeout(150)
def test_a_required_node_that_dies_ends_the_run_within_a_second(write_scenario, tmp_path: Path) -> None:
    path = _scene(write_scenario, tmp_path, duration=600, rate="realtime", required=True, lockstep="[]")
    mcap = tmp_path / "run.mcap"
    proc = subprocess.Popen(
        scenario_cmd("run", str(path), "--record", str(mcap)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
        start_new_session=True,
    )
    lines: list[tuple[float, str]] = []

    def read() -> None:
        assert proc.stderr is not None
        for line in proc.stderr:
            lines.append((time.monotonic(), line.rstrip()))

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        node = None
        deadline = time.monotonic() + 30
        while node is None and time.monotonic() < deadline:
            time.sleep(0.2)
            mine = processes_of(proc.pid, "python.* node.py")  # not another suite's node
            node = mine[0] if mine else None
        assert node is not None, "the node did not start"
        # killed once a few of its commands are recorded (whole chunks), however long the start took
        wait_recorded(mcap, "with_node/r1/cmd_vel", 5, time.monotonic() + 60)
        killed = time.monotonic()
        os.kill(node, signal.SIGKILL)
        proc.wait(timeout=30)
        reader.join(timeout=5)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 1
    said = [(t, ln) for t, ln in lines if "required node 'driver' exited with code -9" in ln]
    assert said, "\n".join(ln for _, ln in lines)
    assert said[0][0] - killed < 1.0, said[0][0] - killed
    assert "Traceback" not in "\n".join(ln for _, ln in lines)
    recorded = _physics(mcap)  # finished and readable, up to the kill
    assert len(recorded["with_node/r1/cmd_vel"]) >= 5


@pytest.mark.timeout(120)
def test_a_failing_node_is_restarted_up_to_its_limit(write_scenario, tmp_path: Path) -> None:
    path = _scene(
        write_scenario,
        tmp_path,
        duration=5.0,
        rate="realtime",
        args='["0.25"]',
        respawn="on-failure",
        lockstep="[]",
    )
    text = path.read_text().replace("respawn: on-failure", "respawn: on-failure\n    respawn_limit: 2")
    path.write_text(text)
    proc = run_cli("run", str(path), "--no-record", timeout=100)
    assert proc.returncode == 0, proc.stderr  # not required: the run goes on
    assert proc.stderr.count("starting it again") == 2, proc.stderr
    assert "node 'driver' exited with code 3" in proc.stderr


@pytest.mark.timeout(60)
def test_node_mistakes_point_at_the_scenario_line(write_scenario, tmp_path: Path) -> None:
    path = _scene(write_scenario, tmp_path, lockstep="[drivr]")
    proc = run_cli("validate", str(path))
    assert proc.returncode != 0
    assert re.search(
        r"scenario\.yaml:\d+:\d+: lockstep\[0\]: no node named 'drivr'", proc.stderr + proc.stdout
    )
    assert "Traceback" not in proc.stderr


@pytest.mark.timeout(60)
def test_a_command_that_does_not_exist_is_a_validation_error(write_scenario, tmp_path: Path) -> None:
    path = _scene(write_scenario, tmp_path)
    path.write_text(path.read_text().replace("cmd: python node.py", "cmd: no_such_program_xyz --fast"))
    for command in ("validate", "run"):
        proc = run_cli(command, str(path))
        assert proc.returncode != 0
        said = proc.stderr + proc.stdout
        assert re.search(
            r"scenario\.yaml:\d+:\d+: nodes\[0\]\.cmd: command 'no_such_program_xyz' not found", said
        ), said
        assert "Traceback" not in said


@pytest.mark.timeout(120)
def test_the_go_to_goal_example_reaches_its_goal(tmp_path: Path) -> None:
    proc = run_cli(
        "run", str(SCENARIOS / "go_to_goal.yaml"), "--record", str(tmp_path / "g.mcap"), timeout=100
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "[controller] arrived at" in proc.stderr


@pytest.mark.timeout(60)
def test_a_required_node_that_dies_at_once_fails_the_run_without_a_traceback(write_scenario) -> None:
    """The node dies at once, while the world is still starting: the world is stopped quietly (it used to
    print a KeyboardInterrupt traceback) and the run fails with the node's own words. (A script that is not
    there is refused before the run: test_a_node_whose_script_is_missing_is_refused_before_the_run.)"""
    path = write_scenario(
        """
        name: gone
        duration: 5
        rate: realtime
        robots:
          - {name: r1, description: "{diffbot}", plugins: [{type: diff_drive}]}
        nodes:
          - name: driver
            cmd: [python, -c, "import sys; sys.exit('driver: cannot open /dev/motor0')"]
            required: true
        """
    )
    r = run_cli("run", str(path), "--no-record", timeout=50)
    assert r.returncode == 1, r.stderr
    assert "required node 'driver' exited with code 1" in r.stderr and "cannot open /dev/motor0" in r.stderr
    assert "Traceback" not in r.stderr and "KeyboardInterrupt" not in r.stderr, r.stderr


@pytest.mark.timeout(60)
def test_a_node_whose_script_is_missing_is_refused_before_the_run(write_scenario) -> None:
    """`python missing_script.py` used to start the world and then die with exit code 2, naming no line of
    the scenario: `run` (as `validate`) now refuses it at the command's line, before anything starts."""
    path = write_scenario(
        """
        name: gone
        duration: 5
        nodes:
          - {name: driver, cmd: python missing_script.py, required: true}
        """
    )
    (path.parent / "missing_scrpt.py").write_text("")
    r = run_cli("run", str(path), "--no-record", timeout=50)
    assert r.returncode == 1, r.stderr
    assert f"{path}:4:" in r.stderr and "nodes[0].cmd: script 'missing_script.py' not found" in r.stderr
    assert "did you mean 'missing_scrpt.py'?" in r.stderr, r.stderr
    assert "exited with code" not in r.stderr and "Traceback" not in r.stderr, r.stderr


def _tail_of(text: str, stopping: bool, capsys: pytest.CaptureFixture[str]) -> str:
    import io

    from runner.launch.nodes import OutputTail

    tail = OutputTail(io.BytesIO(text.encode()), "[n] ")
    tail.stopping = stopping
    tail.run()
    return capsys.readouterr().err


def test_a_keyboardinterrupt_traceback_from_the_runners_own_stop_is_left_out(capsys) -> None:
    """A node stopped by the runner (SIGINT) before it set up its own handling prints Python's
    KeyboardInterrupt traceback: that is the stop obeyed, not news. Any other traceback, or one before the
    runner asked, is shown whole."""
    interrupted = 'started\nTraceback (most recent call last):\n  File "n.py", line 3, in <module>\n    import x\nKeyboardInterrupt\nbye\n'
    failed = 'Traceback (most recent call last):\n  File "n.py", line 3, in <module>\nValueError: bad\n'
    assert _tail_of(interrupted, True, capsys) == "[n] started\n[n] bye\n"
    assert "KeyboardInterrupt" in _tail_of(interrupted, False, capsys)
    out = _tail_of(failed, True, capsys)
    assert out.count("[n] ") == 3 and "ValueError: bad" in out
