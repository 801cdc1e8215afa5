"""pytest plugin (entry point `pytest11`): scenario files with `assertions:` under a `scenarios/` folder are
collected as tests, one item per assertion, so `pytest scenarios/` works in an existing suite.

Each scenario runs once (`scenario run --no-record`, judged live); its assertions report their verdicts,
with the time, value and bound of a failure. An assertion the run could not decide (its window lies past
the run's end...) fails, saying why; `--scenario-allow-undecided` makes it a skip instead.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--scenario-allow-undecided",
        action="store_true",
        help="scenario assertions that a run could not decide are skipped, not failed",
    )


def pytest_collect_file(parent: pytest.Collector, file_path: Path) -> pytest.Collector | None:
    if file_path.suffix not in (".yaml", ".yml") or "scenarios" not in file_path.parts:
        return None
    try:
        text = file_path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    if "\nassertions:" not in "\n" + text:
        return None
    return ScenarioFile.from_parent(parent, path=file_path)


class ScenarioFailure(Exception):
    pass


class ScenarioFile(pytest.File):
    _results: dict[str, Any] | None = None

    def collect(self) -> Any:
        from runner.scenario.loader import load_file

        doc = load_file(self.path)
        names = [a.get("name", f"assertion_{i}") for i, a in enumerate(doc.data.get("assertions") or [])]
        for name in names:
            yield ScenarioItem.from_parent(self, name=str(name))

    def results(self) -> dict[str, Any]:
        if self._results is None:
            with tempfile.TemporaryDirectory() as tmp:
                out = Path(tmp) / "results.json"
                cmd = [
                    sys.executable,
                    "-m",
                    "runner.cli",
                    "run",
                    str(self.path),
                    "-q",
                    "--no-record",
                    "--results-json",
                    str(out),
                ]
                proc = subprocess.run(cmd, capture_output=True, text=True)
                if not out.is_file():
                    raise ScenarioFailure(proc.stderr.strip() or f"scenario run exited {proc.returncode}")
                self._results = json.loads(out.read_text())
        return self._results


class ScenarioItem(pytest.Item):
    def runtest(self) -> None:
        parent = self.parent
        assert isinstance(parent, ScenarioFile)
        data = parent.results()
        if data.get("error"):
            raise ScenarioFailure(data["error"])
        result = next((r for r in data["results"] if r["name"] == self.name), None)
        if result is None:
            raise ScenarioFailure(f"assertion {self.name!r} was not judged")
        if result.get("status") == "undecided":
            why = f"{self.name} ({result['type']}) not decided: {result['message']}"
            if self.config.getoption("--scenario-allow-undecided", False):
                pytest.skip(why)
            raise ScenarioFailure(why)
        if not result["passed"]:
            at = f" at t={result['t']:.3f} s" if result["t"] is not None else ""
            raise ScenarioFailure(
                f"{self.name} ({result['type']}) failed{at}: {result['message']}; value {result['value']}; "
                f"bound {result['bound']}"
            )

    def repr_failure(self, excinfo: Any, style: Any = None) -> str:
        if isinstance(excinfo.value, ScenarioFailure):
            return str(excinfo.value)
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Path, int, str]:
        return self.path, 0, f"scenario {self.path.stem}: {self.name}"
