"""What actors and events cost (issue 22): the demo world (scenarios/two_robots.yaml, every plugin
publishing on a real Zenoh session, nothing subscribed) with 20 actors walking looping paths and 10 events,
against the same world without them. The target: at most 15 % more wall time per sim second.

The actors (13 persons, 5 boxes, a sphere, a cylinder) walk back and forth along the walls and through the
free middle of the arena, where the robots never go, so the physics of the robots is the same in both
worlds: what is measured is playing the actors (a mocap pose per tick), the rays and contacts their bodies
add, and looking at the events. The events mix every kind that keeps being looked at: two times, two
`near` (one between two actors that meet again and again), an `enter` and a `leave` of a named region
(they stop and start a box each time), two `after` (one delayed), and two `message` triggers (the lidar's
every scan at 10 Hz, firing each time; the IMU's at 100 Hz, never firing). Their actions keep firing: repeat
publishes, start/stop of actors, and a delay fault on the joint states for five seconds.

The worlds are run alternately, best of N each, so a machine busy with something else slows them all.
Beside them, in the same run, raw MuJoCo steps the compiled model with and without the actors' bodies
(no plugins, nothing played): what MuJoCo itself pays for twenty more bodies (kinematics, broad phase) is
part of the limit, not ours. Ours is the rest: playing the actors and looking at the events, measured as
the world with them walking and the events against the same world with their bodies standing."""

from __future__ import annotations

from typing import Any

import yaml

from bench.common import DIFFBOT, TWO_ROBOTS, plan_from_text, raw_rate, say, table, world_on_zenoh
from runner.plan import RunPlan

TARGET = 0.15  # at most 15 % more wall time per sim second

# (name, shape, size, z, path, speed): looping paths, all of them clear of the robots' paths (x in
# [-2.3, 1], y in [-1.7, 1.8]), of the walls, the crate, the pillar and the ball
_ACTORS: list[tuple[str, str, list[float] | None, float, list[list[float]], float]] = [
    ("p1", "person", None, 0.0, [[-4.3, 4.3], [-1.5, 4.3]], 1.0),
    ("p2", "person", None, 0.0, [[-1.0, 4.3], [1.5, 4.3]], 0.8),
    ("p3", "person", None, 0.0, [[2.0, 4.3], [4.3, 4.3]], 1.2),
    ("p4", "person", None, 0.0, [[-2.0, 3.7], [0.5, 3.7]], 0.6),
    ("p5", "person", None, 0.0, [[1.0, 3.7], [1.8, 3.7]], 0.5),
    ("p6", "person", None, 0.0, [[-4.3, -4.3], [-1.0, -4.3]], 1.1),
    ("p7", "person", None, 0.0, [[-0.5, -4.3], [2.5, -4.3]], 0.9),
    ("p8", "person", None, 0.0, [[3.0, -4.3], [4.3, -4.3]], 0.7),
    ("p9", "person", None, 0.0, [[4.3, -3.0], [4.3, 3.5]], 1.3),
    ("p10", "person", None, 0.0, [[3.7, -2.0], [3.7, 2.0]], 1.0),
    ("p11", "person", None, 0.0, [[-4.3, -3.5], [-4.3, 3.5]], 1.2),
    ("p12", "person", None, 0.0, [[-3.7, -3.0], [-3.7, 2.0]], 0.8),
    ("p13", "person", None, 0.0, [[1.8, -2.0], [1.8, 1.5]], 1.0),
    ("b1", "box", [0.4, 0.4, 0.4], 0.2, [[-4.0, -3.7], [-1.0, -3.7]], 0.6),
    ("b2", "box", [0.4, 0.4, 0.4], 0.2, [[0.0, -3.7], [2.0, -3.7]], 0.5),
    ("b3", "box", [0.4, 0.4, 0.4], 0.2, [[3.2, -1.5], [3.2, 1.5]], 0.7),
    ("b4", "box", [0.4, 0.4, 0.4], 0.2, [[-3.1, -2.5], [-3.1, 0.5]], 0.4),
    ("b5", "box", [0.4, 0.4, 0.4], 0.2, [[2.5, -2.0], [2.5, 1.5]], 0.6),
    ("s1", "sphere", [0.2], 0.2, [[-1.5, 3.1], [0.5, 3.1]], 0.9),
    ("c1", "cylinder", [0.2, 0.6], 0.3, [[-1.5, -3.1], [0.5, -3.1], [0.5, -2.6]], 0.7),
]

_PING = {"topic": "bench/ping", "type": "std_msgs/msg/String", "data": {"data": "ping"}}

_EVENTS: list[dict[str, Any]] = [
    {"name": "first", "when": {"at": 1.0}, "do": [{"publish": _PING}]},
    {
        "name": "odometry_lags",
        "when": {"at": 2.0},
        "do": [{"fault": {"topic": "r2/joint_states", "delay": 0.05, "duration": 5.0}}, {"stop": "p4"}],
    },
    {
        "name": "p4_again",
        "when": {"after": {"event": "odometry_lags", "delay": 1.5}},
        "do": [{"start": "p4"}],
    },
    {
        "name": "p1_meets_p4",
        "when": {"near": {"body": "p1", "to": "p4", "within": 1.0}},
        "do": [{"publish": _PING}],
        "repeat": True,
    },
    {
        "name": "r1_at_its_corner",
        "when": {"near": {"body": "r1", "to": [-0.5, 0.5], "within": 0.5}},
        "do": [{"publish": _PING}],
    },
    {
        "name": "p13_in",
        "when": {"enter": {"body": "p13", "region": "middle"}},
        "do": [{"stop": "b5"}],
        "repeat": True,
    },
    {
        "name": "p13_out",
        "when": {"leave": {"body": "p13", "region": "middle"}},
        "do": [{"start": "b5"}],
        "repeat": True,
    },
    {"name": "said_in", "when": {"after": "p13_in"}, "do": [{"publish": _PING}], "repeat": True},
    {
        "name": "every_scan",
        "when": {"message": {"topic": "r1/scan", "expr": "ranges.min() < 8.0"}},
        "do": [{"publish": _PING}],
        "repeat": True,
    },
    {
        "name": "imu_guard",
        "when": {"message": {"topic": "r2/imu", "expr": "linear_acceleration.z < 5.0"}},
        "do": [{"publish": _PING}],
        "repeat": True,
    },
]


def scenes() -> tuple[str, str]:
    """(the demo world, the same world with the actors and events), as scenario texts."""
    base = yaml.safe_load(TWO_ROBOTS.read_text())
    base["assertions"] = []
    for robot in base["robots"]:
        robot["description"]["file"] = str(DIFFBOT)  # (the text is compiled from another folder)
    busy = yaml.safe_load(yaml.safe_dump(base))
    busy["world"]["actors"] = [
        {
            "name": name,
            "shape": shape,
            **({"size": size} if size else {}),
            "pose": {"xyz": [*path[0], z]},
            "waypoints": path,
            "speed": speed,
            "loop": True,
            "heading": "travel",
        }
        for name, shape, size, z, path, speed in _ACTORS
    ]
    busy["regions"] = {"middle": {"min": [1.0, -0.5], "max": [3.0, 0.5]}}
    busy["events"] = _EVENTS
    return yaml.safe_dump(base, sort_keys=False), yaml.safe_dump(busy, sort_keys=False)


def plans(seconds: float) -> tuple[RunPlan, RunPlan, RunPlan]:
    """(the demo world, the same with the actors standing where they start and no events: their bodies in
    the physics and in the lidars' way but nothing played, the same with them walking and the events)."""
    base, busy = scenes()
    plan = plan_from_text(busy, seconds=seconds)
    standing = plan.model_copy(deep=True)
    standing.actors, standing.events = [], []
    return plan_from_text(base, seconds=seconds), standing, plan


def run(quick: bool, repeat: int) -> tuple[dict[str, Any], str]:
    seconds = 5.0 if quick else 20.0
    rounds = 1 if quick else max(repeat, 5)
    base, standing, busy = plans(seconds)
    dt = base.step_ns / 1e9
    rates: dict[str, list[float]] = {"raw": [], "raw bodies": [], "without": [], "standing": [], "with": []}
    fired = 0
    raw_steps = round(seconds * 1e9 / base.step_ns)
    for _ in range(rounds):  # alternating: whatever else the machine does slows them all
        rates["raw"].append(raw_rate(base, raw_steps))
        rates["raw bodies"].append(raw_rate(standing, raw_steps))
        for label, plan in (("without", base), ("standing", standing), ("with", busy)):
            stats = world_on_zenoh(plan)
            rates[label].append(stats.steps / stats.wall_s)
            if label == "with":
                fired = stats.published.get(f"{busy.name}/_events", 0)
    say(f"  {rounds} rounds done")
    best = {k: max(v) for k, v in rates.items()}
    # wall time per sim second, relative to the world without them
    cost = {k: best["without"] / v - 1.0 for k, v in best.items()}
    bodies_raw = best["raw"] / best["raw bodies"] - 1.0  # MuJoCo's own cost of the bodies
    ours = best["standing"] / best["with"] - 1.0  # playing them and the events, over the bodies standing
    n_a, n_e = len(busy.actors), len(busy.events)
    rows = [
        ("raw MuJoCo, the demo's compiled model (the limit)", best["raw"], best["raw"] * dt, ""),
        (
            f"  + {n_a} actors' bodies (the limit with them: MuJoCo's own cost)",
            best["raw bodies"],
            best["raw bodies"] * dt,
            f"{bodies_raw * 100:+.1f} %",
        ),
        ("world, all plugins publishing, nothing subscribed", best["without"], best["without"] * dt, ""),
        (
            f"  + {n_a} actors' bodies, standing (MuJoCo: physics, rays)",
            best["standing"],
            best["standing"] * dt,
            f"{cost['standing'] * 100:+.1f} %",
        ),
        (
            f"  + them walking and {n_e} events ({fired / seconds:.1f} firings/s)",
            best["with"],
            best["with"] * dt,
            f"{cost['with'] * 100:+.1f} %",
        ),
        (
            "  ours: walking and events, over the bodies standing",
            "",
            "",
            f"{ours * 100:+.1f} %",
        ),
    ]
    text = table(
        f"actors: two_robots with {n_a} actors and {n_e} events, {seconds:g} s sim, best of {rounds} "
        "alternating",
        ("", "steps/s", "× real time", "wall time"),
        rows,
    )
    doc = {
        "sim_seconds": seconds,
        "rounds": rounds,
        "actors": n_a,
        "events": n_e,
        "firings": fired,
        "steps_per_s": best,
        "all_steps_per_s": rates,
        "overhead": cost["with"],
        "overhead_bodies_only": cost["standing"],
        "mujoco_bodies": bodies_raw,
        "ours": ours,
        "targets": {
            f"actors and events cost <= {TARGET * 100:.0f} % wall time": cost["with"] <= TARGET,
            f"playing them and the events <= {TARGET * 100:.0f} % over their bodies standing": ours <= TARGET,
        },
    }
    return doc, text


if __name__ == "__main__":  # a quick look: python -m bench.actors
    print(run(False, 5)[1])
