"""`--help` reads as a user's help: no type placeholders, and one sentence per command in the list."""

from __future__ import annotations

import re

import pytest
from typer.main import get_command
from typer.testing import CliRunner

from runner.cli import app, first_sentence

PLACEHOLDERS = ("<bool>", "<str>", "<list[", "{file}", "<path>", "<int", "<float")
SENTENCE_END = re.compile(r"[.!?](?=\s+[A-Z`(]|$)")


def _help(*args: str, columns: int = 100) -> str:
    result = CliRunner().invoke(app, [*args, "--help"], env={"COLUMNS": str(columns), "NO_COLOR": "1"})
    assert result.exit_code == 0, result.output
    return result.output


COMMANDS = sorted(get_command(app).commands)  # type: ignore[attr-defined]


@pytest.mark.parametrize("command", ["", *COMMANDS])
def test_no_help_shows_type_placeholders(command: str) -> None:
    text = _help(*([command] if command else []))
    assert "Usage: scenario" in text
    for placeholder in PLACEHOLDERS:
        assert placeholder not in text, (command, placeholder, text)
    assert not re.search(r"\{\w+\}", text.split("\n\n", 2)[1]), text  # the usage line: `FILE`, not `{file}`


def test_values_are_named_and_flags_are_bare() -> None:
    text = _help("run")
    assert re.search(r"Usage: scenario run \[OPTIONS\] FILE\b", text)
    for option, metavar in (("--duration", "SECONDS"), ("--listen", "ENDPOINT"), ("--junit", "FILE")):
        assert re.search(rf"{option}\s+{metavar}\b", text), (option, text)
    flag = next(line for line in text.splitlines() if "--no-record" in line)
    assert re.search(r"--no-record\s+Do not record\.", flag), flag  # nothing between a flag and its help


def test_the_command_list_gives_each_command_one_sentence_on_one_line() -> None:
    group = get_command(app)
    for name in COMMANDS:
        short = group.commands[name].short_help  # type: ignore[attr-defined]
        assert short and "\n" not in short, (name, short)
        assert len(SENTENCE_END.findall(short)) == 1 and short.endswith("."), (name, short)
    text = _help(columns=250)  # wide enough for every line: nothing wraps
    rows = [line for line in text.splitlines() if re.match(r"│ \w+ ", line)]
    listed = {row.split()[1]: row.strip("│ ").split(None, 1)[1].strip() for row in rows}
    assert sorted(listed) == COMMANDS, rows
    for name, line in listed.items():
        assert line.endswith("."), (name, line)  # each line ends where its sentence ends
    body = text[text.index("Commands") :]
    assert not re.search(r"│\s{8,}\S", body), body  # no continuation lines


def test_first_sentence() -> None:
    doc = """Validate, compile and run a scenario; judge it. With a
    `matrix:`, every variant runs.

    Examples: ..."""
    assert first_sentence(doc) == "Validate, compile and run a scenario; judge it."
    assert first_sentence("Print a field, e.g. pose.x (like `ros2 topic echo`).") == (
        "Print a field, e.g. pose.x (like `ros2 topic echo`)."
    )
