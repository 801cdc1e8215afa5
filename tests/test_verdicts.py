"""Verdicts that mean what they say: pass, fail, and not decided (with why), never a pass that was never
tested; interrupted runs exit 130/143; JUnit that CI servers' schema accepts."""

from __future__ import annotations

import json
import signal
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from runner.sim.world import World
from runner.tools.report import judge_for
from runner.wire import msgs
from runner.wire.transport import MemoryBus, unpack_attachment
from tests.conftest import REPO, run_cli, start_cli
from tests.helpers import plan_of

# r1 drives +x at 0.5 m/s for 3 s, then back: it leaves its start (0, 0) by 1.5 m and returns by t=6.
# r2 stands still at (0, 2). Nothing is published on r1/cmd_vel after t=3.
BASE = """
name: v
duration: 6.0
rate: max
robots:
  - name: r1
    description: "{{diffbot}}"
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{{type: diff_drive}}, {{type: lidar, params: {{link: lidar_link, rate: 10}}}}]
  - name: r2
    description: "{{diffbot}}"
    pose: {{xyz: [0, 2, 0.06]}}
    plugins: [{{type: diff_drive}}]
timeline:
  - {{t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.5}}}}}}
  - {{t: 3.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: -0.5}}}}}}
assertions:
  - {assertion}
"""

INTERRUPTED = "the run was interrupted at t=2.000 s"

# (case, assertion, how the run ended: None = completed at 6 s, else interrupted at 2 s,
#  expected status, words of the reason or value)
CASES = [
    # windows the run never reached: today these passed with an empty value
    ("window_after_the_end", "{name: a, type: stay_within, robot: r2, after: 40, "
     "region: {center: [0, 2], radius: 0.5}}", None, "undecided", "opens at t=40 s, after the run's end"),
    ("window_past_the_end", "{name: a, type: max_speed, robot: r1, max: 5, until: 10}", None,
     "undecided", "runs to t=10 s, after the run's end"),
    ("rate_window_after_the_end", "{name: a, type: topic_rate, topic: r1/scan, min: 5, after: 7}", None,
     "undecided", "opens at t=7 s"),
    ("distance_window_past_the_end", "{name: a, type: distance_traveled, robot: r1, min: 1, until: 9}",
     None, "undecided", "runs to t=9 s"),
    # interrupted: not decided is not failed, and not passed either
    ("interrupted_reach_by_15", "{name: a, type: reach, robot: r1, point: [2.5, 0], by: 15}", "cut",
     "undecided", INTERRUPTED),
    ("interrupted_reach_to_the_end", "{name: a, type: reach, robot: r1, point: [2.5, 0]}", "cut",
     "undecided", INTERRUPTED),
    ("interrupted_stay_within", "{name: a, type: stay_within, robot: r2, "
     "region: {center: [0, 2], radius: 0.5}}", "cut", "undecided", INTERRUPTED),
    ("interrupted_rate", "{name: a, type: topic_rate, topic: r1/scan, min: 5}", "cut", "undecided",
     INTERRUPTED),
    # ... but what the run did show is decided: a passed deadline, a broken bound
    ("interrupted_after_the_deadline", "{name: a, type: reach, robot: r1, point: [2.5, 0], by: 1.5}",
     "cut", "fail", "not reached"),
    ("interrupted_speed_broken", "{name: a, type: max_speed, robot: r1, max: 0.2}", "cut", "fail",
     "too fast"),
    ("interrupted_path_too_long", "{name: a, type: distance_traveled, robot: r1, max: 0.5}", "cut", "fail",
     "path length out of bounds"),
    ("interrupted_reached", "{name: a, type: reach, robot: r1, point: [0.5, 0], by: 15}", "cut", "pass",
     "reached at"),
    # a topic that never carried a message: nothing was tested
    ("message_on_a_silent_topic", "{name: a, type: message, topic: r1/cmd_vel, after: 4, expr: 'linear.x > 0'}", None,
     "undecided", "no message on r1/cmd_vel"),
    ("eventually_on_a_silent_topic", "{name: a, type: message, topic: r1/cmd_vel, after: 4, "
     "mode: eventually, expr: 'linear.x > 0'}", None, "undecided", "no message on r1/cmd_vel"),
    ("max_rate_of_a_silent_topic", "{name: a, type: topic_rate, topic: r1/cmd_vel, after: 4, max: 50}", None,
     "undecided", "no message on r1/cmd_vel"),
    ("min_rate_of_a_silent_topic", "{name: a, type: topic_rate, topic: r1/cmd_vel, after: 4, min: 5}", None, "fail",
     "rate out of bounds"),
    # reach: `after` and `leave` ("leave the start, then come back")
    ("reach_at_the_start", "{name: a, type: reach, robot: r2, point: [0, 2]}", None, "pass", "t=0.000"),
    ("reach_after_leaving_never_left", "{name: a, type: reach, robot: r2, point: [0, 2], leave: 1}", None,
     "fail", "never left the start by 1 m"),
    ("reach_after_leaving_and_returning", "{name: a, type: reach, robot: r1, point: [0, 0], "
     "tolerance: 0.3, leave: 1}", None, "pass", "reached at t=5."),
    ("reach_after_a_time", "{name: a, type: reach, robot: r1, point: [0, 0], tolerance: 0.3, after: 4}",
     None, "pass", "reached at t=5."),
    ("reach_after_leaving_cut_before_return", "{name: a, type: reach, robot: r1, point: [0, 0], "
     "tolerance: 0.3, leave: 1}", "cut", "undecided", INTERRUPTED),
    # what held over a whole run still passes
    ("held_to_the_end", "{name: a, type: stay_within, robot: r2, region: {center: [0, 2], radius: 0.5}}",
     None, "pass", "held"),
    ("rate_held", "{name: a, type: topic_rate, topic: r1/scan, min: 9, max: 11, until: 5}", None, "pass",
     "held"),
]  # fmt: skip


def _write(folder: Path, name: str, assertion: str) -> Path:
    from tests.conftest import DIFFBOT

    path = folder / f"{name}.yaml"
    path.write_text(BASE.format(assertion=assertion).replace("{diffbot}", str(DIFFBOT)))
    return path


@pytest.fixture(scope="module")
def published(tmp_path_factory: pytest.TempPathFactory) -> list:
    """What the world publishes, simulated once (real MuJoCo, in-process) with both robots' ground truth:
    the cases differ only in their assertion, so each is judged on these same messages."""
    folder = tmp_path_factory.mktemp("verdicts")
    both = (
        "{name: b1, type: max_speed, robot: r1, max: 9}\n  - {name: b2, type: max_speed, robot: r2, max: 9}"
    )
    bus = MemoryBus()
    World(plan_of(_write(folder, "both", both)), bus).run()
    return bus.sent


@pytest.mark.parametrize(("case", "assertion", "ended", "status", "words"), CASES, ids=[c[0] for c in CASES])
def test_each_verdict_is_pass_fail_or_not_decided_with_why(
    published: list, tmp_path: Path, case: str, assertion: str, ended: str | None, status: str, words: str
):
    plan = plan_of(_write(tmp_path, case, assertion))
    judge = judge_for(plan)
    assert judge is not None
    end = plan.duration_ns if ended is None else 2_000_000_000
    for key, type_name, payload, att in published:
        t = unpack_attachment(att)[1]  # type: ignore[index]
        if t <= end and key in judge.keys:
            judge.feed(key, t, msgs.decode(payload, type_name))
    (r,) = judge.finish(end, complete=ended is None, why="" if ended is None else INTERRUPTED)
    assert (r.status, r.passed, r.undecided) == (status, status == "pass", status == "undecided"), (
        r.message,
        r.value,
    )
    assert words in f"{r.message} {r.value}", (r.message, r.value)
    if status == "undecided":
        assert r.t_ns == end  # (JUnit's time: when it was left undecided)


SHORT = """
name: short
duration: 2.0
rate: max
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins: [{type: diff_drive}]
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.5}}}
assertions:
  - {name: moves, type: reach, robot: r1, point: [0.5, 0], tolerance: 0.2}
  - {name: late_window, type: stay_within, robot: r1, after: 40, region: {center: [0, 0], radius: 5}}
"""


def _junit_valid(path: Path) -> ET.Element:
    from lxml import etree

    schema = etree.XMLSchema(etree.parse(str(Path(__file__).parent / "data" / "junit.xsd")))
    doc = etree.parse(str(path))
    assert schema.validate(doc), schema.error_log
    return ET.parse(path).getroot()


@pytest.mark.timeout(120)
def test_an_undecided_assertion_fails_the_run_unless_allowed(write_scenario, tmp_path: Path):
    """`stay_within after: 40` in a 2 s run: not decided, said why; exit 1, a JUnit <failure> of type
    `undecided` (valid against CI's JUnit schema, with sim times, timestamp and hostname); with
    --allow-undecided, exit 0 and a <skipped>."""
    path = write_scenario(SHORT)
    junit, res = tmp_path / "j.xml", tmp_path / "r.json"
    proc = run_cli("run", str(path), "--no-record", "--junit", str(junit), "--results-json", str(res))
    assert proc.returncode == 1, proc.stderr
    assert "not decided" in proc.stdout and "opens at t=40 s, after the run's end" in proc.stdout
    assert "1 passed, 0 failed, 1 not decided" in proc.stdout
    root = _junit_valid(junit)
    suite = root.find("testsuite")
    assert suite is not None and suite.get("hostname") and suite.get("timestamp")
    assert (suite.get("tests"), suite.get("failures"), suite.get("skipped")) == ("2", "1", "0")
    moves = suite.find("testcase[@name='moves']")
    late = suite.find("testcase[@name='late_window']")
    assert moves is not None and late is not None
    assert 0.5 < float(moves.get("time", "0")) < 2.0  # the sim time it was reached at, not 0
    failure = late.find("failure")
    assert failure is not None and failure.get("type") == "undecided"
    assert failure.get("message", "").startswith("not decided: the window opens at t=40 s")
    assert float(late.get("time", "0")) == pytest.approx(2.0, abs=0.02)
    data = json.loads(res.read_text())
    assert [r["status"] for r in data["results"]] == ["pass", "undecided"] and not data["passed"]

    proc = run_cli(
        "run",
        str(path),
        "--no-record",
        "--allow-undecided",
        "--junit",
        str(junit),
        "--results-json",
        str(res),
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "not counted as failures: --allow-undecided" in proc.stdout
    suite = _junit_valid(junit).find("testsuite")
    assert suite is not None and (suite.get("failures"), suite.get("skipped")) == ("0", "1")
    skipped = suite.find("testcase[@name='late_window']/skipped")
    assert skipped is not None and "opens at t=40 s" in skipped.get("message", "")
    assert json.loads(res.read_text())["passed"]


@pytest.mark.timeout(120)
def test_a_duration_override_leaves_later_windows_undecided(write_scenario, tmp_path: Path):
    """`--duration 1` on a scenario whose reach is due by 1.5 s: not decided (not failed at 1 s)."""
    text = SHORT.replace("tolerance: 0.2}", "tolerance: 0.2, by: 1.5}").replace(
        "  - {name: late_window", "  # - {name: late_window"
    )
    path = write_scenario(text.replace("point: [0.5, 0]", "point: [0.7, 0]"))
    res = tmp_path / "r.json"
    proc = run_cli("run", str(path), "--no-record", "--duration", "1", "--results-json", str(res))
    assert proc.returncode == 1
    (r,) = json.loads(res.read_text())["results"]
    assert r["status"] == "undecided" and "runs to t=1.5 s" in r["message"], r


LONG = """
name: long
duration: 60.0
rate: realtime
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins: [{type: diff_drive}]
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.1}}}
assertions:
  - {name: far, type: reach, robot: r1, point: [5, 0], by: 50}
  - {name: calm, type: max_speed, robot: r1, max: 1}
"""


@pytest.mark.timeout(120)
@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_an_interrupted_run_exits_130_or_143_and_decides_nothing_it_did_not_see(
    write_scenario, tmp_path: Path, sig: int, code: int
):
    """Ctrl-C (or SIGTERM) at a few sim seconds: `reach by 50` is not decided (not FAIL), `max_speed` to
    the end is not decided either (the rest of the run was never seen), and the exit code is the shell's."""
    path = write_scenario(LONG)
    junit = tmp_path / "j.xml"
    proc = start_cli("run", str(path), "--no-record", "--junit", str(junit))
    try:
        deadline = time.monotonic() + 60
        assert proc.stderr is not None
        for line in proc.stderr:  # the run is going once it says so
            if line.startswith("running long") or time.monotonic() > deadline:
                break
        time.sleep(2.0)
        proc.send_signal(sig)
        out, _ = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == code, out
    suite = _junit_valid(junit).find("testsuite")
    assert suite is not None
    how = "interrupted" if sig == signal.SIGINT else "terminated (SIGTERM)"
    for name in ("far", "calm"):
        failure = suite.find(f"testcase[@name='{name}']/failure")
        assert failure is not None and failure.get("type") == "undecided", name
        message = failure.get("message", "")
        assert message.startswith("not decided: ") and f"the run was {how} at t=" in message, message
    assert "FAIL" not in out


@pytest.mark.timeout(120)
def test_a_recording_is_judged_as_the_run_was(write_scenario, tmp_path: Path):
    """`scenario check` reads how the run ended from the recording itself: the same not-decided verdict,
    the same reason, as the live judge's."""
    path = write_scenario(SHORT)
    mcap = tmp_path / "short.mcap"
    live = run_cli("run", str(path), "--record", str(mcap))
    assert live.returncode == 1
    junit = tmp_path / "j.xml"
    proc = run_cli("check", str(mcap), "--scenario", str(path), "--junit", str(junit))
    assert proc.returncode == 1, proc.stderr
    assert "1 passed, 0 failed, 1 not decided" in proc.stdout
    failure = _junit_valid(junit).find(".//testcase[@name='late_window']/failure")
    assert failure is not None and "opens at t=40 s, after the run's end" in failure.get("message", "")
    assert run_cli("check", str(mcap), "--scenario", str(path), "--allow-undecided").returncode == 0


VACUOUS = """
name: vac
duration: 10.0
rate: max
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins: [{type: diff_drive}]
  - name: r2
    description: "{diffbot}"
    pose: {xyz: [0, 2, 0.06]}
    plugins: [{type: diff_drive}]
bridges:
  - {topic: r2/cmd_vl, key: outside/r2/cmd_vel, direction: ZENOH_TO_SIM, encoding: json,
     type: geometry_msgs/msg/Twist}
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.5}}}
  - {t: 1.0, topic: r1/cmd_vell, type: geometry_msgs/msg/Twist, data: {}}
assertions:
  - {name: late, type: stay_within, robot: r1, after: 40, region: {center: [0, 0], radius: 9}}
  - {name: already_there, type: reach, robot: r2, point: [0, 2]}
  - {name: comes_back, type: reach, robot: r2, point: [0, 2], leave: 1}
  - {name: due_later, type: reach, robot: r1, point: [3, 0], by: 12}
  - {name: fine, type: max_speed, robot: r1, max: 1, until: 10}
"""


@pytest.mark.timeout(60)
def test_validate_warns_of_what_would_decide_nothing_and_strict_makes_it_an_error(write_scenario):
    """Each vacuous construct is a located warning with a hint (a did-you-mean for typo'd topics);
    `--strict` makes them errors (exit 1); a clean scenario passes --strict."""
    path = write_scenario(VACUOUS)
    proc = run_cli("validate", str(path))
    assert proc.returncode == 0, proc.stderr
    text = " ".join(proc.stderr.split())  # (rich wraps long lines)
    lines = path.read_text().splitlines()

    def line_of(words: str) -> int:
        return next(i + 1 for i, line in enumerate(lines) if words in line)

    expected = [
        (line_of("cmd_vl"), "bridge 0 publishes on 'r2/cmd_vl', which nothing in the run subscribes to",
         "did you mean 'r2/cmd_vel'?"),
        (line_of("r1/cmd_vell"), "timeline[1] publishes on 'r1/cmd_vell', which nothing in the run "
         "subscribes to", "did you mean 'r1/cmd_vel'?"),
        (line_of("name: late"), "assertions[0] 'late': its window (after: 40 s) lies past the run's end "
         "(duration: 10 s)", "make duration at least 40"),
        (line_of("already_there"), "assertions[1] 'already_there': robot 'r2' starts at its goal (0, 2)",
         "add `leave: 1.0`"),
        (line_of("due_later"), "assertions[3] 'due_later': its window (by: 12 s) lies past the run's end",
         "make duration at least 12"),
    ]  # fmt: skip
    for line, message, hint in expected:
        assert f"{path}:{line}: {message}" in text, message
        assert hint in text.split(f"{path}:{line}: {message}")[1].split("warning:")[0], hint
    assert text.count(f"warning: {path}:") == len(expected)  # comes_back, fine, r1/cmd_vel: no warning

    strict = run_cli("validate", str(path), "--strict")
    assert strict.returncode == 1
    assert f"--strict: {len(expected)} warning(s) about the scenario are errors" in strict.stderr
    assert "Traceback" not in strict.stderr
    assert run_cli("validate", str(REPO / "scenarios" / "two_robots.yaml"), "--strict").returncode == 0


def test_the_judge_waits_for_the_messages_still_in_flight_on_its_own_subscriptions(write_scenario):
    """Without a recording the judge subscribes itself; at the end it waits, as the recorder does, until it
    has every message the world says it published: the last ones decide a verdict. (Real Zenoh sessions;
    the supervisor's view of the run is a stand-in whose world ended having published N messages.)"""
    import threading
    from types import SimpleNamespace

    import zenoh

    from runner.launch.parts import JudgePart
    from runner.wire.transport import free_port, make_config, pack_attachment

    path = write_scenario(
        BASE.format(
            assertion="{name: a, type: message, topic: r1/cmd_vel, mode: eventually, expr: 'linear.x > 1'}"
        )
    )
    plan = plan_of(path)
    key = f"{plan.name}/r1/cmd_vel"
    judge = judge_for(plan)
    assert judge is not None and key in judge.keys
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    n = 40
    twist = "geometry_msgs/msg/Twist"
    slow = msgs.encode(msgs.from_data(twist, {}), twist)
    fast = msgs.encode(msgs.from_data(twist, {"linear": {"x": 2.0}}), twist)
    with zenoh.open(make_config("router", listen=[endpoint])) as session:
        world = SimpleNamespace(
            child=object(), remote_host=None, ended=threading.Event(), end_info={"published": {key: n}}
        )
        world.ended.set()
        run = SimpleNamespace(
            plan=plan, session=session, subs=[], worlds=[world], recorder=None, reason="completed",
            error=None, hurry=threading.Event(), wait=lambda event, timeout_s: event.wait(timeout_s),
        )  # fmt: skip
        part = JudgePart(judge)
        part.start(run)
        with zenoh.open(make_config("client", connect=[endpoint])) as other:
            pub = other.declare_publisher(key)
            time.sleep(0.3)  # (the client's connection and the judge's subscription are declared)

            def publish() -> None:  # the world's last messages, still on their way when the drain begins
                for i in range(n):
                    time.sleep(0.02)
                    pub.put(fast if i == n - 1 else slow, attachment=pack_attachment(i, (i + 1) * 1_000_000))

            sender = threading.Thread(target=publish)
            sender.start()
            try:
                part.drain(run)
                got = dict(part.own)
            finally:
                sender.join(timeout=10)
                for sub in run.subs:
                    sub.undeclare()
    assert got == {key: n}
    (result,) = judge.finish(n * 1_000_000)
    assert result.passed, result.to_json()
