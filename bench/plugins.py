"""Benchmark: what each built-in plugin costs per call, camera frames/s and lidar rays/s.

    python bench/plugins.py [--seconds 2] [--repeat 3]

All figures come from one run on the project's robot (scenarios/robots/diffbot.urdf.xacro) in a small
walled arena with a few boxes, so they are comparable on a noisy machine (best of `--repeat` for each):

- per-call cost: every plugin of the built-in set runs inside a real `World` on an in-memory bus (a
  `MemoryBus` that drops payloads once encoded); each bound hook is wrapped with a timer before `run()`,
  so a call includes the message building and CDR encoding the hook does (not the transport). Median
  and mean per call, in µs;
- cameras: frames/s rendering only (`CameraRenderer.update` + `rgb()` / `depth()`) and end to end
  (the plugin's `after_step`: render, message, encoding), RGB at 320x240 and 640x480, depth (with
  colour and points) at 320x240;
- lidar: rays/s of the plugin's `scan()` (`mj_multiRay`), 2D 360 beams and 3D 16 x 1024.

Targets (issue): >= 100 frames/s for a 320x240 RGB camera without shadows on a CPU-only machine
(rendering), >= 1 M rays/s for the lidar. Results are printed as a table and written to
bench/results/plugins.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import textwrap
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(REPO) not in sys.path:  # `python bench/plugins.py` from a checkout without the package installed
    sys.path.insert(0, str(REPO))
# Headless rendering: the backend is chosen before mujoco is imported (as plugins._render.ensure_gl_backend).
if "MUJOCO_GL" not in os.environ:
    os.environ["MUJOCO_GL"] = "egl"
    os.environ["SCENARIO_GL_AUTO"] = "1"

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from bench.common import gl_renderer  # noqa: E402
from plugins._render import CameraRenderer, gl_backend_in_use  # noqa: E402
from runner.compile import compile_plan  # noqa: E402
from runner.plan import RunPlan  # noqa: E402
from runner.scenario.loader import load_file  # noqa: E402
from runner.scenario.validate import validate_scenario  # noqa: E402
from runner.sim.world import World  # noqa: E402
from runner.wire.transport import MemoryBus  # noqa: E402

DIFFBOT = REPO / "scenarios" / "robots" / "diffbot.urdf.xacro"

ARENA = """
world:
  physics: {timestep: 0.002}
  models:
    - {name: wall_n, shape: box, size: [8.2, 0.1, 0.5], pose: {xyz: [0, 4, 0.25]}}
    - {name: wall_s, shape: box, size: [8.2, 0.1, 0.5], pose: {xyz: [0, -4, 0.25]}}
    - {name: wall_e, shape: box, size: [0.1, 8.2, 0.5], pose: {xyz: [4, 0, 0.25]}}
    - {name: wall_w, shape: box, size: [0.1, 8.2, 0.5], pose: {xyz: [-4, 0, 0.25]}}
    - {name: crate, shape: box, size: [0.6, 0.6, 0.6], pose: {xyz: [2, 0.5, 0.3]}, rgba: [0.6, 0.45, 0.25, 1]}
    - {name: pillar, shape: cylinder, size: [0.3, 1.0], pose: {xyz: [2.5, -1.2, 0.5]},
       rgba: [0.3, 0.6, 0.3, 1]}
    - {name: red_box, shape: box, size: [0.4, 1.0, 0.8], pose: {xyz: [3, 1.8, 0.4]}, rgba: [0.9, 0.1, 0.1, 1]}
"""

# Every built-in plugin, at a rate that gives enough calls in a couple of sim seconds. The drives that
# would fight over the same wheels sit on robots of their own.
PLUGINS_SCENE = """
name: bench_plugins
duration: {duration}
rate: max
seed: 1
{arena}
robots:
  - name: r1
    description: {{file: "{diffbot}"}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive, params: {{rate: 100}}}}
      - {{type: lidar, name: lidar_2d, params: {{link: lidar_link, samples: 360, rate: 50, range_max: 10.0,
          noise_stddev: 0.01}}}}
      - {{type: lidar, name: lidar_3d, params: {{link: lidar_link, topic: scan3d, samples: 1024, rate: 10,
          vertical_samples: 16, vertical_min_angle: -0.26, vertical_max_angle: 0.26, range_max: 10.0}}}}
      - {{type: imu, params: {{link: imu_link, rate: 200, angular_velocity_stddev: 0.001,
          linear_acceleration_stddev: 0.01}}}}
      - {{type: joint_states, params: {{rate: 100}}}}
      - {{type: ground_truth, params: {{rate: 100}}}}
      - {{type: camera, params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 320, height: 240,
          rate: 20}}}}
      - {{type: depth_camera, params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 320,
          height: 240, rate: 10, image_topic: rgbd/image, info_topic: rgbd/camera_info}}}}
  - name: r2
    description: {{file: "{diffbot}"}}
    pose: {{xyz: [-2, 2, 0.06]}}
    plugins:
      - {{type: skid_steer, params: {{rate: 100, left_joints: [left_wheel_joint],
          right_joints: [right_wheel_joint]}}}}
  - name: r3
    description: {{file: "{diffbot}"}}
    pose: {{xyz: [-2, -2, 0.06]}}
    plugins:
      - {{type: planar_move, params: {{rate: 100}}}}
  - name: r4
    description: {{file: "{diffbot}"}}
    pose: {{xyz: [-2, 0, 0.06]}}
    plugins:
      - {{type: joint_controller, params: {{joints: [left_wheel_joint, right_wheel_joint], mode: velocity}}}}
timeline:
  - {{t: 0.1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist,
      data: {{linear: {{x: 0.3}}, angular: {{z: 0.4}}}}}}
  - {{t: 0.1, topic: r2/cmd_vel, type: geometry_msgs/msg/Twist,
      data: {{linear: {{x: 0.3}}, angular: {{z: -0.4}}}}}}
  - {{t: 0.1, topic: r3/cmd_vel, type: geometry_msgs/msg/Twist,
      data: {{linear: {{x: 0.2}}, angular: {{z: 0.3}}}}}}
{commands}
"""

# Cameras for the frame-rate figures (their rate does not matter: they are driven directly).
CAMERAS_SCENE = """
name: bench_cameras
duration: 0.1
rate: max
{arena}
robots:
  - name: r1
    description: {{file: "{diffbot}"}}
    pose: {{xyz: [0, 0, 0.06], rpy: [0, 0, 0.3]}}
    plugins:
      - {{type: camera, name: cam_qvga, params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 320,
          height: 240, image_topic: qvga/image, info_topic: qvga/info}}}}
      - {{type: camera, name: cam_vga, params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 640,
          height: 480, image_topic: vga/image, info_topic: vga/info}}}}
      - {{type: depth_camera, name: rgbd, params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 320,
          height: 240, image_topic: rgbd/image, info_topic: rgbd/info, depth_topic: rgbd/depth,
          depth_info_topic: rgbd/depth_info, points_topic: rgbd/points}}}}
      - {{type: depth_camera, name: depth_only, params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}},
          width: 320, height: 240, publish_color: false, depth_topic: d/depth, depth_info_topic: d/info,
          points_topic: null}}}}
"""

# Hook rows of the per-call table: (plugin name in PLUGINS_SCENE, robot, hook, label).
HOOK_ROWS = [
    ("diff_drive", "r1", "before_step", "diff_drive before_step (100 Hz)"),
    ("diff_drive", "r1", "after_step", "diff_drive after_step: odom + tf"),
    ("lidar_2d", "r1", "after_step", "lidar 360 beams: LaserScan"),
    ("lidar_3d", "r1", "after_step", "lidar 3D 16x1024: LaserScan + PointCloud2"),
    ("imu", "r1", "after_step", "imu"),
    ("joint_states", "r1", "after_step", "joint_states"),
    ("ground_truth", "r1", "after_step", "ground_truth"),
    ("camera", "r1", "after_step", "camera 320x240 rgb8: Image + CameraInfo"),
    ("depth_camera", "r1", "after_step", "depth_camera 320x240: rgb + depth + points"),
    ("planar_move", "r3", "before_step", "planar_move before_step"),
    ("planar_move", "r3", "after_step", "planar_move after_step: odom + tf"),
    ("skid_steer", "r2", "before_step", "skid_steer before_step"),
    ("skid_steer", "r2", "after_step", "skid_steer after_step: odom + tf"),
    ("joint_controller", "r4", "_on_array", "joint_controller per command (no step hook)"),
]

TARGET_FPS_QVGA = 100.0
TARGET_RAYS = 1e6


class DropBus(MemoryBus):
    """A MemoryBus that counts what is published instead of keeping it (camera frames add up)."""

    def __init__(self) -> None:
        super().__init__()
        self.bytes = 0
        self.count = 0

    def publisher(self, key: str, type_name: str) -> Callable[[bytes | bytearray, bytes], None]:
        def send(payload: bytes | bytearray, attachment: bytes) -> None:
            self.bytes += len(payload)
            self.count += 1

        return send


def plan_from(text: str, tmp: Path, duration: float | None = None) -> RunPlan:
    path = tmp / "bench.yaml"
    duration = duration or 1.0
    # joint_controller has no step hook (its actuators do the work): it is timed per command received.
    commands = "\n".join(
        f"  - {{t: {t / 10:g}, topic: r4/joint_controller/command, type: std_msgs/msg/Float64MultiArray, "
        f"data: {{data: [{3 + t % 3:g}, 4.0]}}}}"
        for t in range(1, int(duration * 10))
    )
    body = text.format(
        arena=textwrap.dedent(ARENA).strip(), diffbot=DIFFBOT, duration=duration, commands=commands
    )
    path.write_text(textwrap.dedent(body).lstrip())
    doc = load_file(path)
    return compile_plan(validate_scenario(doc), doc)


def time_hooks(plan: RunPlan) -> tuple[dict[tuple[str, str, str], list[float]], float]:
    """Run the world once with every hook timed. Returns {(plugin, robot, hook): [seconds per call]}
    and the run's steps/s."""
    world = World(plan, DropBus())
    samples: dict[tuple[str, str, str], list[float]] = {}

    def timed(fn: Callable[..., None], times: list[float]) -> Callable[..., None]:
        clock = time.perf_counter

        def call(*args: Any) -> None:
            t0 = clock()
            fn(*args)
            times.append(clock() - t0)

        return call

    for hooks in (world._before, world._after):
        for h in hooks:
            plugin = h.fn.__self__  # type: ignore[attr-defined]  (a bound hook of a plugin)
            if plugin not in world.plugins:  # the world's own feeds (the Foxglove scene): not a plugin
                continue
            key = (plugin.name, plugin.ctx.robot.name, h.fn.__name__)
            h.fn = timed(h.fn, samples.setdefault(key, []))
    # Subscription callbacks of plugins (commands), delivered in the loop.
    for subs in world._local.values():
        for i, (type_name, cb) in enumerate(subs):
            owner = getattr(cb, "__self__", None)
            if owner in world.plugins:
                key = (owner.name, owner.ctx.robot.name, cb.__name__)
                subs[i] = (type_name, timed(cb, samples.setdefault(key, [])))
    stats = world.run()
    return samples, stats.steps / stats.wall_s


def best_rate(fn: Callable[[], Any], min_s: float, repeat: int, warmup: int = 3) -> float:
    """Calls per second of `fn`, best of `repeat` runs of at least `min_s` each."""
    for _ in range(warmup):
        fn()
    best = 0.0
    for _ in range(repeat):
        n = 0
        t0 = time.perf_counter()
        while True:
            fn()
            n += 1
            dt = time.perf_counter() - t0
            if dt >= min_s:
                break
        best = max(best, n / dt)
    return best


def main(argv: list[str] | None = None) -> dict[str, Any]:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=2.0, help="sim seconds of the per-call run")
    ap.add_argument("--repeat", type=int, default=3, help="best of N for each figure")
    ap.add_argument("--min-time", type=float, default=1.0, help="wall seconds per rate measurement")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "plugins.json", help="JSON results file")
    args = ap.parse_args(argv)

    with tempfile.TemporaryDirectory() as tmp_dir:
        tmp = Path(tmp_dir)
        plugins_plan = plan_from(PLUGINS_SCENE, tmp, args.seconds)
        cameras_plan = plan_from(CAMERAS_SCENE, tmp)

    # ------------------------------------------------------------------ (a) per-call cost inside a World
    per_call: dict[tuple[str, str, str], dict[str, float]] = {}
    world_rate = 0.0
    for _ in range(args.repeat):
        samples, steps_per_s = time_hooks(plugins_plan)
        world_rate = max(world_rate, steps_per_s)
        for key, times in samples.items():
            if not times:
                continue
            med, mean = statistics.median(times) * 1e6, statistics.fmean(times) * 1e6
            old = per_call.get(key)
            if old is None or med < old["median_us"]:
                per_call[key] = {"median_us": med, "mean_us": mean, "calls": len(times)}

    # ------------------------------------------------------------------- (b) cameras, (c) lidar
    world = World(cameras_plan, DropBus())
    mujoco.mj_forward(world.model, world.data)
    cams = {p.name: p for p in world.plugins}
    data = world.data

    def render_rgb(cam: Any) -> Callable[[], Any]:
        r: CameraRenderer = cam.renderer

        def f() -> None:
            r.update(data)
            r.rgb()

        return f

    def render_rgbd(cam: Any) -> Callable[[], Any]:
        r: CameraRenderer = cam.renderer

        both = getattr(r, "rgbd", None)  # one render for both where it gives the same depth

        def f() -> None:
            r.update(data)
            if both is not None:
                both()
            else:
                r.rgb()
                r.depth()

        return f

    def render_depth(cam: Any) -> Callable[[], Any]:
        r: CameraRenderer = cam.renderer

        def f() -> None:
            r.update(data)
            r.depth()

        return f

    def end_to_end(cam: Any) -> Callable[[], Any]:
        return lambda: cam.after_step(0)

    fps_rows = [
        ("rgb 320x240", "render", render_rgb(cams["cam_qvga"])),
        ("rgb 320x240", "end to end", end_to_end(cams["cam_qvga"])),
        ("rgb 640x480", "render", render_rgb(cams["cam_vga"])),
        ("rgb 640x480", "end to end", end_to_end(cams["cam_vga"])),
        ("depth 320x240", "render", render_depth(cams["depth_only"])),
        ("depth 320x240", "end to end", end_to_end(cams["depth_only"])),
        ("rgb + depth 320x240", "render", render_rgbd(cams["rgbd"])),
        ("rgb + depth + points 320x240", "end to end", end_to_end(cams["rgbd"])),
    ]
    fps = [(what, how, best_rate(fn, args.min_time, args.repeat)) for what, how, fn in fps_rows]
    for p in world.plugins:
        p.close()

    lidar_world = World(plugins_plan, DropBus())
    lidars = {p.name: p for p in lidar_world.plugins if p.name.startswith("lidar")}
    ray_rows = []
    for name, label in (("lidar_2d", "2D, 360 beams"), ("lidar_3d", "3D, 16 x 1024 beams")):
        lidar = lidars[name]
        n = len(lidar.dist)
        scans = best_rate(lidar.scan, args.min_time, args.repeat)
        raw = _raw_multiray(lidar)
        raw_rays = best_rate(raw, args.min_time, args.repeat) * n if raw else None
        ray_rows.append((label, n, scans, scans * n, _recast(lidar), raw_rays))
    for p in lidar_world.plugins:
        p.close()

    # ------------------------------------------------------------------------------------------ report
    print(
        f"plugins: diffbot in an arena, MUJOCO_GL={os.environ.get('MUJOCO_GL', '')} "
        f"(backend {gl_backend_in_use()}), best of {args.repeat}"
    )
    print(f"world with every plugin: {world_rate:.0f} steps/s (hooks timed)")
    print()
    header = "plugin hook (per call, incl. message + CDR)"
    print(f"{header:52s} {'median µs':>10s} {'mean µs':>10s} {'calls':>6s}")
    for name, robot, hook, label in HOOK_ROWS:
        row = per_call.get((name, robot, hook))
        if row is None:
            continue
        print(f"{label:52s} {row['median_us']:10.1f} {row['mean_us']:10.1f} {row['calls']:6d}")
    print()
    print(f"{'camera':32s} {'':12s} {'frames/s':>9s} {'ms/frame':>9s}")
    for what, how, rate in fps:
        print(f"{what:32s} {how:12s} {rate:9.1f} {1e3 / rate:9.2f}")
    print()
    print(
        f"{'lidar scan() (mj_multiRay)':32s} {'rays':>6s} {'scans/s':>9s} {'M rays/s':>9s} {'re-cast':>8s} "
        f"{'one mj_multiRay, M rays/s':>26s}"
    )
    for label, n, scans, rays, recast, raw_rays in ray_rows:
        raw_text = f"{raw_rays / 1e6:.2f}" if raw_rays else "-"
        recast_text = "-" if recast is None else str(recast)
        print(f"{label:32s} {n:6d} {scans:9.0f} {rays / 1e6:9.2f} {recast_text:>8s} {raw_text:>26s}")
    print(
        "  re-cast: rays whose first hit is a geom the lidar skips (the robot's own), cast again one by one"
    )
    qvga = next(rate for what, how, rate in fps if what == "rgb 320x240" and how == "render")
    rays_min = min(row[3] for row in ray_rows)
    print()
    print(
        f"targets: rgb 320x240 render {qvga:.0f} frames/s (>= {TARGET_FPS_QVGA:.0f}: "
        f"{'met' if qvga >= TARGET_FPS_QVGA else 'NOT met'}); lidar {rays_min / 1e6:.2f} M rays/s "
        f"(>= {TARGET_RAYS / 1e6:g} M: {'met' if rays_min >= TARGET_RAYS else 'NOT met'})"
    )

    result_doc = {
        "benchmark": "plugins",
        "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "machine": {
            "python": platform.python_version(),
            "platform": platform.platform(),
            "processor": _cpu_name(),
            "cpus": os.cpu_count(),
            "mujoco": mujoco.__version__,
            "mujoco_gl": os.environ.get("MUJOCO_GL", ""),
            "gl_backend": gl_backend_in_use(),
            "gl_renderer": gl_renderer(),
        },
        "repeat": args.repeat,
        "sim_seconds": args.seconds,
        "world_steps_per_s": world_rate,
        "per_call_us": {
            label: dict(per_call[(name, robot, hook)], plugin=name, hook=hook)
            for name, robot, hook, label in HOOK_ROWS
            if (name, robot, hook) in per_call
        },
        "camera_frames_per_s": [
            {"image": what, "measure": how, "frames_per_s": rate} for what, how, rate in fps
        ],
        "lidar": [
            {
                "lidar": label,
                "rays": n,
                "scans_per_s": scans,
                "rays_per_s": rays,
                "rays_recast_one_by_one": recast,
                "one_multiray_call_rays_per_s": raw_rays,
            }
            for label, n, scans, rays, recast, raw_rays in ray_rows
        ],
        "targets": {
            "rgb_320x240_render_frames_per_s": {
                "target": TARGET_FPS_QVGA,
                "value": qvga,
                "met": qvga >= TARGET_FPS_QVGA,
            },
            "lidar_rays_per_s": {"target": TARGET_RAYS, "value": rays_min, "met": rays_min >= TARGET_RAYS},
        },
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result_doc, indent=2) + "\n")
    try:
        shown = args.out.resolve().relative_to(REPO)
    except ValueError:
        shown = args.out
    print(f"wrote {shown}")
    return result_doc


def _raw_multiray(lidar: Any) -> Callable[[], None] | None:
    """One `mj_multiRay` call with the lidar's rays, nothing else (what scan() does before its re-casts);
    None if the plugin's internals are not the ones this reads."""
    try:
        m, d = lidar.ctx.model, lidar.ctx.data
        site, local, group, body = lidar.site, lidar.local, lidar.geomgroup, lidar.body
        geomid, dist, cutoff = lidar.geomid.copy(), lidar.dist.copy(), float(lidar.params.range_max)
    except AttributeError:
        return None

    def cast() -> None:
        vec = (d.site_xmat[site].reshape(3, 3) @ local).T.copy()
        mujoco.mj_multiRay(
            m,
            d,
            d.site_xpos[site].copy(),
            vec.reshape(-1),
            group,
            1,
            body,
            geomid,
            dist,
            None,
            len(dist),
            cutoff,
        )

    return cast


def _recast(lidar: Any) -> int | None:
    """How many of the last scan's rays first hit a geom the lidar skips (re-cast one by one by scan())."""
    try:
        lidar.scan()
        gid, skip = lidar.geomid, lidar.skip
    except AttributeError:
        return None
    return int(((gid >= 0) & skip[np.maximum(gid, 0)]).sum())


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


if __name__ == "__main__":
    main()
