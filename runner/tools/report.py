"""Judging a recording offline, and reporting results: a table, JSON, JUnit XML."""

from __future__ import annotations

import re
import struct
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from runner.checks.judge import (
    FAIL,
    PASS,
    UNDECIDED,
    Judge,
    Result,
    ended_early,
    events_key,
    judged_types,
    stops,
)


def judge_for(plan: Any) -> Judge | None:
    from runner.checks import specs_from_plan

    parts = plan.worlds or [plan]  # several worlds: one judge over all (their keys are distinct)
    assertions = [a for part in parts for a in part.assertions]
    events = [events_key(part.name) for part in parts if part.events]
    if not assertions and not events:
        return None
    return Judge(specs_from_plan(assertions), [k for part in parts for k in part.assertion_keys], events)


def firings(fired: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """What a judge saw the events do (`Judge.fired`), as the reports show and write it: per firing its
    event, sim time (s), why it fired, what its actions did, its count (`n`) and its `end:` if it had one."""
    out = []
    for f in fired:
        entry = {
            "event": str(f.get("event", "")),
            "t": f["t_ns"] / 1e9 if "t_ns" in f else float(f.get("t", 0.0)),
            "why": str(f.get("why", "")),
            "did": [str(d) for d in f.get("did") or []],
            "n": int(f.get("n", 1)),
        }
        if isinstance(f.get("end"), dict):
            entry["end"] = f["end"]
        out.append(entry)
    return out


def firing_line(f: dict[str, Any]) -> str:
    """One firing on one line: `t=6.880 s person_crosses: r1 within 3 m of [6.5, 1.5] (3.00 m) -> start
    walker`."""
    did = f" -> {'; '.join(f['did'])}" if f.get("did") else ""
    return f"t={f['t']:.3f} s {f['event']}: {f['why']}{did}"


@dataclass
class Judged:
    """A recording judged again: the results, its last sim time, why it ended before its planned end
    (None: it did not), and what its events did (`firings`)."""

    results: list[Result]
    end_ns: int
    why: str | None
    events: list[dict[str, Any]]


def judge_recording(plan: Any, mcap: Path) -> tuple[list[Result], int, str | None]:
    """`rejudge` without the events: the results, the last sim time and why the run ended early."""
    judged = rejudge(plan, mcap)
    return judged.results, judged.end_ns, judged.why


def rejudge(plan: Any, mcap: Path) -> Judged:
    """Re-judge a recording with the scenario's assertions (the same Judge the live run used), reading its
    events' firings too. How it ended is read from the recording's `scenario` metadata (written by the
    run); a recording without it (cut, or older) counts as complete only if it reaches the planned
    duration. A cut file (its runner killed before it was finished) is read up to its last whole chunk.
    Where the recording stops early, what needs the time after its end is not decided (`Judge.finish`)."""
    judge = judge_for(plan)
    if judge is None:
        return Judged([], 0, None, [])
    end_ns, meta, cut = _feed_recording(judge, judged_types(plan), mcap)
    ended = meta.get("ended")
    if "stopped" in meta:  # the recording itself stopped early (a full disk, a killed runner)
        cause = meta["stopped"] + (f" ({meta['error']})" if meta.get("error") else "")
        why: str | None = stops("the recording", end_ns, cause)
    elif cut:
        why = stops("the recording", end_ns, "the file is cut there, unfinished")
    elif ended is not None:
        why = ended_early(ended, end_ns)
    elif end_ns + 20_000_000 >= plan.duration_ns:  # (20 ms: the last clock before the planned end)
        why = None
    else:
        why = stops("the recording", end_ns, f"before the run's planned end ({plan.duration_ns / 1e9:g} s)")
    results = judge.finish(end_ns, complete=why is None, why=why or "")
    return Judged(results, end_ns, why, firings(judge.fired))


def _feed_recording(judge: Judge, types: dict[str, str], mcap: Path) -> tuple[int, dict[str, str], bool]:
    """Feed `judge` the messages of the recording it asks for: the last sim time the recording holds, its
    `scenario` metadata, and whether the file is cut (no summary: read record by record up to its last
    whole chunk, as `scenario info` does)."""
    from mcap.exceptions import McapError
    from mcap.reader import make_reader
    from mcap.records import Channel, Message, Metadata

    from runner.record.readback import read_records
    from runner.wire import msgs

    end_ns = 0
    wanted = judge.keys
    with open(mcap, "rb") as f:
        try:
            summary = make_reader(f).get_summary()
        except (McapError, struct.error, ValueError, EOFError):
            summary = None
        if summary is not None:
            f.seek(0)
            reader = make_reader(f)
            for _schema, channel, message in reader.iter_messages(log_time_order=True):
                end_ns = max(end_ns, message.log_time)
                topic = channel.topic
                if topic in wanted:
                    judge.feed(topic, message.log_time, msgs.decode(message.data, types[topic]))
            try:
                meta = next((dict(m.metadata) for m in reader.iter_metadata() if m.name == "scenario"), {})
            except Exception:  # a summary without a usable metadata index: nothing to go by
                meta = {}
            return end_ns, meta, False
    topics: dict[int, str] = {}
    meta = {}
    for record in read_records(mcap):  # in the order recorded (each key's messages in sim order)
        if isinstance(record, Channel):
            topics[record.id] = record.topic
        elif isinstance(record, Message):
            end_ns = max(end_ns, record.log_time)
            topic = topics.get(record.channel_id)
            if topic in wanted:
                judge.feed(topic, record.log_time, msgs.decode(record.data, types[topic]))
        elif isinstance(record, Metadata) and record.name == "scenario":
            meta = dict(record.metadata)
    return end_ns, meta, True


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
    events: list[dict[str, Any]] = field(default_factory=list)  # the events' firings (`firings`)
    # said of the run as JUnit <properties> (`scenario test --ray`: the node it ran on, its attempts)
    properties: dict[str, str] = field(default_factory=dict)

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
            "events": self.events,
            **({"properties": self.properties} if self.properties else {}),
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
            events=list(data.get("events") or []),
            properties={str(k): str(v) for k, v in (data.get("properties") or {}).items()},
        )


def failure_text(r: Result) -> str:
    at = f" at t={r.t:.3f} s" if r.t is not None else ""
    if r.type == "event":  # an `end:` that failed the run: its message, and why the event fired
        return f"{r.name} failed the run{at}: {r.message} (fired: {r.value})"
    if r.undecided:
        return f"{r.name} ({r.type}) not decided{at}: {r.message}; value {r.value}; bound {r.bound}"
    return f"{r.name} ({r.type}) failed{at}: {r.message}; value {r.value}; bound {r.bound}"


def write_junit(path: Path, suites: list[Suite]) -> None:
    """JUnit XML in the common shape (Jenkins' junit-10.xsd, which Ant, Surefire, GitLab and GitHub
    readers take): testsuites / testsuite / testcase (/ failure | error | skipped).

    A testcase's `time` is the sim time at which its verdict was reached (the run's end for one held
    to the end). An undecided assertion is a `<failure type="undecided">` whose message says why, or,
    with --allow-undecided, `<skipped>` with that message. A suite whose events fired has them as
    `<properties>` (`event.NAME`: the sim time it first fired) and in its `<system-out>`, one line each
    (`firing_line`); an `end:` event is a testcase of its own (its Result)."""
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
        _properties(suite, s.events, s.properties)  # (first: Ant's schema orders properties, testcases...)
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
        if s.events:
            ET.SubElement(suite, "system-out").text = _event_lines(s.events)
    root.set("tests", str(total))
    root.set("failures", str(failures))
    root.set("errors", str(errors))
    root.set("time", f"{wall:.3f}")
    for el in root.iter():  # names, messages and node output may hold what XML 1.0 cannot carry
        el.text = _xml_text(el.text) if el.text else el.text
        for key, value in el.attrib.items():
            el.set(key, _xml_text(value))
    path.parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


# What XML 1.0 cannot hold, even as a character reference (its `Char` production): ElementTree writes
# them as they are and every reader then refuses the whole file.
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _xml_text(text: str) -> str:
    """`text` with the characters XML cannot hold written as escapes (`\x1b`), as `repr` would."""
    return _NOT_XML.sub(lambda m: repr(m.group())[1:-1], text)


JUNIT_EVENT_LINES = 1000  # firings written to a suite's <system-out>, at most (a repeating event...)


def _properties(suite: ET.Element, events: list[dict[str, Any]], said: dict[str, str]) -> None:
    """The suite's own properties (`said`), and `event.NAME` = the sim time it first fired (and
    `event.NAME.fired` = how often, when more than once), for CI readers that show a suite's properties."""
    if not events and not said:
        return
    props = ET.SubElement(suite, "properties")
    for name, value in said.items():
        ET.SubElement(props, "property", name=name, value=value)
    seen: dict[str, list[float]] = {}
    for f in events:
        seen.setdefault(f["event"], []).append(f["t"])
    for name, times in seen.items():
        ET.SubElement(props, "property", name=f"event.{name}", value=f"{times[0]:.3f}")
        if len(times) > 1:
            ET.SubElement(props, "property", name=f"event.{name}.fired", value=str(len(times)))


def _event_lines(events: list[dict[str, Any]]) -> str:
    lines = [firing_line(f) for f in events[:JUNIT_EVENT_LINES]]
    if len(events) > JUNIT_EVENT_LINES:
        lines.append(f"... and {len(events) - JUNIT_EVENT_LINES} more firing(s)")
    return "\n".join(lines) + "\n"


EVENT_ROWS = 20  # rows of the Events table, at most
EVENT_REPEATS = 3  # firings of one event shown before the rest are folded into one row


def event_rows(events: list[dict[str, Any]]) -> tuple[list[tuple[str, str, str, str]], int]:
    """The Events table's rows (t, event, why, what it did) in firing order, and how many firings they
    leave out. An event that fires again and again shows its first firings, then one row for the rest
    (`4.000..9.000`, `and 12 more firings`), so one that repeats cannot crowd out the others."""
    by_name: dict[str, list[dict[str, Any]]] = {}
    for f in events:
        by_name.setdefault(f["event"], []).append(f)
    rows: list[tuple[tuple[str, str, str, str], int]] = []  # (row, how many firings it stands for)
    seen: dict[str, int] = {}
    for f in events:
        mine = by_name[f["event"]]
        i = seen[f["event"]] = seen.get(f["event"], -1) + 1
        if i < EVENT_REPEATS or len(mine) == EVENT_REPEATS + 1:
            rows.append(((f"{f['t']:.3f}", f["event"], f["why"], "; ".join(f["did"])), 1))
        elif i == EVENT_REPEATS:
            rest = mine[EVENT_REPEATS:]
            span = f"{rest[0]['t']:.3f}..{rest[-1]['t']:.3f}"
            rows.append(((span, f["event"], f"and {len(rest)} more firings", "; ".join(f["did"])), len(rest)))
    kept = rows[:EVENT_ROWS]
    return [r for r, _n in kept], len(events) - sum(n for _r, n in kept)
