"""The `scenario` command.

User mistakes (`ScenarioError`, `RunError`) are printed without a traceback and exit 1; usage errors exit
2; anything else is a bug and shows its traceback.
"""

from __future__ import annotations

import inspect
import json
import math
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from runner import interrupts
from runner.errors import RunError, ScenarioError
from runner.plan import RobotPlan


def first_sentence(doc: str) -> str:
    """A command's line in `scenario --help`: the first sentence of its docstring, on one line."""
    one = " ".join(inspect.cleandoc(doc).split("\n\n")[0].split())
    end = re.search(r"(?<=[.!?])\s+(?=[A-Z`(])", one)
    return one[: end.start()] if end else one


def _plain_help_option(option: Any) -> Any:
    if option is not None:
        option.metavar = ""  # (a flag: no `<bool>` beside it)
    return option


class _Command(typer.core.TyperCommand):
    """A command whose help reads as a user's: a metavar for each value (FILE, SECONDS), none for a flag
    (typer would print `<bool>`, `<str>`, `<float range>`), arguments by their metavar in the usage line
    (`FILE`, not `{file}`), and a one-line, one-sentence short help for the command list (typer would keep
    the docstring's hard line breaks)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if not self.short_help and self.help:
            self.short_help = first_sentence(self.help)
        for param in self.params:
            if isinstance(param, typer.core.TyperOption) and param.is_flag:
                param.metavar = ""
            elif param.metavar is None:
                param.metavar = (param.name or "value").upper()
            if isinstance(param, typer.core.TyperArgument):
                # an argument's metavar names it; typer would add its type beside it
                param.display_type_rich = lambda ctx: None  # type: ignore[method-assign]

    def get_help_option(self, ctx: Any) -> Any:
        return _plain_help_option(super().get_help_option(ctx))

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        pieces = [self.options_metavar] if self.options_metavar else []
        for param in self.get_params(ctx):
            if isinstance(param, typer.core.TyperArgument):
                name = param.metavar or (param.name or "").upper()
                name = name if param.required else f"[{name}]"
                pieces.append(name + ("..." if param.nargs != 1 else ""))
        return pieces


class _Group(typer.core.TyperGroup):
    def get_help_option(self, ctx: Any) -> Any:
        return _plain_help_option(super().get_help_option(ctx))


app = typer.Typer(
    name="scenario",
    help="Declarative robot-simulation scenarios: URDF/xacro robots, MuJoCo physics, Zenoh, MCAP.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    cls=_Group,
)
# Wide tables when piped (CI logs): key names are long and worth reading whole.
out = Console(highlight=False, emoji=False, width=None if sys.stdout.isatty() else 160)
err = Console(stderr=True, highlight=False, emoji=False, width=None if sys.stderr.isatty() else 160)


def _fail(e: Exception) -> typer.Exit:
    text = e.render() if isinstance(e, ScenarioError) else str(e)
    err.print("error: " + text, markup=False, soft_wrap=True, style="red")
    return typer.Exit(1)


# A Zenoh endpoint: protocol/address[#config]
_ENDPOINT = re.compile(r"^(tcp|udp|tls|quic|ws|unixsock-stream|unixpipe|serial|vsock)/[^\s/]+.*$")


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


StrictValidate = Annotated[
    bool,
    typer.Option(
        "--strict",
        help="Warnings about the scenario itself (an assertion window past its end, a timeline topic "
        "nothing subscribes to...) are errors: exit 1 (for CI).",
    ),
]


def _strict_failure(plan: Any) -> None:
    """With --strict: the scenario's own warnings are errors (exit 1)."""
    if plan.scenario_warnings:
        for text in plan.scenario_warnings:
            err.print("error: " + text, markup=False, style="red")
        err.print(
            f"--strict: {len(plan.scenario_warnings)} warning(s) about the scenario are errors",
            markup=False,
            style="red",
        )
        raise typer.Exit(1)


@app.command()
def validate(
    file: Annotated[Path, typer.Argument(help="Scenario YAML file.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print the compiled plan as JSON.")] = False,
    strict: StrictValidate = False,
) -> None:
    """Check a scenario and print what would run: robots, plugins, topics with types and rates.

    Example: scenario validate scenarios/two_robots.yaml
    """
    try:
        plans = _load_variants(file, None, None)
    except ScenarioError as e:
        raise _fail(e) from None
    plan = plans[0][1]
    if len(plans) > 1:
        out.print(f"{len(plans)} variants: " + "; ".join(label for label, _ in plans), markup=False)
    if as_json:
        out.print_json(plan.model_dump_json(exclude={"mjcf"}))
        return
    rate = plan.rate if isinstance(plan.rate, str) else f"{plan.rate:g}× real time"
    parts = plan.worlds or [plan]
    robots_n = sum(len(p.robots) for p in parts)
    worlds = f"{len(parts)} worlds, " if plan.worlds else ""
    out.print(
        f"[bold]{plan.name}[/]: {plan.duration_ns / 1e9:g} s sim at {rate}, step {plan.step_ns / 1e6:g} ms, "
        f"{worlds}{robots_n} robot(s), seed {plan.seed}"
    )
    robots = Table(
        "robot", "namespace", "description", "links", "plugins", title="Robots", title_justify="left"
    )
    if plan.worlds:
        robots.add_column("world")
    for part in parts:
        for r in part.robots:
            row = [
                r.name,
                r.namespace,
                Path(r.description_file).name,
                str(len(r.links)),
                ", ".join(f"{p.name}" + (f" @{p.rate:g} Hz" if p.rate else "") for p in r.plugins),
            ]
            robots.add_row(*row, *([part.name.rsplit("/", 1)[-1]] if plan.worlds else []))
    out.print(robots)
    for part in parts:
        for r in part.robots:
            _print_parity(r)
    topics = Table("key", "type", "dir", "rate (sim Hz)", "from", title="Topics", title_justify="left")
    for part in parts:
        for t in part.topics():
            topics.add_row(t.key, t.type, t.direction, f"{t.rate:g}" if t.rate else "-", t.owner)
    out.print(topics)
    if plan.nodes:
        nodes = Table(
            "node",
            "command",
            "namespace",
            "required",
            "respawn",
            "lockstep",
            title="Nodes",
            title_justify="left",
        )
        for n in plan.nodes:
            argv = [Path(n.argv[0]).name, *n.argv[1:]]
            nodes.add_row(
                n.name,
                " ".join(argv),
                n.namespace or "-",
                "yes" if n.required else "no",
                n.respawn if n.respawn == "never" else f"{n.respawn} (up to {n.respawn_limit})",
                "yes" if n.name in plan.lockstep else "no",
            )
        out.print(nodes)
    if plan.bridges:
        bridges = Table(
            "sim topic", "", "other side", "type", "options", title="Bridges", title_justify="left"
        )
        arrows = {"SIM_TO_ZENOH": "->", "ZENOH_TO_SIM": "<-", "BIDIRECTIONAL": "<->"}
        for b in plan.bridges:
            other = f"ROS 2 {b.ros_topic} (domain {b.ros2.domain})" if b.ros2 else str(b.key)
            options = [b.encoding] if not b.ros2 else []
            options += [f"<= {b.rate:g}/s"] if b.rate else []
            options += ["lazy"] if b.lazy else []
            bridges.add_row(b.sim_key, arrows[b.direction], other, b.type, ", ".join(options))
        out.print(bridges)
    if plan.timeline:
        out.print(
            f"timeline: {len(plan.timeline)} message(s) from t={plan.timeline[0].t_ns / 1e9:g} s "
            f"to t={plan.timeline[-1].t_ns / 1e9:g} s"
        )
    out.print(f"record: {plan.record.path if plan.record.enabled else 'off'}")
    _print_notices(plan.notices, verbose=True)
    if strict:
        for _, p in plans:
            _strict_failure(p)


def _shown_path(file: str) -> str:
    """A path as the user would type it: relative to the current folder when it is below it."""
    try:
        return str(Path(file).relative_to(Path.cwd()))
    except ValueError:
        return file


def _print_parity(robot: RobotPlan) -> None:
    """The robot as in Gazebo: drives and wheels, sensors with topics and rates, self-collision, and what
    was changed, dropped or ignored to load it, each with its file and line."""
    if not robot.gazebo:
        return
    table = Table(
        "", "", "where", title=f"{robot.name} as in Gazebo", title_justify="left", show_header=False, box=None
    )
    for line in robot.gazebo:
        where = f"{_shown_path(line.file)}:{line.line}" if line.file and line.line else ""
        table.add_row(line.kind, line.text, where)
    out.print(table)


def _print_notices(notices: list[str], verbose: bool) -> None:
    if not notices:
        return
    if not verbose:
        err.print(f"{len(notices)} warning(s): `scenario validate` lists them", markup=False)
        return
    err.print(f"{len(notices)} warning(s):", markup=False)
    for text in notices:
        err.print("warning: " + text, markup=False, style="yellow")


AllOpt = Annotated[
    bool,
    typer.Option(
        "--all",
        help="List the run's own helper topics too (`_truth`, `_contacts`, `_state`, `_model`, `_plan`: a "
        "name part starting with `_`); hidden by default, and always recorded.",
    ),
]


AllowUndecided = Annotated[
    bool,
    typer.Option(
        "--allow-undecided",
        help="An assertion the run could not decide (its window lies past the run's end, the run was "
        "interrupted, its topic carried nothing) does not fail the run (by default it does).",
    ),
]


@app.command()
def run(
    file: Annotated[Path, typer.Argument(help="Scenario YAML file.")],
    duration: Annotated[
        float | None, typer.Option(metavar="SECONDS", help="Override the sim duration (s).", min=0.001)
    ] = None,
    rate: Annotated[
        str | None, typer.Option(metavar="RATE", help="realtime | max | a real-time factor.")
    ] = None,
    record: Annotated[
        str | None, typer.Option(metavar="FILE", help="MCAP file to write (overrides the scenario).")
    ] = None,
    no_record: Annotated[bool, typer.Option("--no-record", help="Do not record.")] = False,
    listen: Annotated[
        list[str] | None,
        typer.Option(
            metavar="ENDPOINT", help="Zenoh endpoint to listen on, e.g. tcp/127.0.0.1:7447 (repeatable)."
        ),
    ] = None,
    connect: Annotated[
        list[str] | None,
        typer.Option(metavar="ENDPOINT", help="Zenoh endpoint of another router to join (repeatable)."),
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress line and no table.")] = False,
    junit: Annotated[
        Path | None, typer.Option(metavar="FILE", help="Write the assertions' results as JUnit XML.")
    ] = None,
    no_judge: Annotated[
        bool,
        typer.Option("--no-judge", help="Do not judge the assertions (e.g. with a shortened --duration)."),
    ] = False,
    results_json: Annotated[
        Path | None, typer.Option(metavar="FILE", help="Write the run's results as JSON.")
    ] = None,
    variant: Annotated[
        int | None,
        typer.Option(metavar="N", help="Run only this variant of the scenario's matrix (0-based).", min=0),
    ] = None,
    host: Annotated[
        str | None,
        typer.Option(
            metavar="NAME", help="With `hosts:` in the scenario: run this host's part and join the main host."
        ),
    ] = None,
    local: Annotated[
        bool, typer.Option("--local", help="Run every part on this machine, whatever `hosts:` says.")
    ] = False,
    strict: Annotated[
        bool,
        typer.Option(
            "--strict",
            help="Fail (exit 1) on a warning about the scenario itself (before running) and if any message "
            "published in the run was not recorded.",
        ),
    ] = False,
    foxglove: Annotated[
        int | None,
        typer.Option(
            "--foxglove",
            metavar="PORT",
            help="Serve the run live to Foxglove (WebSocket on 127.0.0.1:PORT, e.g. 8765).",
            min=0,
            max=65535,
        ),
    ] = None,
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
      scenario run fleet.yaml --host gpu_box
    """
    # Until a run starts its processes (loading, compiling), Ctrl-C and SIGTERM end the command at once:
    # nothing is started or recorded yet. Then (runner.launch.run) they stop the run in order, recording kept.
    interrupts.exit_at_once()
    parsed_rate = _parse_rate(rate)
    for option, values in (("--listen", listen), ("--connect", connect)):
        for value in values or []:
            if not _ENDPOINT.match(value):
                raise _fail(
                    RunError(
                        f"{option} {value!r}: not a Zenoh endpoint\n  hint:     write it with its "
                        f"protocol, e.g. tcp/{value.split('/')[-1] or '127.0.0.1:7447'}"
                    )
                )
    try:
        plans = _load_variants(file, record, variant)
    except ScenarioError as e:
        raise _fail(e) from None
    suites = []
    code = 0
    for i, (label, plan) in enumerate(plans):
        if strict:
            _strict_failure(plan)
        if duration is not None:
            _warn_windows(plan, duration, quiet)
        for part in plan.every_plan():  # the run and every world of it
            if duration is not None:
                part.duration_ns = round(duration * 1e9)
            if parsed_rate is not None:
                part.rate = parsed_rate
            if local:
                part.hosts = {}
        if host is not None and not local and host not in plan.hosts:
            raise _fail(
                RunError(f"no host named {host!r}; hosts: {', '.join(plan.hosts) or '(none declared)'}")
            )
        if no_record:
            plan.record.enabled = False
        elif len(plans) > 1:
            path = Path(plan.record.path)
            plan.record.path = str(path.with_name(f"{path.stem}-{i}{path.suffix}"))
        if label and not quiet:
            err.print(f"variant {i}: {label}", markup=False)
        suite, rc = _run_one(
            plan,
            label,
            quiet,
            listen,
            connect,
            no_judge,
            None if local else host,
            strict,
            foxglove,
            allow_undecided=allow_undecided,
            show_all=show_all,
        )
        suites.append(suite)
        code = max(code, rc)
        if rc == 130:
            break
    if junit is not None:
        from runner.tools.report import write_junit

        write_junit(junit, suites)
    if results_json is not None:
        data = suites[0].to_json() if len(suites) == 1 else {"variants": [s.to_json() for s in suites]}
        results_json.write_text(json.dumps(data, indent=2))
    raise typer.Exit(143 if code == 130 and interrupts.terminated() else code)


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


def _load_variants(file: Path, record: str | None, variant: int | None) -> list[tuple[str, Any]]:
    """[(label, plan)] of the scenario's matrix variants (one, unlabelled, without a matrix)."""
    from runner.compile import load_plan
    from runner.scenario.loader import load_file
    from runner.scenario.matrix import variants

    found = variants(load_file(file))
    if variant is not None:
        if not 0 <= variant < len(found):
            raise typer.BadParameter(f"the scenario has {len(found)} variant(s): 0..{len(found) - 1}")
        found = [found[variant]]
    out = []
    for label, doc in found:
        out.append((label, load_plan(doc, record_path=record)))
    return out


def _run_one(
    plan: Any,
    label: str,
    quiet: bool,
    listen: list[str] | None,
    connect: list[str] | None,
    no_judge: bool,
    host: str | None = None,
    strict: bool = False,
    foxglove: int | None = None,
    allow_undecided: bool = False,
    show_all: bool = False,
) -> tuple[Any, int]:
    from runner.checks.judge import ended_early
    from runner.tools.report import Suite, _now, judge_for

    started = _now()
    from runner.launch.run import run_plan
    from runner.wire.transport import free_port, use_run_settings

    total = plan.duration_ns / 1e9
    progress = None
    if not quiet and err.is_terminal:
        from rich.progress import BarColumn, Progress, TextColumn

        progress = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            TextColumn(
                "{task.fields[sim]:>7.2f}/{task.total:.1f} s sim  {task.fields[rtf]:>6.1f}× real time"
            ),
            console=err,
            transient=True,
        )
        task = progress.add_task(plan.name, total=total, sim=0.0, rtf=0.0)
        progress.start()

    def on_progress(sim_ns: int, wall_s: float) -> None:
        if progress is not None:
            sim = sim_ns / 1e9
            progress.update(task, completed=sim, sim=sim, rtf=sim / wall_s if wall_s > 0 else 0.0)

    if not quiet:
        _print_notices(plan.notices, verbose=False)
    member = bool(plan.hosts) and host not in (None, plan.main_host)
    if plan.hosts:
        endpoints = list(listen or []) or [plan.hosts[host or plan.main_host]]
    else:
        # loopback only unless told otherwise (--listen, zenoh.listen)
        endpoints = list(listen or []) or plan.listen or [f"tcp/127.0.0.1:{free_port()}"]
    use_run_settings(plan.zenoh)  # the scenario's zenoh: (TLS...) for every session of the run
    if not quiet:
        who = f" as host {host!r}" if member else ""
        err.print(
            f"running {plan.name}{who} ({total:g} s sim), Zenoh on {', '.join(endpoints)}", markup=False
        )
    judge = None if no_judge or member else judge_for(plan)  # the main host judges
    try:
        result = run_plan(
            plan,
            listen=endpoints,
            connect=connect or (),
            on_progress=on_progress,
            judge=judge,
            host=host,
            foxglove_port=foxglove,
        )
    except RunError as e:
        raise _fail(e) from None
    finally:
        if progress is not None:
            progress.stop()

    ended = ended_early(interrupts.ending(result.reason), result.sim_ns)
    results = (
        judge.finish(result.sim_ns, complete=ended is None, why=ended or "") if judge is not None else []
    )
    if not quiet:
        _print_summary(result, show_all)
    if results:
        _print_results(results, allow_undecided)
    error = result.error
    lost = sum(result.lost.values()) + sum(t.lost for t in result.topics)
    if strict and lost and error is None:
        where = sorted({k for k, n in result.lost.items() if n} | {t.key for t in result.topics if t.lost})
        error = f"--strict: {lost} message(s) published but not recorded, on {', '.join(where)}"
    if error:
        err.print("error: " + error, markup=False, style="red")
    name = f"{plan.name}[{label}]" if label else plan.name
    suite = Suite(
        name,
        results,
        error,
        result.wall_s,
        str(result.mcap) if result.mcap else None,
        sim_s=result.sim_ns / 1e9,
        allow_undecided=allow_undecided,
        timestamp=started,
        interrupted=ended,
    )
    if results and not suite.passed and result.mcap is not None:
        _plot(plan, result.mcap, results)
    code = result.exit_code
    if code == 0 and (not suite.passed or error):
        code = 1
    return suite, code


def _plot(plan: Any, mcap: Path, results: list[Any]) -> None:
    """A failed assertion: the robots' paths, regions and the failure point, as a PNG beside the MCAP."""
    from runner.tools.plot import trajectory_plot

    try:
        png = trajectory_plot(plan, mcap, results, mcap.with_suffix(".trajectory.png"))
    except Exception as e:  # a picture must never hide the verdict
        err.print(f"warning: no trajectory plot ({type(e).__name__}: {e})", markup=False)
        return
    if png is not None:
        out.print(f"trajectory plot: {png}", markup=False)


MARKS = {"pass": "[green]pass[/]", "fail": "[bold red]FAIL[/]", "undecided": "[yellow]not decided[/]"}


def _print_results(results: list[Any], allow_undecided: bool = False) -> None:
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


@app.command()
def check(
    mcap: Annotated[Path, typer.Argument(metavar="RUN.mcap", help="A recording (.mcap).")],
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
    """Judge a recording with a scenario's assertions (the same judge as the live run).

    Example: scenario check runs/two_robots.mcap --scenario scenarios/two_robots.yaml
    """
    from runner.tools.report import Suite, judge_recording, write_junit

    try:
        plans = _load_variants(scenario, None, variant)
    except ScenarioError as e:
        raise _fail(e) from None
    if len(plans) > 1:
        raise _fail(RunError(f"{scenario} has {len(plans)} variants: say which one with --variant"))
    plan = plans[0][1]
    if not any(part.assertions for part in plan.worlds or [plan]):
        raise _fail(RunError(f"{scenario} has no assertions to judge"))
    if not mcap.is_file():
        raise _fail(RunError(f"{mcap}: file not found"))
    try:
        results, end, ended = judge_recording(plan, mcap)
    except Exception as e:
        raise _fail(RunError(f"{mcap}: cannot judge it: {type(e).__name__}: {e}")) from None
    _print_results(results, allow_undecided)
    suite = Suite(
        plan.name,
        results,
        mcap=str(mcap),
        sim_s=end / 1e9,
        allow_undecided=allow_undecided,
        interrupted=ended,
    )
    if not suite.passed:
        _plot(plan, mcap, results)
    if junit is not None:
        write_junit(junit, [suite])
    raise typer.Exit(0 if suite.passed else 1)


@app.command("test")
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
    import subprocess
    import tempfile

    from runner.tools.report import Suite, write_junit

    files: list[Path] = []
    for p in paths:
        files += sorted(p.glob("*.yaml")) if p.is_dir() else [p]
    if not files:
        raise _fail(RunError("no scenario files found in " + ", ".join(map(str, paths))))
    if not no_record:
        out_dir.mkdir(parents=True, exist_ok=True)

    from runner.scenario.loader import load_file
    from runner.scenario.matrix import variants

    tasks: list[tuple[Path, int | None, str]] = []
    for f in files:
        try:
            labels = [label for label, _ in variants(load_file(f))]
        except ScenarioError:
            labels = [""]  # the run itself reports the error
        tasks += [(f, i if len(labels) > 1 else None, label) for i, label in enumerate(labels)]

    def run_one(task: tuple[Path, int | None, str]) -> Suite:
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
                suite.name = name
                return suite
            why = (proc.stderr.strip() or proc.stdout.strip() or f"exit {proc.returncode}").splitlines()
            return Suite(name, error="\n".join(why[-12:]))

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        suites = list(pool.map(run_one, tasks))
    reports: dict[str, str] = {}
    if not no_record:  # one page per scenario, beside its recording
        from runner.tools.html import write_report

        for s in suites:
            if s.mcap and Path(s.mcap).is_file():
                page = Path(s.mcap).with_suffix(".html")
                try:
                    write_report(Path(s.mcap), page)
                    reports[s.name] = str(page)
                except Exception as e:  # a report is a convenience: never a failed test run
                    err.print(f"{s.name}: no report: {e}", markup=False)
    table = Table(
        "scenario",
        "assertions",
        "passed",
        "failed",
        *(["not decided"] if any(s.undecided for s in suites) else []),
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
            *([str(s.undecided)] if any(x.undecided for x in suites) else []),
            verdict,
            f"{s.time_s:.1f}",
            *(link or ([""] if reports else [])),
        )
    out.print(table)
    for s in suites:
        if s.error:
            err.print(f"{s.name}: {s.error}", markup=False, style="red")
        for r in s.results:
            if not r.passed:
                from runner.tools.report import failure_text

                err.print(f"{s.name}: {failure_text(r)}", markup=False, style="red")
    if junit is not None:
        write_junit(junit, suites)
    ok = sum(1 for s in suites if s.passed)
    out.print(f"{ok} passed, {len(suites) - ok} failed", markup=False)
    raise typer.Exit(0 if ok == len(suites) else 1)


def _print_summary(result: Any, show_all: bool = False) -> None:
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
            f"[red]{n_lost}[/red]" if n_lost else "0",
        )
    if hidden:
        table.caption = f"and {hidden} helper topic(s) (`_truth`, `_state`...): --all lists them"
        table.caption_justify = "left"
    if result.topics:
        out.print(table)
    for key, whys in sorted(getattr(result, "rejected", {}).items()):
        for why, n in whys.items():
            out.print(f"rejected: {n} message(s) on {key}: {why}", markup=False, style="yellow")
    sim = result.sim_ns / 1e9
    rtf = sim / result.wall_s if result.wall_s > 0 else 0.0
    where = f" -> {result.mcap}" if result.mcap else ""
    out.print(f"{result.reason}: {sim:.2f} s sim in {result.wall_s:.2f} s wall ({rtf:.1f}× real time){where}")


@app.command()
def info(
    mcap: Annotated[Path, typer.Argument(metavar="RUN.mcap", help="A recording (.mcap).")],
    show_all: AllOpt = False,
) -> None:
    """Topics, types, message counts and the sim-time span of a recording.

    Example: scenario info runs/two_robots.mcap
    """
    from runner.record.recorder import read_summary, recording_live
    from runner.wire.transport import hidden_key

    if not mcap.is_file():
        raise _fail(RunError(f"{mcap}: file not found"))
    try:
        s = read_summary(mcap)
    except Exception as e:
        raise _fail(RunError(f"{mcap}: cannot read it as MCAP: {e}")) from None
    start, end = s["start_ns"], s["end_ns"]
    span = (end - start) / 1e9
    table = Table("topic", "type", "count", "rate (sim Hz)", title=str(mcap), title_justify="left")
    hidden = [t for t in s["topics"] if hidden_key(t["topic"])]
    for t in s["topics"]:
        if t in hidden and not show_all:
            continue
        table.add_row(
            t["topic"],
            t["type"],
            str(t["count"]),
            f"{(t['count'] - 1) / span:.1f}" if span > 0 and t["count"] > 1 else "-",
        )
    if hidden and not show_all:
        table.caption = f"and {len(hidden)} helper topic(s) (`_truth`, `_state`...): --all lists them"
        table.caption_justify = "left"
    out.print(table)
    out.print(f"{s['messages']} messages, sim time {start / 1e9:.3f} s .. {end / 1e9:.3f} s ({span:.3f} s)")
    stopped = s.get("stopped")
    if stopped:
        why = stopped.get("stopped", "the recording ended")
        if stopped.get("error"):
            why += f" ({stopped['error']})"
        out.print(
            f"stopped early: {why}; it holds everything up to {end / 1e9:.3f} s sim, and is complete",
            markup=False,
        )
    if s["cut"] and recording_live(mcap):
        out.print(
            f"live: a run is still recording this file; read up to its last chunk ({end / 1e9:.3f} s sim)",
            markup=False,
        )
    elif s["cut"]:
        out.print(
            f"cut: the recording has no summary (its runner was killed); it reaches {end / 1e9:.3f} s sim, "
            f"every complete chunk read. `scenario recover {mcap}` writes a complete copy.",
            markup=False,
        )


@app.command()
def report(
    mcap: Annotated[Path, typer.Argument(metavar="RUN.mcap", help="A recording (.mcap).")],
    output: Annotated[
        Path | None, typer.Option("--output", "-o", metavar="FILE", help="The page (default: NAME.html).")
    ] = None,
    scenario: Annotated[
        Path | None,
        typer.Option(
            "--scenario", "-s", metavar="FILE", help="The scenario (default: the one the recording carries)."
        ),
    ] = None,
) -> None:
    """One self-contained HTML page about a run: verdict, trajectory plot, assertions and the signals they
    check, camera frames, topics. The scenario is read from the recording itself.

    Example: scenario report runs/two_robots.mcap -o two_robots.html
    """
    from runner.tools.html import write_report

    if not mcap.is_file():
        raise _fail(RunError(f"{mcap}: file not found"))
    plan = None
    try:
        if scenario is not None:
            plans = _load_variants(scenario, str(mcap), None)
            plan = plans[0][1]
        target = output or mcap.with_suffix(".html")
        info = write_report(mcap, target, plan)
    except (RunError, ScenarioError) as e:
        raise _fail(e) from None
    out.print(
        f"{target}: {info['passed']}/{info['assertions']} assertions pass, {info['charts']} signal plot(s), "
        f"{info['frames']} camera frame(s)",
        markup=False,
    )


@app.command()
def render(
    mcap: Annotated[Path, typer.Argument(metavar="RUN.mcap", help="A recording (.mcap).")],
    output: Annotated[
        Path,
        typer.Option("--output", "-o", metavar="FILE", help="The video or picture: .mp4, .gif or .png."),
    ],
    camera: Annotated[
        str,
        typer.Option(
            metavar="CAMERA",
            help="overview (the whole scene), chase:ROBOT (following it), or a model camera.",
        ),
    ] = "overview",
    fps: Annotated[
        float,
        typer.Option(
            metavar="FPS",
            help="Frames per sim second; it plays as long as the run took in sim time (a GIF: 50 at most).",
            min=1,
            max=120,
        ),
    ] = 15.0,
    size: Annotated[
        str, typer.Option(metavar="WxH", help="Width and height in pixels, e.g. 640x480.")
    ] = "960x720",
    world: Annotated[
        str | None, typer.Option(metavar="WORLD", help="With several worlds: which one.")
    ] = None,
) -> None:
    """Render a recorded run again (MuJoCo, offscreen, CPU where there is no GPU): the robots moving, their
    paths drawn as they go, each in the robot's colour (as in the trajectory plot and the report). A .png
    is the run's last moment.

    Examples:
      scenario render runs/two_robots.mcap -o two_robots.mp4
      scenario render runs/two_robots.mcap -o r1.gif --camera chase:r1 --size 480x360
    """
    from runner.launch.announce import replay

    try:
        w, h = (int(v) for v in size.lower().split("x"))
        if w < 16 or h < 16:
            raise ValueError
    except ValueError:
        raise _fail(RunError(f"--size {size!r}: expected WIDTHxHEIGHT, e.g. 640x480")) from None
    if not mcap.is_file():
        raise _fail(RunError(f"{mcap}: file not found"))
    try:
        rec = replay.load(mcap, world)
        notes: list[str] = []
        with _progress_bar("rendering") as bar:
            got = replay.write(
                rec, output, camera=camera, width=w, height=h, fps=fps, progress=bar, notes=notes
            )
    except RunError as e:
        raise _fail(e) from None
    for note in notes:
        err.print(f"note: {note}", markup=False, style="yellow")
    sim = f"{rec.times[-1] / 1e9:.2f} s sim"
    if output.suffix.lower() == ".png":
        out.print(f"{output}: the run at {sim}, camera {camera}", markup=False)
        return
    merged = f" ({got.merged} unchanged frames shown on)" if got.merged else ""
    out.print(
        f"{output}: {got.frames} frames{merged}, plays {got.seconds:.2f} s at {got.fps:g} fps "
        f"({sim}), camera {camera}",
        markup=False,
    )


class _progress_bar:
    """A rich progress bar on stderr, called with (done, total)."""

    def __init__(self, what: str):
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

        self.progress = Progress(
            TextColumn(what), BarColumn(), MofNCompleteColumn(), console=err, transient=True
        )
        self.task = self.progress.add_task(what, total=None)

    def __enter__(self) -> Callable[[int, int], None]:
        self.progress.start()

        def update(done: int, total: int) -> None:
            self.progress.update(self.task, completed=done, total=total)

        return update

    def __exit__(self, *_exc: object) -> None:
        self.progress.stop()


@app.command()
def recover(
    mcap: Annotated[
        Path, typer.Argument(metavar="CUT.mcap", help="A recording cut short (its runner was killed).")
    ],
    output: Annotated[
        Path | None,
        typer.Option("--output", "-o", metavar="FILE", help="Where to write (default: NAME.recovered.mcap)."),
    ] = None,
) -> None:
    """Rewrite a cut recording as a complete MCAP (summary, indexes): every message of its complete chunks.
    The cut file is left as it is.

    Example: scenario recover runs/two_robots.mcap
    """
    from runner.record.recorder import recover as do_recover

    if not mcap.is_file():
        raise _fail(RunError(f"{mcap}: file not found"))
    target = output or mcap.with_name(mcap.stem + ".recovered.mcap")
    if target.resolve() == mcap.resolve():
        raise _fail(RunError("the output would overwrite the cut file; give another --output"))
    s = do_recover(mcap, target)
    out.print(
        f"{target}: {s['messages']} messages on {len(s['topics'])} topics, "
        f"sim time {s['start_ns'] / 1e9:.3f} s .. {s['end_ns'] / 1e9:.3f} s",
        markup=False,
    )


@app.command()
def schema(
    output: Annotated[Path, typer.Option("--output", "-o", metavar="FILE", help="Where to write it.")] = Path(
        "schemas/scenario.schema.json"
    ),
    check: Annotated[bool, typer.Option(help="Exit 1 if the file differs instead of writing it.")] = False,
) -> None:
    """Write the JSON Schema of the scenario format (for editors, via yaml-language-server)."""
    from runner.scenario.jsonschema import render

    text = render()
    if check:
        current = output.read_text() if output.is_file() else ""
        if current != text:
            err.print(f"{output} is stale: run `scenario schema`", markup=False)
            raise typer.Exit(1)
        return
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(text)
    out.print(f"wrote {output}", markup=False)


RunOpt = Annotated[
    str | None, typer.Option("--run", metavar="ID", help="The run to join (default: the one running here).")
]
ConnectOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--connect", metavar="ENDPOINT", help="Zenoh endpoint of the run (default: the local run's)."
    ),
]


def _tool_tokens(session: Any, run: str, tool: str) -> Any:
    """This tool in the run's graph (`scenario graph` shows it, like rqt_graph shows `ros2 topic echo`);
    the tokens go with the session."""
    import os

    from runner.wire.graph import GraphTokens

    return GraphTokens(session, run, f"{tool}-{os.getpid()}", "tool")


@app.command()
def echo(
    topic: Annotated[str, typer.Argument(help="Topic inside the run, e.g. r1/scan (or a full key).")],
    n: Annotated[int | None, typer.Option("-n", metavar="N", help="Stop after N messages.", min=1)] = None,
    field: Annotated[
        str | None, typer.Option(metavar="PATH", help="Print only this field, e.g. pose.pose.position.x.")
    ] = None,
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """Print a topic's messages, decoded, as YAML documents (like `ros2 topic echo`).

    Examples:
      scenario echo r1/scan -n 3
      scenario echo r1/odom --field pose.pose.position
    """
    import queue

    import yaml

    from runner.launch.announce import field_of, find_run, joined, key_of
    from runner.wire import msgs
    from runner.wire.transport import type_from_encoding, unpack_attachment

    try:
        name, endpoints = find_run(run_name, connect)
        key = key_of(name, topic)
        inbox: queue.SimpleQueue[tuple[str, str | None, bytes, int | None]] = queue.SimpleQueue()

        def on_sample(sample: Any) -> None:
            att = unpack_attachment(sample.attachment.to_bytes()) if sample.attachment is not None else None
            stamp = att[1] if att else None
            inbox.put(
                (str(sample.key_expr), type_from_encoding(sample.encoding), sample.payload.to_bytes(), stamp)
            )

        count = 0
        with joined(endpoints) as session:
            tool = _tool_tokens(session, name, "echo")  # (kept: a dropped token is withdrawn)
            tool.subscriber(key)
            sub = session.declare_subscriber(key, on_sample)
            try:
                while n is None or count < n:
                    try:
                        got, type_name, payload, stamp = inbox.get(timeout=0.2)
                    except queue.Empty:
                        continue
                    if type_name is None:
                        continue
                    if not msgs.is_known(type_name):  # e.g. the Foxglove scene (protobuf)
                        out.print(
                            f"# {got} ({type_name}): {len(payload)} bytes, not a ROS 2 message", markup=False
                        )
                        out.print("---", markup=False)
                        count += 1
                        continue
                    data = msgs.to_data(msgs.decode(payload, type_name))
                    if field:
                        data = field_of(data, field)
                    head = f"# {got} ({type_name})" + (
                        f" at {stamp / 1e9:.3f} s" if stamp is not None else ""
                    )
                    out.print(head, markup=False)
                    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
                    # a lone value (`--field pose.pose.position.x`) comes with YAML's document end, `...`:
                    # the `---` below already ends each message
                    out.print(text.removesuffix("\n...\n").rstrip(), markup=False)
                    out.print("---", markup=False)
                    count += 1
            except KeyboardInterrupt:
                pass
            finally:
                sub.undeclare()
    except RunError as e:
        raise _fail(e) from None


@app.command()
def pub(
    topic: Annotated[str, typer.Argument(help="Topic inside the run, e.g. r1/cmd_vel.")],
    type_name: Annotated[
        str, typer.Argument(metavar="TYPE", help="ROS 2 type, e.g. geometry_msgs/msg/Twist.")
    ],
    data: Annotated[
        str, typer.Argument(metavar="YAML", help="The message's fields, e.g. '{linear: {x: 0.3}}'.")
    ] = "{}",
    rate: Annotated[
        float | None, typer.Option("-r", "--rate", metavar="HZ", help="Publish at this rate (Hz, wall).")
    ] = None,
    n: Annotated[
        int | None,
        typer.Option("-n", metavar="N", help="Publish N times (default: once, or forever with -r)."),
    ] = None,
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """Publish a message on a topic of a running scenario (like `ros2 topic pub`).

    Examples:
      scenario pub r1/cmd_vel geometry_msgs/msg/Twist '{linear: {x: 0.3}}'
      scenario pub r1/cmd_vel geometry_msgs/Twist '{angular: {z: 0.5}}' -r 10 -n 50
    """
    import time

    import yaml
    import zenoh

    from runner.launch.announce import find_run, joined, key_of, wait_matched
    from runner.wire import msgs
    from runner.wire.transport import encoding_for, pack_attachment, unpack_attachment

    try:
        full_type = msgs.normalize_type(type_name)
        if not msgs.is_known(full_type):
            near = msgs.similar_types(full_type)
            raise RunError(
                f"unknown message type {type_name!r}" + (f"; did you mean {', '.join(near)}?" if near else "")
            )
        try:
            fields = yaml.safe_load(data) or {}
            payload = msgs.encode(msgs.from_data(full_type, fields), full_type)
        except (yaml.YAMLError, msgs.MessageDataError) as e:
            raise RunError(f"the message does not fit {full_type}: {e}") from None
        name, endpoints = find_run(run_name, connect)
        count = n if n is not None else (None if rate else 1)
        with joined(endpoints) as session:
            sim = {"ns": 0}

            def on_clock(sample: Any) -> None:
                att = (
                    unpack_attachment(sample.attachment.to_bytes()) if sample.attachment is not None else None
                )
                if att:
                    sim["ns"] = att[1]

            tool = _tool_tokens(session, name, "pub")  # (kept: a dropped token is withdrawn)
            tool.publisher(key_of(name, topic), full_type)
            clock = session.declare_subscriber(f"{name}/clock", on_clock)
            publisher = session.declare_publisher(
                key_of(name, topic),
                encoding=encoding_for(full_type),
                congestion_control=zenoh.CongestionControl.BLOCK,
            )
            if not wait_matched(publisher):
                err.print(f"note: nothing subscribes to {key_of(name, topic)} (yet)", markup=False)
            sent = 0
            try:
                while count is None or sent < count:
                    publisher.put(payload, attachment=pack_attachment(sent, sim["ns"]))
                    sent += 1
                    if count is not None and sent >= count:
                        break
                    time.sleep(1.0 / rate if rate else 0.0)
            except KeyboardInterrupt:
                pass
            time.sleep(0.1)  # let the last put leave before the session closes
            clock.undeclare()
            publisher.undeclare()
        err.print(f"published {sent} message(s) on {key_of(name, topic)}", markup=False)
    except RunError as e:
        raise _fail(e) from None


@app.command()
def topics(
    seconds: Annotated[
        float, typer.Option(metavar="SECONDS", help="How long to listen, wall seconds.", min=0.1)
    ] = 1.0,
    show_all: AllOpt = False,
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """List the topics of a running scenario: type, publishers and subscribers (by process), rates (like
    `ros2 topic list -t` and `ros2 topic info`).

    Example: scenario topics --seconds 2
    """
    import time

    from runner.launch.announce import find_run, joined
    from runner.wire.graph import query_graph
    from runner.wire.transport import hidden_key, type_from_encoding, unpack_attachment

    try:
        name, endpoints = find_run(run_name, connect)
        seen: dict[str, dict[str, Any]] = {}

        def on_sample(sample: Any) -> None:
            key = str(sample.key_expr)
            entry = seen.setdefault(
                key, {"type": type_from_encoding(sample.encoding) or "?", "n": 0, "t": []}
            )
            entry["n"] += 1
            att = unpack_attachment(sample.attachment.to_bytes()) if sample.attachment is not None else None
            if att:
                entry["t"].append(att[1])

        with joined(endpoints) as session:
            sub = session.declare_subscriber(f"{name}/**", on_sample)
            time.sleep(seconds)
            sub.undeclare()
            graph = query_graph(session, name)
    except RunError as e:
        raise _fail(e) from None
    for key, type_name in graph.topics().items():  # declared, if silent while we listened
        if key.startswith(name + "/") and key not in seen:
            seen[key] = {"type": type_name or "?", "n": 0, "t": []}
    table = Table(
        "topic",
        "type",
        "publishers",
        "subscribers",
        "messages",
        "rate (Hz, wall)",
        "rate (Hz, sim)",
        title=f"{name}: live topics",
    )
    hidden = 0
    for key in sorted(seen):
        if not show_all and hidden_key(key):
            hidden += 1
            continue  # hidden, as `ros2 topic list` hides `_` topics
        e = seen[key]
        stamps = e["t"]
        sim = (
            (len(stamps) - 1) / ((stamps[-1] - stamps[0]) / 1e9)
            if len(stamps) > 1 and stamps[-1] > stamps[0]
            else 0
        )
        table.add_row(
            key,
            e["type"],
            ", ".join(graph.publishers(key)) or "-",
            ", ".join(graph.subscribers(key)) or "-",
            str(e["n"]),
            f"{e['n'] / seconds:.1f}",
            f"{sim:.1f}" if sim else "-",
        )
    if hidden:
        table.caption = f"and {hidden} helper topic(s) (`_truth`, `_state`...): --all lists them"
        table.caption_justify = "left"
    out.print(table)


@app.command()
def graph(
    output: Annotated[
        Path | None,
        typer.Option(
            "--output", "-o", metavar="NAME", help="Write NAME.dot and NAME.png (default: <run>-graph)."
        ),
    ] = None,
    show_all: AllOpt = False,
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """Draw a running scenario's graph (like rqt_graph) as a Graphviz DOT file and a PNG. It shows the
    processes (worlds, renderers, nodes, bridges, the recorder, the tools), the topics, and who publishes
    and subscribes to what; the topics are listed on the terminal too.

    Examples:
      scenario graph
      scenario graph -o docs/two_robots_graph --run two_robots
    """
    from runner.launch.announce import find_run, joined
    from runner.tools.graph_draw import render_png, summary_lines, to_dot
    from runner.wire.graph import query_graph

    try:
        name, endpoints = find_run(run_name, connect)
        with joined(endpoints) as session:
            g = query_graph(session, name)
    except RunError as e:
        raise _fail(e) from None
    if not show_all:
        g = g.visible()
    if not g.processes:
        raise _fail(RunError(f"run {name!r} announces no processes (is it still starting?)"))
    stem = output or Path(f"{name}-graph")
    stem.parent.mkdir(parents=True, exist_ok=True)
    dot, png = stem.with_name(stem.name + ".dot"), stem.with_name(stem.name + ".png")
    dot.write_text(to_dot(g))
    render_png(g, png)
    for line in summary_lines(g):
        out.print(line, markup=False, highlight=False)
    out.print(
        f"{len(g.processes)} processes, {len(g.topics())} topics -> {dot}, {png}",
        markup=False,
        highlight=False,
    )


# teleop_twist_keyboard's layout: key -> (forward, turn) directions
_MOVES = {
    "i": (1, 0), "o": (1, -1), "j": (0, 1), "l": (0, -1), "u": (1, 1),
    ",": (-1, 0), ".": (-1, 1), "m": (-1, -1),
}  # fmt: skip
_SPEEDS = {
    "q": (1.1, 1.1),
    "z": (0.9, 0.9),
    "w": (1.1, 1.0),
    "x": (0.9, 1.0),
    "e": (1.0, 1.1),
    "c": (1.0, 0.9),
}
_TELEOP_HELP = """Moving around:        speeds:
   u    i    o         q/z  all up/down by 10%
   j    k    l         w/x  linear only
   m    ,    .         e/c  angular only
k (or any other key) stops; Ctrl-C quits (and stops the robot)."""


@app.command()
def teleop(
    robot: Annotated[str, typer.Argument(help="The robot's name (its namespace), e.g. r1.")],
    speed: Annotated[float, typer.Option(metavar="M/S", help="Linear speed, m/s.")] = 0.5,
    turn: Annotated[float, typer.Option(metavar="RAD/S", help="Angular speed, rad/s.")] = 1.0,
    topic: Annotated[str, typer.Option(help="Command topic inside the robot's namespace.")] = "cmd_vel",
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """Drive a robot from the keyboard (the keys of teleop_twist_keyboard), publishing geometry_msgs/Twist.

    Example: scenario teleop r1 --speed 0.3
    """
    import os
    import select
    import termios
    import time
    import tty

    import zenoh

    from runner.launch.announce import find_run, joined, key_of
    from runner.wire import msgs
    from runner.wire.transport import encoding_for, pack_attachment

    try:
        name, endpoints = find_run(run_name, connect)
        key = key_of(name, f"{robot}/{topic}")
        fd = sys.stdin.fileno()
        if not os.isatty(fd):
            raise RunError("teleop reads keys from a terminal; stdin is not one")
        twist_type = "geometry_msgs/msg/Twist"
        with joined(endpoints) as session:
            tool = _tool_tokens(session, name, "teleop")  # (kept: a dropped token is withdrawn)
            tool.publisher(key, twist_type)
            pub = session.declare_publisher(
                key, encoding=encoding_for(twist_type), congestion_control=zenoh.CongestionControl.BLOCK
            )
            seq = 0

            def send(v: float, w: float) -> None:
                nonlocal seq
                data = {"linear": {"x": v}, "angular": {"z": w}}
                pub.put(
                    msgs.encode(msgs.from_data(twist_type, data), twist_type),
                    attachment=pack_attachment(seq, 0),
                )
                seq += 1

            print(f"{_TELEOP_HELP}\npublishing on {key}", end="\r\n", flush=True)
            saved = termios.tcgetattr(fd)
            try:
                tty.setraw(fd)
                while True:
                    ready, _, _ = select.select([fd], [], [], 0.2)
                    if not ready:
                        continue
                    ch = os.read(fd, 1).decode(errors="replace")
                    if ch in ("\x03", "\x04", ""):  # Ctrl-C, Ctrl-D
                        break
                    if ch in _SPEEDS:
                        a, b = _SPEEDS[ch]
                        speed, turn = speed * a, turn * b
                        print(f"speed {speed:.2f} m/s, turn {turn:.2f} rad/s", end="\r\n", flush=True)
                        continue
                    forward, rotate = _MOVES.get(ch, (0, 0))
                    send(forward * speed, rotate * turn)
                    print(
                        f"linear.x {forward * speed:+.2f}  angular.z {rotate * turn:+.2f}",
                        end="\r\n",
                        flush=True,
                    )
            finally:
                termios.tcsetattr(fd, termios.TCSADRAIN, saved)
                send(0.0, 0.0)  # never leave a robot driving
                time.sleep(0.1)
                pub.undeclare()
    except RunError as e:
        raise _fail(e) from None


@app.command(context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
def bench(ctx: typer.Context) -> None:
    """Run the benchmark suite (a checkout's bench/ folder): `scenario bench --quick`, `--only two_robots`,
    `--readme`. Same as `python -m bench`."""
    repo = Path(__file__).resolve().parents[1]
    if not (repo / "bench" / "__main__.py").is_file():
        err.print("[red]error:[/red] the benchmark suite lives in a checkout's bench/ folder; none here")
        raise typer.Exit(2)
    if str(repo) not in sys.path:
        sys.path.insert(0, str(repo))
    from bench.__main__ import main as bench_main

    raise typer.Exit(bench_main(list(ctx.args)))


# every command's help written as `_Command` writes it
for _info in app.registered_commands:
    if _info.cls in (None, typer.core.TyperCommand):
        _info.cls = _Command


def main() -> None:
    # From here Ctrl-C raises KeyboardInterrupt (a run stops its worlds and finishes its recording) and
    # SIGTERM does the same; either, escaping a command, ends it with 130 / 143 and no traceback.
    interrupts.interruptible()
    try:
        app()
    except ScenarioError as e:  # a user mistake that escaped a command: still no traceback
        err.print("error: " + e.render(), markup=False, style="red")
        sys.exit(1)
    except KeyboardInterrupt:
        err.print("interrupted", markup=False)
        sys.exit(143 if interrupts.terminated() else 130)
