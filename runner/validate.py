"""Pydantic validation errors -> `ScenarioError`s that point at the file and line.

Used for the scenario itself and for every plugin's `Params` (with a path prefix such as
`robots[1].plugins[0].params`), so the two read the same.
"""

from __future__ import annotations

import difflib
from typing import Any, TypeVar, get_args, get_origin

from pydantic import BaseModel, ValidationError

from runner.errors import Problem, ScenarioError
from runner.loader import Document, PathKey
from runner.schema import Scenario

M = TypeVar("M", bound=BaseModel)


def _resolve(data: Any, loc: tuple[Any, ...], about_keys: bool) -> tuple[PathKey, Any, bool]:
    """Walk pydantic's `loc` through the data. Union branch names in `loc` ('str', 'Description')
    do not exist in the data and are skipped. Returns (path in the data, the value there, whether the
    last element was missing from a mapping)."""
    path: list[str | int] = []
    cur = data
    missing = False
    for i, el in enumerate(loc):
        last = i == len(loc) - 1
        in_dict = isinstance(cur, dict) and el in cur
        in_list = isinstance(cur, list) and isinstance(el, int) and 0 <= el < len(cur)
        if in_dict or in_list:
            path.append(el)
            cur = cur[el]
        elif last and about_keys and isinstance(cur, dict) and isinstance(el, str):
            path.append(el)
            missing = True
        # else: a union branch tag; skip it
    return tuple(path), cur, missing


def _model_at(root: type[BaseModel], path: PathKey, data: Any = None) -> type[BaseModel] | None:
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


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


_TYPE_WORDS = {
    "string_type": "a string",
    "model_type": "a mapping",
    "dict_type": "a mapping",
    "list_type": "a list",
    "float_type": "a number",
    "int_type": "an integer",
    "bool_type": "true or false",
}


def problems_from_validation(
    err: ValidationError,
    data: Any,
    doc: Document,
    model: type[BaseModel],
    prefix: PathKey = (),
) -> list[Problem]:
    grouped: dict[PathKey, list[tuple[dict[str, Any], Any, bool]]] = {}
    for e in err.errors(include_url=False):
        about_keys = e["type"] in ("missing", "extra_forbidden")
        path, value, missing = _resolve(data, tuple(e["loc"]), about_keys)
        grouped.setdefault(path, []).append((e, value, missing))

    problems: list[Problem] = []
    for path, errs in grouped.items():
        # Several errors on one path come from the branches of a union. Errors inside the branch the
        # user meant (e.g. an unknown key inside a mapping) are worth more than "not a string".
        specific = [x for x in errs if not x[0]["type"].endswith("_type")]
        if specific:
            errs = specific
        elif len(errs) > 1:
            words = sorted({_TYPE_WORDS.get(x[0]["type"], x[0]["type"]) for x in errs})
            _e0, value, _ = errs[0]
            problems.append(
                Problem(
                    "wrong type",
                    doc.locate(prefix + path),
                    prefix + path,
                    expected=" or ".join(words),
                    found=f"{type(value).__name__} {_short(value)}",
                )
            )
            continue
        for e, value, missing in errs:
            problems.append(_problem(e, value, missing, path, doc, model, prefix, data))
    return problems


def _problem(
    e: dict[str, Any],
    value: Any,
    missing: bool,
    path: PathKey,
    doc: Document,
    model: type[BaseModel],
    prefix: PathKey,
    data: Any = None,
) -> Problem:
    full = prefix + path
    kind = e["type"]
    msg: str = e["msg"]
    if kind == "extra_forbidden":
        key = path[-1]
        holder = _model_at(model, path[:-1], data)
        allowed = sorted(holder.model_fields) if holder else []
        close = difflib.get_close_matches(str(key), allowed, n=1)
        return Problem(
            f"unknown key {key!r}",
            doc.locate(full),
            full,
            expected="one of: " + ", ".join(allowed) if allowed else None,
            hint=f"did you mean {close[0]!r}?" if close else "remove it, or check its indentation",
        )
    if kind == "union_tag_invalid":
        ctx = e.get("ctx") or {}
        tags = [t.strip(" '") for t in str(ctx.get("expected_tags", "")).split(",") if t.strip()]
        found = str(ctx.get("tag", ""))
        close = difflib.get_close_matches(found, tags, n=1)
        where = (*full, str(ctx.get("discriminator", "type")).strip("'"))
        return Problem(
            f"unknown {ctx.get('discriminator', 'type')} {found!r}".replace("'type'", "type"),
            doc.locate(where),
            where,
            expected="one of: " + ", ".join(tags),
            hint=f"did you mean {close[0]!r}?" if close else None,
        )
    if kind == "missing":
        key = path[-1]
        holder = _model_at(model, path[:-1], data)
        desc = holder.model_fields[key].description if holder and key in holder.model_fields else None
        return Problem(
            f"missing required key {key!r}",
            doc.locate(full),
            full,
            hint=f"add `{key}:` ({desc})" if desc else f"add `{key}:`",
        )
    if kind == "value_error":
        return Problem(msg.removeprefix("Value error, "), doc.locate(full), full, found=_short(value))
    expected = msg.removeprefix("Input should be ") if msg.startswith("Input should be ") else None
    if expected:
        expected = expected.split(", unable to parse")[0]
        return Problem("wrong value", doc.locate(full), full, expected=expected, found=_short(value))
    return Problem(msg, doc.locate(full), full, found=_short(value))


def validate_model(model: type[M], data: Any, doc: Document, prefix: PathKey = ()) -> M:
    try:
        return model.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(problems_from_validation(err, data, doc, model, prefix)) from None


def validate_scenario(doc: Document) -> Scenario:
    if not isinstance(doc.data, dict):
        raise ScenarioError(
            Problem(
                "a scenario must be a mapping of keys (name:, robots:, ...)",
                doc.locate(()),
                found=type(doc.data).__name__,
                hint="start the file with `name: my_scenario`",
            )
        )
    sc = validate_model(Scenario, doc.data, doc)
    check_consistency(sc, doc)
    return sc


def check_consistency(sc: Scenario, doc: Document) -> None:
    """Rules that span several fields: unique names and namespaces, timeline within the run."""
    problems: list[Problem] = []
    seen_names: dict[str, int] = {}
    seen_ns: dict[str, int] = {}
    for i, robot in enumerate(sc.robots):
        if robot.name in seen_names:
            problems.append(
                Problem(
                    f"robot name {robot.name!r} is used twice",
                    doc.locate(("robots", i, "name")),
                    ("robots", i, "name"),
                    hint=f"robots[{seen_names[robot.name]}] has the same name; names must be unique",
                )
            )
        seen_names.setdefault(robot.name, i)
        ns = robot.ns
        for other, j in seen_ns.items():
            if robot.namespace is None and sc.robots[j].name == robot.name:
                continue  # already reported as a duplicate name
            if ns == other or ns.startswith(other + "/") or other.startswith(ns + "/"):
                where = ("robots", i, "namespace") if robot.namespace else ("robots", i, "name")
                problems.append(
                    Problem(
                        f"namespace {ns!r} clashes with {other!r} of robots[{j}]",
                        doc.locate(where),
                        where,
                        hint="give each robot its own namespace (`namespace: r2`)",
                    )
                )
        seen_ns.setdefault(ns, i)
        plugin_names: dict[str, int] = {}
        for k, p in enumerate(robot.plugins):
            pname = p.name or p.type
            if pname in plugin_names:
                where = ("robots", i, "plugins", k)
                problems.append(
                    Problem(
                        f"two plugins named {pname!r} on robot {robot.name!r}",
                        doc.locate(where),
                        where,
                        hint="give the second one a `name:`",
                    )
                )
            plugin_names.setdefault(pname, k)
    model_names: dict[str, int] = {}
    for i, m in enumerate(sc.world.models):
        if m.name in model_names or m.name in seen_names:
            problems.append(
                Problem(
                    f"model name {m.name!r} is already used",
                    doc.locate(("world", "models", i, "name")),
                    ("world", "models", i, "name"),
                    hint="names of models and robots must be unique",
                )
            )
        model_names.setdefault(m.name, i)
        if not m.static and m.mass is None:
            pass  # default mass of 1 kg, documented
    for i, ev in enumerate(sc.timeline):
        if ev.t > sc.duration:
            problems.append(
                Problem(
                    f"this entry is at t={ev.t} s, after the end of the run",
                    doc.locate(("timeline", i, "t")),
                    ("timeline", i, "t"),
                    expected=f"a time within the duration (0..{sc.duration} s)",
                    found=str(ev.t),
                    hint="raise `duration:` or move the entry earlier",
                )
            )
    if problems:
        raise ScenarioError(problems)
