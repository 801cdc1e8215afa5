"""`scenario run --foxglove PORT`: a WebSocket client speaking Foxglove's protocol sees the run's channels
advertised and receives its messages, live."""

from __future__ import annotations

import json
import signal
import socket
import struct
import subprocess
import time
from typing import Any

import pytest

from runner import msgs
from runner.transport import free_port
from tests.conftest import SCENARIOS, scenario_cmd


@pytest.mark.timeout(90)
def test_a_foxglove_client_sees_the_channels_and_receives_scans() -> None:
    from websockets.sync.client import connect

    port = free_port()
    run = subprocess.Popen(
        scenario_cmd(
            "run",
            str(SCENARIOS / "two_robots.yaml"),
            "--rate",
            "realtime",
            "--no-record",
            "--no-judge",
            "-q",
            "--foxglove",
            str(port),
        ),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 30
        while True:  # the server is up once its port takes connections
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                if time.monotonic() > deadline or run.poll() is not None:
                    raise
                time.sleep(0.2)
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
