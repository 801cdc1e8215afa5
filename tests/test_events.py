"""Events (`events:`): each trigger kind, the order of events within one step, and determinism, on
in-process runs (real MuJoCo on a MemoryBus, tests/events_helpers.py); one run through the CLI with a node,
where a message trigger reads a node's topic and a fault reaches the node."""

from __future__ import annotations

import json
import math
import textwrap

import numpy as np
import pytest

from runner.checks.judge import Result
from runner.plan import RunPlan
from runner.tools.report import judge_for
from runner.wire import msgs
from runner.wire.transport import unpack_attachment
from tests.conftest import SCENARIOS, read_mcap, run_cli
from tests.events_helpers import Ran, plan_of, problems_of, root, run, scenario_text, yaw_of

DRIVE = """
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.5}}}
"""


def judged(plan: RunPlan, ran: Ran) -> list[Result]:
    """The run judged as the live judge judges it: every message it publishes on the judge's keys."""
    judge = judge_for(plan)
    assert judge is not None
    for key, type_name, payload, att in ran.bus.sent:
        if key in judge.keys:
            judge.feed(key, unpack_attachment(att)[1], msgs.decode(payload, type_name))  # type: ignore[index]
    return judge.finish(ran.stats.sim_ns)


# ------------------------------------------------------------------------------------------- at, after
def test_at_fires_at_its_step_and_after_follows_in_the_same_step_or_its_delay_later(tmp_path):
    ran = run(
        plan_of(
            tmp_path,
            """
            events:
              - {name: a, when: {at: 0.5}, do: [{publish: {topic: hi, type: std_msgs/msg/String}}]}
              - {name: b, when: {after: a}, do: [{publish: {topic: hi2, type: std_msgs/msg/String}}]}
              - name: c
                when: {after: {event: a, delay: 0.25}}
                do: [{publish: {topic: hi3, type: std_msgs/msg/String}}]
              - {name: d, when: {at: 0.503}, do: [{publish: {topic: hi4, type: std_msgs/msg/String}}]}
            """,
            robot=False,
        )
    )
    fired = ran.fired()
    # exact times: a at 0.5; b in a's step; c 0.25 s later; d at the first 2 ms step at or after 0.503
    assert [(f["event"], f["t_ns"]) for f in fired] == [
        ("a", 500_000_000),
        ("b", 500_000_000),
        ("d", 504_000_000),
        ("c", 750_000_000),
    ]
    assert [f["t"] for f in fired] == [0.5, 0.5, 0.504, 0.75]
    assert fired[1]["why"] == "after a" and fired[3]["why"] == "0.25 s after a"
    assert all(f["n"] == 1 for f in fired)
    assert [t for t, _m in ran.on("/hi")] == [500_000_000]  # each did its action, once
    assert [t for t, _m in ran.on("/hi3")] == [750_000_000]


# ------------------------------------------------------------------------------------ enter and leave
def test_enter_and_leave_fire_at_the_first_tick_the_robot_is_in_and_out(tmp_path):
    plan = plan_of(
        tmp_path,
        DRIVE,
        """
        regions:
          home: {min: [-0.3, -0.5], max: [0.2, 0.5]}
          strip: {min: [0.5, -1.0], max: [0.8, 1.0]}
        events:
          - {name: in_home, when: {enter: {body: r1, region: home}}, do: [{end: {result: fail}}]}
          - {name: out_home, when: {leave: {body: r1, region: home}}, do: [{start: dummy}]}
          - {name: in_strip, when: {enter: {body: r1, region: strip}}, do: [{start: dummy}]}
          - {name: out_strip, when: {leave: {body: r1, region: strip}}, do: [{start: dummy}]}
          - name: in_circle
            when: {enter: {body: r1, region: {center: [1.0, 0.0], radius: 0.1}}}
            do: [{start: dummy}]
        world:
          actors: [{name: dummy, pose: {xyz: [0, 9, 0]}, start: event}]
        """,
        duration=3.0,
    )
    ran = run(plan, lambda w: w.data.xpos[w.model.body(root(w)).id, :2].copy())
    xs = {ns / 1e9: float(p[0]) for ns, p in ran.samples}

    def first(cond):  # the first 10 ms tick where the robot's root is where `cond` says
        return next(round(t, 3) for t, x in sorted(xs.items()) if cond(x))

    # r1 starts inside `home`: the first look sets where it is, so `in_home` (which would end the run
    # failed) never fires; leaving it does
    assert ran.times("in_home") == []
    assert ran.times("out_home") == [first(lambda x: x > 0.2)]
    assert ran.times("in_strip") == [first(lambda x: x >= 0.5)]
    assert ran.times("out_strip") == [first(lambda x: x > 0.8)]
    assert ran.times("in_circle") == [first(lambda x: x >= 0.9)]
    assert 0.9 < ran.times("in_strip")[0] < ran.times("out_strip")[0] < ran.times("in_circle")[0] < 3.0
    assert ran.stats.ended is None
    why = next(f["why"] for f in ran.fired() if f["event"] == "in_strip")
    assert why.startswith("r1 entered strip at (0.5")


def test_spatial_triggers_look_every_10_ms_whatever_the_physics_step(tmp_path):
    """With a 3 ms step (not a divisor of 10 ms) a region is looked at on the first step of each tick,
    not only where both meet (every 30 ms)."""
    plan = plan_of(
        tmp_path,
        DRIVE,
        """
        world: {physics: {timestep: 0.003}}
        events:
          - {name: in_strip, when: {enter: {body: r1, region: {min: [0.5, -1], max: [0.8, 1]}}}, do: [{end: {result: pass}}]}
        """,
        duration=3.0,
    )
    ran = run(plan, lambda w: float(w.data.xpos[w.model.body(root(w)).id, 0]))
    t = ran.times("in_strip")
    assert len(t) == 1
    # the step of the tick the robot is first seen in it: within one 10 ms tick (+ a 3 ms step) of the
    # first clock sample (every 10 ms) where it is in
    first = next(ns / 1e9 for ns, x in ran.samples if x >= 0.5)
    assert first - 0.013 <= t[0] <= first + 1e-9


# ----------------------------------------------------------------------------------------------- near
def test_near_a_point_and_another_body_as_an_actor_walks_toward_a_robot(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        world:
          actors:
            - {name: walker, waypoints: [[4, 0], [1.2, 0]], speed: 1.0}
        events:
          - {name: near_robot, when: {near: {body: walker, to: r1, within: 2.0}}, do: [{stop: walker}]}
          - {name: near_point, when: {near: {body: walker, to: [3.0, 0.0], within: 0.5}}, do: [{start: walker}]}
          - {name: robot_near_point, when: {near: {body: r1, to: [0, 0], within: 0.3}}, do: [{start: walker}]}
        """,
        duration=3.0,
    )
    ran = run(
        plan,
        lambda w: (
            w.data.xpos[w.model.body("walker").id, :2].copy(),
            w.data.xpos[w.model.body(root(w)).id, :2].copy(),
        ),
    )

    def first(cond):
        return next(round(ns / 1e9, 3) for ns, (a, r) in ran.samples if cond(a, r))

    # the walker's own clock starts at 0: it is at 4 - t; a trigger sees where the last tick put it
    t_point = ran.times("near_point")
    t_robot = ran.times("near_robot")
    assert t_point == [first(lambda a, r: math.hypot(a[0] - 3.0, a[1]) <= 0.5)]
    assert t_point[0] == pytest.approx(0.51, abs=0.011)
    assert t_robot == [first(lambda a, r: math.hypot(*(a - r)) <= 2.0)]
    assert t_robot[0] == pytest.approx(2.0, abs=0.03)
    # r1 starts within 0.3 m of the origin: `near` fires at the first look (it is near; not a change)
    assert ran.times("robot_near_point") == [0.0]
    # and near_robot stopped the walker: it stands ~2 m from r1 to the end
    walker, robot = ran.samples[-1][1]
    assert math.hypot(*(walker - robot)) == pytest.approx(2.0, abs=0.02)


# -------------------------------------------------------------------------------------------- message
def test_message_fires_at_the_first_message_that_matches(tmp_path):
    plan = plan_of(
        tmp_path,
        DRIVE,
        """
        events:
          - name: moved
            when: {message: {topic: r1/odom, expr: pose.pose.position.x > 0.3}}
            do: [{publish: {topic: moved, type: std_msgs/msg/String, data: {data: moved}}}]
          - name: never
            when: {message: {topic: r1/odom, expr: pose.pose.position.x > 50}}
            do: [{end: {result: fail}}]
        """,
    )
    ran = run(plan)
    first = next(t for t, m in ran.on("r1/odom") if m.pose.pose.position.x > 0.3)
    fired = ran.fired()
    assert [(f["event"], f["t_ns"]) for f in fired] == [("moved", first)]
    assert fired[0]["why"] == "`pose.pose.position.x > 0.3` on r1/odom"
    assert [(t, m.data) for t, m in ran.on("/moved")] == [(first, "moved")]


# ------------------------------------------------------------------------------------------ assertion
def test_assertion_becoming_fail_or_pass_fires_when_the_judge_decides(tmp_path):
    plan = plan_of(
        tmp_path,
        DRIVE,
        """
        world:
          models:
            - {name: wall, shape: box, size: [0.2, 4, 0.5], pose: {xyz: [1.2, 0, 0.25]}}
        assertions:
          - {name: no_hit, type: no_collision, between: [r1, wall]}
          - {name: stays, type: stay_within, robot: r1, region: {min: [-1, -1], max: [0.4, 1]}}
          - {name: gets_there, type: reach, robot: r1, point: [0.6, 0], tolerance: 0.05}
        events:
          - {name: hit, when: {assertion: {assertion: no_hit}}, do: [{publish: {topic: hit, type: std_msgs/msg/Empty}}]}
          - {name: out, when: {assertion: {assertion: stays, becomes: fail}}, do: [{publish: {topic: out, type: std_msgs/msg/Empty}}]}
          - {name: there, when: {assertion: {assertion: gets_there, becomes: pass}}, do: [{publish: {topic: there, type: std_msgs/msg/Empty}}]}
          - {name: never, when: {assertion: {assertion: no_hit, becomes: pass}}, do: [{end: {result: fail}}]}
        """,
        duration=4.0,
    )
    ran = run(plan)
    results = {r.name: r for r in judged(plan, ran)}
    assert results["no_hit"].status == "fail" and results["stays"].status == "fail"
    assert results["gets_there"].status == "pass"
    # each event at the step its assertion was decided (the judge's time)
    assert ran.times("hit") == [results["no_hit"].t_ns / 1e9]
    assert ran.times("out") == [results["stays"].t_ns / 1e9]
    assert ran.times("there") == [results["gets_there"].t_ns / 1e9]
    assert 0.5 < ran.times("out")[0] < ran.times("there")[0] < ran.times("hit")[0] < 4.0
    assert ran.times("never") == [] and ran.stats.ended is None
    assert "no_hit" in next(f["why"] for f in ran.fired() if f["event"] == "hit")


# --------------------------------------------------------------------------------------------- repeat
def test_repeat_fires_each_time_the_trigger_holds_anew_once_fires_once(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        world:
          actors:   # 0 -> 2 -> 0 on y = 3 at 2 m/s: through x = 1 at 0.5, 1.5, 2.5, 3.5 s
            - {name: pacer, waypoints: [[0, 3], [2, 3]], speed: 2.0, loop: true}
        regions:
          gate: {min: [0.95, 2.5], max: [1.05, 3.5]}
        events:
          - {name: each, repeat: true, when: {enter: {body: pacer, region: gate}}, do: [{publish: {topic: e, type: std_msgs/msg/Empty}}]}
          - {name: once, when: {enter: {body: pacer, region: gate}}, do: [{publish: {topic: o, type: std_msgs/msg/Empty}}]}
          - {name: follows, repeat: true, when: {after: each}, do: [{publish: {topic: f, type: std_msgs/msg/Empty}}]}
        """,
        duration=4.0,
    )
    ran = run(plan)
    each = ran.times("each")
    assert len(each) == 4
    assert each == pytest.approx([0.49, 1.49, 2.49, 3.49], abs=0.011)
    assert [f["n"] for f in ran.fired() if f["event"] == "each"] == [1, 2, 3, 4]
    assert ran.times("once") == each[:1]
    assert ran.times("follows") == each
    assert len(ran.on("/e")) == 4 and len(ran.on("/o")) == 1


# ------------------------------------------------------------------------------- order within a step
def test_events_set_off_in_a_step_fire_in_it_in_topological_order(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        events:
          - {name: x, when: {after: y}, do: [{publish: {topic: from_x, type: std_msgs/msg/String, data: {data: x}}}]}
          - {name: w, when: {message: {topic: from_z, expr: "data == 'z'"}}, do: [{publish: {topic: from_w, type: std_msgs/msg/String}}]}
          - {name: y, when: {at: 0.3}, do: [{publish: {topic: from_y, type: std_msgs/msg/String, data: {data: y}}}]}
          - {name: z, when: {message: {topic: from_y, expr: "data == 'y'"}}, do: [{publish: {topic: from_z, type: std_msgs/msg/String, data: {data: z}}}]}
          - {name: v, when: {message: {topic: from_x, expr: "data == 'x'"}}, do: [{end: {result: pass, message: all done}}]}
        """,
        robot=False,
    )
    # the plan's order: y first (nothing sets it off), then what it sets off, each after its cause
    order = [e.name for e in plan.events]
    assert order.index("y") < order.index("x") < order.index("v")
    assert order.index("y") < order.index("z") < order.index("w")
    ran = run(plan)
    fired = ran.fired()
    assert [f["event"] for f in fired] == order
    assert {f["t_ns"] for f in fired} == {300_000_000}  # all in y's step
    assert ran.stats.sim_ns == 300_000_000 and "all done" in (ran.stats.ended or "")
    # the `_events` messages were published in the order the events fired, numbered in sequence
    seqs = [unpack_attachment(att)[0] for key, _t, _p, att in ran.bus.sent if key.endswith("/_events")]
    assert seqs == list(range(len(order)))
    assert fired[-1]["end"] == {"result": "pass", "message": "all done"}


# ------------------------------------------------------------------------------------------- end
@pytest.mark.parametrize("result", ["pass", "fail"])
def test_end_stops_the_world_at_its_step_and_the_judge_gets_the_result(tmp_path, result):
    plan = plan_of(
        tmp_path,
        DRIVE,
        f"""
        events:
          - {{name: stop_now, when: {{at: 1.234}}, do: [{{end: {{result: {result}, message: said so}}}}]}}
        """,
        duration=5.0,
    )
    ran = run(plan)
    assert ran.stats.sim_ns == 1_234_000_000
    assert ran.stats.ended == f"event stop_now: {result} (said so)"
    assert max(t for t, _m in ran.on("/clock")) <= 1_234_000_000
    (res,) = judged(plan, ran)
    assert (res.name, res.type, res.status) == ("event stop_now", "event", result)
    assert res.t_ns == 1_234_000_000 and "said so" in res.message


# ------------------------------------------------------------------------------------- determinism
def test_the_same_plan_runs_the_same_twice(tmp_path):
    plan = plan_of(
        tmp_path,
        DRIVE,
        """
        world:
          actors:
            - {name: walker, waypoints: [[3, 1], [3, -1]], speed: 0.7, loop: true, start: event}
        events:
          - {name: go, when: {near: {body: r1, to: [0.4, 0], within: 0.1}}, do: [{start: walker}]}
          - name: noisy
            when: {at: 0.5}
            do:
              - {fault: {topic: r1/scan, noise: 0.05, duration: 1.0}}
              - {fault: {topic: r1/odom, drop: 0.5}}
          - {name: kick, when: {after: {event: go, delay: 0.3}}, do: [{impulse: {body: r1, linear: [0, 0.5, 0]}}]}
        """,
        duration=3.0,
    )
    a, b = run(plan), run(plan)
    assert a.fired() == b.fired() and len(a.fired()) == 3
    assert a.bus.sent == b.bus.sent
    assert np.array_equal(a.world.data.qpos, b.world.data.qpos)
    assert np.array_equal(a.world.data.mocap_pos, b.world.data.mocap_pos)


# ------------------------------------------------------------------------------ through the CLI, a node
@pytest.mark.timeout(90)
def test_a_fault_reaches_a_node_and_its_answer_sets_off_an_event(tmp_path):
    """Through `scenario run` with the corridor driver node (lockstep): a scan fault at 1 s starves its
    lidar watchdog, which says `lidar stale` on `status` 0.5 s later; an event on that message ends the
    run passed. The recording holds the firings on `_events`, and no scan during the fault."""
    node = SCENARIOS / "nodes" / "corridor_driver.py"
    text = scenario_text(
        f"""
        nodes:
          - {{name: driver, cmd: python {node}, namespace: r1, publishes: {{status: std_msgs/msg/String}}}}
        lockstep: [driver]
        events:
          - {{name: blind, when: {{at: 1.0}}, do: [{{fault: {{topic: r1/scan, drop: true}}}}]}}
          - name: noticed
            when: {{message: {{topic: r1/status, expr: "data == 'lidar stale'"}}}}
            do: [{{end: {{result: pass, message: the watchdog saw it}}}}]
        """,
        duration=5.0,
    )
    path = tmp_path / "s.yaml"
    path.write_text(text)
    mcap = tmp_path / "out.mcap"
    proc = run_cli("run", str(path), "--record", str(mcap), timeout=80)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "event noticed" in proc.stdout + proc.stderr
    rec = read_mcap(mcap)
    fired = [json.loads(m.data) for topic, _t, _ns, m in rec if topic.endswith("_events")]
    assert [f["event"] for f in fired] == ["blind", "noticed"]
    assert fired[0]["t"] == 1.0
    # the node's watchdog: no scan for more than 0.5 s, checked every 0.1 s
    assert 1.5 <= fired[1]["t"] <= 1.75
    scans = [ns for topic, _t, ns, _m in rec if topic.endswith("r1/scan")]
    assert scans and max(scans) <= 1_000_000_000


# ------------------------------------------------------------------------------------ publish, set
def test_publish_drives_the_robot_through_its_plugin(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        events:
          - name: go
            when: {at: 0.2}
            do: [{publish: {topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.5}}}}]
        """,
    )
    ran = run(plan, lambda w: float(w.data.xpos[w.model.body(root(w)).id, 0]))
    assert [t for t, _m in ran.on("r1/cmd_vel")] == [200_000_000]
    assert abs(ran.sample(0.2) - ran.sample(0.0)) < 0.002  # standing until then
    assert ran.sample(2.0) - ran.sample(0.2) > 0.6  # then driving at ~0.5 m/s


def test_set_changes_the_lidar_rate_its_noise_and_blinds_a_sector(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        world:
          models:   # r1 in a box of walls: every beam returns
            - {name: n, shape: box, size: [6, 0.1, 1], pose: {xyz: [0, 1.5, 0.5]}}
            - {name: s, shape: box, size: [6, 0.1, 1], pose: {xyz: [0, -1.5, 0.5]}}
            - {name: e, shape: box, size: [0.1, 3, 1], pose: {xyz: [2, 0, 0.5]}}
            - {name: w, shape: box, size: [0.1, 3, 1], pose: {xyz: [-2, 0, 0.5]}}
        events:
          - {name: faster, when: {at: 1.0}, do: [{set: {robot: r1, plugin: lidar, param: rate, value: 20}}]}
          - {name: noisy, when: {at: 1.5}, do: [{set: {robot: r1, plugin: lidar, param: noise_stddev, value: 0.05}}]}
          - name: muddy
            when: {at: 2.0}
            do: [{set: {robot: r1, plugin: lidar, param: blind_sectors, value: [[-0.5, 0.5]]}}]
        """,
        duration=2.5,
    )
    ran = run(plan)
    scans = ran.on("r1/scan")
    stamps = [t for t, _m in scans]
    gaps = np.diff(stamps)
    assert set(gaps[np.array(stamps[1:]) <= 1_000_000_000]) == {100_000_000}  # 10 Hz
    assert set(gaps[np.array(stamps[:-1]) >= 1_000_000_000]) == {50_000_000}  # 20 Hz from 1.0 s
    ranges = {t: np.asarray(m.ranges, dtype=float) for t, m in scans}
    quiet = ranges[1_400_000_000]
    assert np.isfinite(quiet).all()
    assert np.allclose(quiet, ranges[1_000_000_000], atol=1e-4)  # no noise: the same scan
    noisy = ranges[1_950_000_000] - quiet
    assert 0.03 < float(np.std(noisy)) < 0.07  # noise_stddev 0.05 from 1.5 s
    blind = ranges[2_500_000_000]
    angles = scans[-1][1].angle_min + scans[-1][1].angle_increment * np.arange(len(blind))
    inside = np.abs(angles) <= 0.5
    assert inside.sum() >= 10
    assert np.isinf(blind[inside]).all() and np.isfinite(blind[~inside]).all()
    did = [f["did"] for f in ran.fired()]
    assert did[0] == ["set r1/lidar.rate = 20"]


# ----------------------------------------------------------------------------------------- faults
def _fault_run(tmp_path, fault: str, *, duration: float = 2.0, seed: int = 1):
    return run(
        plan_of(
            tmp_path,
            f"""
            events:
              - {{name: f, when: {{at: 0.5}}, do: [{{fault: {fault}}}]}}
            """,
            duration=duration,
            seed=seed,
        )
    )


def test_fault_drop_all_for_a_while_then_the_topic_comes_back(tmp_path):
    ran = _fault_run(tmp_path, "{topic: r1/scan, drop: true, duration: 0.5}")
    stamps = [t for t, _m in ran.on("r1/scan")]
    # the 0.5 s scan went out before the event (sensors come first in a step); 0.6..1.0 are dropped
    assert stamps == [k * 100_000_000 for k in (0, 1, 2, 3, 4, 5, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20)]
    assert ran.fired()[0]["did"] == ["fault on r1/scan: drop for 0.5 s"]


def test_fault_drop_with_a_probability_is_about_p_and_repeats_with_the_seed(tmp_path):
    counts = []
    for seed in (1, 1, 2):
        ran = _fault_run(tmp_path, "{topic: r1/odom, drop: 0.3}", duration=4.5, seed=seed)
        counts.append([t for t, _m in ran.on("r1/odom")])
    after = [[t for t in c if t > 500_000_000] for c in counts]
    assert after[0] == after[1]  # the same seed: the same messages dropped
    assert after[0] != after[2]
    kept = len(after[0]) / 200  # 4 s of 50 Hz
    assert 0.6 < kept < 0.8


def test_fault_delay_sends_each_message_later_unchanged(tmp_path):
    ran = _fault_run(tmp_path, "{topic: r1/odom, delay: 0.1, duration: 0.5}")
    odom = [(t, m.header.stamp.sec * 10**9 + m.header.stamp.nanosec) for t, m in ran.on("r1/odom")]
    late = [(t, stamp) for t, stamp in odom if t != stamp]
    # every message published in (0.5, 1.0] arrives 0.1 s late, its header stamp the old one, the last
    # ones after the fault ended too
    assert [stamp for _t, stamp in late] == [500_000_000 + k * 20_000_000 for k in range(1, 26)]
    assert {t - stamp for t, stamp in late} == {100_000_000}
    assert sorted(stamp for _t, stamp in odom) == [k * 20_000_000 for k in range(101)]  # none lost


def test_fault_freeze_repeats_the_last_message_and_noise_changes_fields_not_the_header(tmp_path):
    ran = _fault_run(tmp_path, "{topic: r1/odom, freeze: true, duration: 0.5}")
    sent = ran.raw("r1/odom")
    last_before = next(p for t, p in sent if t == 500_000_000)
    during = [p for t, p in sent if 500_000_000 < t <= 1_000_000_000]
    assert len(during) == 25 and set(during) == {last_before}
    assert len({p for t, p in sent if t > 1_000_000_000}) > 1  # it ended: fresh messages again

    ran = _fault_run(tmp_path, "{topic: r1/odom, noise: 0.1, fields: [pose.pose.position.x]}")
    odom = [(t, m) for t, m in ran.on("r1/odom") if t > 500_000_000]
    xs = np.array([m.pose.pose.position.x for _t, m in odom])
    ys = np.array([m.pose.pose.position.y for _t, m in odom])
    assert 0.06 < xs.std() < 0.14 and ys.std() < 1e-3
    assert all(m.header.stamp.sec * 10**9 + m.header.stamp.nanosec == t for t, m in odom)
    assert {m.header.frame_id for _t, m in odom} == {"r1/odom"}


def test_fault_on_the_commands_the_robot_takes_in(tmp_path):
    ran = run(
        plan_of(
            tmp_path,
            """
            timeline:
              - {t: 0.5, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.5}}}
            events:
              - {name: cut_off, when: {at: 0.2}, do: [{fault: {topic: r1/cmd_vel, drop: true}}]}
            """,
        ),
        lambda w: float(w.data.xpos[w.model.body(root(w)).id, 0]),
    )
    assert ran.on("r1/cmd_vel") == [] and abs(ran.sample(2.0)) < 0.01  # the drive never heard it


# ------------------------------------------------------------------------------------ block, cut
@pytest.mark.parametrize("action", ["block", "cut"])
def test_block_jams_a_wheel_and_the_robot_turns_cut_leaves_it_free(tmp_path, action):
    plan = plan_of(
        tmp_path,
        DRIVE,
        f"""
        events:
          - {{name: jam, when: {{at: 1.0}}, do: [{{{action}: {{robot: r1, joint: left_wheel_joint}}}}]}}
        """,
        duration=2.5,
    )

    def probe(w):
        m, d = w.model, w.data
        left = m.joint(f"{w.plan.robots[0].prefix}left_wheel_joint")
        right = m.joint(f"{w.plan.robots[0].prefix}right_wheel_joint")
        bid = m.body(root(w)).id
        acts = [a for a in range(m.nu) if m.actuator_trnid[a, 0] == left.id]
        return (
            float(d.qvel[left.dofadr[0]]),
            float(d.qvel[right.dofadr[0]]),
            yaw_of(d.xquat[bid]),
            float(d.actuator_force[acts[0]]),
        )

    ran = run(plan, probe)
    left, right, yaw, force = ran.sample(0.99)
    assert left > 5 and right > 5 and abs(yaw) < 0.02 and force != 0.0  # straight on, both driven
    left, right, yaw, force = ran.sample(2.5)
    assert right > 5
    assert force == 0.0  # no torque from its motor
    if action == "block":
        assert abs(left) < 0.3  # jammed: it skids
        assert yaw > 1.0  # pivoting about the jammed wheel
    else:
        assert left > 3  # free: it rolls along
        forces = [f for ns, (_l, _r, _y, f) in ran.samples if ns > 1_000_000_000]
        assert set(forces) == {0.0}


# ------------------------------------------------------------------------------------- validation
MISTAKES = """
world:
  actors:
    - {name: walker, waypoints: [[3, 1], [3, -1]], start: event}
regions:
  dock: {min: [1, 1], max: [2, 2]}
assertions:
  - {name: no_hit, type: no_collision, between: [r1, walker]}
nodes:
  - {name: talker, cmd: python -c pass, namespace: r1, publishes: {status: std_msgs/msg/String}}
events:
  - {name: e0, when: {near: {body: ghost, to: [0, 0], within: 1}}, do: [{start: walker}]}
  - {name: e1, when: {enter: {body: r1, region: harbour}}, do: [{start: runner}]}
  - {name: e2, when: {at: 1}, do: [{fault: {topic: r1/nothing, drop: true}}, {fault: {topic: r1/status, drop: true}}]}
  - {name: e3, when: {message: {topic: r1/nope, expr: data == 'x'}}, do: [{set: {robot: r1, plugin: radar, param: rate, value: 5}}]}
  - {name: e4, when: {at: 1}, do: [{set: {robot: r1, plugin: lidar, param: samples, value: 5}}]}
  - {name: e5, when: {at: 1}, do: [{block: {robot: r1, joint: third_wheel}}]}
  - {name: e6, when: {assertion: {assertion: no_such}}, do: [{start: walker}]}
  - {name: e7, when: {after: e99}, do: [{start: walker}]}
  - {name: e8, when: {message: {topic: r1/status, expr: data == 'go'}}, do: [{start: walker}]}
"""


def test_every_unknown_name_in_events_is_a_located_problem_all_at_once(tmp_path):
    problems = problems_of(tmp_path, MISTAKES)
    by_path = {tuple(p.path): p for p in problems}
    assert set(by_path) == {
        ("events", 0, "when", "near", "body"),
        ("events", 1, "when", "enter", "region"),
        ("events", 1, "do", 0, "start"),
        ("events", 2, "do", 0, "fault", "topic"),
        ("events", 2, "do", 1, "fault", "topic"),
        ("events", 3, "when", "message", "topic"),
        ("events", 3, "do", 0, "set", "plugin"),
        ("events", 4, "do", 0, "set", "param"),
        ("events", 5, "do", 0, "block", "joint"),
        ("events", 6, "when", "assertion", "assertion"),
        ("events", 7, "when", "after", "event"),
    }  # (e8: a message trigger on a node's declared topic is fine)
    p = by_path["events", 0, "when", "near", "body"]
    assert "ghost" in p.message and "r1" in (p.expected or "") and "walker" in (p.expected or "")
    assert p.hint and p.location.line == MISTAKES.splitlines().index(
        next(x for x in MISTAKES.splitlines() if "ghost" in x)
    ) + 1 + len(scenario_text().splitlines())
    assert "dock" in (by_path["events", 1, "when", "enter", "region"].expected or "")
    assert "walker" in (by_path["events", 1, "do", 0, "start"].expected or "")
    nothing = by_path["events", 2, "do", 0, "fault", "topic"]
    assert "r1/nothing" in nothing.message and "r1/scan" in (nothing.expected or "") and nothing.hint
    assert "node publishes it" in (by_path["events", 2, "do", 1, "fault", "topic"].hint or "")
    assert "lidar" in (by_path["events", 3, "do", 0, "set", "plugin"].expected or "")
    live = by_path["events", 4, "do", 0, "set", "param"]
    assert "cannot change while it runs" in live.message
    assert "noise_stddev" in (live.expected or "") and "blind_sectors" in (live.expected or "")
    assert "left_wheel_joint" in (by_path["events", 5, "do", 0, "block", "joint"].expected or "")
    assert "no_hit" in (by_path["events", 6, "when", "assertion", "assertion"].expected or "")
    assert "e0" in (by_path["events", 7, "when", "after", "event"].expected or "")


@pytest.mark.parametrize(
    ("events", "ring"),
    [
        (
            """
            - {name: a, when: {after: b}, do: [{publish: {topic: x, type: std_msgs/msg/Empty}}]}
            - {name: b, when: {after: a}, do: [{publish: {topic: y, type: std_msgs/msg/Empty}}]}
            """,
            ["a -> b -> a", "b -> a -> b"],
        ),
        (
            """
            - {name: start, when: {at: 1}, do: [{publish: {topic: ping, type: std_msgs/msg/String}}]}
            - name: pong
              when: {message: {topic: ping, expr: "data == ''"}}
              do: [{publish: {topic: pong, type: std_msgs/msg/String}}]
            - name: ping
              when: {message: {topic: pong, expr: "data == ''"}}
              do: [{publish: {topic: ping, type: std_msgs/msg/String}}]
            """,
            ["pong -> ping -> pong", "ping -> pong -> ping"],
        ),
    ],
    ids=["after", "message"],
)
def test_a_ring_of_events_in_one_step_is_refused_and_named(tmp_path, events, ring):
    (p,) = problems_of(tmp_path, "events:\n" + textwrap.indent(textwrap.dedent(events), "  "), robot=False)
    assert "set each other off in the same step" in p.message
    assert any(r in p.message for r in ring), p.message
    assert p.path[0] == "events" and p.path[-1] == "when" and "delay" in (p.hint or "")
    assert p.location.line > 0


def test_a_ring_broken_by_a_delay_is_accepted_and_runs(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        events:
          - {name: tick, repeat: true, when: {after: {event: tock, delay: 0.5}}, do: [{publish: {topic: t, type: std_msgs/msg/Empty}}]}
          - {name: tock, repeat: true, when: {after: tick}, do: [{publish: {topic: u, type: std_msgs/msg/Empty}}]}
          - {name: go, when: {at: 0.1}, do: [{publish: {topic: v, type: std_msgs/msg/Empty}}]}
          - {name: kick, when: {after: go}, do: [{end: {result: pass}}]}
        """,
        robot=False,
    )
    assert [e.name for e in plan.events].index("tick") < [e.name for e in plan.events].index("tock")


def test_events_with_several_worlds_are_refused(tmp_path):
    problems = problems_of(
        tmp_path,
        """
        worlds:
          - {name: a}
          - {name: b}
        events:
          - {name: e, when: {at: 1}, do: [{end: {result: pass}}]}
        """,
        robot=False,
    )
    (p,) = [p for p in problems if tuple(p.path) == ("events",)]
    assert "single world" in p.message and "worlds:" in (p.hint or "")


@pytest.mark.timeout(60)
def test_scenario_validate_reports_the_events_mistakes_with_their_lines(tmp_path):
    path = tmp_path / "bad.yaml"
    text = scenario_text(MISTAKES)
    path.write_text(text)
    proc = run_cli("validate", str(path))
    assert proc.returncode != 0
    out = proc.stdout + proc.stderr
    lines = text.splitlines()

    def line_of(needle: str) -> int:
        return next(i for i, x in enumerate(lines, 1) if needle in x)

    assert f"bad.yaml:{line_of('ghost')}:" in out and "events[0].when.near.body" in out
    assert f"bad.yaml:{line_of('third_wheel')}:" in out and "events[5].do[0].block.joint" in out
    assert "expected:" in out and "hint:" in out
    assert out.count("events[") >= 11
    assert "Traceback" not in out
