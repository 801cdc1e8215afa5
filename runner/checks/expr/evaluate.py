"""Evaluating a compiled expression on a message (`Expr`): reading field paths through messages, mappings
and sequences, numpy semantics for sequences of numbers, Python numbers for scalars, and an `ExprError`
that names the field or operand and its column when a value does not fit."""

from __future__ import annotations

import ast
import dataclasses
from collections.abc import Mapping
from typing import Any

import numpy as np

from runner.checks.expr.fast import Fn, compile_fast
from runner.checks.expr.language import (
    APPLY,
    ARRAY_HINT,
    BINOPS,
    CMPOPS,
    ExprError,
    FieldPath,
    Source,
    did_you_mean,
    index_value,
    is_number,
    is_numeric,
    scalar,
)


def _is_message(v: Any) -> bool:
    return dataclasses.is_dataclass(v) and not isinstance(v, type)


def _field_names(obj: Any) -> list[str]:
    if _is_message(obj):
        return [f.name for f in dataclasses.fields(obj) if not f.name.startswith("_")]
    if isinstance(obj, Mapping):
        return [k for k in obj if isinstance(k, str) and not k.startswith("_")]
    try:
        names = list(vars(obj))
    except TypeError:
        names = [n for n in dir(obj) if not callable(getattr(obj, n, None))]
    return [n for n in names if not n.startswith("_")]


def _describe(v: Any) -> str:
    if isinstance(v, bool | np.bool_):
        return f"a bool ({v})"
    if isinstance(v, str):
        return f"a string ({v!r})"
    if isinstance(v, int | float | np.number):
        return f"a number ({v})"
    if isinstance(v, np.ndarray):
        return f"an array of {v.size} {v.dtype}"
    if isinstance(v, list | tuple):
        kinds = sorted({type(x).__name__ for x in v})
        return f"a list of {len(v)} ({', '.join(kinds)})" if v else "an empty list"
    if _is_message(v):
        return f"a message ({getattr(v, '__msgtype__', type(v).__name__)})"
    if v is None:
        return "None"
    return f"a {type(v).__name__}"


_SLOW = object()


class Expr:
    """A checked expression. `evaluate(msg)` gives its value; `test(msg)` requires true or false."""

    def __init__(self, text: str, tree: ast.Expression, source: Source, paths: tuple[FieldPath, ...]):
        self.text = text
        self._tree = tree
        self._s = source
        self._paths = paths
        self._fast: Fn | None = None  # test()'s closures (runner.checks.expr.fast), made at its first call

    def __getstate__(self) -> dict[str, Any]:
        return {**self.__dict__, "_fast": None}  # (closures do not pickle; made again where it is used)

    def __repr__(self) -> str:
        return f"Expr({self.text!r})"

    def __str__(self) -> str:
        return self.text

    @property
    def fields(self) -> set[str]:
        """The top-level message fields the expression reads."""
        return {str(p.segments[0][0]) for p in self._paths}

    def evaluate(self, msg: Any) -> Any:
        with np.errstate(all="ignore"):
            return self._eval(self._tree.body, msg)

    def test(self, msg: Any) -> bool:
        fast = self._fast
        if fast is None:
            fast = self._fast = compile_fast(self._tree.body)
        try:
            value = fast(msg)
        except Exception:  # (Slow, or what Python refuses): the interpreter gives the value or the error
            value = _SLOW
        if value is _SLOW:
            value = self.evaluate(msg)
        if value is True or value is False:
            return value
        if isinstance(value, np.bool_):
            return bool(value)
        hint = ARRAY_HINT if isinstance(value, np.ndarray | list) else "compare it: speed < 0.5"
        raise ExprError(
            f"the expression must be true or false; it gives {_describe(value)}", None, hint, self.text
        )

    # ----------------------------------------------------------------------------------------- internals
    def _fail(self, message: str, node: ast.AST | None, hint: str | None = None, column: int | None = None):
        if column is None and node is not None:
            column = self._s.node(node)
        raise ExprError(message, column, hint, self.text)

    def _eval(self, node: ast.AST, msg: Any) -> Any:
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name | ast.Attribute | ast.Subscript):
            return self._path(node, msg)
        if isinstance(node, ast.BoolOp):
            is_and = isinstance(node.op, ast.And)
            for v in node.values:
                b = self._bool(self._eval(v, msg), v, "and" if is_and else "or")
                if b != is_and:
                    return b
            return is_and
        if isinstance(node, ast.UnaryOp):
            v = self._eval(node.operand, msg)
            if isinstance(node.op, ast.Not):
                return not self._bool(v, node.operand, "not")
            if not is_numeric(v):
                sym = "-" if isinstance(node.op, ast.USub) else "+"
                self._fail(f"unary '{sym}' needs a number; found {_describe(v)}", node)
            return -v if isinstance(node.op, ast.USub) else +v
        if isinstance(node, ast.BinOp):
            a = self._eval(node.left, msg)
            b = self._eval(node.right, msg)
            sym = BINOPS[type(node.op)]
            col = self._s.between(node.left, node.right, sym)
            for v in (a, b):
                if not is_numeric(v):
                    self._fail(f"'{sym}' needs numbers; found {_describe(v)}", node, column=col)
            try:
                return APPLY[type(node.op)](a, b)
            except ZeroDivisionError:
                self._fail(f"division by zero in '{ast.unparse(node)}'", node, column=col)
            except (TypeError, ValueError, ArithmeticError) as e:
                self._fail(f"cannot compute '{ast.unparse(node)}': {e}", node, column=col)
        if isinstance(node, ast.Compare):
            left_node, left = node.left, self._eval(node.left, msg)
            for op, right_node in zip(node.ops, node.comparators, strict=True):
                right = self._eval(right_node, msg)
                sym = CMPOPS[type(op)]
                col = self._s.between(left_node, right_node, sym)
                try:
                    r = APPLY[type(op)](left, right)
                except (TypeError, ValueError, ArithmeticError):
                    self._fail(
                        f"cannot compare {_describe(left)} with {_describe(right)} using '{sym}'",
                        node,
                        column=col,
                    )
                if len(node.ops) == 1:
                    return r  # may be an array: test() says so
                if not self._bool(r, node, f"a chained comparison ('{sym}')", column=col):
                    return False
                left_node, left = right_node, right
            return True
        if isinstance(node, ast.Call):
            return self._call(node, msg)
        raise AssertionError(f"unchecked node {ast.dump(node)}")  # pragma: no cover

    def _bool(self, v: Any, node: ast.AST, where: str, column: int | None = None) -> bool:
        if isinstance(v, bool | np.bool_):
            return bool(v)
        hint = ARRAY_HINT if isinstance(v, np.ndarray | list) else None
        self._fail(f"{where} needs true or false; found {_describe(v)}", node, hint, column)
        raise AssertionError  # pragma: no cover

    def _path(self, node: ast.AST, msg: Any) -> Any:
        if isinstance(node, ast.Name):
            return self._field(msg, node.id, None, node)
        if isinstance(node, ast.Attribute):
            return self._field(self._path(node.value, msg), node.attr, node.value, node)
        assert isinstance(node, ast.Subscript)
        seq = self._path(node.value, msg)
        i = index_value(node.slice)
        assert i is not None
        shown = ast.unparse(node.value)
        if not isinstance(seq, np.ndarray | list | tuple | str):
            self._fail(f"'{shown}' cannot be indexed; it is {_describe(seq)}", node.slice)
        if not -len(seq) <= i < len(seq):
            self._fail(f"index {i} is out of range: '{shown}' has {len(seq)} items", node.slice)
        return scalar(seq[i])

    def _field(self, obj: Any, name: str, owner: ast.AST | None, node: ast.AST) -> Any:
        fields = getattr(type(obj), "__dataclass_fields__", None)
        if fields is not None and name in fields:  # a message: the usual case, kept fast
            return getattr(obj, name)  # (compile_expr refused names starting with '_')
        column = self._s.attr(node) if isinstance(node, ast.Attribute) else self._s.node(node)
        where = f"'{ast.unparse(owner)}'" if owner is not None else "the message"
        if isinstance(obj, np.ndarray | list | tuple):
            self._fail(
                f"{where} is a sequence ({_describe(obj)}); it has no field {name!r}",
                node,
                f"index it ({ast.unparse(owner) if owner else 'x'}[0]) or reduce it (.min())",
                column,
            )
        if isinstance(obj, str | bytes | bool | int | float | np.generic) or obj is None:
            self._fail(f"{where} is {_describe(obj)}; it has no field {name!r}", node, None, column)
        names = _field_names(obj)
        if name in names:
            return obj[name] if isinstance(obj, Mapping) else getattr(obj, name)
        kind = getattr(obj, "__msgtype__", None)
        self._fail(
            f"{where}{f' ({kind})' if kind and owner is not None else ''} has no field {name!r}; "
            f"fields: {', '.join(names) or '(none)'}",
            node,
            did_you_mean(name, names),
            column,
        )

    def _call(self, node: ast.Call, msg: Any) -> Any:
        func = node.func
        if isinstance(func, ast.Attribute):
            return self._reduce(func.attr, self._eval(func.value, msg), func.value, node)
        assert isinstance(func, ast.Name)
        args = [self._eval(a, msg) for a in node.args]
        if func.id == "len":
            (v,) = args
            if not isinstance(v, np.ndarray | list | tuple | str):
                self._fail(f"len() needs a sequence or a string; found {_describe(v)}", node)
            return len(v)
        if func.id == "abs":
            (v,) = args
            if not is_numeric(v):
                self._fail(f"abs() needs a number; found {_describe(v)}", node)
            return abs(v)
        if len(args) == 1:
            return self._reduce(func.id, args[0], node.args[0], node)
        a, b = args
        for v in (a, b):
            if not is_numeric(v):
                self._fail(f"{func.id}(a, b) needs numbers; found {_describe(v)}", node)
        if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
            try:
                return np.minimum(a, b) if func.id == "min" else np.maximum(a, b)
            except ValueError:  # sequences of different lengths
                self._fail(
                    f"{func.id}(a, b) of sequences needs them of one length; found {_describe(a)} and "
                    f"{_describe(b)}",
                    node,
                    "compare their items, or reduce each first: min(a.min(), b.min())",
                )
        return min(a, b) if func.id == "min" else max(a, b)

    def _reduce(self, name: str, v: Any, operand: ast.AST, node: ast.AST) -> Any:
        shown = ast.unparse(operand)
        if isinstance(v, list | tuple) and all(is_number(x) or isinstance(x, bool | np.bool_) for x in v):
            v = np.asarray(v)
        if not isinstance(v, np.ndarray):
            self._fail(f"{name}() needs a sequence of numbers; '{shown}' is {_describe(v)}", node)
        if v.dtype.kind not in "iufb":
            self._fail(f"{name}() needs a sequence of numbers; '{shown}' is {_describe(v)}", node)
        if v.size == 0:
            self._fail(f"{name} of an empty sequence ('{shown}' has no items)", node)
        return scalar(getattr(np, name)(v))
