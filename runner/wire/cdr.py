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


def string_message(text: str) -> bytes:
    """A `std_msgs/msg/String`'s bytes, as rosbags encodes them (the events' record, one per firing)."""
    data = text.encode()
    return b"\x00\x01\x00\x00" + _U32_PACK(len(data) + 1) + data + b"\x00"


# ------------------------------------------------------------------------------------------------ Peek
_UNPACK = {k: struct.Struct("<" + c).unpack_from for k, c in {
    "bool": "?", "byte": "B", "char": "B", "int8": "b", "uint8": "B", "int16": "h", "uint16": "H",
    "int32": "i", "uint32": "I", "int64": "q", "uint64": "Q", "float32": "f", "float64": "d",
}.items()}  # fmt: skip
_U32 = struct.Struct("<I").unpack_from
_U32_PACK = struct.Struct("<I").pack

# One step of a Peek: `op(raw, pos, values) -> pos`, `raw` the bytes after the encapsulation header (CDR
# aligns from there), `values` the fields read so far
_Op = Callable[[memoryview, int, dict[str, Any]], int]


class Peek:
    """Some top-level fields of a message read straight from its CDR bytes, the rest skipped: what a
    `message` trigger needs of every message of a sensor topic (`linear_acceleration`, `ranges`), at a
    fraction of decoding it all. `peek(payload)` gives a message of the type's own class with only those
    fields set, each exactly as `msgs.decode` gives it (the same class, a Python number, a numpy array of
    the same dtype over the bytes). Only for bytes encoded by this process (it checks no lengths): a
    payload from elsewhere is decoded with `msgs.decode`, which refuses what does not fit.

    A field the type does not have makes `peek` the full `msgs.decode` (`Peek.full` is True): what the
    expression then says of it is what it says of a decoded message."""

    def __init__(self, type_name: str, fields: Sequence[str]):
        self.type = msgs.normalize_type(type_name)
        msgdef = msgs.TYPESTORE.get_msgdef(self.type)
        self.cls = msgdef.cls
        names = [n for n, _ in msgdef.fields]
        wanted = [f for f in fields if f in names]
        self.full = len(wanted) != len(set(fields)) or not wanted
        if not self.full:
            last = max(names.index(f) for f in wanted)
            self._ops = _merge(
                [
                    op
                    for name, desc in msgdef.fields[: last + 1]
                    for op in (_read(name, desc) if name in wanted else _skip(desc))
                ]
            )
        if self.full:
            self.peek = self._decode  # type: ignore[method-assign]

    def _decode(self, payload: bytes | memoryview) -> Any:
        return msgs.decode(payload, self.type)

    def peek(self, payload: bytes | memoryview) -> Any:
        raw = memoryview(payload)[_HEADER:]
        values: dict[str, Any] = {}
        pos = 0
        for op in self._ops:
            pos = op(raw, pos, values)
        msg = self.cls.__new__(self.cls)
        msg.__dict__.update(values)
        return msg


# A run of fields of fixed size is one step: where it ends depends only on where it starts modulo 8 (no
# alignment is over 8), so it is a table of 8 distances. (align, size) pairs until merged.
_Fixed = tuple[int, int]


def _first_align(desc: tuple[Any, Any]) -> int:
    node, args = desc
    if node == Nodetype.BASE:
        return 4 if args[0] in ("string", "wstring") else _SIZE[args[0]]
    if node == Nodetype.NAME:
        return _first_align(msgs.TYPESTORE.get_msgdef(args).fields[0][1])
    if node == Nodetype.SEQUENCE:
        return 4
    return _first_align(args[0])


def _skip(desc: tuple[Any, Any]) -> list[_Op | _Fixed]:
    """The steps that step over a field."""
    node, args = desc
    if node == Nodetype.NAME:
        return [op for _n, d in msgs.TYPESTORE.get_msgdef(args).fields for op in _skip(d)]
    if node == Nodetype.BASE:
        if args[0] in ("string", "wstring"):
            return [_skip_string]
        return [(_SIZE[args[0]], _SIZE[args[0]])]
    sub, length = args
    numeric = sub[0] == Nodetype.BASE and sub[1][0] not in ("string", "wstring")
    if node == Nodetype.ARRAY:
        if numeric:
            return [(_SIZE[sub[1][0]], length * _SIZE[sub[1][0]])] if length else []
        return [op for _ in range(length) for op in _skip(sub)]
    if not numeric:
        item = _merge(_skip(sub))  # a sequence of strings or messages: each item stepped over

        def skip_items(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
            pos = (pos + 3) & -4
            n = _U32(raw, pos)[0]
            pos += 4
            for _ in range(n):
                for op in item:
                    pos = op(raw, pos, values)
            return pos

        return [skip_items]
    size = _SIZE[sub[1][0]]

    def skip_sequence(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
        pos = (pos + 3) & -4
        n = _U32(raw, pos)[0]
        pos += 4
        if n:
            pos = ((pos + size - 1) & -size) + n * size
        return pos

    return [skip_sequence]


def _skip_string(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
    pos = (pos + 3) & -4
    return pos + 4 + _U32(raw, pos)[0]


def _read(name: str, desc: tuple[Any, Any]) -> list[_Op | _Fixed]:
    """The step that reads a field into `values[name]`, as rosbags decodes it."""
    node, args = desc
    if node == Nodetype.NAME:
        msgdef = msgs.TYPESTORE.get_msgdef(args)
        deserialize, cls, store = msgdef.deserialize_cdr_le, msgdef.cls, msgs.TYPESTORE
        a = _first_align(desc)

        def read_message(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
            values[name], pos = deserialize(raw, (pos + a - 1) & -a, cls, store)
            return pos

        return [read_message]
    if node == Nodetype.BASE:
        kind = args[0]
        if kind in ("string", "wstring"):

            def read_string(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
                pos = (pos + 3) & -4
                n = _U32(raw, pos)[0]
                values[name] = bytes(raw[pos + 4 : pos + 3 + n]).decode()
                return pos + 4 + n

            return [read_string]
        size, unpack = _SIZE[kind], _UNPACK[kind]

        def read_number(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
            pos = (pos + size - 1) & -size
            values[name] = unpack(raw, pos)[0]
            return pos + size

        return [read_number]
    sub, length = args
    if sub[0] != Nodetype.BASE or sub[1][0] in ("string", "wstring"):
        return [_read_items(name, sub, length if node == Nodetype.ARRAY else None)]
    kind = sub[1][0]
    size, dtype = _SIZE[kind], msgs._NUMPY[kind]
    if node == Nodetype.ARRAY:

        def read_array(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
            if length:
                pos = (pos + size - 1) & -size
            values[name] = np.frombuffer(raw, dtype=dtype, count=length, offset=pos)
            return pos + length * size

        return [read_array]

    def read_sequence(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
        pos = (pos + 3) & -4
        n = _U32(raw, pos)[0]
        pos += 4
        if n:
            pos = (pos + size - 1) & -size
        values[name] = np.frombuffer(raw, dtype=dtype, count=n, offset=pos)
        return pos + n * size

    return [read_sequence]


def _read_items(name: str, sub: tuple[Any, Any], length: int | None) -> _Op:
    """Reads an array (`length`) or a sequence (None) of strings or messages into a list, as rosbags does."""
    (item,) = _read("item", sub)
    assert callable(item)

    def read_items(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
        n = length
        if n is None:
            pos = (pos + 3) & -4
            n = _U32(raw, pos)[0]
            pos += 4
        one: dict[str, Any] = {}
        items = []
        for _ in range(n):
            pos = item(raw, pos, one)
            items.append(one["item"])
        values[name] = items
        return pos

    return read_items


def _merge(steps: list[_Op | _Fixed]) -> list[_Op]:
    """Runs of fixed-size steps merged into one step each (a table by the start's place modulo 8)."""
    ops: list[_Op] = []
    run: list[_Fixed] = []
    for step in [*steps, None]:
        if isinstance(step, tuple):
            run.append(step)
            continue
        if run:
            ops.append(_fixed(run))
            run = []
        if step is not None:
            ops.append(step)
    return ops


def _fixed(run: list[_Fixed]) -> _Op:
    table = []
    for start in range(8):
        pos = start
        for a, size in run:
            pos = ((pos + a - 1) & -a) + size
        table.append(pos - start)
    if len(set(table)) == 1:
        d = table[0]

        def skip_same(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
            return pos + d

        return skip_same

    def skip_fixed(raw: memoryview, pos: int, values: dict[str, Any]) -> int:
        return pos + table[pos & 7]

    return skip_fixed
