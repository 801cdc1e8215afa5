"""The `scenario` command.

User mistakes (`ScenarioError`, `RunError`) are printed without a traceback and exit 1; usage errors exit
2; anything else is a bug and shows its traceback.
"""

from __future__ import annotations

import math
import signal
import sys
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

from runner.errors import RunError, ScenarioError

app = typer.Typer(
    name="scenario",
    help="Declarative robot-simulation scenarios: URDF/xacro robots, MuJoCo physics, Zenoh, MCAP.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
# Wide tables when piped (CI logs): key names are long and worth reading whole.
out = Console(highlight=False, width=None if sys.stdout.isatty() else 160)
err = Console(stderr=True, highlight=False, width=None if sys.stderr.isatty() else 160)


def _fail(e: Exception) -> typer.Exit:
    text = e.render() if isinstance(e, ScenarioError) else str(e)
    err.print("error: " + text, markup=False, soft_wrap=True, style="red")
    return typer.Exit(1)


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


def _load(file: Path, record: str | None = None) -> Any:
    from runner.compile import compile_plan
    from runner.loader import load_file
    from runner.validate import validate_scenario

    doc = load_file(file)
    scenario = validate_scenario(doc)
    return scenario, compile_plan(scenario, doc, record_path=record)


@app.command()
def validate(
    file: Annotated[Path, typer.Argument(help="Scenario YAML file.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print the compiled plan as JSON.")] = False,
) -> None:
    """Check a scenario and print what would run: robots, plugins, topics with types and rates.

    Example: scenario validate scenarios/two_robots.yaml
    """
    try:
        _scenario, plan = _load(file)
    except ScenarioError as e:
        raise _fail(e) from None
    if as_json:
        out.print_json(plan.model_dump_json(exclude={"mjcf"}))
        return
    rate = plan.rate if isinstance(plan.rate, str) else f"{plan.rate:g}× real time"
    out.print(
        f"[bold]{plan.name}[/]: {plan.duration_ns / 1e9:g} s sim at {rate}, step {plan.step_ns / 1e6:g} ms, "
        f"{len(plan.robots)} robot(s), seed {plan.seed}"
    )
    robots = Table(
        "robot", "namespace", "description", "links", "plugins", title="Robots", title_justify="left"
    )
    for r in plan.robots:
        robots.add_row(
            r.name,
            r.namespace,
            Path(r.description_file).name,
            str(len(r.links)),
            ", ".join(f"{p.name}" + (f" @{p.rate:g} Hz" if p.rate else "") for p in r.plugins),
        )
    out.print(robots)
    topics = Table("key", "type", "dir", "rate (sim Hz)", "from", title="Topics", title_justify="left")
    for t in plan.topics():
        topics.add_row(t.key, t.type, t.direction, f"{t.rate:g}" if t.rate else "-", t.owner)
    out.print(topics)
    if plan.timeline:
        out.print(
            f"timeline: {len(plan.timeline)} message(s) from t={plan.timeline[0].t_ns / 1e9:g} s "
            f"to t={plan.timeline[-1].t_ns / 1e9:g} s"
        )
    out.print(f"record: {plan.record.path if plan.record.enabled else 'off'}")
    _print_notices(plan.notices, verbose=True)


def _print_notices(notices: list[str], verbose: bool) -> None:
    if not notices:
        return
    if not verbose:
        err.print(
            f"{len(notices)} warning(s) about the descriptions: `scenario validate` lists them", markup=False
        )
        return
    err.print(f"{len(notices)} warning(s): read from the descriptions but not acted on", markup=False)
    for text in notices:
        err.print("warning: " + text, markup=False, style="yellow")


@app.command()
def run(
    file: Annotated[Path, typer.Argument(help="Scenario YAML file.")],
    duration: Annotated[float | None, typer.Option(help="Override the sim duration (s).", min=0.001)] = None,
    rate: Annotated[str | None, typer.Option(help="realtime | max | a real-time factor.")] = None,
    record: Annotated[str | None, typer.Option(help="MCAP file to write (overrides the scenario).")] = None,
    no_record: Annotated[bool, typer.Option("--no-record", help="Do not record.")] = False,
    listen: Annotated[
        list[str] | None,
        typer.Option(help="Zenoh endpoint to listen on, e.g. tcp/127.0.0.1:7447 (repeatable)."),
    ] = None,
    connect: Annotated[
        list[str] | None, typer.Option(help="Zenoh endpoint of another router to join (repeatable).")
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress line and no table.")] = False,
) -> None:
    """Validate, compile and run a scenario; record every message to MCAP.

    Examples:
      scenario run scenarios/two_robots.yaml
      scenario run scenarios/two_robots.yaml --rate realtime --listen tcp/127.0.0.1:7447
    """
    from runner.launch import run_plan

    parsed_rate = _parse_rate(rate)
    try:
        _scenario, plan = _load(file, record)
    except ScenarioError as e:
        raise _fail(e) from None
    if duration is not None:
        plan.duration_ns = round(duration * 1e9)
    if parsed_rate is not None:
        plan.rate = parsed_rate
    if no_record:
        plan.record.enabled = False

    # SIGTERM ends the run like Ctrl-C: in order, with the recording finished.
    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))

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

    from runner.transport import free_port

    if not quiet:
        _print_notices(plan.notices, verbose=False)

    endpoints = list(listen or []) or [f"tcp/127.0.0.1:{free_port()}"]
    if not quiet:
        err.print(f"running {plan.name} ({total:g} s sim), Zenoh on {', '.join(endpoints)}", markup=False)
    try:
        result = run_plan(plan, listen=endpoints, connect=connect or (), on_progress=on_progress)
    except RunError as e:
        raise _fail(e) from None
    finally:
        if progress is not None:
            progress.stop()

    if not quiet:
        _print_summary(result)
    if result.error:
        err.print("error: " + result.error, markup=False, style="red")
    raise typer.Exit(result.exit_code)


def _print_summary(result: Any) -> None:
    table = Table("topic", "type", "count", "rate (sim Hz)", "lost", title="Recorded", title_justify="left")
    lost = result.lost
    for t in result.topics:
        n_lost = lost.get(t.key, 0) + t.lost
        table.add_row(t.key, t.type, str(t.count), f"{t.rate():.1f}", str(n_lost) if n_lost else "")
    if result.topics:
        out.print(table)
    sim = result.sim_ns / 1e9
    rtf = sim / result.wall_s if result.wall_s > 0 else 0.0
    where = f" -> {result.mcap}" if result.mcap else ""
    out.print(f"{result.reason}: {sim:.2f} s sim in {result.wall_s:.2f} s wall ({rtf:.1f}× real time){where}")


@app.command()
def info(mcap: Annotated[Path, typer.Argument(help="A recording (.mcap).")]) -> None:
    """Topics, types, message counts and the sim-time span of a recording.

    Example: scenario info runs/two_robots.mcap
    """
    from runner.record import read_summary

    if not mcap.is_file():
        raise _fail(RunError(f"{mcap}: file not found"))
    try:
        s = read_summary(mcap)
    except Exception as e:
        raise _fail(RunError(f"{mcap}: cannot read it as MCAP: {e}")) from None
    start, end = s["start_ns"], s["end_ns"]
    span = (end - start) / 1e9
    table = Table("topic", "type", "count", "rate (sim Hz)", title=str(mcap), title_justify="left")
    for t in s["topics"]:
        table.add_row(
            t["topic"],
            t["type"],
            str(t["count"]),
            f"{(t['count'] - 1) / span:.1f}" if span > 0 and t["count"] > 1 else "-",
        )
    out.print(table)
    out.print(f"{s['messages']} messages, sim time {start / 1e9:.3f} s .. {end / 1e9:.3f} s ({span:.3f} s)")


@app.command()
def schema(
    output: Annotated[Path, typer.Option("--output", "-o", help="Where to write it.")] = Path(
        "schemas/scenario.schema.json"
    ),
    check: Annotated[bool, typer.Option(help="Exit 1 if the file differs instead of writing it.")] = False,
) -> None:
    """Write the JSON Schema of the scenario format (for editors, via yaml-language-server)."""
    from runner.jsonschema import render

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


def main() -> None:
    try:
        app()
    except ScenarioError as e:  # a user mistake that escaped a command: still no traceback
        err.print("error: " + e.render(), markup=False, style="red")
        sys.exit(1)


if __name__ == "__main__":
    main()
