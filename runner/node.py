"""Write a node of a run in a dozen lines: connect, publish and subscribe ROS 2 messages, sleep in sim time.

    from runner.node import Node

    with Node() as node:                          # endpoint, run and namespace from the environment
        cmd = node.publisher("cmd_vel", "geometry_msgs/msg/Twist")
        node.subscribe("scan", "sensor_msgs/msg/LaserScan", lambda scan: ...)
        while node.ok():
            cmd.publish({"linear": {"x": 0.2}})   # a dict or a message object
            node.sleep(0.1)                       # 0.1 s of sim time; callbacks run meanwhile

Services and actions (runner.wire.client: our native service wire, the one `scenario call` uses):

    ok = node.call("flip", "std_srvs/srv/SetBool", {"data": True})           # the response message
    grip = node.action_client("gripper_cmd", "control_msgs/action/GripperCommand")
    goal = grip.send_goal({"command": {"position": 0.02}}, feedback=lambda fb: print(fb.position))
    if goal.accepted:
        end = goal.result()                         # end.status_name == "SUCCEEDED", end.result
    node.service("ping", "std_srvs/srv/Trigger", lambda req: {"success": True})  # offer one

A node started by `scenario run` (a `nodes:` entry) finds the run in its environment: `SCENARIO_ENDPOINT`,
`SCENARIO_RUN`, `SCENARIO_NAMESPACE`, `SCENARIO_NODE`, `SCENARIO_CLOCK`. Started by hand, pass them.

Callbacks run on the node's own thread, inside `sleep()`/`spin_once()` (and while `call()` or a goal's
`result()` waits), in the order messages arrived (the clock included), never concurrently. `sleep()`
returns once the sim clock reached its target: with `lockstep:` naming this node, the world waits for it
at each step, so even a `rate: max` run is repeatable. A lockstep node's `call()` is answered while the
world waits for the node (within the step after the clock the node saw), however long the answer takes;
while it waits for a goal's `result()`, the world goes on one step at a time, as in `sleep()`.
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
from dataclasses import dataclass
from typing import Any

import zenoh

from runner.wire import interfaces, msgs
from runner.wire.client import (
    ActionClient,
    ServiceCallError,
    ServiceClient,
    new_goal_id,
    status_name,
)
from runner.wire.graph import GraphTokens
from runner.wire.transport import (
    ATTACHMENT,
    encoding_for,
    make_config,
    meta_key,
    service_encoding,
    topic_key,
    unpack_attachment,
)

TERMINAL = (4, 5, 6)  # action_msgs/msg/GoalStatus: SUCCEEDED, CANCELED, ABORTED

__all__ = ["GoalResult", "Node", "NodeActionClient", "NodeGoal", "NodePublisher", "ServiceCallError"]

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
        self._client = ServiceClient(self.session, self.graph.base)
        self._answers: dict[int, tuple[Any, str | None]] = {}  # request number -> (response, error)
        self._asked = 0
        self._feedback: dict[bytes, Callable[[Any], None]] = {}  # goal id -> its feedback callback
        self._servers: dict[str, tuple[interfaces.ServiceType, Callable[[Any], Any]]] = {}
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
        self._subscribe_key(self.key(topic), type_name, callback)

    def _subscribe_key(self, key: str, type_name: str, callback: Callable[[Any], None]) -> None:
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
        elif key == "@answer":
            number, response, error = payload
            self._answers[number] = (response, error)
        elif key == "@request":
            self._serve(*payload)
        else:
            for type_name, cb in self._callbacks.get(key, ()):
                cb(msgs.decode(payload, type_name))

    # ------------------------------------------------------------------------------- services, actions
    def ask(self, key: str, type_name: str, request: Any, timeout: float) -> int:
        """Send a request to the service on `key` (a full key); its number, for `answer`."""
        self._asked += 1
        number = self._asked
        self._client.request(
            key,
            type_name,
            request,
            lambda r, e: self._inbox.put(("@answer", (number, r, e))),
            timeout,
        )
        return number

    def answer(self, number: int, what: str, ended: Callable[[], bool] | None = None) -> Any:
        """Wait for request `number`'s response, running callbacks meanwhile; ServiceCallError when there
        is none. A lockstep world answers while it waits for this node (it does not step meanwhile).
        `ended`: the answer needs sim time to pass (a goal's result): the world is let on clock by clock,
        as in `sleep()`, until `ended()` (the goal's end seen on its status topic, in order with the clock
        in lockstep), and then to the clock it was let on to, where it waits again: the instant this node
        goes on at does not depend on when the answer's bytes arrive."""
        target = self.now_ns
        answered_at: float | None = None
        while True:
            done = number in self._answers
            if ended is None:
                if done:
                    break
            elif not ended():
                target = max(target, self.now_ns + 1)  # one more clock
                if done:  # (the end was not seen on the status topic: do not wait for it for ever)
                    answered_at = answered_at or time.monotonic()
                    if time.monotonic() - answered_at > 2.0:
                        break
            elif done and self.now_ns >= target:
                break
            if not self.ok():
                raise ServiceCallError(f"{what}: the run ended (or the node was stopped) before an answer")
            # `target` (the current instant, or the clock after it) is where a lockstep world waits next; an
            # announcement of the current instant also lets it past its first wait, before any clock
            self._wait_pub.put(self._waiting_message(target))
            self.spin_once(timeout=0.1)
        response, error = self._answers.pop(number)
        if error is not None:
            raise ServiceCallError(f"{what}: {error}")
        return response

    def call(self, service: str, type_name: str, request: Any = None, timeout: float = 10.0) -> Any:
        """Call the service `service` (relative to the node's namespace unless it starts with '/') of
        type `type_name` (pkg/srv/Name) with `request` (a message, a dict of its fields, or None for all
        defaults) and return the response message. Callbacks run while it waits. Raises ServiceCallError
        when the server answers with an error, nothing answers on that name, or `timeout` (wall s)
        passes; KeyError for an unknown service type."""
        key = self.key(service)
        return self.answer(self.ask(key, type_name, request, timeout), key)

    def action_client(self, name: str, type_name: str) -> NodeActionClient:
        """A client of the action `name` (relative to the node's namespace unless it starts with '/') of
        type `type_name` (pkg/action/Name), as rclpy's ActionClient."""
        return NodeActionClient(self, self.key(name), type_name)

    def service(self, name: str, type_name: str, handler: Callable[[Any], Any]) -> None:
        """Offer the service `name` of type `type_name`: `handler(request)` returns the response (a
        message or a dict of its fields); it runs on the node's thread, inside `sleep()`/`spin()` as the
        other callbacks. A request that does not decode gets an error reply; so does a handler that
        raises (and the exception goes on, out of `sleep()`/`spin()`: a bug in the node)."""
        key = self.key(name)
        st = interfaces.service_type(type_name)
        if key in self._servers:
            raise ValueError(f"two services on {key}")
        self._servers[key] = (st, handler)
        self.graph.service(key, st.name)

        def on_query(query: zenoh.Query) -> None:
            payload = query.payload.to_bytes() if query.payload is not None else b""
            self._inbox.put(("@request", (key, query, payload)))

        self._keep.append(self.session.declare_queryable(key, on_query, complete=True))

    def _serve(self, key: str, query: zenoh.Query, payload: bytes) -> None:
        st, handler = self._servers[key]
        try:
            try:
                request = msgs.decode(payload, st.request)
            except Exception as e:
                query.reply_err(f"the request does not decode as {st.request}: {e}")
                return
            try:
                response = handler(request)
                if response is None or isinstance(response, dict):
                    response = msgs.from_data(st.response, response or {})
                data = msgs.encode(response, st.response)
            except Exception as e:
                query.reply_err(f"the service failed: {type(e).__name__}: {e}")
                raise
            att = query.attachment
            query.reply(
                key,
                data,
                encoding=service_encoding(st.response),
                attachment=att.to_bytes() if att is not None else None,
            )
        finally:
            query.drop()

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


@dataclass
class GoalResult:
    """How a goal ended: its status (action_msgs/msg/GoalStatus: 4 SUCCEEDED, 5 CANCELED, 6 ABORTED) and
    its result message."""

    status: int
    result: Any

    @property
    def status_name(self) -> str:
        return status_name(self.status)

    @property
    def succeeded(self) -> bool:
        return self.status_name == "SUCCEEDED"


class NodeGoal:
    """A goal sent by a node: `accepted`, its `goal_id` (16 bytes), the server's acceptance `stamp`;
    `result()` waits for its end, `cancel()` asks the server to cancel it."""

    def __init__(self, client: NodeActionClient, goal_id: bytes, accepted: bool, stamp_ns: int):
        self.client = client
        self.goal_id = goal_id
        self.accepted = accepted
        self.stamp_ns = stamp_ns
        self._result: GoalResult | None = None
        self._asked: int | None = None

    def result(self, timeout: float = 3600.0) -> GoalResult:
        """Wait (callbacks running, feedback included) until the goal ends; ServiceCallError when the server
        does not say within `timeout` (wall s)."""
        if self._result is None:
            node, parts = self.client.node, self.client.client.parts
            if self._asked is None:
                self._asked = self.client._ask(self.client.client.get_result, self.goal_id, timeout)
            response = node.answer(
                self._asked, parts.get_result[0], ended=lambda: self.goal_id in self.client.ended
            )
            self._result = GoalResult(int(response.status), response.result)
            self.client.node._feedback.pop(self.goal_id, None)
        return self._result

    def cancel(self, timeout: float = 10.0) -> bool:
        """Ask the server to cancel the goal; whether it agreed (the goal then ends as CANCELED)."""
        node, parts = self.client.node, self.client.client.parts
        number = self.client._ask(self.client.client.cancel, self.goal_id, timeout)
        response = node.answer(number, parts.cancel_goal[0])
        return int(response.return_code) == 0 and len(response.goals_canceling) > 0


class NodeActionClient:
    """A node's client of one action server (`Node.action_client`)."""

    def __init__(self, node: Node, key: str, type_name: str):
        self.node = node
        self.client = ActionClient(node._client, key, type_name)
        self.ended: set[bytes] = set()  # goals whose end the status topic told
        # through the node's own subscriptions: in lockstep, in order with the clock
        node._subscribe_key(*self.client.parts.feedback, self._on_feedback)
        node._subscribe_key(*self.client.parts.status, self._on_status)

    def _on_feedback(self, msg: Any) -> None:
        callback = self.node._feedback.get(bytes(msg.goal_id.uuid))
        if callback is not None:
            callback(msg.feedback)

    def _on_status(self, msg: Any) -> None:
        for s in msg.status_list:
            if int(s.status) in TERMINAL:
                self.ended.add(bytes(s.goal_info.goal_id.uuid))

    @property
    def action(self) -> str:
        return self.client.action

    def _ask(self, send: Callable[..., None], goal_id: bytes, timeout: float) -> int:
        node = self.node
        node._asked += 1
        number = node._asked
        send(goal_id, lambda r, e: node._inbox.put(("@answer", (number, r, e))), timeout)
        return number

    def send_goal(
        self, goal: Any = None, feedback: Callable[[Any], None] | None = None, timeout: float = 10.0
    ) -> NodeGoal:
        """Send a goal (a `<Action>_Goal` message, a dict of its fields, or None for all defaults) and wait
        for the server's answer; `feedback(msg)` gets the goal's feedback (`<Action>_Feedback`), on the
        node's thread. Look at the returned goal's `accepted`."""
        node = self.node
        goal_id = new_goal_id()
        goal_msg = self.client.goal_of(goal)
        if feedback is not None:
            node._feedback[goal_id] = feedback
        node._asked += 1
        number = node._asked
        self.client.send_goal(
            goal_id, goal_msg, lambda r, e: node._inbox.put(("@answer", (number, r, e))), timeout
        )
        try:
            response = node.answer(number, self.client.parts.send_goal[0])
        except ServiceCallError:
            node._feedback.pop(goal_id, None)
            raise
        if not response.accepted:
            node._feedback.pop(goal_id, None)
        stamp = int(response.stamp.sec) * 1_000_000_000 + int(response.stamp.nanosec)
        return NodeGoal(self, goal_id, bool(response.accepted), stamp)
