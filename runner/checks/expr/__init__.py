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

The language in parts: `language` (what it allows, its error, columns in the text), `parse` (checking the
tree: `compile_expr`), `evaluate` (`Expr`, on a message) and `fields` (`check_fields`, against a message
type without a message).
"""

from runner.checks.expr.evaluate import Expr
from runner.checks.expr.fields import check_fields
from runner.checks.expr.language import ExprError
from runner.checks.expr.parse import compile_expr

__all__ = ["Expr", "ExprError", "check_fields", "compile_expr"]
