"""Pydantic validation errors -> `Problem`s that point at the file and line and say, in the user's words,
what is wrong, what was expected and what to do: an unknown key with the one meant, a misspelt `type`, a
name that breaks its pattern (and which character), a list of the wrong length, a number written with its
unit (and the plain SI number to write instead).

Used for the scenario itself and for every plugin's `Params` (with a path prefix such as
`robots[1].plugins[0].params`), so the two read the same.
"""

from __future__ import annotations

import dataclasses
import difflib
import re
from typing import Any

from pydantic import BaseModel, ValidationError

from runner.errors import Problem
from runner.scenario.loader import Document, PathKey
from runner.scenario.model_paths import model_at, resolve, tags, tuple_len, type_at
from runner.scenario.schema import PATTERN_WORDS


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


def short(value: Any, limit: int = 60) -> str:
    """The value as written, cut to `limit` characters."""
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
        path, value, missing = resolve(data, tuple(e["loc"]), about_keys)
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
                    found=f"{_kind(value)} {short(value)}",
                )
            )
            continue
        for e, value, missing in errs:
            problems.append(_with_hint(_problem(e, value, missing, path, doc, model, prefix, data), value))
    return problems


@dataclasses.dataclass(frozen=True)
class _Error:
    """One pydantic error and where it lands: the value there, the path in the data (and the prefix before
    it, for a plugin's params), the document to locate it in and the model it was checked against."""

    e: dict[str, Any]
    value: Any
    missing: bool
    path: PathKey
    doc: Document
    model: type[BaseModel]
    prefix: PathKey
    data: Any

    @property
    def full(self) -> PathKey:
        return self.prefix + self.path

    @property
    def ctx(self) -> dict[str, Any]:
        return self.e.get("ctx") or {}


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
    """The problem one pydantic error describes, by its kind."""
    err = _Error(e, value, missing, path, doc, model, prefix, data)
    kind = e["type"]
    loc = tuple(e["loc"])
    if kind == "extra_forbidden":
        return _unknown_key(err)
    if kind == "union_tag_invalid":
        return _unknown_tag(err)
    if kind == "invalid_key" or (kind.endswith("_type") and loc and loc[-1] == "[key]"):
        return _key_not_text(err)
    if kind == "union_tag_not_found":
        return _missing_tag(err)
    if kind == "string_pattern_mismatch":
        words, why = _pattern_problem(value, str(err.ctx.get("pattern", "")))
        return Problem(
            "not a valid name", doc.locate(err.full), err.full, expected=words, found=short(value), hint=why
        )
    if kind in ("too_short", "too_long") or (kind == "missing" and isinstance(e["loc"][-1], int)):
        return _item_count(err)
    if kind.endswith("_type") and kind in _TYPE_WORDS:
        return _wrong_type(err)
    if kind == "missing":
        return _missing_key(err)
    return _other(err)


def _unknown_key(err: _Error) -> Problem:
    """A key the model does not have: the keys it has, and the one closest to it."""
    key = err.path[-1]
    holder = model_at(err.model, err.path[:-1], err.data)
    allowed = sorted(holder.model_fields) if holder else []
    close = difflib.get_close_matches(str(key), allowed, n=1)
    return Problem(
        f"unknown key {key!r}",
        err.doc.locate(err.full),
        err.full,
        expected="one of: " + ", ".join(allowed) if allowed else None,
        hint=f"did you mean {close[0]!r}?" if close else "remove it, or check its indentation",
    )


def _unknown_tag(err: _Error) -> Problem:
    """A `type:` that names no member of the tagged union: the ones it could be, the closest first."""
    ctx = err.ctx
    tags = [t.strip(" '") for t in str(ctx.get("expected_tags", "")).split(",") if t.strip()]
    found = str(ctx.get("tag", ""))
    close = difflib.get_close_matches(found, tags, n=1)
    where = (*err.full, str(ctx.get("discriminator", "type")).strip("'"))
    return Problem(
        f"unknown {ctx.get('discriminator', 'type')} {found!r}".replace("'type'", "type"),
        err.doc.locate(where),
        where,
        expected="one of: " + ", ".join(tags),
        hint=f"did you mean {close[0]!r}?" if close else None,
    )


def _key_not_text(err: _Error) -> Problem:
    """A mapping key YAML read as a number (or another non-text value) where a name goes."""
    key = err.e.get("input")
    path = err.path
    parent = path[:-1] if path and (path[-1] is key or path[-1] == key) else path
    return Problem(
        f"the key {key!r} is not text",
        err.doc.locate((*err.prefix, *parent, key)),
        err.prefix + parent,
        expected="a name",
        found=f"{_kind(key)} {short(key)}",
        hint="quote it if it is meant as text (`'1': ...`)",
    )


def _missing_tag(err: _Error) -> Problem:
    """An item of a tagged union without its `type:`: the types it could be."""
    where = (*err.full, "type")
    found = tags(type_at(err.model, err.path, err.data))
    return Problem(
        "missing required key 'type'",
        err.doc.locate(err.full),
        where,
        expected="one of: " + ", ".join(found) if found else None,
        hint="add `type:` to say which kind this is",
    )


def _item_count(err: _Error) -> Problem:
    """A list too short or too long: a fixed-size one (a vector) says how many numbers it takes."""
    n = tuple_len(type_at(err.model, err.path, err.data))
    kind, ctx, value = err.e["type"], err.ctx, err.value
    if n is not None:
        expected = f"a list of {n} numbers"
    elif kind == "too_short":
        expected = f"at least {ctx.get('min_length')} item(s)"
    else:
        expected = f"at most {ctx.get('max_length')} item(s)"
    count = len(value) if isinstance(value, list | tuple | str | dict) else None
    return Problem(
        f"expected {n} items, found {count}" if n is not None else "wrong number of items",
        err.doc.locate(err.full),
        err.full,
        expected=expected,
        found=short(value),
    )


def _wrong_type(err: _Error) -> Problem:
    """A value of the wrong type (a string for a number, a mapping for a list...)."""
    kind = err.e["type"]
    expected = _TYPE_WORDS[kind]
    if kind == "tuple_type":
        n = tuple_len(type_at(err.model, err.path, err.data))
        expected = f"a list of {n} numbers" if n else expected
    return Problem(
        "wrong type",
        err.doc.locate(err.full),
        err.full,
        expected=expected,
        found=f"{_kind(err.value)} {short(err.value)}",
    )


def _missing_key(err: _Error) -> Problem:
    """A required key left out: the hint says what it is for (its field's description)."""
    key = err.path[-1]
    holder = model_at(err.model, err.path[:-1], err.data)
    desc = holder.model_fields[key].description if holder and key in holder.model_fields else None
    return Problem(
        f"missing required key {key!r}",
        err.doc.locate(err.full),
        err.full,
        hint=f"add `{key}:` ({desc})" if desc else f"add `{key}:`",
    )


def _other(err: _Error) -> Problem:
    """Any other error: a validator's own message, or pydantic's "Input should be ..." as the expected."""
    msg: str = err.e["msg"]
    full, value = err.full, err.value
    if err.e["type"] == "value_error":
        return Problem(msg.removeprefix("Value error, "), err.doc.locate(full), full, found=short(value))
    expected = msg.removeprefix("Input should be ") if msg.startswith("Input should be ") else None
    if expected:
        expected = expected.split(", unable to parse")[0]
        return Problem("wrong value", err.doc.locate(full), full, expected=expected, found=short(value))
    return Problem(msg, err.doc.locate(full), full, found=short(value))


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
        # pydantic's bounds ("greater than 0") are of a number: say so
        hint = f"give a number {expected}" if expected.startswith(("greater", "less")) else f"give {expected}"
    if hint is None:
        hint = "see the scenario's JSON schema (`scenario schema`) for what this key takes"
    return dataclasses.replace(problem, hint=hint)
