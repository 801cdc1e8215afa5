"""Recorder: subscribes to the run's key space and writes MCAP (ros2msg schemas, CDR payloads).

- `log_time` and `publish_time` are the sim time from the sample's attachment (integer ns);
  a sample without one (a foreign publisher) gets the latest sim time seen.
- Channels and schemas are registered lazily, on a topic's first message.
- Sequence numbers are checked per topic, so a lost message is counted, not guessed.
- The file is written in chunks and finished on every exit path (`close()` in a `finally`), so it is
  readable after a normal end, an error or Ctrl-C.

Speed: the per-message path is a few dict/attribute lookups and two `bytearray` appends (~2 µs of
Python); the encoding is parsed only on a key's first sample. Messages are packed straight into the chunk
being built (`runner.record.mcap_file`; the `mcap` package's `Writer` spends ~3 µs of Python per
message); only the records written once per chunk or per file (chunk, indexes, summary) go through the
`mcap` package's record classes. `bench/recorder.py` measures it: on 2 cores, ~200k messages/s (mean
662 B) sustained from another process with none lost, ~6 µs of CPU per message in the recording process,
Zenoh's included (~100k and ~12 µs with `mcap.Writer` and the previous per-sample code).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import zenoh

from runner.plugin import MAX_INBOUND_BYTES, too_large
from runner.record.claim import claim, lock_of, refuse_foreign
from runner.record.finisher import Guard
from runner.record.mcap_file import CHUNK_SIZE, McapFile, RecordedChannel, TopicStats
from runner.wire import msgs
from runner.wire.transport import ATTACHMENT, count_reason, type_from_encoding, unpack_attachment

# Keys counted one by one for publishers outside the run, at most; past them, together under OTHER_KEYS (a
# stray session putting on 20,000 keys of its own made 20,000 end-table lines and results properties).
OUTSIDE_KEYS = 1000
OTHER_KEYS = "(other keys)"

# Samples queued for the drain thread, at most: bounds the memory a slow disk can take (1024 camera images
# of 1 MB...); a larger queue records no faster (bench/recorder.py).
FIFO_CAPACITY = 1024
DRAIN_BATCH = 256  # samples the drain thread records per lock acquisition, at most

_PUT = zenoh.SampleKind.PUT
_unpack_att = ATTACHMENT.unpack
_ATT_SIZE = ATTACHMENT.size


@dataclass
class Recorder:
    """Records the samples of a run into an MCAP file.

    Two ways to feed it, both thread-safe, both safe against a concurrent `close()`:

    - `on_sample`, a Zenoh callback: `session.declare_subscriber(f"{run}/**", recorder.on_sample)`.
      Zenoh's receive thread runs the recording code (a few µs per sample, Python included).
    - `subscribe(session, f"{run}/**")`, faster: the recorder declares the subscriber itself, with a
      bounded FIFO channel, and a thread of its own drains it in batches (one lock acquisition per
      batch). Zenoh's thread only queues; a full queue back-pressures the publishers (with BLOCK
      congestion control nothing is dropped). `close()` undeclares that subscriber, records what is
      still queued, and only then finishes the file: no need to undeclare it separately.

    `write()` records one message given as plain values (tests, replay).
    """

    path: Path
    include: list[str]
    exclude: list[str] = field(default_factory=list)
    library: str = "scenario-runner"
    chunk_size: int = CHUNK_SIZE
    types: dict[str, str] = field(default_factory=dict)  # the type each known key carries (the plan's)
    inbound: set[str] = field(default_factory=set)  # keys the worlds take from others: checked to decode
    # a guard process finishes the file if this process dies before it does (kill -9): runner.record.finisher
    guarded: bool = False
    compression: str = "zstd"  # the chunks': "zstd" or "none"

    def __post_init__(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        # the path the plan gave; `path` is the one recorded to (see `runner.record.claim`)
        self.asked = self.path
        refuse_foreign(self.path)  # (before its lock is made: a user's `.notes.lock` beside `notes` too)
        self.path, self._claim_fd = claim(self.path)
        self._guard: Guard | None = None
        try:
            refuse_foreign(self.path)
            # unbuffered: whole chunks are written at once, and a failed write (a full disk) leaves no
            # buffer behind that a later flush would write past the point the file is cut back to
            self._file: IO[bytes] = open(self.path, "wb", buffering=0)  # noqa: SIM115 - closed in close()
            self._guard = Guard(self.path, self._claim_fd) if self.guarded else None
            self._mcap = McapFile(
                self._file,
                profile="ros2",
                library=self.library,
                chunk_size=self.chunk_size,
                guard=self._guard,
                compression=self.compression,
            )
        except BaseException:
            self._give_up()
            raise
        self._lock = threading.Lock()
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, RecordedChannel] = {}
        self._skipped: dict[str, bool] = {}
        self._inc = [zenoh.KeyExpr(e) for e in self.include]
        self._exc = [zenoh.KeyExpr(e) for e in self.exclude]
        self.latest_ns = 0
        self.unknown: dict[str, int] = {}  # keys whose samples had no ROS type in their encoding
        self.closed = False
        self.error: OSError | None = None  # what stopped the drain thread's recording, if anything
        self.stopped_ns: int | None = None  # the sim time it stopped at (the judge's data stops there too)
        self.rejected = 0  # samples the drain thread could not record (an exception each)
        self.mistyped: dict[str, dict[str, int]] = {}  # key -> why -> samples of another type, not recorded
        # samples without the run's (sequence, stamp) attachment, per key: every process of the run (worlds,
        # nodes, bridges, the tools) attaches one, so these come from a publisher outside the run
        self.outside: dict[str, int] = {}
        self._subscriber: Any = None
        self._drainer: threading.Thread | None = None
        self._taps: dict[str, Callable[[str, int, bytes], None]] = {}
        self.tap_errors = 0

    def tap(self, keys: Iterable[str], fn: Callable[[str, int, bytes], None]) -> None:
        """Also hand each recorded message of `keys` to `fn(key, sim time ns, payload)`, in order, as it is
        recorded (the live judge reads the run this way: no subscriptions, threads or copies of its own)."""
        for key in keys:
            self._taps[key] = fn

    # ------------------------------------------------------------------------------------------- input
    def wanted(self, key: str) -> bool:
        skip = self._skipped.get(key)
        if skip is None:
            ke = zenoh.KeyExpr(key)
            ok = any(e.intersects(ke) for e in self._inc) and not any(e.intersects(ke) for e in self._exc)
            skip = self._skipped[key] = not ok
        return not skip

    def on_sample(self, sample: zenoh.Sample) -> None:
        """Record one Zenoh sample (a PUT); usable as a subscriber callback."""
        with self._lock:
            if not self.closed:
                self._take(sample)

    def subscribe(self, session: zenoh.Session, key_expr: str, capacity: int = FIFO_CAPACITY) -> None:
        """Declare a subscriber on `key_expr` whose samples a thread of this recorder drains (see the class
        docstring). Undeclared by `close()`."""
        if self._subscriber is not None:
            raise RuntimeError("the recorder already has its subscriber")
        self._subscriber = session.declare_subscriber(key_expr, zenoh.handlers.FifoChannel(capacity))
        self._drainer = threading.Thread(
            target=self._drain, args=(self._subscriber.handler,), name="recorder-drain", daemon=True
        )
        self._drainer.start()

    def _drain(self, handler: Any) -> None:
        recv, try_recv, take, lock = handler.recv, handler.try_recv, self._take, self._lock
        while True:
            try:
                sample = recv()  # blocks without the GIL
            except zenoh.ZError:  # undeclared, and nothing left
                return
            if self.closed or self.error is not None:
                continue  # keep consuming, so that a publisher is never blocked by a full queue
            try:
                with lock:
                    if self.closed:
                        continue
                    take(sample)
                    for _ in range(DRAIN_BATCH):
                        sample = try_recv()
                        if sample is None:
                            break
                        take(sample)
            except zenoh.ZError:
                return
            except OSError as e:  # the disk is full...: stop recording, say it once, keep the queue moving
                self.error, self.stopped_ns = e, self.latest_ns
                with contextlib.suppress(OSError):
                    self._mcap.cut_back()  # the file ends with whole chunks: `close` adds the summary
                print(f"recorder: recording stopped: {e}", file=sys.stderr, flush=True)
            except Exception as e:  # one sample that cannot be recorded (as a callback's would): skip it
                self.rejected += 1
                if self.rejected == 1:
                    print(f"recorder: a sample was not recorded: {e!r}", file=sys.stderr, flush=True)

    def _take(self, sample: zenoh.Sample) -> None:
        """Record a sample; the lock is held and the recorder open."""
        if sample.kind != _PUT:
            return
        key = str(sample.key_expr)
        att = sample.attachment
        raw = att.to_bytes() if att is not None else b""
        if len(raw) != _ATT_SIZE:
            counted = key if key in self.outside or len(self.outside) < OUTSIDE_KEYS else OTHER_KEYS
            self.outside[counted] = self.outside.get(counted, 0) + 1
        ch = self._channels.get(key)
        if self.types and key in self.types:
            given = type_from_encoding(sample.encoding)
            if given is not None and given != self.types[key] and not given.startswith("foxglove."):
                # another type on a typed key (a stray publisher): never on that key's channel
                self._mistyped(key, f"{given}, not {self.types[key]}")
                return
            if key in self.inbound:  # what others send the worlds: it must decode, or it is not recorded
                if len(sample.payload) > MAX_INBOUND_BYTES:
                    # not decoded here either (a valid 96 MB JointState would hold this callback 16 s), and
                    # not recorded undecoded: readers of the recording decode every message of a channel
                    self._mistyped(key, too_large(MAX_INBOUND_BYTES))
                    return
                try:
                    msgs.decode(sample.payload.to_bytes(), self.types[key])
                except Exception:
                    self._mistyped(key, f"payloads that do not decode as {self.types[key]}")
                    return
        if ch is not None and len(raw) == _ATT_SIZE:
            seq, stamp = _unpack_att(raw)
            if stamp > self.latest_ns:
                self.latest_ns = stamp
            self._add(ch, seq, stamp, sample.payload.to_bytes())
            return
        # first sample of a key, a key not recorded, or no attachment
        parsed = unpack_attachment(raw) if att is not None else None
        if ch is None and not self.wanted(key):
            if parsed is not None:
                self.latest_ns = max(self.latest_ns, parsed[1])
            return
        self._write(key, type_from_encoding(sample.encoding), sample.payload.to_bytes(), parsed)

    def _mistyped(self, key: str, why: str) -> None:
        first = count_reason(self.mistyped.setdefault(key, {}), why)
        if first is not None:
            print(f"recorder: not recording messages on {key}: {first}", file=sys.stderr, flush=True)

    def write(self, key: str, type_name: str | None, payload: bytes, att: tuple[int, int] | None) -> None:
        """Record one message: `att` is (sequence number, sim time ns) or None (no attachment)."""
        with self._lock:
            if not self.closed:
                self._write(key, type_name, payload, att)

    def _write(self, key: str, type_name: str | None, payload: bytes, att: tuple[int, int] | None) -> None:
        if att is not None:
            seq, stamp = att
            self.latest_ns = max(self.latest_ns, stamp)
        else:
            seq, stamp = None, self.latest_ns
        ch = self._channels.get(key)
        if ch is None:
            if not self.wanted(key):
                return
            if type_name is not None and type_name.startswith("foxglove."):
                ch = self._register(key, type_name)  # (its schema comes from foxglove-sdk)
            elif type_name is None or not msgs.is_known(type_name):
                self.unknown[key] = self.unknown.get(key, 0) + 1
                return
            else:
                ch = self._register(key, msgs.normalize_type(type_name))
        self._add(ch, seq, stamp, payload)

    def _add(self, ch: RecordedChannel, seq: int | None, stamp: int, payload: bytes) -> None:
        st = ch.stats
        self._mcap.add_message(ch, (seq if seq is not None else st.count) & 0xFFFFFFFF, stamp, payload)
        if seq is not None:
            expected = st.next_seq
            if expected is not None and seq > expected:
                st.lost += seq - expected
            st.next_seq = seq + 1
        st.count += 1
        if st.first_ns is None:
            st.first_ns = stamp
        st.last_ns = stamp
        if self._taps:
            tap = self._taps.get(st.key)
            if tap is not None:
                try:
                    tap(st.key, stamp, payload)
                except Exception as e:  # the reader's mistake must not stop the recording
                    self.tap_errors += 1
                    if self.tap_errors == 1:
                        print(f"recorder: a reader of {st.key} failed: {e!r}", file=sys.stderr, flush=True)

    def _register(self, key: str, type_name: str) -> RecordedChannel:
        foxglove = type_name.startswith("foxglove.")  # Foxglove's schemas (scene): protobuf
        schema_id = self._schemas.get(type_name)
        if schema_id is None:
            if foxglove:
                schema = foxglove_schema(type_name)
                schema_id = self._mcap.register_schema(
                    name=schema.name, encoding="protobuf", data=schema.data
                )
            else:
                schema_id = self._mcap.register_schema(
                    name=type_name, encoding="ros2msg", data=msgs.msgdef(type_name).encode()
                )
            self._schemas[type_name] = schema_id
        ch = self._mcap.register_channel(
            topic=key,
            message_encoding="protobuf" if foxglove else "cdr",
            schema_id=schema_id,
            stats=TopicStats(key, type_name),
        )
        self._channels[key] = ch
        return ch

    # ------------------------------------------------------------------------------------------ output
    def stats(self) -> list[TopicStats]:
        with self._lock:
            return sorted((c.stats for c in self._channels.values()), key=lambda s: s.key)

    def counts(self) -> dict[str, int]:
        with self._lock:
            return {k: c.stats.count for k, c in self._channels.items()}

    def flush_stale(self, max_age_s: float = 1.0) -> None:
        """Write the chunk being built if the last one went out more than `max_age_s` ago: a slow run
        killed outright loses at most that much (the runner calls this as it watches the run)."""
        with self._lock:
            if self.closed or self.error is not None:
                return
            if self._mcap.chunk and time.monotonic() - self._mcap.flushed_at > max_age_s:
                try:
                    self._mcap.flush_chunk()
                except OSError as e:  # the disk is full: as in the drain thread
                    self.error, self.stopped_ns = e, self.latest_ns
                    with contextlib.suppress(OSError):
                        self._mcap.cut_back()
                    print(f"recorder: recording stopped: {e}", file=sys.stderr, flush=True)

    def end_note(self, **values: str) -> None:
        """Say how the run ended, in the recording's `scenario` metadata record (written by `close`)."""
        with self._lock:
            self._mcap.note.update(values)

    def close(self) -> None:
        """Stop recording (what `subscribe` queued first) and finish the file. Idempotent."""
        sub, self._subscriber = self._subscriber, None
        if sub is not None:
            with contextlib.suppress(Exception):
                sub.undeclare()
            if self._drainer is not None and self._drainer is not threading.current_thread():
                self._drainer.join(timeout=10.0)
        with self._lock:
            if self.closed:
                return
            self.closed = True
            if self.error is not None:
                self._mcap.note.update(
                    stopped="the recording could not be written", error=self.error.strerror or str(self.error)
                )
            try:
                if self.error is not None:
                    self._mcap.finish_in_room()
                else:
                    self._mcap.finish()
            except OSError as e:  # not even the summary fits: the file stays readable chunk by chunk
                self.error = self.error or e
                print(
                    f"recorder: the recording's summary could not be written ({e.strerror or e}); "
                    f"`scenario recover {self.path}` completes it",
                    file=sys.stderr,
                    flush=True,
                )
            finally:
                self._file.close()
                if self._guard is not None:
                    self._guard.done()
                with contextlib.suppress(OSError):  # the path is free for the next run
                    lock_of(self.path).unlink()
                    os.close(self._claim_fd)

    def _give_up(self) -> None:
        """The recording could not even begin (a full disk): nothing of it is left, neither the file (it
        holds nothing) nor its lock."""
        if hasattr(self, "_file"):  # (only a file this run created is removed)
            with contextlib.suppress(OSError):
                self._file.close()
            with contextlib.suppress(OSError):
                self.path.unlink()
        if self._guard is not None:
            self._guard.done()
        with contextlib.suppress(OSError):  # removed while held, then given up (runner.record.claim)
            lock_of(self.path).unlink()
        with contextlib.suppress(OSError):
            os.close(self._claim_fd)

    @property
    def guard_pid(self) -> int | None:
        """The pid of the recording's guard process (None: unguarded)."""
        proc = self._guard.proc if self._guard is not None else None
        return proc.pid if proc is not None else None


def foxglove_schema(type_name: str) -> Any:
    """The protobuf schema (name, encoding, FileDescriptorSet) of a Foxglove message, from foxglove-sdk."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import foxglove.messages

    cls = getattr(foxglove.messages, type_name.removeprefix("foxglove."))
    return cls.get_schema()
