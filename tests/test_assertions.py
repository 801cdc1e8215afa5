"""Assertions, each kind passing and failing on real runs; live and offline judgement agree; JUnit."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from runner.errors import ScenarioError
from runner.sim.world import World
from runner.tools.report import judge_for
from runner.wire import msgs
from runner.wire.transport import MemoryBus, unpack_attachment
from tests.conftest import run_cli
from tests.helpers import plan_of

BASE = """
name: a
duration: 6.0
rate: max
world:
  models:
    - {{name: wall, shape: box, size: [0.2, 4, 0.5], pose: {{xyz: [2.6, 0, 0.25]}}}}
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
assertions:
{assertions}
"""


def _judge(write_scenario, assertions: str, name: str = "s.yaml"):  # type: ignore[no-untyped-def]
    """Run in-process (real MuJoCo) and judge what was published, as the live judge does."""
    plan = plan_of(write_scenario(BASE.format(assertions=assertions), name))
    bus = MemoryBus()
    World(plan, bus).run()
    judge = judge_for(plan)
    assert judge is not None
    for key, type_name, payload, att in bus.sent:
        if key in judge.keys:
            judge.feed(key, unpack_attachment(att)[1], msgs.decode(payload, type_name))  # type: ignore[index]
    return {r.name: r for r in judge.finish(plan.duration_ns)}


# (kind, passing assertion, failing assertion): r1 drives +x at 0.5 m/s into a wall at x = 2.5
CASES = [
    (
        "reach",
        "{name: x, type: reach, robot: r1, point: [1.5, 0], tolerance: 0.2, by: 4}",
        "{name: x, type: reach, robot: r1, point: [1.5, 0], tolerance: 0.2, by: 2}",
    ),
    (
        "reach_region",
        "{name: x, type: reach, robot: r1, region: {min: [1, -1], max: [2, 1]}}",
        "{name: x, type: reach, robot: r2, region: {min: [1, -1], max: [2, 1]}}",
    ),
    (
        "stay_within",
        "{name: x, type: stay_within, robot: r2, region: {center: [0, 2], radius: 0.1}}",
        "{name: x, type: stay_within, robot: r1, region: {center: [0, 0], radius: 1.0}}",
    ),
    (
        "keep_out",
        "{name: x, type: stay_within, robot: r1, inside: false, region: {center: [0, 2], radius: 0.5}}",
        "{name: x, type: stay_within, robot: r1, inside: false, region: {center: [1, 0], radius: 0.5}}",
    ),
    (
        "no_collision",
        "{name: x, type: no_collision, between: [r1, r2]}",
        "{name: x, type: no_collision, between: [r1, wall]}",
    ),
    (
        "topic_rate",
        "{name: x, type: topic_rate, topic: r1/scan, min: 9.5, max: 10.5}",
        "{name: x, type: topic_rate, topic: r1/scan, min: 19}",
    ),
    (
        "message_always",
        "{name: x, type: message, topic: r1/scan, expr: 'len(ranges) == 360 and range_max > 11', mode: always}",
        "{name: x, type: message, topic: r1/odom, expr: 'pose.pose.position.x < 1.0', mode: always}",
    ),
    (
        "message_eventually",
        "{name: x, type: message, topic: r1/odom, expr: 'pose.pose.position.x >= 1.0', mode: eventually}",
        "{name: x, type: message, topic: r1/odom, expr: 'pose.pose.position.x >= 5.0', mode: eventually}",
    ),
    (
        "message_never",
        "{name: x, type: message, topic: r1/odom, expr: 'pose.pose.position.y > 0.3', mode: never}",
        "{name: x, type: message, topic: r1/odom, expr: 'pose.pose.position.x > 0.3', mode: never}",
    ),
    (
        "max_speed",
        "{name: x, type: max_speed, robot: r1, max: 0.6}",
        "{name: x, type: max_speed, robot: r1, max: 0.3}",
    ),
    (
        "max_tilt",
        "{name: x, type: max_tilt, robot: r2, max: 0.05}",
        "{name: x, type: max_tilt, robot: r1, max: 0.0001}",
    ),
    (
        "distance_traveled",
        "{name: x, type: distance_traveled, robot: r1, min: 1.5, max: 3.0}",
        "{name: x, type: distance_traveled, robot: r1, min: 5}",
    ),
]


@pytest.mark.timeout(60)
@pytest.mark.parametrize(("kind", "good", "bad"), CASES, ids=[c[0] for c in CASES])
def test_each_kind_passes_and_fails(write_scenario, kind: str, good: str, bad: str):
    ok = _judge(write_scenario, f"  - {good}", "good.yaml")["x"]
    assert ok.passed, ok
    fail = _judge(write_scenario, f"  - {bad}", "bad.yaml")["x"]
    assert not fail.passed, fail
    assert fail.t_ns is not None and fail.value and fail.bound


@pytest.mark.timeout(30)
@pytest.mark.parametrize(
    ("expr", "found"),
    [
        ("__import__('os').system('true')", "call"),
        ("ranges.__class__", "__class__"),
        ("open('x')", "open"),
        ("[r for r in ranges]", "comprehension"),
        ("ranges.min(axis=0) > 1", "keyword"),
        ("rangez.min() > 1", "rangez"),
    ],
)
def test_unsafe_or_wrong_expressions_are_rejected_at_validate_time(write_scenario, expr: str, found: str):
    text = BASE.format(assertions=f'  - {{name: x, type: message, topic: r1/scan, expr: "{expr}"}}')
    with pytest.raises(ScenarioError) as e:
        plan_of(write_scenario(text))
    rendered = e.value.render()
    assert "assertions[0].expr" in rendered and ":" in rendered.split(" ")[0]
    assert found.lower() in rendered.lower(), rendered


SCENARIO_FILE = BASE


@pytest.mark.timeout(120)
def test_live_and_offline_judgements_agree_and_junit_names_the_failure(write_scenario, tmp_path: Path):
    assertions = (
        "\n".join(f"  - {c[2].replace('name: x', 'name: ' + c[0])}" for c in CASES)
        + "\n"
        + "\n".join(f"  - {c[1].replace('name: x', 'name: ok_' + c[0])}" for c in CASES)
    )
    path = write_scenario(SCENARIO_FILE.format(assertions=assertions))
    mcap, junit, res = tmp_path / "a.mcap", tmp_path / "junit.xml", tmp_path / "r.json"
    live = run_cli("run", str(path), "--record", str(mcap), "--junit", str(junit), "--results-json", str(res))
    assert live.returncode == 1, live.stderr  # some assertions fail by design
    live_results = {r["name"]: r for r in json.loads(res.read_text())["results"]}
    offline = run_cli("check", str(mcap), "--scenario", str(path), "--junit", str(tmp_path / "off.xml"))
    assert offline.returncode == 1
    off = ET.parse(tmp_path / "off.xml").getroot()
    on = ET.parse(junit).getroot()
    assert on.tag == "testsuites" and on[0].tag == "testsuite"

    def verdicts(root: ET.Element) -> dict[str, str | None]:
        return {
            c.get("name"): (c.find("failure").get("message") if c.find("failure") is not None else None)  # type: ignore[union-attr,misc]
            for c in root.iter("testcase")
        }

    assert verdicts(on) == verdicts(off)  # same verdicts, same times and values
    for name, r in live_results.items():
        assert r["passed"] == name.startswith("ok_"), (name, r)
    reach = verdicts(on)["reach"]
    assert reach is not None and "reach" in reach and "t=" in reach and "closest" in reach
    # a failed run leaves a trajectory plot beside its recording
    png = mcap.with_suffix(".trajectory.png")
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    from PIL import Image

    from runner.tools.pictures import rgb255, run_colours
    from runner.tools.plot import FAILED, INK

    rgb = np.asarray(Image.open(png).convert("RGB")).astype(int)
    r1, r2 = (rgb255(run_colours(plan_of(path))[n]) for n in ("r1", "r2"))
    assert r1 != r2  # two robots from one file, one colour of their own: r2 takes another

    def count(colour: tuple[int, int, int]) -> int:
        return int((np.abs(rgb - colour).max(axis=2) <= 8).sum())

    # r1's and r2's paths, the failed regions and the crosses where pose assertions failed
    assert count(r1) > 100 and count(r2) > 50 and count(FAILED) > 100 and count(INK) > 50


@pytest.mark.timeout(120)
def test_stop_on_first_failure_ends_the_run_early(write_scenario, tmp_path: Path):
    text = (
        BASE.format(
            assertions="  - {name: slow, type: max_speed, robot: r1, max: 0.3}\n"
            "  - {name: stays, type: stay_within, robot: r2, region: {center: [0, 2], radius: 0.1}}"
        ).replace("duration: 6.0", "duration: 60.0")
        + "stop_on: first_failure\n"
    )
    path = write_scenario(text)
    res = tmp_path / "r.json"
    proc = run_cli("run", str(path), "--no-record", "--results-json", str(res))
    assert proc.returncode == 1, proc.stderr
    assert "stopped:" in proc.stdout  # ended by the judge, not by the duration
    sim = float(proc.stdout.split("stopped: ")[1].split(" s sim")[0])
    # r1 exceeds 0.3 m/s within a sim second; the run ends soon after, not at 60 s (at rate: max the world
    # runs on ~100x real time while the judge's word travels: under load that is several sim seconds)
    assert sim < 30.0
    results = {r["name"]: r for r in json.loads(res.read_text())["results"]}
    assert not results["slow"]["passed"] and results["slow"]["t"] < 2.0


@pytest.mark.timeout(400)
@pytest.mark.parametrize(
    "example",
    # In-process, without node processes: an example driven by a node (`nodes:`) is judged by its real
    # run instead (tests/test_nodes.py::test_the_go_to_goal_example_reaches_its_goal).
    sorted(
        p.stem
        for p in (Path(__file__).parents[1] / "scenarios").glob("*.yaml")
        if "\nnodes:" not in p.read_text()
    ),
)
def test_live_and_recorded_judgements_agree_on_every_example(example: str, tmp_path: Path):
    """Every example, run in-process (cameras shrunk, rates as declared): the judge fed message by message
    as the live run feeds it, and the judge reading the MCAP the real recorder wrote, decide alike."""
    from runner.record import Recorder
    from runner.tools.report import judge_recording
    from tests.test_seeds import _shrunk_plan

    plan = _shrunk_plan(example)
    bus = MemoryBus()
    World(plan, bus).run()
    live = judge_for(plan)
    assert live is not None
    rec = Recorder(tmp_path / "x.mcap", [f"{plan.name}/**"])
    for key, type_name, payload, att in bus.sent:
        stamp = unpack_attachment(att)
        rec.write(key, type_name, payload, stamp)
        if key in live.keys:
            live.feed(key, stamp[1], msgs.decode(payload, type_name))  # type: ignore[index]
    rec.close()
    on = live.finish(plan.duration_ns)
    off, _, _ = judge_recording(plan, tmp_path / "x.mcap")
    assert [r.to_json() for r in on] == [r.to_json() for r in off]
    assert all(r.passed for r in on), [r for r in on if not r.passed]


MATRIX = (
    BASE.format(assertions="  - {name: not_too_fast, type: max_speed, robot: r1, max: 0.45}").replace(
        "duration: 6.0", "duration: 2.0"
    )
    + """matrix:
  seed: [1, 2]
  timeline[0].data.linear.x: [0.3, 0.6]
"""
)


@pytest.mark.timeout(200)
def test_matrix_variants_are_run_and_reported_apart(write_scenario, tmp_path: Path):
    path = write_scenario(MATRIX)
    proc = run_cli("validate", str(path))
    assert proc.returncode == 0 and "4 variants" in proc.stdout, proc.stdout + proc.stderr
    junit = tmp_path / "m.xml"
    proc = run_cli("test", str(path), "-j", "2", "--no-record", "--junit", str(junit), timeout=180)
    assert proc.returncode == 1  # the fast variants break the speed bound
    suites = {s.get("name"): s for s in ET.parse(junit).getroot().findall("testsuite")}
    assert set(suites) == {
        f"scenario[seed={seed},timeline[0].data.linear.x={v}]" for seed in (1, 2) for v in (0.3, 0.6)
    }
    for name, s in suites.items():
        failed = s.find("testcase/failure") is not None
        assert failed == name.endswith("=0.6]"), name


def test_a_bad_matrix_path_is_a_clear_error(write_scenario):
    path = write_scenario(MATRIX.replace("timeline[0].data.linear.x", "timeline[5].data.linear.x"))
    proc = run_cli("validate", str(path))
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    assert "matrix.timeline[5].data.linear.x" in proc.stderr and "does not lead to a value" in proc.stderr


@pytest.mark.timeout(120)
def test_check_judges_one_variant_of_a_matrix(write_scenario, tmp_path: Path):
    path = write_scenario(MATRIX)
    mcap = tmp_path / "v.mcap"
    proc = run_cli("run", str(path), "--variant", "3", "--record", str(mcap), "-q")
    assert proc.returncode == 1  # variant 3 drives at 0.6 m/s
    unnamed = run_cli("check", str(mcap), "--scenario", str(path))
    assert unnamed.returncode == 1
    assert "4 variants" in unnamed.stderr and "--variant" in unnamed.stderr
    proc = run_cli("check", str(mcap), "--scenario", str(path), "--variant", "3")
    assert proc.returncode == 1 and "not_too_fast" in proc.stdout and "FAIL" in proc.stdout
