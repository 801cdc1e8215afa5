"""Where everything of the PNG drawing of a run's graph goes (`Layout`), in 1x units (the drawing
multiplies by `SS`): three columns, processes that mostly publish on the left, the topics in the middle
(grouped by namespace), processes that mostly subscribe on the right (a process that answers services
names them in its box); each process near the topics it
touches; each edge's ends spread along the box sides in an order that avoids needless crossings; the
legend wrapped to the width.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from runner.tools.graph_draw.model import (
    EDGE,
    EDGE_BACK,
    EDGE_WILD,
    LEFT_ROLES,
    ROLE_COLORS,
    Edge,
    GraphModel,
    relative_key,
    short_type,
)

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
class Box:
    x: float
    y: float
    w: float
    h: float

    @property
    def cy(self) -> float:
        return self.y + self.h / 2


class Fonts:
    def __init__(self, scale: int):
        from PIL import ImageFont

        self.title = ImageFont.load_default(size=20 * scale)
        self.sub = ImageFont.load_default(size=13 * scale)
        self.label = ImageFont.load_default(size=14 * scale)
        self.small = ImageFont.load_default(size=12 * scale)
        self.scale = scale

    def width(self, font: Any, text: str) -> float:
        return font.getlength(text) / self.scale


def fit(fonts: Fonts, font: Any, text: str, max_w: float) -> str:
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
class Line:
    """One edge as drawn: from `start` to `end` (the arrowhead), `back` when against the flow."""

    edge: Edge
    start: tuple[float, float] = (0.0, 0.0)
    end: tuple[float, float] = (0.0, 0.0)
    back: bool = False


def count(n: int, one: str, many: str) -> str:
    return f"{n} {one if n == 1 else many}"


def side(m: GraphModel) -> dict[str, str]:
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


def process_lines(m: GraphModel, name: str, role: str) -> list[tuple[str, str]]:
    lines = [("label", name)]
    if role != name:
        lines.append(("small", role if role != "?" else "(role unknown)"))
    if m.wildcards.get(name):
        lines.append(("small", "sub: " + ", ".join(m.wildcards[name])))
    served = [s for s in m.services if name in s.servers]
    if served:  # the services and actions it answers, named in its box (the drawing has no column for them)
        names = [relative_key(m.run, s.key) + (" (action)" if s.kind == "action" else "") for s in served]
        lines.append(("small", f"serves {len(served)}: " + ", ".join(names)))
    return lines


def place(items: list[tuple[str, float, float]], top: float, bottom: float, gap: float) -> dict[str, float]:
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


def ports(box: Box, n: int) -> list[float]:
    """`n` attachment heights spread along a box side."""
    if n <= 0:
        return []
    if n == 1:
        return [box.cy]
    inset = min(PAD, box.h / 4)
    step = (box.h - 2 * inset) / (n - 1)
    return [box.y + inset + i * step for i in range(n)]


def bezier(p0: tuple[float, float], p3: tuple[float, float], n: int = 32) -> list[tuple[float, float]]:
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


class Layout:
    """The PNG's geometry, worked out in the order a reader would: the boxes' sizes, the columns' heights,
    the header and the width, the legend, then the topic boxes, the process boxes, and the edges."""

    def __init__(self, m: GraphModel, fonts: Fonts, width: int | None):
        self.m = m
        self.fonts = fonts
        self.side = side(m)
        self.left = [n for n in m.processes if self.side[n] == "L"]
        self.right = [n for n in m.processes if self.side[n] == "R"]
        self._measure()
        self._heights()
        self._header_and_width(width)
        self._legend()
        self.head_h = 62
        self.total_h = self.head_h + self.content_h + 16 + self.legend_h + MARGIN
        self.top = self.head_h
        lw, tw, gap = self.left_w, self.topic_w, self.gap
        self.xs = {"L": MARGIN, "T": MARGIN + lw + gap, "R": MARGIN + lw + gap + tw + gap}
        self._topic_boxes()
        self._process_boxes()
        self._edges()

    def _measure(self) -> None:
        """The texts of each box (shortened to fit) and the boxes' sizes."""
        m, fonts = self.m, self.fonts
        self.topic_lines = {
            t.key: (fit(fonts, fonts.label, t.rel, MAX_TOPIC_W), short_type(t.type)) for t in m.topics
        }
        topic_w = max(
            [140.0]
            + [
                max(fonts.width(fonts.label, a), fonts.width(fonts.small, b)) + 2 * PAD
                for a, b in self.topic_lines.values()
            ]
        )
        self.topic_w = min(topic_w, MAX_TOPIC_W + 2 * PAD)
        self.proc_lines = {
            n: [
                (kind, fit(fonts, getattr(fonts, kind), text, MAX_PROC_W))
                for kind, text in process_lines(m, n, r)
            ]
            for n, r in m.processes.items()
        }
        n_edges = {n: sum(1 for e in m.edges if e.process == n) for n in m.processes}

        def proc_size(n: str) -> tuple[float, float]:
            lines = self.proc_lines[n]
            w = max(fonts.width(getattr(fonts, k), t) for k, t in lines) + 2 * PAD + 8
            text_h = sum(18 if k == "label" else 15 for k, _ in lines)
            return max(w, 90.0), max(text_h + 2 * PAD - 2, n_edges[n] * PORT_STEP + 2 * PAD)

        self.psize = {n: proc_size(n) for n in m.processes}
        self.left_w = max([100.0] + [self.psize[n][0] for n in self.left])
        self.right_w = max([100.0] + [self.psize[n][0] for n in self.right])

    def _heights(self) -> None:
        """The topic column (with a head per namespace group), the process columns, the content band."""
        m, psize = self.m, self.psize
        groups: list[str] = []
        for t in m.topics:
            if not groups or groups[-1] != t.group:
                groups.append(t.group)
        self.show_groups = len(groups) > 1 or (groups and groups[0] != "")
        topics_h = len(m.topics) * (TOPIC_H + TOPIC_GAP) - (TOPIC_GAP if m.topics else 0)
        topics_h += (GROUP_HEAD + 6) * len(groups) if self.show_groups else 0
        if not m.topics:
            topics_h = TOPIC_H
        self.topics_h = topics_h
        left, right = self.left, self.right
        self.col_h = {
            "L": sum(psize[n][1] for n in left) + PROC_GAP * max(len(left) - 1, 0),
            "R": sum(psize[n][1] for n in right) + PROC_GAP * max(len(right) - 1, 0),
        }
        self.content_h = max(topics_h, self.col_h["L"], self.col_h["R"], 60)

    def _header_and_width(self, width: int | None) -> None:
        """The title and counts line, the natural width, and the width drawn at (`width` when wider: the
        columns spread out to it)."""
        m, side, fonts = self.m, self.side, self.fonts
        self.title = f"Run graph: {m.run}"
        self.n_back = sum(1 for e in m.edges if (e.kind == "sub") == (side[e.process] == "L"))
        self.counts = "  ·  ".join(
            [count(len(m.processes), "process", "processes"), count(len(m.topics), "topic", "topics")]
            + [count(len(m.edges), "connection", "connections")]
            + ([count(len(m.services), "service or action", "services and actions")] if m.services else [])
            + ([f"{self.n_back} against the flow (orange)"] if self.n_back else [])
        )
        gap = min(GAP + 120, max(GAP, 0.15 * self.content_h))  # a taller fan gets a wider gap
        left_w, topic_w, right_w = self.left_w, self.topic_w, self.right_w
        natural_w = 2 * MARGIN + left_w + topic_w + right_w + 2 * gap
        natural_w = max(
            natural_w,
            2 * MARGIN + fonts.width(fonts.title, self.title),
            2 * MARGIN + fonts.width(fonts.sub, self.counts),
        )
        target_w = natural_w
        if width is not None and width > natural_w:  # spread the columns out to the width asked
            target_w = float(width)
        self.gap = gap + (target_w - (2 * MARGIN + left_w + topic_w + right_w + 2 * gap)) / 2
        self.natural_w, self.target_w = natural_w, target_w

    def _legend(self) -> None:
        """The legend's items (roles present, topic, the kinds of edges drawn), wrapped to the width."""
        m = self.m
        roles_present = sorted({r for r in m.processes.values()}, key=lambda r: (r not in ROLE_COLORS, r))
        legend: list[tuple[str, Any, str]] = [
            ("role", r, r if r != "?" else "unknown role") for r in roles_present
        ]
        legend.append(("topic", None, "topic (type below)"))
        legend.append(("edge", EDGE, "publishes / subscribes"))
        if self.n_back:
            legend.append(("edge", EDGE_BACK, "against the flow (arrowhead at the target)"))
        if any(e.wildcard for e in m.edges):
            legend.append(("edge", EDGE_WILD, "through a wildcard subscription"))
        self.legend_rows: list[list[tuple[str, Any, str, float]]] = [[]]
        x = MARGIN
        for kind, what, text in legend:
            w = (34 if kind != "role" else 22) + 6 + self.fonts.width(self.fonts.small, text) + 22
            if self.legend_rows[-1] and x + w > self.target_w - MARGIN:
                self.legend_rows.append([])
                x = MARGIN
            self.legend_rows[-1].append((kind, what, text, x))
            x += w
        self.legend_h = 22 * len(self.legend_rows) + 14

    def _topic_boxes(self) -> None:
        """The topic boxes, centred in the content band, and the band behind each namespace group."""
        self.tboxes: dict[str, Box] = {}
        self.bands: list[tuple[str, float, float]] = []
        y = self.top + (self.content_h - self.topics_h) / 2
        current = None
        for t in self.m.topics:
            if self.show_groups and t.group != current:
                if current is not None:
                    y += 6
                self.bands.append((t.group, y, 0.0))
                y += GROUP_HEAD
                current = t.group
            self.tboxes[t.key] = Box(self.xs["T"], y, self.topic_w, TOPIC_H)
            y += TOPIC_H + TOPIC_GAP
            if self.show_groups:
                g, y0, _ = self.bands[-1]
                self.bands[-1] = (g, y0, y - TOPIC_GAP)

    def _process_boxes(self) -> None:
        """The process boxes: near the topics they touch (loners at the bottom)."""
        m, top, content_h, psize = self.m, self.top, self.content_h, self.psize

        def wanted(n: str) -> float:
            ys = [self.tboxes[e.key].cy for e in m.edges if e.process == n]
            return sum(ys) / len(ys) if ys else top + content_h + 1e6  # loners sink to the bottom

        self.pboxes: dict[str, Box] = {}
        for col, names in (("L", self.left), ("R", self.right)):
            items = sorted(((n, wanted(n), psize[n][1]) for n in names), key=lambda i: (i[1], i[0]))
            if all(i[1] > top + content_h for i in items):
                start = top + (content_h - self.col_h[col]) / 2
                items = [(n, start + content_h, h) for n, _, h in items]
                tops = {}
                yy = start
                for n, _, h in items:
                    tops[n] = yy
                    yy += h + PROC_GAP
            else:
                items = [(n, min(w, top + content_h), h) for n, w, h in items]
                tops = place(items, top, top + content_h, PROC_GAP)
            for n in names:
                w, h = psize[n]
                x0 = self.xs["L"] + self.left_w - w if col == "L" else self.xs["R"]
                self.pboxes[n] = Box(x0, tops[n], w, h)

    def _edges(self) -> None:
        """Which side of each box every edge attaches to, in an order that avoids needless crossings."""
        side, pboxes, tboxes = self.side, self.pboxes, self.tboxes
        lines = [Line(e, back=(e.kind == "sub") == (side[e.process] == "L")) for e in self.m.edges]
        proc_port: dict[int, float] = {}
        topic_port: dict[int, float] = {}
        for n, box in pboxes.items():
            mine = [i for i, ln in enumerate(lines) if ln.edge.process == n]
            mine.sort(key=lambda i: (tboxes[lines[i].edge.key].cy, lines[i].edge.kind))
            for i, py in zip(mine, ports(box, len(mine)), strict=True):
                proc_port[i] = py
        for key, box in tboxes.items():
            for col in ("L", "R"):
                mine = [
                    i for i, ln in enumerate(lines) if ln.edge.key == key and side[ln.edge.process] == col
                ]
                mine.sort(key=lambda i: (proc_port[i], lines[i].edge.kind))
                for i, ty in zip(mine, ports(box, len(mine)), strict=True):
                    topic_port[i] = ty
        for i, ln in enumerate(lines):
            pb, tb = pboxes[ln.edge.process], tboxes[ln.edge.key]
            if side[ln.edge.process] == "L":
                p, t = (pb.x + pb.w, proc_port[i]), (tb.x, topic_port[i])
            else:
                p, t = (pb.x, proc_port[i]), (tb.x + tb.w, topic_port[i])
            ln.start, ln.end = (p, t) if ln.edge.kind == "pub" else (t, p)
        self.lines = lines
