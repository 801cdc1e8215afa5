"""Following a path through a scenario's data and its pydantic models side by side: where pydantic's error
location (`loc`, with union branch names in it) lands in the data (`resolve`), which model holds the value
there (`model_at`), its annotation (`type_at`), the length of a fixed-size list (`tuple_len`) and the
`type` tags of a tagged union (`tags`). In a union tagged by `type`, the member the data names is followed.
"""

from __future__ import annotations

from typing import Annotated, Any, get_args, get_origin

from pydantic import BaseModel

from runner.scenario.loader import PathKey


def resolve(data: Any, loc: tuple[Any, ...], about_keys: bool) -> tuple[PathKey, Any, bool]:
    """Walk pydantic's `loc` through the data. Union branch names in `loc` ('str', 'Description')
    do not exist in the data and are skipped. Returns (path in the data, the value there, whether the
    last element was missing from a mapping)."""
    path: list[str | int] = []
    cur = data
    missing = False
    for i, el in enumerate(loc):
        last = i == len(loc) - 1
        in_dict = isinstance(cur, dict) and _has_key(cur, el)
        in_list = isinstance(cur, list) and isinstance(el, int) and 0 <= el < len(cur)
        if in_dict or in_list:
            path.append(el)
            cur = cur[el]
        elif last and about_keys and isinstance(cur, dict) and isinstance(el, str):
            path.append(el)
            missing = True
        # else: a union branch tag, '[key]', or an item missing from a too short list; skip it
    return tuple(path), cur, missing


def _has_key(d: dict[Any, Any], el: Any) -> bool:
    try:
        return el in d
    except TypeError:  # an unhashable element of `loc`
        return False


def model_at(root: type[BaseModel], path: PathKey, data: Any = None) -> type[BaseModel] | None:
    """The model class that holds the value at `path` (for listing the keys it accepts); in a union
    tagged by `type`, the member the data names."""
    tp: Any = root
    cur = data
    for el in path:
        tp = _pick_member(tp, cur)
        tp = _unwrap_model(tp, el)
        cur = _step(cur, el)
        if tp is None:
            return None
    return _unwrap_model(_pick_member(tp, cur), None)


def _step(cur: Any, el: Any) -> Any:
    if isinstance(cur, dict):
        return cur.get(el)
    if isinstance(cur, list) and isinstance(el, int) and 0 <= el < len(cur):
        return cur[el]
    return None


def _pick_member(tp: Any, cur: Any) -> Any:
    """Of a union of models, the one whose `type` literal matches the data's `type`."""
    if not isinstance(cur, dict) or "type" not in cur:
        return tp
    for arg in _flatten(tp):
        is_model = isinstance(arg, type) and issubclass(arg, BaseModel) and "type" in arg.model_fields
        if is_model and cur["type"] in get_args(arg.model_fields["type"].annotation):
            return arg
    return tp


def _flatten(tp: Any) -> list[Any]:
    args = get_args(tp)
    if not args:
        return [tp]
    out: list[Any] = []
    for a in args:
        out += _flatten(a)
    return out


def _unwrap_model(tp: Any, el: Any) -> Any:
    """Step one element down a type: a field of a model, an item of a list/dict, a branch of a union."""
    if el is None:
        if isinstance(tp, type) and issubclass(tp, BaseModel):
            return tp
        for arg in get_args(tp):
            found = _unwrap_model(arg, None)
            if found is not None:
                return found
        return None
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        field = tp.model_fields.get(el) if isinstance(el, str) else None
        return field.annotation if field else None
    origin = get_origin(tp)
    if origin in (list, tuple) and isinstance(el, int):
        args = get_args(tp)
        return args[0] if args else None
    if origin is dict:
        args = get_args(tp)
        return args[1] if len(args) == 2 else None
    for arg in get_args(tp):  # union / Annotated
        found = _unwrap_model(arg, el)
        if found is not None:
            return found
    return None


def type_at(root: type[BaseModel], path: PathKey, data: Any = None) -> Any:
    """The annotation of the value at `path` (None when it cannot be followed)."""
    tp: Any = root
    cur = data
    for el in path:
        tp = _unwrap_model(_pick_member(tp, cur), el)
        cur = _step(cur, el)
        if tp is None:
            return None
    return tp


def tuple_len(tp: Any) -> int | None:
    """The number of items of a fixed-length tuple type (also inside `| None`)."""
    for arg in [tp, *get_args(tp)]:
        while get_origin(arg) is Annotated:
            arg = get_args(arg)[0]
        if get_origin(arg) is tuple:
            args = get_args(arg)
            if args and Ellipsis not in args:
                return len(args)
    return None


def tags(tp: Any) -> list[str]:
    """The `type` literals of a union of models tagged by `type`."""
    out: list[str] = []
    for arg in _flatten(tp):
        if isinstance(arg, type) and issubclass(arg, BaseModel) and "type" in arg.model_fields:
            out += [str(t) for t in get_args(arg.model_fields["type"].annotation)]
    return out
