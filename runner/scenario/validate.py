"""Pydantic validation errors -> `ScenarioError`s that point at the file and line.

Used for the scenario itself and for every plugin's `Params` (with a path prefix such as
`robots[1].plugins[0].params`), so the two read the same.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import re
from typing import Annotated, Any, TypeVar, get_args, get_origin

from pydantic import BaseModel, ValidationError

from runner.errors import Problem, ScenarioError
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import PATTERN_WORDS, Scenario

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


def _type_at(root: type[BaseModel], path: PathKey, data: Any = None) -> Any:
    """The annotation of the value at `path` (None when it cannot be followed)."""
    tp: Any = root
    cur = data
    for el in path:
        tp = _unwrap_model(_pick_member(tp, cur), el)
        cur = _step(cur, el)
        if tp is None:
            return None
    return tp


def _tuple_len(tp: Any) -> int | None:
    """The number of items of a fixed-length tuple type (also inside `| None`)."""
    for arg in [tp, *get_args(tp)]:
        while get_origin(arg) is Annotated:
            arg = get_args(arg)[0]
        if get_origin(arg) is tuple:
            args = get_args(arg)
            if args and Ellipsis not in args:
                return len(args)
    return None


def _tags(tp: Any) -> list[str]:
    """The `type` literals of a union of models tagged by `type`."""
    out: list[str] = []
    for arg in _flatten(tp):
        if isinstance(arg, type) and issubclass(arg, BaseModel) and "type" in arg.model_fields:
            out += [str(t) for t in get_args(arg.model_fields["type"].annotation)]
    return out


def _pattern_problem(value: Any, pattern: str) -> tuple[str, str | None]:
    """(what the pattern allows, in words; why the value does not fit) for a string_pattern_mismatch."""
    words, extra = PATTERN_WORDS.get(pattern, (f"text matching the pattern {pattern}", ""))
    if not isinstance(value, str):
        return words, None
    if value == "":
        return words, "it is empty"
    reserved = sorted({c for c in value if c in "*$?#"})
    if reserved:
        return words, (
            "not allowed: "
            + ", ".join(repr(c) for c in reserved)
            + " (wildcards and reserved characters of Zenoh key expressions: names become key chunks)"
        )
    bad = sorted({c for c in value if not (c.isascii() and (c.isalnum() or c == "_")) and c not in extra})
    if bad:
        return words, "not allowed: " + ", ".join(repr(c) for c in bad)
    if "/" in extra and ("//" in value or value.endswith("/") or value.startswith("//")):
        return words, "an empty chunk: no doubled or trailing '/'"
    if value.startswith("/") and re.fullmatch(pattern, "/a") is None:
        return words, "no leading '/' here"
    chunks = value.split("/") if "/" in extra else [value]
    if any(c[:1].isdigit() for c in chunks if c):
        return words, "a name (or a chunk of it) starts with a digit"
    if value[:1] in "-.":
        return words, f"it starts with {value[0]!r}"
    return words, None


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _kind(value: Any) -> str:
    """What a YAML reader calls the value's type."""
    if value is None:
        return "null"
    return {
        dict: "mapping",
        list: "list",
        str: "string",
        bool: "boolean",
        int: "integer",
        float: "number",
    }.get(type(value), type(value).__name__)


_TYPE_WORDS = {
    "string_type": "a string",
    "model_type": "a mapping",
    "model_attributes_type": "a mapping",
    "dict_type": "a mapping",
    "list_type": "a list",
    "tuple_type": "a list",
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

    # A misspelt required key is both "unknown key 'descripton'" and "missing key 'description'": say it once.
    unknown = {
        (p[:-1], str(p[-1]))
        for p, errs in grouped.items()
        for e, _, _ in errs
        if e["type"] == "extra_forbidden"
    }
    for path in list(grouped):
        if path and all(e["type"] == "missing" for e, _, _ in grouped[path]):
            typos = [k for parent, k in unknown if parent == path[:-1]]
            if difflib.get_close_matches(str(path[-1]), typos, n=1):
                del grouped[path]

    problems: list[Problem] = []
    for path, errs in grouped.items():
        deeper = any(len(other) > len(path) and other[: len(path)] == path for other in grouped)
        if deeper and all(x[0]["type"].endswith("_type") for x in errs):
            continue  # `description: str | {file, args}`: the mapping's own errors say more
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
                    found=f"{_kind(value)} {_short(value)}",
                )
            )
            continue
        for e, value, missing in errs:
            problems.append(_with_hint(_problem(e, value, missing, path, doc, model, prefix, data), value))
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
    loc = tuple(e["loc"])
    if kind == "invalid_key" or (kind.endswith("_type") and loc and loc[-1] == "[key]"):
        key = e.get("input")
        parent = path[:-1] if path and (path[-1] is key or path[-1] == key) else path
        return Problem(
            f"the key {key!r} is not text",
            doc.locate((*prefix, *parent, key)),
            prefix + parent,
            expected="a name",
            found=f"{_kind(key)} {_short(key)}",
            hint="quote it if it is meant as text (`'1': ...`)",
        )
    if kind == "union_tag_not_found":
        where = (*full, "type")
        tags = _tags(_type_at(model, path, data))
        return Problem(
            "missing required key 'type'",
            doc.locate(full),
            where,
            expected="one of: " + ", ".join(tags) if tags else None,
            hint="add `type:` to say which kind this is",
        )
    if kind == "string_pattern_mismatch":
        words, why = _pattern_problem(value, str((e.get("ctx") or {}).get("pattern", "")))
        return Problem(
            "not a valid name", doc.locate(full), full, expected=words, found=_short(value), hint=why
        )
    if kind in ("too_short", "too_long") or (kind == "missing" and isinstance(e["loc"][-1], int)):
        n = _tuple_len(_type_at(model, path, data))
        ctx = e.get("ctx") or {}
        if n is not None:
            expected = f"a list of {n} numbers"
        elif kind == "too_short":
            expected = f"at least {ctx.get('min_length')} item(s)"
        else:
            expected = f"at most {ctx.get('max_length')} item(s)"
        count = len(value) if isinstance(value, list | tuple | str | dict) else None
        return Problem(
            f"expected {n} items, found {count}" if n is not None else "wrong number of items",
            doc.locate(full),
            full,
            expected=expected,
            found=_short(value),
        )
    if kind.endswith("_type") and kind in _TYPE_WORDS:
        expected = _TYPE_WORDS[kind]
        if kind == "tuple_type":
            n = _tuple_len(_type_at(model, path, data))
            expected = f"a list of {n} numbers" if n else expected
        return Problem(
            "wrong type", doc.locate(full), full, expected=expected, found=f"{_kind(value)} {_short(value)}"
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


# Units people write after numbers, and what the scenario wants instead (SI: seconds, metres, radians)
_UNITS = {
    "ms": ("seconds", 1e-3),
    "s": ("seconds", 1.0),
    "sec": ("seconds", 1.0),
    "us": ("seconds", 1e-6),
    "mm": ("metres", 1e-3),
    "cm": ("metres", 1e-2),
    "m": ("metres", 1.0),
    "km": ("metres", 1e3),
    "deg": ("radians", 3.141592653589793 / 180),
    "°": ("radians", 3.141592653589793 / 180),
    "rad": ("radians", 1.0),
    "hz": ("Hz", 1.0),
    "kg": ("kilograms", 1.0),
    "g": ("kilograms", 1e-3),
}
_SYNONYMS = {"cube": "box", "ball": "sphere", "tube": "cylinder", "rect": "box"}
_NUMBER_WITH_UNIT = re.compile(r"^\s*([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)\s*([a-zA-Z°]+)\s*$")


def _with_hint(problem: Problem, value: Any) -> Problem:
    """Every problem says what to do: a number written with its unit gets the plain number in SI units,
    a word close to (or meaning) an allowed one gets it, and anything else a hint from what was expected."""
    if problem.hint:
        return problem
    if ": write " in problem.message:  # a validator's own advice: "<what is wrong>: write <the fix>"
        what, fix = problem.message.split(": write ", 1)
        return dataclasses.replace(problem, message=what, hint=f"write {fix}")
    expected = problem.expected or ""
    hint = None
    if isinstance(value, str) and "number" in expected:
        m = _NUMBER_WITH_UNIT.match(value)
        if m and m.group(2).lower() in _UNITS:
            unit, factor = _UNITS[m.group(2).lower()]
            hint = f"numbers are plain, in {unit}: write {float(m.group(1)) * factor:g}"
        else:
            hint = "write a plain number (SI units: metres, seconds, radians), without quotes"
    elif isinstance(value, str) and expected:
        options = re.findall(r"'([^']+)'", expected)
        word = value.strip().lower()
        close = [_SYNONYMS[word]] if _SYNONYMS.get(word) in options else []
        close = close or difflib.get_close_matches(word, options, n=1)
        hint = (
            f"did you mean {close[0]!r}?"
            if close
            else (f"use one of: {', '.join(options)}" if options else None)
        )
    if hint is None and expected:
        hint = f"give {expected}"
    if hint is None:
        hint = "see the scenario's JSON schema (`scenario schema`) for what this key takes"
    return dataclasses.replace(problem, hint=hint)


def validate_model(model: type[M], data: Any, doc: Document, prefix: PathKey = ()) -> M:
    try:
        return model.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(problems_from_validation(err, data, doc, model, prefix)) from None


def validate_scenario(doc: Document) -> Scenario:
    """The scenario model of a document, or a ScenarioError (schema and cross-field rules). To find every
    mistake of a file at once, compile included, use `runner.compile.load_plan`."""
    check_document(doc)
    sc = validate_model(Scenario, doc.data, doc)
    check_consistency(sc, doc)
    return sc


def check_document(doc: Document) -> None:
    """What must hold before anything else can be read: a mapping, and no NUL in any text."""
    if not isinstance(doc.data, dict):
        raise ScenarioError(
            Problem(
                "a scenario must be a mapping of keys (name:, robots:, ...)",
                doc.locate(()),
                found=type(doc.data).__name__,
                hint="start the file with `name: my_scenario`",
            )
        )
    _check_text(doc.data, doc, ())


def _check_text(value: Any, doc: Document, path: PathKey) -> None:
    """No text in a scenario holds a NUL character: no name, path or command can (the OS refuses it)."""
    bad = isinstance(value, str) and "\x00" in value
    if bad:
        raise ScenarioError(
            Problem(
                "this text holds a NUL character",
                doc.locate(path),
                path,
                found=_short(value),
                hint="remove the \\0 (or \\x00) escape",
            )
        )
    if isinstance(value, dict):
        for k, v in value.items():
            _check_text(k, doc, (*path, k))
            _check_text(v, doc, (*path, k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _check_text(v, doc, (*path, i))


def check_consistency(sc: Scenario, doc: Document) -> None:
    """Rules that span several fields: unique names and namespaces, timeline within the run."""
    problems = consistency_problems(sc, doc)
    if problems:
        raise ScenarioError(problems)


def consistency_problems(sc: Scenario, doc: Document) -> list[Problem]:
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
    worlds: list[tuple[PathKey, Any]] = [(("world",), sc.world)]
    worlds += [(("worlds", k), w) for k, w in enumerate(sc.worlds)]
    for at, world in worlds:
        model_names: dict[str, int] = {}
        for i, m in enumerate(world.models):
            where: PathKey = (*at, "models", i, "name")
            if m.name in model_names or m.name in seen_names:
                problems.append(
                    Problem(
                        f"model name {m.name!r} is already used",
                        doc.locate(where),
                        where,
                        hint="names of models and robots must be unique",
                    )
                )
            model_names.setdefault(m.name, i)
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
    return problems


@dataclasses.dataclass
class Pruned:
    """A scenario's data with what the schema refused taken out, so that the rest can still be checked in
    the same pass (`runner.compile.load_plan`): unknown keys and refused values are dropped (a default
    takes their place); an item of a list that still does not validate is removed whole. `removed` lists
    those removals, to map the paths of later problems back to the user's file, and `names` the names
    of removed items (robots, nodes...): a problem that names one of them is a consequence, not news."""

    data: Any
    removed: list[tuple[PathKey, int]] = dataclasses.field(default_factory=list)  # (list, index), in order
    names: set[str] = dataclasses.field(default_factory=set)

    def original(self, path: PathKey) -> PathKey:
        """A path in the pruned data -> the same place in the user's file."""
        p = list(path)
        for lpath, index in reversed(self.removed):
            n = len(lpath)
            if len(p) > n and tuple(p[:n]) == lpath and isinstance(p[n], int) and p[n] >= index:
                p[n] += 1
        return tuple(p)


# lists whose items others name (a robot in an assertion, a node in `lockstep`, a world in `world:`)
_REFERRED = ("robots", "nodes", "worlds", "models")


def prune(model: type[BaseModel], data: Any, rounds: int = 6) -> tuple[BaseModel, Pruned] | None:
    """`data` (which `model` refuses) with the refused parts taken out until it validates, or None when
    that would take out more than list items and optional keys (a required top-level key, say)."""
    pruned = Pruned(copy.deepcopy(data))
    for _ in range(rounds):
        try:
            return model.model_validate(pruned.data), pruned
        except ValidationError as err:
            cut: dict[PathKey, str] = {}  # data path -> "key" (drop the key) or "item" (drop the list item)
            for e in err.errors(include_url=False):
                about_keys = e["type"] in ("missing", "extra_forbidden")
                path, _value, missing = _resolve(pruned.data, tuple(e["loc"]), about_keys)
                short = e["type"] == "missing" and isinstance(e["loc"][-1], int)  # a list too short
                if (short or e["type"] != "missing") and path and not missing and isinstance(path[-1], str):
                    cut[path] = "key"  # (a default, if the field has one; else "missing" next round)
                    continue
                items = [k for k, el in enumerate(path) if isinstance(el, int)]
                if path == ("name",) and missing and isinstance(pruned.data, dict):
                    pruned.data["name"] = "scenario"  # the run's name only labels what follows
                    continue
                if not items:
                    return None
                cut[path[: items[-1] + 1]] = "item"
            # deepest first, and list items from the back, so that earlier cuts do not move later ones
            order = sorted(cut, key=lambda p: (len(p), p[-1] if isinstance(p[-1], int) else 0), reverse=True)
            for path in order:
                if any(len(o) < len(path) and path[: len(o)] == o for o in cut):
                    continue  # inside something that goes anyway
                parent = pruned.data
                for el in path[:-1]:
                    parent = parent[el]
                if cut[path] == "item":
                    item = parent[path[-1]]
                    name = item.get("name") if isinstance(item, dict) else None
                    if isinstance(name, str) and path[-2] in _REFERRED:
                        pruned.names.add(name)
                        if isinstance(item.get("namespace"), str):
                            pruned.names.add(item["namespace"])
                    del parent[path[-1]]
                    pruned.removed.append((path[:-1], int(path[-1])))
                else:
                    del parent[path[-1]]
    return None
