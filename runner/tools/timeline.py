"""The run's story over sim time, for the HTML report: what its events did and when (one lane per event, a
marker per firing, its why beside it), and when its assertions failed or were left undecided; and the
events as a table. Drawn as inline SVG, like the report's other plots."""

from __future__ import annotations

import html
import math
from typing import Any

from runner.tools.report import event_rows, failure_text, firing_line

LANES = 12  # events drawn in lanes of their own, at most; the rest share one
FIRING, PASSED, FAILED, UNDECIDED = "#2f6fdf", "#1a7f37", "#cf222e", "#9a6700"


def _ticks(x1: float) -> list[float]:
    """Round sim times along an axis from 0 to x1: about five of them."""
    raw = x1 / 5
    step = 10 ** math.floor(math.log10(raw)) if raw > 0 else 1.0
    for m in (1, 2, 5, 10):
        if raw <= m * step:
            step *= m
            break
    return [i * step for i in range(int(x1 / step + 1e-9) + 1)]


def _short(text: str, n: int) -> str:
    return text if len(text) <= n else text[: n - 1] + "…"


def timeline_svg(events: list[dict[str, Any]], results: list[Any], end_s: float) -> str:
    """One lane per event (in the order they first fired), a marker per firing (an `end:` in its verdict's
    colour), each with its full line as a tooltip and, for an event that fired once, its why beside it;
    then a lane for each assertion that failed or was not decided, a marker at its time with its message
    beside it (a collision's place); the run's end dashed."""
    names = list(dict.fromkeys(f["event"] for f in events))
    lanes = names[:LANES] + (["other events"] if len(names) > LANES else [])
    verdicts = [r for r in results if not r.passed and r.t is not None and r.type != "event"][:LANES]
    rows = lanes + [r.name for r in verdicts]
    w, left, pad, top, lane = 900, 170, 30, 30, 26
    h = top + lane * len(rows) + 34
    times = [f["t"] for f in events] + [r.t for r in verdicts] + [end_s]
    x1 = max(max(times), 1e-3)
    h_ = html.escape

    def px(t: float) -> float:
        return left + t / x1 * (w - left - pad)

    def ypx(row: int) -> float:
        return top + lane * row + lane / 2

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" role="img" class="timeline">']
    title = "What happened, over sim time"
    parts.append(f'<text x="{left}" y="18" font-size="13" font-weight="600">{title}</text>')
    axis = top + lane * len(rows) + 4
    parts.append(f'<line x1="{left}" y1="{axis}" x2="{w - pad}" y2="{axis}" stroke="#999"/>')
    for t in _ticks(x1):
        parts.append(f'<line x1="{px(t):.1f}" y1="{axis}" x2="{px(t):.1f}" y2="{axis + 4}" stroke="#999"/>')
        parts.append(
            f'<text x="{px(t):.1f}" y="{axis + 16}" font-size="10" text-anchor="middle">{t:g} s</text>'
        )
    end = px(end_s)
    parts.append(
        f'<line class="run-end" x1="{end:.1f}" y1="{top - 4}" x2="{end:.1f}" y2="{axis}" stroke="#777" '
        'stroke-dasharray="4,3"><title>the run ended at t='
        f"{end_s:.3f} s</title></line>"
    )
    for i, name in enumerate(rows):
        y = ypx(i)
        parts.append(f'<line x1="{left}" y1="{y:.1f}" x2="{w - pad}" y2="{y:.1f}" stroke="#eee"/>')
        parts.append(
            f'<text x="{left - 8}" y="{y + 4:.1f}" font-size="11" text-anchor="end">'
            f"{h_(_short(name, 26))}<title>{h_(name)}</title></text>"
        )
    counts = {n: sum(1 for f in events if f["event"] == n) for n in names}
    for f in events:
        row = lanes.index(f["event"]) if f["event"] in lanes else len(lanes) - 1
        end_of = f.get("end")
        colour = FIRING if not end_of else (PASSED if end_of.get("result") == "pass" else FAILED)
        x, y = px(f["t"]), ypx(row)
        parts.append(
            f'<circle class="firing" cx="{x:.1f}" cy="{y:.1f}" r="5" fill="{colour}">'
            f"<title>{h_(firing_line(f))}</title></circle>"
        )
        if counts[f["event"]] == 1 and f["event"] in lanes[:LANES]:
            text = f"t={f['t']:.2f} s: {f['why']}" + (f" -> {'; '.join(f['did'])}" if f["did"] else "")
            parts.append(_label(x, y, text, x > (left + w) / 2, colour))
    for i, r in enumerate(verdicts):
        x, y = px(r.t), ypx(len(lanes) + i)
        colour = UNDECIDED if r.undecided else FAILED
        parts.append(
            f'<path class="verdict" d="M{x:.1f},{y - 6:.1f} l6,6 l-6,6 l-6,-6 z" fill="{colour}">'
            f"<title>{h_(failure_text(r))}</title></path>"
        )
        said = "not decided" if r.undecided else r.message
        parts.append(_label(x, y, f"t={r.t:.2f} s: {said}", x > (left + w) / 2, colour))
    parts.append("</svg>")
    return "".join(parts)


def _label(x: float, y: float, text: str, before: bool, colour: str) -> str:
    """A marker's label, on its right (or its left, past the middle of the plot)."""
    dx, anchor = (-9, "end") if before else (9, "start")
    return (
        f'<text x="{x + dx:.1f}" y="{y + 4:.1f}" font-size="10" text-anchor="{anchor}" fill="{colour}">'
        f"{html.escape(_short(text, 90))}</text>"
    )


def events_table(events: list[dict[str, Any]]) -> str:
    """The firings as a table: sim time, event, why, what it did (an event that fired again and again
    folded after its first firings, as on the terminal)."""
    h = html.escape
    rows, left = event_rows(events)
    body = "".join(
        f"<tr><td>{h(t)}</td><td>{h(name)}</td><td>{h(why)}</td><td>{h(did)}</td></tr>"
        for t, name, why, did in rows
    )
    more = (
        f'<p class="sub">and {left} more firing(s), all on the run\'s <code>_events</code></p>'
        if left
        else ""
    )
    return (
        "<table><tr><th>t (sim s)</th><th>event</th><th>why</th><th>what it did</th></tr>"
        f"{body}</table>{more}"
    )
