"""The end of an MCAP recording (summary, footer), and the guard that writes it when the recorder cannot.

A recording is written chunk by chunk; its summary (schemas, channels, statistics, chunk indexes) and
footer come last, and `mcap`'s standard reader (`make_reader(f).iter_messages()`) needs them. A runner
killed outright (kill -9, the OOM killer, a CI job's timeout killing its process group) never writes
them. So the recorder starts a small guard process beside it (`Guard`), in a session of its own, and
tells it, through a pipe, what each chunk it wrote adds to the summary. When that pipe closes without the
recorder having said it finished (its process is gone), the guard cuts the file back to its last whole
chunk and writes the summary and footer itself, with a `scenario` metadata record saying the runner was
killed: the file reads with any MCAP reader, `scenario info` says how it ended. It takes milliseconds.

The guard holds the recording's claim (the lock beside it, see `runner.record.claim`) until the file
is complete, so no other run takes the name meanwhile; and it shares the runner's stdout/stderr, so a
caller that waits for those to close (`subprocess.run`, `communicate`) finds the file complete.

Kept to the standard library: the guard runs this file as a script (`python runner/record/finisher.py`).
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import struct
import subprocess
import sys
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

MAGIC = b"\x89MCAP0\r\n"
# opcodes (MCAP spec)
OP_FOOTER = 0x02
OP_SCHEMA = 0x03
OP_CHANNEL = 0x04
OP_METADATA = 0x0C
OP_CHUNK_INDEX = 0x08
OP_METADATA_INDEX = 0x0D
OP_STATISTICS = 0x0B
OP_SUMMARY_OFFSET = 0x0E
OP_DATA_END = 0x0F
_FRAME = struct.Struct("<I")


def _string(s: str) -> bytes:
    b = s.encode()
    return struct.pack("<I", len(b)) + b


def _record(opcode: int, body: bytes) -> bytes:
    return struct.pack("<BQ", opcode, len(body)) + body


def metadata_record(name: str, values: dict[str, str]) -> bytes:
    pairs = b"".join(_string(k) + _string(v) for k, v in values.items())
    return _record(OP_METADATA, _string(name) + struct.pack("<I", len(pairs)) + pairs)


def data_end_record() -> bytes:
    return _record(OP_DATA_END, struct.pack("<I", 0))


# The end of a file whose summary is still to come: DataEnd, a footer saying "no summary", the magic. MCAP
# readers read such a file from the start (`mcap`'s `make_reader(f).iter_messages()` does).
TRAILER = data_end_record() + struct.pack("<BQQQI", OP_FOOTER, 8 + 8 + 4, 0, 0, 0) + MAGIC


@dataclass
class Tail:
    """What a recording's summary needs, as serialized records (shared by the recorder's own `finish` and
    the guard's): each field grows as chunks are written."""

    schemas: list[bytes] = field(default_factory=list)
    channels: list[bytes] = field(default_factory=list)
    chunk_indexes: list[bytes] = field(default_factory=list)
    counts: dict[int, int] = field(default_factory=dict)  # channel id -> messages in written chunks
    start_ns: int | None = None
    end_ns: int = 0

    def statistics(self, metadata_count: int) -> bytes:
        counts = b"".join(struct.pack("<HQ", cid, n) for cid, n in sorted(self.counts.items()))
        body = struct.pack(
            "<QHIIIIQQ",
            sum(self.counts.values()),
            len(self.schemas),
            len(self.channels),
            0,  # attachments
            metadata_count,
            len(self.chunk_indexes),
            self.start_ns or 0,
            self.end_ns,
        ) + struct.pack("<I", len(counts))
        return _record(OP_STATISTICS, body + counts)

    def end(self, pos: int, note: dict[str, str] | None = None) -> bytes:
        """Everything after the data written so far, which ends at `pos`: the note as a `scenario`
        metadata record, DataEnd, the summary (with its offsets) and the footer."""
        out = bytearray()
        metadata_indexes = []
        if note:
            record = metadata_record("scenario", note)
            metadata_indexes.append(
                _record(OP_METADATA_INDEX, struct.pack("<QQ", pos, len(record)) + _string("scenario"))
            )
            out += record
        out += data_end_record()
        summary_start = pos + len(out)
        summary = bytearray()
        offsets = bytearray()
        for opcode, records in (
            (OP_SCHEMA, self.schemas),
            (OP_CHANNEL, self.channels),
            (OP_STATISTICS, [self.statistics(len(metadata_indexes))]),
            (OP_CHUNK_INDEX, self.chunk_indexes),
            (OP_METADATA_INDEX, metadata_indexes),
        ):
            if not records:
                continue
            begin = len(summary)
            for r in records:
                summary += r
            offsets += _record(
                OP_SUMMARY_OFFSET, struct.pack("<BQQ", opcode, summary_start + begin, len(summary) - begin)
            )
        summary_offset_start = summary_start + len(summary)
        summary += offsets
        footer_head = struct.pack("<BQQQ", OP_FOOTER, 8 + 8 + 4, summary_start, summary_offset_start)
        crc = zlib.crc32(footer_head, zlib.crc32(summary))
        out += summary + footer_head + struct.pack("<I", crc) + MAGIC
        return bytes(out)


# ------------------------------------------------------------------------------------------ the guard
class Guard:
    """The recorder's side: starts the guard and reports each chunk to it. Reporting costs one small
    pipe write per chunk (256 kB of messages). A guard that died is noticed and left alone."""

    def __init__(self, path: Path, claim_fd: int):
        read, self._write = os.pipe()
        self.proc: subprocess.Popen[bytes] | None = None
        try:
            self.proc = subprocess.Popen(
                # this file as a script: none of the package's imports (runner/__init__ sets up OpenGL)
                [sys.executable, __file__, str(path), str(read), str(claim_fd)],
                stdin=subprocess.DEVNULL,
                pass_fds=(read, claim_fd),
                start_new_session=True,  # a signal to the runner's process group does not reach it
            )
        except OSError as e:  # no process to spare: recording goes on, unguarded
            print(f"recorder: no guard for {path} ({e.strerror or e})", file=sys.stderr, flush=True)
            os.close(self._write)
        finally:
            os.close(read)

    def send(self, item: Any) -> None:
        if self.proc is None:
            return
        data = pickle.dumps(item, protocol=pickle.HIGHEST_PROTOCOL)
        frame = memoryview(_FRAME.pack(len(data)) + data)
        try:
            while frame:  # (a large schema may take more than one write)
                frame = frame[os.write(self._write, frame) :]
        except OSError:  # the guard is gone: recording goes on, unguarded
            self._drop()

    def done(self) -> None:
        """The recorder finished the file itself: the guard ends without touching it."""
        self.send(("done",))
        self._drop()

    def _drop(self) -> None:
        proc, self.proc = self.proc, None
        with contextlib.suppress(OSError):
            os.close(self._write)
        if proc is not None:
            try:
                proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


def _frames(fd: int) -> Any:
    buf = bytearray()
    while True:
        chunk = os.read(fd, 65536)
        if not chunk:
            return
        buf += chunk
        while len(buf) >= 4:
            (n,) = _FRAME.unpack_from(buf)
            if len(buf) < 4 + n:
                break
            yield pickle.loads(bytes(buf[4 : 4 + n]))
            del buf[: 4 + n]


def guard(path: Path, fd: int) -> bool:
    """Follow the recorder's reports on `fd` until it closes; finish `path` if the recorder did not.
    Returns whether it had to."""
    tail = Tail()
    good = 0  # where the file's last whole chunk ends (0: not known yet)
    for item in _frames(fd):
        kind = item[0]
        if kind == "done":
            return False
        if kind == "header":
            good = max(good, item[1])
        elif kind == "schema":
            tail.schemas.append(item[1])
        elif kind == "channel":
            tail.channels.append(item[1])
        elif kind == "chunk":
            _, index, counts, start, end, good = item
            tail.chunk_indexes.append(index)
            for cid, n in counts.items():
                tail.counts[cid] = tail.counts.get(cid, 0) + n
            tail.start_ns = start if tail.start_ns is None else min(tail.start_ns, start)
            tail.end_ns = max(tail.end_ns, end)
    if good == 0:
        return False  # the file's header was never reported written: nothing to finish
    note = {
        "stopped": "its runner ended without finishing the recording (killed)",
        "finished_by": "the recording's guard, at its last whole chunk",
    }
    end = tail.end(good, note)
    fd = os.open(path, os.O_WRONLY)
    try:
        # written over the trailer (and whatever was written of a chunk cut short), then cut: until the
        # moment it is complete, the file stays readable as it was
        written = 0
        while written < len(end):
            written += os.pwrite(fd, end[written:], good + written)
        os.ftruncate(fd, good + len(end))
    finally:
        os.close(fd)
    with contextlib.suppress(OSError):  # the runner is gone: the path is free for the next run
        path.with_name(f".{path.name}.lock").unlink()
    return True


def main(argv: list[str]) -> int:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # it ends when the recorder does, however it does
    path, fd, claim = Path(argv[0]), int(argv[1]), int(argv[2])
    status = 0
    try:
        if guard(path, fd):
            print(f"recorder guard: its runner ended without finishing {path}; finished it", file=sys.stderr)
    except OSError as e:  # a full disk, the file removed: nothing more to do
        print(f"recorder guard: {path} could not be finished: {e.strerror or e}", file=sys.stderr)
        status = 1
    # the claim is given up last (the runner, when it finished the file itself, removes the lock file)
    os.close(claim)
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
