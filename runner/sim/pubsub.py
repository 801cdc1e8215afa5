"""What the world process sends and takes in: its publishers (`Outgoing`: CDR on the bus, stamped and
numbered, and handed at once to subscribers in the same process), the plugins' subscriptions, and the
inbox of messages from other processes, delivered at the next boundary (`PubSub`, a part of `World`).
"""

from __future__ import annotations

import queue
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from runner.plan import RunPlan
from runner.plugin import MAX_INBOUND_BYTES, Publisher, too_large
from runner.wire import msgs
from runner.wire.transport import ATTACHMENT as _ATT
from runner.wire.transport import Bus, topic_key

if TYPE_CHECKING:
    from runner.sim.links import Lockstep


# Why an inbound message was dropped, as the end-of-run table and the recording's metadata count it
NONFINITE = "NaN or Inf values"


# A subscriber in this process: (type, callback, peek): `peek(payload)` gives what the callback reads of
# each message this process publishes (runner.wire.cdr.Peek), or None for the whole decoded message
Local = tuple[str, Callable[[Any, int], None], Callable[[bytes], Any] | None]

_NO_EPOCH = [0]


class Outgoing:
    """One published key: sends CDR bytes with the (sequence, stamp) attachment and hands the message to
    subscribers inside this process (decoded only when there is one). While an event's fault is on the key
    (`fault`, runner.sim.faults), every message goes through it instead: dropped, held, replaced."""

    __slots__ = ("epoch", "fault", "key", "last", "local", "send", "seq", "type")

    def __init__(self, key: str, type_name: str, send: Callable[[bytes | bytearray, bytes], None]):
        self.key = key
        self.type = type_name
        self.send = send
        self.seq = 0
        self.local: list[Local] = []
        self.fault: Any = None
        self.last: bytes | bytearray | None = None  # the last message sent (what a `freeze` fault repeats)
        # added to the attachment's stamp (not to the message): the sim time run before the last
        # `reset_simulation` (shared by a world's publishers), so that the recording's log time, the
        # attachment's stamp, keeps going forward while the messages' own times start again from 0
        self.epoch = _NO_EPOCH

    def publish(self, msg: Any, stamp_ns: int) -> None:
        self.publish_encoded(msgs.encode(msg, self.type), msg, stamp_ns)

    def publish_encoded(self, payload: bytes | bytearray, msg: Any, stamp_ns: int) -> None:
        """`msg` already encoded (`payload`): a message sent again and again, encoded once."""
        if self.fault is not None:
            self.fault.take(self, payload, msg, stamp_ns)
        else:
            self.deliver(payload, msg, stamp_ns)

    def publish_cdr(self, payload: bytes | bytearray, stamp_ns: int) -> None:
        """Send CDR bytes. A `bytearray` is borrowed (a camera's frame, encoded in place and rewritten for
        the next one): the bus copies it once as it sends it, and it is copied here only where it is kept
        (a fault holding it, a subscriber in this process)."""
        self.publish_encoded(payload if self.fault is None else bytes(payload), None, stamp_ns)

    def deliver(self, payload: bytes | bytearray, msg: Any, stamp_ns: int) -> None:
        """Send, and hand to subscribers in this process (`msg`, or `payload` decoded when there is one);
        past any fault: what `publish` sends without one, and what a fault lets through or releases late."""
        self.send(payload, _ATT.pack(self.seq, stamp_ns + self.epoch[0]))
        self.seq += 1
        # a borrowed buffer still holds this message when a fault starts (faults start between frames)
        self.last = payload
        if self.local:
            if msg is None and not isinstance(payload, bytes):
                payload = bytes(payload)  # (a borrowed buffer, written again by the next message)
            for _type, cb, peek in self.local:
                if msg is None:
                    if peek is not None:  # (it reads only the fields it needs)
                        cb(peek(payload), stamp_ns)
                        continue
                    msg = msgs.decode(payload, self.type)
                cb(msg, stamp_ns)


class PubSub:
    """The world's publishers and subscriptions, and its inbox: a part of `World` (a base class, so that
    the loop calls these methods with no layer in between). `World.__init__` sets the attributes below
    and calls `_init_pubsub` before anything publishes or subscribes."""

    plan: RunPlan
    bus: Bus
    now_ns: int
    _lockstep: Lockstep | None

    def _init_pubsub(self) -> None:
        self._out: dict[str, Outgoing] = {}
        self._epoch = [0]  # sim ns run before the last reset_simulation (Outgoing.epoch)
        self._local: dict[str, list[Local]] = {}
        self._remote_subscribed: set[str] = set()
        self._inbox: queue.SimpleQueue[tuple[str, bytes, bytes | None]] = queue.SimpleQueue()
        self._received: dict[str, int] = {}  # messages from other processes, per key
        # keys a plugin takes from other processes: a message there with a NaN or Inf anywhere is dropped
        # before any subscriber sees it (one NaN in a command would reach MuJoCo's controls, or stay in a
        # controller's state for good: a diff drive's integral never forgets it)
        self._checked: set[str] = set()
        self._nonfinite_said: set[str] = set()
        # the same keys: the most bytes a message there may have (MAX_INBOUND_BYTES, or what its plugins
        # ask for), checked on arrival: a larger one is neither decoded nor queued
        self._max_bytes: dict[str, int] = {}
        self._too_large_said: set[str] = set()

    def make_publisher(self, key: str, type_name: str) -> Outgoing:
        out = self._out.get(key)
        if out is None:
            out = Outgoing(key, type_name, self.bus.publisher(key, type_name))
            out.local = self._local.setdefault(key, [])
            out.epoch = self._epoch
            self._out[key] = out
        elif out.type != type_name:
            raise ValueError(f"{key} is published as {out.type} and as {type_name}")
        return out

    def publish(self, out: Outgoing, msg: Any, stamp_ns: int) -> None:
        out.publish(msg, stamp_ns)

    def publish_cdr(self, out: Outgoing, payload: bytes, stamp_ns: int) -> None:
        out.publish_cdr(payload, stamp_ns)

    def _publisher_factory(self, namespace: str) -> Callable[[str, str], Publisher]:
        def make(topic: str, type_name: str) -> Publisher:
            type_name = msgs.normalize_type(type_name)
            out = self.make_publisher(topic_key(self.plan.name, namespace, topic), type_name)
            return Publisher(out.key, type_name, out.publish, out.publish_cdr)

        return make

    def _subscriber_factory(self, namespace: str, checked: bool = True) -> Callable[..., None]:
        """`subscribe(topic, type, callback, max_bytes=None)` for a robot's plugins; `checked`: messages
        from other processes holding a NaN or Inf, or of more than `max_bytes` (MAX_INBOUND_BYTES), are
        dropped (plugins), or delivered as they are (what an event watches: a node's LaserScan says "no
        return" with +inf, REP 117; a node's camera image may be large)."""

        def subscribe(
            topic: str, type_name: str, callback: Callable[[Any, int], None], max_bytes: int | None = None
        ) -> None:
            key = topic_key(self.plan.name, namespace, topic)
            if checked:
                self._checked.add(key)
                # several plugins on a key: the largest bound, so that each gets what it asked for
                limit = MAX_INBOUND_BYTES if max_bytes is None else int(max_bytes)
                self._max_bytes[key] = max(limit, self._max_bytes.get(key, 0))
            # the same list as the publisher's `local`, if this process also publishes the key
            entry = (msgs.normalize_type(type_name), callback, None)
            self._local.setdefault(key, []).append(entry)
            subs_of = getattr(self, "_subs_of", None)
            if subs_of is not None and checked:  # (a robot's: taken back if it is deleted, runner.sim.grow)
                subs_of.setdefault(namespace, []).append((key, entry))
            if key not in self._remote_subscribed:
                self._remote_subscribed.add(key)
                self.bus.subscribe(key, self._on_remote, msgs.normalize_type(type_name))

        return subscribe

    def _on_remote(self, key: str, payload: bytes, att: bytes | None) -> None:
        """A message from another process (a Zenoh thread): queued for the next boundary, and counted, so
        lockstep knows when everything a node sent has arrived (a dropped one too: it arrived). On a key a
        plugin takes, one over its size bound is dropped here, before it is decoded or queued."""
        limit = self._max_bytes.get(key)
        if limit is not None and len(payload) > limit:
            why = too_large(limit)
            if key not in self._too_large_said:
                self._too_large_said.add(key)
                print(
                    f"world: {key}: a message of {len(payload):,} bytes, {why}; dropped before it is decoded "
                    "(its subscriber keeps the last good one)",
                    file=sys.stderr,
                )
            self._reject(key, why)
        else:
            self._inbox.put((key, payload, att))
        self._received[key] = self._received.get(key, 0) + 1
        lockstep = self._lockstep
        if lockstep is not None:
            lockstep.poke()

    def _drain_inbox(self) -> None:
        checked = self._checked
        while True:
            try:
                key, payload, _att = self._inbox.get_nowait()
            except queue.Empty:
                return
            decoded: dict[str, Any] = {}  # type -> the message, decoded once (None: dropped)
            for type_name, cb, _peek in self._local.get(key, ()):
                if type_name in decoded:
                    msg = decoded[type_name]
                else:
                    msg = decoded[type_name] = self._inbound(key, payload, type_name, key in checked)
                if msg is not None:
                    cb(msg, self.now_ns)

    def _inbound(self, key: str, payload: bytes, type_name: str, checked: bool) -> Any:
        """A message from another process, decoded; None (dropped, and counted by the bus) when it is not
        of the type, or, on a key a plugin takes (`checked`), when it holds a NaN or Inf: the plugin keeps
        its last good command."""
        try:
            msg = msgs.decode(payload, type_name)
        except Exception:
            # not a message of the subscribed type: a foreign publisher's mistake, dropped and counted
            self._reject(key, f"{len(payload)} bytes that do not decode as {type_name}")
            return None
        if checked:
            where = msgs.nonfinite(msg, type_name)
            if where is not None:
                if key not in self._nonfinite_said:
                    self._nonfinite_said.add(key)
                    value = msg
                    for part in where:
                        value = value[part] if isinstance(part, int) else getattr(value, part)
                    print(
                        f"world: {key} at t = {self.now_ns / 1e9:.3f} s: {msgs.path_text(where)} is {value}; "
                        "the message is dropped (its subscriber keeps the last good one)",
                        file=sys.stderr,
                    )
                self._reject(key, NONFINITE)
                return None
        return msg

    def _reject(self, key: str, why: str) -> None:
        reject = getattr(self.bus, "reject", None)
        if reject is not None:
            reject(key, why)

    def published(self) -> dict[str, int]:
        return {k: o.seq for k, o in self._out.items()}
