"""The summary page of a suite (`scenario test --ray`: `summary.html` at the top of the artifacts): the pass
rate overall and per matrix parameter value, the slowest runs, each failure with its error or failed
assertions and links to its report and recording, and every run with the node it ran on and its attempts.
One self-contained page; links are relative to it (each variant's folder lies beside it)."""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from typing import Any

from runner.tools.report import Suite, failure_text

SLOWEST = 10  # rows of the slowest runs

_STYLE = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:2em auto;
max-width:1100px;color:#222;padding:0 1em}table{border-collapse:collapse;margin:.5em 0 1.5em}
td,th{border-bottom:1px solid #ddd;padding:.25em .8em;text-align:left;font-size:.92em}th{background:#f4f4f6}
.pass{color:#1a7f37;font-weight:600}.fail{color:#cf222e;font-weight:600}.badge{display:inline-block;
padding:.2em .7em;border-radius:1em;color:#fff;font-weight:600}.ok{background:#1a7f37}.ko{background:#cf222e}
pre{white-space:pre-wrap;margin:.2em 0}
"""


@dataclass
class Row:
    """A run as the page shows it: its suite, its matrix values, the node it ran on, its attempts, and its
    files ({name: link relative to the page, or a URL})."""

    suite: Suite
    values: dict[str, str] = field(default_factory=dict)
    node: str = ""
    attempts: int = 0
    links: dict[str, str] = field(default_factory=dict)
    wall_s: float = 0.0  # the run's process from start to end (the suite's `time_s`: its run alone)


def summary_html(title: str, rows: list[Row], wall_s: float, interrupted: bool = False) -> str:
    passed = sum(1 for r in rows if r.suite.passed)
    rate = passed / len(rows) if rows else 0.0
    badge = "ok" if rows and passed == len(rows) and not interrupted else "ko"
    head = (
        f"<h1>{_e(title)}</h1><p><span class='badge {badge}'>{passed} of {len(rows)} passed "
        f"({rate:.0%})</span> in {wall_s:.1f} s"
        + (" &mdash; <b>interrupted</b> (Ctrl-C): runs not finished are errors" if interrupted else "")
        + "</p>"
    )
    parts = [head, _by_value(rows), _slowest(rows), _failures(rows), _all(rows)]
    body = "\n".join(p for p in parts if p)
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>{_e(title)}</title>"
        f"<style>{_STYLE}</style></head><body>{body}</body></html>\n"
    )


def _by_value(rows: list[Row]) -> str:
    """The pass rate for each value of each matrix parameter."""
    table: dict[tuple[str, str], list[bool]] = {}
    for r in rows:
        for key, value in r.values.items():
            table.setdefault((key, value), []).append(r.suite.passed)
    if not table:
        return ""
    lines = [
        f"<tr><td>{_e(k)}</td><td>{_e(v)}</td><td>{sum(ok)} / {len(ok)}</td>"
        f"<td>{sum(ok) / len(ok):.0%}</td></tr>"
        for (k, v), ok in sorted(table.items())
    ]
    return (
        "<h2>Pass rate by parameter value</h2><table><tr><th>parameter</th><th>value</th><th>passed</th>"
        "<th>rate</th></tr>" + "".join(lines) + "</table>"
    )


def _slowest(rows: list[Row]) -> str:
    slow = sorted(rows, key=lambda r: -r.wall_s)[:SLOWEST]
    lines = [
        f"<tr><td>{_name(r)}</td><td>{r.wall_s:.2f}</td><td>{r.suite.time_s:.2f}</td><td>{_e(r.node)}</td></tr>"
        for r in slow
    ]
    return (
        "<h2>Slowest runs</h2><table><tr><th>run</th><th>wall time (s)</th><th>of it, running (s)</th>"
        "<th>node</th></tr>" + "".join(lines) + "</table>"
    )


def _failures(rows: list[Row]) -> str:
    failed = [r for r in rows if not r.suite.passed]
    if not failed:
        return ""
    items = []
    for r in failed:
        why = [r.suite.error] if r.suite.error else []
        why += [failure_text(x) for x in r.suite.results if not x.passed]
        items.append(f"<li>{_name(r)} {_files(r)}<pre>{_e(chr(10).join(w for w in why if w))}</pre></li>")
    return f"<h2>Failures ({len(failed)})</h2><ul>" + "".join(items) + "</ul>"


def _all(rows: list[Row]) -> str:
    lines = []
    for r in rows:
        s = r.suite
        verdict = (
            "<span class='pass'>pass</span>"
            if s.passed
            else ("<span class='fail'>ERROR</span>" if s.error else "<span class='fail'>FAIL</span>")
        )
        ok = sum(1 for x in s.results if x.passed)
        lines.append(
            f"<tr><td>{_name(r)}</td><td>{verdict}</td><td>{ok} / {len(s.results)}</td>"
            f"<td>{r.wall_s:.2f}</td><td>{_e(r.node)}</td><td>{r.attempts or ''}</td>"
            f"<td>{_files(r)}</td></tr>"
        )
    return (
        f"<h2>All runs ({len(rows)})</h2><table><tr><th>run</th><th>result</th><th>assertions passed</th>"
        "<th>wall time (s)</th><th>node</th><th>attempts</th><th>files</th></tr>"
        + "".join(lines)
        + "</table>"
    )


def _name(r: Row) -> str:
    link = next((v for k, v in r.links.items() if k.endswith(".html")), None)
    text = _e(r.suite.name)
    return f"<a href='{_e(link)}'>{text}</a>" if link else text


def _files(r: Row) -> str:
    order = {".html": 0, ".mcap": 1, ".png": 2}
    names = sorted(r.links, key=lambda n: (order.get(n[n.rfind(".") :], 3), n))
    labels = {".html": "report", ".mcap": "recording", ".png": "plot"}
    return " ".join(f"<a href='{_e(r.links[n])}'>{labels.get(n[n.rfind('.') :], _e(n))}</a>" for n in names)


def _e(text: Any) -> str:
    return html.escape(str(text), quote=True)
