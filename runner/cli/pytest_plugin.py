"""pytest plugin (entry point `pytest11`): scenario files with `assertions:` under a `scenarios/` folder are
collected as tests, one item per assertion, so `pytest scenarios/` works in an existing suite. An event that
can end the run (`end:`) is an item too, `event NAME`: it fails if it fired and ended the run as a failure.

Each scenario runs once (`scenario run --no-record`, judged live); its assertions report their verdicts,
with the time, value and bound of a failure. An assertion the run could not decide (its window lies past
the run's end...) fails, saying why; `--scenario-allow-undecided` makes it a skip instead. With a
`matrix:`, every variant runs, and an assertion passes when it passes in each one (a failure names the
variant, its drawn values included).
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
    if "\nassertions:" not in "\n" + text and "\nevents:" not in "\n" + text:
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
        for e in doc.data.get("events") or []:  # (named as the judge names an ending's result)
            if isinstance(e, dict) and any(isinstance(a, dict) and "end" in a for a in e.get("do") or []):
                names.append(f"event {e.get('name')}")
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
        """The assertion's verdict in the run (in each variant of a matrix: it must pass in every one)."""
        parent = self.parent
        assert isinstance(parent, ScenarioFile)
        data = parent.results()
        runs = data.get("variants") or [data]
        failures: list[str] = []
        undecided: list[str] = []
        for run in runs:
            named = f"{run['name']}: " if len(runs) > 1 else ""
            if run.get("error"):
                failures.append(named + run["error"])
                continue
            result = next((r for r in run["results"] if r["name"] == self.name), None)
            if result is None and self.name.startswith("event "):
                continue  # the event never fired: it did not end the run
            if result is None:
                failures.append(f"{named}assertion {self.name!r} was not judged")
            elif result.get("status") == "undecided":
                undecided.append(f"{named}{self.name} ({result['type']}) not decided: {result['message']}")
            elif not result["passed"]:
                at = f" at t={result['t']:.3f} s" if result["t"] is not None else ""
                failures.append(
                    f"{named}{self.name} ({result['type']}) failed{at}: {result['message']}; value "
                    f"{result['value']}; bound {result['bound']}"
                )
        if undecided and not failures and self.config.getoption("--scenario-allow-undecided", False):
            pytest.skip("\n".join(undecided))
        if failures or undecided:
            raise ScenarioFailure("\n".join(failures + undecided))

    def repr_failure(self, excinfo: Any, style: Any = None) -> str:
        if isinstance(excinfo.value, ScenarioFailure):
            return str(excinfo.value)
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Path, int, str]:
        return self.path, 0, f"scenario {self.path.stem}: {self.name}"
