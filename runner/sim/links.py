"""The world's links to the processes it keeps in step with: a renderer process that renders a plugin's
frames from the state the world sends it (`RemoteRender`), and the nodes of `lockstep:` that the world
waits for at each boundary (`Lockstep`).
"""

from __future__ import annotations

import contextlib
import json
import struct
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

# the state a renderer gets: sim time ns, frame number, the sim time run before the last reset_simulation
# (the renderer's epoch: runner.sim.pubsub.Outgoing.epoch), the world's model generation (a robot spawned or
# deleted: runner.sim.grow), then the state
STATE_HEAD = struct.Struct("<qQqq")
_WAIT = struct.Struct("<q")


class RemoteRender:
    """The world's end of one rendering plugin that runs in a renderer process.

    At the plugin's times the world sends the state (`<run>/@meta/render/<i>`: sim time + positions);
    the renderer renders, publishes the frame under the plugin's own topics, and acknowledges
    (`.../<i>/done`, with its message counts). At most `DEPTH` frames are in flight: the world simulates on
    while a frame renders, and waits only when the renderer falls behind (lockstep, nothing dropped)."""

    DEPTH = 1
    TIMEOUT_S = 60.0

    def __init__(self, session: Any, run: str, index: int):
        import zenoh

        from runner.wire.transport import meta_key

        self.session = session
        self.alive_key = meta_key(run, "render", "alive")
        self.index = index
        self.sent = 0
        self.acked = 0
        self.published: dict[str, int] = {}
        self._cond = threading.Condition()
        self._pub = session.declare_publisher(
            meta_key(run, "render", str(index)),
            congestion_control=zenoh.CongestionControl.BLOCK,
            reliability=zenoh.Reliability.RELIABLE,
        )
        self._stop = session.declare_publisher(meta_key(run, "render", "stop"))
        self._sub = session.declare_subscriber(meta_key(run, "render", str(index), "done"), self._on_done)

    def listening(self) -> bool:
        """The renderer process holds its liveliness token once it is subscribed and ready."""
        replies = self.session.liveliness().get(self.alive_key, timeout=1.0)
        return any(r.ok is not None for r in replies)

    def _on_done(self, sample: Any) -> None:
        info = json.loads(sample.payload.to_bytes())
        with self._cond:
            self.acked = max(self.acked, int(info["n"]))
            self.published.update(info.get("published", {}))
            self._cond.notify_all()

    def _wait(self, acked: int, should_stop: Callable[[], bool]) -> None:
        deadline = time.monotonic() + self.TIMEOUT_S
        with self._cond:
            while self.acked < acked:
                if should_stop():
                    return
                if time.monotonic() > deadline:
                    raise RuntimeError(f"the renderer process did not answer for {self.TIMEOUT_S:.0f} s")
                self._cond.wait(0.05)

    def send(
        self,
        now_ns: int,
        state: bytes,
        should_stop: Callable[[], bool],
        epoch_ns: int = 0,
        generation: int = 0,
    ) -> None:
        self._wait(self.sent - self.DEPTH + 1, should_stop)
        self._pub.put(STATE_HEAD.pack(now_ns, self.sent, epoch_ns, generation) + state)
        self.sent += 1

    def finish(self, should_stop: Callable[[], bool]) -> None:
        """Wait for the frames in flight, so they are published before the world says it has ended."""
        self._wait(self.sent, should_stop)

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self._stop.put(b"")
        for ent in (self._sub, self._pub, self._stop):
            with contextlib.suppress(Exception):
                ent.undeclare()


class Lockstep:
    """The world's side of `lockstep:`. Each node named there says, whenever it goes to sleep, the sim
    time it sleeps until (`<run>/@meta/lockstep/<node>`, int64 ns; runner.node does it in `sleep()`).
    Before the world takes in commands at a boundary, it waits until every such node sleeps past the last
    clock it published: the node has seen that instant and answered it. A node whose liveliness token goes
    away (it died) is no longer waited for; one that never answers stops the run after `TIMEOUT_S`."""

    TIMEOUT_S = 30.0

    def __init__(self, session: Any, run: str, names: list[str], received: dict[str, int], keys: set[str]):
        from runner.wire.transport import meta_key

        self.waiting: dict[str, int] = {}  # node -> sim time it sleeps until
        self.sent: dict[str, dict[str, int]] = {}  # node -> messages it had published per key by then
        self.received = received  # the world's count of messages received per key
        self.keys = keys  # the keys the world subscribes to
        self.names = set(names)
        self._cond = threading.Condition()
        self._prefix = meta_key(run, "lockstep", "")
        self._node_prefix = meta_key(run, "node", "")
        self._seen: set[str] = set()
        self._subs = [
            session.declare_subscriber(meta_key(run, "lockstep", "*"), self._on_wait),
            session.liveliness().declare_subscriber(meta_key(run, "node", "*"), self._on_alive, history=True),
        ]

    def _on_wait(self, sample: Any) -> None:
        name = str(sample.key_expr)[len(self._prefix) :]
        data = sample.payload.to_bytes()
        (until,) = _WAIT.unpack_from(data)
        sent = json.loads(data[_WAIT.size :] or b"{}")
        with self._cond:
            if until >= self.waiting.get(name, until):
                self.waiting[name] = until
                self.sent[name] = sent
            self._cond.notify_all()

    def poke(self) -> None:
        with self._cond:
            self._cond.notify_all()

    def _answered(self, name: str, clock_sent: int) -> bool:
        """The node sleeps past the last clock and everything it published by then has arrived."""
        if self.waiting.get(name, -1) <= clock_sent:
            return False
        received = self.received
        return all(received.get(k, 0) >= n for k, n in self.sent.get(name, {}).items() if k in self.keys)

    def _on_alive(self, sample: Any) -> None:
        import zenoh

        name = str(sample.key_expr)[len(self._node_prefix) :]
        with self._cond:
            if sample.kind == zenoh.SampleKind.PUT:
                self._seen.add(name)
            elif name in self.names:
                self.names.discard(name)  # gone: not waited for any more
                print(
                    f"world: lockstep node {name!r} is gone; not waiting for it", file=sys.stderr, flush=True
                )
            self._cond.notify_all()

    def wait(
        self, clock_sent: int, should_stop: Callable[[], bool], serve: Callable[[], None] | None = None
    ) -> None:
        """Until every node answered the clock; `serve()` answers the requests that arrive meanwhile (a
        lockstep node that asks the world something in its turn waits for the answer before it answers)."""
        deadline = time.monotonic() + self.TIMEOUT_S
        while True:
            if serve is not None:
                serve()
            with self._cond:
                late = [n for n in self.names if not self._answered(n, clock_sent)]
                if not late or should_stop():
                    return
                if time.monotonic() > deadline:
                    who = ", ".join(sorted(late))
                    raise RuntimeError(f"lockstep node(s) {who} did not answer for {self.TIMEOUT_S:.0f} s")
                self._cond.wait(0.05)

    def close(self) -> None:
        for sub in self._subs:
            with contextlib.suppress(Exception):
                sub.undeclare()
