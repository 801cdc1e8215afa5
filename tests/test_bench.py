"""The benchmark suite runs (its cheapest sections), so it does not rot between releases. Figures are not
judged here: timings belong to `python -m bench`, not to tests on a shared CI machine."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.mark.timeout(120)
def test_bench_suite_runs_and_writes_results(tmp_path: Path) -> None:
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "bench",
            "--quick",
            "--only",
            "messages,two_robots,actors",
            "--results",
            str(tmp_path),
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=110,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "raw MuJoCo, batched mj_step (the limit)" in proc.stdout
    doc = json.loads((tmp_path / "two_robots.json").read_text())
    assert doc["machine"]["cpus"] >= 1
    rates = doc["steps_per_s"]
    # every row measured (which is faster is the bench's to say: one quick round on a loaded machine can
    # see raw physics slowed by a neighbour more than the world)
    assert rates["raw_batched"] > 0 and rates["world_zenoh"] > 0
    assert rates["recorded"] > 0
    assert doc["lost"] == [0]
    messages = json.loads((tmp_path / "messages.json").read_text())
    types = {row["type"] for row in messages["rows"]}
    assert {"sensor_msgs/msg/Imu", "sensor_msgs/msg/LaserScan", "nav_msgs/msg/Odometry"} <= types
    # a fixed layout is cheaper than building the bytes with rosbags
    assert all(row["fixed_layout_us"] < row["rosbags_encode_us"] for row in messages["rows"])
    # the actors row ran the three worlds, and the events in it fired (the scan trigger, 10 a second)
    actors = json.loads((tmp_path / "actors.json").read_text())
    assert (actors["actors"], actors["events"]) == (20, 10)
    assert set(actors["steps_per_s"]) == {"raw", "raw bodies", "raw moving", "without", "standing", "with"}
    assert all(v > 0 for v in actors["steps_per_s"].values())
    assert actors["firings"] >= 10 * actors["sim_seconds"]
    assert "+ them walking and 10 events" in proc.stdout
    assert "ours: playing them and the events" in proc.stdout


@pytest.mark.timeout(60)
def test_unknown_section_is_a_clear_error() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "bench", "--only", "nope"],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 2
    assert "unknown section(s) nope" in proc.stderr


@pytest.mark.timeout(120)
def test_the_readme_bench_tables_describe_what_the_demo_publishes_now(tmp_path: Path) -> None:
    """The README's two_robots table states how many messages the demo records per sim second; when the
    demo publishes more or fewer (a new plugin, a new topic, another rate), the table describes a run that
    no longer exists: regenerate it (`python -m bench --only two_robots --readme`). Every table says the
    machine and day it was measured on."""
    import re

    from bench.common import TWO_ROBOTS, plan_from_file, readme_tables
    from runner.launch.run import run_plan

    text = (REPO / "README.md").read_text()
    block = text[text.index("<!-- bench:begin -->") : text.index("<!-- bench:end -->")]
    tables = readme_tables(block)
    assert {"two_robots", "actors"} <= set(tables)
    for name, table in tables.items():
        assert re.search(r"^_.+\(\d+ cpus\), Python [\d.]+, MuJoCo [\d.]+, \d{4}-\d\d-\d\d_$", table, re.M), (
            name
        )
    stated = re.search(r"(\d+) messages per sim second, (\d+) s sim", tables["two_robots"])
    assert stated, tables["two_robots"].splitlines()[0]
    per_s, seconds = int(stated.group(1)), float(stated.group(2))
    plan = plan_from_file(TWO_ROBOTS, seconds=seconds)  # as the bench runs it
    plan.record.path = str(tmp_path / "demo.mcap")
    result = run_plan(plan, listen=[])
    assert result.reason == "completed", result.error
    now = sum(t.count + t.lost for t in result.topics) / seconds  # (what it published: recorded or not)
    assert round(now) == per_s, (
        f"the README's two_robots table says {per_s} messages per sim second; the demo records {now:.0f} now: "
        "regenerate it with `python -m bench --only two_robots --readme` on a quiet machine"
    )


@pytest.mark.timeout(120)
def test_the_camera_bound_renders_each_declared_camera_at_its_size_and_rate() -> None:
    """bench/cameras.py's rendering bound for a seed's camera robot: every camera of the scenario, at its
    declared size, for as many frames as its rate gives; and the GL renderer it reports."""
    import os

    os.environ.setdefault("MUJOCO_GL", "egl")
    from bench import cameras as bc
    from bench.common import REPO as repo
    from bench.common import gl_renderer, plan_from_file

    plan = plan_from_file(repo / "scenarios" / "block_robot.yaml", seconds=0.2)
    specs = bc.camera_specs(plan)
    assert [(s.name, s.width, s.height, s.rate, s.depth, s.noise) for s in specs] == [
        ("br/vislight_cam_camera", 800, 800, 30.0, False, 0.007),
        ("br1/vislight_cam_camera", 800, 800, 30.0, False, 0.007),
    ]
    bound = bc.render_bound(plan, 0.2)
    assert [(c["size"], c["frames"]) for c in bound["cameras"]] == [("800x800", 6), ("800x800", 6)]
    assert bound["wall_s"] > 0 and bound["one_pass_wall_s"] > 0
    frame = bc.rendered_frame(plan)
    assert frame.shape == (800, 800, 3) and 20 < frame.mean() < 235  # the ground and the sky, not blank
    cost = bc.noise_cost(80, 60, 0.007, repeat=2)
    assert cost["noisy_ms"] > 0 and cost["plain_ms"] > 0
    assert gl_renderer()  # e.g. llvmpipe here, the GPU's name where EGL finds one


@pytest.mark.timeout(120)
def test_the_worlds_floor_puts_what_the_world_publishes() -> None:
    """bench.common.world_floor, the floor the two_robots, scaling and cameras tables show: the same hooks
    at the same times put the same keys, as many messages each (but for once-only ones), numbered from 0
    and stamped with their sim time, as the world with every plugin computing; on a real Zenoh session,
    taken by a subscriber in another session."""
    import threading
    import time

    import zenoh

    from bench.common import TWO_ROBOTS, World, ZenohBus, floor_of, plan_from_file
    from runner.wire.transport import free_port, make_config, unpack_attachment

    plan = plan_from_file(TWO_ROBOTS, seconds=1.0)
    got: dict[str, list[tuple[int, int]]] = {}
    lock = threading.Lock()

    def on(sample: zenoh.Sample) -> None:
        att = sample.attachment
        if att is not None:
            with lock:
                got.setdefault(str(sample.key_expr), []).append(unpack_attachment(att.to_bytes()))

    counts = {}
    for floor in (False, True):
        got.clear()
        endpoint = f"tcp/127.0.0.1:{free_port()}"
        with (
            zenoh.open(make_config("router", listen=[endpoint])) as session,
            zenoh.open(make_config("client", connect=[endpoint])) as other,
        ):
            sub = other.declare_subscriber(f"{plan.name}/**", on)
            time.sleep(0.3)  # (the subscription reaches the router)
            bus = ZenohBus(session)
            world = World(plan, bus)
            stats = (floor_of(world) if floor else world).run()
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline:
                with lock:
                    if all(len(got.get(k, ())) >= n for k, n in stats.published.items()):
                        break
                time.sleep(0.05)
            sub.undeclare()
            bus.undeclare_all()
        with lock:
            counts[floor] = {k: len(v) for k, v in got.items()}
            for key, atts in got.items():
                assert [seq for seq, _t in atts] == list(range(len(atts))), key
                assert all(t % plan.step_ns == 0 and 0 <= t <= plan.duration_ns for _s, t in atts), key
    world_counts, floor_counts = counts[False], counts[True]
    assert {k for k, n in world_counts.items() if n > 2} <= set(floor_counts)
    assert all(abs(floor_counts.get(k, 0) - n) <= 2 for k, n in world_counts.items()), (
        world_counts,
        floor_counts,
    )
    assert sum(floor_counts.values()) > 700  # the demo's 748 messages per sim second
