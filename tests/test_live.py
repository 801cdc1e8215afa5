"""`scenario run --foxglove PORT`: a WebSocket client speaking Foxglove's protocol sees the run's channels
advertised and receives its messages, live."""

from __future__ import annotations

import json
import signal
import socket
import struct
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest

from runner.wire import msgs
from runner.wire.transport import free_port
from tests.conftest import SCENARIOS, scenario_cmd


@pytest.mark.timeout(90)
def test_a_foxglove_client_sees_the_channels_and_receives_scans() -> None:
    from websockets.sync.client import connect

    port = free_port()
    run = _serving(port, within=30)
    try:
        with connect(
            f"ws://127.0.0.1:{port}", subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"]
        ) as ws:
            got = _scans(ws)
    finally:
        run.send_signal(signal.SIGINT)
        run.communicate(timeout=30)
    assert len(got) >= 3
    assert all(len(s.ranges) == 360 for _t, s in got)
    stamps = [t for t, _s in got]
    assert stamps == sorted(stamps) and stamps[-1] - stamps[0] >= 0.1e9  # sim time, 10 Hz


def _scans(ws: Any) -> list[tuple[int, Any]]:
    """What a Foxglove client does: read the server's info and advertisements, subscribe to r1's scans."""
    channels: dict[str, dict] = {}
    info = None
    deadline = time.monotonic() + 20
    wanted = {"two_robots/r1/scan", "two_robots/scene"}
    while not wanted <= set(channels) and time.monotonic() < deadline:
        frame = ws.recv(timeout=10)
        if isinstance(frame, str):
            op = json.loads(frame)
            if op["op"] == "serverInfo":
                info = op
            elif op["op"] == "advertise":
                channels.update({c["topic"]: c for c in op["channels"]})
    assert info is not None and "two_robots" in info["name"]
    scan = channels["two_robots/r1/scan"]
    assert scan["encoding"] == "cdr" and scan["schemaName"] == "sensor_msgs/msg/LaserScan"
    assert channels["two_robots/scene"]["encoding"] == "protobuf"
    ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": scan["id"]}]}))
    got = []
    deadline = time.monotonic() + 20
    while len(got) < 3 and time.monotonic() < deadline:
        frame = ws.recv(timeout=10)
        if isinstance(frame, bytes) and frame[0] == 0x01:  # message data
            sub_id, stamp = struct.unpack_from("<IQ", frame, 1)
            assert sub_id == 7
            got.append((stamp, msgs.decode(frame[13:], "sensor_msgs/msg/LaserScan")))
    return got


CLIENTS = Path(__file__).parent / "clients"


def _serving(port: int, within: float = 60, extra: tuple[str, ...] = ()) -> subprocess.Popen[str]:
    """two_robots at real time, served live on `port` (`extra`: more options); returns once the port takes
    connections (within `within` s, or it fails)."""
    run = subprocess.Popen(
        scenario_cmd(
            "run", str(SCENARIOS / "two_robots.yaml"), "--rate", "realtime", "--no-record", "--no-judge", "-q",
            "--foxglove", str(port), *extra,
        ),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    deadline = time.monotonic() + within
    while True:  # the server is up once its port takes connections
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return run
        except OSError:
            if time.monotonic() > deadline or run.poll() is not None:
                run.kill()
                raise
            time.sleep(0.2)


@pytest.mark.timeout(120)
def test_every_name_of_the_protocol_is_taken() -> None:
    """foxglove-sdk's server takes `foxglove.sdk.v1` only; Lichtblick and `@foxglove/ws-protocol` offer
    `foxglove.websocket.v1` (the same protocol) and got HTTP 400. Each name alone now connects and is
    answered in its own name; a name of another protocol is still refused."""
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    port = free_port()
    run = _serving(port)
    try:
        for name in ("foxglove.websocket.v1", "foxglove.sdk.v1"):
            with connect(f"ws://127.0.0.1:{port}", subprotocols=[name], open_timeout=20) as ws:  # type: ignore[list-item]
                assert ws.subprotocol == name
                info = json.loads(ws.recv(timeout=20))
                assert info["op"] == "serverInfo" and "time" in info["capabilities"], info
        with pytest.raises(InvalidStatus):
            connect(f"ws://127.0.0.1:{port}", subprotocols=["mqtt"], open_timeout=20)  # type: ignore[list-item]
    finally:
        run.send_signal(signal.SIGINT)
        run.communicate(timeout=30)


@pytest.mark.timeout(180)
def test_foxgloves_own_client_library_decodes_scans_and_follows_sim_time() -> None:
    """The npm `@foxglove/ws-protocol` client (as Lichtblick uses it) with Foxglove's CDR reader: it
    connects, subscribes, decodes r1's scans with the advertised schema, and receives the sim time (the
    `time` capability), which advances with the scans' log times."""
    import shutil

    node = shutil.which("node")
    modules = CLIENTS / "node_modules" / "@foxglove" / "ws-protocol"
    assert node is not None and modules.is_dir(), (
        "Node and the test clients are needed: run `.ci/setup --test` (installs nodejs and "
        "`npm install` in tests/clients)"
    )
    port = free_port()
    run = _serving(port)
    try:
        proc = subprocess.run(
            [
                node,
                str(CLIENTS / "foxglove_ws_client.mjs"),
                f"ws://127.0.0.1:{port}",
                "two_robots/r1/scan",
                "5",
            ],
            capture_output=True,
            text=True,
            timeout=90,
        )
    finally:
        run.send_signal(signal.SIGINT)
        _, run_err = run.communicate(timeout=30)
    # (the run's own words too: a server that closed the connection early says why there)
    assert proc.returncode == 0, proc.stdout + proc.stderr + "\nthe run said:\n" + run_err[-3000:]
    got = json.loads(proc.stdout.strip().splitlines()[-1])
    assert got["protocol"] == "foxglove.websocket.v1" and "time" in got["capabilities"], got
    assert got["channel"] == {
        "encoding": "cdr",
        "schemaName": "sensor_msgs/msg/LaserScan",
        "schemaEncoding": "ros2msg",
    }
    scans = got["messages"]
    assert len(scans) >= 5 and all(s["ranges"] == 360 and s["frame_id"] for s in scans), scans
    times = [int(t) for t in got["times"]]
    assert times == sorted(times) and times[-1] > times[0], times[:5]
    logs = [int(s["log_time"]) for s in scans]
    assert logs == sorted(logs) and logs[-1] - logs[0] >= 0.3e9  # sim time at 10 Hz, not wall clock
    assert abs(times[-1] - logs[-1]) < 5e9  # the viewer's clock is the scans' clock
