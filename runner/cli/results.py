"""Assertion verdicts on the terminal, as `run` and `check` print them: the table, the pass/fail summary
line, and the trajectory plot written beside the recording when an assertion failed; and `test`'s table of
scenario runs and their failures."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rich.style import Style
from rich.table import Table
from rich.text import Text

from runner.cli.console import err, out
from runner.tools.report import event_rows

MARKS = {
    "pass": Text("pass", "green"),
    "fail": Text("FAIL", "bold red"),
    "undecided": Text("not decided", "yellow"),
}


def plot_failure(plan: Any, mcap: Path, results: list[Any]) -> None:
    """A failed assertion: the robots' paths, regions and the failure point, as a PNG beside the MCAP."""
    from runner.tools.plot import trajectory_plot

    try:
        png = trajectory_plot(plan, mcap, results, mcap.with_suffix(".trajectory.png"))
    except Exception as e:  # a picture must never hide the verdict
        err.print(f"warning: no trajectory plot ({type(e).__name__}: {e})", markup=False)
        return
    if png is not None:
        out.print(f"trajectory plot: {png}", markup=False)


def print_results(results: list[Any], allow_undecided: bool = False) -> None:
    """The assertions' table and a summary line; an undecided one is named with why."""
    table = Table(
        "assertion",
        "type",
        "result",
        "at (sim s)",
        "value",
        "bound",
        title="Assertions",
        title_justify="left",
    )
    for r in results:
        table.add_row(
            r.name, r.type, MARKS[r.status], f"{r.t:.3f}" if r.t is not None else "", r.value, r.bound
        )
    out.print(table)
    failed = [r for r in results if r.status == "fail"]
    undecided = [r for r in results if r.undecided]
    summary = f"{len(results) - len(failed) - len(undecided)} passed, {len(failed)} failed"
    if undecided:
        counted = (
            "not counted as failures: --allow-undecided" if allow_undecided else "each counts as a failure"
        )
        summary += f", {len(undecided)} not decided ({counted})"
    bad = failed or (undecided and not allow_undecided)
    out.print(summary, style="red" if bad else ("yellow" if undecided else "green"), markup=False)
    for r in undecided:
        out.print(f"  not decided: {r.name}: {r.message}", markup=False)
    for r in failed:
        if r.type == "event":  # an `end:` that failed the run: its own message says why
            out.print(f"  {r.name} failed the run at t={r.t:.3f} s: {r.message}", markup=False)


def print_events(events: list[dict[str, Any]]) -> None:
    """What the run's events did, when and why (`firings`); nothing for a run without events."""
    if not events:
        return
    table = Table("t (sim s)", "event", "why", "what it did", title="Events", title_justify="left")
    rows, left = event_rows(events)
    for row in rows:
        table.add_row(*row)
    if left:
        table.caption = f"and {left} more firing(s): every one is on the run's `_events` topic"
        table.caption_justify = "left"
    out.print(table)


def suites_table(suites: list[Any], reports: dict[str, str], where: dict[str, str] | None = None) -> Table:
    """One row per scenario run (`scenario test`): assertions passed, failed (not decided), events fired
    (when some run had events), verdict, time, where it ran (with --ray: {name: node and attempts}), report
    link (a path, or a URL)."""
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
        *(["ran on"] if where else []),
        *(["report"] if reports else []),
        title="Scenarios",
        title_justify="left",
    )
    for s in suites:
        failed = sum(1 for r in s.results if r.status == "fail")
        verdict = MARKS["pass"] if s.passed else (Text("ERROR", "bold red") if s.error else MARKS["fail"])
        link = [_link(reports[s.name])] if s.name in reports else []
        table.add_row(
            s.name,
            str(len(s.results)),
            str(len(s.results) - failed - s.undecided),
            str(failed),
            *([str(s.undecided)] if any_undecided else []),
            *([str(len(s.events))] if any_events else []),
            verdict,
            f"{s.time_s:.1f}",
            *([where.get(s.name, "")] if where else []),
            *(link or ([""] if reports else [])),
        )
    return table


def _link(target: str) -> Text:
    """A terminal link to a report: a file, or a URL as it is."""
    url = target if "://" in target else f"file://{Path(target).resolve()}"
    return Text(target, Style(link=url))


def print_failures(suites: list[Any]) -> None:
    """Each run's error and each failed assertion, named by its scenario."""
    for s in suites:
        if s.error:
            err.print(f"{s.name}: {s.error}", markup=False, style="red")
        for r in s.results:
            if not r.passed:
                from runner.tools.report import failure_text

                err.print(f"{s.name}: {failure_text(r)}", markup=False, style="red")
