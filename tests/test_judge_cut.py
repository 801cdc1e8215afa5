"""The judge never decides on missing data: when the recording or the judge's feed stops before the run's
end (a full disk, a file cut by a kill), what needs the time after the cut is not decided, saying where
and why; what was decided before the cut keeps its verdict."""

from __future__ import annotations

import resource
import signal
import subprocess
from pathlib import Path

import pytest

from runner.sim.world import World
from runner.tools.report import judge_for
from runner.wire import msgs
from runner.wire.transport import MemoryBus, unpack_attachment
from tests.conftest import REPO, run_cli, scenario_cmd
from tests.helpers import plan_of

# r1 drives +x at 0.5 m/s from (0, 0): it is at x=0.25 near t=0.5 s and at x=1.5 near t=3 s
DRIVE = """
name: cut
duration: 6.0
rate: max
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins: [{type: diff_drive}]
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.5}}}
assertions:
  - {name: far, type: reach, robot: r1, point: [1.5, 0], tolerance: 0.2, by: 5}
  - {name: near, type: reach, robot: r1, point: [0.25, 0], tolerance: 0.1}
  - {name: slow, type: max_speed, robot: r1, max: 0.2}
  - {name: early_speed, type: max_speed, robot: r1, max: 5, until: 1}
  - {name: upright, type: max_tilt, robot: r1, max: 0.5}
"""

CUT_NS = 1_500_000_000


def test_a_judge_whose_data_stops_decides_nothing_after_the_cut(write_scenario) -> None:
    """The world ran to 6 s but the judge's data stopped at 1.5 s (the recording it reads could not be
    written past there): `far` (reached near t=3 s, by 5) used to fail "not reached, closest ..." on the
    partial data, a verdict the full run contradicts. Now it is not decided, saying where the data
    stopped and why; `near` (reached), `slow` (broken) and `early_speed` (its window ends before the
    cut) keep their verdicts; `upright` (to the end) is not decided."""
    plan = plan_of(write_scenario(DRIVE))
    bus = MemoryBus()
    World(plan, bus).run()

    def judged(cut: bool) -> dict[str, object]:
        judge = judge_for(plan)
        assert judge is not None
        for key, type_name, payload, att in bus.sent:
            t = unpack_attachment(att)[1]  # type: ignore[index]
            if t <= CUT_NS and key in judge.keys:
                judge.feed(key, t, msgs.decode(payload, type_name))
        if cut:
            judge.data_stops(CUT_NS, "the recording stops at t=1.500 s: No space left on device")
        why = "the run was stopped by an error at t=6.000 s"
        return {r.name: r for r in judge.finish(plan.duration_ns, complete=False, why=why)}

    blind = judged(cut=False)
    assert blind["far"].status == "fail"  # what the judge said before: a false FAIL (the full run passes)
    full = {r.name: r for r in _full(plan, bus)}
    assert full["far"].status == "pass", full["far"].message

    results = judged(cut=True)
    far = results["far"]
    assert far.status == "undecided" and far.t_ns == CUT_NS, (far.message, far.value)
    assert "the recording stops at t=1.500 s: No space left on device" in far.message
    assert results["upright"].status == "undecided"
    assert "the recording stops at t=1.500 s" in results["upright"].message
    assert results["near"].status == "pass" and "reached at t=0." in results["near"].message
    assert results["slow"].status == "fail" and results["slow"].message == "too fast"
    assert results["early_speed"].status == "pass"


def test_a_live_judge_that_got_fewer_messages_than_published_knows_where_its_data_stops(
    write_scenario,
) -> None:
    """The live judge's accounting (runner.launch.parts.JudgePart), on what a real world published: fed
    (as its subscription or the recorder feeds it) the ground truth up to t=1.5 s only, while the world
    says at its end that it published 6 s of it, the judge is told its data on that key stops at the last
    message it got; `far` is not decided (it failed "not reached" before), with how many it got. A judge
    that got every message is told nothing."""
    from types import SimpleNamespace

    from runner.launch.parts import JudgePart

    plan = plan_of(write_scenario(DRIVE))
    bus = MemoryBus()
    World(plan, bus).run()
    published: dict[str, int] = {}
    for key, *_ in bus.sent:
        published[key] = published.get(key, 0) + 1
    run = SimpleNamespace(recorder=None, worlds=[SimpleNamespace(end_info={"published": published})])

    def judged(until_ns: int) -> dict[str, object]:
        judge = judge_for(plan)
        assert judge is not None
        part = JudgePart(judge)
        feed = part.feeder(plan)
        for key, _type_name, payload, att in bus.sent:
            t = unpack_attachment(att)[1]  # type: ignore[index]
            if t <= until_ns and key in judge.keys:
                feed(key, t, payload)
        part.close(run)  # type: ignore[arg-type]
        return {r.name: r for r in judge.finish(plan.duration_ns)}

    starved = judged(CUT_NS)
    far = starved["far"]
    assert far.status == "undecided" and far.t_ns is not None and far.t_ns <= CUT_NS, (far.message, far.value)
    assert "the judge's data stops at t=1.500 s: it received 76 of the" in far.message, far.message
    assert f"76 of the {published['cut/r1/_truth']} messages published on cut/r1/_truth" in far.message
    assert starved["near"].status == "pass" and starved["slow"].status == "fail"
    fed_all = judged(plan.duration_ns)
    assert fed_all["far"].status == "pass" and fed_all["upright"].status == "pass"


def _full(plan, bus: MemoryBus) -> list:  # type: ignore[no-untyped-def]
    judge = judge_for(plan)
    assert judge is not None
    for key, type_name, payload, att in bus.sent:
        if key in judge.keys:
            judge.feed(key, unpack_attachment(att)[1], msgs.decode(payload, type_name))  # type: ignore[index]
    return judge.finish(plan.duration_ns)


@pytest.mark.timeout(180)
def test_a_recording_cut_by_a_kill_is_judged_up_to_its_cut(write_scenario, tmp_path: Path) -> None:
    """A real run's recording cut in the middle of a chunk (as a runner killed without its guard leaves
    it), where it holds the run up to about t=3 s: `scenario check` used to refuse it ("cannot judge it:
    EndOfFile"). Now it judges every whole chunk: `near` (reached early) passes, `slow` fails, and `far`
    (reached near t=4.7 s), `upright` are not decided, saying where the recording stops."""
    from mcap.reader import make_reader

    path = write_scenario(DRIVE.replace("point: [1.5, 0]", "point: [2.5, 0]").replace("by: 5", "by: 5.8"))
    mcap = tmp_path / "run.mcap"
    # at real time the recorder writes a chunk every second of the run (flush_stale): cuts in sim time
    done = run_cli("run", str(path), "--record", str(mcap), "--rate", "realtime", "-q", timeout=150)
    assert done.returncode == 1 and "far" in done.stdout, done.stdout[-2000:] + done.stderr[-2000:]
    assert "pass" in _rows(done.stdout)["far"], done.stdout  # the full run passes `far` (near t=4.7 s)
    with mcap.open("rb") as f:
        chunks = sorted(make_reader(f).get_summary().chunk_indexes, key=lambda c: c.chunk_start_offset)  # type: ignore[union-attr]
    cut_in = next(c for c in chunks if c.message_end_time > 3_000_000_000)
    assert cut_in.message_start_time > 500_000_000  # (`near` is decided in the chunks before the cut)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(mcap.read_bytes()[: cut_in.chunk_start_offset + cut_in.chunk_length // 2])

    checked = run_cli("check", str(cut), "--scenario", str(path), timeout=120)
    out = checked.stdout
    assert "cannot judge" not in checked.stderr and "Traceback" not in checked.stderr, checked.stderr[-2000:]
    assert checked.returncode == 1, out
    rows = _rows(out)
    assert "pass" in rows["near"] and "FAIL" in rows["slow"], out
    assert "not decided" in rows["far"] and "not decided" in rows["upright"], out
    assert "the recording stops at t=" in out and "the file is cut there, unfinished" in out, out


def _rows(table: str) -> dict[str, str]:
    """The rows of the Assertions table, by assertion name."""
    return {line.split("│")[1].strip(): line for line in table.splitlines() if line.count("│") > 3}


FSIZE_LIMIT = 1_000_000  # bytes: two_robots fills it near t=10 s of its 20 s


@pytest.mark.timeout(180)
def test_a_live_judge_starved_by_a_full_disk_says_where_its_data_stopped(tmp_path: Path) -> None:
    """A full disk mid-run (the process's file-size limit fails a write the same way, as in
    test_reliability): the live judge reads the run from the recorder, so its data stops where the
    recording does, while the world runs on until the run stops. Every assertion not decided by then
    says "the recording stops at t=X s: File too large" (it said "the run was stopped by an error at" the
    world's later time, and a deadline between the two was failed on data that never came); the ones
    decided before keep their verdict."""
    text = (REPO / "scenarios" / "two_robots.yaml").read_text()
    text = text.replace("file: robots/", f"file: {REPO / 'scenarios' / 'robots'}/")
    text += (
        "  - {name: r1_moves_off, type: reach, robot: r1, point: [-1.8, -1.0], tolerance: 0.1}\n"
        "  - {name: never_open, type: message, topic: r1/scan, expr: 'ranges.max() > 1.0', mode: never}\n"
    )
    path = tmp_path / "two_robots.yaml"
    path.write_text(text)
    mcap = tmp_path / "full.mcap"

    def small_disk() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails (EFBIG) instead
        resource.setrlimit(resource.RLIMIT_FSIZE, (FSIZE_LIMIT, FSIZE_LIMIT))

    r = subprocess.run(
        scenario_cmd("run", str(path), "--record", str(mcap), "--results-json", str(tmp_path / "r.json")),
        capture_output=True, text=True, timeout=150, preexec_fn=small_disk, cwd=REPO,
    )  # fmt: skip
    assert r.returncode == 1 and "the recording stopped: File too large" in r.stderr, r.stderr[-2000:]
    import json

    suite = json.loads((tmp_path / "r.json").read_text())
    results = {x["name"]: x for x in suite["results"]}
    assert results["r1_moves_off"]["status"] == "pass", results["r1_moves_off"]
    assert results["never_open"]["status"] == "fail", results["never_open"]
    open_ = [x for x in results.values() if x["status"] == "undecided"]
    assert len(open_) >= 5, results
    for x in open_:
        assert "the recording stops at t=" in x["message"] and "File too large" in x["message"], x
        assert x["t"] <= suite["sim_s"], (x, suite["sim_s"])  # where the data stopped, not the world's end
