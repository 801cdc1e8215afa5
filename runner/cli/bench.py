"""`scenario bench`: the benchmark suite of a checkout (its bench/ folder), the same as `python -m bench`."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from runner.cli.console import err


def bench(ctx: typer.Context) -> None:
    """Run the benchmark suite (a checkout's bench/ folder): `scenario bench --quick`, `--only two_robots`,
    `--readme`. Same as `python -m bench`."""
    repo = Path(__file__).resolve().parents[2]  # (runner/cli/bench.py -> the checkout)
    if not (repo / "bench" / "__main__.py").is_file():
        err.print(
            "[red]error:[/red] the benchmark suite lives in a checkout's bench/ folder; none here",
            markup=True,
        )
        raise typer.Exit(2)
    if str(repo) not in sys.path:
        sys.path.insert(0, str(repo))
    from bench.__main__ import main as bench_main

    raise typer.Exit(bench_main(list(ctx.args)))
