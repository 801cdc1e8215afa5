"""Hosts: a run split across two machines joined by Zenoh, tested for real on one machine with two Linux
network namespaces (a veth pair between them, each side with its own address): the main host records and
judges, the other runs its world with `scenario run FILE --host NAME`. The recording holds the same topics
as the one-host run of the same scenario (`--local`)."""

from __future__ import annotations

import os
import random
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest
from mcap.reader import make_reader

from tests.conftest import REPO, processes_of, scenario_cmd, start_cli, wait_recorded

SCENE = """
name: spread
duration: 3.0
rate: max
hosts:
  main: {{endpoint: "tcp/{a}:7447"}}
  far: {{endpoint: "tcp/{b}:7448"}}
worlds:
  - name: near
  - name: yonder
    host: far
robots:
  - name: r1
    world: near
    description: "{diffbot}"
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{{type: diff_drive}}, {{type: imu, params: {{rate: 100}}}}]
  - name: r2
    world: yonder
    description: "{diffbot}"
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{{type: diff_drive}}, {{type: lidar, params: {{link: lidar_link, samples: 90, rate: 10}}}}]
timeline:
  - {{t: 0.0, topic: near/r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.3}}}}}}
  - {{t: 0.0, topic: yonder/r2/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.4}}}}}}
assertions:
  - {{name: r2_drives_far_away, type: distance_traveled, robot: r2, min: 0.9, max: 1.3}}
"""


def _sh(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(list(args), capture_output=True, text=True, timeout=30)


@pytest.fixture
def two_namespaces():
    """Two network namespaces joined by a veth pair: (name_a, addr_a, name_b, addr_b)."""
    if os.geteuid() != 0 or shutil.which("ip") is None:
        pytest.skip("network namespaces need root and iproute2 (`ip`): the two-host test cannot run here")
    tag = f"sc{os.getpid() % 100000}"
    a, b = f"{tag}a", f"{tag}b"
    net = random.randint(10, 250)
    addr_a, addr_b = f"10.{net}.77.1", f"10.{net}.77.2"
    steps = [
        ("ip", "netns", "add", a),
        ("ip", "netns", "add", b),
        ("ip", "link", "add", f"{tag}va", "type", "veth", "peer", "name", f"{tag}vb"),
        ("ip", "link", "set", f"{tag}va", "netns", a),
        ("ip", "link", "set", f"{tag}vb", "netns", b),
        ("ip", "-n", a, "addr", "add", f"{addr_a}/24", "dev", f"{tag}va"),
        ("ip", "-n", b, "addr", "add", f"{addr_b}/24", "dev", f"{tag}vb"),
        ("ip", "-n", a, "link", "set", f"{tag}va", "up"),
        ("ip", "-n", b, "link", "set", f"{tag}vb", "up"),
        ("ip", "-n", a, "link", "set", "lo", "up"),
        ("ip", "-n", b, "link", "set", "lo", "up"),
    ]
    try:
        for step in steps:
            proc = _sh(*step)
            if proc.returncode != 0:
                pytest.skip(
                    f"cannot set up network namespaces here ({' '.join(step)}: {proc.stderr.strip()})"
                )
        yield a, addr_a, b, addr_b
    finally:
        _sh("ip", "netns", "del", a)
        _sh("ip", "netns", "del", b)


def _start_hosts(path: Path, ns_a: str, ns_b: str, *main_args: str) -> tuple[subprocess.Popen[str], ...]:
    """The main host's runner in one namespace, the far host's (`--host far`) in the other."""
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    runs = (
        (ns_a, scenario_cmd("run", str(path), *main_args)),
        (ns_b, scenario_cmd("run", str(path), "--host", "far")),
    )
    return tuple(
        subprocess.Popen(
            ["ip", "netns", "exec", ns, *cmd],
            cwd=REPO,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for ns, cmd in runs
    )


def _topics(path: Path) -> dict[str, int]:
    out: dict[str, int] = {}
    with open(path, "rb") as f:
        for _, channel, _message in make_reader(f).iter_messages():
            out[channel.topic] = out.get(channel.topic, 0) + 1
    return out


@pytest.mark.timeout(180)
def test_a_two_host_run_records_what_the_one_host_run_does(
    two_namespaces, write_scenario, tmp_path: Path
) -> None:
    ns_a, addr_a, ns_b, addr_b = two_namespaces
    path = write_scenario(SCENE.format(a=addr_a, b=addr_b, diffbot="{diffbot}"))
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    spread = tmp_path / "spread.mcap"
    main, far = _start_hosts(path, ns_a, ns_b, "--record", str(spread))
    try:
        main_out, main_err = main.communicate(timeout=120)
        far_out, far_err = far.communicate(timeout=60)
    finally:
        for p in (main, far):
            if p.poll() is None:
                p.kill()
    assert main.returncode == 0, main_out + main_err + "\n--- far:\n" + far_out + far_err
    assert far.returncode == 0, far_out + far_err
    assert f"Zenoh on tcp/{addr_b}:7448" in far_err  # the far part ran on its own address
    assert "1 passed, 0 failed" in main_out  # judged on the main host, from the far world's messages

    local = tmp_path / "local.mcap"
    proc = subprocess.run(
        [*scenario_cmd("run", str(path), "--local", "--record", str(local), "-q")],
        cwd=REPO,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    spread_topics, local_topics = _topics(spread), _topics(local)
    assert set(spread_topics) == set(local_topics)
    assert "spread/yonder/r2/scan" in spread_topics and "spread/near/r1/imu" in spread_topics
    assert spread_topics == local_topics  # every message of both worlds, wherever they ran


@pytest.mark.timeout(240)
def test_a_world_lost_on_the_other_host_fails_the_run(two_namespaces, write_scenario, tmp_path: Path) -> None:
    ns_a, addr_a, ns_b, addr_b = two_namespaces
    text = SCENE.format(a=addr_a, b=addr_b, diffbot="{diffbot}").replace("duration: 3.0", "duration: 600")
    path = write_scenario(text.replace("rate: max", "rate: realtime"))
    mcap = tmp_path / "spread.mcap"
    main, far = _start_hosts(path, ns_a, ns_b, "--record", str(mcap), "--no-judge")
    try:
        far_world = None
        deadline = time.monotonic() + 120  # a loaded machine (another suite beside) starts slowly
        while far_world is None and time.monotonic() < deadline:
            time.sleep(0.3)
            # this run's far world (not another test's, nor a helper a world forks)
            mine = processes_of(far.pid, r"runner\.sim /", direct=True)
            far_world = mine[0] if mine else None
        assert far_world is not None, "the far world did not start"
        # killed once it steps (its clock in the recording's whole chunks), however long the start took
        wait_recorded(mcap, "spread/yonder/clock", 1, deadline)
        killed = time.monotonic()
        os.kill(far_world, signal.SIGKILL)
        main_out, main_err = main.communicate(timeout=30)
        took = time.monotonic() - killed
        far.communicate(timeout=30)
    finally:
        for p in (main, far):
            if p.poll() is None:
                p.kill()
    assert main.returncode == 1, main_out + main_err
    assert "the world yonder process on host 'far' went away" in main_err, main_err
    assert took < 5.0, took
    assert "spread/near/clock" in _topics(mcap)  # finished and readable


def _ancestor(pid: int, ancestor: int) -> bool:
    """Whether `ancestor` is a parent, grandparent... of `pid` (False if either is gone)."""
    try:
        while pid > 1:
            status = Path(f"/proc/{pid}/status").read_text()
            pid = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("PPid:")))
            if pid == ancestor:
                return True
    except (OSError, StopIteration, ValueError):
        pass
    return False


NODE = """
from runner.node import Node

with Node() as node:
    cmd = node.publisher("cmd_vel", "geometry_msgs/msg/Twist")
    while node.ok():
        cmd.publish({"linear": {"x": 0.2}})
        node.sleep(0.1)
"""


@pytest.mark.timeout(120)
def test_a_required_node_lost_on_the_other_host_fails_the_run(
    two_namespaces, write_scenario, tmp_path: Path
) -> None:
    ns_a, addr_a, ns_b, addr_b = two_namespaces
    (tmp_path / "node.py").write_text(NODE)
    text = SCENE.format(a=addr_a, b=addr_b, diffbot="{diffbot}").replace("duration: 3.0", "duration: 600")
    text = text.replace("rate: max", "rate: realtime") + (
        "nodes:\n  - {name: driver, host: far, namespace: r2, cmd: python node.py, required: true}\n"
    )
    path = write_scenario(text)
    mcap = tmp_path / "spread.mcap"
    main, far = _start_hosts(path, ns_a, ns_b, "--record", str(mcap), "--no-judge")
    try:
        node = None
        deadline = time.monotonic() + 40
        while node is None and time.monotonic() < deadline:
            time.sleep(0.3)
            out = subprocess.run(["pgrep", "-f", "python.* node.py"], capture_output=True, text=True).stdout
            node = next((int(p) for p in out.split() if _ancestor(int(p), far.pid)), None)
        assert node is not None, "the node did not start"
        # killed once its commands are in the recording (its whole chunks, read as they are written),
        # however long the start took on a loaded machine
        wait_recorded(mcap, "spread/yonder/r2/cmd_vel", 5, deadline + 40, every_s=0.3)
        os.kill(node, signal.SIGKILL)
        main_out, main_err = main.communicate(timeout=30)
        _far_out, far_err = far.communicate(timeout=30)
    finally:
        for p in (main, far):
            if p.poll() is None:
                p.kill()
    assert main.returncode == 1, main_out + main_err
    assert "required node 'driver' on host 'far' went away" in main_err, main_err
    assert far.returncode == 1 and "required node 'driver' exited with code -9" in far_err, far_err
    topics = _topics(mcap)  # finished and readable, with the far node's commands in it
    assert topics.get("spread/yonder/r2/cmd_vel", 0) >= 5


@pytest.mark.timeout(90)
def test_the_main_host_says_which_host_it_waits_for(write_scenario) -> None:
    """A host started by hand may come a while after the main one: the main runner says whom it waits for
    (instead of failing after a short fixed time), and Ctrl-C still ends the wait."""
    from runner.wire.transport import free_port

    a, b = free_port(), free_port()
    text = SCENE.format(a="127.0.0.1", b="127.0.0.1", diffbot="{diffbot}")
    path = write_scenario(text.replace(":7447", f":{a}").replace(":7448", f":{b}"))
    proc = start_cli("run", str(path), "--no-judge")
    try:
        assert proc.stderr is not None
        lines: list[str] = []
        for line in proc.stderr:  # ends when the runner does: the test's timeout bounds it
            lines.append(line)
            if "waiting for" in line:
                break
        assert (
            lines
            and "waiting for host 'far' to join (run `scenario run FILE --host NAME` there)" in lines[-1]
        )
        proc.send_signal(signal.SIGINT)
        _out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, "".join(lines) + err


def test_start_limits_tell_this_host_from_the_others() -> None:
    """This host's parts get START_TIMEOUT_S; other hosts HOST_JOIN_TIMEOUT_S, said once after a few
    seconds; the worlds wait longer still for the word to start, so that the runner is the one that says why."""
    import threading
    from types import SimpleNamespace

    from runner.errors import RunError
    from runner.launch import worlds as launch
    from runner.sim import __main__ as world_main

    def part(label: str, host: str | None, ready: bool = False) -> SimpleNamespace:
        event = threading.Event()
        if ready:
            event.set()
        return SimpleNamespace(label=label, remote_host=host, ready=event)

    here, far = part("world near", None, ready=True), part("world yonder", "far")
    waiting: set[str] = set()
    launch._check_start([here, far], 1.0, waiting)
    assert waiting == set()
    launch._check_start([here, far], launch.HOST_WAIT_NOTICE_S + 1, waiting)
    assert waiting == {"far"}
    launch._check_start([here, far], launch.START_TIMEOUT_S + 1, waiting)  # only this host's parts
    with pytest.raises(RunError, match=r"not every host joined within \d+ s: world yonder on host 'far'"):
        launch._check_start([here, far], launch.HOST_JOIN_TIMEOUT_S + 1, waiting)
    slow = part("world near", None)
    with pytest.raises(RunError, match=r"not every part started within \d+ s: world near$"):
        launch._check_start([slow, far], launch.START_TIMEOUT_S + 1, waiting)
    assert world_main.START_TIMEOUT_S > launch.HOST_JOIN_TIMEOUT_S + 30
