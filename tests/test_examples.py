"""Every scenario shipped in scenarios/ validates (the real CLI's command, in process). That each one runs,
records and passes its assertions through the real CLI, in processes, is one `scenario test` over them all
(tests/test_scenario_test.py::test_all_examples_pass_their_assertions_with_junit)."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from runner.cli import app
from tests.conftest import SCENARIOS

EXAMPLES = sorted(SCENARIOS.glob("*.yaml"))


def test_there_are_examples():
    assert any(p.name == "two_robots.yaml" for p in EXAMPLES)


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
@pytest.mark.timeout(60)
def test_example_validates(path: Path):
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 0, result.output
    assert "Traceback" not in result.output
