"""Services and actions from the outside, against a real run: `scenario call` and `scenario action` (a
goal's feedback, result, rejection, Ctrl-C cancelling it), a node's `call`, action client and own
service, a lockstep node asking the world, and `validate`, `topics` and `graph` listing them.

The services are a test plugin's (tests/service_plugin/scenario_flipper.py: SetBool `flip`, Trigger
`fail` that raises, Empty `hang` that never answers, GripperCommand action `grip`), registered through the
`scenario.plugins` entry-point group as a third-party package would be."""

from __future__ import annotations

import os
import queue
import re
import shutil
import signal
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from runner.wire.transport import free_port
from tests.conftest import DIFFBOT, read_mcap, run_cli, scenario_cmd

PLUGIN = Path(__file__).parent / "service_plugin"

SCENE = """
name: svcrun
duration: 600
rate: realtime
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: flipper}
"""


@pytest.fixture(scope="module")
def flipper(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """The flipper plugin registered as an installed package is (a .dist-info with its entry point), on
    PYTHONPATH for the processes the tests start: the environment itself is not touched."""
    site = tmp_path_factory.mktemp("site")
    shutil.copy(PLUGIN / "scenario_flipper.py", site)
    info = site / "scenario_flipper-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: scenario-flipper\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[scenario.plugins]\nflipper = scenario_flipper:Flipper\n")
    before = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join([str(site), *([before] if before else [])])
    yield site
    if before is None:
        os.environ.pop("PYTHONPATH", None)
    else:
        os.environ["PYTHONPATH"] = before


@pytest.fixture(scope="module")
def live(flipper: Path, tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """A running scenario with the flipper plugin (real time); its endpoint. Ready once `echo` hears its
    clock."""
    folder = tmp_path_factory.mktemp("svcrun")
    path = folder / "scenario.yaml"
    path.write_text(SCENE.replace("{diffbot}", str(DIFFBOT)))
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    proc = subprocess.Popen(
        scenario_cmd("run", str(path), "--no-record", "--listen", endpoint, "-q"),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 40
        while time.monotonic() < deadline and proc.poll() is None:
            probe = run_cli("echo", "clock", "-n", "1", "--connect", endpoint, "--run", "svcrun", timeout=20)
            if probe.returncode == 0:
                break
        assert proc.poll() is None, proc.stderr.read() if proc.stderr else ""
        yield endpoint
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)


def _call(*args: str, timeout: float = 30) -> subprocess.CompletedProcess[str]:
    return run_cli("call", *args, timeout=timeout)


def _error(proc: subprocess.CompletedProcess[str]) -> str:
    """A failed command's error: exit 1, one `error:` line, no traceback."""
    assert proc.returncode == 1, (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr, proc.stderr
    assert "error: " in proc.stderr, proc.stderr
    return proc.stderr


@pytest.mark.timeout(180)
def test_call_prints_the_response_as_yaml_and_errors_clearly(live: str) -> None:
    proc = _call("r1/flip", "std_srvs/srv/SetBool", "{data: true}")
    assert proc.returncode == 0, proc.stderr
    first = yaml.safe_load(proc.stdout)
    assert first["success"] is True and first["message"].endswith("data=True"), proc.stdout
    # the type as the run's graph says it; found with --connect too
    proc = _call("r1/flip", "{data: false}", "--connect", live, "--run", "svcrun")
    assert proc.returncode == 0, proc.stderr
    second = yaml.safe_load(proc.stdout)
    assert second["success"] is False and second["message"].endswith("data=False"), proc.stdout
    n1, n2 = (int(re.match(r"call (\d+) ", r["message"]).group(1)) for r in (first, second))  # type: ignore[union-attr]
    assert n2 == n1 + 1  # the same service, answered by the world each time
    assert "calling svcrun/r1/flip (std_srvs/srv/SetBool)" in proc.stderr
    # the server's error reply
    assert "the service failed: RuntimeError: asked to fail" in _error(_call("r1/fail"))
    # nothing answering within --timeout
    assert "no answer from svcrun/r1/hang within 0.5 s" in _error(_call("r1/hang", "--timeout", "0.5"))
    # mistakes of the user's
    assert "has no service r1/flop; did you mean r1/flip?" in _error(_call("r1/flop", "{data: true}"))
    assert "no service answers on svcrun/r1/nothing" in _error(_call("r1/nothing", "std_srvs/srv/Empty"))
    assert "is a std_srvs/srv/SetBool, not a std_srvs/srv/Trigger" in _error(
        _call("r1/flip", "std_srvs/srv/Trigger")
    )
    assert "the request is not YAML: line 1, column 10" in _error(_call("r1/flip", "{data: [1"))
    assert "has no field 'dta'" in _error(_call("r1/flip", "{dta: true}"))
    assert "unknown service type 'std_srvs/SetBol'; did you mean std_srvs/srv/SetBool?" in _error(
        _call("r1/flip", "std_srvs/SetBol", "{data: true}")
    )
    assert "r1/grip is an action: use `scenario action`" in _error(_call("r1/grip"))


@pytest.mark.timeout(180)
def test_action_prints_feedback_and_result_and_says_a_rejection(live: str) -> None:
    proc = run_cli("action", "r1/grip", "{command: {position: 0.35}}", "--feedback", timeout=30)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert re.search(r"^Goal accepted with ID: [0-9a-f]{32}$", out, re.M), out
    feedback = [yaml.safe_load(block) for block in re.findall(r"Feedback:\n((?:    .*\n)+)", out)]
    # every 0.1 s of sim time for 0.35 s: 0.0, 0.1, 0.2, 0.3
    assert [round(f["position"], 3) for f in feedback] == [0.0, 0.1, 0.2, 0.3], out
    result = yaml.safe_load(re.search(r"Result:\n((?:    .*\n)+)", out).group(1))  # type: ignore[union-attr]
    assert result["reached_goal"] is True and result["position"] == pytest.approx(0.35), out
    assert out.rstrip().endswith("Goal finished with status: SUCCEEDED"), out
    # no --feedback: none printed; the type given explicitly
    proc = run_cli(
        "action", "r1/grip", "control_msgs/action/GripperCommand", "{command: {position: 0.1}}", timeout=30
    )
    assert proc.returncode == 0 and "Feedback:" not in proc.stdout, proc.stdout + proc.stderr
    # rejected (a negative position): said, exit 1
    proc = run_cli("action", "r1/grip", "{command: {position: -1}}", timeout=30)
    assert proc.returncode == 1 and "Goal was rejected." in proc.stdout, proc.stdout + proc.stderr
    assert "has no action r1/gripp; did you mean r1/grip?" in _error(
        run_cli("action", "r1/gripp", "{command: {position: 1}}", timeout=30)
    )
    assert "has no field 'comand'" in _error(run_cli("action", "r1/grip", "{comand: {}}", timeout=30))
    assert (
        "r1/grip is a control_msgs/action/GripperCommand, not a control_msgs/action/FollowJointTrajectory"
        in (
            _error(
                run_cli("action", "r1/grip", "control_msgs/action/FollowJointTrajectory", "{}", timeout=30)
            )
        )
    )


@pytest.mark.timeout(120)
def test_ctrl_c_cancels_the_goal(live: str) -> None:
    """As `ros2 action send_goal`: Ctrl-C sends cancel_goal; the goal ends CANCELED, the command with 130."""
    proc = subprocess.Popen(
        scenario_cmd("action", "r1/grip", "{command: {position: 60}}", "--feedback"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )
    lines: queue.SimpleQueue[str] = queue.SimpleQueue()
    reader = threading.Thread(target=lambda: [lines.put(line) for line in proc.stdout], daemon=True)  # type: ignore[union-attr]
    reader.start()
    seen = []
    try:
        deadline = time.monotonic() + 40
        while not any(line.startswith("Feedback:") for line in seen) and time.monotonic() < deadline:
            try:
                seen.append(lines.get(timeout=1))
            except queue.Empty:
                assert proc.poll() is None, proc.stderr.read()  # type: ignore[union-attr]
        assert any(line.startswith("Feedback:") for line in seen), seen
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    stderr = proc.stderr.read()  # type: ignore[union-attr]
    reader.join(timeout=10)  # (it ends with the process's stdout)
    while not lines.empty():
        seen.append(lines.get())
    out = "".join(seen)
    assert proc.returncode == 130, (out, stderr)
    assert "Canceling goal..." in stderr and "Goal canceled." in stderr, stderr
    assert "Goal finished with status: CANCELED" in out, out
    assert "Traceback" not in stderr


@pytest.mark.timeout(180)
def test_a_node_calls_services_sends_goals_and_offers_a_service(live: str) -> None:
    from runner.node import Node, ServiceCallError
    from runner.wire.ros2 import gid

    with Node("asker", endpoint=live, run="svcrun", namespace="r1", handle_signals=False) as node:
        events: list[Any] = []
        node.subscribe("flip/_service_event", "std_srvs/srv/SetBool_Event", events.append)
        response = node.call("flip", "std_srvs/srv/SetBool", {"data": True})
        assert response.success is True and response.message.endswith("data=True")
        deadline = time.monotonic() + 10
        while len(events) < 2 and time.monotonic() < deadline:
            node.spin_once(timeout=0.1)
        # the world's service events name the asker as rmw_zenoh's attachment does: its GID, request 1
        assert [e.info.event_type for e in events] == [1, 2]  # REQUEST_RECEIVED, RESPONSE_SENT
        assert {bytes(e.info.client_gid) for e in events} == {gid(node.graph.base)}
        assert {e.info.sequence_number for e in events} == {1}
        with pytest.raises(ServiceCallError, match="asked to fail"):
            node.call("fail", "std_srvs/srv/Trigger")
        with pytest.raises(ServiceCallError, match="no service answers on svcrun/r1/nothing"):
            node.call("nothing", "std_srvs/srv/Empty", timeout=2)
        with pytest.raises(ServiceCallError, match=r"within 0\.5 s"):
            node.call("hang", "std_srvs/srv/Empty", timeout=0.5)

        grip = node.action_client("grip", "control_msgs/action/GripperCommand")
        feedback: list[float] = []
        goal = grip.send_goal(
            {"command": {"position": 0.25}}, feedback=lambda fb: feedback.append(fb.position)
        )
        assert goal.accepted and goal.stamp_ns > 0
        end = goal.result(timeout=30)
        assert end.succeeded and end.result.reached_goal and end.result.position == pytest.approx(0.25)
        assert [round(p, 3) for p in feedback] == [0.0, 0.1, 0.2]  # on the node's thread, in order

        long = grip.send_goal({"command": {"position": 60}})
        node.sleep(0.1)
        assert long.cancel() is True
        assert long.result(timeout=30).status_name == "CANCELED"
        assert grip.send_goal({"command": {"position": -1}}).accepted is False

        # a node's own service, called by `scenario call` (found through the node's graph token)
        node.service("ping", "std_srvs/srv/Trigger", lambda _request: {"success": True, "message": "pong"})
        proc = subprocess.Popen(
            scenario_cmd("call", "r1/ping", "--connect", live, "--run", "svcrun"),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        deadline = time.monotonic() + 40
        while proc.poll() is None and time.monotonic() < deadline:
            node.spin_once(timeout=0.1)  # the node answers inside spin_once, on its own thread
        if proc.poll() is None:
            proc.kill()
        out, stderr = proc.communicate(timeout=10)
        assert proc.returncode == 0, stderr
        assert yaml.safe_load(out) == {"success": True, "message": "pong"}


@pytest.mark.timeout(120)
def test_topics_graph_and_validate_list_the_services_and_actions(live: str, tmp_path: Path) -> None:
    proc = run_cli("topics", "--seconds", "0.5", timeout=30)
    assert proc.returncode == 0, proc.stderr
    rows = {line.split("│")[1].strip(): line for line in proc.stdout.splitlines() if "svcrun/r1/" in line}
    for key, type_name, kind in (
        ("svcrun/r1/flip", "std_srvs/srv/SetBool", "service"),
        ("svcrun/r1/grip", "control_msgs/action/GripperCommand", "action"),
    ):
        assert key in rows, proc.stdout
        assert type_name in rows[key] and kind in rows[key] and "world" in rows[key], rows[key]
    assert "svcrun/r1/grip/_action/send_goal" not in proc.stdout  # an action once, by its name
    every = run_cli("topics", "--seconds", "0.5", "--all", timeout=30)
    assert (
        "svcrun/r1/grip/_action/cancel_goal" in every.stdout and "action_msgs/srv/CancelGoal" in every.stdout
    )

    proc = run_cli("graph", "-o", str(tmp_path / "g"), timeout=30)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert any(re.fullmatch(r"r1/flip\s+std_srvs/srv/SetBool\s+service: world", line) for line in lines), (
        lines
    )
    assert any(
        re.fullmatch(r"r1/grip\s+control_msgs/action/GripperCommand\s+action: world", line) for line in lines
    ), lines
    # the 4 of the robot's plugins, and the world's 12 simulation control services (runner.plan)
    assert ", 16 services and actions -> " in " ".join(proc.stdout.split()), proc.stdout
    dot = (tmp_path / "g.dot").read_text()
    assert '"service:svcrun/r1/grip"' in dot and "shape=octagon" in dot and "shape=hexagon" in dot
    assert '"service:svcrun/r1/flip" -> "process:world" [style=dotted];' in dot
    assert (tmp_path / "g.png").stat().st_size > 0


@pytest.mark.timeout(120)
def test_validate_lists_the_services_and_action_servers(flipper: Path, write_scenario) -> None:
    proc = run_cli("validate", str(write_scenario(SCENE)), timeout=60)
    assert proc.returncode == 0, proc.stderr
    text = proc.stdout
    assert "Services and actions" in text, text
    table = text[text.index("Services and actions") :]
    for key, type_name, kind in (
        ("svcrun/r1/flip", "std_srvs/srv/SetBool", "service"),
        ("svcrun/r1/fail", "std_srvs/srv/Trigger", "service"),
        ("svcrun/r1/grip", "control_msgs/action/GripperCommand", "action"),
    ):
        row = next(line for line in table.splitlines() if f" {key} " in line)
        assert type_name in row and kind in row and "r1/flipper" in row, row


CALLER = """
name: svclock
duration: 1.0
rate: max
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: flipper}
nodes:
  - {name: caller, cmd: python caller_node.py, namespace: r1, publishes: {calls: std_msgs/msg/String}}
lockstep: [caller]
"""


@pytest.mark.timeout(180)
def test_a_lockstep_node_is_answered_while_the_world_waits_for_it(
    flipper: Path, write_scenario, tmp_path
) -> None:
    """A lockstep node's calls are answered where the world waits for it (within the step after the
    clock it saw), its goal while it lets the world on step by step; two rate: max runs get the same."""
    path = write_scenario(CALLER)
    shutil.copy(PLUGIN / "caller_node.py", path.parent)
    recorded = []
    for i in range(2):
        mcap = tmp_path / f"svclock{i}.mcap"
        proc = run_cli("run", str(path), "--record", str(mcap), "--no-judge", "-q", timeout=120)
        assert proc.returncode == 0, proc.stderr
        recorded.append([(t, m.data) for topic, _, t, m in read_mcap(mcap) if topic == "svclock/r1/calls"])
    calls = [data for _t, data in recorded[0]]
    for i, data in enumerate(("True", "False", "True")):
        # answered while the world waits for the node: at the first step boundary after the clock it saw
        # (the scenario's step is 2 ms), not later however long the answer takes in wall time
        got = re.fullmatch(rf"{data} call {i + 1} at (\d+): data={data} \(asked at (\d+)\)", calls[i])
        assert got and 0 <= int(got.group(1)) - int(got.group(2)) <= 2_000_000, calls
    assert calls[3].startswith("error svclock/r1/fail: the service failed: RuntimeError: asked to fail"), (
        calls
    )
    assert recorded[0] == recorded[1]  # rate: max, lockstep: the same answers at the same sim times
    assert calls[4] == "True SUCCEEDED True 3", calls  # feedback at 0.0, 0.1, 0.2 s of a 0.25 s goal


def test_the_graph_shows_an_action_once_by_its_name_and_draws_services(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """In process, a graph as the tokens give it: an action's three services are one entry (its
    send_goal's type without `_SendGoal`), hidden services stay hidden, the drawings take them all (the
    PNG names them in the box of the process that answers them)."""
    from PIL import Image, ImageDraw

    drawn: list[str] = []
    original = ImageDraw.ImageDraw.text

    def text(self: Any, xy: Any, text: str, *args: Any, **kwargs: Any) -> Any:
        drawn.append(text)
        return original(self, xy, text, *args, **kwargs)

    monkeypatch.setattr(ImageDraw.ImageDraw, "text", text)

    from runner.tools.graph_draw import render_png, summary_lines, to_dot
    from runner.wire.graph import Endpoint, Graph

    g = Graph("run", {"world": "world", "ctl": "node"})
    grip = "run/r1/grip/_action"
    g.endpoints |= {
        Endpoint("world", "pub", "run/clock", "rosgraph_msgs/msg/Clock"),
        Endpoint("ctl", "sub", "run/clock", "rosgraph_msgs/msg/Clock"),
        Endpoint("world", "srv", "run/r1/flip", "std_srvs/srv/SetBool"),
        Endpoint("world", "srv", f"{grip}/send_goal", "control_msgs/action/GripperCommand_SendGoal"),
        Endpoint("world", "srv", f"{grip}/cancel_goal", "action_msgs/srv/CancelGoal"),
        Endpoint("world", "srv", f"{grip}/get_result", "control_msgs/action/GripperCommand_GetResult"),
        Endpoint("world", "pub", f"{grip}/feedback", "control_msgs/action/GripperCommand_FeedbackMessage"),
        Endpoint("world", "srv", "run/_secret", "std_srvs/srv/Empty"),
        Endpoint("ctl", "srv", "run/r1/ping", None),
    }
    shown = g.visible()
    assert [(o.key, o.type, o.kind, o.servers) for o in shown.offered()] == [
        ("run/r1/flip", "std_srvs/srv/SetBool", "service", ["world"]),
        ("run/r1/grip", "control_msgs/action/GripperCommand", "action", ["world"]),
        ("run/r1/ping", None, "service", ["ctl"]),
    ]
    assert "run/r1/grip/_action/feedback" not in shown.topics()  # (hidden, as rqt_graph hides it)
    every = {(o.key, o.kind) for o in g.offered(every=True)}
    assert {
        ("run/_secret", "service"),
        (f"{grip}/cancel_goal", "service"),
        ("run/r1/grip", "action"),
    } <= every
    assert summary_lines(shown) == [
        "clock    rosgraph_msgs/msg/Clock             pubs: world  subs: ctl",
        "r1/flip  std_srvs/srv/SetBool                service: world",
        "r1/grip  control_msgs/action/GripperCommand  action: world",
        "r1/ping  -                                   service: ctl",
    ]
    dot = to_dot(shown)
    assert 'label="r1/grip\\ncontrol_msgs/action/GripperCommand\\n(action)", shape=octagon' in dot
    assert '"service:run/r1/ping" -> "process:ctl" [style=dotted];' in dot
    assert "2 processes, 1 topics, 3 services and actions" in dot
    render_png(shown, tmp_path / "g.png")
    assert Image.open(tmp_path / "g.png").size[0] > 100
    assert "serves 2: r1/flip, r1/grip (action)" in drawn and "serves 1: r1/ping" in drawn, drawn
    assert any("3 services and actions" in t for t in drawn), drawn
