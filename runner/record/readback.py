"""Reading recordings back: what a recording holds (`read_summary`, for `scenario info` and the report),
also when it was cut (its runner killed: read record by record up to its last whole chunk), and
`recover`, which rewrites a cut recording as a complete one.
"""

from __future__ import annotations

import contextlib
import struct
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import zstandard
from mcap.records import Channel, Schema


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


def read_records(path: Path) -> Iterable[Any]:
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
    for record in read_records(path):
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
        for record in read_records(path):
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
