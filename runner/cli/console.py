"""The terminal every command writes to: `out` (results) and `err` (progress, warnings, errors), and `fail`,
which prints a user's mistake (`ScenarioError`, `RunError`) without a traceback and ends the command with
exit 1."""

from __future__ import annotations

import re
import sys
from typing import Any

import typer
from rich.console import Console
from rich.text import Text

from runner.errors import ScenarioError

# Characters a terminal acts on rather than shows: C0 controls but tab and newline (ESC starts the
# sequences that clear the screen, set the window title, write the clipboard), DEL, C1 controls, and the
# bidirectional overrides that reorder what is shown ("Trojan Source").
_CONTROLS = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


def visible(text: str) -> str:
    """`text` with every control character written as an escape (`\x1b`, `\u202e`), as `repr` would."""
    return _CONTROLS.sub(lambda m: repr(m.group())[1:-1], text)


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
