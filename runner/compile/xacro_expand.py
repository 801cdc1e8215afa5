"""xacro -> URDF text, with `$(find pkg)` resolved through our package map (no ROS install).

The xacro package resolves `$(find)` through ament_index_python, which is not on PyPI; we replace its
resolver. That is a private API of xacro (`xacro.substitution_args._eval_find`): this module is the only
place that touches it, and tests/compile/test_xacro.py pins the behaviour.
"""

from __future__ import annotations

import contextlib
import io
import threading
import xml.parsers.expat
from dataclasses import dataclass
from pathlib import Path

import xacro
import xacro.substitution_args as _sa

from runner.compile.packages import PackageMap
from runner.errors import SourceError


class XacroError(SourceError):
    """xacro could not expand the file."""


class MissingPackage(XacroError):
    pass


_lock = threading.Lock()


@dataclass
class Expanded:
    urdf: str
    sources: list[Path]  # the xacro file and every file it included, for pointing at lines


def expand(path: Path, args: dict[str, str], packages: PackageMap) -> Expanded:
    """Run xacro on `path` with `args` (`$(arg name)`); return the URDF text and the files it read."""

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

    with _lock:
        saved = _sa._eval_find, _sa._eval_dict.get("find")
        _sa._eval_find = find
        _sa._eval_dict["find"] = find
        stderr = io.StringIO()
        xacro.all_includes = []
        try:
            with contextlib.redirect_stderr(stderr):
                doc = xacro.process_file(str(path), mappings={k: str(v) for k, v in args.items()})
            sources = [path] + [Path(f) for f in dict.fromkeys(xacro.all_includes)]
            return Expanded(doc.toprettyxml(indent="  "), sources)
        except MissingPackage:
            raise
        except xml.parsers.expat.ExpatError as e:
            raise XacroError(
                f"not well-formed XML: {xml.parsers.expat.errors.messages.get(e.code, e)}",
                _current_file(path),
                e.lineno,
                hint="look for an unclosed tag, a stray '<' or '&'",
            ) from None
        except Exception as e:
            cause = e.__cause__ or e.__context__
            if isinstance(cause, MissingPackage):
                raise cause from None
            message = " ".join(str(e).split())
            raise XacroError(message, _current_file(path), hint=_hint(message)) from None
        finally:
            _sa._eval_find, found = saved
            if found is not None:
                _sa._eval_dict["find"] = found


def _line_of(file: Path, needle: str) -> int | None:
    try:
        for i, line in enumerate(file.read_text(encoding="utf-8", errors="replace").splitlines()):
            if needle in line:
                return i + 1
    except OSError:
        pass
    return None


def _current_file(default: Path) -> Path:
    stack = getattr(xacro, "filestack", None)
    return Path(stack[-1]) if stack else default


def _hint(message: str) -> str | None:
    if "Undefined substitution argument" in message:
        return "pass it under `description: {args: {...}}` in the scenario, or give the <xacro:arg> a default"
    if "is not defined" in message:
        return "a ${...} expression names a property that no <xacro:property> defines"
    if "No such file" in message or "not found" in message:
        return "check the include's path; $(find pkg) and relative paths are resolved from the including file"
    return None
