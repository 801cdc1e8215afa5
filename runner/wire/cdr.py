"""Fixed-layout CDR encoding: the hot path of every sensor publisher.

A sensor publishes the same message shape again and again: the frame id, the joint names, the number of
ranges and the covariances never change; only the stamp and a few numbers do. `Layout` serializes a
template message once with rosbags (so the constant bytes are rosbags' bytes), walks the type's definition
with the CDR alignment rules to find where each field lies, and then writes only the changing fields
into that buffer in place, through numpy views. The result is byte-identical to encoding the filled
message with rosbags (tests/test_cdr.py checks that on every layout the built-in plugins use), at a
fraction of the cost: no message objects, no per-call type lookups.

    layout = Layout("sensor_msgs/msg/Imu", template, ["header.stamp", "orientation", "angular_velocity"])
    payload = layout.encode(stamp_ns, quat_xyzw, gyro_xyz)      # bytes, ready for the wire

Field paths are dotted, with `[i]` for elements of arrays and sequences (`transforms[0].transform`).
A field that is a `builtin_interfaces/msg/Time` takes integer nanoseconds; a field whose leaves are all
one numeric type laid out back to back (a `Vector3`, a `Pose`, a `float32[]` of fixed length) takes a
sequence or numpy array of that many numbers; a numeric scalar takes a number.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from rosbags.typesys.base import Nodetype

from runner.wire import msgs

_SIZE = {
    "bool": 1,
    "byte": 1,
    "char": 1,
    "int8": 1,
    "uint8": 1,
    "int16": 2,
    "uint16": 2,
    "int32": 4,
    "uint32": 4,
    "int64": 8,
    "uint64": 8,
    "float32": 4,
    "float64": 8,
}
_DTYPE = {k: np.dtype(v).newbyteorder("<") for k, v in msgs._NUMPY.items()}
_TIME = struct.Struct("<iI")
_HEADER = 4  # the CDR encapsulation header; alignment counts from after it


@dataclass(frozen=True)
class Span:
    """Where a field's bytes lie: `count` values of numeric `kind` from `offset` (None: not numeric or
    not contiguous, e.g. a message with a string inside)."""

    offset: int
    kind: str | None
    count: int
    time: bool = False


class LayoutError(ValueError):
    pass


class Layout:
    """A message of fixed shape, encoded by writing only its changing fields (see the module doc)."""

    def __init__(self, type_name: str, template: Any, fields: Sequence[str]):
        self.type = msgs.normalize_type(type_name)
        self.buf = bytearray(msgs.encode(template, self.type))
        self.spans: dict[str, Span] = {}
        end = self._walk_message(self.type, template, "", _HEADER)
        if end != len(self.buf):
            raise LayoutError(f"{self.type}: layout walk ended at byte {end}, rosbags wrote {len(self.buf)}")
        self.fields = tuple(fields)
        self._writers: list[Callable[[Any], None]] = [self._writer(f) for f in self.fields]
        if len(self.fields) == 1 and self.spans[self.fields[0]].time:
            self.encode = self._make_stamp_only(self.spans[self.fields[0]].offset)  # type: ignore[method-assign]

    # ------------------------------------------------------------------------------------------ use
    def encode(self, *values: Any) -> bytes:
        """The message's bytes with `values` written into `fields` (in order)."""
        for write, value in zip(self._writers, values, strict=True):
            write(value)
        return bytes(self.buf)

    def fill(self, *values: Any) -> bytearray:
        """`encode` without the copy: `values` written into `fields`, and the buffer itself returned. It is
        borrowed: the next `fill`/`encode` (or a write through a `view`) changes it. For large messages
        (camera frames) whose publisher hands the bytes on at once (`Publisher.publish_cdr` copies a
        `bytearray` where it keeps one)."""
        for write, value in zip(self._writers, values, strict=True):
            write(value)
        return self.buf

    def _make_stamp_only(self, off: int) -> Callable[[int], bytes]:
        """The common case (a stamp; the numbers written through views): one pack and one copy."""
        buf, pack = self.buf, _TIME.pack_into

        def encode(ns: int) -> bytes:
            pack(buf, off, ns // 1_000_000_000, ns % 1_000_000_000)
            return bytes(buf)

        return encode

    def view(self, field: str) -> np.ndarray:
        """A writable numpy view of a numeric field inside the buffer (fill it, then call `encode()`)."""
        span = self._span(field)
        if span.kind is None or span.time:
            raise LayoutError(f"{self.type}.{field} is not a run of numbers")
        return np.frombuffer(self.buf, dtype=_DTYPE[span.kind], count=span.count, offset=span.offset)

    # --------------------------------------------------------------------------------------- build
    def _span(self, field: str) -> Span:
        try:
            return self.spans[field]
        except KeyError:
            raise LayoutError(f"{self.type} has no field {field!r}") from None

    def _writer(self, field: str) -> Callable[[Any], None]:
        span = self._span(field)
        buf = self.buf
        if span.time:
            off = span.offset

            def write_time(ns: int) -> None:
                _TIME.pack_into(buf, off, ns // 1_000_000_000, ns % 1_000_000_000)

            return write_time
        view = self.view(field)

        def write(value: Any) -> None:
            view[:] = value

        return write

    def _walk_message(self, type_name: str, value: Any, path: str, pos: int) -> int:
        start = pos
        kinds: set[str | None] = set()
        count = 0
        first = None
        for name, desc in msgs.TYPESTORE.get_msgdef(type_name).fields:
            sub = f"{path}.{name}" if path else name
            pos = self._walk(desc, getattr(value, name), sub, pos)
            span = self.spans[sub]
            kinds.add(span.kind)
            count += span.count
            first = span.offset if first is None else first
        contiguous = len(kinds) == 1 and None not in kinds and first is not None
        if contiguous:
            (kind,) = kinds
            contiguous = pos - first == count * _SIZE[kind]  # type: ignore[index]
        if path:
            is_time = type_name == "builtin_interfaces/msg/Time"
            self.spans[path] = Span(
                first if first is not None else start,
                next(iter(kinds)) if contiguous else None,
                count if contiguous else 0,
                time=is_time,
            )
        return pos

    def _walk(self, desc: tuple[Any, Any], value: Any, path: str, pos: int) -> int:
        node, args = desc
        if node == Nodetype.NAME:
            return self._walk_message(args, value, path, pos)
        if node == Nodetype.BASE:
            kind = args[0]
            if kind in ("string", "wstring"):
                pos = _align(pos, 4)
                self.spans[path] = Span(pos, None, 0)
                return pos + 4 + len(value.encode()) + 1
            pos = _align(pos, _SIZE[kind])
            self.spans[path] = Span(pos, kind, 1)
            return pos + _SIZE[kind]
        if node == Nodetype.ARRAY or node == Nodetype.SEQUENCE:
            subdesc = args[0]
            n = len(value)
            if node == Nodetype.SEQUENCE:
                pos = _align(pos, 4) + 4
            if subdesc[0] == Nodetype.BASE and subdesc[1][0] not in ("string", "wstring"):
                kind = subdesc[1][0]
                if n:
                    pos = _align(pos, _SIZE[kind])
                self.spans[path] = Span(pos, kind, n)
                return pos + n * _SIZE[kind]
            start = pos
            for i, item in enumerate(value):
                pos = self._walk(subdesc, item, f"{path}[{i}]", pos)
            self.spans[path] = Span(start, None, 0)
            return pos
        raise LayoutError(f"unsupported field {path} ({node})")


def _align(pos: int, size: int) -> int:
    rel = pos - _HEADER
    return _HEADER + ((rel + size - 1) // size) * size
