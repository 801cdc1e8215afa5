"""Drawing a run's graph into a PNG with Pillow alone (no Graphviz), from its `Layout`: the header, the
namespace bands, the edges (an edge against the flow in orange, one only through a wildcard subscription
pale), the process and topic boxes, the arrowheads on top, and the legend. Drawn at `SS` times the size,
then scaled down: smooth lines and curves without an antialiasing API.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from runner.tools.graph_draw.layout import (
    ARROW_L,
    ARROW_W,
    MARGIN,
    PAD,
    SS,
    TOPIC_H,
    Box,
    Fonts,
    Layout,
    Line,
    bezier,
    fit,
)
from runner.tools.graph_draw.model import (
    EDGE,
    EDGE_BACK,
    EDGE_BACK_WILD,
    EDGE_WILD,
    ROLE_COLORS,
    TEXT,
    TEXT_DIM,
    TOPIC_FILL,
    TOPIC_LINE,
    UNKNOWN_COLORS,
    build_model,
)
from runner.wire.graph import Graph

RULE = (222, 226, 230)  # the lines under the header and above the legend


def render_png(graph: Graph, path: Path, *, width: int | None = None) -> None:
    """Draw the graph into a PNG at `path` (Pillow alone, no Graphviz). The height grows with the number
    of topics; `width` fixes the image's width (the columns spread out, or the drawing is scaled down)."""
    from PIL import Image

    lay = Layout(build_model(graph), Fonts(SS), width)
    c = _Canvas(lay)
    c.header()
    c.bands()
    c.edges()
    c.processes()
    c.topics()
    for ln in lay.lines:  # arrowheads last, on top of the box outlines they touch
        c.arrow(ln.end, 1 if ln.end[0] >= ln.start[0] else -1, _color(ln))
    c.legend()

    out_w = round(lay.target_w)
    if width is not None and width < lay.natural_w:
        out_w = width
    out_h = max(1, round(lay.total_h * out_w / lay.target_w))
    img = c.img.resize((out_w, out_h), Image.Resampling.LANCZOS)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    img.save(path, format="PNG", optimize=False)


def _color(ln: Line) -> Any:
    if ln.back:
        return EDGE_BACK_WILD if ln.edge.wildcard else EDGE_BACK
    return EDGE_WILD if ln.edge.wildcard else EDGE


def S(v: float) -> float:
    """1x units -> pixels of the image drawn at `SS` times the size."""
    return v * SS


class _Canvas:
    """The image being drawn, at `SS` times the size, and the parts of the drawing in their order."""

    def __init__(self, lay: Layout):
        from PIL import Image, ImageDraw

        self.lay = lay
        self.fonts = lay.fonts
        self.img = Image.new("RGB", (round(lay.target_w * SS), round(lay.total_h * SS)), "white")
        self.draw = ImageDraw.Draw(self.img)

    def text(self, x: float, y: float, t: str, font: Any, fill: Any, anchor: str = "la") -> None:
        self.draw.text((S(x), S(y)), t, font=font, fill=fill, anchor=anchor)

    def arrow(self, tip: tuple[float, float], d: int, fill: Any) -> None:
        bx = tip[0] - d * ARROW_L
        self.draw.polygon(
            [(S(tip[0]), S(tip[1])), (S(bx), S(tip[1] - ARROW_W)), (S(bx), S(tip[1] + ARROW_W))], fill=fill
        )

    def rule(self, y: float) -> None:
        self.draw.line([(S(MARGIN), S(y)), (S(self.lay.target_w - MARGIN), S(y))], fill=RULE, width=SS)

    def header(self) -> None:
        lay = self.lay
        self.text(MARGIN, 14, lay.title, self.fonts.title, TEXT)
        self.text(MARGIN, 40, lay.counts, self.fonts.sub, TEXT_DIM)
        self.rule(lay.head_h - 8)

    def bands(self) -> None:
        """A band behind each namespace group of topics, its name on top."""
        x, w = self.lay.xs["T"], self.lay.topic_w
        for g, y0, y1 in self.lay.bands:
            self.draw.rounded_rectangle(
                [S(x - 8), S(y0), S(x + w + 8), S(y1 + 6)], radius=S(6), fill=(241, 243, 245)
            )
            self.text(x - 2, y0 + 3, f"{g}/", self.fonts.small, TEXT_DIM)

    def edges(self) -> None:
        """The curves: wildcard ones underneath, then the flow, those against it on top."""
        lines = self.lay.lines
        order = sorted(range(len(lines)), key=lambda i: (not lines[i].edge.wildcard, lines[i].back, i))
        for i in order:
            ln = lines[i]
            pts = bezier(ln.start, ln.end)
            self.draw.line(
                [(S(x), S(y)) for x, y in pts], fill=_color(ln), width=round(1.6 * SS), joint="curve"
            )

    def processes(self) -> None:
        """Each process: a rounded box in its role's colours, its name, role and wildcard subscriptions."""
        lay, draw = self.lay, self.draw
        for n, box in lay.pboxes.items():
            fill, outline = ROLE_COLORS.get(lay.m.processes[n], UNKNOWN_COLORS)
            draw.rounded_rectangle(
                [S(box.x), S(box.y), S(box.x + box.w), S(box.y + box.h)],
                radius=S(min(16, box.h / 2)),
                fill=fill,
                outline=outline,
                width=SS,
            )
            plines = lay.proc_lines[n]
            th = sum(18 if k == "label" else 15 for k, _ in plines)
            yy = box.cy - th / 2
            for k, t in plines:
                font = getattr(self.fonts, k)
                self.text(box.x + box.w / 2, yy, t, font, TEXT if k == "label" else TEXT_DIM, "ma")
                yy += 18 if k == "label" else 15

    def topics(self) -> None:
        """Each topic: a box with its key and short type; an empty box saying so when there are none."""
        lay, draw, fonts = self.lay, self.draw, self.fonts
        for t in lay.m.topics:
            box = lay.tboxes[t.key]
            draw.rectangle(
                [S(box.x), S(box.y), S(box.x + box.w), S(box.y + box.h)],
                fill=TOPIC_FILL,
                outline=TOPIC_LINE,
                width=SS,
            )
            key_line, type_line = lay.topic_lines[t.key]
            if type_line:
                self.text(box.x + PAD, box.y + 5, key_line, fonts.label, TEXT)
                type_line = fit(fonts, fonts.small, type_line, box.w - 2 * PAD)
                self.text(box.x + PAD, box.y + 24, type_line, fonts.small, TEXT_DIM)
            else:
                self.text(box.x + PAD, box.cy, key_line, fonts.label, TEXT, "lm")
        if not lay.m.topics:
            box = Box(lay.xs["T"], lay.top + (lay.content_h - TOPIC_H) / 2, lay.topic_w, TOPIC_H)
            draw.rounded_rectangle(
                [S(box.x), S(box.y), S(box.x + box.w), S(box.y + box.h)],
                radius=S(6),
                outline=(173, 181, 189),
                width=SS,
            )
            self.text(box.x + box.w / 2, box.cy, "no topics", fonts.label, TEXT_DIM, "mm")

    def legend(self) -> None:
        """Under a rule: a swatch and a label per legend item, row by row."""
        lay, draw, line_w = self.lay, self.draw, round(1.6 * SS)
        ly = lay.top + lay.content_h + 16
        self.rule(ly - 6)
        for row in lay.legend_rows:
            cy = ly + 11
            for kind, what, label, x0 in row:
                if kind == "role":
                    fill, outline = ROLE_COLORS.get(what, UNKNOWN_COLORS)
                    draw.rounded_rectangle(
                        [S(x0), S(cy - 7), S(x0 + 22), S(cy + 7)],
                        radius=S(7),
                        fill=fill,
                        outline=outline,
                        width=SS,
                    )
                    tx = x0 + 28
                elif kind == "topic":
                    draw.rectangle(
                        [S(x0), S(cy - 7), S(x0 + 34), S(cy + 7)],
                        fill=TOPIC_FILL,
                        outline=TOPIC_LINE,
                        width=SS,
                    )
                    tx = x0 + 40
                else:
                    draw.line([(S(x0), S(cy)), (S(x0 + 34 - ARROW_L), S(cy))], fill=what, width=line_w)
                    self.arrow((x0 + 34, cy), 1, what)
                    tx = x0 + 40
                self.text(tx, cy, label, self.fonts.small, TEXT, "lm")
            ly += 22
