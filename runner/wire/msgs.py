"""ROS 2 message types: build from YAML data, CDR encode/decode, `ros2msg` schema text.

Backed by the `rosbags` typestore (ROS 2 Jazzy definitions), so the bytes on the wire, in the MCAP file
and in a ROS 2 node are the same.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np
from rosbags.typesys.base import Nodetype

from runner.wire.typestore import TYPESTORE

T = TYPESTORE.types

_NUMPY = {
    "bool": np.bool_,
    "byte": np.uint8,
    "char": np.uint8,
    "int8": np.int8,
    "uint8": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "float32": np.float32,
    "float64": np.float64,
}


class MessageDataError(ValueError):
    """Message data (from YAML) does not fit the type. `path` is the field path inside the message."""

    def __init__(self, message: str, path: tuple[str | int, ...] = (), hint: str | None = None):
        super().__init__(message)
        self.path = path
        self.hint = hint


def normalize_type(name: str) -> str:
    """`geometry_msgs/Twist` -> `geometry_msgs/msg/Twist` (the ROS 2 full name)."""
    parts = name.strip().split("/")
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return name.strip()


def is_known(type_name: str) -> bool:
    return normalize_type(type_name) in T


def similar_types(type_name: str, n: int = 3) -> list[str]:
    import difflib

    return difflib.get_close_matches(normalize_type(type_name), list(T), n=n, cutoff=0.5)


def encode(msg: Any, type_name: str) -> bytes:
    return bytes(TYPESTORE.serialize_cdr(msg, type_name))


def decode(data: bytes | memoryview, type_name: str) -> Any:
    return TYPESTORE.deserialize_cdr(data, type_name)


@cache
def msgdef(type_name: str) -> str:
    """The `ros2msg` schema text of a type, with its dependencies (as MCAP and Foxglove expect). A service's
    or action's messages (`pkg/srv/Name_Event`, `pkg/action/Name_FeedbackMessage`), which rosbags' writer
    refuses, are written the same way."""
    if "/msg/" in type_name and all("/msg/" in t for t in _dependencies(type_name)):
        text, _ = TYPESTORE.generate_msgdef(type_name, ros_version=2)
        return text
    parts = [_definition(type_name)]
    for dep in _dependencies(type_name):
        parts.append(f"{'=' * 80}\nMSG: {_short(dep)}\n{_definition(dep)}")
    return "\n".join(parts)


def _short(name: str) -> str:
    """`pkg/msg/Name` -> `pkg/Name`, as ros2msg dependency headers and field types write messages; a
    service's or action's message too (`pkg/srv/Name_Request` -> `pkg/Name_Request`): readers of the
    format (rosidl_adapter's parser in mcap_ros2, Foxglove's) take `pkg/Name` only."""
    pkg, _kind, short = name.split("/")
    return f"{pkg}/{short}"


def _dependencies(type_name: str) -> list[str]:
    """Every type `type_name` refers to, depth first, each once."""
    out: list[str] = []
    todo = [type_name]
    while todo:
        name = todo.pop(0)
        for _f, (kind, detail) in TYPESTORE.fielddefs[name][1]:
            if kind == Nodetype.BASE:
                continue
            ref = detail if kind == Nodetype.NAME else detail[0][1]
            if isinstance(ref, str) and ref not in out and ref != type_name:
                out.append(ref)
                todo.append(ref)
    return out


def _definition(name: str) -> str:
    consts, fields = TYPESTORE.fielddefs[name]
    lines = [f"{ctype} {cname}={value}" for cname, ctype, value in consts]
    for fname, node in fields:
        lines.append(f"{_field_text(node)} {fname}")
    return "\n".join(lines) + "\n"


def _field_text(node: tuple[Any, Any]) -> str:
    kind, detail = node
    if kind == Nodetype.BASE:
        base, bound = detail
        return f"{base}<={bound}" if bound else base
    if kind == Nodetype.NAME:
        return _short(detail)
    inner, length = detail
    text = _field_text(inner)
    if kind == Nodetype.ARRAY:
        return f"{text}[{length}]"
    return f"{text}[<={length}]" if length else f"{text}[]"


def time_msg(ns: int) -> Any:
    return T["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def header(ns: int, frame_id: str) -> Any:
    return T["std_msgs/msg/Header"](stamp=time_msg(ns), frame_id=frame_id)


# ---------------------------------------------------------------------------------------------- from data
def _base_value(kind: str, value: Any, path: tuple[str | int, ...]) -> Any:
    if kind == "string" or kind == "wstring":
        if not isinstance(value, str):
            raise MessageDataError(f"expected a string, found {value!r}", path)
        return value
    if kind == "bool":
        if not isinstance(value, bool):
            raise MessageDataError(f"expected true or false, found {value!r}", path)
        return value
    if kind.startswith("float"):
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise MessageDataError(f"expected a number ({kind}), found {value!r}", path)
        return float(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise MessageDataError(f"expected an integer ({kind}), found {value!r}", path)
    info = np.iinfo(_NUMPY[kind])
    if not info.min <= value <= info.max:
        raise MessageDataError(f"{value} is out of range for {kind} ({info.min}..{info.max})", path)
    return value


def _default_base(kind: str) -> Any:
    if kind in ("string", "wstring"):
        return ""
    if kind == "bool":
        return False
    if kind.startswith("float"):
        return 0.0
    return 0


def _field_value(desc: tuple[Any, Any], value: Any, path: tuple[str | int, ...]) -> Any:
    node, detail = desc
    if node == Nodetype.BASE:
        kind = detail[0]
        return _default_base(kind) if value is None else _base_value(kind, value, path)
    if node == Nodetype.NAME:
        return from_data(detail, value if value is not None else {}, path)
    # ARRAY (fixed length) or SEQUENCE
    (inner_node, inner_detail), length = detail
    items = [] if value is None else value
    if not isinstance(items, list):
        raise MessageDataError(f"expected a list, found {value!r}", path)
    if node == Nodetype.ARRAY and value is not None and len(items) != length:
        raise MessageDataError(f"expected {length} items, found {len(items)}", path)
    if inner_node == Nodetype.BASE and inner_detail[0] in _NUMPY:
        kind = inner_detail[0]
        vals = [_base_value(kind, v, (*path, i)) for i, v in enumerate(items)]
        if node == Nodetype.ARRAY and value is None:
            return np.zeros(length, dtype=_NUMPY[kind])
        return np.array(vals, dtype=_NUMPY[kind])
    if node == Nodetype.ARRAY and value is None:
        items = [None] * length
    return [_field_value((inner_node, inner_detail), v, (*path, i)) for i, v in enumerate(items)]


def from_data(type_name: str, data: Any, path: tuple[str | int, ...] = ()) -> Any:
    """Build a message from plain data (a YAML mapping); missing fields are zero/empty."""
    type_name = normalize_type(type_name)
    if type_name not in T:
        raise MessageDataError(f"unknown message type {type_name!r}", path)
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise MessageDataError(f"expected a mapping of fields for {type_name}, found {data!r}", path)
    _, fields = TYPESTORE.fielddefs[type_name]
    names = [f[0] for f in fields]
    for key in data:
        if key not in names:
            import difflib

            close = difflib.get_close_matches(str(key), names, n=1)
            raise MessageDataError(
                f"{type_name} has no field {key!r} (fields: {', '.join(names)})",
                (*path, key),
                hint=f"did you mean {close[0]!r}?" if close else None,
            )
    kwargs = {name: _field_value(desc, data.get(name), (*path, name)) for name, desc in fields}
    return T[type_name](**kwargs)


def check_data(type_name: str, data: Any, path: tuple[str | int, ...] = ()) -> None:
    """What `from_data` checks (each field given fits its type; the same errors), without building the
    message: a field left out is its zero and needs no look. A 20,000-entry timeline is checked in a
    fraction of the time building each message took."""
    type_name = normalize_type(type_name)
    if type_name not in T:
        raise MessageDataError(f"unknown message type {type_name!r}", path)
    _check_message(type_name, data, path)


def _check_message(type_name: str, data: Any, path: tuple[str | int, ...]) -> None:
    if data is None:
        return
    if not isinstance(data, dict):
        raise MessageDataError(f"expected a mapping of fields for {type_name}, found {data!r}", path)
    fields = _field_table(type_name)
    for key, value in data.items():
        desc = fields.get(key) if isinstance(key, str) else None
        if desc is None:
            from_data(type_name, data, path)  # raises the unknown field's error, worded once
        if value is not None:
            _check_field(desc, value, (*path, key))


@cache
def _field_table(type_name: str) -> dict[str, Any]:
    return {name: desc for name, desc in TYPESTORE.fielddefs[type_name][1]}


def _check_field(desc: tuple[Any, Any], value: Any, path: tuple[str | int, ...]) -> None:
    node, detail = desc
    if node == Nodetype.BASE:
        _base_value(detail[0], value, path)
    elif node == Nodetype.NAME:  # (a field's type name is a full one already)
        _check_message(detail, value, path)
    else:  # an array or sequence: the same checks as _field_value's
        _field_value(desc, value, path)


_EMPTY_MEMBER = "structure_needs_at_least_one_member"


def _field_names(msg: Any) -> list[str]:
    """A message's fields (not its constants, which rosbags' classes also carry as attributes)."""
    defs = TYPESTORE.fielddefs.get(getattr(msg, "__msgtype__", ""))
    if defs is None:
        return [k for k in msg.__dataclass_fields__ if k != "__msgtype__"]
    return [name for name, _desc in defs[1]]


def to_data(msg: Any) -> Any:
    """A message as plain data (for printing and tests): its fields, without its constants (class
    variables, as `ros2 topic echo` leaves them out) or the member rosidl adds to an empty message."""
    if hasattr(msg, "__dataclass_fields__"):
        names = _field_names(msg)
        return {k: to_data(getattr(msg, k)) for k in names if k != _EMPTY_MEMBER}
    if isinstance(msg, np.ndarray):
        return msg.tolist()
    if isinstance(msg, list):
        return [to_data(x) for x in msg]
    return msg


# ------------------------------------------------------------------------------------ non-finite values
@cache
def _float_fields(type_name: str) -> tuple[tuple[str, str, str | None], ...]:
    """Where a type holds floating-point numbers: (field, how, nested type) for each field that is a
    float ("f"), a message holding floats ("m"), a float array ("a") or an array of such messages ("l").
    Empty for a type without any (a String, an Image): nothing to check."""
    out: list[tuple[str, str, str | None]] = []
    for name, (node, detail) in TYPESTORE.fielddefs[type_name][1]:
        if node == Nodetype.BASE:
            if detail[0].startswith("float"):
                out.append((name, "f", None))
        elif node == Nodetype.NAME:
            if _float_fields(detail):
                out.append((name, "m", detail))
        else:
            (inner_node, inner_detail), _length = detail
            if inner_node == Nodetype.BASE:
                if inner_detail[0].startswith("float"):
                    out.append((name, "a", None))
            elif inner_node == Nodetype.NAME and _float_fields(inner_detail):
                out.append((name, "l", inner_detail))
    return tuple(out)


def nonfinite(msg: Any, type_name: str) -> tuple[str | int, ...] | None:
    """The path (`("linear", "x")`, `("ranges", 3)`) of the first NaN or ±Inf in a message of `type_name`,
    or None when every float in it is finite. Only the float fields are visited (the per-type plan is
    cached), and a float array is one `np.isfinite`: a Twist costs ~2 µs, a String nothing."""
    for name, how, sub in _float_fields(type_name):
        value = getattr(msg, name)
        if how == "f":
            if not math.isfinite(value):
                return (name,)
        elif how == "m":
            inner = nonfinite(value, sub)  # type: ignore[arg-type]
            if inner is not None:
                return (name, *inner)
        elif how == "a":
            ok = np.isfinite(value)
            if not ok.all():
                return (name, int(np.flatnonzero(~ok)[0]))
        else:
            for i, item in enumerate(value):
                inner = nonfinite(item, sub)  # type: ignore[arg-type]
                if inner is not None:
                    return (name, i, *inner)
    return None


def path_text(path: tuple[str | int, ...]) -> str:
    """`("ranges", 3)` -> `ranges[3]`, `("linear", "x")` -> `linear.x`."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else part)
    return text


# the service and action types (and their messages) are registered with the messages: every process that
# decodes one (the recorder, `scenario echo`, a report) knows them
from runner.wire import interfaces as _interfaces  # noqa: E402, F401
