"""Commands about the scenario format that run nothing: `validate` (check a scenario and print what would
run, table by table: robots, their Gazebo parity, topics, services and actions, nodes, bridges) and
`schema` (the format's JSON Schema)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from runner.cli.console import err, fail, out
from runner.cli.notices import print_notices
from runner.cli.plans import drawn_line, load_variants, strict_failure
from runner.errors import ScenarioError
from runner.plan import RobotPlan

StrictValidate = Annotated[
    bool,
    typer.Option(
        "--strict",
        help="Warnings about the scenario itself (an assertion window past its end, a timeline topic "
        "nothing subscribes to...) are errors: exit 1 (for CI).",
    ),
]


def validate(
    file: Annotated[Path, typer.Argument(help="Scenario YAML file.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print the compiled plan as JSON.")] = False,
    strict: StrictValidate = False,
    every: Annotated[
        bool,
        typer.Option(
            "--all",
            help="Say every warning: without it, a kind of warning said 3 times or more (a tag ignored in "
            "every sensor) is one line, with how many more and where.",
        ),
    ] = False,
) -> None:
    """Check a scenario and print what would run: robots, plugins, topics with types and rates,
    services and actions.

    Example: scenario validate scenarios/two_robots.yaml
    """
    try:
        plans = load_variants(file, None, None)
    except ScenarioError as e:
        raise fail(e) from None
    plan = plans[0][1]
    if len(plans) > 1:
        out.print(f"{len(plans)} variants: " + "; ".join(label for label, _ in plans), markup=False)
    if as_json:
        out.print_json(plan.model_dump_json(exclude={"mjcf"}))
        return
    parts = plan.worlds or [plan]
    _print_headline(plan, parts)
    if drawn_line(plan):
        out.print(drawn_line(plan), markup=False)
    out.print(_robots_table(plan, parts))
    for part in parts:
        for r in part.robots:
            _print_parity(r)
    out.print(_topics_table(parts))
    if any(part.services() for part in parts):
        out.print(_services_table(parts))
    if plan.nodes:
        out.print(_nodes_table(plan))
    if plan.bridges:
        out.print(_bridges_table(plan))
    if any(part.actors or part.events for part in parts):
        out.print(_happenings_table(parts))
    if plan.timeline:
        calls = sum(1 for e in plan.timeline if e.call)
        what = f"{len(plan.timeline) - calls} message(s)" + (f", {calls} service call(s)" if calls else "")
        first, last = plan.timeline[0].t_ns / 1e9, plan.timeline[-1].t_ns / 1e9
        out.print(f"timeline: {what} from t={first:g} s to t={last:g} s")
    out.print(f"record: {plan.record.path if plan.record.enabled else 'off'}")
    print_notices(plan.notice_items, verbose=True, every=every)
    if strict:
        for _, p in plans:
            strict_failure(p)


def _print_headline(plan: Any, parts: list[Any]) -> None:
    """The run in one line: name, duration, rate, step, worlds, robots, seed."""
    rate = plan.rate if isinstance(plan.rate, str) else f"{plan.rate:g}× real time"
    robots_n = sum(len(p.robots) for p in parts)
    worlds = f"{len(parts)} worlds, " if plan.worlds else ""
    out.print(
        f"[bold]{plan.name}[/]: {plan.duration_ns / 1e9:g} s sim at {rate}, step {plan.step_ns / 1e6:g} ms, "
        f"{worlds}{robots_n} robot(s), seed {plan.seed}",
        markup=True,  # (a run's name is letters, digits, '_', '.' and '-': no markup of its own)
    )


def _robots_table(plan: Any, parts: list[Any]) -> Table:
    """Each robot: namespace, description file, links, plugins with rates (and its world, with several)."""
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
    return robots


def _topics_table(parts: list[Any]) -> Table:
    """Every topic of the run: key, type, direction, rate and who declares it."""
    topics = Table("key", "type", "dir", "rate (sim Hz)", "from", title="Topics", title_justify="left")
    for part in parts:
        for t in part.topics():
            topics.add_row(t.key, t.type, t.direction, f"{t.rate:g}" if t.rate else "-", t.owner)
    return topics


def _services_table(parts: list[Any]) -> Table:
    """Every service and action server the run answers (the world's own first): key, type, kind and who
    answers it; an action's `_action/` services and topics are under its key."""
    table = Table("key", "type", "kind", "from", title="Services and actions", title_justify="left")
    for part in parts:
        for s in part.services():
            table.add_row(s.key, s.type, s.kind, s.owner or "-")
    return table


def _nodes_table(plan: Any) -> Table:
    """The scenario's nodes: command, namespace, required, respawn, lockstep."""
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
    return nodes


def _bridges_table(plan: Any) -> Table:
    """The bridges: sim topic, direction, the other side (a Zenoh key or a ROS 2 topic), type, options."""
    bridges = Table("sim topic", "", "other side", "type", "options", title="Bridges", title_justify="left")
    arrows = {"SIM_TO_ZENOH": "->", "ZENOH_TO_SIM": "<-", "BIDIRECTIONAL": "<->"}
    for b in plan.bridges:
        other = f"ROS 2 {b.ros_topic} (domain {b.ros2.domain})" if b.ros2 else str(b.key)
        options = [b.encoding] if not b.ros2 else []
        options += [f"<= {b.rate:g}/s"] if b.rate else []
        options += ["lazy"] if b.lazy else []
        bridges.add_row(b.sim_key, arrows[b.direction], other, b.type, ", ".join(options))
    return bridges


def _happenings_table(parts: list[Any]) -> Table:
    """The actors (how they move, when they start) and the events (when, what they do), in step order."""
    table = Table("", "name", "when", "what", title="Actors and events", title_justify="left")
    for part in parts:
        for a in part.actors:
            start = "on an event" if a.start_ns is None else f"at {a.start_ns / 1e9:g} s"
            if a.hinge is not None:
                what = f"turns {a.hinge['angle']:g} rad about a hinge in {a.hinge['duration']:g} s"
            elif len(a.points) > 1:
                what = f"walks {len(a.points)} points in {a.times[-1]:.1f} s" + (
                    ", looping" if a.loop else ""
                )
            else:
                what = "stands"
            table.add_row("actor", a.name, start, what)
        for e in part.events:
            table.add_row("event", e.name + (" (repeats)" if e.repeat else ""), _when(e.when), _did(e.do))
    return table


def _when(w: dict[str, Any]) -> str:
    kind = w["kind"]
    if kind == "at":
        return f"at {w['t_ns'] / 1e9:g} s"
    if kind in ("enter", "leave"):
        return f"{w['body']['name']} {'enters' if kind == 'enter' else 'leaves'} {w['label']}"
    if kind == "near":
        to = w["to"]["name"] if isinstance(w["to"], dict) else str(w["to"])
        return f"{w['body']['name']} within {w['within']:g} m of {to}"
    if kind == "message":
        return f"{w['topic']}: {w['expr']}"
    if kind == "after":
        return f"{w['delay_ns'] / 1e9:g} s after {w['event']}" if w["delay_ns"] else f"after {w['event']}"
    return f"assertion {w['name']} {'passes' if w['becomes'] == 'pass' else 'fails'}"


def _did(actions: list[dict[str, Any]]) -> str:
    words = []
    for a in actions:
        target = a.get("name") or a.get("topic") or a.get("label") or (a.get("target") or {}).get("name")
        if a["kind"] == "publish":
            target = a["key"].split("/", 1)[1]
        if a["kind"] == "end":
            target = a["result"]
        words.append(f"{a['kind']} {target}" if target else a["kind"])
    return "; ".join(words)


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
