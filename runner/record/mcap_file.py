"""The MCAP file a recording writes: chunked, indexed, with its summary (`McapFile`), and the per-topic
counts kept as it goes (`TopicStats`).

The per-message work is two appends to the chunk being built and two to its channel's index; only the
records written once per chunk or per file (chunk, indexes, summary) go through the `mcap` package's
record classes. Each chunk is handed to the OS as it is written, followed by a trailer, so that the file
reads up to its last chunk whatever happens to the process (see `runner.record.finisher`).
"""

from __future__ import annotations

import errno
import os
import struct
import sys
import time
import zlib
from array import array
from dataclasses import dataclass
from typing import IO

import zstandard
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import Channel, ChunkIndex, Header, McapRecord, Schema

from runner.record.finisher import MAGIC, TRAILER, Guard, Tail

CHUNK_SIZE = 256 * 1024  # uncompressed bytes per chunk
ZSTD_LEVEL = 1  # vs the default 3: 10-30% faster here, for the same ratio on sensor data (bench/recorder.py)

# Message record: opcode, record length, channel id, sequence, log time, publish time (then the data).
_MESSAGE_HEAD = struct.Struct("<BQHIQQ")
_MESSAGE_FIXED = _MESSAGE_HEAD.size - 9  # the record's length minus the data's
_MESSAGE_INDEX_HEAD = struct.Struct("<BQHI")
# Chunk record up to its data: opcode, record length, start, end, uncompressed size and crc, compression
# (a string: "zstd", or "" for none), compressed size.
_CHUNK_HEADS = {
    "zstd": struct.Struct("<BQQQQII4sQ"),
    "": struct.Struct("<BQQQQII0sQ"),
}
COMPRESSIONS = {"zstd": "zstd", "none": ""}  # the scenario's `record.compression` -> the MCAP's name
_OP_MESSAGE = int(Opcode.MESSAGE)
_OP_MESSAGE_INDEX = int(Opcode.MESSAGE_INDEX)


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


class RecordedChannel:
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


class McapFile:
    """A chunked, indexed MCAP writer (the layout of `mcap.writer.Writer` with its defaults: zstd chunks,
    message indexes, chunk indexes, statistics, repeated schemas and channels, summary offsets, summary
    CRC), whose per-message work is two appends to the chunk and two to the channel's index. With
    `compression="none"` the chunks are stored as they are (the MCAP's empty compression name).

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
        compression: str = "zstd",
    ):
        self._stream = stream
        self.chunk_size = chunk_size
        self.chunk = bytearray()  # the uncompressed records of the chunk being built
        if compression not in COMPRESSIONS:
            raise ValueError(f"compression is one of {', '.join(COMPRESSIONS)}, not {compression!r}")
        self.compression = COMPRESSIONS[compression]
        self._head = _CHUNK_HEADS[self.compression]
        self._zstd = zstandard.ZstdCompressor(level=ZSTD_LEVEL)
        self._tail = Tail()  # the summary's records, as chunks are written
        self._by_id: dict[int, RecordedChannel] = {}
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
    ) -> RecordedChannel:
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
        ch = self._by_id[channel.id] = RecordedChannel(channel.id, stats)
        return ch

    def add_message(self, ch: RecordedChannel, sequence: int, stamp: int, data: bytes) -> None:
        if len(data) >= self.chunk_size:
            self._add_large(ch, sequence, stamp, data)
            return
        chunk = self.chunk
        offset = len(chunk)
        # packed first: a stamp that does not fit (negative) raises before anything changed
        chunk += _MESSAGE_HEAD.pack(_OP_MESSAGE, _MESSAGE_FIXED + len(data), ch.id, sequence, stamp, stamp)
        chunk += data
        ch.index.append(stamp)
        ch.index.append(offset)
        if len(chunk) >= self.chunk_size:
            self.flush_chunk()

    def _add_large(self, ch: RecordedChannel, sequence: int, stamp: int, data: bytes) -> None:
        """A message as large as a chunk (a camera frame) is a chunk of its own, after the one being built,
        compressed and written from `data` itself: never copied into the chunk buffer."""
        head = _MESSAGE_HEAD.pack(_OP_MESSAGE, _MESSAGE_FIXED + len(data), ch.id, sequence, stamp, stamp)
        self.flush_chunk()
        if self.chunk:
            # schemas and channels registered since the last chunk (no message of theirs yet) go first
            head = bytes(self.chunk) + head
            self.chunk.clear()
        offset = len(head) - _MESSAGE_HEAD.size
        index = array("Q", [stamp, offset])
        if sys.byteorder != "little":
            index.byteswap()
        self._write_chunk([head, data], stamp, stamp, [(ch.id, index.tobytes())])

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
        self._write_chunk([self.chunk], start, end, indexes)
        self.chunk.clear()

    def _write_chunk(
        self, parts: list[bytes | bytearray], start: int, end: int, indexes: list[tuple[int, bytes]]
    ) -> None:
        """Write a chunk whose records are `parts` (in order; compressed as one), then its indexes."""
        size = sum(len(part) for part in parts)
        crc = 0  # of the uncompressed records
        for part in parts:
            crc = zlib.crc32(part, crc)
        if not self.compression:  # written as they are
            compressed = list(parts)
        elif len(parts) == 1:
            compressed = [self._zstd.compress(parts[0])]
        else:
            stream = self._zstd.compressobj(size=size)
            compressed = [stream.compress(part) for part in parts]
            compressed.append(stream.flush())
        compressed_size = sum(len(c) for c in compressed)
        chunk_start = self._pos
        name = self.compression.encode()
        head = self._head.pack(
            int(Opcode.CHUNK),
            self._head.size - 9 + compressed_size,
            start,
            end,
            size,
            crc,
            len(name),
            name,
            compressed_size,
        )
        chunk_length = len(head) + compressed_size
        out = bytearray()
        offsets: dict[int, int] = {}
        for channel_id, data in indexes:
            offsets[channel_id] = chunk_start + chunk_length + len(out)
            out += _MESSAGE_INDEX_HEAD.pack(int(Opcode.MESSAGE_INDEX), 6 + len(data), channel_id, len(data))
            out += data
        counts = {cid: len(data) // 16 for cid, data in indexes}  # (stamp, offset) pairs
        index = ChunkIndex(
            message_start_time=start,
            message_end_time=end,
            chunk_start_offset=chunk_start,
            chunk_length=chunk_length,
            message_index_offsets=offsets,
            message_index_length=len(out),
            compression=self.compression,
            compressed_size=compressed_size,
            uncompressed_size=size,
        )
        # One write, over the previous trailer: the chunk, its indexes and a new trailer. Handed to the OS
        # with every chunk, so a runner killed outright (kill -9) leaves a file that any MCAP reader reads
        # up to its last chunk, which the guard then completes with its summary. The pieces go to the OS
        # as they are (one gathered write): the compressed data is not copied into one buffer first.
        if len(compressed) == 1 and compressed_size < 4 * 1024 * 1024:
            self._write_trailed(bytearray(head) + compressed[0] + out)
        else:
            self._write_trailed_parts([head, *compressed, out])
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

    def _write_trailed_parts(self, parts: list[bytes | bytearray]) -> None:
        """`_write_trailed` of the concatenation of `parts`, without concatenating them: one gathered write
        (`os.writev`) where the stream has a file descriptor, else one write per part."""
        parts = [*parts, TRAILER]
        total = sum(len(part) for part in parts)
        try:
            fd = self._stream.fileno()
        except (AttributeError, OSError):
            fd = None
        if fd is None:
            for part in parts:
                self._write(part)
        else:
            self._stream.flush()
            views = [memoryview(part) for part in parts if len(part)]
            while views:
                n = os.writev(fd, views)
                if n == 0:
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
                while views and n >= len(views[0]):
                    n -= len(views[0])
                    views.pop(0)
                if n:
                    views[0] = views[0][n:]
            self._pos += total
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
