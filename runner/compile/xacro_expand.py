"""xacro -> URDF text, with `$(find pkg)` resolved through our package map (no ROS install).

The xacro package resolves `$(find)` through ament_index_python, which is not on PyPI; we replace its
resolver. It evaluates `${...}` and `$(eval ...)` with Python's `eval`, which a description can escape
from; we replace its evaluator with ours (xacro_sandbox.py), and its global symbols with ours. Those are
private APIs of xacro (`substitution_args._eval_find`, `_eval`, `safe_eval`, `_global_symbols`): this
module is the only place that touches them, under a lock and restored after, and tests/test_xacro.py and
tests/test_xacro_sandbox.py pin the behaviour.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import threading
import xml.parsers.expat
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import xacro
import xacro.substitution_args as _sa

from runner.compile.filesize import HINT as SIZE_HINT
from runner.compile.filesize import too_large
from runner.compile.packages import PackageMap
from runner.compile.xacro_sandbox import Sandbox, SandboxError
from runner.errors import SourceError, did_you_mean


class XacroError(SourceError):
    """xacro could not expand the file."""


class MissingPackage(XacroError):
    pass


class IncludeCycle(XacroError):
    pass


class TooLarge(XacroError):
    """An included file larger than a description file may be (runner/compile/filesize.py)."""


class OutsidePackages(XacroError):
    """A description read (`<xacro:include>`, `xacro.load_yaml`) a file outside what the scenario trusts."""


_lock = threading.Lock()


@dataclass
class Expanded:
    urdf: str
    sources: list[Path]  # the xacro file and every file it included, for pointing at lines
    # per element of the output, in document order: the file and line it was written at (a macro's
    # element: in the macro's file), or None for one xacro made up (`xacro:element`)
    origins: list[tuple[Path, int] | None] | None = None


# the attribute that carries an element's origin through xacro (its file's index, its line): set on every
# element as its file is parsed, copied with it into macro calls and includes, taken off the output
ORIGIN = "scenario_origin_"


def expand(path: Path, args: dict[str, str], packages: PackageMap) -> Expanded:
    """Run xacro on `path` with `args` (`$(arg name)`); return the URDF text and the files it read."""
    find = _package_finder(path, packages)
    real_parse = xacro.parse
    with _lock:
        saved = _sa._eval_find, _sa._eval_dict.get("find")
        saved_eval = xacro.safe_eval, xacro._global_symbols, _sa._eval
        sandbox = Sandbox(_trusted_load_yaml(xacro.load_yaml, path, packages))
        _sa._eval_find = find
        _sa._eval_dict["find"] = find
        xacro.safe_eval = sandbox.safe_eval
        xacro._global_symbols = sandbox.root
        _sa._eval = sandbox.substitution_eval
        xacro.parse = _cycle_guard(real_parse, path, packages)
        stderr = io.StringIO()
        xacro.all_includes = []
        files: list[Path] = []
        xacro.parse = _with_origins(xacro.parse, files)
        try:
            with contextlib.redirect_stderr(stderr):
                doc = xacro.process_file(str(path), mappings={k: str(v) for k, v in args.items()})
            sources = [path] + [Path(f) for f in dict.fromkeys(xacro.all_includes)]
            _check_readable(sources, path, packages)
            origins = _take_origins(doc, files)
            return Expanded(doc.toprettyxml(indent="  "), sources, origins)
        except (MissingPackage, IncludeCycle, OutsidePackages, TooLarge):
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
            xacro.safe_eval, xacro._global_symbols, _sa._eval = saved_eval
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


def _cycle_guard(real_parse: Callable[..., Any], path: Path, packages: PackageMap) -> Callable[..., Any]:
    """xacro's `parse`, refusing an included file outside what the scenario trusts before it is read, and
    stopping an include cycle (a includes b includes a) at the first file that is already being read:
    xacro itself recurses without end."""

    def parse(inp, filename=None):  # type: ignore[no-untyped-def]
        # xacro has pushed `filename` on its stack before parsing it.
        stack = list(getattr(xacro, "filestack", None) or [])
        if inp is None and filename and len(stack) > 1:
            if not packages.readable(Path(filename), path):
                raise _outside(Path(filename), Path(stack[-2]))
            oversize = too_large(Path(filename))
            if oversize is not None:  # before expat reads it
                includer = Path(stack[-2])
                raise TooLarge(
                    oversize, includer, _line_of(includer, Path(filename).name, "include"), hint=SIZE_HINT
                )
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


def _with_origins(parse: Callable[..., Any], files: list[Path]) -> Callable[..., Any]:
    """xacro's `parse`, marking every element of a file it reads with its line (`ORIGIN`): the lines are
    lxml's, of the same file, element for element in document order (minidom keeps none). xacro's own
    tags are left alone (xacro warns of attributes it does not know on them)."""

    def parse_marked(inp, filename=None):  # type: ignore[no-untyped-def]
        doc = parse(inp, filename)
        if inp is None and filename:
            file = Path(os.path.join(getattr(xacro, "root_dir", ""), filename))
            with contextlib.suppress(Exception):  # (no origins: the locator's older search takes over)
                from lxml import etree

                tree = etree.parse(str(file), etree.XMLParser(resolve_entities=False, no_network=True))
                lines = [e.sourceline for e in tree.getroot().iter() if isinstance(e.tag, str)]
                elements = doc.getElementsByTagName("*")
                if len(lines) == len(elements):
                    files.append(file)
                    for el, line in zip(elements, lines, strict=True):
                        if not el.tagName.startswith("xacro:"):
                            el.setAttribute(ORIGIN, f"{len(files) - 1}:{line}")
        return doc

    return parse_marked


def _take_origins(doc: Any, files: list[Path]) -> list[tuple[Path, int] | None]:
    """Each output element's origin, in document order, its mark taken off."""
    out: list[tuple[Path, int] | None] = []
    for el in doc.getElementsByTagName("*"):
        mark = el.getAttribute(ORIGIN) if el.hasAttribute(ORIGIN) else ""
        if mark:
            el.removeAttribute(ORIGIN)
            index, line = mark.split(":")
            out.append((files[int(index)], int(line)))
        else:
            out.append(None)
    return out


def _trusted_load_yaml(real: Callable[[str], Any], path: Path, packages: PackageMap) -> Callable[[str], Any]:
    """xacro's `load_yaml`, refusing a file outside what the scenario trusts before it is opened."""

    def load_yaml(filename: str) -> Any:
        full = Path(xacro.abs_filename_spec(str(filename)))
        if not packages.readable(full, path):
            raise _outside(full, _current_file(path))
        return real(filename)

    return load_yaml


def _check_readable(sources: list[Path], path: Path, packages: PackageMap) -> None:
    """Every file the expansion read (`<xacro:include>`, `xacro.load_yaml`) is one the scenario trusts
    (checked again after the expansion, whatever way a file was read)."""
    for read in sources[1:]:
        if not packages.readable(read, path):
            raise _outside(read, next((f for f in sources if _line_of(f, read.name)), path))


def _outside(read: Path, holder: Path) -> OutsidePackages:
    target = read.resolve()
    # (it looks inside; it is not). `..` alone is no link: compared with the path's `..` folded away
    # (Path.absolute keeps them, and every `../x` was said to be "a link to" itself)
    link = f" (a link to {target})" if target != Path(os.path.abspath(read)) else ""
    return OutsidePackages(
        f"{read}{link} is outside the scenario's folder and packages",
        holder,
        _line_of(holder, read.name),
        hint="a robot description may read files of the scenario's folder, its own folder "
        "and the packages (`packages:`, SCENARIO_PACKAGE_PATH); list other folders the "
        "scenario trusts under `allow_paths:`",
    )


def _xacro_error(e: Exception, path: Path) -> XacroError:
    """What xacro raised, as an error at the file and line it is about (called while xacro's file stack
    still says which file it was reading)."""
    for cause in _causes(e):
        if isinstance(cause, SourceError):  # ours, raised inside xacro: already located
            return cause
        if isinstance(cause, SandboxError):
            return _refused(cause, path)
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
        missing = re.findall(r"[^\s,\[\]]+", message.partition("[")[2].partition("]")[0])
        for candidate in dict.fromkeys([file, *sources]):
            line = _call_lacking(candidate, name, missing)
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


def _causes(e: BaseException) -> list[BaseException]:
    """`e` and what it wraps (xacro's `XacroException.exc`, Python's cause and context), outermost first."""
    out: list[BaseException] = []
    todo: list[BaseException | None] = [e]
    while todo:
        x = todo.pop(0)
        if x is None or any(x is seen for seen in out):
            continue
        out.append(x)
        todo += [getattr(x, "exc", None), x.__cause__, x.__context__]
    return out


def _refused(e: SandboxError, path: Path) -> XacroError:
    """An expression the sandbox refused, at the line where the expression is written."""
    sources = [_current_file(path), path, *map(Path, xacro.all_includes)]
    shown = e.expr if len(e.expr) <= 120 else e.expr[:117] + "..."
    where, line = _expression_line(e.expr, e.opener, sources)
    closer = "}" if e.opener == "${" else ")"
    return XacroError(f"{e.why}: {e.opener}{shown}{closer}", where, line, hint=e.hint)


def _expression_line(expr: str, opener: str, sources: list[Path]) -> tuple[Path, int | None]:
    """Where `expr` is written: xacro gives the expression as parsed (entities decoded, an attribute's
    newlines turned to spaces, `${...}` inside `$(eval ...)` already expanded), so we match it loosely,
    whole then by a shrinking prefix."""
    for length in dict.fromkeys([len(expr), 60, 30, 15, 6]):
        if length > len(expr):
            continue
        for lead in dict.fromkeys([opener, "${", "$(eval", ""]):
            pattern = re.compile(_loose(lead) + r"\s*" + _loose(expr[:length].strip()))
            for file in dict.fromkeys(sources):
                try:
                    text = file.read_text(encoding="utf-8", errors="replace")
                except OSError:
                    continue
                m = pattern.search(text)
                if m:
                    return file, text.count("\n", 0, m.start()) + 1
    return sources[0], None


_ENTITIES = {
    "<": ("&lt;", "&#60;"),
    ">": ("&gt;", "&#62;"),
    "&": ("&amp;", "&#38;"),
    '"': ("&quot;", "&#34;"),
    "'": ("&apos;", "&#39;"),
}


def _loose(text: str) -> str:
    """A regular expression for `text` as written in XML: any whitespace for whitespace, an entity for
    a character it may stand for."""
    out = []
    for c in text:
        if c.isspace():
            out.append(r"\s+")
        elif c in _ENTITIES:
            out.append("(?:" + "|".join(map(re.escape, (c, *_ENTITIES[c]))) + ")")
        else:
            out.append(re.escape(c))
    return "".join(out)


def _line_of(file: Path, needle: str, also: str = "") -> int | None:
    """The first line of `file` holding `needle` (and `also`, when given)."""
    try:
        for i, line in enumerate(file.read_text(encoding="utf-8", errors="replace").splitlines()):
            if needle in line and also in line:
                return i + 1
    except OSError:
        pass
    return None


def _call_lacking(file: Path, macro: str, missing: list[str]) -> int | None:
    """The line of the first call of `macro` in `file` that gives none of the `missing` parameters: xacro
    expands in document order, so an earlier call that lacked them would have failed first (the first
    call of all, which we used to point at, may well give them)."""
    try:
        text = file.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    for m in re.finditer(rf"<xacro:(?:[\w.]+\.)?{re.escape(macro)}(?=[\s/>])([^>]*)>", text):
        given = set(re.findall(r"([\w:.-]+)\s*=", m.group(1)))
        if not given & set(missing):
            return text.count("\n", 0, m.start()) + 1
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
