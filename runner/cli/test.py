"""Commands that judge scenarios for CI: `check` (judge a recording with a scenario's assertions) and `test`
(run many scenarios, each in its own process, and report them in one table and one JUnit file; here with
`-j N`, or on a Ray cluster with `--ray`: runner.cli.cluster). The pytest plugin
(`runner.cli.pytest_plugin`) runs scenarios the same way from pytest."""

from __future__ import annotations

import re
from functools import partial
from pathlib import Path
from typing import Annotated, Any

import typer

from runner.cli.console import err, fail, out
from runner.cli.help import Command
from runner.cli.options import AllowUndecided, RecordingArg
from runner.cli.plans import load_variants
from runner.cli.results import plot_failure, print_events, print_failures, print_results, suites_table
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
        # the recording is given: the scenario's record.path is not used, nor checked
        plans = load_variants(scenario, str(mcap), variant)
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


# `--ray ADDRESS`: what Ray takes as a cluster's address (anything else after `--ray` is not its value)
_RAY_ADDRESS = re.compile(r"^(auto|local|ray://\S+|\S+:\d+)$")


class TestCommand(Command):
    """`scenario test`, whose `--ray` takes an address or none: `--ray` followed by something that is not a
    Ray address (a scenario path, another option, nothing) means Ray's own default (`ray.init()`)."""

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        fixed: list[str] = []
        for i, arg in enumerate(args):
            nxt = args[i + 1] if i + 1 < len(args) else ""
            if arg == "--ray" and not (_RAY_ADDRESS.match(nxt) and not Path(nxt).exists()):
                arg = "--ray="
            fixed.append(arg)
        return super().parse_args(ctx, fixed)


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
    timeout: Annotated[
        float | None,
        typer.Option(
            metavar="SECONDS",
            help="Stop a run that takes longer than this (wall time); it is reported as an error.",
            min=0.001,
        ),
    ] = None,
    ray: Annotated[
        str | None,
        typer.Option(
            "--ray",
            metavar="[ADDRESS]",
            help="Run every scenario and variant as a task on a Ray cluster: the head's address "
            "(host:port, ray://host:10001), or none for Ray's default (RAY_ADDRESS, else a cluster "
            "started on this machine, else a new local one). Needs Ray: the `ray` extra.",
        ),
    ] = None,
    artifacts: Annotated[
        str | None,
        typer.Option(
            metavar="URL",
            help="With --ray: where recordings, reports, plots and summary.html go, one folder per "
            "variant: a local folder (default: --out; the workers send the files back) or an fsspec URL "
            "the workers write to (s3://bucket/runs, gs://..., file:///shared/mount).",
        ),
    ] = None,
    gpus: Annotated[
        str,
        typer.Option(
            metavar="auto|N",
            help="With --ray: GPUs a run with cameras asks for: auto (1 when the cluster has GPUs, else "
            "none) or a number (0: never). A scenario's `resources:` says otherwise.",
        ),
    ] = "auto",
) -> None:
    """Run many scenarios (in parallel processes, or on a Ray cluster), print a results table, write JUnit
    XML; exit 0 only if every run completes and every assertion passes.

    Examples:
      scenario test scenarios/ -j 2 --junit report.xml
      scenario test scenarios/ --ray --junit report.xml
      scenario test scenarios/ --ray 10.0.0.1:6379 --artifacts s3://bucket/runs --timeout 600
    """
    from runner.tools.suite import scenario_files, variants_of

    _check_ray_options(ray, artifacts, gpus)
    files = scenario_files(paths)
    if not files:
        raise fail(RunError("no scenario files found in " + ", ".join(map(str, paths))))
    if ray is not None:
        from runner.cli.cluster import test_on_ray

        where = artifacts if artifacts is not None else str(out_dir)
        test_on_ray(variants_of(files), ray, where, not no_record, allow_undecided, timeout, gpus, junit)
        return
    _test_here(variants_of(files), jobs, junit, out_dir, no_record, allow_undecided, timeout)


def _check_ray_options(ray: str | None, artifacts: str | None, gpus: str) -> None:
    """--artifacts and --gpus go with --ray; --gpus is `auto` or a number."""
    if ray is None:
        for option, given in (("--artifacts", artifacts is not None), ("--gpus", gpus != "auto")):
            if given:
                raise typer.BadParameter(f"{option} goes with --ray (without it, recordings go to --out)")
    if gpus != "auto":
        try:
            ok = float(gpus) >= 0
        except ValueError:
            ok = False
        if not ok:
            raise typer.BadParameter(f"--gpus {gpus!r}: expected auto or a number of GPUs (0 or more)")


def _test_here(
    variants: list[Any],
    jobs: int,
    junit: Path | None,
    out_dir: Path,
    no_record: bool,
    allow_undecided: bool,
    timeout: float | None,
) -> None:
    """The suite on this machine, `jobs` runs at once."""
    import concurrent.futures

    from runner.tools.report import write_junit

    if not no_record:
        out_dir.mkdir(parents=True, exist_ok=True)
    run_one = partial(
        _run_here, out_dir=out_dir, no_record=no_record, allow_undecided=allow_undecided, timeout=timeout
    )
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        suites = list(pool.map(run_one, variants))
    reports = {} if no_record else _write_reports(suites)  # one page per scenario, beside its recording
    out.print(suites_table(suites, reports))
    print_failures(suites)
    if junit is not None:
        write_junit(junit, suites)
    ok = sum(1 for s in suites if s.passed)
    out.print(f"{ok} passed, {len(suites) - ok} failed", markup=False)
    raise typer.Exit(0 if ok == len(suites) else 1)


def _run_here(
    variant: Any, out_dir: Path, no_record: bool, allow_undecided: bool, timeout: float | None
) -> Any:
    """`scenario run` of one variant in a process of its own (runner.tools.suite, as a Ray task runs it)."""
    from runner.tools.suite import run_variant

    record = None if no_record else out_dir / f"{variant.stem}.mcap"
    # `scenario test` killed outright (kill -9, the OOM killer) stops its runs as Ctrl-C does: they would
    # live on (each run's own processes end with it, runner.launch.keeper). The pool's threads, which
    # start the runs, live until every run is over: the signal is tied to the thread that started a run.
    return run_variant(
        variant, record, allow_undecided=allow_undecided, timeout_s=timeout, die_with_parent=True
    )


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
