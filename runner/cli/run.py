"""`scenario run`: validate, compile and run a scenario (each variant of its matrix, or this host's part of
it), with a progress line on a terminal, the table of what was recorded, what the events did, the
assertions' verdicts, and the results as JUnit XML or JSON."""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table
from rich.text import Text

from runner import interrupts
from runner.cli.console import err, fail, out
from runner.cli.notices import print_notices
from runner.cli.options import AllOpt, AllowUndecided
from runner.cli.plans import drawn_line, load_variants, strict_failure
from runner.cli.results import plot_failure, print_events, print_results
from runner.errors import RunError, ScenarioError

# A Zenoh endpoint: protocol/address[#config]
_ENDPOINT = re.compile(r"^(tcp|udp|tls|quic|ws|unixsock-stream|unixpipe|serial|vsock)/[^\s/]+.*$")

# `run`'s own options (each named after its parameter: --duration, --rate...)
_Duration = Annotated[
    float | None, typer.Option(metavar="SECONDS", help="Override the sim duration (s).", min=0.001)
]
_Rate = Annotated[str | None, typer.Option(metavar="RATE", help="realtime | max | a real-time factor.")]
_Record = Annotated[
    str | None, typer.Option(metavar="FILE", help="MCAP file to write (overrides the scenario).")
]
_NoRecord = Annotated[bool, typer.Option("--no-record", help="Do not record.")]
_Listen = Annotated[
    list[str] | None,
    typer.Option(
        metavar="ENDPOINT", help="Zenoh endpoint to listen on, e.g. tcp/127.0.0.1:7447 (repeatable)."
    ),
]
_Connect = Annotated[
    list[str] | None,
    typer.Option(metavar="ENDPOINT", help="Zenoh endpoint of another router to join (repeatable)."),
]
_Quiet = Annotated[bool, typer.Option("--quiet", "-q", help="No progress line and no table.")]
_JUnit = Annotated[
    Path | None, typer.Option(metavar="FILE", help="Write the assertions' results as JUnit XML.")
]
_NoJudge = Annotated[
    bool, typer.Option("--no-judge", help="Do not judge the assertions (e.g. with a shortened --duration).")
]
_ResultsJson = Annotated[Path | None, typer.Option(metavar="FILE", help="Write the run's results as JSON.")]
_Variant = Annotated[
    int | None,
    typer.Option(metavar="N", help="Run only this variant of the scenario's matrix (0-based).", min=0),
]
_Host = Annotated[
    str | None,
    typer.Option(
        metavar="NAME", help="With `hosts:` in the scenario: run this host's part and join the main host."
    ),
]
_Local = Annotated[
    bool, typer.Option("--local", help="Run every part on this machine, whatever `hosts:` says.")
]
_Strict = Annotated[
    bool,
    typer.Option(
        "--strict",
        help="Fail (exit 1) on a warning about the scenario itself (before running) and if any message "
        "published in the run was not recorded.",
    ),
]
_Foxglove = Annotated[
    int | None,
    typer.Option(
        "--foxglove",
        metavar="PORT",
        help="Serve the run live to Foxglove (WebSocket on 127.0.0.1:PORT, e.g. 8765).",
        min=0,
        max=65535,
    ),
]


_FoxgloveOrigin = Annotated[
    list[str] | None,
    typer.Option(
        "--foxglove-origin",
        metavar="ORIGIN",
        help="With --foxglove: also let web pages of this origin (scheme://host[:port]) connect; "
        "repeatable. Allowed without it: the Foxglove app, pages on localhost, local files, and clients "
        "that send no Origin (not browsers).",
    ),
]


@dataclass
class RunOptions:
    """What `run` was told that each variant's run needs."""

    quiet: bool
    listen: list[str] | None
    connect: list[str] | None
    no_judge: bool
    host: str | None  # (None with --local)
    strict: bool
    foxglove: int | None
    foxglove_origins: tuple[str, ...]
    allow_undecided: bool
    show_all: bool


def run(
    file: Annotated[Path, typer.Argument(help="Scenario YAML file.")],
    duration: _Duration = None,
    rate: _Rate = None,
    record: _Record = None,
    no_record: _NoRecord = False,
    listen: _Listen = None,
    connect: _Connect = None,
    quiet: _Quiet = False,
    junit: _JUnit = None,
    no_judge: _NoJudge = False,
    results_json: _ResultsJson = None,
    variant: _Variant = None,
    host: _Host = None,
    local: _Local = False,
    strict: _Strict = False,
    foxglove: _Foxglove = None,
    foxglove_origin: _FoxgloveOrigin = None,
    allow_undecided: AllowUndecided = False,
    show_all: AllOpt = False,
) -> None:
    """Validate, compile and run a scenario; record every message to MCAP; judge its assertions. With a
    `matrix:`, every variant runs and is judged on its own. With `hosts:`, this plays the first (main)
    host; `--host NAME` on another machine plays that one.

    Examples:
      scenario run scenarios/two_robots.yaml
      scenario run scenarios/two_robots.yaml --rate realtime --listen tcp/127.0.0.1:7447
      scenario run scenarios/two_robots.yaml --rate realtime --foxglove 8765
      scenario run scenarios/two_robots.yaml --foxglove 8765 --foxglove-origin https://viz.example.org
      scenario run fleet.yaml --host gpu_box
    """
    # Until a run starts its processes (loading, compiling), Ctrl-C and SIGTERM end the command at once:
    # nothing is started or recorded yet. Then (runner.launch.run) they stop the run in order, recording kept.
    interrupts.exit_at_once()
    parsed_rate = _parse_rate(rate)
    _check_endpoints(listen, connect)
    origins = _check_origins(foxglove_origin, foxglove)
    try:
        # (with --no-record, the scenario's record.path is not checked: nothing is written there)
        plans = load_variants(file, os.devnull if no_record else record, variant)
    except ScenarioError as e:
        raise fail(e) from None
    who = None if local else host
    options = RunOptions(
        quiet, listen, connect, no_judge, who, strict, foxglove, origins, allow_undecided, show_all
    )
    suites = []
    code = 0
    for i, (label, plan) in enumerate(plans):
        if strict:
            strict_failure(plan)
        if duration is not None:
            _warn_windows(plan, duration, quiet)
        _override(plan, duration, parsed_rate, local)
        if host is not None and not local and host not in plan.hosts:
            raise fail(
                RunError(f"no host named {host!r}; hosts: {', '.join(plan.hosts) or '(none declared)'}")
            )
        if no_record:
            plan.record.enabled = False
        elif len(plans) > 1:
            path = Path(plan.record.path)
            plan.record.path = str(path.with_name(f"{path.stem}-{i}{path.suffix}"))
        if label and not quiet:
            err.print(f"variant {i}: {label}", markup=False)
        elif drawn_line(plan) and not quiet:
            err.print(drawn_line(plan), markup=False)
        suite, rc = _run_one(plan, label, options)
        suites.append(suite)
        code = max(code, rc)
        if rc == 130:
            break
    _write_results(suites, junit, results_json)
    raise typer.Exit(143 if code == 130 and interrupts.terminated() else code)


def _parse_rate(value: str | None) -> str | float | None:
    if value is None:
        return None
    if value in ("realtime", "max"):
        return value
    try:
        f = float(value)
    except ValueError:
        raise typer.BadParameter("expected 'realtime', 'max' or a positive real-time factor") from None
    if not f > 0 or math.isinf(f):
        raise typer.BadParameter("a real-time factor must be a positive number")
    return f


def _check_endpoints(listen: list[str] | None, connect: list[str] | None) -> None:
    """--listen and --connect take Zenoh endpoints, written with their protocol."""
    for option, values in (("--listen", listen), ("--connect", connect)):
        for value in values or []:
            if not _ENDPOINT.match(value):
                raise fail(
                    RunError(
                        f"{option} {value!r}: not a Zenoh endpoint\n  hint:     write it with its "
                        f"protocol, e.g. tcp/{value.split('/')[-1] or '127.0.0.1:7447'}"
                    )
                )


def _check_origins(origins: list[str] | None, port: int | None) -> tuple[str, ...]:
    """--foxglove-origin: web origins as browsers send them, and only with --foxglove."""
    from runner.launch.live_gate import valid_origin

    for origin in origins or []:
        if not valid_origin(origin):
            raise fail(
                RunError(
                    f"--foxglove-origin {origin!r}: not a web origin\n  expected: scheme://host[:port] "
                    "(http, https or file), or null\n  hint:     as the browser's address bar shows the "
                    "page, without its path, e.g. https://viz.example.org or http://192.168.1.7:8080"
                )
            )
    if origins and port is None:
        raise fail(RunError("--foxglove-origin is for the live view: give --foxglove PORT too"))
    return tuple(origins or ())


def _override(plan: Any, duration: float | None, rate: str | float | None, local: bool) -> None:
    """--duration, --rate and --local, on the run and every world of it."""
    for part in plan.every_plan():
        if duration is not None:
            part.duration_ns = round(duration * 1e9)
        if rate is not None:
            part.rate = rate
        if local:
            part.hosts = {}


def _write_results(suites: list[Any], junit: Path | None, results_json: Path | None) -> None:
    """--junit and --results-json: every variant's results."""
    if junit is not None:
        from runner.tools.report import write_junit

        write_junit(junit, suites)
    if results_json is not None:
        data = suites[0].to_json() if len(suites) == 1 else {"variants": [s.to_json() for s in suites]}
        results_json.write_text(json.dumps(data, indent=2))


def _warn_windows(plan: Any, duration: float, quiet: bool) -> None:
    """`run --duration` shorter than an assertion's window: it will not be decided; say so first."""
    from runner.checks import specs_from_plan
    from runner.compile import window_edge

    for part in plan.worlds or [plan]:
        for a in specs_from_plan(part.assertions):
            edge = window_edge(a)
            if edge is not None and edge[1] > duration and not quiet:
                err.print(
                    f"warning: assertion {a.name!r}: its window ({edge[0]}: {edge[1]:g} s) lies past "
                    f"--duration {duration:g}: it will not be decided",
                    markup=False,
                    style="yellow",
                )


def _run_one(plan: Any, label: str, options: RunOptions) -> tuple[Any, int]:
    """Run one plan (a variant, or this host's part), print and judge it: its suite and exit code."""
    from runner.checks.judge import ended_early
    from runner.launch.run import run_plan
    from runner.tools.report import Suite, _now, firings, judge_for
    from runner.wire.transport import use_run_settings

    started = _now()
    host = options.host
    if not options.quiet:
        print_notices(plan.notice_items, verbose=False)
    member = bool(plan.hosts) and host not in (None, plan.main_host)
    endpoints = _endpoints(plan, options.listen, host)
    use_run_settings(plan.zenoh)  # the scenario's zenoh: (TLS...) for every session of the run
    if not options.quiet:
        who = f" as host {host!r}" if member else ""
        err.print(
            f"running {plan.name}{who} ({plan.duration_ns / 1e9:g} s sim), Zenoh on {', '.join(endpoints)}",
            markup=False,
        )
    judge = None if options.no_judge or member else judge_for(plan)  # the main host judges
    try:
        with _progress_line(plan, shown=not options.quiet and err.is_terminal) as on_progress:
            result = run_plan(
                plan,
                listen=endpoints,
                connect=options.connect or (),
                on_progress=on_progress,
                judge=judge,
                host=host,
                foxglove_port=options.foxglove,
                foxglove_origins=options.foxglove_origins,
            )
    except RunError as e:
        raise fail(e) from None
    ended = ended_early(interrupts.ending(result.reason), result.sim_ns)
    results = (
        judge.finish(result.sim_ns, complete=ended is None, why=ended or "") if judge is not None else []
    )
    events = firings(judge.fired) if judge is not None else []
    if not options.quiet:
        _print_summary(result, options.show_all)
        print_events(events)
    if results:
        print_results(results, options.allow_undecided)
    error = _run_error(result, options.strict)
    if error:
        err.print("error: " + error, markup=False, style="red")
    suite = Suite(
        f"{plan.name}[{label}]" if label else plan.name,
        results,
        error,
        result.wall_s,
        str(result.mcap) if result.mcap else None,
        sim_s=result.sim_ns / 1e9,
        allow_undecided=options.allow_undecided,
        timestamp=started,
        interrupted=ended,
        label=label,
        events=events,
        properties=_run_properties(result),
    )
    if results and not suite.passed and result.mcap is not None:
        plot_failure(plan, result.mcap, results)
    code = result.exit_code
    if code == 0 and (not suite.passed or error):
        code = 1
    return suite, code


def _endpoints(plan: Any, listen: list[str] | None, host: str | None) -> list[str]:
    """Where this run's Zenoh router listens: --listen, else this host's address (with `hosts:`), else
    the scenario's `zenoh.listen`, else a free port on loopback."""
    from runner.wire.transport import free_port

    if plan.hosts:
        return list(listen or []) or [plan.hosts[host or plan.main_host]]
    # loopback only unless told otherwise (--listen, zenoh.listen)
    return list(listen or []) or plan.listen or [f"tcp/127.0.0.1:{free_port()}"]


@contextmanager
def _progress_line(plan: Any, shown: bool) -> Iterator[Callable[[int, float], None]]:
    """The run's progress on stderr (sim seconds, real-time factor) while it runs: the callback to give
    `run_plan`, a no-op when not shown."""
    if not shown:
        yield lambda sim_ns, wall_s: None
        return
    from rich.progress import BarColumn, Progress, TextColumn

    progress = Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.fields[sim]:>7.2f}/{task.total:.1f} s sim  {task.fields[rtf]:>6.1f}× real time"),
        console=err,
        transient=True,
    )
    task = progress.add_task(plan.name, total=plan.duration_ns / 1e9, sim=0.0, rtf=0.0)
    progress.start()

    def on_progress(sim_ns: int, wall_s: float) -> None:
        sim = sim_ns / 1e9
        progress.update(task, completed=sim, sim=sim, rtf=sim / wall_s if wall_s > 0 else 0.0)

    try:
        yield on_progress
    finally:
        progress.stop()


def _run_error(result: Any, strict: bool) -> str | None:
    """The run's error; with --strict, messages published but not recorded are one, and so are messages
    dropped on their way in (a NaN in a command, another type: what was sent was not obeyed)."""
    error: str | None = result.error
    lost = sum(result.lost.values()) + sum(t.lost for t in result.topics)
    if strict and lost and error is None:
        where = sorted({k for k, n in result.lost.items() if n} | {t.key for t in result.topics if t.lost})
        error = f"--strict: {lost} message(s) published but not recorded, on {', '.join(where)}"
    rejected = getattr(result, "rejected", {})
    if strict and rejected and error is None:
        n = sum(sum(whys.values()) for whys in rejected.values())
        error = f"--strict: {n} message(s) rejected, on {', '.join(sorted(rejected))} (the table says why)"
    return error


def _print_summary(result: Any, show_all: bool = False) -> None:
    """What the run recorded (topic, type, counts, rate, losses), what was rejected, and how fast it ran."""
    from runner.wire.transport import hidden_key

    table = Table(
        "topic",
        "type",
        "published",
        "recorded",
        "rate (sim Hz)",
        "lost",
        title="Recorded",
        title_justify="left",
    )
    lost = result.lost
    hidden = 0
    for t in result.topics:
        n_lost = lost.get(t.key, 0) + t.lost
        if hidden_key(t.key) and not show_all and not n_lost:  # (a loss is never hidden)
            hidden += 1
            continue
        published = result.published.get(t.key)  # (the worlds' count; other publishers say theirs by seq)
        table.add_row(
            t.key,
            t.type,
            str(published) if published is not None else "-",
            str(t.count),
            f"{t.rate():.1f}",
            Text(str(n_lost), "red") if n_lost else "0",
        )
    if hidden:
        table.caption = f"and {hidden} helper topic(s) (`_truth`, `_state`...): --all lists them"
        table.caption_justify = "left"
    if result.topics:
        out.print(table)
    for key, whys in sorted(getattr(result, "rejected", {}).items()):
        for why, n in whys.items():
            out.print(f"rejected: {n} message(s) on {key}: {why}", markup=False, style="yellow")
    _print_outside(result)
    sim = result.sim_ns / 1e9
    rtf = sim / result.wall_s if result.wall_s > 0 else 0.0
    where = f" -> {result.mcap}" if result.mcap else ""
    out.print(f"{result.reason}: {sim:.2f} s sim in {result.wall_s:.2f} s wall ({rtf:.1f}× real time){where}")


def _run_properties(result: Any) -> dict[str, str]:
    """What the results (JSON, JUnit <properties>) say of messages dropped or put from outside the run:
    `rejected.<key>` = `1 NaN or Inf values`, `outside.<key>` = how many, `outside.from` = who."""
    said = {
        f"rejected.{key}": "; ".join(f"{n} {why}" for why, n in whys.items())
        for key, whys in sorted(getattr(result, "rejected", {}).items())
    }
    outside = getattr(result, "outside", {})
    said.update({f"outside.{key}": str(n) for key, n in sorted(outside.items())})
    if outside and getattr(result, "outsiders", None):
        said["outside.from"] = "; ".join(result.outsiders)
    return said


def _print_outside(result: Any) -> None:
    """Messages put on the run's keys by publishers outside the run (a stray client, a flood), and who."""
    outside: dict[str, int] = getattr(result, "outside", {})
    if not outside:
        return
    who = getattr(result, "outsiders", [])
    named = (
        f"a publisher outside the run ({who[0]})"
        if len(who) == 1
        else f"publishers outside the run ({'; '.join(who)})"
        if who
        else "a publisher outside the run (gone before it could be named)"
    )
    recorded = {t.key: t.count for t in result.topics}
    for key, n in sorted(outside.items()):
        total = recorded.get(key)
        head = (
            f"recorded {total} message(s) on {key}, {n}" if total is not None else f"{n} message(s) on {key}"
        )
        out.print(f"outside: {head} from {named}", markup=False, style="yellow")
