"""Judging a recording offline, and reporting results: a table, JSON, JUnit XML."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from runner.checks.judge import FAIL, PASS, UNDECIDED, Judge, Result, ended_early, events_key, judged_types


def judge_for(plan: Any) -> Judge | None:
    from runner.checks import specs_from_plan

    parts = plan.worlds or [plan]  # several worlds: one judge over all (their keys are distinct)
    assertions = [a for part in parts for a in part.assertions]
    events = [events_key(part.name) for part in parts if part.events]
    if not assertions and not events:
        return None
    return Judge(specs_from_plan(assertions), [k for part in parts for k in part.assertion_keys], events)


def judge_recording(plan: Any, mcap: Path) -> tuple[list[Result], int, str | None]:
    """Re-judge a recording with the scenario's assertions (the same Judge the live run used). Returns the
    results, the recording's last sim time, and why the run ended before its planned end (None: it did
    not). How it ended is read from the recording's `scenario` metadata (written by the run); a recording
    without it (cut, or older) counts as complete only if it reaches the planned duration."""
    from mcap.reader import make_reader

    from runner.wire import msgs

    judge = judge_for(plan)
    if judge is None:
        return [], 0, None
    types = judged_types(plan)
    end_ns = 0
    meta: dict[str, str] = {}
    with open(mcap, "rb") as f:
        reader = make_reader(f)
        wanted = judge.keys
        for _schema, channel, message in reader.iter_messages(log_time_order=True):
            end_ns = max(end_ns, message.log_time)
            if channel.topic in wanted:
                judge.feed(channel.topic, message.log_time, msgs.decode(message.data, types[channel.topic]))
        try:
            meta = next((dict(m.metadata) for m in reader.iter_metadata() if m.name == "scenario"), {})
        except Exception:  # no summary (a cut file): no metadata to go by
            meta = {}
    at = f" at t={end_ns / 1e9:.3f} s"
    ended = meta.get("ended")
    if "stopped" in meta:  # the recording itself stopped early (a full disk, a killed runner)
        why: str | None = f"the recording stopped early{at} ({meta['stopped']})"
    elif ended is not None:
        why = ended_early(ended, end_ns)
    elif end_ns + 20_000_000 >= plan.duration_ns:  # (20 ms: the last clock before the planned end)
        why = None
    else:
        why = f"the recording ends{at}, before the run's planned end ({plan.duration_ns / 1e9:g} s)"
    return judge.finish(end_ns, complete=why is None, why=why or ""), end_ns, why


def _now() -> str:
    """A JUnit timestamp: local time, ISO 8601 to the second, no zone (as Ant and Surefire write it)."""
    import datetime

    return datetime.datetime.now().replace(microsecond=0).isoformat()


@dataclass
class Suite:
    """The results of one scenario run (a JUnit testsuite)."""

    name: str
    results: list[Result] = field(default_factory=list)
    error: str | None = None  # the run itself failed (not an assertion)
    time_s: float = 0.0
    mcap: str | None = None
    sim_s: float = 0.0  # the sim time the run reached (the time of verdicts held to its end)
    allow_undecided: bool = False  # an undecided assertion does not fail the suite (--allow-undecided)
    timestamp: str = field(default_factory=_now)  # when it started
    interrupted: str | None = None  # "interrupted at t=...": why the run ended before its planned end
    label: str = ""  # the matrix variant's label (its values and drawn values), "" without a matrix

    @property
    def passed(self) -> bool:
        return self.error is None and all(
            r.passed or (r.undecided and self.allow_undecided) for r in self.results
        )

    @property
    def undecided(self) -> int:
        return sum(1 for r in self.results if r.undecided)

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "passed": self.passed,
            "error": self.error,
            "time_s": self.time_s,
            "sim_s": self.sim_s,
            "timestamp": self.timestamp,
            "interrupted": self.interrupted,
            "allow_undecided": self.allow_undecided,
            "mcap": self.mcap,
            "label": self.label,
            "counts": {
                status: sum(1 for r in self.results if r.status == status)
                for status in (PASS, FAIL, UNDECIDED)
            },
            "results": [r.to_json() for r in self.results],
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Suite:
        results = [
            Result(
                r["name"],
                r["type"],
                r.get("status") or (PASS if r["passed"] else FAIL),
                None if r["t"] is None else round(r["t"] * 1e9),
                r["value"],
                r["bound"],
                r["message"],
            )
            for r in data.get("results", [])
        ]
        return cls(
            data["name"],
            results,
            data.get("error"),
            data.get("time_s", 0.0),
            data.get("mcap"),
            sim_s=data.get("sim_s", 0.0),
            allow_undecided=data.get("allow_undecided", False),
            timestamp=data.get("timestamp") or _now(),
            interrupted=data.get("interrupted"),
            label=data.get("label", ""),
        )


def failure_text(r: Result) -> str:
    at = f" at t={r.t:.3f} s" if r.t is not None else ""
    if r.undecided:
        return f"{r.name} ({r.type}) not decided{at}: {r.message}; value {r.value}; bound {r.bound}"
    return f"{r.name} ({r.type}) failed{at}: {r.message}; value {r.value}; bound {r.bound}"


def write_junit(path: Path, suites: list[Suite]) -> None:
    """JUnit XML in the common shape (Jenkins' junit-10.xsd, which Ant, Surefire, GitLab and GitHub
    readers take): testsuites / testsuite / testcase (/ failure | error | skipped).

    A testcase's `time` is the sim time at which its verdict was reached (the run's end for one held
    to the end). An undecided assertion is a `<failure type="undecided">` whose message says why, or,
    with --allow-undecided, `<skipped>` with that message."""
    import socket

    root = ET.Element("testsuites", name="scenario")
    total = failures = errors = 0
    wall = 0.0
    for s in suites:
        cases = s.results or []
        skipped = sum(1 for r in cases if r.undecided) if s.allow_undecided else 0
        suite = ET.SubElement(
            root,
            "testsuite",
            name=s.name,
            tests=str(len(cases) + (1 if s.error else 0)),
            failures=str(sum(1 for r in cases if not r.passed) - skipped),
            errors="1" if s.error else "0",
            skipped=str(skipped),
            time=f"{s.time_s:.3f}",
            timestamp=s.timestamp,
            hostname=socket.gethostname() or "localhost",
        )
        wall += s.time_s
        if s.error:
            case = ET.SubElement(suite, "testcase", classname=s.name, name="run", time=f"{s.sim_s:.3f}")
            ET.SubElement(
                case, "error", message=s.error.splitlines()[0] if s.error else "", type="RunError"
            ).text = s.error
            errors += 1
            total += 1
        for r in cases:
            t = r.t if r.t is not None else s.sim_s
            case = ET.SubElement(suite, "testcase", classname=s.name, name=r.name, time=f"{max(t, 0.0):.3f}")
            total += 1
            if r.passed:
                continue
            text = failure_text(r)
            if r.undecided and s.allow_undecided:
                ET.SubElement(case, "skipped", message=f"not decided: {r.message}").text = text
                continue
            failures += 1
            if r.undecided:
                ET.SubElement(
                    case, "failure", message=f"not decided: {r.message}", type="undecided"
                ).text = text
            else:
                ET.SubElement(case, "failure", message=text, type=r.type).text = text
    root.set("tests", str(total))
    root.set("failures", str(failures))
    root.set("errors", str(errors))
    root.set("time", f"{wall:.3f}")
    path.parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
