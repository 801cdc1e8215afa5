"""xacro -> URDF text, with `$(find pkg)` resolved through our package map (no ROS install).

The xacro package resolves `$(find)` through ament_index_python, which is not on PyPI; we replace its
resolver. That is a private API of xacro (`xacro.substitution_args._eval_find`): this module is the only
place that touches it, and tests/compile/test_xacro.py pins the behaviour.
"""

from __future__ import annotations

import contextlib
import io
import re
import threading
import xml.parsers.expat
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import xacro
import xacro.substitution_args as _sa

from runner.compile.packages import PackageMap
from runner.errors import SourceError, did_you_mean


class XacroError(SourceError):
    """xacro could not expand the file."""


class MissingPackage(XacroError):
    pass


class IncludeCycle(XacroError):
    pass


class OutsidePackages(XacroError):
    """A description read (`<xacro:include>`, `xacro.load_yaml`) a file outside what the scenario trusts."""


_lock = threading.Lock()


@dataclass
class Expanded:
    urdf: str
    sources: list[Path]  # the xacro file and every file it included, for pointing at lines


def expand(path: Path, args: dict[str, str], packages: PackageMap) -> Expanded:
    """Run xacro on `path` with `args` (`$(arg name)`); return the URDF text and the files it read."""
    find = _package_finder(path, packages)
    real_parse = xacro.parse
    with _lock:
        saved = _sa._eval_find, _sa._eval_dict.get("find")
        _sa._eval_find = find
        _sa._eval_dict["find"] = find
        xacro.parse = _cycle_guard(real_parse)
        stderr = io.StringIO()
        xacro.all_includes = []
        try:
            with contextlib.redirect_stderr(stderr):
                doc = xacro.process_file(str(path), mappings={k: str(v) for k, v in args.items()})
            sources = [path] + [Path(f) for f in dict.fromkeys(xacro.all_includes)]
            _check_readable(sources, path, packages)
            return Expanded(doc.toprettyxml(indent="  "), sources)
        except (MissingPackage, IncludeCycle, OutsidePackages):
            raise
        except xml.parsers.expat.ExpatError as e:
            raise XacroError(
                f"not well-formed XML: {xml.parsers.expat.errors.messages.get(e.code, e)}",
                _current_file(path),
                e.lineno,
                hint="look for an unclosed tag, a stray '<' or '&'",
            ) from None
        except Exception as e:
            raise _xacro_error(e, path) from None
        finally:
            xacro.parse = real_parse
            _sa._eval_find, found = saved
            if found is not None:
                _sa._eval_dict["find"] = found


def _package_finder(path: Path, packages: PackageMap) -> Callable[[str], str]:
    """xacro's `$(find pkg)` through our package map: the package's folder, or `MissingPackage` at the
    line that asks for it."""

    def find(pkg: str) -> str:
        root = packages.find(pkg)
        if root is None:
            asker = _current_file(path)
            raise MissingPackage(
                f"package {pkg!r} not found (asked by $(find {pkg}))",
                asker,
                _line_of(asker, f"$(find {pkg})"),
                hint="add it under `packages:` in the scenario, or put its folder (with a package.xml) "
                "beside the scenario or on SCENARIO_PACKAGE_PATH; searched: "
                + ", ".join(packages.searched()),
            )
        return str(root)

    return find


def _cycle_guard(real_parse: Callable[..., Any]) -> Callable[..., Any]:
    """xacro's `parse`, stopping an include cycle (a includes b includes a) at the first file that is
    already being read: xacro itself recurses without end."""

    def parse(inp, filename=None):  # type: ignore[no-untyped-def]
        # xacro has pushed `filename` on its stack before parsing it.
        stack = list(getattr(xacro, "filestack", None) or [])
        if inp is None and filename and len(stack) > 1:
            again = _same_file_index(stack[:-1], filename)
            if again is not None:
                chain = [Path(f).name for f in stack[again:-1]] + [Path(filename).name]
                includer = Path(stack[-2])
                raise IncludeCycle(
                    "include cycle: " + " includes ".join(chain),
                    includer,
                    _line_of(includer, Path(filename).name, "include"),
                    hint="a file cannot include itself, directly or through others; remove one of the "
                    "<xacro:include> tags",
                )
        return real_parse(inp, filename)

    return parse


def _check_readable(sources: list[Path], path: Path, packages: PackageMap) -> None:
    """Every file the expansion read (`<xacro:include>`, `xacro.load_yaml`) is one the scenario trusts."""
    for read in sources[1:]:
        if not packages.readable(read, path):
            holder = next((f for f in sources if _line_of(f, read.name)), path)
            raise OutsidePackages(
                f"{read} is outside the scenario's folder and packages",
                holder,
                _line_of(holder, read.name),
                hint="a robot description may read files of the scenario's folder, its own folder "
                "and the packages (`packages:`, SCENARIO_PACKAGE_PATH); list other folders the "
                "scenario trusts under `allow_paths:`",
            )


def _xacro_error(e: Exception, path: Path) -> XacroError:
    """What xacro raised, as an error at the file and line it is about (called while xacro's file stack
    still says which file it was reading)."""
    cause = e.__cause__ or e.__context__
    if isinstance(cause, MissingPackage):
        return cause
    if isinstance(cause, IncludeCycle):
        return cause
    message = " ".join(str(e).split())
    missing = getattr(e, "exc", None)
    if isinstance(missing, FileNotFoundError) and missing.filename:
        message = f"included file not found: {missing.filename}"
    file = _current_file(path)
    sources = [path, *map(Path, xacro.all_includes)]
    macros = getattr(e, "macros", None) or []
    name = macros[0].body.getAttribute("name") if macros and hasattr(macros[0], "body") else ""
    if message.startswith("Undefined parameters") and name:
        # the call that lacks them: `<xacro:wheel .../>` (not the definition, `<xacro:macro ...>`)
        message = f"the call of macro {name!r} does not give {message.removeprefix('Undefined ')}"
        for candidate in dict.fromkeys([file, *sources]):
            line = _line_of(candidate, f"<xacro:{name}")
            if line is not None:
                return XacroError(
                    message,
                    candidate,
                    line,
                    hint='give them at the call, or defaults in the macro\'s params (params="radius:=0.05")',
                )
    if isinstance(e, RecursionError) or "maximum recursion depth" in message:
        loop = _self_calling_macro(sources)
        return XacroError(
            f"macro {loop[0]!r} calls itself without end" if loop else "xacro recursed without end",
            loop[1] if loop else file,
            loop[2] if loop else None,
            hint="a macro that calls itself needs an <xacro:if> that stops it",
        )
    file, line = _locate_message(message, file, sources)
    return XacroError(message, file, line, hint=_hint(message) or _other_hint(message, sources))


def _line_of(file: Path, needle: str, also: str = "") -> int | None:
    """The first line of `file` holding `needle` (and `also`, when given)."""
    try:
        for i, line in enumerate(file.read_text(encoding="utf-8", errors="replace").splitlines()):
            if needle in line and also in line:
                return i + 1
    except OSError:
        pass
    return None


def _self_calling_macro(sources: list[Path]) -> tuple[str, Path, int] | None:
    """(macro, file, line of its definition) of a macro whose body calls itself, in the expansion's files."""
    definition = re.compile(r'<xacro:macro\s[^>]*name="([^"]+)"')
    for file in dict.fromkeys(sources):
        try:
            text = file.read_text(encoding="utf-8", errors="replace")
        except OSError:
            continue
        for m in definition.finditer(text):
            end = text.find("</xacro:macro>", m.end())
            if end >= 0 and f"<xacro:{m.group(1)}" in text[m.end() : end]:
                return m.group(1), file, text.count("\n", 0, m.start()) + 1
    return None


def _same_file_index(stack: list[str | None], filename: str) -> int | None:
    target = Path(filename).resolve()
    for i, f in enumerate(stack):
        if f is not None and Path(f).resolve() == target:
            return i
    return None


# What to look for in the xacro sources to find the line of an error, from xacro's message.
_NEEDLES: list[tuple[re.Pattern[str], str, str]] = [
    (re.compile(r"name '(\w+)' is not defined when evaluating expression '([^']*)'"), "${{{1}", ""),
    (re.compile(r"name '(\w+)' is not defined"), "{0}", "${"),
    (re.compile(r"Undefined substitution argument (\S+)"), "$(arg {0})", ""),
    (re.compile(r"(?:No such file or directory|included file not found): (\S+)"), "@basename", "include"),
    (re.compile(r"unknown macro name: (?:xacro:)?(\S+)"), "<xacro:{0}", ""),
    (re.compile(r"Invalid parameter \"(\w+)\""), '{0}="', ""),
    (re.compile(r"invalid expression: (.+?)(?: when evaluating| \[|$)"), "{0}", ""),
    (re.compile(r"when evaluating expression '([^']*)'"), "${{{0}", ""),
]


def _locate_message(message: str, file: Path, sources: list[Path]) -> tuple[Path, int | None]:
    """file:line of what xacro's message is about: found by text in the current file, else in the
    other files of the expansion."""
    for pattern, needle_form, also in _NEEDLES:
        m = pattern.search(message)
        if not m:
            continue
        if needle_form == "@basename":
            needle = Path(m.group(1).rstrip("'\"")).name
        else:
            needle = needle_form.format(*m.groups())
        for candidate in dict.fromkeys([file, *sources]):
            line = _line_of(candidate, needle, also)
            if line is not None:
                return candidate, line
    return file, None


def _current_file(default: Path) -> Path:
    stack = getattr(xacro, "filestack", None)
    return Path(stack[-1]) if stack else default


def _hint(message: str) -> str | None:
    if "Undefined substitution argument" in message:
        return "pass it under `description: {args: {...}}` in the scenario, or give the <xacro:arg> a default"
    if "missing attribute 'default'" in message:
        return 'give the <xacro:arg> a default (`default="..."`), or pass it under `description: {args:}`'
    if "is not defined" in message:
        return "a ${...} expression names a property that no <xacro:property> defines"
    if "when evaluating expression" in message:
        return "an xacro argument or property of the wrong kind? Check the values passed under `args:`"
    if "No such file" in message or "not found" in message:
        return "check the include's path; $(find pkg) and relative paths are resolved from the including file"
    return None


def _other_hint(message: str, sources: list[Path]) -> str:
    """A hint for what `_hint` has none for: an unknown macro with the defined one closest to it."""
    import re

    m = re.match(r"unknown macro name:?\s*(?:xacro:)?(\S+)", message)
    if m:
        defined = []
        for src in sources:
            try:
                defined += re.findall(r"<xacro:macro\s+name=[\"']([^\"']+)", src.read_text(errors="replace"))
            except OSError:
                continue
        return did_you_mean(m.group(1), defined, "macros defined") + (
            " (a macro is called after its <xacro:macro>, in this file or one it includes)"
        )
    return "xacro stopped at this line: check the element's attributes and the ${...} in it"
