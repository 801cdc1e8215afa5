"""The interpreter of one xacro expression's syntax tree, for the sandbox (xacro_sandbox.py): every
node kind it does not handle is refused; what it may call, and how big a value may grow, the sandbox says.
"""

from __future__ import annotations

import ast
import re
from collections.abc import Callable, Iterable, Iterator
from typing import Any, Protocol

import xacro


class Host(Protocol):
    """What the interpreter asks of the sandbox."""

    def spend(self, units: int) -> None: ...
    def refuse(self, why: str) -> Exception: ...
    def checked(self, value: Any) -> Any: ...
    def bounded_list(self, items: Iterable[Any]) -> list[Any]: ...
    def check_callable(self, f: Any) -> None: ...
    def weigh(self, value: Any) -> int: ...
    def metered(self, f: Callable[..., Any]) -> Callable[..., Any]: ...
    def binop(self, op: ast.operator, a: Any, b: Any) -> Any: ...
    def method(self, obj: Any, name: str, args: tuple[Any, ...], kwargs: dict[str, Any]) -> Any: ...


# Names whose absence the user should read as "refused", not "a typo" (when no property has the name).
_DANGEROUS_NAMES = frozenset(
    {
        "eval",
        "exec",
        "compile",
        "open",
        "getattr",
        "setattr",
        "delattr",
        "hasattr",
        "vars",
        "type",
        "globals",
        "dir",
        "__import__",
        "breakpoint",
        "help",
        "exit",
        "quit",
        "input",
        "print",
        "object",
        "super",
        "memoryview",
        "bytearray",
        "classmethod",
        "staticmethod",
        "property",
        "id",
        "format",
        "iter",
        "next",
        "callable",
        "chr",
    }
)

_WHAT = {
    ast.Lambda: "a lambda",
    ast.NamedExpr: "an assignment expression (:=)",
    ast.Await: "await",
    ast.Yield: "yield",
    ast.YieldFrom: "yield",
}

_STR_METHODS = frozenset(
    {
        "split",
        "rsplit",
        "join",
        "replace",
        "strip",
        "lstrip",
        "rstrip",
        "lower",
        "upper",
        "title",
        "capitalize",
        "swapcase",
        "casefold",
        "startswith",
        "endswith",
        "find",
        "rfind",
        "index",
        "rindex",
        "count",
        "isdigit",
        "isnumeric",
        "isdecimal",
        "isalpha",
        "isalnum",
        "isspace",
        "islower",
        "isupper",
        "istitle",
        "splitlines",
        "partition",
        "rpartition",
        "removeprefix",
        "removesuffix",
    }
)
_DICT_METHODS = frozenset({"get", "keys", "values", "items"})
_SEQ_METHODS = frozenset({"index", "count"})

_FORMAT_SPEC = re.compile(r"^[<>^=]?[+\- ]?#?0?\d{0,3}[,_]?(?:\.\d{1,3})?[bcdeEfFgGnosxX%]?$")


BINOPS: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.FloorDiv: lambda a, b: a // b,
    ast.Mod: lambda a, b: a % b,
    ast.Pow: lambda a, b: a**b,
    ast.LShift: lambda a, b: a << b,
    ast.RShift: lambda a, b: a >> b,
    ast.BitOr: lambda a, b: a | b,
    ast.BitXor: lambda a, b: a ^ b,
    ast.BitAnd: lambda a, b: a & b,
}
_CMPOPS: dict[type[ast.cmpop], Callable[[Any, Any], bool]] = {
    ast.Eq: lambda a, b: a == b,
    ast.NotEq: lambda a, b: a != b,
    ast.Lt: lambda a, b: a < b,
    ast.LtE: lambda a, b: a <= b,
    ast.Gt: lambda a, b: a > b,
    ast.GtE: lambda a, b: a >= b,
    ast.Is: lambda a, b: a is b,
    ast.IsNot: lambda a, b: a is not b,
    ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
}


class Bound:
    """A whitelisted method of a string, list or dict (`s.split`): callable, nothing else reachable."""

    __slots__ = ("name", "obj", "sandbox")

    def __init__(self, obj: Any, name: str, sandbox: Host):
        self.obj = obj
        self.name = name
        self.sandbox = sandbox

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.sandbox.method(self.obj, self.name, args, kwargs)

    def __repr__(self) -> str:
        return f"<method {self.name}>"


class Interpreter:
    """The interpreter of one expression's tree: every node kind not handled here is refused."""

    def __init__(self, sandbox: Host, lookup: Callable[[str], Any]):
        self.s = sandbox
        self.lookup = lookup
        self.scopes: list[dict[str, Any]] = []  # the loop variables of the comprehensions being evaluated

    def eval(self, node: ast.AST) -> Any:
        self.s.spend(1)
        handler = getattr(self, "_" + type(node).__name__, None)
        if handler is None:
            what = _WHAT.get(type(node), f"a {type(node).__name__} expression")
            raise self.s.refuse(what)
        return handler(node)

    def _Constant(self, node: ast.Constant) -> Any:
        return node.value

    def _Name(self, node: ast.Name) -> Any:
        name = node.id
        if name.startswith("__"):
            raise self.s.refuse(f"the name {name!r}")
        for scope in reversed(self.scopes):
            if name in scope:
                return scope[name]
        try:
            return self.lookup(name)
        except KeyError:
            if name in _DANGEROUS_NAMES:
                raise self.s.refuse(f"{name}()") from None
            raise NameError(f"name '{name}' is not defined") from None

    def _BinOp(self, node: ast.BinOp) -> Any:
        a = self.eval(node.left)
        b = self.eval(node.right)
        return self.s.checked(self.s.binop(node.op, a, b))

    def _UnaryOp(self, node: ast.UnaryOp) -> Any:
        v = self.eval(node.operand)
        if isinstance(node.op, ast.Not):
            return not v
        if isinstance(node.op, ast.USub):
            return -v
        if isinstance(node.op, ast.UAdd):
            return +v
        return ~v

    def _BoolOp(self, node: ast.BoolOp) -> Any:
        value: Any = None
        for operand in node.values:
            value = self.eval(operand)
            if isinstance(node.op, ast.And) and not value:
                return value
            if isinstance(node.op, ast.Or) and value:
                return value
        return value

    def _Compare(self, node: ast.Compare) -> Any:
        left = self.eval(node.left)
        for op, right_node in zip(node.ops, node.comparators, strict=True):
            right = self.eval(right_node)
            self.s.weigh(right)  # `x in big`, `big == other` scan: spent from the expansion's work
            if not _CMPOPS[type(op)](left, right):
                return False
            left = right
        return True

    def _IfExp(self, node: ast.IfExp) -> Any:
        return self.eval(node.body) if self.eval(node.test) else self.eval(node.orelse)

    def _Subscript(self, node: ast.Subscript) -> Any:
        value = self.eval(node.value)
        key = self.eval(node.slice)
        if isinstance(key, str) and key.startswith("_") and isinstance(value, xacro.Table):
            raise self.s.refuse(f"the name {key!r}")
        return self.s.checked(value[key]) if isinstance(key, slice) else value[key]

    def _Slice(self, node: ast.Slice) -> slice:
        part = [None if n is None else self.eval(n) for n in (node.lower, node.upper, node.step)]
        return slice(*part)

    def _items(self, elts: list[ast.expr]) -> list[Any]:
        out: list[Any] = []
        for e in elts:
            if isinstance(e, ast.Starred):
                out.extend(self.s.bounded_list(self.eval(e.value)))
            else:
                out.append(self.eval(e))
        return out

    def _List(self, node: ast.List) -> Any:
        return self.s.checked(self._items(node.elts))

    def _Tuple(self, node: ast.Tuple) -> Any:
        return self.s.checked(tuple(self._items(node.elts)))

    def _Set(self, node: ast.Set) -> Any:
        return self.s.checked(set(self._items(node.elts)))

    def _Dict(self, node: ast.Dict) -> Any:
        out: dict[Any, Any] = {}
        for k, v in zip(node.keys, node.values, strict=True):
            if k is None:
                out.update(self.eval(v))
            else:
                out[self.eval(k)] = self.eval(v)
        return self.s.checked(out)

    # Comprehensions (xacro's own tests use them: `[2*item.val.x for item in xacro.load_yaml(...)]`) are
    # loops of this interpreter, not code objects: what they iterate is a value we weighed, what they
    # build is weighed as it grows, and each step is spent from the expansion's work.

    def _ListComp(self, node: ast.ListComp) -> Any:
        return self.s.bounded_list(self._generate(node.generators, lambda: self.eval(node.elt)))

    def _GeneratorExp(self, node: ast.GeneratorExp) -> Any:
        return self.s.bounded_list(self._generate(node.generators, lambda: self.eval(node.elt)))

    def _SetComp(self, node: ast.SetComp) -> Any:
        return self.s.checked(set(self._ListComp(node)))  # type: ignore[arg-type]

    def _DictComp(self, node: ast.DictComp) -> Any:
        pairs = self._generate(node.generators, lambda: (self.eval(node.key), self.eval(node.value)))
        return self.s.checked(dict(self.s.bounded_list(pairs)))

    def _generate(self, generators: list[ast.comprehension], element: Callable[[], Any]) -> Iterator[Any]:
        first, rest = generators[0], generators[1:]
        if first.is_async:
            raise self.s.refuse("async")
        scope: dict[str, Any] = {}
        self.scopes.append(scope)
        try:
            for item in self.eval(first.iter):  # evaluated outside the new variables, as Python does
                self.s.spend(1)
                self._bind(first.target, item, scope)
                if all(self.eval(test) for test in first.ifs):
                    if rest:
                        yield from self._generate(rest, element)
                    else:
                        yield element()
        finally:
            del self.scopes[next(i for i, x in enumerate(self.scopes) if x is scope)]

    def _bind(self, target: ast.expr, value: Any, scope: dict[str, Any]) -> None:
        if isinstance(target, ast.Name) and not target.id.startswith("__"):
            scope[target.id] = value
        elif isinstance(target, ast.Tuple | ast.List) and not any(
            isinstance(e, ast.Starred) for e in target.elts
        ):
            values = list(value)
            if len(values) != len(target.elts):
                raise ValueError(f"cannot unpack {len(values)} values into {len(target.elts)} names")
            for t, v in zip(target.elts, values, strict=True):
                self._bind(t, v, scope)
        else:
            raise self.s.refuse("a loop variable that is not a plain name")

    def _Attribute(self, node: ast.Attribute) -> Any:
        name = node.attr
        if name.startswith("_"):
            raise self.s.refuse(f"the attribute {name!r}")
        obj = self.eval(node.value)
        if isinstance(obj, xacro.Table):  # xacro's namespaces: python, math, xacro, include ns=
            try:
                return obj[name]
            except KeyError:
                if name in _DANGEROUS_NAMES or name in ("type", "vars"):
                    raise self.s.refuse(f"{name}()") from None
                raise NameError(f"name '{name}' is not defined") from None
        if isinstance(obj, dict) and name in _DICT_METHODS:
            return Bound(obj, name, self.s)
        if isinstance(obj, xacro.YamlDictWrapper):  # dotted access to a YAML key
            return obj[name]
        if isinstance(obj, str) and name in _STR_METHODS:
            return Bound(obj, name, self.s)
        if isinstance(obj, list | tuple) and name in _SEQ_METHODS:
            return Bound(obj, name, self.s)
        raise self.s.refuse(f"the attribute {name!r} of {_article(obj)}")

    def _Call(self, node: ast.Call) -> Any:
        f = self.eval(node.func)
        self.s.check_callable(f)
        args = self._items(node.args)
        kwargs: dict[str, Any] = {}
        for kw in node.keywords:
            if kw.arg is None:
                kwargs.update(self.eval(kw.value))
            else:
                kwargs[kw.arg] = self.eval(kw.value)
        for a in (*args, *kwargs.values()):
            if callable(a):  # map(f, ...), sorted(key=f): f runs too
                self.s.check_callable(a)
            self.s.weigh(a)  # a call costs what it reads (max(x) scans x): spent from the expansion's work
        if callable(kwargs.get("key")):  # sorted(x, key=list): each key it makes is weighed and spent
            kwargs["key"] = self.s.metered(kwargs["key"])
        return self.s.checked(f(*args, **kwargs))

    def _JoinedStr(self, node: ast.JoinedStr) -> Any:
        out = []
        for part in node.values:
            if isinstance(part, ast.Constant):
                out.append(str(part.value))
            else:
                out.append(self.eval(part))
        return self.s.checked("".join(out))

    def _FormattedValue(self, node: ast.FormattedValue) -> str:
        value = self.eval(node.value)
        spec = ""
        if node.format_spec is not None:
            parts = node.format_spec.values if isinstance(node.format_spec, ast.JoinedStr) else []
            if not all(isinstance(p, ast.Constant) for p in parts):
                raise self.s.refuse("an f-string format computed from an expression")
            spec = "".join(str(p.value) for p in parts if isinstance(p, ast.Constant))
            if not _FORMAT_SPEC.match(spec):
                raise self.s.refuse(f"the f-string format {spec!r}")
        value = self.s.checked(value)
        if node.conversion == ord("r"):
            value = repr(value)
        elif node.conversion == ord("a"):
            value = ascii(value)
        elif node.conversion == ord("s"):
            value = str(value)
        if not isinstance(value, str | int | float | complex | bool) and value is not None:
            value = str(value)
        return format(value, spec)


def _article(obj: Any) -> str:
    name = type(obj).__name__
    return f"an {name}" if name[:1] in "aeiou" else f"a {name}"
