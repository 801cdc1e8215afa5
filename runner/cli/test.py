"""Commands that judge scenarios for CI: `check` (judge a recording with a scenario's assertions) and `test`
(run many scenarios, each in its own process, and report them in one table and one JUnit file). The
pytest plugin (`runner.cli.pytest_plugin`) runs scenarios the same way from pytest."""

from __future__ import annotations

import json
import sys
from functools import partial
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from runner.cli.console import err, fail, out
from runner.cli.options import AllowUndecided, RecordingArg
from runner.cli.plans import load_variants
from runner.cli.results import plot_failure, print_events, print_results
from runner.errors import RunError, ScenarioError


def check(
    mcap: RecordingArg,
    scenario: Annotated[
        Path, typer.Option("--scenario", "-s", metavar="FILE", help="The scenario whose assertions to judge.")
    ],
    junit: Annotated[
        Path | None, typer.Option(metavar="FILE", help="Write the results as JUnit XML.")
    ] = None,
    variant: Annotated[
        int | None, typer.Option(metavar="N", help="The matrix variant the recording is of (0-based).", min=0)
    ] = None,
    allow_undecided: AllowUndecided = False,
) -> None:
    """Judge a recording with a scenario's assertions (the same judge as the live run), and say what its
    events did.

    Example: scenario check runs/two_robots.mcap --scenario scenarios/two_robots.yaml
    """
    from runner.tools.report import Suite, rejudge, write_junit

    try:
        plans = load_variants(scenario, None, variant)
    except ScenarioError as e:
        raise fail(e) from None
    if len(plans) > 1:
        raise fail(RunError(f"{scenario} has {len(plans)} variants: say which one with --variant"))
    plan = plans[0][1]
    if not any(part.assertions or part.events for part in plan.worlds or [plan]):
        raise fail(RunError(f"{scenario} has no assertions to judge and no events"))
    if not mcap.is_file():
        raise fail(RunError(f"{mcap}: file not found"))
    try:
        judged = rejudge(plan, mcap)
    except Exception as e:
        raise fail(RunError(f"{mcap}: cannot judge it: {type(e).__name__}: {e}")) from None
    results = judged.results
    print_events(judged.events)
    if results:
        print_results(results, allow_undecided)
    suite = Suite(
        plan.name,
        results,
        mcap=str(mcap),
        sim_s=judged.end_ns / 1e9,
        allow_undecided=allow_undecided,
        interrupted=judged.why,
        events=judged.events,
    )
    if results and not suite.passed:
        plot_failure(plan, mcap, results)
    if junit is not None:
        write_junit(junit, [suite])
    raise typer.Exit(0 if suite.passed else 1)


# A scenario run of `test`: the file, its variant's index (None without a matrix) and the variant's label.
Task = tuple[Path, int | None, str]


def test_cmd(
    paths: Annotated[list[Path], typer.Argument(help="Scenario files or folders (their *.yaml).")],
    jobs: Annotated[int, typer.Option("--jobs", "-j", metavar="N", help="Scenarios run at once.", min=1)] = 1,
    junit: Annotated[
        Path | None, typer.Option(metavar="FILE", help="Write every result as JUnit XML.")
    ] = None,
    out_dir: Annotated[
        Path, typer.Option("--out", metavar="FOLDER", help="Folder for the recordings.")
    ] = Path("runs/test"),
    no_record: Annotated[
        bool, typer.Option("--no-record", help="Judge live only; write no recordings.")
    ] = False,
    allow_undecided: AllowUndecided = False,
) -> None:
    """Run many scenarios (in parallel processes), print a results table, write JUnit XML; exit 0 only if
    every run completes and every assertion passes.

    Example: scenario test scenarios/ -j 2 --junit report.xml
    """
    import concurrent.futures

    from runner.tools.report import write_junit

    files: list[Path] = []
    for p in paths:
        files += sorted(p.glob("*.yaml")) if p.is_dir() else [p]
    if not files:
        raise fail(RunError("no scenario files found in " + ", ".join(map(str, paths))))
    if not no_record:
        out_dir.mkdir(parents=True, exist_ok=True)
    run_one = partial(_run_in_process, out_dir=out_dir, no_record=no_record, allow_undecided=allow_undecided)
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        suites = list(pool.map(run_one, _tasks(files)))
    reports = {} if no_record else _write_reports(suites)  # one page per scenario, beside its recording
    out.print(_suites_table(suites, reports))
    _print_failures(suites)
    if junit is not None:
        write_junit(junit, suites)
    ok = sum(1 for s in suites if s.passed)
    out.print(f"{ok} passed, {len(suites) - ok} failed", markup=False)
    raise typer.Exit(0 if ok == len(suites) else 1)


def _tasks(files: list[Path]) -> list[Task]:
    """Every run of the files: one per file, or one per variant of a file's matrix."""
    from runner.scenario.loader import load_file
    from runner.scenario.matrix import variants

    tasks: list[Task] = []
    for f in files:
        try:
            labels = [label for label, _ in variants(load_file(f))]
        except ScenarioError:
            labels = [""]  # the run itself reports the error
        tasks += [(f, i if len(labels) > 1 else None, label) for i, label in enumerate(labels)]
    return tasks


def _run_in_process(task: Task, out_dir: Path, no_record: bool, allow_undecided: bool) -> Any:
    """`scenario run` of one task in a process of its own: its suite, read back from --results-json (or
    the process's last words as the suite's error)."""
    import subprocess
    import tempfile

    from runner.tools.report import Suite

    f, index, label = task
    name = f"{f.stem}[{label}]" if label else f.stem
    with tempfile.TemporaryDirectory() as tmp:
        res = Path(tmp) / "results.json"
        cmd = [sys.executable, "-m", "runner.cli", "run", str(f), "-q", "--results-json", str(res)]
        stem = f.stem if index is None else f"{f.stem}-{index}"
        cmd += ["--no-record"] if no_record else ["--record", str(out_dir / f"{stem}.mcap")]
        if index is not None:
            cmd += ["--variant", str(index)]
        if allow_undecided:
            cmd += ["--allow-undecided"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if res.is_file():
            suite = Suite.from_json(json.loads(res.read_text()))
            # the run's own label: a pose drawn in collision was drawn again there
            suite.name = f"{f.stem}[{suite.label}]" if suite.label else name
            return suite
        why = (proc.stderr.strip() or proc.stdout.strip() or f"exit {proc.returncode}").splitlines()
        return Suite(name, error="\n".join(why[-12:]))


def _write_reports(suites: list[Any]) -> dict[str, str]:
    """An HTML report beside each recording: {suite name: page}."""
    from runner.tools.html import write_report

    reports: dict[str, str] = {}
    for s in suites:
        if s.mcap and Path(s.mcap).is_file():
            page = Path(s.mcap).with_suffix(".html")
            try:
                write_report(Path(s.mcap), page)
                reports[s.name] = str(page)
            except Exception as e:  # a report is a convenience: never a failed test run
                err.print(f"{s.name}: no report: {e}", markup=False)
    return reports


def _suites_table(suites: list[Any], reports: dict[str, str]) -> Table:
    """One row per scenario run: assertions passed, failed (not decided), events fired (when some run had
    events), verdict, time, report link."""
    any_undecided = any(s.undecided for s in suites)
    any_events = any(s.events for s in suites)
    table = Table(
        "scenario",
        "assertions",
        "passed",
        "failed",
        *(["not decided"] if any_undecided else []),
        *(["events fired"] if any_events else []),
        "result",
        "time (s)",
        *(["report"] if reports else []),
        title="Scenarios",
        title_justify="left",
    )
    for s in suites:
        failed = sum(1 for r in s.results if r.status == "fail")
        verdict = "[green]pass[/]" if s.passed else ("[bold red]ERROR[/]" if s.error else "[bold red]FAIL[/]")
        link = (
            [f"[link=file://{Path(reports[s.name]).resolve()}]{reports[s.name]}[/link]"]
            if s.name in reports
            else []
        )
        table.add_row(
            s.name,
            str(len(s.results)),
            str(len(s.results) - failed - s.undecided),
            str(failed),
            *([str(s.undecided)] if any_undecided else []),
            *([str(len(s.events))] if any_events else []),
            verdict,
            f"{s.time_s:.1f}",
            *(link or ([""] if reports else [])),
        )
    return table


def _print_failures(suites: list[Any]) -> None:
    """Each run's error and each failed assertion, named by its scenario."""
    for s in suites:
        if s.error:
            err.print(f"{s.name}: {s.error}", markup=False, style="red")
        for r in s.results:
            if not r.passed:
                from runner.tools.report import failure_text

                err.print(f"{s.name}: {failure_text(r)}", markup=False, style="red")
