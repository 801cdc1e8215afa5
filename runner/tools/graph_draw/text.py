"""The run's graph as text: Graphviz DOT (`to_dot`, for `dot -Tsvg` where Graphviz is installed) and one
plain line per topic, service and action for a terminal (`summary_lines`).
"""

from __future__ import annotations

from runner.tools.graph_draw.model import (
    ROLE_COLORS,
    TOPIC_FILL,
    TOPIC_LINE,
    UNKNOWN_COLORS,
    build_model,
    relative_key,
    short_type,
)
from runner.wire.graph import Graph


def _dot_str(text: str) -> str:
    """A DOT double-quoted string. Graphviz's scanner takes `\\"` as a quote and `\\\\` as a pair, so
    escaping both keeps any text (a trailing backslash too) inside its quotes; newlines become `\\n`."""
    text = text.replace("\\", "\\\\").replace('"', '\\"').replace("\r", "").replace("\n", "\\n")
    return f'"{text}"'


def topic_id(key: str) -> str:
    """The DOT node name of a topic (before quoting)."""
    return f"topic:{key}"


def service_id(key: str) -> str:
    """The DOT node name of a service or action (before quoting)."""
    return f"service:{key}"


def process_id(name: str) -> str:
    """The DOT node name of a process (before quoting)."""
    return f"process:{name}"


def _label(*lines: str) -> str:
    return _dot_str("\n".join(line for line in lines if line))


def to_dot(graph: Graph) -> str:
    """The graph as a Graphviz digraph: processes as ellipses coloured by role, topics as boxes (key
    inside the run, short type underneath), edges publisher -> topic -> subscriber; services as hexagons
    and actions as octagons, a dotted edge to the process that answers them (requests go that way)."""
    m = build_model(graph)
    served = f", {len(m.services)} services and actions" if m.services else ""
    title = f"{m.run}: {len(m.processes)} processes, {len(m.topics)} topics{served}"
    out = [
        f"digraph {_dot_str(m.run)} {{",
        f"  graph [rankdir=LR, label={_dot_str(title)}, labelloc=t, fontname=Helvetica, nodesep=0.25];",
        "  node [fontname=Helvetica, fontsize=11];",
        '  edge [color="#3c4655", arrowsize=0.7];',
    ]
    for name, role in m.processes.items():
        fill, line = ROLE_COLORS.get(role, UNKNOWN_COLORS)
        wild = ", ".join(m.wildcards.get(name, []))
        label = _label(name, role if role != name else "", f"sub: {wild}" if wild else "")
        out.append(
            f"  {_dot_str(process_id(name))} [label={label}, shape=ellipse, style=filled, "
            f'fillcolor="{fill}", color="{line}", tooltip={_dot_str(role)}];'
        )
    for t in m.topics:
        label = _label(t.rel, short_type(t.type))
        out.append(
            f'  {_dot_str(topic_id(t.key))} [label={label}, shape=box, style="rounded,filled", '
            f'fillcolor="{TOPIC_FILL}", color="{TOPIC_LINE}", tooltip={_dot_str(t.key)}];'
        )
    for s in m.services:
        label = _label(relative_key(m.run, s.key), s.type or "", "(action)" if s.kind == "action" else "")
        shape = "octagon" if s.kind == "action" else "hexagon"
        out.append(
            f'  {_dot_str(service_id(s.key))} [label={label}, shape={shape}, style="filled", '
            f'fillcolor="{TOPIC_FILL}", color="{TOPIC_LINE}", tooltip={_dot_str(s.key)}];'
        )
    for e in m.edges:
        p, t = _dot_str(process_id(e.process)), _dot_str(topic_id(e.key))
        if e.kind == "pub":
            out.append(f"  {p} -> {t};")
        else:
            out.append(f"  {t} -> {p}{' [style=dashed]' if e.wildcard else ''};")
    for s in m.services:
        for server in s.servers:
            out.append(f"  {_dot_str(service_id(s.key))} -> {_dot_str(process_id(server))} [style=dotted];")
    out.append("}")
    return "\n".join(out) + "\n"


def summary_lines(graph: Graph) -> list[str]:
    """One line per topic, columns aligned: `key  type  pubs: a, b  subs: c`; then one per service and
    action: `key  type  service: a` (`action: a`), `a` the process that answers it."""
    m = build_model(graph)
    rows = []
    for t in m.topics:
        pubs = ", ".join(e.process for e in m.edges if e.key == t.key and e.kind == "pub") or "-"
        subs = ", ".join(e.process for e in m.edges if e.key == t.key and e.kind == "sub") or "-"
        rows.append((t.rel, t.type or "-", f"pubs: {pubs}  subs: {subs}"))
    for s in m.services:
        rows.append((relative_key(m.run, s.key), s.type or "-", f"{s.kind}: {', '.join(s.servers) or '-'}"))
    kw = max((len(r[0]) for r in rows), default=0)
    tw = max((len(r[1]) for r in rows), default=0)
    return [f"{k:<{kw}}  {ty:<{tw}}  {rest}".rstrip() for k, ty, rest in rows]
