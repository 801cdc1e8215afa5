"""Recorder: subscribes to the run's key space and writes MCAP (ros2msg schemas, CDR payloads).

- `log_time` and `publish_time` are the sim time from the sample's attachment (integer ns);
  a sample without one (a foreign publisher) gets the latest sim time seen.
- Channels and schemas are registered lazily, on a topic's first message.
- Sequence numbers are checked per topic, so a lost message is counted, not guessed.
- The file is written in chunks and finished on every exit path (`close()` in a `finally`), so it is
  readable after a normal end, an error or Ctrl-C.

Speed: the per-message path is a few dict/attribute lookups and two `bytearray` appends (~2 µs of
Python); the encoding is parsed only on a key's first sample. Messages are packed straight into the chunk
being built (`_McapFile`; the `mcap` package's `Writer` spends ~3 µs of Python per message); only the
records written once per chunk or per file (chunk, indexes, summary) go through the `mcap` package's
record classes. `bench/recorder.py` measures it: on 2 cores, ~200k messages/s (mean 662 B) sustained from
another process with none lost, ~6 µs of CPU per message in the recording process, Zenoh's included
(~100k and ~12 µs with `mcap.Writer` and the previous per-sample code).
"""

from __future__ import annotations

import contextlib
import errno
import os
import struct
import sys
import threading
import time
import zlib
from array import array
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import zenoh
import zstandard
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import Channel, ChunkIndex, Header, McapRecord, Schema

from runner.record.finisher import MAGIC, TRAILER, Guard, Tail
from runner.wire import msgs
from runner.wire.transport import ATTACHMENT, type_from_encoding, unpack_attachment

CHUNK_SIZE = 256 * 1024  # uncompressed bytes per chunk
ZSTD_LEVEL = 1  # vs the default 3: 10-30% faster here, for the same ratio on sensor data (bench/recorder.py)
# Samples queued for the drain thread, at most: bounds the memory a slow disk can take (1024 camera images
# of 1 MB...); a larger queue records no faster (bench/recorder.py).
FIFO_CAPACITY = 1024
DRAIN_BATCH = 256  # samples the drain thread records per lock acquisition, at most

# Message record: opcode, record length, channel id, sequence, log time, publish time (then the data).
_MESSAGE_HEAD = struct.Struct("<BQHIQQ")
_MESSAGE_FIXED = _MESSAGE_HEAD.size - 9  # the record's length minus the data's
_MESSAGE_INDEX_HEAD = struct.Struct("<BQHI")
# Chunk record up to its data: opcode, record length, start, end, uncompressed size and crc, compression
# (a 4-byte string: "zstd"), compressed size.
_CHUNK_HEAD = struct.Struct("<BQQQQII4sQ")
_ZSTD = b"zstd"
_OP_MESSAGE = int(Opcode.MESSAGE)
_OP_MESSAGE_INDEX = int(Opcode.MESSAGE_INDEX)
_PUT = zenoh.SampleKind.PUT
_unpack_att = ATTACHMENT.unpack
_ATT_SIZE = ATTACHMENT.size


@dataclass(slots=True)
class TopicStats:
    key: str
    type: str
    count: int = 0
    first_ns: int | None = None
    last_ns: int | None = None
    next_seq: int | None = None
    lost: int = 0

    def rate(self) -> float:
        """Messages per sim second between the first and the last message."""
        if self.count < 2 or self.first_ns is None or self.last_ns is None or self.last_ns <= self.first_ns:
            return 0.0
        return (self.count - 1) / ((self.last_ns - self.first_ns) / 1e9)


class _Channel:
    __slots__ = ("id", "index", "stats")

    def __init__(self, channel_id: int, stats: TopicStats):
        self.id = channel_id
        self.stats = stats
        # (log time, offset in the chunk) of each of its messages in the chunk being built, flat
        self.index = array("Q")


def _record_bytes(record: McapRecord) -> bytes:
    builder = RecordBuilder()
    record.write(builder)
    return bytes(builder.end())


class _McapFile:
    """A chunked, indexed MCAP writer (the layout of `mcap.writer.Writer` with its defaults: zstd chunks,
    message indexes, chunk indexes, statistics, repeated schemas and channels, summary offsets, summary
    CRC), whose per-message work is two appends to the chunk and two to the channel's index.

    Not thread-safe: the `Recorder` calls it under its lock.
    """

    def __init__(
        self,
        stream: IO[bytes],
        *,
        profile: str,
        library: str,
        chunk_size: int = CHUNK_SIZE,
        guard: Guard | None = None,
    ):
        self._stream = stream
        self.chunk_size = chunk_size
        self.chunk = bytearray()  # the uncompressed records of the chunk being built
        self._zstd = zstandard.ZstdCompressor(level=ZSTD_LEVEL)
        self._tail = Tail()  # the summary's records, as chunks are written
        self._by_id: dict[int, _Channel] = {}
        self.flushed_at = time.monotonic()
        self._pos = 0
        self.guard = guard
        self._write_trailed(bytearray(MAGIC + _record_bytes(Header(profile=profile, library=library))))
        self._good = self._pos  # the end of the last chunk written whole
        # each chunk written: where it starts, its last message's time, its messages per channel
        self._written: list[tuple[int, int, dict[int, int]]] = []
        self.note: dict[str, str] = {}  # written as a metadata record `scenario` by `finish`
        if guard is not None:
            guard.send(("header", self._good))

    def _write(self, data: bytes | bytearray) -> None:
        view = memoryview(data)
        while view:
            n = self._stream.write(view)  # an unbuffered file may take part of it (a disk filling up)
            if n is None or n >= len(view):
                break
            if n == 0:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            view = view[n:]
        self._pos += len(data)

    def cut_back(self) -> None:
        """After a failed write (a full disk): drop what was written of the chunk that failed, so the file
        ends with whole chunks and `finish` can add its summary in the space that freed."""
        good = self._good
        fd = self._stream.fileno()
        os.ftruncate(fd, good)
        os.lseek(fd, good, os.SEEK_SET)
        self._pos = good
        self.chunk.clear()
        for ch in self._by_id.values():
            del ch.index[:]

    def register_schema(self, name: str, encoding: str, data: bytes) -> int:
        schema = Schema(id=len(self._tail.schemas) + 1, data=data, encoding=encoding, name=name)
        record = _record_bytes(schema)
        self._tail.schemas.append(record)
        self.chunk += record
        if self.guard is not None:
            self.guard.send(("schema", record))
        return schema.id

    def register_channel(
        self, topic: str, message_encoding: str, schema_id: int, stats: TopicStats
    ) -> _Channel:
        channel = Channel(
            id=len(self._tail.channels) + 1,
            topic=topic,
            message_encoding=message_encoding,
            schema_id=schema_id,
            metadata={},
        )
        record = _record_bytes(channel)
        self._tail.channels.append(record)
        self.chunk += record
        if self.guard is not None:
            self.guard.send(("channel", record))
        ch = self._by_id[channel.id] = _Channel(channel.id, stats)
        return ch

    def add_message(self, ch: _Channel, sequence: int, stamp: int, data: bytes) -> None:
        chunk = self.chunk
        offset = len(chunk)
        # packed first: a stamp that does not fit (negative) raises before anything changed
        chunk += _MESSAGE_HEAD.pack(_OP_MESSAGE, _MESSAGE_FIXED + len(data), ch.id, sequence, stamp, stamp)
        chunk += data
        ch.index.append(stamp)
        ch.index.append(offset)
        if len(chunk) >= self.chunk_size:
            self.flush_chunk()

    def flush_chunk(self) -> None:
        """Compress the chunk being built and write it, then its message indexes."""
        indexed = [ch for ch in self._by_id.values() if ch.index]
        if not indexed:
            # Schemas and channels but no message yet: they stay for the next chunk (as `mcap.Writer` does,
            # a chunk without messages is never written; the summary repeats them anyway).
            return
        start = min(min(ch.index[0::2]) for ch in indexed)
        end = max(max(ch.index[0::2]) for ch in indexed)
        indexes = []
        for ch in indexed:
            entries = ch.index
            if sys.byteorder != "little":
                entries.byteswap()
            indexes.append((ch.id, entries.tobytes()))
            del entries[:]
        self._write_chunk(self.chunk, start, end, indexes)
        self.chunk.clear()

    def _write_chunk(self, chunk: bytearray, start: int, end: int, indexes: list[tuple[int, bytes]]) -> None:
        compressed = self._zstd.compress(chunk)
        chunk_start = self._pos
        out = bytearray(
            _CHUNK_HEAD.pack(
                int(Opcode.CHUNK),
                _CHUNK_HEAD.size - 9 + len(compressed),
                start,
                end,
                len(chunk),
                zlib.crc32(chunk),
                len(_ZSTD),
                _ZSTD,
                len(compressed),
            )
        )
        out += compressed
        chunk_length = len(out)
        offsets: dict[int, int] = {}
        for channel_id, data in indexes:
            offsets[channel_id] = chunk_start + len(out)
            out += _MESSAGE_INDEX_HEAD.pack(int(Opcode.MESSAGE_INDEX), 6 + len(data), channel_id, len(data))
            out += data
        counts = {cid: len(data) // 16 for cid, data in indexes}  # (stamp, offset) pairs
        index = ChunkIndex(
            message_start_time=start,
            message_end_time=end,
            chunk_start_offset=chunk_start,
            chunk_length=chunk_length,
            message_index_offsets=offsets,
            message_index_length=len(out) - chunk_length,
            compression=_ZSTD.decode(),
            compressed_size=len(compressed),
            uncompressed_size=len(chunk),
        )
        # One write, over the previous trailer: the chunk, its indexes and a new trailer. Handed to the OS
        # with every chunk, so a runner killed outright (kill -9) leaves a file that any MCAP reader reads
        # up to its last chunk, which the guard then completes with its summary.
        self._write_trailed(out)
        index_record = _record_bytes(index)
        self._written.append((chunk_start, end, counts))
        tail = self._tail
        tail.chunk_indexes.append(index_record)
        for cid, n in counts.items():
            tail.counts[cid] = tail.counts.get(cid, 0) + n
        tail.start_ns = start if tail.start_ns is None else min(tail.start_ns, start)
        tail.end_ns = max(tail.end_ns, end)
        self._good = self._pos
        self.flushed_at = time.monotonic()
        if self.guard is not None:
            self.guard.send(("chunk", index_record, counts, start, end, self._good))

    def _write_trailed(self, data: bytearray) -> None:
        """Write `data` followed by `TRAILER` (an MCAP end without a summary; appended to `data` in place),
        the file position staying at the end of `data`: until the next write the file is complete, only
        without an index."""
        data += TRAILER
        self._write(data)
        self._stream.seek(-len(TRAILER), os.SEEK_CUR)
        self._pos -= len(TRAILER)

    def finish_in_room(self) -> int:
        """`finish`, after a failed write: where the summary does not fit in what cutting back freed (a
        full disk, a size limit), the last chunks are given up one by one until it does. Returns how many
        chunks were given up."""
        given_up = 0
        while True:
            try:
                self.finish()
                return given_up
            except OSError:
                if not self._written:
                    raise
            start, _end, counts = self._written.pop()
            tail = self._tail
            tail.chunk_indexes.pop()
            for cid, n in counts.items():
                self._by_id[cid].stats.count -= n
                tail.counts[cid] -= n
            self._good = start
            self.cut_back()
            tail.end_ns = max((end for _, end, _ in self._written), default=0)
            given_up += 1

    def finish(self) -> None:
        """Write the last chunk, the summary and the footer. Does not close the stream."""
        self.flush_chunk()
        for ch in self._by_id.values():  # channels registered in a chunk never written: 0 messages
            self._tail.counts.setdefault(ch.id, 0)
        self._write(self._tail.end(self._pos, self.note))
        self._stream.truncate()  # (the summary always covers the trailer it replaces: only to be sure)
        self._stream.flush()


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

    def __post_init__(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.asked = self.path  # the path the plan gave; `path` is the one recorded to (see `_claim`)
        self.path, self._claim_fd = _claim(self.path)
        # unbuffered: whole chunks are written at once, and a failed write (a full disk) leaves no buffer
        # behind that a later flush would write past the point the file is cut back to
        self._file: IO[bytes] = open(self.path, "wb", buffering=0)  # noqa: SIM115 - closed in close()
        self._guard = Guard(self.path, self._claim_fd) if self.guarded else None
        self._mcap = _McapFile(
            self._file,
            profile="ros2",
            library=self.library,
            chunk_size=self.chunk_size,
            guard=self._guard,
        )
        self._lock = threading.Lock()
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, _Channel] = {}
        self._skipped: dict[str, bool] = {}
        self._inc = [zenoh.KeyExpr(e) for e in self.include]
        self._exc = [zenoh.KeyExpr(e) for e in self.exclude]
        self.latest_ns = 0
        self.unknown: dict[str, int] = {}  # keys whose samples had no ROS type in their encoding
        self.closed = False
        self.error: OSError | None = None  # what stopped the drain thread's recording, if anything
        self.rejected = 0  # samples the drain thread could not record (an exception each)
        self.mistyped: dict[str, dict[str, int]] = {}  # key -> why -> samples of another type, not recorded
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
                self.error = e
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
        ch = self._channels.get(key)
        if self.types and key in self.types:
            given = type_from_encoding(sample.encoding)
            if given is not None and given != self.types[key] and not given.startswith("foxglove."):
                # another type on a typed key (a stray publisher): never on that key's channel
                self._mistyped(key, f"{given}, not {self.types[key]}")
                return
            if key in self.inbound:  # what others send the worlds: it must decode, or it is not recorded
                try:
                    msgs.decode(sample.payload.to_bytes(), self.types[key])
                except Exception:
                    self._mistyped(key, f"payloads that do not decode as {self.types[key]}")
                    return
        if ch is not None and att is not None:
            raw = att.to_bytes()
            if len(raw) == _ATT_SIZE:
                seq, stamp = _unpack_att(raw)
                if stamp > self.latest_ns:
                    self.latest_ns = stamp
                self._add(ch, seq, stamp, sample.payload.to_bytes())
                return
        # first sample of a key, a key not recorded, or no attachment
        parsed = unpack_attachment(att.to_bytes()) if att is not None else None
        if ch is None and not self.wanted(key):
            if parsed is not None:
                self.latest_ns = max(self.latest_ns, parsed[1])
            return
        self._write(key, type_from_encoding(sample.encoding), sample.payload.to_bytes(), parsed)

    def _mistyped(self, key: str, why: str) -> None:
        counts = self.mistyped.setdefault(key, {})
        if why not in counts:
            print(f"recorder: not recording messages on {key}: {why}", file=sys.stderr, flush=True)
        counts[why] = counts.get(why, 0) + 1

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

    def _add(self, ch: _Channel, seq: int | None, stamp: int, payload: bytes) -> None:
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

    def _register(self, key: str, type_name: str) -> _Channel:
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
                    self.error = e
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
                    self.path.with_name(f".{self.path.name}.lock").unlink()
                    os.close(self._claim_fd)


def foxglove_schema(type_name: str) -> Any:
    """The protobuf schema (name, encoding, FileDescriptorSet) of a Foxglove message, from foxglove-sdk."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import foxglove.messages

    cls = getattr(foxglove.messages, type_name.removeprefix("foxglove."))
    return cls.get_schema()


def read_summary(path: Path) -> dict[str, Any]:
    """Topics, types, counts and sim-time span of an MCAP file (for `scenario info`). A file without its
    summary (the recording was cut: its runner was killed) is read record by record up to its last
    complete chunk; then `cut` is True and `readable_bytes` says how far it reaches."""
    from mcap.exceptions import McapError
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        try:
            summary = make_reader(f).get_summary()
        except (McapError, struct.error, ValueError, EOFError):
            summary = None
        if summary is None or summary.statistics is None:
            return _scan(path)
        stats = summary.statistics
        topics = []
        for cid, ch in sorted(summary.channels.items(), key=lambda kv: kv[1].topic):
            schema = summary.schemas.get(ch.schema_id)
            topics.append(
                {
                    "topic": ch.topic,
                    "type": schema.name if schema else "",
                    "count": stats.channel_message_counts.get(cid, 0),
                }
            )
        note: dict[str, str] = {}
        for index in summary.metadata_indexes if hasattr(summary, "metadata_indexes") else []:
            if index.name == "scenario":
                with contextlib.suppress(McapError, struct.error, ValueError, EOFError):
                    meta = next((m for m in make_reader(f).iter_metadata() if m.name == "scenario"), None)
                    note = dict(meta.metadata) if meta is not None else {}
        stopped = note if "stopped" in note else None
        return {
            "start_ns": stats.message_start_time,
            "end_ns": stats.message_end_time,
            "messages": stats.message_count,
            "topics": topics,
            "cut": False,
            "stopped": stopped,  # why the recording ended early, when it says so (a full disk)
            "ended": note.get("ended"),  # how the run ended: completed, interrupted, terminated...
        }


def _records(path: Path) -> Iterable[Any]:
    """The records of an MCAP file in order (chunks opened), up to the first incomplete one."""
    from mcap.exceptions import McapError
    from mcap.stream_reader import StreamReader

    with open(path, "rb") as f:
        try:
            yield from StreamReader(f, validate_crcs=True).records
        except (McapError, struct.error, ValueError, EOFError, zstandard.ZstdError):
            return  # cut there


def _scan(path: Path) -> dict[str, Any]:
    from mcap.records import Message

    schemas: dict[int, str] = {}
    channels: dict[int, tuple[str, str]] = {}
    counts: dict[int, int] = {}
    start, end = None, 0
    for record in _records(path):
        if isinstance(record, Schema):
            schemas[record.id] = record.name
        elif isinstance(record, Channel):
            channels[record.id] = (record.topic, schemas.get(record.schema_id, ""))
        elif isinstance(record, Message):
            counts[record.channel_id] = counts.get(record.channel_id, 0) + 1
            start = record.log_time if start is None else min(start, record.log_time)
            end = max(end, record.log_time)
    topics = [
        {"topic": topic, "type": type_name, "count": counts.get(cid, 0)}
        for cid, (topic, type_name) in sorted(channels.items(), key=lambda kv: kv[1][0])
    ]
    return {
        "start_ns": start or 0,
        "end_ns": end,
        "messages": sum(counts.values()),
        "topics": topics,
        "cut": True,
    }


def recover(path: Path, out: Path) -> dict[str, Any]:
    """Write `out`: a complete MCAP (summary, indexes) with every message the cut file `path` holds."""
    from mcap.records import Message
    from mcap.writer import CompressionType, Writer

    schema_ids: dict[int, int] = {}
    channel_ids: dict[int, int] = {}
    with open(out, "wb") as f:
        writer = Writer(f, compression=CompressionType.ZSTD)
        writer.start(profile="ros2", library="scenario-runner (recovered)")
        for record in _records(path):
            if isinstance(record, Schema) and record.id not in schema_ids:
                schema_ids[record.id] = writer.register_schema(record.name, record.encoding, record.data)
            elif isinstance(record, Channel) and record.id not in channel_ids:
                channel_ids[record.id] = writer.register_channel(
                    record.topic,
                    record.message_encoding,
                    schema_ids.get(record.schema_id, 0),
                    dict(record.metadata),
                )
            elif isinstance(record, Message) and record.channel_id in channel_ids:
                writer.add_message(
                    channel_ids[record.channel_id],
                    record.log_time,
                    record.data,
                    record.publish_time,
                    record.sequence,
                )
        writer.finish()
    return read_summary(out)


def recording_live(path: Path) -> bool:
    """Whether a live run (or its guard) holds the claim on the recording `path` (see `_claim`)."""
    import fcntl

    try:
        fd = os.open(path.with_name(f".{path.name}.lock"), os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError:
        return True
    finally:
        os.close(fd)
    return False


def _claim(path: Path) -> tuple[Path, int]:
    """The recording path this run may write, and the descriptor that holds it: a lock on a hidden
    `.<name>.lock` beside it (released when the process ends, however it ends). A path another live run
    is recording to is not touched: the next free `<stem>-2.mcap`, `-3`... is taken instead."""
    import fcntl

    for n in range(1, 1000):
        candidate = path if n == 1 else path.with_name(f"{path.stem}-{n}{path.suffix}")
        lock = candidate.with_name(f".{candidate.name}.lock")
        fd = os.open(lock, os.O_WRONLY | os.O_CREAT, 0o600)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        return candidate, fd
    raise OSError(f"a thousand runs are recording beside {path}")
