"""Commands that join a running scenario over Zenoh, like the `ros2` tools: `echo` (print a topic's
messages), `pub` (publish on a topic), `topics` (the live topics, their publishers, subscribers and rates)
and `graph` (the run's graph, as rqt_graph draws it). Each shows up in the run's graph as a tool."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich.table import Table

from runner.cli.console import err, fail, out
from runner.cli.options import AllOpt, ConnectOpt, RunOpt
from runner.errors import RunError


def tool_tokens(session: Any, run: str, tool: str) -> Any:
    """This tool in the run's graph (`scenario graph` shows it, like rqt_graph shows `ros2 topic echo`);
    the tokens go with the session."""
    import os

    from runner.wire.graph import GraphTokens

    return GraphTokens(session, run, f"{tool}-{os.getpid()}", "tool")


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

    from runner.launch.announce import find_run, joined, key_of
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
            tool = tool_tokens(session, name, "echo")  # (kept: a dropped token is withdrawn)
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
                    _print_message(got, type_name, payload, stamp, field)
                    count += 1
            except KeyboardInterrupt:
                pass
            finally:
                sub.undeclare()
    except RunError as e:
        raise fail(e) from None


def _print_message(key: str, type_name: str, payload: bytes, stamp: int | None, field: str | None) -> None:
    """One message as `echo` prints it: a `# key (type) at t` line, the message (or --field of it) as a
    YAML document, and `---`; a message that is not ROS 2 (e.g. the Foxglove scene) by its size."""
    import yaml

    from runner.launch.announce import field_of
    from runner.wire import msgs

    if not msgs.is_known(type_name):  # e.g. the Foxglove scene (protobuf)
        out.print(f"# {key} ({type_name}): {len(payload)} bytes, not a ROS 2 message", markup=False)
        out.print("---", markup=False)
        return
    data = msgs.to_data(msgs.decode(payload, type_name))
    if field:
        data = field_of(data, field)
    head = f"# {key} ({type_name})" + (f" at {stamp / 1e9:.3f} s" if stamp is not None else "")
    out.print(head, markup=False)
    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
    # a lone value (`--field pose.pose.position.x`) comes with YAML's document end, `...`:
    # the `---` below already ends each message
    out.print(text.removesuffix("\n...\n").rstrip(), markup=False)
    out.print("---", markup=False)


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

    import zenoh

    from runner.launch.announce import find_run, joined, key_of, wait_matched
    from runner.wire.transport import encoding_for, pack_attachment, unpack_attachment

    try:
        full_type, payload = _encoded(type_name, data)
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

            tool = tool_tokens(session, name, "pub")  # (kept: a dropped token is withdrawn)
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
        raise fail(e) from None


def _encoded(type_name: str, data: str) -> tuple[str, bytes]:
    """`pub`'s message: its full type name and its CDR bytes, from the type as written and the YAML."""
    import yaml

    from runner.wire import msgs

    full_type = msgs.normalize_type(type_name)
    if not msgs.is_known(full_type):
        near = msgs.similar_types(full_type)
        raise RunError(
            f"unknown message type {type_name!r}" + (f"; did you mean {', '.join(near)}?" if near else "")
        )
    try:
        fields = yaml.safe_load(data) or {}
        return full_type, msgs.encode(msgs.from_data(full_type, fields), full_type)
    except (yaml.YAMLError, msgs.MessageDataError) as e:
        raise RunError(f"the message does not fit {full_type}: {e}") from None


def topics(
    seconds: Annotated[
        float, typer.Option(metavar="SECONDS", help="How long to listen, wall seconds.", min=0.1)
    ] = 1.0,
    show_all: AllOpt = False,
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """List the topics of a running scenario: type, publishers and subscribers (by process), rates (like
    `ros2 topic list -t` and `ros2 topic info`). Then its services and actions, with their types and
    servers (like `ros2 service list -t`, `ros2 action list -t`).

    Example: scenario topics --seconds 2
    """
    import time

    from runner.launch.announce import find_run, joined
    from runner.wire.graph import query_graph
    from runner.wire.transport import type_from_encoding, unpack_attachment

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
        raise fail(e) from None
    for key, type_name in graph.topics().items():  # declared, if silent while we listened
        if key.startswith(name + "/") and key not in seen:
            seen[key] = {"type": type_name or "?", "n": 0, "t": []}
    out.print(_topics_table(name, seen, graph, seconds, show_all))
    # the run's own (a bridge's copies for ROS 2, under rmw_zenoh's keys, are the graph's to show)
    offered = [o for o in graph.offered(every=show_all) if o.key.startswith(name + "/")]
    if offered:
        out.print(_services_table(name, offered))


def _services_table(name: str, offered: list[Any]) -> Table:
    """`topics`' second table: the services and actions answered in the run (like `ros2 service list -t`
    and `ros2 action list -t`), each with its type and the process that answers it."""
    table = Table("service / action", "type", "kind", "server", title=f"{name}: services and actions")
    for o in offered:
        table.add_row(o.key, o.type or "?", o.kind, ", ".join(o.servers) or "-")
    table.caption = "`scenario call NAME` / `scenario action NAME GOAL` ask them"
    table.caption_justify = "left"
    return table


def _topics_table(
    name: str, seen: dict[str, dict[str, Any]], graph: Any, seconds: float, show_all: bool
) -> Table:
    """`topics`' table: each topic heard or declared, its type, publishers, subscribers and rates."""
    from runner.wire.transport import hidden_key

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
    return table


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
    and subscribes to what, and the services and actions each process answers; the topics, services and
    actions are listed on the terminal too.

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
        raise fail(e) from None
    if not show_all:
        g = g.visible()
    if not g.processes:
        raise fail(RunError(f"run {name!r} announces no processes (is it still starting?)"))
    stem = output or Path(f"{name}-graph")
    stem.parent.mkdir(parents=True, exist_ok=True)
    dot, png = stem.with_name(stem.name + ".dot"), stem.with_name(stem.name + ".png")
    dot.write_text(to_dot(g))
    render_png(g, png)
    for line in summary_lines(g):
        out.print(line, markup=False, highlight=False)
    offered = g.offered()
    served = f", {len(offered)} services and actions" if offered else ""
    out.print(
        f"{len(g.processes)} processes, {len(g.topics())} topics{served} -> {dot}, {png}",
        markup=False,
        highlight=False,
    )
