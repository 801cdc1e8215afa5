"""`scenario test --ray`: the suite on a Ray cluster (runner.tools.fanout), as the terminal shows it: one
progress bar (done, running, failed, ETA) and a line per finished run, then `test`'s table (with the node
each run took and its attempts, reports linked), the failures, one JUnit file and the summary page
(`summary.html` at the top of the artifacts)."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import typer

from runner import interrupts
from runner.cli.console import err, fail, out
from runner.cli.results import print_failures, suites_table
from runner.errors import RunError


def test_on_ray(
    variants: list[Any],
    address: str,
    where: str,
    record: bool,
    allow_undecided: bool,
    timeout_s: float | None,
    gpus: str,
    junit: Path | None,
) -> None:
    """Run `variants` on the cluster at `address` ("": Ray's default), their files to `where`; exit 0 only
    if every run passed, 130 (143) when Ctrl-C (SIGTERM) cut the suite short."""
    from runner.tools import artifacts, fanout

    started = time.perf_counter()
    try:
        if artifacts.is_url(where):
            artifacts.check_url(where)
        root, runtime_env = fanout.shipped([v.file for v in variants], where)
        ray = fanout.connect(address, runtime_env)
    except RunError as e:
        raise fail(e) from None
    interrupts.interruptible()  # (ray.init made SIGTERM exit at once: it cancels the suite as Ctrl-C does)
    try:
        cluster = fanout.cluster_info(ray)
        _say_cluster(cluster, time.perf_counter() - started)
        jobs, notes = fanout.plan_jobs(variants, gpus, cluster)
        for note in notes:
            err.print("note: " + note, markup=False)
        settings = fanout.Settings(record, allow_undecided, timeout_s, where, root)
        with _progress(len(jobs)) as (on_progress, on_done):
            outcomes, interrupted = fanout.run_jobs(ray, jobs, settings, on_progress, on_done)
    except RunError as e:
        raise fail(e) from None
    finally:
        ray.shutdown()
    _report(outcomes, where, junit, time.perf_counter() - started, interrupted, len(jobs))


def _say_cluster(cluster: dict[str, Any], joined_s: float) -> None:
    total = cluster["total"]
    err.print(
        f"Ray cluster: {len(cluster['nodes'])} node(s), {total.get('CPU', 0):g} CPU(s), "
        f"{total.get('GPU', 0):g} GPU(s), joined in {joined_s:.1f} s",
        markup=False,
    )


@contextmanager
def _progress(total: int) -> Iterator[tuple[Callable[[int, int, int], None], Callable[[Any], None]]]:
    """(on_progress, on_done) for run_jobs: one bar on a terminal (done / running / failed, ETA), and a
    line per finished run (the only output when stderr is not a terminal, as in CI logs)."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    finished = [0]

    def on_done(outcome: Any) -> None:
        finished[0] += 1
        s = outcome.suite
        verdict = "pass" if s.passed else ("ERROR" if s.error else "FAIL")
        err.print(f"[{finished[0]}/{total}] {s.name}: {verdict} ({s.time_s:.1f} s)", markup=False)

    if not err.is_terminal:
        yield (lambda done, running, failed: None), on_done
        return
    bar = Progress(
        TextColumn("[bold]scenario test --ray"),
        BarColumn(),
        TextColumn(
            "{task.completed}/{task.total} done, {task.fields[running]} running, {task.fields[failed]} failed"
        ),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=err,
        transient=True,
    )
    task = bar.add_task("suite", total=total, running=0, failed=0)

    def on_progress(done: int, running: int, failed: int) -> None:
        bar.update(task, completed=done, running=running, failed=failed)

    bar.start()
    try:
        yield on_progress, on_done
    finally:
        bar.stop()


def _report(
    outcomes: list[Any], where: str, junit: Path | None, wall_s: float, interrupted: bool, total: int
) -> None:
    """The table, the retries and failures, JUnit, the summary page; then the exit."""
    from runner.tools import artifacts
    from runner.tools.report import write_junit
    from runner.tools.summary import Row, summary_html

    suites = [o.suite for o in outcomes]
    reports = {o.suite.name: o.files[f"{o.job.key}.html"] for o in outcomes if f"{o.job.key}.html" in o.files}
    ran_on = {o.suite.name: _ran_on(o) for o in outcomes}
    out.print(suites_table(suites, reports, ran_on))
    for o in outcomes:
        if o.attempts > 1:
            err.print(
                f"{o.suite.name}: retried: its worker died; attempt {o.attempts} ran it to its end",
                markup=False,
                style="yellow",
            )
    print_failures(suites)
    if junit is not None:
        write_junit(junit, suites)
    rows = [
        Row(
            o.suite,
            o.job.values,
            _ran_on(o),
            o.attempts,
            {n: _relative(p, where) for n, p in o.files.items()},
            o.wall_s,
        )
        for o in outcomes
    ]
    try:
        page = artifacts.write_text(
            where, "summary.html", summary_html("scenario test --ray", rows, wall_s, interrupted)
        )
        out.print(f"summary: {page}", markup=False)
    except Exception as e:  # a page is a convenience: never what fails the suite
        err.print(f"no summary page: {type(e).__name__}: {e}", markup=False)
    ok = sum(1 for s in suites if s.passed)
    out.print(f"{ok} passed, {len(suites) - ok} failed", markup=False)
    if interrupted:
        err.print(f"interrupted: {total - ok} of {total} runs did not pass or were cancelled", markup=False)
        raise typer.Exit(143 if interrupts.terminated() else 130)
    raise typer.Exit(0 if ok == len(suites) == total else 1)


def _ran_on(outcome: Any) -> str:
    """`127.0.0.1 3f2a9c1e` (the node's address and id), and `(2 attempts)` when it was retried."""
    props = outcome.suite.properties
    node = f"{props.get('ray.node_address', '')} {outcome.node[:8]}".strip()
    return node + (f" ({outcome.attempts} attempts)" if outcome.attempts > 1 else "")


def _relative(path: str, root: str) -> str:
    """A file's link from the summary page at the top of the artifacts: relative when it lies under it."""
    base = root.rstrip("/") + "/"
    if path.startswith(base):
        return path[len(base) :]
    return path if "://" in path else Path(path).resolve().as_uri()
