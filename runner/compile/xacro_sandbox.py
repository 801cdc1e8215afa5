"""xacro's expressions (`${...}`, `$(eval ...)`) evaluated by walking their syntax tree ourselves.

xacro 2.1.1 compiles an expression and `eval`s it with `__builtins__` emptied, refusing only `__` names of
the top-level code object (xacro/__init__.py `safe_eval`); `$(eval ...)` even runs with the real builtins
(xacro/substitution_args.py `_eval`). A lambda's nested code object, a comprehension, `python.type` or
`python.vars` reach Python's internals from there, and `open(...)` runs in `$(eval)`. A description is a
file users download from anywhere and CI expands on pull requests, so we never hand its text to Python's
`eval`: `Sandbox` parses it with `ast` and interprets a small whitelist of node kinds itself.

What an expression can reach: constants; the properties and arguments xacro passes in; a fixed set of
functions (the builtins and math functions xacro exposes, less `type` and `vars`, with the ones that can
allocate without end bounded) and xacro's helpers (`xacro.load_yaml` only inside the folders the scenario
trusts, checked before the file is opened). Attribute access is a lookup in xacro's namespaces and YAML
dictionaries, or one of a few methods of strings, lists and dictionaries; a name or attribute starting with
an underscore is refused (Python's parser has already folded `＿＿class＿＿` into `__class__`). Every value
an expression builds is weighed: strings, lists and integers past a bound are refused before they are
built where they could be built big at once (`'a' * 10**10`, `10**10**10`, `range(10**12)`), and an
expansion that spends too much evaluating is stopped.
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Callable, Iterable
from typing import Any

import xacro
import xacro.substitution_args as _sa

from runner.compile.xacro_eval import BINOPS, Bound, Interpreter

# xacro's own helpers (message, warning, error, print_location, fatal, arg), taken before any expansion
# replaces its global symbols by ours
_XACRO_HELPERS: dict[str, Any] = dict(xacro._global_symbols["xacro"])

MAX_WEIGHT = 1_000_000  # characters of a string, items of a value counted through its nesting
MAX_INT_BITS = 16_384  # an integer's size (10**4932)
MAX_LENGTH = 10_000  # characters of one expression
MAX_DEPTH = 100  # nesting of its syntax tree
# nodes evaluated and items weighed in one expansion: the UR30 arm's description spends 17,000; the
# bound is reached in about 10 s on a loaded 2-core machine
MAX_WORK = 5_000_000
MAX_ROUND_DIGITS = 1_000
MAX_FACTORIAL = 1_000  # math.factorial, comb, perm: their argument

HINT = (
    "an expression in a robot description may use numbers, strings, arithmetic, comparisons, "
    "`x if c else y`, list/dict literals and indexing, math functions (sqrt, radians, pi...), a few "
    "builtins (len, str, int, float, min, max, round, abs, sum, sorted, range...), a few string and "
    "dict methods, properties, and xacro's helpers (xacro.load_yaml, xacro.arg...); nothing that "
    "reaches Python itself"
)

# printf-style `%` formatting: a width or precision past 3 digits, or taken from the arguments (`*`)
_WIDE_FORMAT = re.compile(r"%[^a-zA-Z%]*(?:\*|\d{4,})")


class SandboxError(Exception):
    """An expression that is not allowed (or not an expression); `expr` is its text."""

    def __init__(self, why: str, expr: str, opener: str = "${", hint: str = HINT):
        super().__init__(why)
        self.why = why
        self.expr = expr
        self.opener = opener  # how the expression starts in the file: "${" or "$(eval "
        self.hint = hint


class Sandbox:
    """One expansion's evaluator. `load_yaml` is xacro's, already limited to the trusted folders."""

    def __init__(self, load_yaml: Callable[[str], Any]):
        self.work = 0
        self.expr = ""  # the expression being evaluated, for errors
        self.opener = "${"
        self.allowed: set[int] = set()  # ids of the callables an expression may call...
        self._keep: list[Any] = []  # ...kept alive, so that no other object takes one of their ids
        self.root = self._root(load_yaml)
        self._collect(self.root)

    # --- what expressions see -------------------------------------------------------------------------

    def _root(self, load_yaml: Callable[[str], Any]) -> dict[str, Any]:
        """xacro's global symbols (xacro/__init__.py `create_global_symbols`) without `python.type` and
        `python.vars`, with bounded versions of what can allocate without end."""
        x = xacro
        builtins: dict[str, Any] = {
            "list": list, "dict": dict, "map": self._map, "len": len, "str": str, "float": float,
            "int": int, "bool": bool, "True": True, "False": False, "min": min, "max": max,
            "round": self._round,
        }  # fmt: skip
        python = dict(builtins)
        python.update(
            {
                "sorted": sorted, "range": self._range, "abs": abs, "all": all, "any": any,
                "complex": complex, "divmod": divmod, "enumerate": self._enumerate,
                "filter": self._filter, "frozenset": frozenset, "hash": hash, "isinstance": isinstance,
                "issubclass": issubclass, "ord": ord, "repr": repr, "reversed": self._reversed,
                "slice": slice, "set": set, "sum": sum, "tuple": tuple, "zip": self._zip, "pow": self._pow,
            }
        )  # fmt: skip
        maths = {k: v for k, v in vars(math).items() if not k.startswith("_")}
        maths.update(
            factorial=self._factorial, comb=self._comb, perm=self._perm, prod=self._prod, lcm=self._lcm
        )
        helpers = {
            k: _XACRO_HELPERS[k] for k in ("message", "warning", "error", "print_location", "fatal", "arg")
        }
        helpers.update(
            load_yaml=load_yaml,
            abs_filename=x.abs_filename_spec,
            dotify=x.YamlDictWrapper,
            tokenize=_tokenize,
        )
        root: dict[str, Any] = dict(builtins)
        # kept at the top level by xacro for compatibility (it warns they are deprecated)
        root.update(sorted=sorted, range=self._range, load_yaml=load_yaml, abs_filename=x.abs_filename_spec)
        root.update(dotify=x.YamlDictWrapper)
        root.update(maths)
        for name, content in (("python", python), ("math", maths), ("xacro", helpers)):
            ns = x.NameSpace()
            dict.update(ns, content)
            root[name] = ns
        return root

    def _collect(self, values: dict[str, Any]) -> None:
        for v in dict.values(values):
            if isinstance(v, dict):
                self._collect(v)
            elif callable(v):
                self.allowed.add(id(v))
                self._keep.append(v)

    def substitution_eval(self, s: str, context: dict[str, Any]) -> str:
        """`$(eval ...)` (xacro/substitution_args.py `_eval`, which runs with Python's builtins): the
        names it offers, arg(), dirname(), the booleans, list/dict/map/str/float/int, env/optenv/find,
        math, then the xacro arguments by name."""
        args = context.setdefault("arg", {})
        functions: dict[str, Any] = {
            "arg": lambda name: _sa.convert_value(_sa._eval_arg(name, args=args), "auto"),
            "dirname": lambda: _sa._eval_dirname(context["filename"]),
            "env": _sa._eval_dict["env"], "optenv": _sa._eval_dict["optenv"], "find": _sa._eval_dict["find"],
        }  # fmt: skip
        self._collect(functions)
        functions.update(self.root["math"].items())
        functions.update(
            true=True, false=False, list=list, dict=dict, map=self._map, str=str, float=float, int=int
        )
        functions["True"], functions["False"] = True, False

        def lookup(name: str) -> Any:
            if name in functions:
                return functions[name]
            return _sa.convert_value(args[name], "auto")

        return str(self.evaluate(s, lookup, opener="$(eval "))

    # --- entry points ----------------------------------------------------------------------------------

    def safe_eval(self, expr: Any, symbols: Any, locals: Any = None) -> Any:
        """xacro's `safe_eval(expr, globals, locals)` (xacro/__init__.py): `${...}`, and units in YAML."""
        return self.evaluate(expr, symbols.__getitem__)

    def evaluate(self, expr: Any, lookup: Callable[[str], Any], opener: str = "${") -> Any:
        """The value of `expr`, its names found by `lookup` (KeyError: not defined)."""
        if not isinstance(expr, str):
            expr = str(expr)
        text = expr.strip()
        outer = self.expr, self.opener
        self.expr, self.opener = text, opener
        try:
            if len(text) > MAX_LENGTH:
                raise self.refuse(f"an expression longer than {MAX_LENGTH} characters")
            try:
                tree = ast.parse(text, mode="eval")
            except SyntaxError as e:
                raise SandboxError(
                    f"not a valid expression ({e.msg})",
                    text,
                    opener,
                    "check the brackets, quotes and operators",
                ) from None
            except (RecursionError, MemoryError, ValueError):
                raise self.refuse("an expression nested too deeply") from None
            self._check_depth(tree)
            return self.checked(Interpreter(self, lookup).eval(tree.body))
        finally:
            self.expr, self.opener = outer

    def _check_depth(self, tree: ast.AST) -> None:
        stack: list[tuple[ast.AST, int]] = [(tree, 0)]
        while stack:
            node, depth = stack.pop()
            if depth > MAX_DEPTH:
                raise self.refuse(f"an expression nested more than {MAX_DEPTH} levels deep")
            stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))

    # --- bounds ------------------------------------------------------------------------------------------

    def spend(self, units: int) -> None:
        self.work += units
        if self.work > MAX_WORK:
            raise SandboxError(
                f"expressions that take more than {MAX_WORK} steps to evaluate are not allowed in a robot "
                "description",
                self.expr,
                self.opener,
            )

    def refuse(self, why: str) -> SandboxError:
        return SandboxError(f"{why} is not allowed in a robot description", self.expr, self.opener)

    def weigh(self, value: Any, limit: int = MAX_WEIGHT) -> int:
        """Characters and items of `value` through its nesting (shared parts counted each time they
        appear, as `str()` would print them), stopping past `limit`."""
        total = 0
        stack = [value]
        while stack and total <= limit:
            v = stack.pop()
            if isinstance(v, str | bytes):
                total += len(v) + 1
            elif isinstance(v, int):
                total += v.bit_length() // 64 + 1
            elif isinstance(v, dict):
                total += 1 + len(v)
                stack.extend(dict.keys(v))
                stack.extend(dict.values(v))
            elif isinstance(v, list | tuple | set | frozenset):
                total += 1 + len(v)
                stack.extend(list.__iter__(v) if isinstance(v, list) else iter(v))
            else:
                total += 1
        self.spend(total)
        return total

    def checked(self, value: Any) -> Any:
        if isinstance(value, int) and value.bit_length() > MAX_INT_BITS:
            raise self.refuse(f"an integer of more than {MAX_INT_BITS} bits")
        if isinstance(value, str | bytes | list | tuple | dict | set | frozenset) and (
            self.weigh(value) > MAX_WEIGHT
        ):
            raise self.refuse(f"a value of more than {MAX_WEIGHT} characters or items")
        return value

    def bounded_list(self, items: Iterable[Any]) -> list[Any]:
        out: list[Any] = []
        weight = 0
        for item in items:
            weight += self.weigh(item) + 1
            if weight > MAX_WEIGHT:
                raise self.refuse(f"a list of more than {MAX_WEIGHT} characters or items")
            out.append(item)
        return out

    def check_callable(self, f: Any) -> None:
        if isinstance(f, Bound) or id(f) in self.allowed:
            return
        raise self.refuse(f"calling {_describe(f)}")

    # --- bounded builtins ----------------------------------------------------------------------------

    def _range(self, *args: int) -> range:
        r = range(*args)
        try:
            n = len(r)
        except OverflowError:
            n = MAX_WEIGHT + 1
        if n > MAX_WEIGHT:
            raise self.refuse(f"a range of more than {MAX_WEIGHT} numbers")
        return r

    def _pow(self, base: Any, exp: Any, mod: Any = None) -> Any:
        if mod is None:
            return self.binop(ast.Pow(), base, exp)
        return pow(base, exp, mod)

    def _round(self, x: Any, ndigits: int | None = None) -> Any:
        if ndigits is None:
            return round(x)
        if isinstance(ndigits, int) and abs(ndigits) > MAX_ROUND_DIGITS:
            raise self.refuse(f"round() to more than {MAX_ROUND_DIGITS} digits")
        return round(x, ndigits)

    def _small(self, name: str, *ns: Any) -> None:
        for n in ns:
            if isinstance(n, int) and n > MAX_FACTORIAL:
                raise self.refuse(f"math.{name}() of a number above {MAX_FACTORIAL}")

    def _factorial(self, n: int) -> int:
        self._small("factorial", n)
        return math.factorial(n)

    def _comb(self, n: int, k: int) -> int:
        self._small("comb", n, k)
        return math.comb(n, k)

    def _perm(self, n: int, k: int | None = None) -> int:
        self._small("perm", n, *(() if k is None else (k,)))
        return math.perm(n, k)

    def _prod(self, iterable: Iterable[Any], *, start: Any = 1) -> Any:
        out = start
        for x in self.bounded_list(iterable):
            out = self.checked(self.binop(ast.Mult(), out, x))
        return out

    def _lcm(self, *ints: int) -> int:
        out = 1
        for x in ints:
            if _is_int(x) and out.bit_length() + x.bit_length() > MAX_INT_BITS:  # lcm(a, b) <= a * b
                raise self.refuse(f"an integer of more than {MAX_INT_BITS} bits")
            out = math.lcm(out, x)
        return out

    def _map(self, f: Any, *iterables: Iterable[Any]) -> list[Any]:
        # a list, not a lazy map: every value an expression holds is one we could weigh
        self.check_callable(f)
        return self.bounded_list(map(self.metered(f), *iterables))

    def _filter(self, f: Any, iterable: Iterable[Any]) -> list[Any]:
        if f is not None:
            self.check_callable(f)
        return self.bounded_list(filter(None if f is None else self.metered(f), iterable))

    def _zip(self, *iterables: Iterable[Any]) -> list[Any]:
        return self.bounded_list(zip(*iterables, strict=False))

    def _enumerate(self, iterable: Iterable[Any], start: int = 0) -> list[Any]:
        return self.bounded_list(enumerate(iterable, start))

    def _reversed(self, seq: Any) -> list[Any]:
        return self.bounded_list(reversed(seq))

    # --- operators and methods with a size that the operands do not bound ----------------------------

    def binop(self, op: ast.operator, a: Any, b: Any) -> Any:
        if isinstance(op, ast.Mult):
            self._check_repeat(a, b)
            self._check_repeat(b, a)
            if _is_int(a) and _is_int(b) and a.bit_length() + b.bit_length() > MAX_INT_BITS:
                raise self.refuse(f"an integer of more than {MAX_INT_BITS} bits")
        elif isinstance(op, ast.Pow):
            if (
                _is_int(a)
                and _is_int(b)
                and b > 0
                and abs(a) > 1
                and (b > MAX_INT_BITS or b * (abs(a).bit_length() - 1) > MAX_INT_BITS)
            ):
                raise self.refuse(f"an integer of more than {MAX_INT_BITS} bits")
        elif isinstance(op, ast.LShift):
            if _is_int(a) and _is_int(b) and a and b > 0 and a.bit_length() + b > MAX_INT_BITS:
                raise self.refuse(f"an integer of more than {MAX_INT_BITS} bits")
        elif isinstance(op, ast.Mod) and isinstance(a, str | bytes):
            fmt = a if isinstance(a, str) else a.decode("latin-1")
            if _WIDE_FORMAT.search(fmt):
                raise self.refuse("a %-format with a width or precision above 999")
        elif isinstance(op, ast.MatMult):
            raise self.refuse("the @ operator")
        return BINOPS[type(op)](a, b)

    def _check_repeat(self, seq: Any, n: Any) -> None:
        if (
            isinstance(seq, str | bytes | list | tuple)
            and _is_int(n)
            and n > 0
            and (n > MAX_WEIGHT or self.weigh(seq) * n > MAX_WEIGHT)
        ):
            raise self.refuse(f"a value of more than {MAX_WEIGHT} characters or items")

    def metered(self, f: Callable[..., Any]) -> Callable[..., Any]:
        """`f` as a builtin calls it (map, filter, sorted's key): each call spent, its result weighed."""

        def call(*args: Any) -> Any:
            self.spend(1)
            return self.checked(f(*args))

        return call

    def method(self, obj: Any, name: str, args: tuple[Any, ...], kwargs: dict[str, Any]) -> Any:
        self.weigh(obj)  # s.count(x) scans s
        for a in (*args, *kwargs.values()):
            if callable(a):
                self.check_callable(a)
        if isinstance(obj, str) and name == "join":
            (items,) = args
            parts = self.bounded_list(items)
            if sum(len(p) for p in parts if isinstance(p, str)) + len(obj) * len(parts) > MAX_WEIGHT:
                raise self.refuse(f"a string of more than {MAX_WEIGHT} characters")
            return obj.join(parts)
        if isinstance(obj, str) and name == "replace" and len(args) >= 2:
            old, new = args[0], args[1]
            if isinstance(old, str) and isinstance(new, str):
                n = obj.count(old) if old else len(obj) + 1
                if len(obj) + n * max(0, len(new) - len(old)) > MAX_WEIGHT:
                    raise self.refuse(f"a string of more than {MAX_WEIGHT} characters")
        result = getattr(obj, name)(*args, **kwargs)
        if name in ("keys", "values", "items"):
            result = self.bounded_list(result)
        return self.checked(result)


def _tokenize(s: str, sep: str = ",; ", skip_empty: bool = True) -> list[str]:
    """xacro.tokenize (xacro/__init__.py) with `sep` taken as characters: xacro builds a regular
    expression from it, which a description could make backtrack without end."""
    results = re.split("[" + "".join(re.escape(c) for c in sep) + "]", s)
    return [item for item in results if item] if skip_empty else results


def _is_int(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _describe(f: Any) -> str:
    name = getattr(type(f), "__name__", "?")
    return f"a {name} that is not one of the functions a description may call"
