"""The terminal every command writes to: `out` (results) and `err` (progress, warnings, errors), and `fail`,
which prints a user's mistake (`ScenarioError`, `RunError`) without a traceback and ends the command with
exit 1."""

from __future__ import annotations

import sys

import typer
from rich.console import Console

from runner.errors import ScenarioError

# Wide tables when piped (CI logs): key names are long and worth reading whole.
out = Console(highlight=False, emoji=False, width=None if sys.stdout.isatty() else 160)
err = Console(stderr=True, highlight=False, emoji=False, width=None if sys.stderr.isatty() else 160)


def fail(e: Exception) -> typer.Exit:
    """Print `e` as `error: ...` (a `ScenarioError` with its file, line and hint) and return the exit to
    raise: `raise fail(e) from None`."""
    text = e.render() if isinstance(e, ScenarioError) else str(e)
    err.print("error: " + text, markup=False, soft_wrap=True, style="red")
    return typer.Exit(1)
