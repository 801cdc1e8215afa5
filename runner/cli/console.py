"""The terminal every command writes to: `out` (results) and `err` (progress, warnings, errors), and `fail`,
which prints a user's mistake (`ScenarioError`, `RunError`) without a traceback and ends the command with
exit 1."""

from __future__ import annotations

import sys
from typing import Any

import typer
from rich.console import Console
from rich.text import Text

from runner.errors import ScenarioError, visible


class _Terminal(Console):
    """A console whose strings are text, never markup (`[/x]` in an assertion's name, a topic of another
    process, a recording's topic made rich raise `MarkupError` and end the command with a traceback), and
    whose control characters are shown, not obeyed. Markup is asked for where it is meant: `markup=True`,
    `Text.from_markup`."""

    def render_str(self, text: str, **kwargs: Any) -> Text:
        return super().render_str(visible(text), **kwargs)


# Wide tables when piped (CI logs): key names are long and worth reading whole.
out = _Terminal(highlight=False, emoji=False, markup=False, width=None if sys.stdout.isatty() else 160)
err = _Terminal(
    stderr=True, highlight=False, emoji=False, markup=False, width=None if sys.stderr.isatty() else 160
)


def fail(e: Exception) -> typer.Exit:
    """Print `e` as `error: ...` (a `ScenarioError` with its file, line and hint) and return the exit to
    raise: `raise fail(e) from None`."""
    text = e.render() if isinstance(e, ScenarioError) else str(e)
    err.print("error: " + text, markup=False, soft_wrap=True, style="red")
    return typer.Exit(1)
