"""Checking an expression against a message type without a message (`check_fields`), as the compile pass
does for every `message` assertion: each field path is followed through the type's definition, and the
kind of value each part of the expression gives is inferred, so that what evaluating would refuse is
refused before the run."""

from __future__ import annotations

import ast
from typing import Any

from runner.checks.expr.evaluate import Expr
from runner.checks.expr.language import ARRAY_HINT, BINOPS, CMPOPS, REDUCERS, ExprError, did_you_mean


def _describe_type(desc: tuple[Any, Any]) -> str:
    from rosbags.typesys.base import Nodetype

    node, detail = desc
    if node == Nodetype.BASE:
        return "a string" if detail[0] in ("string", "wstring") else f"a {detail[0]}"
    if node == Nodetype.NAME:
        return f"a message ({detail})"
    inner, length = detail
    inner_s = _describe_type(inner).split(" ", 1)[1]
    if node == Nodetype.ARRAY:
        return f"an array of {length} {inner_s}"
    return f"a sequence of {inner_s}"


def _kind_of_type(desc: tuple[Any, Any]) -> str:
    """What `_infer` calls a field's type: num, bool, str, numseq (numbers or bools), seq, msg."""
    from rosbags.typesys.base import Nodetype

    node, detail = desc
    if node == Nodetype.BASE:
        return "str" if detail[0].endswith("string") else "bool" if detail[0] == "bool" else "num"
    if node == Nodetype.NAME:
        return "msg"
    inner_node, inner_detail = detail[0]
    numeric = inner_node == Nodetype.BASE and not inner_detail[0].endswith("string")
    return "numseq" if numeric else "seq"


_KIND_WORDS = {
    "num": "a number",
    "bool": "true or false",
    "str": "a string",
    "numseq": "a sequence",
    "seq": "a sequence",
    "msg": "a message",
}


def _infer(expr: Expr, node: ast.AST, kinds: dict[int, str]) -> str:
    """The kind of value `node` gives on a message of the checked type; refuses what evaluate() would."""

    def fail(message: str, at: ast.AST, hint: str | None = None, column: int | None = None) -> None:
        raise ExprError(message, column if column is not None else expr._s.node(at), hint, expr.text)

    def need_bool(k: str, at: ast.AST, where: str) -> None:
        if k != "bool":
            hint = ARRAY_HINT if k in ("numseq", "seq") else None
            fail(f"{where} needs true or false; '{ast.unparse(at)}' gives {_KIND_WORDS[k]}", at, hint)

    def need_numbers(k: str, at: ast.AST, where: str, column: int | None = None) -> None:
        if k not in ("num", "numseq"):
            fail(f"{where} needs numbers; '{ast.unparse(at)}' gives {_KIND_WORDS[k]}", at, None, column)

    if isinstance(node, ast.Constant):
        v = node.value
        return "bool" if isinstance(v, bool) else "str" if isinstance(v, str) else "num"
    if id(node) in kinds:
        return kinds[id(node)]
    if isinstance(node, ast.BoolOp):
        for v in node.values:
            need_bool(_infer(expr, v, kinds), v, "and" if isinstance(node.op, ast.And) else "or")
        return "bool"
    if isinstance(node, ast.UnaryOp):
        k = _infer(expr, node.operand, kinds)
        if isinstance(node.op, ast.Not):
            need_bool(k, node.operand, "not")
            return "bool"
        need_numbers(k, node.operand, f"unary '{'-' if isinstance(node.op, ast.USub) else '+'}'")
        return k
    if isinstance(node, ast.BinOp):
        sym = BINOPS[type(node.op)]
        col = expr._s.between(node.left, node.right, sym)
        ks = [_infer(expr, side, kinds) for side in (node.left, node.right)]
        for k, side in zip(ks, (node.left, node.right), strict=True):
            need_numbers(k, side, f"'{sym}'", col)
        return "numseq" if "numseq" in ks else "num"
    if isinstance(node, ast.Compare):
        operands = [node.left, *node.comparators]
        ks = [_infer(expr, o, kinds) for o in operands]
        for i, op in enumerate(node.ops):
            a, b = ks[i], ks[i + 1]
            sym = CMPOPS[type(op)]
            col = expr._s.between(operands[i], operands[i + 1], sym)
            if {a, b} & {"numseq", "seq"} and len(node.ops) > 1:
                fail(f"a chained comparison ('{sym}') compares a whole sequence", node, ARRAY_HINT, col)
            if sym not in ("==", "!=") and {a, b} == {"str", "num"}:
                fail(f"cannot compare a string with a number using '{sym}'", node, None, col)
        return "numseq" if {ks[0], ks[1]} & {"numseq", "seq"} else "bool"
    if isinstance(node, ast.Call):
        func = node.func
        if isinstance(func, ast.Attribute) or (func.id in ("min", "max") and len(node.args) == 1):  # type: ignore[union-attr]
            operand = func.value if isinstance(func, ast.Attribute) else node.args[0]
            name = func.attr if isinstance(func, ast.Attribute) else func.id  # type: ignore[union-attr]
            k = _infer(expr, operand, kinds)
            if k != "numseq":
                fail(
                    f"{name}() needs a sequence of numbers; '{ast.unparse(operand)}' gives {_KIND_WORDS[k]}",
                    node,
                )
            return "num"
        ks = [_infer(expr, a, kinds) for a in node.args]
        if func.id == "len":  # type: ignore[union-attr]
            if ks[0] not in ("numseq", "seq", "str"):
                shown = ast.unparse(node.args[0])
                fail(f"len() needs a sequence or a string; '{shown}' gives {_KIND_WORDS[ks[0]]}", node)
            return "num"
        for k, a in zip(ks, node.args, strict=True):
            need_numbers(k, a, f"{func.id}()", expr._s.node(node))  # type: ignore[union-attr]
        return "numseq" if "numseq" in ks else "num"
    raise AssertionError(f"unchecked node {ast.dump(node)}")  # pragma: no cover


# What to do, by what check_fields found (its messages say what is wrong; these, what to write instead)
_HINTS = {
    " is not a known type": "give a ROS 2 type such as nav_msgs/msg/Odometry",
    "; it has no field ": "only a message has fields: compare this value itself",
    " is out of range: ": "an index counts from 0 (or from -1 back from the end) within the array's length",
    " cannot be indexed; ": "only arrays, sequences and strings take an index [i]",
    "len() needs ": "len() counts the items of a sequence field, such as len(ranges)",
    "() needs a sequence of numbers": "a reducer takes a sequence of numbers: ranges.min(), ranges.mean()",
    ", not a value; ": "read one of its fields, e.g. pose.position.x rather than pose.position",
}


def _hint(message: str) -> str | None:
    return next((hint for part, hint in _HINTS.items() if part in message), None)


def check_fields(expr: Expr, type_name: str, condition: bool = True) -> None:
    """Check `expr` against the message type `type_name` (e.g. `nav_msgs/msg/Odometry`) without a message:
    every field must exist, indexes must follow a sequence (and fit a fixed-size array), reducers need a
    sequence of numbers and len() a sequence or a string, a path used as a value must not end at a message,
    and operators must get what they need at run time. With `condition` (the default) the whole expression
    must give true or false, as `Expr.test` requires. Raises ExprError."""
    from rosbags.typesys.base import Nodetype

    from runner.wire.msgs import TYPESTORE, normalize_type

    type_name = normalize_type(type_name)
    if type_name not in TYPESTORE.fielddefs:
        raise ExprError(f"unknown message type {type_name!r}", None, _hint(" is not a known type"), expr.text)

    def fail(message: str, column: int | None, hint: str | None = None) -> None:
        raise ExprError(message, column, hint or _hint(message), expr.text)

    kinds: dict[int, str] = {}
    for p in expr._paths:
        cur: tuple[Any, Any] = (Nodetype.NAME, type_name)
        shown = ""
        for seg, col in p.segments:
            node, detail = cur
            if isinstance(seg, str):
                if node == Nodetype.NAME:
                    fields = TYPESTORE.fielddefs[detail][1]
                    names = [f[0] for f in fields]
                    if seg not in names:
                        where = f"'{shown}' ({detail})" if shown else detail
                        fail(
                            f"'{shown + '.' if shown else ''}{seg}': {where} has no field {seg!r}; "
                            f"fields: {', '.join(names)}",
                            col,
                            did_you_mean(seg, names) or "use one of the fields listed",
                        )
                    cur = dict(fields)[seg]
                elif node in (Nodetype.ARRAY, Nodetype.SEQUENCE):
                    fail(
                        f"'{shown}' is {_describe_type(cur)}; it has no field {seg!r}",
                        col,
                        f"index it ({shown}[0]) or reduce it ({shown}.min())",
                    )
                else:
                    fail(f"'{shown}' is {_describe_type(cur)}; it has no field {seg!r}", col)
                shown = f"{shown}.{seg}" if shown else seg
            else:
                if node in (Nodetype.ARRAY, Nodetype.SEQUENCE):
                    inner, length = detail
                    if node == Nodetype.ARRAY and not -length <= seg < length:
                        fail(f"index {seg} is out of range: '{shown}' is {_describe_type(cur)}", col)
                    cur = inner
                elif node == Nodetype.BASE and detail[0] in ("string", "wstring"):
                    pass  # a character of a string
                else:
                    fail(f"'{shown}' cannot be indexed; it is {_describe_type(cur)}", col)
                shown = f"{shown}[{seg}]"
        node, detail = cur
        kind = _kind_of_type(cur)
        if p.use == "len":
            if kind not in ("numseq", "seq", "str"):
                fail(f"len() needs a sequence or a string; '{shown}' is {_describe_type(cur)}", p.column)
        elif p.use in REDUCERS:
            if kind != "numseq":
                fail(f"{p.use}() needs a sequence of numbers; '{shown}' is {_describe_type(cur)}", p.column)
        elif kind == "msg":
            names = [f[0] for f in TYPESTORE.fielddefs[detail][1]]
            fail(
                f"'{shown}' is {_describe_type(cur)}, not a value; use one of its fields: {', '.join(names)}",
                p.column,
            )
        kinds[id(p.node)] = kind
    kind = _infer(expr, expr._tree.body, kinds)
    if condition and kind != "bool":
        hint = ARRAY_HINT if kind in ("numseq", "seq") else "compare it: ranges.min() > 0.25"
        fail(f"the expression must be true or false; it gives {_KIND_WORDS[kind]}", None, hint)
