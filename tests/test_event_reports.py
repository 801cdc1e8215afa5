"""What the events did, shown to the user: the Events table at the end of `scenario run`, the firings in
--results-json and in JUnit (properties, system-out, an `end:` as a testcase of its own, valid for CI's
schema), the same firings from `scenario check` on the recording, the HTML report's timeline (with a
collision's time and place), and `scenario test`'s count. One real run of a small scenario serves most."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest

from tests.conftest import DIFFBOT, REPO, run_cli, scenario_cmd

# r1 waits; at 1 s an event sets it going and starts a box that walks across its path (they touch near
# t=1.9 s); at 2.5 s another ends the run as a failure. Two assertions: one fails on the collision.
SCENARIO = f"""
name: ev
duration: 3.0
rate: max
world:
  actors:
    - {{name: walker, shape: box, size: [0.3, 0.3, 0.4], waypoints: [[0.3, 2.0], [0.3, -2.0]], speed: 2.0,
       start: event}}
robots:
  - name: r1
    description: {{file: {DIFFBOT}}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{{type: diff_drive}}]
events:
  - name: go
    when: {{at: 1.0}}
    do:
      - publish: {{topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.3}}}}}}
      - start: walker
  - name: give_up
    when: {{at: 2.5}}
    do:
      - end: {{result: fail, message: time is up}}
assertions:
  - {{name: slow, type: max_speed, robot: r1, max: 5.0}}
  - {{name: no_collision_with_the_walker, type: no_collision, between: [r1, walker]}}
"""

GO = "t=1.000 s go: at 1 s -> published on r1/cmd_vel; start walker"
GIVE_UP = "t=2.500 s give_up: at 2.5 s -> end: fail (time is up)"


@pytest.fixture(scope="module")
def ran(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The scenario run once: its file, recording, JUnit, results JSON and terminal output."""
    d = tmp_path_factory.mktemp("events")
    path = d / "ev.yaml"
    path.write_text(SCENARIO)
    mcap, junit, res = d / "ev.mcap", d / "j.xml", d / "r.json"
    cmd = scenario_cmd(
        "run", str(path), "--record", str(mcap), "--junit", str(junit), "--results-json", str(res)
    )
    env = dict(os.environ, COLUMNS="200")  # (wide enough that no table cell wraps)
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=90, cwd=REPO, env=env)
    return {"dir": d, "path": path, "mcap": mcap, "junit": junit, "json": res, "proc": proc}


def _row(*cells: str) -> re.Pattern[str]:
    return re.compile(r"│\s*" + r"\s*│\s*".join(re.escape(c) for c in cells) + r"\s*│")


def test_the_end_of_run_table_lists_every_firing(ran: dict[str, Any]) -> None:
    proc = ran["proc"]
    assert proc.returncode == 1, proc.stdout + proc.stderr  # the `end: fail` event fails the run
    out = proc.stdout
    # after the recorded topics, before the assertions
    assert out.index("Recorded") < out.index("Events") < out.index("Assertions")
    assert _row("1.000", "go", "at 1 s", "published on r1/cmd_vel; start walker").search(out), out
    assert _row("2.500", "give_up", "at 2.5 s", "end: fail (time is up)").search(out), out
    assert "event give_up failed the run at t=2.500 s: time is up" in out
    data = json.loads(ran["json"].read_text())
    assert [(f["event"], f["t"], f["did"]) for f in data["events"]] == [
        ("go", 1.0, ["published on r1/cmd_vel", "start walker"]),
        ("give_up", 2.5, ["end: fail (time is up)"]),
    ]
    assert data["events"][1]["end"] == {"result": "fail", "message": "time is up"}
    got = {r["name"]: r for r in data["results"]}
    assert got["event give_up"]["status"] == "fail" and got["event give_up"]["t"] == 2.5
    hit = got["no_collision_with_the_walker"]
    assert hit["status"] == "fail" and 1.0 < hit["t"] < 2.5 and "r1 touched walker at (" in hit["message"]


def _junit_valid(path: Path) -> ET.Element:
    """Valid against the JUnit schema CI servers read (tests/data/junit.xsd, as test_verdicts checks)."""
    from lxml import etree

    schema = etree.XMLSchema(etree.parse(str(REPO / "tests" / "data" / "junit.xsd")))
    assert schema.validate(etree.parse(str(path))), schema.error_log
    return ET.parse(path).getroot()


def test_junit_carries_the_firings_and_the_ending_event(ran: dict[str, Any], tmp_path: Path) -> None:
    from runner.tools.report import Suite, write_junit

    suite = _junit_valid(ran["junit"]).find("testsuite")
    assert suite is not None and (suite.get("tests"), suite.get("failures")) == ("3", "2")
    # Ant's order: properties, testcases, system-out
    tags = [child.tag for child in suite]
    assert tags[0] == "properties" and tags[-1] == "system-out" and set(tags[1:-1]) == {"testcase"}
    props = {p.get("name"): p.get("value") for p in suite.iter("property")}
    assert props == {"event.go": "1.000", "event.give_up": "2.500"}
    assert (suite.findtext("system-out") or "").splitlines() == [GO, GIVE_UP]
    ending = suite.find("testcase[@name='event give_up']")
    assert ending is not None and ending.get("time") == "2.500"
    failure = ending.find("failure")
    assert failure is not None and failure.get("type") == "event"
    assert failure.get("message") == "event give_up failed the run at t=2.500 s: time is up (fired: at 2.5 s)"
    # `scenario test` reads a run's suite back from its JSON: the same JUnit comes out of it
    again = tmp_path / "again.xml"
    write_junit(again, [Suite.from_json(json.loads(ran["json"].read_text()))])
    assert ET.tostring(_junit_valid(again)) == ET.tostring(_junit_valid(ran["junit"]))


def test_check_on_the_recording_gives_the_same_results_and_firings(
    ran: dict[str, Any], tmp_path: Path
) -> None:
    junit = tmp_path / "off.xml"
    proc = run_cli("check", str(ran["mcap"]), "--scenario", str(ran["path"]), "--junit", str(junit))
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "Events" in proc.stdout and "give_up" in proc.stdout
    live = _junit_valid(ran["junit"]).find("testsuite")
    off = _junit_valid(junit).find("testsuite")
    assert live is not None and off is not None
    assert off.findtext("system-out") == live.findtext("system-out")
    assert ET.tostring(off.find("properties")) == ET.tostring(live.find("properties"))
    cases = [(c.get("name"), c.get("time"), ET.tostring(c)) for c in off.iter("testcase")]
    assert cases == [(c.get("name"), c.get("time"), ET.tostring(c)) for c in live.iter("testcase")]

    # events and no assertions: still judged, the ending event its one result
    bare = tmp_path / "bare.yaml"
    bare.write_text(SCENARIO.split("assertions:")[0])
    proc = run_cli("check", str(ran["mcap"]), "--scenario", str(bare))
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert _row("1.000", "go", "at 1 s").search(proc.stdout) and "event give_up" in proc.stdout
    assert "0 passed, 1 failed" in proc.stdout


def test_the_report_draws_the_firings_and_the_failures_on_a_timeline(ran: dict[str, Any]) -> None:
    page = ran["dir"] / "ev.html"
    proc = run_cli("report", str(ran["mcap"]), "-o", str(page))
    assert proc.returncode == 0, proc.stderr
    assert "2 event firing(s)" in proc.stdout
    text = page.read_text()
    svg = re.search(r'<svg[^>]*class="timeline".*?</svg>', text)
    assert svg is not None
    timeline = svg.group(0)
    firings = re.findall(r'<circle class="firing"[^>]*fill="(#\w+)"><title>([^<]*)</title>', timeline)
    assert firings == [("#2f6fdf", GO.replace(">", "&gt;")), ("#cf222e", GIVE_UP.replace(">", "&gt;"))]
    # the collision, in its own lane: when and where
    hit = re.search(r"t=(\d+\.\d\d) s: r1 touched walker at \((-?[\d.]+), (-?[\d.]+), (-?[\d.]+)\)", timeline)
    assert hit is not None and 1.0 < float(hit[1]) < 2.5, timeline
    assert 'class="run-end"' in timeline and "<title>no_collision_with_the_walker</title>" in timeline
    # the events' table, the firings marked on the speed plot, the ending's message in the assertions
    assert "<td>go</td><td>at 1 s</td><td>published on r1/cmd_vel; start walker</td>" in text
    speed = next(s for s in re.findall(r"<svg.*?</svg>", text) if "Speed of each robot" in s)
    assert speed.count('class="event-mark"') == 2
    assert "<small>time is up</small>" in text


def test_the_trajectory_plot_marks_where_a_collision_happened(ran: dict[str, Any], tmp_path: Path) -> None:
    """The same failed no_collision, with and without a place in its value: the place is drawn."""
    import numpy as np
    from PIL import Image

    from runner.checks.judge import Result
    from runner.tools.html import load_plan
    from runner.tools.plot import trajectory_plot

    plan = load_plan(ran["mcap"])
    pngs = []
    for place in ("", " at (1.00, 1.00, 0.10)"):
        hit = Result("no_collision_with_the_walker", "no_collision", "fail", 1_900_000_000,
                     f"r1 touched walker{place}", "no contact", f"r1 touched walker{place}")  # fmt: skip
        png = trajectory_plot(plan, ran["mcap"], [hit], tmp_path / f"p{len(pngs)}.png")
        assert png is not None
        pngs.append(np.asarray(Image.open(png).convert("L")).astype(int))
    changed = np.argwhere(np.abs(pngs[0] - pngs[1]) > 60)
    assert 10 < len(changed) < 2000  # one small cross, nothing else
    assert np.ptp(changed[:, 0]) < 30 and np.ptp(changed[:, 1]) < 30


def test_scenario_test_counts_the_firings(ran: dict[str, Any]) -> None:
    env = dict(os.environ, COLUMNS="200")
    cmd = scenario_cmd("test", str(ran["path"]), "--no-record")
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=90, cwd=REPO, env=env)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "events fired" in proc.stdout
    assert _row("ev", "3", "1", "2", "2", "FAIL").search(proc.stdout), proc.stdout


def test_an_event_that_fires_again_and_again_is_folded_in_the_table() -> None:
    from runner.tools.report import EVENT_REPEATS, event_rows

    ticks = [
        {"event": "tick", "t": 0.5 * i, "why": "every 0.5 s", "did": ["published on a"]} for i in range(10)
    ]
    once = {"event": "bump", "t": 3.2, "why": "r1 entered dock", "did": ["teleport r1"]}
    events = sorted([*ticks, once], key=lambda f: f["t"])
    rows, left = event_rows(events)
    assert left == 0
    assert [r[0] for r in rows] == ["0.000", "0.500", "1.000", "1.500..4.500", "3.200"]
    assert rows[EVENT_REPEATS][2] == "and 7 more firings" and rows[-1][1] == "bump"
    # one firing more than shown is shown, not folded into a row of one
    rows, left = event_rows(ticks[: EVENT_REPEATS + 1])
    assert [r[0] for r in rows] == ["0.000", "0.500", "1.000", "1.500"] and left == 0
    # many events: the table stops at its rows and says how many firings it left out
    many = [{"event": f"e{i}", "t": float(i), "why": "at t", "did": []} for i in range(30)]
    rows, left = event_rows(many)
    assert len(rows) == 20 and left == 10


def test_pytest_reports_an_event_that_failed_the_run(tmp_path: Path) -> None:
    """The pytest plugin: an event with `end:` is an item of its own, failed with its message."""
    folder = tmp_path / "scenarios"
    folder.mkdir()
    (folder / "ev.yaml").write_text(SCENARIO)
    cmd = ["-m", "pytest", "-q", "-p", "no:cacheprovider", "-rf", str(folder / "ev.yaml")]
    proc = subprocess.run([sys.executable, *cmd], capture_output=True, text=True, timeout=110, cwd=REPO)
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "2 failed, 1 passed" in proc.stdout, proc.stdout
    assert "event give_up (event) failed at t=2.500 s: time is up" in proc.stdout, proc.stdout
