"""Write a node of a run in a dozen lines: connect, publish and subscribe ROS 2 messages, sleep in sim time.

    from runner.node import Node

    with Node() as node:                          # endpoint, run and namespace from the environment
        cmd = node.publisher("cmd_vel", "geometry_msgs/msg/Twist")
        node.subscribe("scan", "sensor_msgs/msg/LaserScan", lambda scan: ...)
        while node.ok():
            cmd.publish({"linear": {"x": 0.2}})   # a dict or a message object
            node.sleep(0.1)                       # 0.1 s of sim time; callbacks run meanwhile

A node started by `scenario run` (a `nodes:` entry) finds the run in its environment: `SCENARIO_ENDPOINT`,
`SCENARIO_RUN`, `SCENARIO_NAMESPACE`, `SCENARIO_NODE`, `SCENARIO_CLOCK`. Started by hand, pass them.

Callbacks run on the node's own thread, inside `sleep()`/`spin_once()`, in the order messages arrived
(the clock included), never concurrently. `sleep()` returns once the sim clock reached its target: with
`lockstep:` naming this node, the world waits for it at each step, so even a `rate: max` run is repeatable.
"""

from __future__ import annotations

import json
import os
import queue
import signal
import struct
import threading
import time
from collections.abc import Callable
from typing import Any

import zenoh

from runner.wire import msgs
from runner.wire.graph import GraphTokens
from runner.wire.transport import (
    ATTACHMENT,
    encoding_for,
    make_config,
    meta_key,
    topic_key,
    unpack_attachment,
)

_WAIT = struct.Struct("<q")  # lockstep: the sim time (ns) this node sleeps until
NEVER = 2**63 - 1


class NodePublisher:
    def __init__(self, node: Node, key: str, type_name: str):
        self.node = node
        self.key = key
        self.type = type_name
        self.seq = 0
        self._pub = node.session.declare_publisher(
            key,
            encoding=encoding_for(type_name),
            congestion_control=zenoh.CongestionControl.BLOCK,
            reliability=zenoh.Reliability.RELIABLE,
        )

    def publish(self, msg: Any) -> None:
        """Publish a message object, or a dict of its fields (`{"linear": {"x": 0.2}}`), stamped with the
        current sim time."""
        if isinstance(msg, dict):
            msg = msgs.from_data(self.type, msg)
        self._pub.put(msgs.encode(msg, self.type), attachment=ATTACHMENT.pack(self.seq, self.node.now_ns))
        self.seq += 1


class Node:
    def __init__(
        self,
        name: str | None = None,
        *,
        endpoint: str | None = None,
        run: str | None = None,
        namespace: str | None = None,
        handle_signals: bool = True,
        wait_for_world: float = 30.0,
        ordered: bool | None = None,
    ):
        env = os.environ
        self.name = name or env.get("SCENARIO_NODE") or "node"
        self.run = run or env.get("SCENARIO_RUN") or ""
        endpoint = endpoint or env.get("SCENARIO_ENDPOINT")
        if not self.run or not endpoint:
            raise RuntimeError(
                "runner.node: no run to join; start it from a scenario's `nodes:` or pass run= and endpoint= "
                "(or set SCENARIO_RUN and SCENARIO_ENDPOINT)"
            )
        ns = namespace if namespace is not None else env.get("SCENARIO_NAMESPACE", "")
        self.namespace = ns.strip("/")
        self.clock_key = env.get("SCENARIO_CLOCK") or f"{self.run}/clock"
        self.now_ns = 0
        self._clock_seen = False
        self._stopped = threading.Event()
        self._ended = False
        self._inbox: queue.SimpleQueue[tuple[str, Any]] = queue.SimpleQueue()
        self._callbacks: dict[str, list[tuple[str, Callable[[Any], None]]]] = {}
        self._keep: list[Any] = []
        self._publishers: list[NodePublisher] = []
        if handle_signals and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, lambda *_: self._stopped.set())
            signal.signal(signal.SIGTERM, lambda *_: self._stopped.set())
        self.session = zenoh.open(make_config("client", connect=[endpoint]))
        # Zenoh calls each subscriber's callback on a thread of its own, so the order between topics is
        # lost. In lockstep (the launcher says so), one subscription to the whole run keeps the world's
        # order: every message of sim time t comes before the clock of t, so a node woken by the clock has
        # seen all of it, and the run is repeatable.
        self.graph = GraphTokens(self.session, self.run, self.name, "node")
        self.graph.subscriber(self.clock_key, "rosgraph_msgs/msg/Clock")
        self.ordered = ordered if ordered is not None else env.get("SCENARIO_LOCKSTEP") == "1"
        if self.ordered:
            self._keep.append(self.session.declare_subscriber(f"{self.run}/**", self._on_any))
        else:
            self._keep.append(self.session.declare_subscriber(self.clock_key, self._on_clock))
        self._keep.append(
            self.session.declare_subscriber(
                meta_key(self.run, "world", "end"), lambda _s: self._inbox.put(("@end", None))
            )
        )
        self._wait_pub = self.session.declare_publisher(
            meta_key(self.run, "lockstep", self.name), congestion_control=zenoh.CongestionControl.BLOCK
        )
        self._token = self.session.liveliness().declare_token(meta_key(self.run, "node", self.name))
        if wait_for_world:
            self._wait_for_world(wait_for_world)

    def _wait_for_world(self, timeout_s: float) -> None:
        """Until the world process is up and subscribed (its liveliness token), so that nothing this node
        publishes first is lost; then a lockstep world waits for this node before its first step."""
        deadline = time.monotonic() + timeout_s
        key = meta_key(self.run, "world", "alive")
        while not self._stopped.is_set():
            if any(r.ok is not None for r in self.session.liveliness().get(key, timeout=1.0)):
                return
            if time.monotonic() > deadline:
                self.close()
                raise RuntimeError(
                    f"runner.node: the world of run {self.run!r} did not come up in {timeout_s:g} s"
                )
            time.sleep(0.02)

    # ----------------------------------------------------------------------------------------- topics
    def key(self, topic: str) -> str:
        """`scan` -> `<run>/<ns>/scan`; `/clock` -> `<run>/clock`."""
        return topic_key(self.run, self.namespace, topic)

    def publisher(self, topic: str, type_name: str) -> NodePublisher:
        pub = NodePublisher(self, self.key(topic), msgs.normalize_type(type_name))
        self._publishers.append(pub)
        self.graph.publisher(pub.key, pub.type)
        return pub

    def _waiting_message(self, until_ns: int) -> bytes:
        """Lockstep: the sim time this node sleeps until, and how many messages it published on each key
        so far (the world takes them all in before it goes on: Zenoh does not keep the order between keys)."""
        counts: dict[str, int] = {}
        for pub in self._publishers:
            counts[pub.key] = counts.get(pub.key, 0) + pub.seq
        return _WAIT.pack(until_ns) + json.dumps(counts).encode()

    def subscribe(self, topic: str, type_name: str, callback: Callable[[Any], None]) -> None:
        """`callback(msg)` runs inside `sleep()`/`spin_once()`, on this node's thread."""
        key = self.key(topic)
        type_name = msgs.normalize_type(type_name)
        first = key not in self._callbacks
        self._callbacks.setdefault(key, []).append((type_name, callback))
        self.graph.subscriber(key, type_name)
        if first and not self.ordered:

            def on_sample(sample: zenoh.Sample, key: str = key) -> None:
                self._inbox.put((key, sample.payload.to_bytes()))

            self._keep.append(self.session.declare_subscriber(key, on_sample))

    # ------------------------------------------------------------------------------------------- time
    @property
    def now(self) -> float:
        """Sim time, seconds (0 until the first clock message)."""
        return self.now_ns / 1e9

    def _on_any(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if key == self.clock_key:
            self._on_clock(sample)
        elif key in self._callbacks:
            self._inbox.put((key, sample.payload.to_bytes()))

    def _on_clock(self, sample: zenoh.Sample) -> None:
        att = sample.attachment
        parsed = unpack_attachment(att.to_bytes()) if att is not None else None
        if parsed is not None:
            ns = parsed[1]
        else:
            clock = msgs.decode(sample.payload.to_bytes(), "rosgraph_msgs/msg/Clock").clock
            ns = clock.sec * 1_000_000_000 + clock.nanosec
        self._inbox.put(("@clock", ns))

    def ok(self) -> bool:
        """False once the run has ended or the node was asked to stop."""
        return not self._ended and not self._stopped.is_set()

    def sleep(self, seconds: float) -> bool:
        """Run callbacks until the sim clock has advanced by `seconds`; False if the run ended meanwhile."""
        target = self.now_ns + round(seconds * 1e9)
        announce = self._waiting_message(target)
        self._wait_pub.put(announce)  # lockstep: the world may step on until `target`
        while self.ok():
            if self._clock_seen and self.now_ns >= target:
                return True
            if not self.spin_once(timeout=0.1):
                self._wait_pub.put(announce)  # nothing for 0.1 s: say it again (cheap, idempotent)
        return False

    def spin_once(self, timeout: float | None = 0.1) -> bool:
        """Handle what arrived (waiting up to `timeout` s for the first message); False if nothing did."""
        try:
            item = self._inbox.get(timeout=timeout) if timeout else self._inbox.get_nowait()
        except queue.Empty:
            return False
        while True:
            self._handle(*item)
            if item[0] == "@clock":
                return True  # one sim instant at a time: sleep() checks its target after each clock
            try:
                item = self._inbox.get_nowait()
            except queue.Empty:
                return True

    def spin(self) -> None:
        """Run callbacks until the run ends (a node that only reacts to messages)."""
        self._wait_pub.put(self._waiting_message(NEVER))
        while self.ok():
            self.spin_once(timeout=0.1)

    def _handle(self, key: str, payload: Any) -> None:
        if key == "@clock":
            self.now_ns = max(self.now_ns, int(payload))
            self._clock_seen = True
        elif key == "@end":
            self._ended = True
        else:
            for type_name, cb in self._callbacks.get(key, ()):
                cb(msgs.decode(payload, type_name))

    # -------------------------------------------------------------------------------------- lifetime
    def close(self) -> None:
        self.graph.close()
        for ent in (self._token, self._wait_pub, *self._keep):
            try:
                ent.undeclare()
            except Exception:
                continue
        self._keep.clear()
        self.session.close()

    def __enter__(self) -> Node:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()
