"""A small, safe expression language for assertions on message fields.

    ranges.min() > 0.25
    abs(twist.twist.angular.z) < 0.6 and header.frame_id == "r1/odom"
    len(name) == 2 and position[0] > 1

The text is parsed with `ast.parse(..., mode="eval")` and the tree is checked against a whitelist and then
interpreted here; nothing the user writes is ever given to `eval`, `exec` or `compile`. What is allowed:

- field paths `a.b.c` (a bare name is a top-level field of the message), integer indexes `a[0]`, `a[-1]`
- numbers, strings, `True`/`False`
- `+ - * / %`, unary `-` and `+`; comparisons `< <= > >= == !=` (chained too); `and`, `or`, `not`
- reducers `.min() .max() .mean() .sum() .std()` and the functions `abs(x)`, `len(x)`, `min(x)`, `max(x)`,
  `min(a, b)`, `max(a, b)`

Sequences of numbers are numpy arrays and follow numpy semantics (elementwise arithmetic, reducers computed
by numpy, inf and NaN as numpy treats them). A single number taken out of an array (an index, a reducer)
becomes the Python int or float it equals, like a message's scalar fields: `data[0] - 10` cannot wrap
around for a uint8, and `ranges.max() > 1e308` is true for an inf in a float32 array.
"""

from __future__ import annotations

import ast
import dataclasses
import difflib
import re
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["Expr", "ExprError", "check_fields", "compile_expr"]

REDUCERS = ("min", "max", "mean", "sum", "std")
FUNCTIONS = ("abs", "len", "min", "max")
CALLS_ALLOWED = "abs, len, min, max and .min() .max() .mean() .sum() .std()"
ALLOWED = (
    "field paths (pose.position.x, ranges[0]), numbers, strings, True/False, + - * / %, "
    "comparisons < <= > >= == !=, and/or/not, " + CALLS_ALLOWED
)
MAX_DEPTH = 100  # nesting of the tree; keeps the interpreter's recursion bounded

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")

_BINOPS: dict[type[ast.operator], str] = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.Mod: "%",
}
_OTHER_BINOPS: dict[type[ast.operator], str] = {
    ast.Pow: "**",
    ast.FloorDiv: "//",
    ast.MatMult: "@",
    ast.LShift: "<<",
    ast.RShift: ">>",
    ast.BitAnd: "&",
    ast.BitOr: "|",
    ast.BitXor: "^",
}
_CMPOPS: dict[type[ast.cmpop], str] = {
    ast.Lt: "<",
    ast.LtE: "<=",
    ast.Gt: ">",
    ast.GtE: ">=",
    ast.Eq: "==",
    ast.NotEq: "!=",
}
_OTHER_CMPOPS: dict[type[ast.cmpop], str] = {
    ast.In: "in",
    ast.NotIn: "not in",
    ast.Is: "is",
    ast.IsNot: "is not",
}

# Node kinds refused outright: what the message calls them, and a hint.
_REFUSED: dict[type[ast.AST], tuple[str, str | None]] = {
    ast.Lambda: ("lambda", None),
    ast.ListComp: ("a comprehension", "reduce a sequence with .min() .max() .mean() .sum() .std()"),
    ast.SetComp: ("a comprehension", "reduce a sequence with .min() .max() .mean() .sum() .std()"),
    ast.DictComp: ("a comprehension", "reduce a sequence with .min() .max() .mean() .sum() .std()"),
    ast.GeneratorExp: ("a comprehension", "reduce a sequence with .min() .max() .mean() .sum() .std()"),
    ast.IfExp: ("a conditional expression (x if c else y)", "combine conditions with and/or"),
    ast.NamedExpr: ("an assignment (:=)", None),
    ast.JoinedStr: ("an f-string", 'write a plain string: "r1/odom"'),
    ast.FormattedValue: ("an f-string", 'write a plain string: "r1/odom"'),
    ast.Starred: ("a starred expression (*x)", None),
    ast.List: ("a list", "index a sequence field instead: position[0]"),
    ast.Tuple: ("a tuple", None),
    ast.Set: ("a set", None),
    ast.Dict: ("a dict", None),
    ast.Await: ("await", None),
    ast.Yield: ("yield", None),
    ast.YieldFrom: ("yield", None),
    ast.Slice: ("a slice", "index one item: position[0]"),
}


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


# --------------------------------------------------------------------------------------------- compiling
@dataclasses.dataclass(frozen=True)
class _Path:
    """One field path of the expression, for `check_fields`: `segments` are field names (str) and indexes
    (int) with their columns; `use` is what is done with the value: "value", "len" or a reducer's name."""

    segments: tuple[tuple[str | int, int | None], ...]
    use: str
    column: int | None
    node: ast.AST = dataclasses.field(compare=False, repr=False)


class _Source:
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


def _is_path(node: ast.AST) -> bool:
    return isinstance(node, ast.Name | ast.Attribute | ast.Subscript)


def _index_value(node: ast.AST) -> int | None:
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
    return None


class _Checker:
    """Walks the tree once: refuses whatever is not on the whitelist and collects the field paths."""

    def __init__(self, source: _Source):
        self.s = source
        self.paths: list[_Path] = []

    def fail(
        self, message: str, node: ast.AST | None = None, hint: str | None = None, column: int | None = None
    ):
        if column is None and node is not None:
            column = self.s.node(node)
        raise ExprError(message, column, hint, self.s.text)

    def refuse(self, what: str, node: ast.AST, hint: str | None = None, column: int | None = None):
        self.fail(f"{what} is not allowed in an expression; allowed: {ALLOWED}", node, hint, column)

    def check(self, node: ast.AST, depth: int = 0) -> None:
        if depth > MAX_DEPTH:
            self.fail(f"the expression is nested too deeply (more than {MAX_DEPTH} levels)", node)
        d = depth + 1
        if isinstance(node, ast.Expression):
            self.check(node.body, d)
        elif isinstance(node, ast.BoolOp):
            for v in node.values:
                self.check(v, d)
        elif isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.Invert):
                self.fail("the operator '~' is not allowed; unary operators are -, + and not", node)
            self.check(node.operand, d)
        elif isinstance(node, ast.BinOp):
            op = type(node.op)
            if op not in _BINOPS:
                sym = _OTHER_BINOPS.get(op, op.__name__)
                self.fail(
                    f"the operator '{sym}' is not allowed; arithmetic is limited to + - * / %",
                    node,
                    column=self.s.between(node.left, node.right, sym),
                )
            self.check(node.left, d)
            self.check(node.right, d)
        elif isinstance(node, ast.Compare):
            left = node.left
            for op, right in zip(node.ops, node.comparators, strict=True):
                if type(op) not in _CMPOPS:
                    sym = _OTHER_CMPOPS.get(type(op), type(op).__name__)
                    self.fail(
                        f"the comparison '{sym}' is not allowed; comparisons are < <= > >= == !=",
                        node,
                        column=self.s.between(left, right, sym),
                    )
                left = right
            self.check(node.left, d)
            for c in node.comparators:
                self.check(c, d)
        elif isinstance(node, ast.Constant):
            v = node.value
            if not isinstance(v, bool | int | float | str):
                kind = {type(None): "None", bytes: "a bytes literal", complex: "a complex number"}.get(
                    type(v), repr(v)
                )
                self.fail(f"{kind} is not allowed; constants are numbers, strings and True/False", node)
        elif _is_path(node):
            self.path(node, "value", d)
        elif isinstance(node, ast.Call):
            self.call(node, d)
        elif type(node) in _REFUSED:
            what, hint = _REFUSED[type(node)]
            self.refuse(what, node, hint)
        else:
            self.refuse(f"{type(node).__name__}", node)

    def path(self, node: ast.AST, use: str, depth: int) -> None:
        """A field path: `a`, `a.b`, `a[0].b`; anything else in the chain is refused."""
        segments: list[tuple[str | int, int | None]] = []
        cur = node
        while True:
            if depth > MAX_DEPTH:
                self.fail(f"the expression is nested too deeply (more than {MAX_DEPTH} levels)", cur)
            depth += 1
            if isinstance(cur, ast.Name):
                self.name(cur.id, cur)
                segments.append((cur.id, self.s.node(cur)))
                break
            if isinstance(cur, ast.Attribute):
                self.attr_name(cur)
                segments.append((cur.attr, self.s.attr(cur)))
                if not _is_path(cur.value):
                    self.fail(
                        f"'.{cur.attr}' follows {_what(cur.value)}; fields are read from a field path "
                        "that starts at a message field (pose.pose.position.x)",
                        cur,
                        column=self.s.attr(cur),
                    )
                cur = cur.value
                continue
            if isinstance(cur, ast.Subscript):
                i = _index_value(cur.slice)
                if i is None:
                    self.index_error(cur)
                segments.append((i, self.s.node(cur.slice)))  # type: ignore[arg-type]
                if not _is_path(cur.value):
                    self.fail(
                        f"an index follows {_what(cur.value)}; only field paths can be indexed (position[0])",
                        cur,
                    )
                cur = cur.value
                continue
            raise AssertionError(cur)  # pragma: no cover - _is_path() was checked
        self.paths.append(_Path(tuple(reversed(segments)), use, self.s.node(node), node))

    def name(self, name: str, node: ast.AST) -> None:
        if name.startswith("_"):
            self.fail(f"names starting with '_' are not allowed; found {name!r}", node)
        if not _IDENTIFIER.match(name):
            self.fail(f"field names are plain ASCII identifiers (letters, digits, '_'); found {name!r}", node)

    def attr_name(self, node: ast.Attribute) -> None:
        if node.attr.startswith("_"):
            self.fail(
                f"attribute names starting with '_' are not allowed; found {node.attr!r}",
                node,
                hint="read message fields: pose.pose.position.x",
                column=self.s.attr(node),
            )
        if not _IDENTIFIER.match(node.attr):
            self.fail(
                f"field names are plain ASCII identifiers (letters, digits, '_'); found {node.attr!r}",
                node,
                column=self.s.attr(node),
            )

    def index_error(self, node: ast.Subscript) -> None:
        sl = node.slice
        if isinstance(sl, ast.Slice):
            found = "a slice"
        elif isinstance(sl, ast.Tuple):
            found = "several indexes"
        elif isinstance(sl, ast.Constant):
            found = repr(sl.value)
        else:
            found = repr(ast.unparse(sl))
        self.fail(
            f"indexes must be integer constants such as [0] or [-1]; found {found}",
            sl,
            hint="reduce a sequence with .min() .max() .mean() .sum() .std()",
        )

    def call(self, node: ast.Call, depth: int) -> None:
        func = node.func
        if isinstance(func, ast.Attribute):
            if func.attr.startswith("_"):
                self.attr_name(func)
            if func.attr not in REDUCERS:
                self.fail(
                    f"calls are limited to {CALLS_ALLOWED}; found a call to '.{func.attr}()'",
                    node,
                    column=self.s.attr(func),
                )
            shown = f".{func.attr}()"
        elif isinstance(func, ast.Name):
            if func.id not in FUNCTIONS:
                self.fail(f"calls are limited to {CALLS_ALLOWED}; found a call to {func.id!r}", func)
            shown = f"{func.id}()"
        else:
            self.fail(f"calls are limited to {CALLS_ALLOWED}; found a call to {_what(func)}", func)
        for kw in node.keywords:
            found = f"'{kw.arg}='" if kw.arg else "'**'"
            self.fail(f"{shown} takes no keyword arguments; found {found}", kw)
        for a in node.args:
            if isinstance(a, ast.Starred):
                self.fail(f"{shown} takes no starred arguments (*x)", a)
        n = len(node.args)
        if isinstance(func, ast.Attribute):
            if n:
                self.fail(f"{shown} takes no arguments; found {n}", node.args[0])
            self.operand(func.value, func.attr, depth)
        elif func.id in ("abs", "len"):  # type: ignore[union-attr]
            if n != 1:
                self.fail(f"{shown} takes one argument; found {n}", node)
            self.operand(node.args[0], "len" if func.id == "len" else "value", depth)  # type: ignore[union-attr]
        else:
            if n not in (1, 2):
                self.fail(f"{shown} takes one argument (a sequence) or two (numbers); found {n}", node)
            if n == 1:
                self.operand(node.args[0], func.id, depth)  # type: ignore[union-attr]
            else:
                for a in node.args:
                    self.check(a, depth)

    def operand(self, node: ast.AST, use: str, depth: int) -> None:
        if _is_path(node):
            self.path(node, use, depth)
        else:
            self.check(node, depth)


def _what(node: ast.AST) -> str:
    if isinstance(node, ast.Constant):
        return f"a constant ({node.value!r})"
    if isinstance(node, ast.Call):
        return "a call"
    if type(node) in _REFUSED:
        return _REFUSED[type(node)][0]
    return "an expression"


def _syntax_error(e: SyntaxError, source: _Source) -> ExprError:
    text = source.text
    if not text.strip():
        return ExprError(
            "the expression is empty; write a condition such as ranges.min() > 0.25", None, None, text
        )
    # SyntaxError.offset counts characters from 1; 0 means "at the end of the text"
    col = source.shift + (e.offset if e.offset and e.offset > 0 else len(source.src.rstrip()) + 1)
    hint = None
    if re.match(r"\s*(import|from)\s", text):
        what = "an import statement is not allowed"
    elif ":=" in text:
        what = "an assignment (:=) is not allowed"
    else:
        what = f"invalid expression ({e.msg or 'invalid syntax'})"
        if "&&" in text or "||" in text:
            hint = "write `and` and `or`"
        elif re.search(r"![^=]", text):
            hint = "write `not x` (and `!=` for 'not equal')"
    return ExprError(f"{what}; allowed: {ALLOWED}", col, hint, text)


def compile_expr(text: str) -> Expr:
    """Parse and check `text`; raises ExprError for anything outside the language."""
    if not isinstance(text, str):
        raise ExprError(f"an expression is a string; found {type(text).__name__}")
    source = _Source(text)
    try:
        tree = ast.parse(source.src, mode="eval")
    except SyntaxError as e:
        raise _syntax_error(e, source) from None
    except (RecursionError, MemoryError):
        raise ExprError("the expression is nested too deeply", None, None, text) from None
    checker = _Checker(source)
    checker.check(tree)
    return Expr(text, tree, source, tuple(checker.paths))


# -------------------------------------------------------------------------------------------- evaluating
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


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float | np.number) and not isinstance(v, bool | np.bool_)


def _is_numeric(v: Any) -> bool:
    return _is_number(v) or (isinstance(v, np.ndarray) and v.dtype.kind in "iuf")


def _scalar(v: Any) -> Any:
    """A numpy scalar (an item of an array, a reducer's result) as the Python number it equals, as message
    scalar fields are: no integer wraparound, and `x > 1e308` or `x == 0.1` mean what they say for a
    float32 (numpy would round the Python number to float32 first)."""
    if isinstance(v, np.generic):
        return v.item()
    return v


def _binop(op: type[ast.operator], a: Any, b: Any) -> Any:
    if op is ast.Add:
        return a + b
    if op is ast.Sub:
        return a - b
    if op is ast.Mult:
        return a * b
    if op is ast.Div:
        return a / b
    return a % b


def _compare(op: type[ast.cmpop], a: Any, b: Any) -> Any:
    if op is ast.Lt:
        return a < b
    if op is ast.LtE:
        return a <= b
    if op is ast.Gt:
        return a > b
    if op is ast.GtE:
        return a >= b
    if op is ast.Eq:
        return a == b
    return a != b


_ARRAY_HINT = "reduce a sequence to one value first: ranges.min() > 0.25, not ranges > 0.25"


class Expr:
    """A checked expression. `evaluate(msg)` gives its value; `test(msg)` requires true or false."""

    def __init__(self, text: str, tree: ast.Expression, source: _Source, paths: tuple[_Path, ...]):
        self.text = text
        self._tree = tree
        self._s = source
        self._paths = paths

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
        value = self.evaluate(msg)
        if isinstance(value, bool | np.bool_):
            return bool(value)
        hint = _ARRAY_HINT if isinstance(value, np.ndarray | list) else "compare it: speed < 0.5"
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
            if not _is_numeric(v):
                sym = "-" if isinstance(node.op, ast.USub) else "+"
                self._fail(f"unary '{sym}' needs a number; found {_describe(v)}", node)
            return -v if isinstance(node.op, ast.USub) else +v
        if isinstance(node, ast.BinOp):
            a = self._eval(node.left, msg)
            b = self._eval(node.right, msg)
            sym = _BINOPS[type(node.op)]
            col = self._s.between(node.left, node.right, sym)
            for v in (a, b):
                if not _is_numeric(v):
                    self._fail(f"'{sym}' needs numbers; found {_describe(v)}", node, column=col)
            try:
                return _binop(type(node.op), a, b)
            except ZeroDivisionError:
                self._fail(f"division by zero in '{ast.unparse(node)}'", node, column=col)
            except (TypeError, ValueError, ArithmeticError) as e:
                self._fail(f"cannot compute '{ast.unparse(node)}': {e}", node, column=col)
        if isinstance(node, ast.Compare):
            left_node, left = node.left, self._eval(node.left, msg)
            for op, right_node in zip(node.ops, node.comparators, strict=True):
                right = self._eval(right_node, msg)
                sym = _CMPOPS[type(op)]
                col = self._s.between(left_node, right_node, sym)
                try:
                    r = _compare(type(op), left, right)
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
        hint = _ARRAY_HINT if isinstance(v, np.ndarray | list) else None
        self._fail(f"{where} needs true or false; found {_describe(v)}", node, hint, column)
        raise AssertionError  # pragma: no cover

    def _path(self, node: ast.AST, msg: Any) -> Any:
        if isinstance(node, ast.Name):
            return self._field(msg, node.id, None, node)
        if isinstance(node, ast.Attribute):
            return self._field(self._path(node.value, msg), node.attr, node.value, node)
        assert isinstance(node, ast.Subscript)
        seq = self._path(node.value, msg)
        i = _index_value(node.slice)
        assert i is not None
        shown = ast.unparse(node.value)
        if not isinstance(seq, np.ndarray | list | tuple | str):
            self._fail(f"'{shown}' cannot be indexed; it is {_describe(seq)}", node.slice)
        if not -len(seq) <= i < len(seq):
            self._fail(f"index {i} is out of range: '{shown}' has {len(seq)} items", node.slice)
        return _scalar(seq[i])

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
            _did_you_mean(name, names),
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
            if not _is_numeric(v):
                self._fail(f"abs() needs a number; found {_describe(v)}", node)
            return abs(v)
        if len(args) == 1:
            return self._reduce(func.id, args[0], node.args[0], node)
        a, b = args
        for v in (a, b):
            if not _is_numeric(v):
                self._fail(f"{func.id}(a, b) needs numbers; found {_describe(v)}", node)
        if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
            return np.minimum(a, b) if func.id == "min" else np.maximum(a, b)
        return min(a, b) if func.id == "min" else max(a, b)

    def _reduce(self, name: str, v: Any, operand: ast.AST, node: ast.AST) -> Any:
        shown = ast.unparse(operand)
        if isinstance(v, list | tuple) and all(_is_number(x) or isinstance(x, bool | np.bool_) for x in v):
            v = np.asarray(v)
        if not isinstance(v, np.ndarray):
            self._fail(f"{name}() needs a sequence of numbers; '{shown}' is {_describe(v)}", node)
        if v.dtype.kind not in "iufb":
            self._fail(f"{name}() needs a sequence of numbers; '{shown}' is {_describe(v)}", node)
        if v.size == 0:
            self._fail(f"{name} of an empty sequence ('{shown}' has no items)", node)
        return _scalar(getattr(np, name)(v))


def _did_you_mean(name: str, names: list[str]) -> str | None:
    if name in ("true", "false"):
        return "booleans are written True and False"
    close = difflib.get_close_matches(name, names, n=1)
    return f"did you mean {close[0]!r}?" if close else None


# ------------------------------------------------------------------------------------- checking by type
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
            hint = _ARRAY_HINT if k in ("numseq", "seq") else None
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
        sym = _BINOPS[type(node.op)]
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
            sym = _CMPOPS[type(op)]
            col = expr._s.between(operands[i], operands[i + 1], sym)
            if {a, b} & {"numseq", "seq"} and len(node.ops) > 1:
                fail(f"a chained comparison ('{sym}') compares a whole sequence", node, _ARRAY_HINT, col)
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
        raise ExprError(f"unknown message type {type_name!r}", None, None, expr.text)

    def fail(message: str, column: int | None, hint: str | None = None) -> None:
        raise ExprError(message, column, hint, expr.text)

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
                            _did_you_mean(seg, names),
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
        hint = _ARRAY_HINT if kind in ("numseq", "seq") else "compare it: ranges.min() > 0.25"
        fail(f"the expression must be true or false; it gives {_KIND_WORDS[kind]}", None, hint)
