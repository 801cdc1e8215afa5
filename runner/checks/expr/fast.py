"""The fast path of `Expr.test`: the checked tree turned once into nested closures that compute what the
interpreter (`Expr._eval`) computes, with its checks, but without walking the tree at every message. On
anything the interpreter would refuse or treat specially (a value of the wrong kind, an empty sequence, an
index out of range, a division by zero, a field that is not a message's), a closure raises `Slow` and the
message is evaluated again by the interpreter, which gives the value or the located error as before: the
two agree on every message (tests/test_expr.py checks them side by side on generated expressions)."""

from __future__ import annotations

import ast
import operator
from collections.abc import Callable
from typing import Any

import numpy as np

from runner.checks.expr.language import APPLY, index_value, is_numeric, scalar

Fn = Callable[[Any], Any]


class Slow(Exception):
    """Let the interpreter evaluate this message (it knows what to say)."""


def _truth(v: Any) -> bool:
    if v is True or v is False:
        return v
    if isinstance(v, np.bool_):
        return bool(v)
    raise Slow


def compile_fast(node: ast.AST) -> Fn:
    """`fn(msg)`: the value of the expression `node` on `msg`, or `Slow` raised."""
    if isinstance(node, ast.Constant):
        value = node.value
        return lambda msg: value
    if isinstance(node, ast.Name):
        return _field(None, node.id)
    if isinstance(node, ast.Attribute):
        return _field(compile_fast(node.value), node.attr)
    if isinstance(node, ast.Subscript):
        return _index(compile_fast(node.value), index_value(node.slice))
    if isinstance(node, ast.BoolOp):
        return _boolop(isinstance(node.op, ast.And), [compile_fast(v) for v in node.values])
    if isinstance(node, ast.UnaryOp):
        return _unary(node.op, compile_fast(node.operand))
    if isinstance(node, ast.BinOp):
        return _binop(APPLY[type(node.op)], compile_fast(node.left), compile_fast(node.right))
    if isinstance(node, ast.Compare):
        return _compare(
            [APPLY[type(op)] for op in node.ops], [compile_fast(n) for n in [node.left, *node.comparators]]
        )
    if isinstance(node, ast.Call):
        return _call(node)
    raise AssertionError(f"unchecked node {ast.dump(node)}")  # pragma: no cover


def _field(owner: Fn | None, name: str) -> Fn:
    def field(obj: Any) -> Any:
        if name in getattr(type(obj), "__dataclass_fields__", ()):
            return getattr(obj, name)
        raise Slow  # a mapping, an object, a missing field: the interpreter says what it is

    if owner is None:
        return field
    return lambda msg: field(owner(msg))


def _index(seq_fn: Fn, i: int | None) -> Fn:
    assert i is not None

    def index(msg: Any) -> Any:
        seq = seq_fn(msg)
        if not isinstance(seq, np.ndarray | list | tuple | str) or not -len(seq) <= i < len(seq):
            raise Slow
        return scalar(seq[i])

    return index


def _boolop(is_and: bool, fns: list[Fn]) -> Fn:
    def boolop(msg: Any) -> Any:
        for fn in fns:
            if _truth(fn(msg)) != is_and:
                return not is_and
        return is_and

    return boolop


def _unary(op: ast.unaryop, fn: Fn) -> Fn:
    if isinstance(op, ast.Not):
        return lambda msg: not _truth(fn(msg))
    negate = isinstance(op, ast.USub)

    def unary(msg: Any) -> Any:
        v = fn(msg)
        if not is_numeric(v):
            raise Slow
        return -v if negate else +v

    return unary


def _binop(op: Callable[[Any, Any], Any], left: Fn, right: Fn) -> Fn:
    def binop(msg: Any) -> Any:
        a, b = left(msg), right(msg)
        if not (is_numeric(a) and is_numeric(b)):
            raise Slow
        if type(a) is np.ndarray or type(b) is np.ndarray:
            with np.errstate(all="ignore"):
                return op(a, b)
        return op(a, b)  # (a division by zero raises: the interpreter says where)

    return binop


def _compare(ops: list[Callable[[Any, Any], Any]], fns: list[Fn]) -> Fn:
    if len(ops) == 1:
        (op,), (left, right) = ops, fns

        def compare(msg: Any) -> Any:
            a, b = left(msg), right(msg)
            if type(a) is np.ndarray or type(b) is np.ndarray:
                with np.errstate(all="ignore"):
                    return op(a, b)
            return op(a, b)

        return compare

    def chained(msg: Any) -> Any:
        left = fns[0](msg)
        for op, fn in zip(ops, fns[1:], strict=True):
            right = fn(msg)
            with np.errstate(all="ignore"):
                r = op(left, right)
            if not _truth(r):
                return False
            left = right
        return True

    return chained


def _call(node: ast.Call) -> Fn:
    func = node.func
    if isinstance(func, ast.Attribute):
        return _reduce(func.attr, compile_fast(func.value))
    assert isinstance(func, ast.Name)
    args = [compile_fast(a) for a in node.args]
    name = func.id
    if name == "len":
        (arg,) = args

        def length(msg: Any) -> Any:
            v = arg(msg)
            if not isinstance(v, np.ndarray | list | tuple | str):
                raise Slow
            return len(v)

        return length
    if name == "abs":
        (arg,) = args

        def absolute(msg: Any) -> Any:
            v = arg(msg)
            if not is_numeric(v):
                raise Slow
            return abs(v)

        return absolute
    if len(args) == 1:
        return _reduce(name, args[0])
    first, second = args
    pick = (np.minimum, min) if name == "min" else (np.maximum, max)

    def two(msg: Any) -> Any:
        a, b = first(msg), second(msg)
        if not (is_numeric(a) and is_numeric(b)):
            raise Slow
        if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
            with np.errstate(all="ignore"):
                return pick[0](a, b)
        return pick[1](a, b)

    return two


def _reduce(name: str, fn: Fn) -> Fn:
    method = operator.methodcaller(name)  # (the array's own method: what np.NAME calls, without its wrapper)
    quiet = name in ("min", "max")  # (they never warn, not even on NaN: no errstate to pay for)

    def reduce(msg: Any) -> Any:
        v = fn(msg)
        if type(v) is not np.ndarray or v.dtype.kind not in "iufb" or v.size == 0:
            raise Slow  # (a list of numbers, too: the interpreter makes it an array)
        if quiet:
            return scalar(method(v))
        with np.errstate(all="ignore"):
            return scalar(method(v))

    return reduce
