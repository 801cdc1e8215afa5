"""The shape of the code (docs/architecture.md): the layers and no import cycles, checked by import-linter
with the contracts in pyproject.toml; and modules and functions small enough to read, with the few
exceptions named here and why."""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MODULE_LINES = 600
FUNCTION_LINES = 80

# (path, what) -> why it reads better whole. Keep this short: split instead where a reader would gain.
LONG_ON_PURPOSE: dict[tuple[str, str], str] = {}


def _lint_imports(cwd: Path, config: Path, env_path: Path) -> subprocess.CompletedProcess[str]:
    code = "import sys; from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())"
    return subprocess.run(
        [sys.executable, "-c", code, "--config", str(config), "--no-cache"],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
        env={"PYTHONPATH": str(env_path), "PATH": "/usr/bin:/bin"},
    )


def test_the_import_contracts_hold() -> None:
    """Layers (cli > tools > launch > sim|record|node > compile > checks > scenario|plan > plugin > wire >
    base), plugins kept to the plugin API, the public aliases unused inside, no cycles between siblings."""
    out = _lint_imports(ROOT, ROOT / "pyproject.toml", ROOT)
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]
    assert "4 kept, 0 broken" in out.stdout, out.stdout[-2000:]


def test_a_cycle_or_an_upward_import_breaks_the_contracts(tmp_path: Path) -> None:
    """The same kinds of contract fail on a package that has a cycle and a lower layer importing a higher
    one (so the test above cannot pass by checking nothing)."""
    pkg = tmp_path / "shapely_pkg"
    (pkg / "low").mkdir(parents=True)
    (pkg / "high").mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "low" / "__init__.py").write_text("")
    (pkg / "high" / "__init__.py").write_text("")
    (pkg / "low" / "a.py").write_text("from shapely_pkg.low import b\n")
    (pkg / "low" / "b.py").write_text(
        "def f():\n    from shapely_pkg.low import a\n    from shapely_pkg import high\n"
    )
    config = tmp_path / "setup.cfg"
    config.write_text(
        textwrap.dedent(
            """
            [importlinter]
            root_package = shapely_pkg
            [importlinter:contract:layers]
            name = layers
            type = layers
            layers =
                shapely_pkg.high
                shapely_pkg.low
            [importlinter:contract:acyclic]
            name = acyclic
            type = acyclic_siblings
            ancestors = shapely_pkg
            """
        )
    )
    out = _lint_imports(tmp_path, config, tmp_path)
    assert out.returncode == 1, out.stdout
    assert "0 kept, 2 broken" in out.stdout, out.stdout


def _sizes() -> tuple[list[str], list[str]]:
    long_modules, long_functions = [], []
    for path in sorted([*ROOT.glob("runner/**/*.py"), *ROOT.glob("plugins/**/*.py")]):
        rel = path.relative_to(ROOT).as_posix()
        text = path.read_text()
        lines = text.count("\n")
        if lines > MODULE_LINES and (rel, "module") not in LONG_ON_PURPOSE:
            long_modules.append(f"{rel}: {lines} lines")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                n = (node.end_lineno or node.lineno) - node.lineno + 1
                if n > FUNCTION_LINES and (rel, node.name) not in LONG_ON_PURPOSE:
                    long_functions.append(f"{rel}:{node.lineno} {node.name}: {n} lines")
    return long_modules, long_functions


def test_modules_and_functions_stay_readable() -> None:
    long_modules, long_functions = _sizes()
    assert not long_modules, (
        f"modules over {MODULE_LINES} lines (split, or say why in LONG_ON_PURPOSE): {long_modules}"
    )
    assert not long_functions, f"functions over {FUNCTION_LINES} lines: {long_functions}"


@pytest.mark.parametrize("why", list(LONG_ON_PURPOSE.values()) or ["(none)"])
def test_every_exception_says_why(why: str) -> None:
    assert why == "(none)" or len(why) > 30


def test_the_public_imports_stay_where_users_find_them() -> None:
    """What node scripts, plugins and the README's examples import (docs/architecture.md, Public imports)."""
    import runner.msgs
    import runner.transport
    import runner.wire.msgs
    import runner.wire.transport
    from runner import msgs
    from runner.node import Node
    from runner.plugin import (
        BuildContext,
        Plugin,
        PluginParams,
        RatedParams,
        RobotHandle,
        RuntimeContext,
        Topic,
    )
    from runner.transport import encoding_for, free_port, make_config

    assert runner.msgs is runner.wire.msgs and msgs is runner.wire.msgs  # the same module, not a copy
    assert runner.transport is runner.wire.transport
    assert make_config is runner.wire.transport.make_config and callable(encoding_for) and callable(free_port)
    assert msgs.T["geometry_msgs/msg/Twist"] is not None
    assert all(callable(c) for c in (Node, BuildContext, Plugin, PluginParams, RatedParams, RobotHandle))
    assert RuntimeContext.__annotations__["robot"] in ("RobotHandle", RobotHandle) and Topic is not None
