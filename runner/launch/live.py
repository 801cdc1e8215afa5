"""`scenario run --foxglove PORT`: the run, live, over Foxglove's WebSocket protocol (foxglove-sdk's server).

Every key of the run becomes a channel the first time it carries a message: ROS 2 messages as `cdr` with
their `ros2msg` schema, the scene as `protobuf`; each message is logged with its sim time. Open Foxglove,
connect to `ws://127.0.0.1:PORT` and the 3D view, plots and images follow the run as it goes; the server
advertises the `time` capability and sends the sim time, so the viewer's clock is the sim clock. The port
takes both names of the protocol (`foxglove.websocket.v1`, `foxglove.sdk.v1`: runner.launch.live_gate) and
refuses web pages of other sites (their `Origin`): the Foxglove app, local pages and files, and the origins
given (`--foxglove-origin`) only. The server listens on loopback unless a host is given.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
import warnings
from collections.abc import Sequence
from typing import Any

import zenoh

from runner.errors import RunError, visible
from runner.wire import msgs
from runner.wire.transport import type_from_encoding, unpack_attachment

TIME_PERIOD_S = 0.02  # how often viewers are told the sim time, at most (wall)


def _say_refused(origin: str) -> None:
    """Said once per origin on the runner's console: a web page of another site tried to read the run."""
    origin = visible(origin[:200])  # (any bytes a client sends: escape sequences are shown, not obeyed)
    print(
        f"Foxglove: refused a WebSocket from origin {origin}: not an allowed origin; "
        f"allow it with --foxglove-origin {origin}",
        file=sys.stderr,
        flush=True,
    )


class LiveView:
    def __init__(
        self,
        session: zenoh.Session,
        run: str,
        port: int,
        host: str = "127.0.0.1",
        origins: Sequence[str] = (),
    ):
        """`origins`: web page origins allowed besides the Foxglove app's and local ones
        (runner.launch.live_gate.origin_allowed)."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            import foxglove
        from foxglove.websocket import Capability

        from runner.launch.live_gate import SubprotocolGate

        self._fox = foxglove
        self.context = foxglove.Context()
        try:
            # the SDK's server on a loopback port of its own, behind the gate on the user's port, which
            # takes every name clients give the protocol (foxglove.websocket.v1 as well as foxglove.sdk.v1)
            self.server = foxglove.start_server(
                name=f"scenario {run}",
                host="127.0.0.1",
                port=0,
                context=self.context,
                capabilities=[Capability.Time],  # the viewer's clock is the sim clock
            )
        except Exception as e:
            raise RunError(f"cannot serve Foxglove: {e}") from None
        try:
            self.gate = SubprotocolGate(
                self.server.port, host=host, port=port, origins=origins, on_refused=_say_refused
            )
        except OSError as e:  # the port is taken, say
            self.server.stop()
            raise RunError(f"cannot serve Foxglove on {host}:{port}: {e.strerror or e}") from None
        self.port = self.gate.port
        self._told = 0.0  # when sim time was last sent to viewers (wall, monotonic)
        self._channels: dict[str, Any] = {}
        self._lock = threading.Lock()
        self._latest = 0
        self._sub = session.declare_subscriber(f"{run}/**", self._on_sample)

    def _channel(self, key: str, type_name: str) -> Any:
        with self._lock:
            ch = self._channels.get(key)
            if ch is None:
                fox = self._fox
                if type_name.startswith("foxglove."):
                    from runner.record import foxglove_schema

                    s = foxglove_schema(type_name)
                    schema, encoding = fox.Schema(name=s.name, encoding="protobuf", data=s.data), "protobuf"
                else:
                    data = msgs.msgdef(type_name).encode()
                    schema, encoding = fox.Schema(name=type_name, encoding="ros2msg", data=data), "cdr"
                ch = fox.Channel(key, schema=schema, message_encoding=encoding, context=self.context)
                self._channels[key] = ch
            return ch

    def _on_sample(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        ch = self._channels.get(key)
        if ch is None:  # a key's first message: its type says whether (and how) it is shown
            type_name = type_from_encoding(sample.encoding)
            if type_name is None or not (type_name.startswith("foxglove.") or msgs.is_known(type_name)):
                return
            ch = self._channel(key, type_name)
        att = unpack_attachment(sample.attachment.to_bytes()) if sample.attachment is not None else None
        if att is not None and att[1] > self._latest:
            self._latest = att[1]
            now = time.monotonic()
            if now - self._told >= TIME_PERIOD_S:  # (at rate: max, thousands of sim steps a second)
                self._told = now
                with contextlib.suppress(Exception):
                    self.server.broadcast_time(self._latest)
        stamp = att[1] if att is not None else self._latest
        with contextlib.suppress(Exception):  # a viewer's trouble never stops the run
            ch.log(sample.payload.to_bytes(), log_time=stamp)

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self._sub.undeclare()
        self.gate.close()
        with contextlib.suppress(Exception):
            self.server.stop()
