"""Recorder: subscribes to the run's key space and writes MCAP (ros2msg schemas, CDR payloads).

- `log_time` and `publish_time` are the sim time from the sample's attachment (integer ns);
  a sample without one (a foreign publisher) gets the latest sim time seen.
- Channels and schemas are registered lazily, on a topic's first message.
- Sequence numbers are checked per topic, so a lost message is counted, not guessed.
- The file is written in chunks and finished on every exit path (`close()` in a `finally`), so it is
  readable after a normal end, an error or Ctrl-C.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import zenoh
from mcap.writer import CompressionType, Writer

from runner import msgs
from runner.transport import type_from_encoding, unpack_attachment


@dataclass
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


@dataclass
class _Channel:
    id: int
    stats: TopicStats


@dataclass
class Recorder:
    path: Path
    include: list[str]
    exclude: list[str] = field(default_factory=list)
    library: str = "scenario-runner"

    def __post_init__(self) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: IO[bytes] = open(self.path, "wb")  # noqa: SIM115 - closed in close()
        self._writer = Writer(self._file, chunk_size=256 * 1024, compression=CompressionType.ZSTD)
        self._writer.start(profile="ros2", library=self.library)
        self._lock = threading.Lock()
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, _Channel] = {}
        self._skipped: dict[str, bool] = {}
        self._inc = [zenoh.KeyExpr(e) for e in self.include]
        self._exc = [zenoh.KeyExpr(e) for e in self.exclude]
        self.latest_ns = 0
        self.unknown: dict[str, int] = {}  # keys whose samples had no ROS type in their encoding
        self.closed = False

    # ------------------------------------------------------------------------------------------- input
    def wanted(self, key: str) -> bool:
        skip = self._skipped.get(key)
        if skip is None:
            ke = zenoh.KeyExpr(key)
            ok = any(e.intersects(ke) for e in self._inc) and not any(e.intersects(ke) for e in self._exc)
            skip = self._skipped[key] = not ok
        return not skip

    def on_sample(self, sample: zenoh.Sample) -> None:
        if sample.kind != zenoh.SampleKind.PUT:
            return
        key = str(sample.key_expr)
        att = sample.attachment
        self.write(
            key,
            type_from_encoding(sample.encoding),
            sample.payload.to_bytes(),
            unpack_attachment(att.to_bytes()) if att is not None else None,
        )

    def write(self, key: str, type_name: str | None, payload: bytes, att: tuple[int, int] | None) -> None:
        with self._lock:
            if self.closed:
                return
            if att is not None:
                seq, stamp = att
                self.latest_ns = max(self.latest_ns, stamp)
            else:
                seq, stamp = None, self.latest_ns
            if not self.wanted(key):
                return
            ch = self._channels.get(key)
            if ch is None:
                if type_name is None or not msgs.is_known(type_name):
                    self.unknown[key] = self.unknown.get(key, 0) + 1
                    return
                ch = self._register(key, msgs.normalize_type(type_name))
            st = ch.stats
            if seq is not None:
                if st.next_seq is not None and seq > st.next_seq:
                    st.lost += seq - st.next_seq
                st.next_seq = seq + 1
            st.count += 1
            if st.first_ns is None:
                st.first_ns = stamp
            st.last_ns = stamp
            self._writer.add_message(
                channel_id=ch.id,
                log_time=stamp,
                publish_time=stamp,
                data=payload,
                sequence=(seq if seq is not None else st.count - 1) & 0xFFFFFFFF,
            )

    def _register(self, key: str, type_name: str) -> _Channel:
        schema_id = self._schemas.get(type_name)
        if schema_id is None:
            schema_id = self._writer.register_schema(
                name=type_name, encoding="ros2msg", data=msgs.msgdef(type_name).encode()
            )
            self._schemas[type_name] = schema_id
        channel_id = self._writer.register_channel(topic=key, message_encoding="cdr", schema_id=schema_id)
        ch = _Channel(channel_id, TopicStats(key, type_name))
        self._channels[key] = ch
        return ch

    # ------------------------------------------------------------------------------------------ output
    def stats(self) -> list[TopicStats]:
        with self._lock:
            return sorted((c.stats for c in self._channels.values()), key=lambda s: s.key)

    def counts(self) -> dict[str, int]:
        with self._lock:
            return {k: c.stats.count for k, c in self._channels.items()}

    def close(self) -> None:
        with self._lock:
            if self.closed:
                return
            self.closed = True
            try:
                self._writer.finish()
            finally:
                self._file.close()


def read_summary(path: Path) -> dict[str, Any]:
    """Topics, types, counts and sim-time span of an MCAP file (for `scenario info`)."""
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        if summary is None or summary.statistics is None:
            raise ValueError("the file has no summary (was the recording cut?)")
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
        return {
            "start_ns": stats.message_start_time,
            "end_ns": stats.message_end_time,
            "messages": stats.message_count,
            "topics": topics,
        }
