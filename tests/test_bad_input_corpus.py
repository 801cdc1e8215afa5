"""The bad-input corpus: every `tests/bad_inputs/<case>.yaml` is a scenario with one mistake.

Each case file starts with comment lines: `# case: what it shows`, then `# expect: text` lines, each a piece
of the error that `scenario validate` must print (file:line, the path in the scenario, what was expected,
a hint: one `# expect:` line is the hint's, and every problem said must have one). Extra files a case needs (xacro, URDF, bridge files) live in `tests/bad_inputs/<case>/`. A new file
is a new test.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from runner.cli import app

CORPUS = Path(__file__).resolve().parent / "bad_inputs"
CASES = sorted(CORPUS.glob("*.yaml"))
EXPECT = "# expect: "
# `name.yaml:12`, `case/robot.urdf.xacro:4`: a file and a line
FILE_LINE = re.compile(r"^(?:[\w.-]+/)*[\w-]+(?:\.[\w-]+)+:\d+")
# A problem as printed: `<file>:<line>[:<col>]: ...` (the first after `error: `), its details indented below
PROBLEM = re.compile(r"^(?:error: )?\S+:\d+(?::\d+)?: ")
# The line that only says which scenario line loaded the file a problem is in: the problem above has the hint
CONTEXT = re.compile(r": while loading (?:robot '[^']*'|the world file)$")


def header(case: Path) -> tuple[str, list[str]]:
    """(what the case shows, the expected pieces of the error) from the leading comment block."""
    what = ""
    expects: list[str] = []
    for line in case.read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        if line.startswith("# case:"):
            what = line.removeprefix("# case:").strip()
        elif line.startswith(EXPECT):
            expects.append(line.removeprefix(EXPECT))
    return what, expects


def test_the_corpus_is_big_enough() -> None:
    assert len(CASES) >= 40, [c.name for c in CASES]


def test_extra_folders_belong_to_a_case() -> None:
    names = {c.stem for c in CASES}
    folders = {p.name for p in CORPUS.iterdir() if p.is_dir() and p.name != "__pycache__"}
    assert folders <= names, f"folders without a case file: {sorted(folders - names)}"


@pytest.mark.parametrize("case", CASES, ids=[c.stem for c in CASES])
def test_case_header(case: Path) -> None:
    what, expects = header(case)
    assert what, f"{case.name}: the first lines need `# case: <what it shows>`"
    assert len(expects) >= 3, f"{case.name}: at least 3 `# expect:` lines, found {len(expects)}"
    located = [e for e in expects if FILE_LINE.match(e)]
    assert located, f"{case.name}: one `# expect:` line must be a `<file>:<line>`, e.g. {case.name}:7:"
    assert all(e.strip() for e in expects), f"{case.name}: an empty `# expect:` matches anything"
    hints = [e for e in expects if e.startswith("hint:") and len(e.removeprefix("hint:").strip()) >= 8]
    assert hints, (
        f"{case.name}: one `# expect:` line must be the hint, e.g. `# expect: hint:     did you mean`"
    )


def problems_without_hint(output: str) -> list[str]:
    """The problems of `validate`'s output (a `file:line:` line and its indented details) that say no
    `hint:`, but for the lines that only name the scenario line that loaded a file."""
    blocks: list[list[str]] = []
    for line in output.splitlines():
        if line.startswith("  ") and blocks:
            blocks[-1].append(line)
        elif PROBLEM.match(line):
            blocks.append([line])
    return [
        b[0]
        for b in blocks
        if not CONTEXT.search(b[0]) and not any(ln.strip().startswith("hint:") for ln in b[1:])
    ]


@pytest.mark.parametrize("case", CASES, ids=[c.stem for c in CASES])
def test_bad_input(case: Path) -> None:
    _, expects = header(case)
    result = CliRunner().invoke(app, ["validate", str(case)])
    output = result.output + (result.stderr if result.stderr not in result.output else "")
    assert "Traceback" not in output, output
    assert result.exit_code == 1, f"exit {result.exit_code}:\n{output}"
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert output.lstrip().startswith("error: "), output
    missing = [e for e in expects if e not in output]
    assert not missing, f"{case.name}: {missing} not in:\n{output}"
    bare = problems_without_hint(output)
    assert not bare, f"{case.name}: every problem says what to do (a `hint:`); these do not: {bare}"
