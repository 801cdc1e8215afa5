"""Judging a recording offline, and reporting results: a table, JSON, JUnit XML."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from runner.checks.judge import Judge, Result, judged_types


def judge_for(plan: Any) -> Judge | None:
    from runner.checks import specs_from_plan

    parts = plan.worlds or [plan]  # several worlds: one judge over all (their keys are distinct)
    assertions = [a for part in parts for a in part.assertions]
    if not assertions:
        return None
    return Judge(specs_from_plan(assertions), [k for part in parts for k in part.assertion_keys])


def judge_recording(plan: Any, mcap: Path) -> tuple[list[Result], int]:
    """Re-judge a recording with the scenario's assertions (the same Judge the live run used). Returns the
    results and the recording's last sim time."""
    from mcap.reader import make_reader

    from runner import msgs

    judge = judge_for(plan)
    if judge is None:
        return [], 0
    types = judged_types(plan)
    end_ns = 0
    with open(mcap, "rb") as f:
        reader = make_reader(f)
        wanted = judge.keys
        for _schema, channel, message in reader.iter_messages(log_time_order=True):
            end_ns = max(end_ns, message.log_time)
            if channel.topic in wanted:
                judge.feed(channel.topic, message.log_time, msgs.decode(message.data, types[channel.topic]))
    return judge.finish(end_ns), end_ns


@dataclass
class Suite:
    """The results of one scenario run (a JUnit testsuite)."""

    name: str
    results: list[Result] = field(default_factory=list)
    error: str | None = None  # the run itself failed (not an assertion)
    time_s: float = 0.0
    mcap: str | None = None

    @property
    def passed(self) -> bool:
        return self.error is None and all(r.passed for r in self.results)

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "error": self.error,
            "time_s": self.time_s,
            "mcap": self.mcap,
            "results": [r.to_json() for r in self.results],
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Suite:
        results = [
            Result(
                r["name"],
                r["type"],
                r["passed"],
                None if r["t"] is None else round(r["t"] * 1e9),
                r["value"],
                r["bound"],
                r["message"],
            )
            for r in data.get("results", [])
        ]
        return cls(data["name"], results, data.get("error"), data.get("time_s", 0.0), data.get("mcap"))


def failure_text(r: Result) -> str:
    at = f" at t={r.t:.3f} s" if r.t is not None else ""
    return f"{r.name} ({r.type}) failed{at}: {r.message}; value {r.value}; bound {r.bound}"


def write_junit(path: Path, suites: list[Suite]) -> None:
    """JUnit XML in the common shape: testsuites / testsuite / testcase (/ failure | error)."""
    root = ET.Element("testsuites", name="scenario")
    total = failures = errors = 0
    for s in suites:
        cases = s.results or []
        suite = ET.SubElement(
            root,
            "testsuite",
            name=s.name,
            tests=str(max(len(cases), 1 if s.error else 0)),
            failures=str(sum(1 for r in cases if not r.passed)),
            errors="1" if s.error else "0",
            time=f"{s.time_s:.3f}",
        )
        if s.error:
            case = ET.SubElement(suite, "testcase", classname=s.name, name="run", time=f"{s.time_s:.3f}")
            ET.SubElement(
                case, "error", message=s.error.splitlines()[0] if s.error else "", type="RunError"
            ).text = s.error
            errors += 1
            total += 1
        for r in cases:
            case = ET.SubElement(suite, "testcase", classname=s.name, name=r.name, time="0")
            total += 1
            if not r.passed:
                failures += 1
                ET.SubElement(case, "failure", message=failure_text(r), type=r.type).text = failure_text(r)
    root.set("tests", str(total))
    root.set("failures", str(failures))
    root.set("errors", str(errors))
    path.parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
