"""How `scenario --help` reads: the command classes that give every value a metavar (FILE, SECONDS) and a
flag none, name arguments by their metavar in the usage line, and give each command a one-sentence line in
the command list (`first_sentence`)."""

from __future__ import annotations

import inspect
import re
from typing import Any

import typer


def first_sentence(doc: str) -> str:
    """A command's line in `scenario --help`: the first sentence of its docstring, on one line."""
    one = " ".join(inspect.cleandoc(doc).split("\n\n")[0].split())
    end = re.search(r"(?<=[.!?])\s+(?=[A-Z`(])", one)
    return one[: end.start()] if end else one


def _plain_help_option(option: Any) -> Any:
    if option is not None:
        option.metavar = ""  # (a flag: no `<bool>` beside it)
    return option


class Command(typer.core.TyperCommand):
    """A command whose help reads as a user's: a metavar for each value (FILE, SECONDS), none for a flag
    (typer would print `<bool>`, `<str>`, `<float range>`), arguments by their metavar in the usage line
    (`FILE`, not `{file}`), and a one-line, one-sentence short help for the command list (typer would keep
    the docstring's hard line breaks)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if not self.short_help and self.help:
            self.short_help = first_sentence(self.help)
        for param in self.params:
            if isinstance(param, typer.core.TyperOption) and param.is_flag:
                param.metavar = ""
            elif param.metavar is None:
                param.metavar = (param.name or "value").upper()
            if isinstance(param, typer.core.TyperArgument):
                # an argument's metavar names it; typer would add its type beside it
                param.display_type_rich = lambda ctx: None  # type: ignore[method-assign]

    def get_help_option(self, ctx: Any) -> Any:
        return _plain_help_option(super().get_help_option(ctx))

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if isinstance(param, typer.core.TyperArgument):
                name = param.metavar or (param.name or "").upper()
                name = name if param.required else f"[{name}]"
                pieces.append(name + ("..." if param.nargs != 1 else ""))
        return pieces


class Group(typer.core.TyperGroup):
    """The `scenario` group: its `--help` flag without a metavar, as each command's."""

    def get_help_option(self, ctx: Any) -> Any:
        return _plain_help_option(super().get_help_option(ctx))
