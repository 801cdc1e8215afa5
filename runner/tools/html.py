"""`scenario report RUN.mcap -o report.html`: one self-contained HTML page about a recorded run.

What it shows: the scenario (name, description, duration), the run's topics with their counts and rates,
the assertions judged again from the recording (the same judge as the live run) with a plot of each
robot's speed and each checked topic's rate over sim time, the trajectory plot, a few camera frames, and a
timeline of what the run's events did and when its assertions failed (runner.tools.timeline).
Pictures are inline (PNG as data URIs, plots as SVG), so the file can be mailed or attached to CI as is.
The scenario comes from the recording itself (`<run>/_plan`, written at the start of every run).
"""

from __future__ import annotations

import base64
import html
import io
import math
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from runner.errors import RunError
from runner.wire import msgs

STYLE = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:2em auto;max-width:1000px;
color:#222;padding:0 1em}h1{margin-bottom:.1em}.sub{color:#666;margin-top:0}table{border-collapse:collapse;
margin:.5em 0 1.5em}td,th{border-bottom:1px solid #ddd;padding:.25em .8em;text-align:left;font-size:.92em}
th{background:#f4f4f6}.pass{color:#1a7f37;font-weight:600}.fail{color:#cf222e;font-weight:600}.undecided{color:#9a6700;font-weight:600}
.badge{display:inline-block;padding:.2em .7em;border-radius:1em;color:#fff;font-weight:600}
.ok{background:#1a7f37}.ko{background:#cf222e}figure{margin:0 0 1.5em}figcaption{color:#555;font-size:.9em}
.frames img{max-width:32%;margin-right:1%}svg{background:#fcfcfd;border:1px solid #e4e4e8}
"""


def load_plan(mcap: Path) -> Any:
    from mcap.reader import make_reader

    from runner.plan import RunPlan

    with open(mcap, "rb") as f:
        for _s, channel, message in make_reader(f).iter_messages():
            if channel.topic.endswith("/_plan"):
                text = msgs.decode(message.data, "std_msgs/msg/String").data
                return RunPlan.model_validate_json(text)
    raise RunError(f"{mcap}: the recording does not carry its scenario; give it with --scenario FILE")


def _series(
    mcap: Path, keys: set[str], stamps_only: set[str] = frozenset()
) -> dict[str, list[tuple[int, Any]]]:
    """(log time, (schema, data)) of every message on `keys`; for `stamps_only` keys, (log time, None): a
    rate over a long run of camera images stays a list of numbers."""
    from mcap.reader import make_reader

    out: dict[str, list[tuple[int, Any]]] = {k: [] for k in keys | stamps_only}
    with open(mcap, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages(topics=sorted(keys | stamps_only)):
            keep = channel.topic in keys
            out[channel.topic].append(
                (message.log_time, (schema.name if schema else "", message.data) if keep else None)
            )
    return out


def image_rgb(img: Any) -> np.ndarray | None:
    """A sensor_msgs/Image as an RGB array to look at: colour as it is, mono and depth as grey (depth
    scaled to its own range, near bright); None for an encoding we cannot show."""
    h, w, enc = img.height, img.width, img.encoding
    if not h or not w:
        return None
    raw = np.frombuffer(bytes(img.data), np.uint8)
    try:
        if enc in ("rgb8", "bgr8", "rgba8", "bgra8"):
            ch = 4 if enc.endswith("a8") else 3
            arr = raw[: h * img.step].reshape(h, img.step)[:, : w * ch].reshape(h, w, ch)[..., :3]
            return np.ascontiguousarray(arr if enc.startswith("rgb") else arr[..., ::-1])
        if enc == "mono8":
            g = raw[: h * img.step].reshape(h, img.step)[:, :w]
            return np.repeat(g[..., None], 3, axis=2)
        if enc in ("mono16", "16UC1", "32FC1"):
            dt = np.dtype("<f4" if enc == "32FC1" else "<u2").newbyteorder(">" if img.is_bigendian else "<")
            rows = raw[: h * img.step].reshape(h, img.step)[:, : w * dt.itemsize]
            v = np.ascontiguousarray(rows).view(dt).reshape(h, w).astype(np.float64)
            ok = np.isfinite(v) & (v > 0)
            if not ok.any():
                return np.zeros((h, w, 3), np.uint8)
            lo, hi = v[ok].min(), v[ok].max()
            scaled = (v - lo) / max(hi - lo, 1e-9)
            if enc != "mono16":
                scaled = 1.0 - scaled  # depth: near is bright
            g = np.where(ok, 40 + 215 * scaled, 0).astype(np.uint8)
            return np.repeat(g[..., None], 3, axis=2)
    except ValueError:  # data shorter than its header says
        return None
    return None


def _camera_frames(mcap: Path, summary: dict[str, Any], n: int = 3) -> tuple[str, list[Any]]:
    """Up to n frames, evenly spread over the run, of the first camera that can be shown (colour cameras
    before depth ones); read one message at a time, so a long run's images never sit in memory."""
    from mcap.reader import make_reader

    from runner.wire.transport import hidden_key

    cams = [
        t for t in summary["topics"] if t["type"] == "sensor_msgs/msg/Image" and not hidden_key(t["topic"])
    ]
    cams.sort(key=lambda t: ("depth" in t["topic"], t["topic"]))
    for t in cams:
        count = int(t["count"])
        want = set(np.linspace(0, count - 1, min(n, count)).astype(int).tolist()) if count else set()
        frames = []
        with open(mcap, "rb") as f:
            for i, (_s, _c, message) in enumerate(make_reader(f).iter_messages(topics=[t["topic"]])):
                if i not in want:
                    continue
                rgb = image_rgb(msgs.decode(message.data, "sensor_msgs/msg/Image"))
                if rgb is None:
                    break
                frames.append(rgb)
                if len(frames) == len(want):
                    break
        if frames:
            return t["topic"], frames
    return "", []


Line = tuple[str, list[float], list[float], str]  # label, sim times (s), values, colour (#rrggbb)
Bound = tuple[float, str]  # a horizontal line: value, label


def svg_chart(
    title: str,
    unit: str,
    lines: list[Line],
    bounds: list[Bound] | None = None,
    marks: list[tuple[float, str]] | None = None,
) -> str:
    """A small line chart: (label, sim times s, values, colour) per line; the assertions' bounds as dashed
    horizontal lines, each labelled; `marks` (sim time, what: the events' firings) as dotted vertical
    lines, named in their tooltips."""
    w, h, pad, left = 640, 220, 36, 48
    bounds = [(v, label) for v, label in bounds or [] if v is not None and math.isfinite(v)]
    xs = [x for _l, t, _v, _c in lines for x in t] or [0.0, 1.0]
    ys = [y for _l, _t, v, _c in lines for y in v if math.isfinite(y)] + [v for v, _ in bounds]
    ys = ys or [0.0, 1.0]
    x0, x1 = min(xs), max(max(xs), min(xs) + 1e-9)
    y0, y1 = min(0.0, min(ys)), max(ys) * 1.12 or 1.0

    def px(x: float, y: float) -> str:
        u = left + (x - x0) / (x1 - x0) * (w - left - pad)
        v = h - pad + (y0 - y) / (y1 - y0) * (h - 2 * pad)
        return f"{u:.1f},{v:.1f}"

    def ypx(y: float) -> float:
        return h - pad + (y0 - y) / (y1 - y0) * (h - 2 * pad)

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" role="img">']
    parts.append(f'<text x="{left}" y="18" font-size="13" font-weight="600">{html.escape(title)}</text>')
    parts.append(f'<line x1="{left}" y1="{h - pad}" x2="{w - pad}" y2="{h - pad}" stroke="#999"/>')
    parts.append(f'<line x1="{left}" y1="{pad}" x2="{left}" y2="{h - pad}" stroke="#999"/>')
    parts.append(f'<text x="{left - 4}" y="{pad + 4}" font-size="10" text-anchor="end">{y1:.3g}</text>')
    parts.append(f'<text x="{left - 4}" y="{h - pad}" font-size="10" text-anchor="end">{y0:.3g}</text>')
    parts.append(f'<text x="{left}" y="{h - pad + 14}" font-size="10">{x0:.3g} s</text>')
    parts.append(f'<text x="{w - pad}" y="{h - pad + 14}" font-size="10" text-anchor="end">{x1:.3g} s</text>')
    parts.append(f'<text x="{left}" y="{h - 6}" font-size="10">{html.escape(unit)}</text>')
    for t, what in marks or []:
        if x0 <= t <= x1:
            a, b = px(t, y0), px(t, y1)
            parts.append(
                f'<polyline class="event-mark" points="{a} {b}" stroke="#2f6fdf" stroke-width="1" '
                f'stroke-dasharray="2,3" fill="none"><title>{html.escape(what)}</title></polyline>'
            )
    top = max((v for v, _ in bounds), default=None)
    for value, label in bounds:
        a, b = px(x0, value), px(x1, value)
        # the highest bound's label above its line, the others below theirs: a min and a max close
        # together (a rate's 9.5..10.5 Hz) keep their labels apart
        dy = -4 if value == top else 12
        parts.append(
            f'<polyline class="bound" points="{a} {b}" stroke="#555" stroke-width="1.2" '
            'stroke-dasharray="6,4" fill="none"/>'
        )
        parts.append(
            f'<text x="{left + 6}" y="{ypx(value) + dy:.1f}" font-size="10" fill="#444">'
            f"{html.escape(label)}</text>"
        )
    for i, (label, t, v, colour) in enumerate(lines):
        pts = " ".join(px(a, b) for a, b in zip(t, v, strict=True) if math.isfinite(b))
        parts.append(f'<polyline points="{pts}" stroke="{colour}" stroke-width="1.8" fill="none"/>')
        parts.append(
            f'<text x="{w - pad - 4}" y="{pad + 14 * (i + 1)}" font-size="11" text-anchor="end" '
            f'fill="{colour}">{html.escape(label)}</text>'
        )
    parts.append("</svg>")
    return "".join(parts)


def _shown_path(file: str | None) -> str:
    """The scenario's file as the reader would type it: relative to the current folder when below it."""
    if not file:
        return ""
    try:
        return str(Path(file).resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return file


def _png_uri(path_or_rgb: Path | np.ndarray) -> str:
    if isinstance(path_or_rgb, Path):
        data = path_or_rgb.read_bytes()
    else:
        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(path_or_rgb).save(buf, format="PNG")
        data = buf.getvalue()
    return "data:image/png;base64," + base64.b64encode(data).decode()


def write_report(mcap: Path, out: Path, plan: Any = None) -> dict[str, Any]:
    from runner.record import read_summary
    from runner.tools.plot import trajectory_plot
    from runner.tools.report import firing_line, rejudge

    plan = plan or load_plan(mcap)
    summary = read_summary(mcap)
    # (with several worlds, each world's plan holds its own assertions, their topics inside the world)
    keyed = [(a, part.name) for part in plan.parts() for a in part.assertions]
    judged = rejudge(plan, mcap) if keyed or any(part.events for part in plan.parts()) else None
    results, events = (judged.results, judged.events) if judged else ([], [])
    charts = _charts(plan, mcap, keyed, [(f["t"], firing_line(f)) for f in events])
    camera, frames = _camera_frames(mcap, summary)
    with tempfile.TemporaryDirectory() as tmp:
        plot = trajectory_plot(plan, mcap, results, Path(tmp) / "trajectory.png")
        trajectory = _png_uri(plot) if plot is not None and plot.exists() else None
    span = (summary["end_ns"] - summary["start_ns"]) / 1e9
    h = html.escape
    page = [
        f'<!doctype html><html><head><meta charset="utf-8"><title>{h(plan.name)}: run report</title>',
        f"<style>{STYLE}</style></head><body>",
        f'<h1>{h(plan.name)}</h1><p class="sub">{h(_shown_path(plan.scenario_file))}</p>',
        *_variant_lines(plan),
        f"<p>{_verdict(results)} &nbsp; {span:.2f} s sim, {summary['messages']} messages recorded"
        + (" (the recording was cut)" if summary.get("cut") else "")
        + "</p>",
    ]
    if trajectory:
        page.append(
            f'<figure><img alt="trajectory plot" src="{trajectory}" style="max-width:100%">'
            "<figcaption>Paths from above, with the assertions' regions and goals</figcaption></figure>"
        )
    if results:
        page.append(
            "<h2>Assertions</h2><table><tr><th>assertion</th><th>type</th><th>result</th>"
            f"<th>at (sim s)</th><th>value</th><th>bound</th></tr>{''.join(_result_row(r) for r in results)}"
            "</table>"
        )
    page += _timeline(events, results, span)
    if charts:
        page.append("<h2>Signals</h2>" + "".join(f"<figure>{c}</figure>" for c in charts))
    if frames:
        page.append(
            f'<h2>Camera</h2><p class="sub">{h(camera)}</p><div class="frames">'
            + "".join(f'<img alt="camera frame" src="{_png_uri(f)}">' for f in frames)
            + "</div>"
        )
    page.append(
        "<h2>Topics</h2><table><tr><th>topic</th><th>type</th><th>messages</th><th>sim Hz</th></tr>"
        f"{_topic_rows(summary, span)}</table>"
    )
    page.append("</body></html>")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(page), encoding="utf-8")
    return {
        "assertions": len(results),
        "passed": sum(r.passed for r in results),
        "charts": len(charts),
        "frames": len(frames),
        "trajectory": trajectory is not None,
        "events": len(events),
    }


def _timeline(events: list[dict[str, Any]], results: list[Any], span: float) -> list[str]:
    """What the events did and when the assertions failed, over sim time, then the events' table; nothing
    for a run without events or failures."""
    from runner.tools.timeline import events_table, timeline_svg

    if not events and all(r.passed for r in results):
        return []
    return [
        "<h2>Timeline</h2>",
        f"<figure>{timeline_svg(events, results, span)}</figure>",
        *(["<h3>Events</h3>", events_table(events)] if events else []),
    ]


def _variant_lines(plan: Any) -> list[str]:
    """The matrix variant the run was (its label) and the values it drew at random, if any."""
    from runner.scenario.draws import shown

    lines = [f'<p class="sub">variant: {html.escape(plan.variant)}</p>'] if plan.variant else []
    if plan.drawn:
        lines.append(f'<p class="sub">drawn: {html.escape(shown(plan.drawn))}</p>')
    return lines


def _charts(
    plan: Any, mcap: Path, keyed: list[tuple[dict[str, Any], str]], marks: list[tuple[float, str]]
) -> list[str]:
    """The signals: each robot's speed (ground truth), its distance travelled and tilt where an assertion
    bounds them, and each checked topic's rate per sim second; each with the bounds its assertions set,
    and the events' firings marked (`marks`)."""
    from runner.checks.judge import truth_key
    from runner.tools.pictures import run_colours

    truth = {r.name: truth_key(p.name, r.namespace) for p in plan.parts() for r in p.robots}
    rate_keys = sorted({f"{w}/{a['topic'].strip('/')}" for a, w in keyed if a.get("type") == "topic_rate"})
    series = _series(mcap, set(truth.values()), stamps_only=set(rate_keys) - set(truth.values()))
    colours = run_colours(plan)  # each robot's colour, as in the trajectory plot and `scenario render`
    speed, travelled, tilt = _robot_signals(series, truth, colours)
    kinds = {a.get("type") for a, _ in keyed}
    charts = []
    if speed:
        charts.append(
            svg_chart("Speed of each robot (ground truth)", "m/s", speed, _bounds(keyed, "max_speed"), marks)
        )
    if travelled and "distance_traveled" in kinds:
        charts.append(
            svg_chart("Distance travelled", "m", travelled, _bounds(keyed, "distance_traveled"), marks)
        )
    if tilt and "max_tilt" in kinds:
        charts.append(svg_chart("Tilt from upright", "rad", tilt, _bounds(keyed, "max_tilt"), marks))
    return charts + _rate_charts(plan, keyed, rate_keys, series, colours)


def _robot_signals(
    series: dict[str, list[tuple[int, Any]]], truth: dict[str, str], colours: dict[str, Any]
) -> tuple[list[Line], list[Line], list[Line]]:
    """Each robot's speed, distance travelled and tilt over sim time, from its ground truth."""
    from runner.tools.pictures import hex_colour

    speed: list[Line] = []
    travelled: list[Line] = []
    tilt: list[Line] = []
    for name, key in truth.items():
        t, v, dist, tilts = [], [], [], []
        last = None
        for stamp, (_s, data) in series.get(key, []):
            odom = msgs.decode(data, "nav_msgs/msg/Odometry")
            lin, p, q = odom.twist.twist.linear, odom.pose.pose.position, odom.pose.pose.orientation
            t.append(stamp / 1e9)
            v.append(math.hypot(lin.x, lin.y))
            here = (p.x, p.y)
            dist.append((dist[-1] if dist else 0.0) + (math.dist(here, last) if last else 0.0))
            last = here
            # the angle between the body's z axis and the world's
            tilts.append(math.acos(max(-1.0, min(1.0, 1 - 2 * (q.x * q.x + q.y * q.y)))))
        if t:
            colour = hex_colour(colours[name])
            speed.append((name, t, v, colour))
            travelled.append((name, t, dist, colour))
            tilt.append((name, t, tilts, colour))
    return speed, travelled, tilt


def _rate_charts(
    plan: Any,
    keyed: list[tuple[dict[str, Any], str]],
    rate_keys: list[str],
    series: dict[str, list[tuple[int, Any]]],
    colours: dict[str, Any],
) -> list[str]:
    """A chart per topic a `topic_rate` assertion checks: messages per whole sim second, in the colour of
    the robot the topic belongs to."""
    from runner.tools.pictures import NEUTRAL, hex_colour

    owners = {f"{p.name}/{r.namespace}/": hex_colour(colours[r.name]) for p in plan.parts() for r in p.robots}
    charts = []
    for key in rate_keys:
        topic = key.removeprefix(f"{plan.name}/")
        stamps = [s / 1e9 for s, _ in series.get(key, [])]
        if stamps:
            whole = max(1, int(stamps[-1]))  # whole sim seconds (a last, partial second would dip)
            counts = np.histogram(stamps, bins=np.arange(0, whole + 1))[0]
            secs = np.arange(0, whole) + 0.5
            colour = next((c for prefix, c in owners.items() if key.startswith(prefix)), hex_colour(NEUTRAL))
            charts.append(
                svg_chart(
                    f"Rate of {topic}",
                    "messages per sim second (Hz)",
                    [(topic, list(secs), list(counts.astype(float)), colour)],
                    _bounds(keyed, "topic_rate", key),
                )
            )
    return charts


def _bounds(keyed: list[tuple[dict[str, Any], str]], kind: str, key: str | None = None) -> list[Bound]:
    """The bounds of the assertions of this kind (and topic key), to draw as dashed lines."""
    out: list[Bound] = []
    for a, w in keyed:
        if a.get("type") != kind or (key is not None and f"{w}/{a['topic'].strip('/')}" != key):
            continue
        for side in ("min", "max"):
            if isinstance(a.get(side), int | float):
                out.append((float(a[side]), f"{side} {a[side]:g} ({a.get('name', kind)})"))
    return out


_LABEL = {"pass": "pass", "fail": "FAIL", "undecided": "not decided"}


def _result_row(r: Any) -> str:
    h = html.escape
    # why it was not decided, or what failed (when the value does not say it already: a collision's does)
    why = f"<br><small>{h(r.message)}</small>" if not r.passed and r.message != r.value else ""
    at = "" if r.t is None else f"{r.t:.2f}"
    return (
        f'<tr><td>{h(r.name)}</td><td>{h(r.type)}</td><td class="{r.status}">{_LABEL[r.status]}</td>'
        f"<td>{at}</td><td>{h(str(r.value or ''))}</td><td>{h(str(r.bound or ''))}{why}</td></tr>"
    )


def _verdict(results: list[Any]) -> str:
    """The badge: how many assertions pass (and how many were not decided)."""
    if not results:
        return '<span class="badge ok">no assertions</span>'
    passed = sum(r.passed for r in results)
    undecided = sum(r.undecided for r in results)
    return (
        f'<span class="badge {"ok" if passed == len(results) else "ko"}">'
        f"{passed} of {len(results)} assertions pass"
        f"{f', {undecided} not decided' if undecided else ''}</span>"
    )


def _topic_rows(summary: dict[str, Any], span: float) -> str:
    """A table row per recorded topic: type, count, rate per sim second; the run's helper topics
    (`_truth`...) left out, as `scenario info` leaves them out."""
    from runner.wire.transport import hidden_key

    h = html.escape
    return "".join(
        f"<tr><td>{h(t['topic'])}</td><td>{h(t['type'])}</td><td>{t['count']}</td>"
        f"<td>{(t['count'] - 1) / span:.1f}</td></tr>"
        if span > 0 and t["count"] > 1
        else f"<tr><td>{h(t['topic'])}</td><td>{h(t['type'])}</td><td>{t['count']}</td><td>-</td></tr>"
        for t in summary["topics"]
        if not hidden_key(t["topic"])
    )
