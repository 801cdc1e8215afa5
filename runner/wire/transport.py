"""Zenoh: session configuration, the wire format of our samples, and the `Bus` the world publishes on.

Wire format of every sample the simulation publishes:
- key: `<run>/<ns>/<topic>` (or `<run>/clock`); run metadata under `<run>/@meta/...` (a verbatim chunk,
  so `<run>/**` never matches it);
- payload: the CDR encoding of a ROS 2 message;
- encoding: `application/cdr;<ros type>` (e.g. `application/cdr;sensor_msgs/msg/LaserScan`);
- attachment: 16 bytes, little-endian `uint64 sequence number, int64 sim time in ns`.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import struct
import sys
import threading
from collections.abc import Callable, Sequence
from typing import Any, Protocol

import zenoh

from runner.errors import visible

ATTACHMENT = struct.Struct("<Qq")
META = "@meta"


def pack_attachment(seq: int, stamp_ns: int) -> bytes:
    return ATTACHMENT.pack(seq, stamp_ns)


def unpack_attachment(data: bytes | None) -> tuple[int, int] | None:
    if data is None or len(data) != ATTACHMENT.size:
        return None
    return ATTACHMENT.unpack(data)


def encoding_for(type_name: str) -> zenoh.Encoding:
    """`application/cdr;<ros type>`; Foxglove's own schemas (`foxglove.SceneUpdate`) are protobuf."""
    if type_name.startswith("foxglove."):
        return zenoh.Encoding.APPLICATION_PROTOBUF.with_schema(type_name)
    return zenoh.Encoding.APPLICATION_CDR.with_schema(type_name)


def zenoh_reason(err: Exception) -> str:
    """Zenoh's error text without the Rust source location it carries (`Str("x") at .../x.rs:86`)."""
    import re

    text = re.sub(r"\s+at \S+\.rs:\d+(?::\d+)?\.?", "", str(err)).strip()
    quoted = re.fullmatch(r'Str\("(.*)"\)', text)
    return quoted.group(1) if quoted else text


def type_from_encoding(encoding: Any) -> str | None:
    text = str(encoding)
    if text.startswith(("application/cdr;", "application/protobuf;")):
        return text.split(";", 1)[1] or None
    return None


# Kinds of dropped sample told apart per key, at most: the type another publisher names and a payload's
# size are theirs to choose, and a stray session that named a new type in each of 10,000 samples made
# 10,000 stderr lines (their escape sequences obeyed by the terminal), end-table lines and 0.7 MB of
# metadata. Past this, they are counted together.
MAX_REASONS = 8
OTHER_REASONS = f"other reasons (more than {MAX_REASONS} kinds)"


def count_reason(counts: dict[str, int], why: str) -> str | None:
    """Count a dropped sample under `why` in `counts` (one key's), or under `OTHER_REASONS` past
    `MAX_REASONS` kinds; the reason to say on stderr when it is the first of its kind, else None."""
    why = visible(why[:200])
    if why not in counts and len(counts) >= MAX_REASONS:
        why = OTHER_REASONS
    first = why not in counts
    counts[why] = counts.get(why, 0) + 1
    return why if first else None


def meta_key(run: str, *parts: str) -> str:
    return "/".join((run, META, *parts))


def hidden_topic(rel: str) -> bool:
    """The run's own helper topics (`_truth/...`, `_contacts`): a chunk starting with `_`, hidden as ROS
    hides `_` topics. `rel` is a key without the run's name."""
    return any(chunk.startswith("_") for chunk in rel.split("/"))


def hidden_key(key: str) -> bool:
    """`hidden_topic` for a full key (`<run>/...`, its first chunk the run's name): what `scenario info`,
    `topics`, the end-of-run table and the report leave out unless told `--all`."""
    return hidden_topic(key.split("/", 1)[1] if "/" in key else key)


def topic_key(run: str, namespace: str, topic: str) -> str:
    """`scan` in namespace r1 -> `run/r1/scan`; `/clock` (absolute) -> `run/clock`."""
    if topic.startswith("/"):
        return f"{run}{topic}"
    return f"{run}/{namespace}/{topic}" if namespace else f"{run}/{topic}"


def free_port(host: str = "127.0.0.1") -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


def make_config(
    mode: str,
    *,
    listen: Sequence[str] = (),
    connect: Sequence[str] = (),
) -> zenoh.Config:
    """A Zenoh config with multicast scouting off: peers find each other only through explicit endpoints.

    The run's own Zenoh settings (the scenario's `zenoh:`: TLS, access control...), handed to every process
    of the run in `SCENARIO_ZENOH`, come first; the session's role and endpoints go on top."""
    conf = _run_settings()
    conf.insert_json5("mode", json.dumps(mode))
    conf.insert_json5("scouting/multicast/enabled", "false")
    # No gossip either: sessions meet only through the endpoints given (a run's topology is explicit).
    conf.insert_json5("scouting/gossip/enabled", "false")
    conf.insert_json5("scouting/delay", "0")
    if listen:
        conf.insert_json5("listen/endpoints", json.dumps(list(listen)))
    if connect:
        conf.insert_json5("connect/endpoints", json.dumps(list(connect)))
    if connect:
        # A router or client started before the one it joins (another host's runner, say) retries often,
        # not on Zenoh's default back-off of up to 4 s.
        conf.insert_json5(
            "connect/retry", '{"period_init_ms": 100, "period_max_ms": 500, "period_increase_factor": 2}'
        )
    if mode == "client":
        # A client started a moment before its router keeps retrying instead of failing at once.
        conf.insert_json5("connect/timeout_ms", "10000")
    return conf


ZENOH_ENV = "SCENARIO_ZENOH"


def _run_settings() -> zenoh.Config:
    spec = os.environ.get(ZENOH_ENV)
    if not spec:
        return zenoh.Config()
    data = json.loads(spec)
    conf = zenoh.Config.from_file(data["file"]) if data.get("file") else zenoh.Config()
    for key, value in data.get("settings", {}).items():
        conf.insert_json5(key, json.dumps(value))
    return conf


def use_run_settings(settings: dict[str, Any] | None) -> None:
    """Make the run's Zenoh settings apply to every session this process opens, and to its children."""
    if settings:
        os.environ[ZENOH_ENV] = json.dumps(settings)
    else:
        os.environ.pop(ZENOH_ENV, None)


class Bus(Protocol):
    """What the world process publishes on and listens to. `ZenohBus` in runs; `MemoryBus` in unit tests."""

    def publisher(self, key: str, type_name: str) -> Callable[[bytes | bytearray, bytes], None]: ...

    def subscribe(
        self, key: str, callback: Callable[[str, bytes, bytes | None], None], type_name: str | None = None
    ) -> None: ...


# `respond(payload, error)`: answers one request, once: `payload` (the response's CDR), or `error` (text)
Respond = Callable[[bytes | None, str | None], None]
# `on_request(payload, attachment, respond)`: a request to a service, on a Zenoh thread
OnRequest = Callable[[bytes, bytes | None, Respond], None]


def service_encoding(type_name: str) -> zenoh.Encoding:
    return zenoh.Encoding.APPLICATION_CDR.with_schema(type_name)


# Payloads at least this large (camera frames, point clouds) are copied once into Zenoh's shared memory
# and sent from there: a subscriber on this host maps them, one on another host gets them over the network
# as usual. Smaller ones are put as bytes (Zenoh copies them into its own buffer).
SHM_MIN_BYTES = 64 * 1024
SHM_POOL_BYTES = 64 * 1024 * 1024


class SharedMemorySender:
    """Copies large payloads into a Zenoh shared-memory pool (made on first use) and puts them from there:
    one copy, where `put(bytes)` makes Zenoh copy the bytes into its own buffer and then again into shared
    memory or a socket. When the pool is full (subscribers still hold its buffers) or shared memory is not
    available, the payload is put as bytes instead: nothing waits for it."""

    def __init__(self, pool_bytes: int = SHM_POOL_BYTES):
        self.pool_bytes = pool_bytes
        self._provider: Any = None
        self._policy: Any = None
        self.ok = True
        self.sent = 0  # payloads sent from shared memory
        self.fallbacks = 0  # payloads put as bytes because the pool was full

    def buffer(self, payload: bytes | bytearray) -> Any:
        """A shared-memory buffer holding a copy of `payload`, or None (put the bytes themselves)."""
        if not self.ok:
            return None
        if self._provider is None:
            # POSIX shared memory lives in /dev/shm: a pool larger than what is free there (a container's
            # default is 64 MB) would crash the process when its pages are touched, so it stays well within
            try:
                free = os.statvfs("/dev/shm")
                self.pool_bytes = min(self.pool_bytes, free.f_bavail * free.f_frsize // 4)
            except OSError:
                pass
            if self.pool_bytes < 4 * len(payload):
                self.ok = False
                return None
            try:
                from zenoh import shm

                self._provider = shm.ShmProvider.default_backend(self.pool_bytes)
                self._policy = shm.GarbageCollect()
            except Exception:
                self.ok = False
                return None
        try:
            buf = self._provider.alloc(len(payload), policy=self._policy)
        except zenoh.ZError:
            self.fallbacks += 1
            return None
        buf[:] = payload if isinstance(payload, bytes | bytearray) else bytes(payload)
        self.sent += 1
        return buf


class ZenohBus:
    """Publishers and subscribers on a session; with `graph` (a `runner.wire.graph.GraphTokens`), each is also
    announced in the run's graph."""

    def __init__(self, session: zenoh.Session, graph: Any = None, best_effort: Sequence[str] = ()):
        self.session = session
        self.graph = graph
        self.rejected: dict[str, dict[str, int]] = {}  # key -> why -> how many inbound samples were dropped
        self.best_effort = [zenoh.KeyExpr(e) for e in best_effort]
        self._keep: list[Any] = []
        self._pubs: list[Any] = []
        self._of_key: dict[str, list[tuple[str, Any, str | None]]] = {}  # key -> (kind, entity, type)
        self.shm = SharedMemorySender()

    def _held(self, kind: str, key: str, entity: Any, type_name: str | None) -> None:
        self._keep.append(entity)
        self._of_key.setdefault(key, []).append((kind, entity, type_name))

    def withdraw(self, key: str) -> None:
        """Everything declared on `key` (publisher, subscriber, queryable) undeclared, and its graph tokens
        withdrawn: a deleted robot's topics and services go away, as its plugins do."""
        for kind, entity, type_name in self._of_key.pop(key, []):
            with contextlib.suppress(Exception):
                entity.undeclare()
            with contextlib.suppress(ValueError):
                self._keep.remove(entity)
            if entity in self._pubs:
                self._pubs.remove(entity)
            if self.graph is not None:
                self.graph.withdraw(kind, key, type_name)

    def publisher(self, key: str, type_name: str) -> Callable[[bytes | bytearray, bytes], None]:
        if self.graph is not None:
            self.graph.publisher(key, type_name)
        # Reliable by default: a publisher waits rather than drop (nothing recorded is lost; a slow subscriber
        # slows the simulation down); `qos:` makes some topics best effort (they drop instead).
        drop = any(e.intersects(zenoh.KeyExpr(key)) for e in self.best_effort)
        pub = self.session.declare_publisher(
            key,
            encoding=encoding_for(type_name),
            congestion_control=zenoh.CongestionControl.DROP if drop else zenoh.CongestionControl.BLOCK,
            reliability=zenoh.Reliability.BEST_EFFORT if drop else zenoh.Reliability.RELIABLE,
        )
        self._held("pub", key, pub, type_name)
        self._pubs.append(pub)

        shm = self.shm

        def send(payload: bytes | bytearray, attachment: bytes) -> None:
            if len(payload) >= SHM_MIN_BYTES:
                buf = shm.buffer(payload)
                if buf is not None:
                    pub.put(buf, attachment=attachment)
                    return
            pub.put(payload, attachment=attachment)

        return send

    def subscribe(
        self, key: str, callback: Callable[[str, bytes, bytes | None], None], type_name: str | None = None
    ) -> None:
        if self.graph is not None:
            self.graph.subscriber(key, type_name)

        def on_sample(sample: zenoh.Sample) -> None:
            att = sample.attachment
            given = type_from_encoding(sample.encoding)
            if type_name is not None and given is not None and given != type_name:
                # another type on this key (a stray publisher): never delivered as the subscribed type
                self.reject(str(sample.key_expr), f"{given}, not {type_name}")
                return
            callback(str(sample.key_expr), sample.payload.to_bytes(), att.to_bytes() if att else None)

        # REMOTE only: what this process publishes is delivered to its own plugins directly, in order.
        sub = self.session.declare_subscriber(key, on_sample, allowed_origin=zenoh.Locality.REMOTE)
        self._held("sub", key, sub, type_name)

    def queryable(self, key: str, on_request: OnRequest, type_name: str) -> None:
        """A service on `key` (a Zenoh queryable): each query's payload and attachment go to `on_request`
        with a `respond` that replies once, now or later (the query stays open until then), with the
        response's CDR (`<type>_Response` as its encoding's schema) or an error."""
        encoding = service_encoding(f"{type_name}_Response")

        def on_query(query: zenoh.Query) -> None:
            lock = threading.Lock()
            state = {"done": False}

            def respond(payload: bytes | None, error: str | None) -> None:
                with lock:
                    if state["done"]:
                        return
                    state["done"] = True
                try:
                    if payload is not None:
                        att = query.attachment
                        query.reply(
                            key, payload, encoding=encoding, attachment=att.to_bytes() if att else None
                        )
                    else:
                        query.reply_err(error or "error")
                except Exception as e:  # (the client gave up, the session is closing)
                    print(f"world: {key}: could not answer a request: {zenoh_reason(e)}", file=sys.stderr)
                finally:
                    query.drop()

            att = query.attachment
            payload = query.payload.to_bytes() if query.payload is not None else b""
            on_request(payload, att.to_bytes() if att else None, respond)

        self._held("srv", key, self.session.declare_queryable(key, on_query, complete=True), type_name)
        if self.graph is not None:
            # announced once it answers: the bridge offers it to ROS 2 when it sees this token
            self.graph.service(key, type_name)

    def reject(self, key: str, why: str) -> None:
        """Count a dropped inbound sample; the first of each kind on a key is said on stderr."""
        first = count_reason(self.rejected.setdefault(key, {}), why)
        if first is not None:
            print(
                f"world: dropping messages on {key}: {first} (another publisher's mistake)",
                file=sys.stderr,
            )

    def all_matched(self) -> bool:
        """Whether every publisher declared so far has a subscriber somewhere."""
        return all(p.matching_status.matching for p in self._pubs)

    def undeclare_all(self) -> None:
        for ent in self._keep:
            with contextlib.suppress(Exception):
                ent.undeclare()
        self._keep.clear()
        self._pubs.clear()
        if self.graph is not None:
            self.graph.close()


class MemoryBus:
    """An in-process bus for unit tests of logic: keeps what was published, lets a test inject input."""

    def __init__(self) -> None:
        self.rejected: dict[str, dict[str, int]] = {}
        self.sent: list[tuple[str, str, bytes, bytes]] = []
        self.services: dict[str, OnRequest] = {}
        self.withdrawn: list[str] = []
        self._subs: dict[str, list[Callable[[str, bytes, bytes | None], None]]] = {}

    def publisher(self, key: str, type_name: str) -> Callable[[bytes | bytearray, bytes], None]:
        def send(payload: bytes | bytearray, attachment: bytes) -> None:
            self.sent.append((key, type_name, bytes(payload), attachment))  # (a bytearray is borrowed)

        return send

    def subscribe(
        self, key: str, callback: Callable[[str, bytes, bytes | None], None], type_name: str | None = None
    ) -> None:
        self._subs.setdefault(key, []).append(callback)

    def reject(self, key: str, why: str) -> None:
        count_reason(self.rejected.setdefault(key, {}), why)

    def queryable(self, key: str, on_request: OnRequest, type_name: str) -> None:
        self.services[key] = on_request

    def call(
        self, key: str, payload: bytes, attachment: bytes | None = None
    ) -> list[tuple[bytes | None, str | None]]:
        """Send a request to the service on `key`; the list its answer is appended to (when it comes)."""
        answers: list[tuple[bytes | None, str | None]] = []
        self.services[key](payload, attachment, lambda p, e: answers.append((p, e)))
        return answers

    def withdraw(self, key: str) -> None:
        """What was declared on `key` is gone (ZenohBus.withdraw): `withdrawn` keeps the keys, in order."""
        self._subs.pop(key, None)
        self.services.pop(key, None)
        self.withdrawn.append(key)

    def inject(self, key: str, payload: bytes, attachment: bytes | None = None) -> None:
        for cb in self._subs.get(key, []):
            cb(key, payload, attachment)
