"""Compiling an expression (`compile_expr`): the text is parsed with `ast.parse(..., mode="eval")` and the
tree is walked once against the whitelist, refusing anything else with a message that names it, says
what is allowed and points at its column; the field paths it reads are collected on the way."""

from __future__ import annotations

import ast
import re

from runner.checks.expr.evaluate import Expr
from runner.checks.expr.language import (
    ALLOWED,
    BINOPS,
    CALLS_ALLOWED,
    CMPOPS,
    FUNCTIONS,
    MAX_DEPTH,
    REDUCERS,
    ExprError,
    FieldPath,
    Source,
    index_value,
    is_path,
)
from runner.errors import closest

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")

# Operators and comparisons Python has and the language refuses, by their symbol.
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
_OTHER_CMPOPS: dict[type[ast.cmpop], str] = {
    ast.In: "in",
    ast.NotIn: "not in",
    ast.Is: "is",
    ast.IsNot: "is not",
}

_ONE_CONDITION = "an expression is one condition on the message's fields, e.g. ranges.min() > 0.25"

# What to write instead of an operator or comparison the language refuses.
_INSTEAD: dict[str, str] = {
    "**": "write x * x (powers are not in the language)",
    "//": "write / (division), and compare instead of rounding",
    "@": "write * for a product of numbers",
    "<<": "did you mean '<'?",
    ">>": "did you mean '>'?",
    "&": "write `and`",
    "|": "write `or`",
    "^": "write `!=` for 'one but not the other' of two conditions",
    "in": "compare with == (joined with `or` for several values)",
    "not in": "compare with != (joined with `and` for several values)",
    "is": "write ==",
    "is not": "write !=",
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


class _Checker:
    """Walks the tree once: refuses whatever is not on the whitelist and collects the field paths."""

    def __init__(self, source: Source):
        self.s = source
        self.paths: list[FieldPath] = []

    def fail(
        self, message: str, node: ast.AST | None = None, hint: str | None = None, column: int | None = None
    ):
        if column is None and node is not None:
            column = self.s.node(node)
        raise ExprError(message, column, hint, self.s.text)

    def refuse(self, what: str, node: ast.AST, hint: str | None = None, column: int | None = None):
        self.fail(
            f"{what} is not allowed in an expression; allowed: {ALLOWED}",
            node,
            hint or _ONE_CONDITION,
            column,
        )

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
                self.fail(
                    "the operator '~' is not allowed; unary operators are -, + and not",
                    node,
                    hint="write `not`",
                )
            self.check(node.operand, d)
        elif isinstance(node, ast.BinOp):
            op = type(node.op)
            if op not in BINOPS:
                sym = _OTHER_BINOPS.get(op, op.__name__)
                self.fail(
                    f"the operator '{sym}' is not allowed; arithmetic is limited to + - * / %",
                    node,
                    hint=_INSTEAD.get(sym),
                    column=self.s.between(node.left, node.right, sym),
                )
            self.check(node.left, d)
            self.check(node.right, d)
        elif isinstance(node, ast.Compare):
            left = node.left
            for op, right in zip(node.ops, node.comparators, strict=True):
                if type(op) not in CMPOPS:
                    sym = _OTHER_CMPOPS.get(type(op), type(op).__name__)
                    self.fail(
                        f"the comparison '{sym}' is not allowed; comparisons are < <= > >= == !=",
                        node,
                        hint=_INSTEAD.get(sym),
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
                self.fail(
                    f"{kind} is not allowed; constants are numbers, strings and True/False",
                    node,
                    hint="compare with a number or a string: frame_id == 'map', len(ranges) > 0",
                )
        elif is_path(node):
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
                if not is_path(cur.value):
                    self.fail(
                        f"'.{cur.attr}' follows {_what(cur.value)}; fields are read from a field path "
                        "that starts at a message field (pose.pose.position.x)",
                        cur,
                        column=self.s.attr(cur),
                    )
                cur = cur.value
                continue
            if isinstance(cur, ast.Subscript):
                i = index_value(cur.slice)
                if i is None:
                    self.index_error(cur)
                segments.append((i, self.s.node(cur.slice)))  # type: ignore[arg-type]
                if not is_path(cur.value):
                    self.fail(
                        f"an index follows {_what(cur.value)}; only field paths can be indexed (position[0])",
                        cur,
                    )
                cur = cur.value
                continue
            raise AssertionError(cur)  # pragma: no cover - is_path() was checked
        self.paths.append(FieldPath(tuple(reversed(segments)), use, self.s.node(node), node))

    def name(self, name: str, node: ast.AST) -> None:
        if name.startswith("_"):
            self.fail(
                f"names starting with '_' are not allowed; found {name!r}",
                node,
                hint="read message fields: pose.pose.position.x",
            )
        if not _IDENTIFIER.match(name):
            self.fail(
                f"field names are plain ASCII identifiers (letters, digits, '_'); found {name!r}",
                node,
                hint="write the field's name as its message definition does: ranges, pose.position.x",
            )

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
                near = closest(func.attr, REDUCERS)
                self.fail(
                    f"calls are limited to {CALLS_ALLOWED}; found a call to '.{func.attr}()'",
                    node,
                    hint=f"did you mean '.{near}()'?" if near else "reduce a sequence: ranges.min() > 0.25",
                    column=self.s.attr(func),
                )
            shown = f".{func.attr}()"
        elif isinstance(func, ast.Name):
            if func.id not in FUNCTIONS:
                near = closest(func.id, FUNCTIONS) or (f".{r}" if (r := closest(func.id, REDUCERS)) else None)
                self.fail(
                    f"calls are limited to {CALLS_ALLOWED}; found a call to {func.id!r}",
                    func,
                    hint=(
                        f"did you mean {near.lstrip('.')!r}? (as a method: ranges{near}())"
                        if near and near.startswith(".")
                        else f"did you mean {near!r}?"
                        if near
                        else "functions: abs(x), len(seq), min/max(seq or a, b); reducers: .mean() .std()"
                    ),
                )
            shown = f"{func.id}()"
        else:
            self.fail(
                f"calls are limited to {CALLS_ALLOWED}; found a call to {_what(func)}",
                func,
                hint="call abs, len, min or max by name, or a reducer on a field: ranges.min()",
            )
        for kw in node.keywords:
            found = f"'{kw.arg}='" if kw.arg else "'**'"
            self.fail(
                f"{shown} takes no keyword arguments; found {found}",
                kw,
                hint=f"write {shown} with plain arguments",
            )
        for a in node.args:
            if isinstance(a, ast.Starred):
                self.fail(
                    f"{shown} takes no starred arguments (*x)",
                    a,
                    hint="give the sequence itself: max(ranges)",
                )
        n = len(node.args)
        if isinstance(func, ast.Attribute):
            if n:
                self.fail(f"{shown} takes no arguments; found {n}", node.args[0], hint=f"write ranges{shown}")
            self.operand(func.value, func.attr, depth)
        elif func.id in ("abs", "len"):  # type: ignore[union-attr]
            if n != 1:
                self.fail(f"{shown} takes one argument; found {n}", node, hint=f"e.g. {shown[:-2]}(ranges)")
            self.operand(node.args[0], "len" if func.id == "len" else "value", depth)  # type: ignore[union-attr]
        else:
            if n not in (1, 2):
                self.fail(
                    f"{shown} takes one argument (a sequence) or two (numbers); found {n}",
                    node,
                    hint=f"{shown[:-2]}(ranges) or {shown[:-2]}(a, b); nest them for more",
                )
            if n == 1:
                self.operand(node.args[0], func.id, depth)  # type: ignore[union-attr]
            else:
                for a in node.args:
                    self.check(a, depth)

    def operand(self, node: ast.AST, use: str, depth: int) -> None:
        if is_path(node):
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


def _syntax_error(e: SyntaxError, source: Source) -> ExprError:
    text = source.text
    if not text.strip():
        return ExprError(
            "the expression is empty",
            None,
            "write a condition such as ranges.min() > 0.25",
            text,
        )
    # SyntaxError.offset counts characters from 1; 0 means "at the end of the text"
    col = source.shift + (e.offset if e.offset and e.offset > 0 else len(source.src.rstrip()) + 1)
    hint = None
    if re.match(r"\s*(import|from)\s", text):
        what = "an import statement is not allowed"
        hint = _ONE_CONDITION
    elif ":=" in text:
        what = "an assignment (:=) is not allowed"
        hint = "compare with == (an expression assigns nothing)"
    else:
        what = f"invalid expression ({e.msg or 'invalid syntax'})"
        if "&&" in text or "||" in text:
            hint = "write `and` and `or`"
        elif re.search(r"![^=]", text):
            hint = "write `not x` (and `!=` for 'not equal')"
        elif re.search(r"(?<![<>=!])=(?!=)", text):
            hint = "compare with == (a single = assigns)"
        elif text.count("(") != text.count(")") or text.count("[") != text.count("]"):
            hint = "close every ( and [ you open"
        else:
            hint = "a condition such as ranges.min() > 0.25 and abs(twist.twist.linear.x) < 0.5"
    return ExprError(f"{what}; allowed: {ALLOWED}", col, hint, text)


def compile_expr(text: str) -> Expr:
    """Parse and check `text`; raises ExprError for anything outside the language."""
    if not isinstance(text, str):
        raise ExprError(f"an expression is a string; found {type(text).__name__}")
    source = Source(text)
    try:
        tree = ast.parse(source.src, mode="eval")
    except SyntaxError as e:
        raise _syntax_error(e, source) from None
    except (RecursionError, MemoryError):
        raise ExprError("the expression is nested too deeply", None, None, text) from None
    checker = _Checker(source)
    checker.check(tree)
    return Expr(text, tree, source, tuple(checker.paths))
