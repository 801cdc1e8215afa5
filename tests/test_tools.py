"""`scenario echo`, `pub` and `topics` against a real running scenario (found on this machine without
being told, or joined by endpoint)."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
import yaml

from runner.wire.transport import free_port
from tests.conftest import run_cli, scenario_cmd

SCENE = """
name: toolrun
duration: 120
rate: realtime
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive, params: {odometry_source: world}}
      - {type: lidar, params: {link: lidar_link, samples: 8, rate: 10}}
"""


@pytest.fixture
def live_run(write_scenario, tmp_path: Path):
    path = write_scenario(SCENE)
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    proc = subprocess.Popen(
        scenario_cmd("run", str(path), "--no-record", "--listen", endpoint, "-q"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            probe = run_cli("echo", "clock", "-n", "1", "--connect", endpoint, "--run", "toolrun", timeout=20)
            if probe.returncode == 0:
                break
        yield endpoint
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)


def _docs(text: str) -> list[dict]:
    return [d for d in yaml.safe_load_all(text) if d is not None]


@pytest.mark.timeout(90)
def test_echo_pub_and_topics_work_on_a_live_run(live_run: str) -> None:
    # echo -n 3: three decoded scans, found without --connect (the local run announces itself)
    proc = run_cli("echo", "r1/scan", "-n", "3", timeout=30)
    assert proc.returncode == 0, proc.stderr
    scans = _docs(proc.stdout)
    assert len(scans) == 3 and all(len(s["ranges"]) == 8 for s in scans), proc.stdout
    assert proc.stdout.count("# toolrun/r1/scan (sensor_msgs/msg/LaserScan) at ") == 3

    def x() -> float:
        got = run_cli("echo", "r1/odom", "-n", "1", "--field", "pose.pose.position.x", timeout=30)
        assert got.returncode == 0, got.stderr
        assert "..." not in got.stdout, got.stdout  # (YAML's document end after a lone value)
        return float(_docs(got.stdout)[0])

    start = x()
    # pub moves the robot: 0.5 m/s for ~1 s
    proc = run_cli(
        "pub",
        "r1/cmd_vel",
        "geometry_msgs/Twist",
        "{linear: {x: 0.5}}",
        "-r",
        "20",
        "-n",
        "20",
        "--connect",
        live_run,
        "--run",
        "toolrun",
        timeout=30,
    )
    assert proc.returncode == 0, proc.stderr
    assert "published 20 message(s) on toolrun/r1/cmd_vel" in proc.stderr
    time.sleep(0.5)
    assert x() > start + 0.3

    proc = run_cli("topics", "--seconds", "1.5", timeout=30)
    assert proc.returncode == 0, proc.stderr
    for key in ("toolrun/clock", "toolrun/r1/scan", "toolrun/r1/odom", "toolrun/r1/tf"):
        assert key in proc.stdout, proc.stdout
    assert "sensor_msgs/msg/LaserScan" in proc.stdout
    scan_row = next(line for line in proc.stdout.splitlines() if "toolrun/r1/scan" in line)
    assert "world" in scan_row and "recorder" not in scan_row  # (--no-record: no recorder)
    cmd_row = next(line for line in proc.stdout.splitlines() if "toolrun/r1/cmd_vel" in line)
    assert "geometry_msgs/msg/Twist" in cmd_row  # subscribed by the world, silent: listed all the same
    # the run's helper topics (`_state`, for `scenario render`) only with --all, as in `scenario info`
    assert "toolrun/_state" not in proc.stdout and "helper topic(s)" in proc.stdout, proc.stdout
    every = run_cli("topics", "--seconds", "1", "--all", timeout=30)
    assert every.returncode == 0, every.stderr
    assert "toolrun/_state" in every.stdout and "helper topic(s)" not in every.stdout, every.stdout


@pytest.mark.timeout(90)
def test_graph_draws_every_plugins_topics_and_the_tools(
    live_run: str, write_scenario, tmp_path: Path
) -> None:
    from PIL import Image

    from runner.compile import compile_plan
    from runner.scenario.loader import load_file
    from runner.scenario.validate import validate_scenario

    doc = load_file(tmp_path / "scenario.yaml")  # the live run's own file
    plan = compile_plan(validate_scenario(doc), doc)
    echo = subprocess.Popen(
        scenario_cmd("echo", "r1/scan", "--connect", live_run, "--run", "toolrun"),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        time.sleep(2.0)  # its tokens declared
        proc = run_cli("graph", "-o", str(tmp_path / "g"), timeout=30)
    finally:
        echo.terminate()
        echo.wait(timeout=10)
    assert proc.returncode == 0, proc.stderr
    dot = (tmp_path / "g.dot").read_text()
    assert dot.startswith("digraph")
    plugin_topics = [t for r in plan.robots for p in r.plugins for t in p.topics]
    assert len(plugin_topics) >= 4  # cmd_vel in; odom, tf, scan out
    for t in plugin_topics:  # every plugin's topic, with its direction
        edge = (
            f'"process:world" -> "topic:{t.key}"'
            if t.direction == "pub"
            else f'"topic:{t.key}" -> "process:world"'
        )
        assert edge in dot, (edge, dot)
        assert t.key.removeprefix("toolrun/") in proc.stdout
    assert f'"topic:toolrun/r1/scan" -> "process:echo-{echo.pid}"' in dot
    with Image.open(tmp_path / "g.png") as img:
        assert img.format == "PNG" and img.width > 300 and img.height > 200


@pytest.mark.timeout(60)
def test_tools_say_clearly_when_there_is_nothing_to_join() -> None:
    proc = run_cli("echo", "r1/scan", "--run", "no_such_run_here", timeout=30)
    assert proc.returncode == 1
    assert "no run named 'no_such_run_here'" in proc.stderr and "Traceback" not in proc.stderr
    proc = run_cli("pub", "r1/cmd_vel", "geometry_msgs/Twst", "{}", "--run", "x", timeout=30)
    assert proc.returncode == 1 and "unknown message type" in proc.stderr and "Twist" in proc.stderr


@pytest.mark.timeout(90)
def test_teleop_key_presses_publish_the_right_twists(live_run: str) -> None:
    """Through a pseudo-terminal, as a user's keyboard: i forward, j turn left, q faster, k stop."""
    import pty

    import zenoh

    from runner.wire import msgs
    from runner.wire.transport import make_config

    got: list[tuple[float, float]] = []

    def on_twist(sample: zenoh.Sample) -> None:
        t = msgs.decode(sample.payload.to_bytes(), "geometry_msgs/msg/Twist")
        got.append((round(t.linear.x, 4), round(t.angular.z, 4)))

    with zenoh.open(make_config("client", connect=[live_run])) as session:
        sub = session.declare_subscriber("toolrun/r1/cmd_vel", on_twist)
        master, slave = pty.openpty()
        proc = subprocess.Popen(
            scenario_cmd(
                "teleop", "r1", "--speed", "0.4", "--turn", "0.8", "--connect", live_run, "--run", "toolrun"
            ),
            stdin=slave,
            stdout=slave,
            stderr=slave,
            start_new_session=True,
        )
        os.close(slave)
        try:
            screen = b""
            deadline = time.monotonic() + 30
            while b"publishing on toolrun/r1/cmd_vel" not in screen and time.monotonic() < deadline:
                screen += os.read(master, 4096)
            time.sleep(0.5)  # the subscriber is matched
            for key in (b"i", b"j", b"q", b"i", b"k"):
                os.write(master, key)
                time.sleep(0.2)
            os.write(master, b"\x03")  # Ctrl-C: quits, and stops the robot
            proc.wait(timeout=15)
            time.sleep(0.3)
        finally:
            if proc.poll() is None:
                proc.kill()
            os.close(master)
        sub.undeclare()
    assert proc.returncode == 0
    assert got == [(0.4, 0.0), (0.0, 0.8), (0.44, 0.0), (0.0, 0.0), (0.0, 0.0)], got


@pytest.mark.timeout(60)
def test_teleop_needs_a_terminal(live_run: str) -> None:
    proc = subprocess.run(
        scenario_cmd("teleop", "r1", "--connect", live_run, "--run", "toolrun"),
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert proc.returncode == 1 and "not one" in proc.stderr and "Traceback" not in proc.stderr
