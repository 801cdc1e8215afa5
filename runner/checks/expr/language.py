"""What the expression language is made of, shared by its parts (checking, evaluating, checking by
type): the operators, functions and reducers it allows (and what the operators compute, what counts as a
number), the error it raises (`ExprError`, with a caret under the column), where in the user's text a node
of the tree stands (`Source`) and the field paths an expression reads (`FieldPath`)."""

from __future__ import annotations

import ast
import dataclasses
import operator
from collections.abc import Callable
from typing import Any

import numpy as np

from runner.errors import closest

REDUCERS = ("min", "max", "mean", "sum", "std")
FUNCTIONS = ("abs", "len", "min", "max")
CALLS_ALLOWED = "abs, len, min, max and .min() .max() .mean() .sum() .std()"
ALLOWED = (
    "field paths (pose.position.x, ranges[0]), numbers, strings, True/False, + - * / %, "
    "comparisons < <= > >= == !=, and/or/not, " + CALLS_ALLOWED
)
MAX_DEPTH = 100  # nesting of the tree; keeps the interpreter's recursion bounded

# The operators and comparisons allowed, by their symbol (as messages name them).
BINOPS: dict[type[ast.operator], str] = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.Mod: "%",
}
CMPOPS: dict[type[ast.cmpop], str] = {
    ast.Lt: "<",
    ast.LtE: "<=",
    ast.Gt: ">",
    ast.GtE: ">=",
    ast.Eq: "==",
    ast.NotEq: "!=",
}
# ... and what they compute
APPLY: dict[type[ast.operator] | type[ast.cmpop], Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.Mod: operator.mod,
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
}


def is_number(v: Any) -> bool:
    """A number that is not a bool (scalar fields are Python numbers; items and reductions become them)."""
    t = type(v)
    if t is float or t is int:
        return True
    return isinstance(v, int | float | np.number) and not isinstance(v, bool | np.bool_)


def is_numeric(v: Any) -> bool:
    """A number (not a bool) or an array of numbers: what arithmetic takes."""
    if isinstance(v, np.ndarray):
        return v.dtype.kind in "iuf"
    return is_number(v)


def scalar(v: Any) -> Any:
    """A numpy scalar (an item of an array, a reducer's result) as the Python number it equals, as message
    scalar fields are: no integer wraparound, and `x > 1e308` or `x == 0.1` mean what they say for a
    float32 (numpy would round the Python number to float32 first)."""
    return v.item() if isinstance(v, np.generic) else v


class ExprError(ValueError):
    """An expression that is not allowed, names a field the message lacks, or cannot be evaluated.

    `message` says what was found and what is allowed; `column` is the 1-based position in the expression
    text where the problem is (None when it is not about one place); `hint` may suggest a fix; `text` is the
    expression, when known. `str(error)` is the message."""

    def __init__(
        self, message: str, column: int | None = None, hint: str | None = None, text: str | None = None
    ):
        super().__init__(message)
        self.message = message
        self.column = column
        self.hint = hint
        self.text = text

    def render(self) -> str:
        """The message, with the expression and a caret under the column when both are known."""
        lines = [self.message]
        if self.text is not None and self.column is not None and "\n" not in self.text:
            lines += [f"  {self.text}", "  " + " " * (self.column - 1) + "^"]
        if self.hint:
            lines.append(f"  hint: {self.hint}")
        return "\n".join(lines)


@dataclasses.dataclass(frozen=True)
class FieldPath:
    """One field path of the expression, for `check_fields`: `segments` are field names (str) and indexes
    (int) with their columns; `use` is what is done with the value: "value", "len" or a reducer's name."""

    segments: tuple[tuple[str | int, int | None], ...]
    use: str
    column: int | None
    node: ast.AST = dataclasses.field(compare=False, repr=False)


class Source:
    """Maps the parsed text's UTF-8 byte offsets back to 1-based columns of the user's text."""

    def __init__(self, text: str):
        self.text = text
        # Newlines (YAML block scalars) become spaces so that the text is one line and keeps its length;
        # leading blanks are dropped (Python refuses them) and added back to every column.
        flat = text.replace("\r", " ").replace("\n", " ")
        stripped = flat.lstrip(" \t\f")
        self.shift = len(flat) - len(stripped)
        self.src = stripped
        self._bytes = stripped.encode()
        self._between: dict[tuple[int, int], int | None] = {}

    def column(self, col_offset: int | None) -> int | None:
        if col_offset is None:
            return None
        return self.shift + len(self._bytes[:col_offset].decode(errors="replace")) + 1

    def between(self, left: ast.AST, right: ast.AST, symbol: str) -> int | None:
        """Column of an operator `symbol` written between two operands."""
        key = (id(left), id(right))
        if key not in self._between:
            self._between[key] = self._find_between(left, right, symbol)
        return self._between[key]

    def _find_between(self, left: ast.AST, right: ast.AST, symbol: str) -> int | None:
        start = getattr(left, "end_col_offset", None)
        end = getattr(right, "col_offset", None)
        if start is None or end is None:
            return self.column(getattr(left, "col_offset", None))
        seg = self._bytes[start:end].decode(errors="replace")
        i = seg.find(symbol.split()[0])
        if i < 0:
            return self.column(start)
        return self.column(start + len(seg[:i].encode()))

    def node(self, node: ast.AST) -> int | None:
        return self.column(getattr(node, "col_offset", None))

    def attr(self, node: ast.Attribute) -> int | None:
        """Column of the attribute's name (after the dot)."""
        return self.column(node.end_col_offset - len(node.attr.encode()) if node.end_col_offset else None)


def is_path(node: ast.AST) -> bool:
    return isinstance(node, ast.Name | ast.Attribute | ast.Subscript)


def index_value(node: ast.AST) -> int | None:
    """The integer of an index `[3]` or `[-1]`, or None when it is anything else."""
    if isinstance(node, ast.Constant) and type(node.value) is int:
        return node.value
    if (
        isinstance(node, ast.UnaryOp)
        and isinstance(node.op, ast.USub)
        and isinstance(node.operand, ast.Constant)
        and type(node.operand.value) is int
    ):
        return -node.operand.value


ARRAY_HINT = "reduce a sequence to one value first: ranges.min() > 0.25, not ranges > 0.25"


def did_you_mean(name: str, names: list[str]) -> str | None:
    if name in ("true", "false"):
        return "booleans are written True and False"
    near = closest(name, names)
    return f"did you mean {near!r}?" if near else None
