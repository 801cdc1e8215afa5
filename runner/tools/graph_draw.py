"""Draw a run's graph (`runner.wire.graph.Graph`) the way rqt_graph does for ROS: processes, topics, and
arrows publisher -> topic -> subscriber.

- `to_dot(graph)`: Graphviz DOT text, for `dot -Tsvg` where Graphviz is installed;
- `render_png(graph, path)`: a PNG drawn with Pillow alone, in three columns: processes that mostly
  publish on the left, the topics in the middle (grouped by namespace), processes that mostly subscribe
  on the right. An edge that runs against that flow (a topic feeding a left-hand process, such as
  `cmd_vel` into the world, or a right-hand process publishing) is drawn in orange, arrowhead at its
  target; an edge that only exists through a wildcard subscription (the recorder's `<run>/**`) is pale;
- `summary_lines(graph)`: one plain line per topic, for a terminal.

The output depends on the graph alone (everything is sorted), so the same graph gives the same bytes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from runner.wire.graph import Graph

# role -> (fill, outline); anything else (a process only seen through its endpoints) is grey
ROLE_COLORS: dict[str, tuple[str, str]] = {
    "world": ("#cfe2ff", "#1f5fbf"),
    "renderer": ("#e6d5f7", "#6f42c1"),
    "node": ("#d3f0d8", "#2b8a3e"),
    "bridge": ("#ffe3c4", "#d9480f"),
    "recorder": ("#f9d2d2", "#c92a2a"),
    "tool": ("#fff1a8", "#b08800"),
}
UNKNOWN_COLORS = ("#e9ecef", "#6c757d")
LEFT_ROLES = ("world", "renderer", "bridge")  # where a process goes when its edges do not decide

TOPIC_FILL, TOPIC_LINE = "#f8f9fa", "#495057"
EDGE = (60, 70, 85)
EDGE_WILD = (165, 175, 190)
EDGE_BACK = (214, 88, 16)
EDGE_BACK_WILD = (240, 175, 130)
TEXT, TEXT_DIM = (33, 37, 41), (90, 98, 108)


# ---------------------------------------------------------------------------------------------------------
# the model all three outputs share


@dataclass(frozen=True)
class _Topic:
    key: str  # the full key
    rel: str  # the key inside the run
    type: str | None
    group: str  # first chunk of `rel` when it has several ("r1"), "" for the run's own topics


@dataclass(frozen=True)
class _Edge:
    process: str
    key: str
    kind: str  # "pub" (process -> topic) | "sub" (topic -> process)
    wildcard: bool  # a subscription only through a wildcard key expression


@dataclass
class _Model:
    run: str
    topics: list[_Topic]
    processes: dict[str, str]  # name -> role ("?" when unknown), sorted by name
    edges: list[_Edge]
    wildcards: dict[str, list[str]] = field(default_factory=dict)  # process -> its wildcard subscriptions


def relative_key(run: str, key: str) -> str:
    """`<run>/r1/scan` -> `r1/scan`; a key outside the run stays whole."""
    return key[len(run) + 1 :] if key.startswith(run + "/") else key


def short_type(type_name: str | None) -> str:
    """`sensor_msgs/msg/LaserScan` -> `sensor_msgs/LaserScan`; "" when unknown."""
    if not type_name:
        return ""
    parts = type_name.split("/")
    if len(parts) == 3 and parts[1] == "msg":
        return f"{parts[0]}/{parts[2]}"
    return type_name


def _model(graph: Graph) -> _Model:
    topics = []
    for key, type_name in graph.topics().items():
        rel = relative_key(graph.run, key)
        chunks = rel.split("/")
        topics.append(_Topic(key, rel, type_name, chunks[0] if len(chunks) > 1 else ""))
    topics.sort(key=lambda t: (t.group != "", t.group, t.rel))

    processes = dict(graph.processes)
    for e in graph.endpoints:
        processes.setdefault(e.process, "?")
    processes = dict(sorted(processes.items()))

    exact_subs = {(e.process, e.key) for e in graph.endpoints if e.kind == "sub"}
    edges = []
    for t in topics:
        edges += [_Edge(p, t.key, "pub", False) for p in graph.publishers(t.key)]
        edges += [_Edge(p, t.key, "sub", (p, t.key) not in exact_subs) for p in graph.subscribers(t.key)]

    wildcards: dict[str, list[str]] = {}
    for e in sorted(graph.endpoints, key=lambda e: (e.process, e.key)):
        if e.kind == "sub" and "*" in e.key:
            wildcards.setdefault(e.process, []).append(relative_key(graph.run, e.key))
    return _Model(graph.run, topics, processes, edges, wildcards)


# ---------------------------------------------------------------------------------------------------------
# DOT


def _dot_str(text: str) -> str:
    """A DOT double-quoted string. Graphviz's scanner takes `\\"` as a quote and `\\\\` as a pair, so
    escaping both keeps any text (a trailing backslash too) inside its quotes; newlines become `\\n`."""
    text = text.replace("\\", "\\\\").replace('"', '\\"').replace("\r", "").replace("\n", "\\n")
    return f'"{text}"'


def topic_id(key: str) -> str:
    """The DOT node name of a topic (before quoting)."""
    return f"topic:{key}"


def process_id(name: str) -> str:
    """The DOT node name of a process (before quoting)."""
    return f"process:{name}"


def _label(*lines: str) -> str:
    return _dot_str("\n".join(line for line in lines if line))


def to_dot(graph: Graph) -> str:
    """The graph as a Graphviz digraph: processes as ellipses coloured by role, topics as boxes (key
    inside the run, short type underneath), edges publisher -> topic -> subscriber."""
    m = _model(graph)
    title = f"{m.run}: {len(m.processes)} processes, {len(m.topics)} topics"
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
    for e in m.edges:
        p, t = _dot_str(process_id(e.process)), _dot_str(topic_id(e.key))
        if e.kind == "pub":
            out.append(f"  {p} -> {t};")
        else:
            out.append(f"  {t} -> {p}{' [style=dashed]' if e.wildcard else ''};")
    out.append("}")
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------------------------------------
# plain text


def summary_lines(graph: Graph) -> list[str]:
    """One line per topic, columns aligned: `key  type  pubs: a, b  subs: c`."""
    m = _model(graph)
    rows = []
    for t in m.topics:
        pubs = ", ".join(e.process for e in m.edges if e.key == t.key and e.kind == "pub") or "-"
        subs = ", ".join(e.process for e in m.edges if e.key == t.key and e.kind == "sub") or "-"
        rows.append((t.rel, t.type or "-", pubs, subs))
    kw = max((len(r[0]) for r in rows), default=0)
    tw = max((len(r[1]) for r in rows), default=0)
    return [f"{k:<{kw}}  {ty:<{tw}}  pubs: {p}  subs: {s}".rstrip() for k, ty, p, s in rows]


# ---------------------------------------------------------------------------------------------------------
# PNG

SS = 2  # drawn at twice the size, then scaled down: smooth lines and curves without an antialiasing API
MARGIN = 24
GAP = 200  # between columns, where the edges run
TOPIC_H = 42
TOPIC_GAP = 10
GROUP_HEAD = 20
PROC_GAP = 18
PORT_STEP = 11  # apart enough that neighbouring arrowheads stay distinct
PAD = 10
ARROW_L, ARROW_W = 10, 4.5
MAX_TOPIC_W, MAX_PROC_W = 380, 260


@dataclass
class _Box:
    x: float
    y: float
    w: float
    h: float

    @property
    def cy(self) -> float:
        return self.y + self.h / 2


class _Fonts:
    def __init__(self, scale: int):
        from PIL import ImageFont

        self.title = ImageFont.load_default(size=20 * scale)
        self.sub = ImageFont.load_default(size=13 * scale)
        self.label = ImageFont.load_default(size=14 * scale)
        self.small = ImageFont.load_default(size=12 * scale)
        self.scale = scale

    def width(self, font: Any, text: str) -> float:
        return font.getlength(text) / self.scale


def _fit(fonts: _Fonts, font: Any, text: str, max_w: float) -> str:
    """The text, shortened in the middle with `...` to fit `max_w`."""
    if fonts.width(font, text) <= max_w:
        return text
    head, tail = len(text) // 2, len(text) - len(text) // 2
    while head + tail > 1:
        if head >= tail:
            head -= 1
        else:
            tail -= 1
        candidate = text[:head] + "..." + text[len(text) - tail :]
        if fonts.width(font, candidate) <= max_w:
            return candidate
    return "..."


@dataclass
class _Line:
    """One edge as drawn: from `start` to `end` (the arrowhead), `back` when against the flow."""

    edge: _Edge
    start: tuple[float, float] = (0.0, 0.0)
    end: tuple[float, float] = (0.0, 0.0)
    back: bool = False


def _count(n: int, one: str, many: str) -> str:
    return f"{n} {one if n == 1 else many}"


def _side(m: _Model) -> dict[str, str]:
    """'L' or 'R' per process: the side where it has more edges; its role decides a tie."""
    out = {}
    for name, role in m.processes.items():
        pubs = sum(1 for e in m.edges if e.process == name and e.kind == "pub")
        subs = sum(1 for e in m.edges if e.process == name and e.kind == "sub")
        if pubs != subs:
            out[name] = "L" if pubs > subs else "R"
        else:
            out[name] = "L" if role in LEFT_ROLES else "R"
    return out


def _process_lines(m: _Model, name: str, role: str) -> list[tuple[str, str]]:
    lines = [("label", name)]
    if role != name:
        lines.append(("small", role if role != "?" else "(role unknown)"))
    if m.wildcards.get(name):
        lines.append(("small", "sub: " + ", ".join(m.wildcards[name])))
    return lines


def _place(items: list[tuple[str, float, float]], top: float, bottom: float, gap: float) -> dict[str, float]:
    """Tops for boxes (name, wanted centre, height), kept in order: as near their wanted centres as
    they fit without overlapping, inside [top, bottom]."""
    tops: list[float] = []
    for _, want, h in items:
        y = max(want - h / 2, top, (tops[-1] + items[len(tops) - 1][2] + gap) if tops else top)
        tops.append(y)
    limit = bottom
    for i in range(len(items) - 1, -1, -1):
        h = items[i][2]
        if tops[i] + h > limit:
            tops[i] = max(top, limit - h)
        limit = tops[i] - gap
    return {name: y for (name, _, _), y in zip(items, tops, strict=True)}


def _ports(box: _Box, n: int) -> list[float]:
    """`n` attachment heights spread along a box side."""
    if n <= 0:
        return []
    if n == 1:
        return [box.cy]
    inset = min(PAD, box.h / 4)
    step = (box.h - 2 * inset) / (n - 1)
    return [box.y + inset + i * step for i in range(n)]


def _bezier(p0: tuple[float, float], p3: tuple[float, float], n: int = 32) -> list[tuple[float, float]]:
    """A cubic curve leaving `p0` and reaching `p3` horizontally."""
    c = abs(p3[0] - p0[0]) * 0.45
    d = 1 if p3[0] >= p0[0] else -1
    p1, p2 = (p0[0] + d * c, p0[1]), (p3[0] - d * c, p3[1])
    pts = []
    for i in range(n + 1):
        s = i / n
        a, b, cc, dd = (1 - s) ** 3, 3 * s * (1 - s) ** 2, 3 * s * s * (1 - s), s**3
        pts.append(
            (
                a * p0[0] + b * p1[0] + cc * p2[0] + dd * p3[0],
                a * p0[1] + b * p1[1] + cc * p2[1] + dd * p3[1],
            )
        )
    return pts


def render_png(graph: Graph, path: Path, *, width: int | None = None) -> None:
    """Draw the graph into a PNG at `path` (Pillow alone, no Graphviz). The height grows with the number
    of topics; `width` fixes the image's width (the columns spread out, or the drawing is scaled down)."""
    from PIL import Image, ImageDraw

    m = _model(graph)
    fonts = _Fonts(SS)
    side = _side(m)
    left = [n for n in m.processes if side[n] == "L"]
    right = [n for n in m.processes if side[n] == "R"]

    # sizes (all in 1x units; drawing multiplies by SS)
    topic_lines = {
        t.key: (_fit(fonts, fonts.label, t.rel, MAX_TOPIC_W), short_type(t.type)) for t in m.topics
    }
    topic_w = max(
        [140.0]
        + [
            max(fonts.width(fonts.label, a), fonts.width(fonts.small, b)) + 2 * PAD
            for a, b in topic_lines.values()
        ]
    )
    topic_w = min(topic_w, MAX_TOPIC_W + 2 * PAD)
    proc_lines = {
        n: [
            (kind, _fit(fonts, getattr(fonts, kind), text, MAX_PROC_W))
            for kind, text in _process_lines(m, n, r)
        ]
        for n, r in m.processes.items()
    }
    n_edges = {n: sum(1 for e in m.edges if e.process == n) for n in m.processes}

    def proc_size(n: str) -> tuple[float, float]:
        lines = proc_lines[n]
        w = max(fonts.width(getattr(fonts, k), t) for k, t in lines) + 2 * PAD + 8
        text_h = sum(18 if k == "label" else 15 for k, _ in lines)
        return max(w, 90.0), max(text_h + 2 * PAD - 2, n_edges[n] * PORT_STEP + 2 * PAD)

    psize = {n: proc_size(n) for n in m.processes}
    left_w = max([100.0] + [psize[n][0] for n in left])
    right_w = max([100.0] + [psize[n][0] for n in right])

    groups: list[str] = []
    for t in m.topics:
        if not groups or groups[-1] != t.group:
            groups.append(t.group)
    show_groups = len(groups) > 1 or (groups and groups[0] != "")
    topics_h = len(m.topics) * (TOPIC_H + TOPIC_GAP) - (TOPIC_GAP if m.topics else 0)
    topics_h += (GROUP_HEAD + 6) * len(groups) if show_groups else 0
    if not m.topics:
        topics_h = TOPIC_H
    col_h = {
        "L": sum(psize[n][1] for n in left) + PROC_GAP * max(len(left) - 1, 0),
        "R": sum(psize[n][1] for n in right) + PROC_GAP * max(len(right) - 1, 0),
    }
    content_h = max(topics_h, col_h["L"], col_h["R"], 60)

    title = f"Run graph: {m.run}"
    n_back = sum(1 for e in m.edges if (e.kind == "sub") == (side[e.process] == "L"))
    counts = "  ·  ".join(
        [_count(len(m.processes), "process", "processes"), _count(len(m.topics), "topic", "topics")]
        + [_count(len(m.edges), "connection", "connections")]
        + ([f"{n_back} against the flow (orange)"] if n_back else [])
    )
    gap = min(GAP + 120, max(GAP, 0.15 * content_h))  # a taller fan gets a wider gap
    natural_w = 2 * MARGIN + left_w + topic_w + right_w + 2 * gap
    natural_w = max(
        natural_w, 2 * MARGIN + fonts.width(fonts.title, title), 2 * MARGIN + fonts.width(fonts.sub, counts)
    )
    target_w = natural_w
    if width is not None and width > natural_w:  # spread the columns out to the width asked
        target_w = float(width)
    gap += (target_w - (2 * MARGIN + left_w + topic_w + right_w + 2 * gap)) / 2

    # legend items, wrapped to the width
    roles_present = sorted({r for r in m.processes.values()}, key=lambda r: (r not in ROLE_COLORS, r))
    legend: list[tuple[str, Any, str]] = [
        ("role", r, r if r != "?" else "unknown role") for r in roles_present
    ]
    legend.append(("topic", None, "topic (type below)"))
    legend.append(("edge", EDGE, "publishes / subscribes"))
    if n_back:
        legend.append(("edge", EDGE_BACK, "against the flow (arrowhead at the target)"))
    if any(e.wildcard for e in m.edges):
        legend.append(("edge", EDGE_WILD, "through a wildcard subscription"))
    legend_rows: list[list[tuple[str, Any, str, float]]] = [[]]
    x = MARGIN
    for kind, what, text in legend:
        w = (34 if kind != "role" else 22) + 6 + fonts.width(fonts.small, text) + 22
        if legend_rows[-1] and x + w > target_w - MARGIN:
            legend_rows.append([])
            x = MARGIN
        legend_rows[-1].append((kind, what, text, x))
        x += w
    legend_h = 22 * len(legend_rows) + 14

    head_h = 62
    total_h = head_h + content_h + 16 + legend_h + MARGIN
    top = head_h
    xs = {"L": MARGIN, "T": MARGIN + left_w + gap, "R": MARGIN + left_w + gap + topic_w + gap}

    # topic boxes, centred in the content band
    tboxes: dict[str, _Box] = {}
    bands: list[tuple[str, float, float]] = []
    y = top + (content_h - topics_h) / 2
    current = None
    for t in m.topics:
        if show_groups and t.group != current:
            if current is not None:
                y += 6
            bands.append((t.group, y, 0.0))
            y += GROUP_HEAD
            current = t.group
        tboxes[t.key] = _Box(xs["T"], y, topic_w, TOPIC_H)
        y += TOPIC_H + TOPIC_GAP
        if show_groups:
            g, y0, _ = bands[-1]
            bands[-1] = (g, y0, y - TOPIC_GAP)

    # process boxes: near the topics they touch
    def wanted(n: str) -> float:
        ys = [tboxes[e.key].cy for e in m.edges if e.process == n]
        return sum(ys) / len(ys) if ys else top + content_h + 1e6  # loners sink to the bottom

    pboxes: dict[str, _Box] = {}
    for col, names in (("L", left), ("R", right)):
        items = sorted(((n, wanted(n), psize[n][1]) for n in names), key=lambda i: (i[1], i[0]))
        if all(i[1] > top + content_h for i in items):
            start = top + (content_h - col_h[col]) / 2
            items = [(n, start + content_h, h) for n, _, h in items]
            tops = {}
            yy = start
            for n, _, h in items:
                tops[n] = yy
                yy += h + PROC_GAP
        else:
            items = [(n, min(w, top + content_h), h) for n, w, h in items]
            tops = _place(items, top, top + content_h, PROC_GAP)
        for n in names:
            w, h = psize[n]
            x0 = xs["L"] + left_w - w if col == "L" else xs["R"]
            pboxes[n] = _Box(x0, tops[n], w, h)

    # edges: which side of each box they attach to, in an order that avoids needless crossings
    lines = [_Line(e, back=(e.kind == "sub") == (side[e.process] == "L")) for e in m.edges]
    proc_port: dict[int, float] = {}
    topic_port: dict[int, float] = {}
    for n, box in pboxes.items():
        mine = [i for i, ln in enumerate(lines) if ln.edge.process == n]
        mine.sort(key=lambda i: (tboxes[lines[i].edge.key].cy, lines[i].edge.kind))
        for i, py in zip(mine, _ports(box, len(mine)), strict=True):
            proc_port[i] = py
    for key, box in tboxes.items():
        for col in ("L", "R"):
            mine = [i for i, ln in enumerate(lines) if ln.edge.key == key and side[ln.edge.process] == col]
            mine.sort(key=lambda i: (proc_port[i], lines[i].edge.kind))
            for i, ty in zip(mine, _ports(box, len(mine)), strict=True):
                topic_port[i] = ty
    for i, ln in enumerate(lines):
        pb, tb = pboxes[ln.edge.process], tboxes[ln.edge.key]
        if side[ln.edge.process] == "L":
            p, t = (pb.x + pb.w, proc_port[i]), (tb.x, topic_port[i])
        else:
            p, t = (pb.x, proc_port[i]), (tb.x + tb.w, topic_port[i])
        ln.start, ln.end = (p, t) if ln.edge.kind == "pub" else (t, p)

    # drawing
    s = SS
    img = Image.new("RGB", (round(target_w * s), round(total_h * s)), "white")
    draw = ImageDraw.Draw(img)

    def S(v: float) -> float:
        return v * s

    def text(x: float, y: float, t: str, font: Any, fill: Any, anchor: str = "la") -> None:
        draw.text((S(x), S(y)), t, font=font, fill=fill, anchor=anchor)

    def arrow(tip: tuple[float, float], d: int, fill: Any) -> None:
        bx = tip[0] - d * ARROW_L
        draw.polygon(
            [(S(tip[0]), S(tip[1])), (S(bx), S(tip[1] - ARROW_W)), (S(bx), S(tip[1] + ARROW_W))], fill=fill
        )

    text(MARGIN, 14, title, fonts.title, TEXT)
    text(MARGIN, 40, counts, fonts.sub, TEXT_DIM)
    draw.line(
        [(S(MARGIN), S(head_h - 8)), (S(target_w - MARGIN), S(head_h - 8))], fill=(222, 226, 230), width=s
    )

    for g, y0, y1 in bands:
        draw.rounded_rectangle(
            [S(xs["T"] - 8), S(y0), S(xs["T"] + topic_w + 8), S(y1 + 6)], radius=S(6), fill=(241, 243, 245)
        )
        text(xs["T"] - 2, y0 + 3, f"{g}/", fonts.small, TEXT_DIM)

    def color(ln: _Line) -> Any:
        if ln.back:
            return EDGE_BACK_WILD if ln.edge.wildcard else EDGE_BACK
        return EDGE_WILD if ln.edge.wildcard else EDGE

    order = sorted(range(len(lines)), key=lambda i: (not lines[i].edge.wildcard, lines[i].back, i))
    for i in order:
        ln = lines[i]
        pts = _bezier(ln.start, ln.end)
        draw.line([(S(x), S(y)) for x, y in pts], fill=color(ln), width=round(1.6 * s), joint="curve")

    for n, box in pboxes.items():
        fill, outline = ROLE_COLORS.get(m.processes[n], UNKNOWN_COLORS)
        draw.rounded_rectangle(
            [S(box.x), S(box.y), S(box.x + box.w), S(box.y + box.h)],
            radius=S(min(16, box.h / 2)),
            fill=fill,
            outline=outline,
            width=s,
        )
        plines = proc_lines[n]
        th = sum(18 if k == "label" else 15 for k, _ in plines)
        yy = box.cy - th / 2
        for k, t in plines:
            text(box.x + box.w / 2, yy, t, getattr(fonts, k), TEXT if k == "label" else TEXT_DIM, "ma")
            yy += 18 if k == "label" else 15

    for t in m.topics:
        box = tboxes[t.key]
        draw.rectangle(
            [S(box.x), S(box.y), S(box.x + box.w), S(box.y + box.h)],
            fill=TOPIC_FILL,
            outline=TOPIC_LINE,
            width=s,
        )
        key_line, type_line = topic_lines[t.key]
        if type_line:
            text(box.x + PAD, box.y + 5, key_line, fonts.label, TEXT)
            text(
                box.x + PAD,
                box.y + 24,
                _fit(fonts, fonts.small, type_line, box.w - 2 * PAD),
                fonts.small,
                TEXT_DIM,
            )
        else:
            text(box.x + PAD, box.cy, key_line, fonts.label, TEXT, "lm")
    if not m.topics:
        box = _Box(xs["T"], top + (content_h - TOPIC_H) / 2, topic_w, TOPIC_H)
        draw.rounded_rectangle(
            [S(box.x), S(box.y), S(box.x + box.w), S(box.y + box.h)],
            radius=S(6),
            outline=(173, 181, 189),
            width=s,
        )
        text(box.x + box.w / 2, box.cy, "no topics", fonts.label, TEXT_DIM, "mm")

    for ln in lines:  # arrowheads last, on top of the box outlines they touch
        arrow(ln.end, 1 if ln.end[0] >= ln.start[0] else -1, color(ln))

    ly = top + content_h + 16
    draw.line([(S(MARGIN), S(ly - 6)), (S(target_w - MARGIN), S(ly - 6))], fill=(222, 226, 230), width=s)
    for row in legend_rows:
        cy = ly + 11
        for kind, what, label, x0 in row:
            if kind == "role":
                fill, outline = ROLE_COLORS.get(what, UNKNOWN_COLORS)
                draw.rounded_rectangle(
                    [S(x0), S(cy - 7), S(x0 + 22), S(cy + 7)],
                    radius=S(7),
                    fill=fill,
                    outline=outline,
                    width=s,
                )
                tx = x0 + 28
            elif kind == "topic":
                draw.rectangle(
                    [S(x0), S(cy - 7), S(x0 + 34), S(cy + 7)], fill=TOPIC_FILL, outline=TOPIC_LINE, width=s
                )
                tx = x0 + 40
            else:
                draw.line([(S(x0), S(cy)), (S(x0 + 34 - ARROW_L), S(cy))], fill=what, width=round(1.6 * s))
                arrow((x0 + 34, cy), 1, what)
                tx = x0 + 40
            text(tx, cy, label, fonts.small, TEXT, "lm")
        ly += 22

    out_w = round(target_w)
    if width is not None and width < natural_w:
        out_w = width
    out_h = max(1, round(total_h * out_w / target_w))
    img = img.resize((out_w, out_h), Image.Resampling.LANCZOS)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    img.save(path, format="PNG", optimize=False)
