"""Actors (`world.actors`) and the events' actions on bodies: paths played at their speed or times, looped,
facing where they go, a hinged door; started, stopped and resumed; seen by a lidar and pushing a robot;
teleport, push and impulse on robots, free models and actors. In-process runs (real MuJoCo on a
MemoryBus, tests/events_helpers.py); a probe samples the state every 10 ms of sim time."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.events_helpers import mocap, plan_of, root, run, yaw_of

ZERO_G = """
world:
  physics: {gravity: [0, 0, 0]}
  models:
    - {name: box, shape: box, size: [0.2, 0.2, 0.2], static: false, mass: 2.0, pose: {xyz: [0, 3, 1]}}
"""


def _box(w):  # the free box's position and linear velocity
    bid = w.model.body("box").id
    dof = int(w.model.jnt_dofadr[w.model.body_jntadr[bid]])
    return w.data.xpos[bid].copy(), w.data.qvel[dof : dof + 3].copy()


# ---------------------------------------------------------------------------------------- paths
def test_paths_at_speed_at_given_times_looped_facing_where_they_go_and_a_hinged_door(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        world:
          actors:
            - {name: timed, shape: box, size: [0.2, 0.2, 0.2], waypoints: [{xyz: [0, 5], t: 0}, {xyz: [2, 5], t: 1}, {xyz: [2, 7], t: 3}]}
            - {name: looper, waypoints: [[0, 8], [1, 8]], speed: 1.0, loop: true, heading: travel}
            - {name: late, waypoints: [[0, -5], [4, -5]], speed: 2.0, start: 0.5}
            - name: door
              shape: box
              size: [1.0, 0.05, 2.0]
              pose: {xyz: [5, -8, 1]}
              hinge: {at: [-0.5, 0, 0], axis: [0, 0, 1], angle: 1.5708, duration: 2.0}
              start: 0.5
        """,
        duration=3.5,
        robot=False,
    )
    ran = run(plan, lambda w: {a: mocap(w, a) for a in ("timed", "looper", "late", "door")})

    def at(t, actor):
        return ran.sample(t)[actor]

    # timed waypoints: linear between the given times, then it stays at the last
    assert at(0.5, "timed")[0] == pytest.approx([1.0, 5.0, 0.0], abs=1e-6)
    assert at(2.0, "timed")[0] == pytest.approx([2.0, 6.0, 0.0], abs=1e-6)
    assert at(3.5, "timed")[0] == pytest.approx([2.0, 7.0, 0.0], abs=1e-6)
    # a loop at 1 m/s: out in 1 s, back in 1 s, again; facing where it goes (travel)
    assert at(0.5, "looper")[0][:2] == pytest.approx([0.5, 8.0], abs=1e-6)
    assert at(1.5, "looper")[0][:2] == pytest.approx([0.5, 8.0], abs=1e-6)
    assert at(3.25, "looper")[0][:2] == pytest.approx([0.75, 8.0], abs=1e-6)
    assert yaw_of(at(0.5, "looper")[1]) == pytest.approx(0.0, abs=1e-6)
    assert abs(yaw_of(at(1.5, "looper")[1])) == pytest.approx(math.pi, abs=1e-6)
    # a start time: it stands at its first point until then, then goes at its speed
    assert at(0.4, "late")[0][:2] == pytest.approx([0.0, -5.0], abs=1e-9)
    assert at(1.0, "late")[0][:2] == pytest.approx([1.0, -5.0], abs=1e-6)
    assert at(3.5, "late")[0][:2] == pytest.approx([4.0, -5.0], abs=1e-6)  # (its end: it stays)
    # the door: closed until 0.5 s, half open at 1.5 s, open from 2.5 s on, turned about its hinge line
    assert yaw_of(at(0.4, "door")[1]) == pytest.approx(0.0, abs=1e-9)
    assert yaw_of(at(1.5, "door")[1]) == pytest.approx(math.pi / 4, abs=1e-3)
    pos, quat = at(3.5, "door")
    assert yaw_of(quat) == pytest.approx(1.5708, abs=1e-6)
    assert pos == pytest.approx([4.5, -7.5, 1.0], abs=1e-3)  # its centre, 0.5 m from the hinge at x = 4.5


def test_start_stop_and_resume_where_it_stopped(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        world:
          actors:
            - {name: walker, waypoints: [[0, 4], [5, 4]], speed: 1.0, start: event}
        events:
          - {name: go, when: {at: 0.5}, do: [{start: walker}]}
          - {name: halt, when: {at: 1.0}, do: [{stop: walker}]}
          - {name: again, when: {at: 1.5}, do: [{start: walker}]}
        """,
        duration=2.0,
    )
    ran = run(plan, lambda w: float(mocap(w, "walker")[0][0]))
    x = {round(ns / 1e9, 2): v for ns, v in ran.samples}
    assert x[0.0] == x[0.5] == 0.0  # standing at its first point until started (its first tick: t = 0)
    assert x[0.99] == pytest.approx(0.49, abs=1e-6)  # 1 m/s from 0.5 s
    assert x[1.0] == x[1.25] == x[1.49] == x[0.99]  # stopped: stays put
    assert x[1.5] == pytest.approx(0.5, abs=1e-6)  # resumes where it was, not where time would have it
    assert x[2.0] == pytest.approx(1.0, abs=1e-6)  # moved 1 s in all


# ------------------------------------------------------------------------------- seen, and pushing
def test_a_person_is_seen_by_the_lidar_where_it_stands_and_pushes_a_robot_it_walks_into(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        world:
          actors:   # walks to 2 m ahead of r1 (in 2 s), waits, then walks through where r1 is
            - {name: person, waypoints: [{xyz: [2, 3], t: 0}, {xyz: [2, 0], t: 2}, {xyz: [2, 0], t: 2.5}, {xyz: [-2, 0], t: 5.5}]}
        assertions:
          - {name: no_touch, type: no_collision, between: [r1, person]}
        """,
        duration=5.0,
    )
    ran = run(plan, lambda w: w.data.xpos[w.model.body(root(w)).id].copy())
    scans = ran.on("r1/scan")
    ahead = [(t, float(m.ranges[len(m.ranges) // 2])) for t, m in scans]  # the beam at 0 rad
    assert math.isinf(dict(ahead)[0]) and math.isinf(dict(ahead)[1_000_000_000])  # nothing ahead yet
    # at 2.0..2.5 s the person (a 0.25 m capsule) stands 2 m ahead of r1 (less its lidar's offset)
    seen = dict(ahead)[2_200_000_000]
    assert 1.55 < seen < 1.8, seen
    assert abs(dict(ahead)[2_400_000_000] - seen) < 0.01
    # it walks on through r1: r1 is pushed back (-x) and the contact is reported
    start, end = ran.samples[0][1], ran.samples[-1][1]
    assert end[0] < start[0] - 0.2
    contacts = [m for _t, m in ran.on("/_contacts")]
    assert any("person" in (s.collision1_name + s.collision2_name) for m in contacts for s in m.states)


# --------------------------------------------------------------------------------- teleport
def test_teleport_a_robot_a_free_model_and_an_actor(tmp_path):
    plan = plan_of(
        tmp_path,
        """
        world:
          models:
            - {name: box, shape: box, size: [0.2, 0.2, 0.2], static: false, pose: {xyz: [0, 3, 0.1]}}
          actors:
            - {name: walker, waypoints: [[0, -3], [4, -3]], speed: 1.0}
        timeline:
          - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.5}}}
        events:
          - name: jump
            when: {at: 1.0}
            do:
              - {teleport: {body: r1, pose: {xyz: [3, 1, 0.06], rpy: [0, 0, 1.5708]}}}
              - {teleport: {body: box, pose: {xyz: [-2, 2, 0.5]}}}
              - {teleport: {body: walker, pose: {xyz: [-3, -3, 0]}}}
          - {name: walk_on, when: {at: 1.5}, do: [{start: walker}]}
        """,
        duration=2.0,
    )

    def probe(w):
        r = root(w)
        return (
            w.data.xpos[w.model.body(r).id].copy(),
            w.data.xquat[w.model.body(r).id].copy(),
            w.data.xpos[w.model.body("box").id].copy(),
            mocap(w, "walker")[0],
        )

    ran = run(plan, probe)
    robot, quat, box, walker = ran.sample(1.0)  # the same step: the state the rest of it sees
    assert robot == pytest.approx([3, 1, 0.06], abs=1e-6)
    assert yaw_of(quat) == pytest.approx(1.5708, abs=1e-6)
    assert box == pytest.approx([-2, 2, 0.5], abs=1e-6)
    assert walker == pytest.approx([-3, -3, 0], abs=1e-9)
    robot2, _quat2, box2, walker2 = ran.sample(1.2)
    # r1 drives on from there, along its new heading (+y); the box falls; the walker stands until started
    assert robot2[1] > 1.0 + 0.02 and robot2[0] == pytest.approx(3.0, abs=0.02)
    assert box2[2] < 0.5 - 0.1
    assert np.array_equal(walker2, walker)
    assert ran.sample(2.0)[3][0] > ran.sample(1.5)[3][0] + 0.3  # started again: back on its path


# ------------------------------------------------------------------------------- push, impulse
def test_a_push_moves_a_free_box_by_f_over_m_t2_over_2_then_is_gone(tmp_path):
    plan = plan_of(
        tmp_path,
        ZERO_G,
        """
        events:
          - {name: shove, when: {at: 0.5}, do: [{push: {body: box, force: [4, 0, 0], duration: 0.5}}]}
        """,
        duration=2.0,
        robot=False,
    )
    ran = run(plan, _box)
    x0 = ran.sample(0.5)[0][0]
    pos, vel = ran.sample(1.0)
    assert pos[0] - x0 == pytest.approx(4 / 2 * 0.5**2 / 2, rel=0.02)  # F/m t²/2 = 0.25 m
    assert vel[0] == pytest.approx(1.0, rel=0.01)
    pos2, vel2 = ran.sample(2.0)
    assert vel2[0] == pytest.approx(vel[0], abs=1e-9)  # the force is gone: it coasts
    assert pos2[0] - pos[0] == pytest.approx(vel[0] * 1.0, rel=1e-3)
    assert abs(pos2[1] - 3.0) < 1e-9 and abs(pos2[2] - 1.0) < 1e-9


def test_overlapping_pushes_on_one_body_add_up_and_each_ends_on_its_own(tmp_path):
    plan = plan_of(
        tmp_path,
        ZERO_G,
        """
        events:
          - {name: a, when: {at: 0.0}, do: [{push: {body: box, force: [2, 0, 0], duration: 1.0}}]}
          - {name: b, when: {at: 0.5}, do: [{push: {body: box, force: [0, 2, 0], duration: 1.0}}]}
        """,
        duration=2.0,
        robot=False,
    )
    ran = run(plan, _box)
    # a: 1 m/s² along x from 0 to 1 s; b: 1 m/s² along y from 0.5 to 1.5 s
    assert ran.sample(2.0)[1][:2] == pytest.approx([1.0, 1.0], rel=0.01)
    assert ran.sample(0.75)[1][:2] == pytest.approx([0.75, 0.25], rel=0.02)
    assert not ran.world.data.xfrc_applied.any()  # nothing left on


def test_an_impulse_changes_velocity_by_j_over_m(tmp_path):
    plan = plan_of(
        tmp_path,
        ZERO_G,
        """
        events:
          - {name: kick, when: {at: 0.5}, do: [{impulse: {body: box, linear: [0, 1, -0.5]}}]}
          - {name: kick_r1, when: {at: 0.5}, do: [{impulse: {body: r1, linear: [0, 0, 1.0]}}]}
        """,
        duration=1.0,
    )
    ran = run(plan, lambda w: _box(w)[1])
    assert ran.sample(0.49) == pytest.approx([0, 0, 0], abs=1e-9)
    assert ran.sample(0.5) == pytest.approx([0, 0.5, -0.25], abs=1e-9)  # J/m, m = 2 kg
    assert ran.sample(1.0) == pytest.approx([0, 0.5, -0.25], abs=1e-9)
    # r1 (no gravity, floating): its whole mass moves up at J/m
    mass = float(ran.world.model.body_subtreemass[ran.world.model.body(root(ran.world)).id])
    rid = ran.world.model.body(root(ran.world)).id
    dof = int(ran.world.model.jnt_dofadr[ran.world.model.body_jntadr[rid]])
    assert ran.world.data.qvel[dof + 2] == pytest.approx(1.0 / mass, rel=0.05)


def test_played_poses_are_each_actors_path_at_its_own_clock_through_windows_starts_and_stops():
    """`Actors` gathers the next WINDOW ticks of every moving actor's poses at once; whatever the starts,
    stops and teleports in between (some mid-window), each tick's pose must be the sampled path's at that
    actor's own clock: the sample of its own tick count, looped or held at the path's end."""
    import mujoco

    from runner.plan import ActorPlan
    from runner.sim.actors import TICK_NS, WINDOW, Actors, sample_path

    xml = (
        "<mujoco><worldbody>"
        + "".join(f'<body name="a{i}" mocap="true"><geom size="0.1"/></body>' for i in range(4))
        + "</worldbody></mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    plans = [
        ActorPlan(
            name="a0",
            start_ns=0,
            pos=[0, 0, 0],
            quat=[1, 0, 0, 0],
            times=[0, 1.3],
            points=[[0, 0, 0], [1.3, 0, 0]],
            loop=True,
        ),
        ActorPlan(
            name="a1",
            start_ns=None,
            pos=[0, 1, 0],
            quat=[1, 0, 0, 0],
            times=[0, 0.7, 2.0],
            points=[[0, 1, 0], [0.7, 1, 0], [0.7, 2.3, 0]],
            travel=True,
        ),
        ActorPlan(
            name="a2",
            start_ns=250_000_000,
            pos=[0, 2, 0],
            quat=[1, 0, 0, 0],
            times=[0, 3.1],
            points=[[0, 2, 0], [3.1, 2, 0]],
            loop=True,
        ),
        ActorPlan(
            name="a3",
            start_ns=0,
            pos=[0, 3, 0],
            quat=[1, 0, 0, 0],
            times=[0, 0.5],
            points=[[0, 3, 0], [0.5, 3, 0]],
        ),
    ]
    actors = Actors(m, d, plans)
    tables = [sample_path(p) for p in plans]
    clocks = [0, 0, 0, 0]
    moving = [False] * 4
    rng = np.random.default_rng(3)
    for k in range(7 * WINDOW + 13):
        now = k * TICK_NS
        for i, p in enumerate(plans):
            if p.start_ns == now:  # (a start time starts it, whatever happened before)
                moving[i] = True
        if k % 37 == 5:  # a start or a stop now and then, mid-window
            i = int(rng.integers(4))
            (actors.stop if moving[i] else actors.start)(i)
            moving[i] = not moving[i]
        actors.tick(now)
        for i, (pos, quat) in enumerate(tables):
            if not moving[i]:
                continue
            n = len(pos)
            j = clocks[i] % (n - 1) if plans[i].loop and n > 1 else min(clocks[i], n - 1)
            assert np.array_equal(d.mocap_pos[i], pos[j]), (k, i)
            assert np.array_equal(d.mocap_quat[i], quat[j]), (k, i)
            clocks[i] += 1
    assert sum(clocks) > 3 * WINDOW  # they did move, across several windows
