"""The camera scenarios as declared against their limit: physics plus MuJoCo's rendering alone.

For a scenario with cameras (`block_robot`: two 800x800 RGB cameras at 30 Hz with Gazebo noise;
`harmonic_nav`: an 800x600 RGB-D camera at 100 Hz), measured in one run, alternating, best of N:

- physics: the compiled model's raw step rate (batched `mj_step`, no plugins), for the run's steps;
- rendering: each camera's frames (its rate x the sim time) rendered and read back at its size and settings
  (no MSAA, shadows or reflections), colour and depth from one render for an RGB-D camera
  (`mjr_render` + `mjr_readPixels`, nothing else): the limit is sim seconds / (physics + rendering wall).
  Beside it, `mujoco.Renderer` alone for the same frames at the same size and quality: `render()` for an RGB
  frame, and `render()` plus `render()` with depth rendering on for an RGB-D one (one or the other per call);
- the scenario: the world alone on Zenoh (nothing subscribed) and `scenario run`'s path (world process +
  Zenoh + MCAP recorder), judged off;
- noise: `PixelNoise.apply` on a frame of the camera's size (flipped view in, message buffer out) against
  the plain copy it replaces, per frame, against the frame's render time;
- copies: a rendered frame's bytes from the world's send to the recorder's file (`copies`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from plugins._pixels import PixelNoise
from plugins._render import CameraRenderer, camera_name
from runner.plan import RunPlan


@dataclass
class CameraSpec:
    name: str  # the MuJoCo camera
    width: int
    height: int
    rate: float
    depth: bool  # an RGB-D frame (colour and depth)
    noise: float


def camera_specs(plan: RunPlan) -> list[CameraSpec]:
    out = []
    for robot in plan.robots:
        for p in robot.plugins:
            if p.type not in ("camera", "depth_camera") or not p.rate:
                continue
            params = p.params
            depth = p.type == "depth_camera"
            out.append(
                CameraSpec(
                    robot.prefix + camera_name(p.name),
                    int(params.get("width", 320)),
                    int(params.get("height", 240)),
                    float(p.rate),
                    depth,
                    float(params.get("noise_stddev", 0.0))
                    if (not depth or params.get("publish_color", True))
                    else 0.0,
                )
            )
    return out


def _model(plan: RunPlan) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    model.vis.quality.offsamples = 0  # as CameraRenderer sets them
    model.vis.quality.shadowsize = 0
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def _frame(r: mujoco.Renderer, data: mujoco.MjData, camera: str) -> None:
    r.update_scene(data, camera=camera)
    r.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
    r.render()


def render_bound(plan: RunPlan, seconds: float) -> dict[str, Any]:
    """Wall seconds `mujoco.Renderer` takes for every camera frame of `seconds` of sim time, and the one-pass
    figure (colour and depth from one render); per camera, ms per frame."""
    model, data = _model(plan)
    total = one_pass_total = 0.0
    per_camera = []
    for spec in camera_specs(plan):
        frames = max(1, round(spec.rate * seconds))
        renderer = mujoco.Renderer(model, spec.height, spec.width)
        depth_renderer = mujoco.Renderer(model, spec.height, spec.width) if spec.depth else None
        if depth_renderer is not None:
            depth_renderer.enable_depth_rendering()
        try:
            _frame(renderer, data, spec.name)  # warm
            t0 = time.perf_counter()
            for _ in range(frames):
                _frame(renderer, data, spec.name)
                if depth_renderer is not None:
                    _frame(depth_renderer, data, spec.name)
            wall = time.perf_counter() - t0
        finally:
            renderer.close()
            if depth_renderer is not None:
                depth_renderer.close()
        cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, spec.name)
        one = CameraRenderer(model, cam, spec.width, spec.height, 0.02, 100.0)
        try:
            one.update(data)
            one._render(depth_too=spec.depth)
            t0 = time.perf_counter()
            for _ in range(frames):
                one.update(data)
                one._render(depth_too=spec.depth)  # mjr_render + mjr_readPixels, nothing else
            one_wall = time.perf_counter() - t0
        finally:
            one.close()
        total += wall
        one_pass_total += one_wall
        per_camera.append(
            {
                "camera": spec.name,
                "size": f"{spec.width}x{spec.height}",
                "rate": spec.rate,
                "depth": spec.depth,
                "frames": frames,
                "renderer_ms_per_frame": wall / frames * 1e3,
                "one_pass_ms_per_frame": one_wall / frames * 1e3,
            }
        )
    return {"wall_s": total, "one_pass_wall_s": one_pass_total, "cameras": per_camera}


def noise_cost(width: int, height: int, stddev: float, repeat: int = 30) -> dict[str, float]:
    """ms per frame: the noisy write of a frame (flipped view in, message buffer out) and the plain copy
    it replaces; their difference is what the noise costs."""
    rng = np.random.default_rng(1)
    raw = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
    out = np.empty_like(raw)
    noise = PixelNoise(stddev, np.random.default_rng(2))
    noise.apply(raw[::-1], out)  # the table is made at setup

    def best(fn: Any) -> float:
        fn()
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        return min(times) * 1e3

    noisy = best(lambda: noise.apply(raw[::-1], out))
    plain = best(lambda: np.copyto(out, raw[::-1]))
    return {"noisy_ms": noisy, "plain_ms": plain, "noise_ms": max(0.0, noisy - plain)}


_RECORDER = """
import sys, time, zstandard, zenoh
from pathlib import Path
from runner.record import Recorder
from runner.wire.transport import make_config
rec = Recorder(Path(sys.argv[2]), ["cam/**"])
take, spent, zstd = rec._take, [0.0, 0, 0.0, 0.0], zstandard.ZstdCompressor(level=1)
def timed(sample):
    t0 = time.perf_counter()
    data = sample.payload.to_bytes()
    t1 = time.perf_counter()
    take(sample)
    t2 = time.perf_counter()
    zstd.compress(data)
    spent[0] += t2 - t0; spent[1] += 1; spent[2] += t1 - t0; spent[3] += time.perf_counter() - t2
rec._take = timed
with zenoh.open(make_config("client", connect=[sys.argv[1]])) as s:
    sub = s.declare_subscriber("cam/**", lambda sample: rec.on_sample(sample))
    print("ready", flush=True)
    sys.stdin.readline()
    sub.undeclare()
rec.close()
n = max(spent[1], 1)
# the recorder's own time per frame: `_take` (to_bytes + chunk + compression + write), less the extra to_bytes
print(n, (spent[0] - spent[2]) / n * 1e3, spent[2] / n * 1e3, spent[3] / n * 1e3, flush=True)
"""


def rendered_frame(plan: RunPlan) -> np.ndarray:
    """The first camera's view of the scenario at rest, with its noise: a frame as the camera sends it
    (it compresses as the run's frames do)."""
    model, data = _model(plan)
    spec = camera_specs(plan)[0]
    cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, spec.name)
    r = CameraRenderer(model, cam, spec.width, spec.height, 0.02, 100.0)
    try:
        r.update(data)
        rgb = r.rgb_view()
        out = np.empty((spec.height, spec.width, 3), np.uint8)
        if spec.noise > 0:
            return PixelNoise(spec.noise, np.random.default_rng(0)).apply(rgb, out)
        np.copyto(out, rgb)
        return out
    finally:
        r.close()


def copies(pixels: np.ndarray, frames: int = 60) -> dict[str, Any]:
    """What a frame's bytes cost on their way from the camera into the MCAP, ms per 800x800-like RGB frame:
    a plain copy of that many bytes (the unit), the world's send (into Zenoh shared memory, `put`) against
    `put` of the bytes themselves (which Zenoh copies into its buffer, then into shared memory), and in
    the recorder process (a real `Recorder` on a subscriber): `to_bytes` (the one copy Zenoh's Python API
    allows on the receiving side) and the recorder's whole work per frame with the zstd compression it
    contains measured apart."""
    import subprocess
    import sys
    import tempfile

    import zenoh

    from runner.wire.transport import ZenohBus, free_port, make_config

    frame = bytearray(60) + bytearray(pixels.tobytes())  # (a header's worth of bytes in front)
    size = len(frame)
    dst = bytearray(size)
    view_src, view_dst = np.frombuffer(frame, np.uint8), np.frombuffer(dst, np.uint8)
    t0 = time.perf_counter()
    for _ in range(frames):
        np.copyto(view_dst, view_src)
    copy_ms = (time.perf_counter() - t0) / frames * 1e3
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    with tempfile.TemporaryDirectory() as tmp, zenoh.open(make_config("router", listen=[endpoint])) as s:
        proc = subprocess.Popen(
            [sys.executable, "-c", _RECORDER, endpoint, str(Path(tmp) / "copies.mcap")],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        try:
            assert proc.stdout is not None and proc.stdin is not None
            proc.stdout.readline()
            bus = ZenohBus(s)
            send = bus.publisher("cam/image", "sensor_msgs/msg/Image")
            deadline = time.monotonic() + 5
            while not bus.all_matched() and time.monotonic() < deadline:
                time.sleep(0.01)
            send(frame, b"\0" * 16)  # the shared-memory pool is made on the first
            spent = {True: 0.0, False: 0.0}
            for i in range(frames):  # alternating: from shared memory, and put as bytes (Zenoh copies)
                shm = i % 2 == 0
                bus.shm.ok = shm
                frame[-1] = i & 0xFF
                t0 = time.perf_counter()
                send(frame, b"\0" * 16)
                spent[shm] += time.perf_counter() - t0
                time.sleep(0.005)  # a camera's pace, not a burst: the pool is not the question here
            time.sleep(0.5)  # the recorder takes the last ones
            proc.stdin.write("\n")
            proc.stdin.flush()
            n, take_ms, to_bytes_ms, zstd_ms = proc.stdout.read().split()
            shm_sent = bus.shm.sent
            bus.undeclare_all()
        finally:
            proc.kill()
            proc.wait()
    return {
        "frame_bytes": size,
        "copy_ms": copy_ms,
        "send_ms": spent[True] / (frames // 2) * 1e3,
        "send_as_bytes_ms": spent[False] / (frames - frames // 2) * 1e3,
        "sent_from_shared_memory": shm_sent,
        "recorded": int(n),
        "recorder_to_bytes_ms": float(to_bytes_ms),
        "recorder_take_ms": float(take_ms),
        "recorder_zstd_ms": float(zstd_ms),
    }
