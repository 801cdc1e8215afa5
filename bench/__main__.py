"""The benchmark suite: `python -m bench [--quick] [--only SECTION,...] [--readme]` (or `scenario bench`).

Every figure of a section is measured in the same run, so ratios are comparable on a noisy machine.
Sections (in order):

- two_robots: the demo scenario (lidar 10 Hz, imu 100 Hz, odom/tf/joint_states 50 Hz per robot),
  judging off. The raw MuJoCo step rate of its compiled model (no plugins, robots at rest) is the limit;
  then the world's floor (its loop and hooks at their rates, each hook only putting its messages, encoded
  beforehand, and making MuJoCo's own calls for its sensor: the lidars' ray casts; bench.common.world_floor:
  what no implementation of the plugins can go below), the world with every plugin publishing on a real
  Zenoh session and nothing subscribed, the full
  `scenario run` (world process + Zenoh + MCAP recorder), and the same with an external subscriber
  process taking every message too. Ratio to the limit and × real time.
- scaling: 1, 2, 4, 8, 16 robots (diff_drive + lidar + imu + joint_states + tf each), the world's floor,
  world on Zenoh and full recorded run: × real time and wall cost per robot-second, relative to one robot;
  the recorded run against raw MuJoCo.
- messages: encode cost by type, fixed layout (runner.wire.cdr) vs rosbags, µs per message.
- cameras: the demo plus one 320x240 RGB camera per robot at 10 Hz, recorded; then the seeds' camera robots
  as declared (block_robot, harmonic_nav) against their limit, physics + one render per frame (and
  mujoco.Renderer's calls), the world's floor (its loop, renders and puts, nothing else computed), the
  world alone and the recorded run; the noise's cost per frame against its
  render; a frame's bytes on their way into the MCAP; the GL renderer used (bench/cameras.py).
- realtime: `rate: realtime` for 60 s (10 s with --quick): the factor overall and over its worst second,
  and the delay from a `cmd_vel` put by another process to the controller acting on it.
- lockstep: the go-to-goal example with its controller node in lockstep with the world, and free-running.
- recorder: messages/s the recorder sustains from another process, with sequence numbers checked.
- soak: the demo for 10 sim minutes at `rate: max`, recorded with --strict: resident memory of the runner
  and of the world from warm-up to the end (bench/soak.py), messages lost.
- plugins: per-plugin cost per call, camera frames/s, lidar rays/s (bench/plugins.py).
- actors: the demo world with 20 actors walking looping paths and 10 events (every trigger kind that keeps
  being looked at, actions that keep firing), against the same world without them, alternating, best of
  N (bench/actors.py). Target: at most 15 % more wall time per sim second.
- meshes: static non-convex collision meshes split into convex pieces (bench/meshes.py): a 50k-triangle
  one-mesh building the first time and from the cache (targets: < 10 s, < 0.2 s), and the worst case.
- ray: a suite of 24 short variants as `scenario test -j 2` and as `scenario test --ray` on the same 2
  cores, with a running cluster and with `--ray` starting its own (bench/ray.py): variants per minute and
  Ray's overhead per variant (target: under 1 s).

- limits: large legitimate inputs against the issue-35 targets (bench/limits.py): a 20,000-entry timeline
  validated (target: < 5 s); URDF chains of 500 to 10,000 hinged links and 3,000 links on fixed joints, and
  a 5 M-triangle mesh (a sphere, random triangles: binary STL; a sphere as OBJ), each `scenario validate` in
  its own process: wall time and peak memory against 60 s and 2 GB, and whether it validated or was
  refused with a located error.
- hardware: a heavy 3-link arm on gz_ros2_control's position interface (bench/hardware.py): the drift from
  its initial values over 10 s at three timesteps (target: <= 0.005 rad), the sag under an outside load and
  with the servo alone, an effort limit below its weight, the peak speed of a step command against the URDF
  velocity limit, and the world's loop with and without velocity limits.
- mobile: mobile-base controllers from controllers files, what the physics gives them (bench/mobile.py): a
  56 kg skid steer's turn with its wheels' torque unlimited (as gz_ros2_control without <limit effort>) and
  held to 20 N·m, an Ackermann car's turning radius, a mecanum robot's strafe.

Results go to bench/results/<section>.json (with machine info); `--readme` also writes the tables into
README.md between the `bench:begin`/`bench:end` markers.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import textwrap
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))
if "MUJOCO_GL" not in os.environ:  # cameras render headless; decided before mujoco is imported
    os.environ["MUJOCO_GL"] = "egl"
    os.environ["SCENARIO_GL_AUTO"] = "1"

import runner  # noqa: E402,F401  (picks a working GL backend before mujoco loads)
from bench.common import (  # noqa: E402
    DIFFBOT,
    RESULTS,
    TWO_ROBOTS,
    gl_renderer,
    machine,
    plan_from_file,
    plan_from_text,
    raw_driving_rate,
    raw_rate,
    readme_tables,
    say,
    table,
    world_floor,
    world_on_zenoh,
)
from runner.launch.run import run_plan  # noqa: E402
from runner.plan import RunPlan  # noqa: E402
from runner.wire.transport import free_port  # noqa: E402

SECTIONS = (
    "two_robots",
    "scaling",
    "messages",
    "cameras",
    "realtime",
    "lockstep",
    "recorder",
    "soak",
    "plugins",
    "meshes",
    "actors",
    "ray",
    "limits",
    "hardware",
    "mobile",
)


# ------------------------------------------------------------------------------------------- helpers
def _full_run(plan: RunPlan, tmp: Path, tag: str, listen: list[str] | None = None) -> tuple[float, int, int]:
    """`scenario run`'s path: (steps/s, messages recorded, lost)."""
    plan.record.path = str(tmp / f"{tag}.mcap")
    result = run_plan(plan, listen=listen or [])
    if result.reason != "completed":
        raise SystemExit(f"bench run failed: {result.reason} {result.error}")
    return (
        (result.sim_ns / plan.step_ns) / result.wall_s,
        sum(t.count for t in result.topics),
        sum(t.lost for t in result.topics),
    )


_SUBSCRIBER = textwrap.dedent(
    """
    import sys, time, zenoh
    from runner.wire.transport import make_config
    n = 0
    def on(sample):
        global n
        n += 1
    conf = make_config("client", connect=[sys.argv[1]])
    with zenoh.open(conf) as s:
        sub = s.declare_subscriber(sys.argv[2] + "/**", on)
        print("ready", flush=True)
        sys.stdin.readline()
        sub.undeclare()
    print(n, flush=True)
    """
)


def _with_external_subscriber(plan: RunPlan, tmp: Path) -> tuple[float, int, int]:
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    proc = subprocess.Popen(
        [sys.executable, "-c", _SUBSCRIBER, endpoint, plan.name],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        cwd=REPO,
    )
    try:
        assert proc.stdout is not None and proc.stdin is not None
        rate, recorded, _lost = _full_run(plan, tmp, "external", listen=[endpoint])
        proc.stdin.write("\n")
        proc.stdin.flush()
        out = proc.stdout.read().split()
        got = int(out[-1]) if out and out[-1].isdigit() else -1
    finally:
        proc.kill()
        proc.wait()
    return rate, recorded, got


# ------------------------------------------------------------------------------------------ sections
def two_robots(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    seconds = 10.0 if args.quick else 20.0
    plan = plan_from_file(TWO_ROBOTS, seconds=seconds)
    dt = plan.step_ns / 1e9
    steps = plan.duration_ns // plan.step_ns
    rep = args.repeat
    limit = max(raw_rate(plan, steps) for _ in range(rep))
    loop = max(raw_rate(plan, steps, batched=False) for _ in range(rep))
    driving = max(raw_driving_rate(plan) for _ in range(rep))
    say("  raw MuJoCo done")
    floor = max(s.steps / s.wall_s for s in (world_floor(plan) for _ in range(rep)))
    quiet = max(s.steps / s.wall_s for s in (world_on_zenoh(plan) for _ in range(rep)))
    say("  world on Zenoh done")
    runs = [_full_run(plan, tmp, f"two_robots{i}") for i in range(rep)]
    recorded = max(r[0] for r in runs)
    say("  recorded runs done")
    ext = [_with_external_subscriber(plan, tmp) for _ in range(rep)]
    external = max(r[0] for r in ext)
    msgs_per_sim_s = runs[0][1] / seconds
    rows = [
        ("raw MuJoCo, batched mj_step (the limit)", limit, limit * dt, 1.0),
        ("raw MuJoCo, mj_step per call from Python", loop, loop * dt, loop / limit),
        ("raw MuJoCo replaying the run's controls (robots driving)", driving, driving * dt, driving / limit),
        (
            "world floor: its loop, its messages put (encoded beforehand), the lidars' ray casts",
            floor,
            floor * dt,
            floor / limit,
        ),
        ("world, all plugins publishing, nothing subscribed", quiet, quiet * dt, quiet / limit),
        ("scenario run: world process + Zenoh + MCAP recorder", recorded, recorded * dt, recorded / limit),
        ("  + an external subscriber process", external, external * dt, external / limit),
    ]
    text = table(
        f"two_robots: {len(plan.robots)} robots, {msgs_per_sim_s:.0f} messages per sim second, "
        f"{seconds:g} s sim, best of {rep}",
        ("", "steps/s", "× real time", "of the limit"),
        rows,
    )
    doc = {
        "sim_seconds": seconds,
        "step_s": dt,
        "messages_per_sim_second": msgs_per_sim_s,
        "steps_per_s": {
            "raw_batched": limit,
            "raw_loop": loop,
            "world_floor": floor,
            "world_zenoh": quiet,
            "recorded": recorded,
            "recorded_external_subscriber": external,
        },
        "x_real_time": {
            "raw_batched": limit * dt,
            "world_zenoh": quiet * dt,
            "recorded": recorded * dt,
            "recorded_external_subscriber": external * dt,
        },
        "ratio_to_limit": {
            "world_floor": floor / limit,
            "world_zenoh": quiet / limit,
            "recorded": recorded / limit,
            "recorded_external_subscriber": external / limit,
        },
        "lost": [r[2] for r in runs],
        "external_subscriber_received": [r[2] for r in ext],
        # the (24): recorded >= 0.5 of raw, the world alone >= 0.7 (the floor says how far that
        # can go: the loop, the puts and the ray casts alone, no plugin computing anything)
        "targets": {
            "x_real_time_recorded >= 50": recorded * dt >= 50,
            "ratio_to_limit_recorded >= 0.5": recorded / limit >= 0.5,
            "ratio_to_limit_world >= 0.7": quiet / limit >= 0.7,
        },
    }
    return doc, text


def _robots_scene(n: int, seconds: float, extra: str = "") -> str:
    side = max(1, int(n**0.5 + 0.999))
    robots = []
    for i in range(n):
        x, y = (i % side) * 2.5 - (side - 1) * 1.25, (i // side) * 2.5 - (side - 1) * 1.25
        robots.append(
            f"""
  - name: r{i + 1}
    description: {{file: "{DIFFBOT}"}}
    pose: {{xyz: [{x:.2f}, {y:.2f}, 0.06]}}
    plugins:
      - {{type: diff_drive, params: {{rate: 50}}}}
      - {{type: lidar, params: {{link: lidar_link, samples: 360, rate: 10, range_max: 8.0,
          noise_stddev: 0.01}}}}
      - {{type: imu, params: {{link: imu_link, rate: 100}}}}
      - {{type: joint_states, params: {{rate: 50}}}}
      - {{type: tf, params: {{rate: 50}}}}{extra}"""
        )
    timeline = "\n".join(
        f"  - {{t: 0.1, topic: r{i + 1}/cmd_vel, type: geometry_msgs/msg/Twist, "
        f"data: {{linear: {{x: 0.2}}, angular: {{z: 0.3}}}}}}"
        for i in range(n)
    )
    half = side * 1.25 + 2
    return f"""
name: bench_{n}_robots
duration: {seconds}
rate: max
seed: 1
world:
  physics: {{timestep: 0.002}}
  models:
    - {{name: wall_n, shape: box, size: [{2 * half}, 0.1, 0.5], pose: {{xyz: [0, {half}, 0.25]}}}}
    - {{name: wall_s, shape: box, size: [{2 * half}, 0.1, 0.5], pose: {{xyz: [0, {-half}, 0.25]}}}}
    - {{name: crate, shape: box, size: [0.4, 0.4, 0.4], pose: {{xyz: [0.6, 0.6, 0.2]}}}}
robots:{"".join(robots)}
timeline:
{timeline}
"""


def scaling(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    seconds = 4.0 if args.quick else 10.0
    counts = (1, 2, 4, 8, 16)
    out: list[dict[str, Any]] = []
    for n in counts:
        plan = plan_from_text(_robots_scene(n, seconds), seconds=seconds)
        dt = plan.step_ns / 1e9
        limit = max(raw_rate(plan, plan.duration_ns // plan.step_ns) for _ in range(args.repeat))
        floor = max(s.steps / s.wall_s for s in (world_floor(plan) for _ in range(args.repeat)))
        quiet = max(s.steps / s.wall_s for s in (world_on_zenoh(plan) for _ in range(args.repeat)))
        recorded = max(_full_run(plan, tmp, f"scale{n}_{i}")[0] for i in range(args.repeat))
        out.append(
            {
                "robots": n,
                "raw_x_real_time": limit * dt,
                "floor_x_real_time": floor * dt,
                "world_x_real_time": quiet * dt,
                "recorded_x_real_time": recorded * dt,
                "floor_of_raw": floor / limit,
                "world_of_raw": quiet / limit,
                "recorded_of_raw": recorded / limit,
                # wall milliseconds per robot per sim second
                "world_ms_per_robot_second": 1e3 / (quiet * dt) / n,
                "recorded_ms_per_robot_second": 1e3 / (recorded * dt) / n,
            }
        )
        say(f"  {n} robots done")
    base_w, base_r = out[0]["world_ms_per_robot_second"], out[0]["recorded_ms_per_robot_second"]
    for row in out:
        row["world_cost_vs_1"] = row["world_ms_per_robot_second"] / base_w
        row["recorded_cost_vs_1"] = row["recorded_ms_per_robot_second"] / base_r
    rows = [
        (
            r["robots"],
            r["raw_x_real_time"],
            r["floor_x_real_time"],
            r["world_x_real_time"],
            r["world_ms_per_robot_second"],
            r["world_cost_vs_1"],
            r["recorded_x_real_time"],
            r["recorded_of_raw"],
            r["recorded_ms_per_robot_second"],
            r["recorded_cost_vs_1"],
        )
        for r in out
    ]
    text = table(
        f"scaling: diff_drive + lidar + imu + joint_states + tf per robot, {seconds:g} s sim, "
        f"best of {args.repeat}",
        (
            "robots",
            "raw × rt",
            "floor × rt",
            "world × rt",
            "ms/robot-s",
            "vs 1",
            "recorded × rt",
            "of raw",
            "ms/robot-s",
            "vs 1",
        ),
        rows,
    )
    last = out[-1]
    doc = {
        "sim_seconds": seconds,
        "rows": out,
        "targets": {
            "16 robots recorded cost per robot-second <= 1.5x one robot": last["recorded_cost_vs_1"] <= 1.5,
            "16 robots recorded >= 0.45 of raw": last["recorded_of_raw"] >= 0.45,
        },
    }
    return doc, text


def messages(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    import timeit

    import numpy as np

    from runner.sim.world import World
    from runner.wire import msgs
    from runner.wire.transport import MemoryBus

    plan = plan_from_file(TWO_ROBOTS, seconds=0.2)
    bus = MemoryBus()
    World(plan, bus).run()
    # one message per type, as the demo publishes it, and its layout as the plugin built it
    samples: dict[str, bytes] = {}
    for _key, type_name, payload, _att in bus.sent:
        if msgs.is_known(type_name):  # (not the Foxglove scene: protobuf)
            samples.setdefault(type_name, payload)
    from runner.wire.cdr import Layout

    rows = []
    doc_rows = []
    for type_name, payload in sorted(samples.items()):
        msg = msgs.decode(payload, type_name)
        probe = Layout(type_name, msg, [])
        stamps = [f for f, span in probe.spans.items() if span.time and (f.endswith("stamp") or f == "clock")]
        layout = Layout(type_name, msg, stamps)
        values = [123] * len(stamps)
        n = 20000
        fixed = timeit.timeit(lambda layout=layout, v=values: layout.encode(*v), number=n) / n * 1e6
        ros = timeit.timeit(lambda msg=msg, t=type_name: msgs.encode(msg, t), number=n) / n * 1e6
        dec = timeit.timeit(lambda p=payload, t=type_name: msgs.decode(p, t), number=n) / n * 1e6
        rows.append((type_name, len(payload), fixed, ros, ros / fixed, dec))
        doc_rows.append(
            {
                "type": type_name,
                "bytes": len(payload),
                "fixed_layout_us": fixed,
                "rosbags_encode_us": ros,
                "rosbags_decode_us": dec,
            }
        )
    del np
    text = table(
        "messages: encode cost per message (µs), as the demo's plugins publish them",
        ("type", "bytes", "fixed layout", "rosbags", "speed-up", "rosbags decode"),
        rows,
    )
    return {"rows": doc_rows}, text


_CAMERA = """
      - {{type: camera, params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 320, height: 240,
          rate: 10}}}}"""


def cameras(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import cameras as bc

    seconds = 4.0 if args.quick else 10.0
    base = plan_from_text(_robots_scene(2, seconds), seconds=seconds)
    cams = plan_from_text(_robots_scene(2, seconds, extra=_CAMERA.format()), seconds=seconds)
    dt = base.step_ns / 1e9
    without = max(_full_run(base, tmp, f"nocam{i}")[0] for i in range(args.repeat))
    cams.renderers = "world"
    inline = max(_full_run(cams, tmp, f"cam{i}")[0] for i in range(args.repeat))
    cams.renderers = "process"
    apart = max(_full_run(cams, tmp, f"camp{i}")[0] for i in range(args.repeat))
    rows: list[tuple[Any, ...]] = [
        ("2 robots, no cameras", without * dt),
        ("+ 2 × 320x240 RGB at 10 Hz, rendered in the sim process", inline * dt),
        ("+ 2 × 320x240 RGB at 10 Hz, in a renderer process", apart * dt),
    ]
    say("  demo rows done")
    renderer = gl_renderer()
    text = table(
        f"cameras: recorded runs, {seconds:g} s sim, best of {args.repeat}", ("", "× real time"), rows
    )
    doc: dict[str, Any] = {
        "sim_seconds": seconds,
        "gl_backend": os.environ.get("MUJOCO_GL", ""),
        "gl_renderer": renderer,
        "x_real_time": {
            "no_cameras": without * dt,
            "cameras_in_sim_process": inline * dt,
            "cameras_in_renderer_process": apart * dt,
        },
        "targets": {"two cameras >= 10x real time": max(inline, apart) * dt >= 10},
        "scenarios": {},
    }
    # The seeds' own camera robots as declared, against physics + MuJoCo's renderer alone (bench/cameras.py)
    scenario_rows = []
    noise_rows = []
    compression_rows: list[tuple[Any, ...]] = []
    for name in ("block_robot", "harmonic_nav"):
        secs = 2.0 if args.quick else 10.0
        plan = plan_from_file(REPO / "scenarios" / f"{name}.yaml", seconds=secs)
        steps = plan.duration_ns // plan.step_ns
        physics = max(raw_rate(plan, steps) for _ in range(args.repeat))
        bounds, floors, worlds, runs, runs_plain = [], [], [], [], []
        for i in range(args.repeat):  # alternating: the bound and the runs see the same machine
            bounds.append(bc.render_bound(plan, secs))
            st = world_floor(plan)
            floors.append(st.steps / st.wall_s)
            st = world_on_zenoh(plan)
            worlds.append(st.steps / st.wall_s)
            runs.append(_full_run(plan, tmp, f"{name}{i}")[0])
            if name == "block_robot":  # its frames recorded: the same with `record.compression: none`
                plain = plan.model_copy(deep=True)
                plain.record.compression = "none"
                runs_plain.append(_full_run(plain, tmp, f"{name}_plain{i}")[0])
        bound = min(bounds, key=lambda b: b["one_pass_wall_s"])
        renderer_wall = min(b["wall_s"] for b in bounds)
        physics_wall = steps / physics
        dt_s = plan.step_ns / 1e9
        # the limit: physics + one render (read back) per frame, at the camera's size and settings
        limit = secs / (physics_wall + bound["one_pass_wall_s"])
        with_renderer = secs / (physics_wall + renderer_wall)  # mujoco.Renderer's calls instead
        floor = max(floors) * dt_s  # the world's loop, its renders and its puts, nothing else computed
        world = max(worlds) * dt_s
        ours = max(runs) * dt_s
        specs = bc.camera_specs(plan)
        what = ", ".join(
            f"{s.width}x{s.height} {'RGB-D' if s.depth else 'RGB'} {s.rate:g} Hz" for s in specs[:1]
        ) + (f" (×{len(specs)})" if len(specs) > 1 else "")
        row = (f"{name}: {what}", limit, floor, floor / limit, world, world / limit, ours, ours / limit)
        scenario_rows.append((*row, with_renderer, ours / with_renderer))
        doc["scenarios"][name] = {
            "sim_seconds": secs,
            "physics_x_real_time": physics * dt_s,
            "render_bound": bound,
            "limit_x_real_time": limit,
            "mujoco_renderer_limit_x_real_time": with_renderer,
            "world_floor_x_real_time": floor,
            "world_x_real_time": world,
            "x_real_time": ours,
            "x_real_time_runs": [r * dt_s for r in runs],
            "ratio_to_limit": ours / limit,
            "world_floor_ratio_to_limit": floor / limit,
            "world_ratio_to_limit": world / limit,
            "ratio_to_mujoco_renderer_limit": ours / with_renderer,
        }
        for spec in specs[:1]:
            if spec.noise > 0:
                cost = bc.noise_cost(spec.width, spec.height, spec.noise)
                per_frame = bound["cameras"][0]["one_pass_ms_per_frame"]
                noise_rows.append(
                    (f"{name}: {spec.width}x{spec.height} RGB, stddev {spec.noise:g}", cost["plain_ms"],
                     cost["noisy_ms"], cost["noise_ms"], per_frame, cost["noise_ms"] / per_frame)
                )  # fmt: skip
                doc["scenarios"][name]["noise"] = {**cost, "render_ms_per_frame": per_frame}
        if runs_plain:
            sizes = {c: (tmp / f"{name}{c}0.mcap").stat().st_size / secs / 1e6 for c in ("", "_plain")}
            plain = max(runs_plain) * dt_s
            compression_rows = [
                ("zstd (the default)", ours, ours / limit, sizes[""]),
                ("none", plain, plain / limit, sizes["_plain"]),
            ]
            doc["scenarios"][name]["uncompressed"] = {
                "x_real_time": plain,
                "ratio_to_limit": plain / limit,
                "mb_per_sim_second": sizes["_plain"],
                "zstd_mb_per_sim_second": sizes[""],
            }
        say(f"  {name} done")
    text += "\n\n" + table(
        f"cameras at declared sizes, {10 if not args.quick else 2} s sim, best of {args.repeat} alternating: "
        f"limit = physics + one render per frame (GL: {renderer or 'unknown'})",
        ("scenario", "limit × rt", "world floor × rt", "of the limit", "world × rt", "of the limit",
         "scenario run × rt", "of the limit", "mujoco.Renderer limit × rt", "run of it"),
        scenario_rows,
    )  # fmt: skip
    if compression_rows:
        text += "\n\n" + table(
            "block_robot recorded, by `record.compression`: the recorder's zstd (~5 ms per noisy 800x800 "
            "frame) shares the 2 cores with the rendering",
            ("record.compression", "scenario run × rt", "of the limit", "MB per sim second"),
            compression_rows,
        )
    if noise_rows:
        text += "\n\n" + table(
            "camera noise per frame (ms): the frame written plain and with Gazebo noise, against its render",
            ("camera", "plain copy", "with noise", "noise", "render", "noise / render"),
            noise_rows,
        )
    # a frame's bytes from the camera into the MCAP (bench/cameras.py copies)
    br_plan = plan_from_file(REPO / "scenarios" / "block_robot.yaml", seconds=1.0)
    sizes = bc.camera_specs(br_plan)[0]
    c = bc.copies(bc.rendered_frame(br_plan), frames=30 if args.quick else 120)
    doc["copies"] = c
    unit = c["copy_ms"]
    text += "\n\n" + table(
        f"a {sizes.width}x{sizes.height} RGB frame ({c['frame_bytes'] / 1e6:.2f} MB) on its way into the "
        "MCAP, ms per frame (a plain copy of its bytes is the unit)",
        ("", "ms", "plain copies' worth"),
        [
            ("plain copy of the frame's bytes", unit, 1.0),
            ("world: send from Zenoh shared memory (one copy into it, then put)", c["send_ms"],
             c["send_ms"] / unit),
            ("world: put the bytes as they are (Zenoh copies them, twice)", c["send_as_bytes_ms"],
             c["send_as_bytes_ms"] / unit),
            ("recorder: to_bytes (the one copy it makes)", c["recorder_to_bytes_ms"],
             c["recorder_to_bytes_ms"] / unit),
            ("recorder: all its work per frame (to_bytes, zstd, CRC, write)", c["recorder_take_ms"],
             c["recorder_take_ms"] / unit),
            ("  of which zstd level 1", c["recorder_zstd_ms"], c["recorder_zstd_ms"] / unit),
        ],
    )  # fmt: skip
    br = doc["scenarios"]["block_robot"]
    doc["targets"].update(
        {
            f"{n} >= 0.7 of its rendering bound": doc["scenarios"][n]["ratio_to_limit"] >= 0.7
            for n in doc["scenarios"]
        }
    )
    doc["targets"]["block_robot >= 1x real time"] = br["x_real_time"] >= 1.0
    doc["targets"]["camera noise <= 10 % of a frame's render"] = all(r[-1] <= 0.10 for r in noise_rows)
    return doc, text


_COMMANDER = textwrap.dedent(
    """
    import random, sys, time, zenoh
    from runner.wire import msgs
    from runner.wire.transport import make_config, pack_attachment
    key, seconds = sys.argv[2], float(sys.argv[3])
    conf = make_config("client", connect=[sys.argv[1]])
    Twist = msgs.T["geometry_msgs/msg/Twist"]
    Vec = msgs.T["geometry_msgs/msg/Vector3"]
    with zenoh.open(conf) as s:
        enc = zenoh.Encoding.APPLICATION_CDR.with_schema("geometry_msgs/msg/Twist")
        pub = s.declare_publisher(key, encoding=enc)
        while not pub.matching_status.matching:
            time.sleep(0.01)
        rnd = random.Random(3)
        end = time.monotonic() + seconds
        i = 0
        while time.monotonic() < end:
            time.sleep(rnd.uniform(0.02, 0.06))  # random phase against the control period
            sent = time.monotonic()
            msg = Twist(linear=Vec(x=0.1 + 0.01 * (i % 2), y=0.0, z=sent), angular=Vec(x=0.0, y=0.0, z=0.0))
            pub.put(bytes(msgs.encode(msg, "geometry_msgs/msg/Twist")), attachment=pack_attachment(i, 0))
            i += 1
    """
)


def realtime(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    """The world runs in this process (so the controller can be timed) on a router session; the commander
    is another process that connects to it, as a user's node would."""
    import statistics

    import zenoh

    from plugins.diff_drive import WheelDrive
    from runner.sim.world import World
    from runner.wire.transport import ZenohBus, make_config

    seconds = 10.0 if args.quick else 60.0
    plan = plan_from_file(TWO_ROBOTS, seconds=seconds)
    plan.rate = "realtime"
    plan.timeline = []
    pending: list[float] = []
    delays: list[float] = []
    on_cmd, before = WheelDrive._on_cmd, WheelDrive.before_step

    def timed_on_cmd(self: Any, msg: Any, stamp_ns: int) -> None:
        if self.ctx.robot.name == "r1":
            pending.append(float(msg.linear.z))
        on_cmd(self, msg, stamp_ns)

    started = {"at": float("inf")}

    def timed_before(self: Any, now_ns: int) -> None:
        before(self, now_ns)
        if pending and self.ctx.robot.name == "r1":
            now = time.monotonic()
            # commands sent before the loop started waited for it, not for the loop: not counted
            delays.extend(now - t for t in pending if t >= started["at"])
            pending.clear()

    def on_progress(ns: int) -> None:
        progress.append((time.perf_counter(), ns))

    progress: list[tuple[float, int]] = []
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    WheelDrive._on_cmd, WheelDrive.before_step = timed_on_cmd, timed_before  # type: ignore[method-assign]
    try:
        with zenoh.open(make_config("router", listen=[endpoint])) as session:
            bus = ZenohBus(session)
            world = World(plan, bus)
            proc = subprocess.Popen(
                [sys.executable, "-c", _COMMANDER, endpoint, f"{plan.name}/r1/cmd_vel", str(seconds - 1.0)],
                cwd=REPO,
            )
            time.sleep(1.0)  # the commander connects and sees the subscriber
            started["at"] = time.monotonic()
            try:
                stats = world.run(on_progress=on_progress)
            finally:
                proc.wait(timeout=30)
                bus.undeclare_all()
    finally:
        WheelDrive._on_cmd, WheelDrive.before_step = on_cmd, before  # type: ignore[method-assign]
    factor = stats.sim_ns / 1e9 / stats.wall_s
    # worst one-second window of the factor
    worst = 0.0
    j = 0
    for i in range(len(progress)):
        while j < len(progress) and progress[j][0] - progress[i][0] < 1.0:
            j += 1
        if j == len(progress):
            break
        w, s = progress[j][0] - progress[i][0], (progress[j][1] - progress[i][1]) / 1e9
        worst = max(worst, abs(s / w - 1.0))
    period = 1.0 / 50.0  # the drive's control period in the demo
    ms = sorted(d * 1e3 for d in delays)
    if not ms:
        raise SystemExit("realtime: no command reached the controller")
    q = statistics.quantiles(ms, n=100)
    bound = 1.0 + period * 1e3
    within = sum(1 for v in ms if v <= bound) / len(ms)
    rows = [
        ("real-time factor over the run", f"{factor:.4f}", f"{abs(factor - 1) * 100:.2f} % off"),
        ("worst 1 s window", "", f"{worst * 100:.2f} % off"),
        (f"cmd_vel -> controller, {len(ms)} commands: median", f"{statistics.median(ms):.2f} ms", ""),
        ("  p90 / p99 / max", f"{q[89]:.2f} / {q[98]:.2f} / {ms[-1]:.2f} ms", ""),
        (f"  within 1 ms + one control period ({bound:.0f} ms)", f"{within * 100:.1f} %", ""),
    ]
    text = table(f"realtime: {seconds:g} s at rate: realtime", ("", "value", ""), rows)
    doc = {
        "sim_seconds": seconds,
        "factor": factor,
        "worst_window_deviation": worst,
        "cmd_delay_ms": {
            "n": len(ms),
            "median": statistics.median(ms),
            "p90": q[89],
            "p99": q[98],
            "max": ms[-1],
            "min": ms[0],
            "control_period_ms": period * 1e3,
            "share_within_bound": within,
        },
        "targets": {
            "factor within 2%": abs(factor - 1) <= 0.02,
            "cmd delay p99 <= 1 ms + one control period": q[98] <= bound,
            "cmd delay max <= 1 ms + one control period": ms[-1] <= bound,
        },
    }
    return doc, text


def lockstep(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    """The go-to-goal example: its controller node in lockstep with the world, and free-running."""
    from bench.common import REPO as repo

    seconds = 15.0
    path = repo / "scenarios" / "go_to_goal.yaml"
    stepped = plan_from_file(path, seconds=seconds)
    free = plan_from_file(path, seconds=seconds)
    free.lockstep = []
    dt = stepped.step_ns / 1e9
    rates = {}
    for label, plan in (("lockstep", stepped), ("free", free)):
        rates[label] = max(_full_run(plan, tmp, f"{label}{i}")[0] for i in range(args.repeat)) * dt
    rows = [
        ("controller node in lockstep (repeatable)", rates["lockstep"]),
        ("controller node free-running (rate: max outruns it)", rates["free"]),
    ]
    text = table(
        f"lockstep: go_to_goal, a robot and its controller node at 10 Hz, {seconds:g} s sim, "
        f"best of {args.repeat}",
        ("", "× real time"),
        rows,
    )
    return {"sim_seconds": seconds, "x_real_time": rates}, text


def recorder(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import recorder as rec

    doc = rec.run(seconds=2.0 if args.quick else 5.0)
    rows = [(k, v) for k, v in doc.items() if isinstance(v, int | float) and not isinstance(v, bool)]
    return doc, table("recorder: another process publishing as fast as it can", ("", "value"), rows)


def soak(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench.soak import soak as run_soak

    seconds = 120.0 if args.quick else 600.0
    doc = run_soak(seconds)
    rows = [(k, v) for k, v in doc.items() if not isinstance(v, list)]
    grow = max(doc.get(f"{p}_rss_{g}growth_pct", 0.0) for p in ("runner", "world") for g in ("", "peak_"))
    doc["targets"] = {"RSS growth < 10 % and nothing lost": grow < 10.0 and doc["lost"] == 0}
    return doc, table(
        f"soak: two_robots, {seconds:g} s sim at rate: max, recorded, --strict", ("", "value"), rows
    )


def plugins(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import plugins as pl

    argv = ["--out", str(args.results / "plugins.json")]
    if args.quick:
        argv += ["--repeat", "1", "--min-time", "0.3"]
    doc = pl.main(argv)
    return doc, ""


def meshes(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import meshes as bm

    doc = bm.run(args.quick)
    rows = doc["rows"]
    text = table(
        "Non-convex static meshes (convex pieces)",
        ["mesh", "triangles", "pieces", "first s", "cached s", "MuJoCo compile: mesh / pieces s"],
        [
            [r["mesh"], r["triangles"], r["pieces"], r["first_s"], r["cached_s"],
             f"{r['compile_mesh_s']} / {r['compile_pieces_s']}"]
            for r in rows
        ],
    )  # fmt: skip
    big = rows[0]
    doc["targets"] = {
        "a 50k-triangle building is ready in < 10 s the first time": big["ready_first_s"] < 10
        and big["triangles"] >= 50_000,
        "... and in < 0.2 s from the cache": big["cached_s"] < 0.2 and big["triangles"] >= 50_000,
    }
    return doc, text


def actors(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import actors as ba

    return ba.run(args.quick, args.repeat)


def ray(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import ray as br

    return br.run(args.quick, args.repeat)


def limits(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import limits as bl

    return bl.run(args.quick)


def hardware(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import hardware as bh

    return bh.run(args.quick)


def mobile(args: argparse.Namespace, tmp: Path) -> tuple[dict[str, Any], str]:
    from bench import mobile as bm

    return bm.run(args.quick)


RUNNERS = {
    "two_robots": two_robots,
    "scaling": scaling,
    "messages": messages,
    "cameras": cameras,
    "realtime": realtime,
    "lockstep": lockstep,
    "recorder": recorder,
    "soak": soak,
    "plugins": plugins,
    "meshes": meshes,
    "actors": actors,
    "ray": ray,
    "limits": limits,
    "hardware": hardware,
    "mobile": mobile,
}


def main(argv: list[str] | None = None) -> int:
    import tempfile

    ap = argparse.ArgumentParser(
        prog="python -m bench", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--quick", action="store_true", help="shorter runs (a smoke test of the suite)")
    ap.add_argument("--only", default="", help=f"comma-separated sections of: {', '.join(SECTIONS)}")
    ap.add_argument("--repeat", type=int, default=3, help="best of N for each figure")
    ap.add_argument("--readme", action="store_true", help="write the tables into README.md")
    ap.add_argument("--results", type=Path, default=RESULTS, help="folder for the JSON results")
    args = ap.parse_args(argv)
    results = args.results
    if args.quick:
        args.repeat = min(args.repeat, 1)
    chosen = [s.strip() for s in args.only.split(",") if s.strip()] or list(SECTIONS)
    unknown = [s for s in chosen if s not in RUNNERS]
    if unknown:
        ap.error(f"unknown section(s) {', '.join(unknown)}; sections: {', '.join(SECTIONS)}")
    info = machine()
    say(f"machine: {info['cpu']}, {info['cpus']} cpus, Python {info['python']}, MuJoCo {info['mujoco']}")
    results.mkdir(parents=True, exist_ok=True)
    texts: dict[str, str] = {}
    with tempfile.TemporaryDirectory() as tmp_dir:
        for name in chosen:
            say(f"\n[{name}]")
            t0 = time.perf_counter()
            doc, text = RUNNERS[name](args, Path(tmp_dir))
            if text:
                say("\n" + text)
                texts[name] = text
            if name != "plugins":  # bench/plugins.py writes its own file
                doc = {"benchmark": name, "machine": info, "quick": args.quick, **doc}
                (results / f"{name}.json").write_text(json.dumps(doc, indent=2) + "\n")
            for target, met in (doc.get("targets") or {}).items():
                if isinstance(met, bool):
                    say(f"  target {'met    ' if met else 'NOT met'}: {target}")
                elif isinstance(met, dict) and "met" in met:
                    say(f"  target {'met    ' if met['met'] else 'NOT met'}: {target}")
            say(f"  ({time.perf_counter() - t0:.0f} s)")
    if args.readme and texts:
        _write_readme(texts, info)
    return 0


def _write_readme(texts: dict[str, str], info: dict[str, Any]) -> None:
    """The tables of the sections that ran written into README.md between the bench markers, each with the
    machine and day it was measured on; the tables of sections that did not run are kept as they are (with
    their own machine line), all in the suite's order."""
    readme = REPO / "README.md"
    text = readme.read_text()
    begin, end = "<!-- bench:begin -->", "<!-- bench:end -->"
    if begin not in text or end not in text:
        say("README.md has no bench markers; tables not written")
        return
    a, b = text.index(begin) + len(begin), text.index(end)
    tables = readme_tables(text[a:b])
    where = (
        f"_{info['cpu']} ({info['cpus']} cpus), Python {info['python']}, MuJoCo {info['mujoco']}, "
        f"{info['date'][:10]}_"
    )
    for name, t in texts.items():
        title, _, rest = re.sub(r"^### ", "#### ", t, flags=re.M).partition("\n")
        tables[name] = f"{title}\n\n{where}\n{rest}".rstrip()
    order = [n for n in SECTIONS if n in tables] + [n for n in tables if n not in SECTIONS]
    body = "\n\n".join([README_HEAD, *[tables[n] for n in order]])
    readme.write_text(text[:a] + "\n" + body + "\n" + text[b:])
    say("README.md tables updated")


README_HEAD = "Measured by `python -m bench`; under each table, the machine and the day it was measured on."


if __name__ == "__main__":
    raise SystemExit(main())
