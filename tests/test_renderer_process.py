"""Cameras rendered in a renderer process of their own (`renderers: process`) give the very frames the
world process would render itself, on time, none lost; and a renderer that dies fails the run clearly."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from mcap.reader import make_reader

from tests.conftest import processes_of, run_cli, scenario_cmd, wait_recorded

SCENE = """
name: cams
duration: 1.0
rate: max
seed: 3
renderers: {mode}
world:
  models:
    - {{name: crate, shape: box, size: [0.5, 0.5, 0.5], pose: {{xyz: [1.0, 0.2, 0.25]}}, rgba: [0.8, 0.3, 0.1, 1]}}
robots:
  - name: r1
    description: {{file: "{{diffbot}}"}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive}}
      - {{type: camera, params: {{link: lidar_link, pose: {{xyz: [0.04, 0, 0]}}, width: 64, height: 48, rate: 20,
          noise_stddev: 2.0}}}}
      - {{type: depth_camera, params: {{link: lidar_link, width: 32, height: 24, rate: 10,
          image_topic: rgbd/image, info_topic: rgbd/camera_info}}}}
timeline:
  - {{t: 0.1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{angular: {{z: 1.0}}}}}}
"""


def _frames(path: Path) -> dict[str, list[tuple[int, bytes]]]:
    out: dict[str, list[tuple[int, bytes]]] = {}
    with open(path, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages():
            if "image" in channel.topic or "depth" in channel.topic or "camera_info" in channel.topic:
                out.setdefault(channel.topic, []).append((message.log_time, bytes(message.data)))
    return out


@pytest.mark.timeout(120)
def test_renderer_process_gives_the_frames_the_world_would(write_scenario, tmp_path: Path) -> None:
    runs = {}
    for mode in ("world", "process"):
        path = write_scenario(SCENE.format(mode=mode), f"{mode}.yaml")
        mcap = tmp_path / f"{mode}.mcap"
        proc = run_cli("run", str(path), "--record", str(mcap), "-q", timeout=100)
        assert proc.returncode == 0, proc.stderr
        runs[mode] = _frames(mcap)
    world, apart = runs["world"], runs["process"]
    assert set(world) == set(apart) and "cams/r1/camera/image_raw" in world, sorted(world)
    for topic, frames in world.items():
        rate = 20 if topic in ("cams/r1/camera/image_raw", "cams/r1/camera/camera_info") else 10
        assert [t for t, _ in frames] == [i * 10**9 // rate for i in range(rate + 1)], topic
        # same pose, same seeded noise: the same bytes, frame by frame (the robot turns, so frames differ)
        assert frames == apart[topic], topic
    images = [data for _, data in world["cams/r1/camera/image_raw"]]
    assert len(set(images)) > 5


@pytest.mark.timeout(60)
def test_a_renderer_that_dies_fails_the_run_and_keeps_the_recording(write_scenario, tmp_path: Path) -> None:
    path = write_scenario(
        SCENE.format(mode="process")
        .replace("duration: 1.0", "duration: 600")
        .replace("rate: max", "rate: realtime")
    )
    mcap = tmp_path / "run.mcap"
    proc = subprocess.Popen(
        scenario_cmd("run", str(path), "--record", str(mcap)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )
    try:
        renderer = None
        deadline = time.monotonic() + 30
        while renderer is None and time.monotonic() < deadline:
            time.sleep(0.2)
            pids = processes_of(proc.pid, "runner.sim.render")  # this run's, not another suite's
            renderer = pids[0] if pids else None
        assert renderer is not None, "no renderer process"
        # some frames recorded first (waited for, not slept: under load 1.5 s once gave none)
        assert wait_recorded(mcap, "cams/r1/camera/image_raw", 1, time.monotonic() + 60), "no frame recorded"
        os.kill(renderer, signal.SIGKILL)
        _out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode != 0
    assert "renderer process exited" in err, err[-2000:]
    assert "Traceback" not in err
    frames = _frames(mcap)  # finished and readable
    assert frames.get("cams/r1/camera/image_raw"), sorted(frames)


LARGE = """
name: big
duration: 0.5
rate: max
seed: 5
renderers: world
world:
  models:
    - {name: crate, shape: box, size: [0.5, 0.5, 0.5], pose: {xyz: [1.0, 0.2, 0.25]}, rgba: [0.8, 0.3, 0.1, 1]}
robots:
  - name: r1
    description: {file: "{diffbot}"}
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive}
      - {type: camera, params: {link: lidar_link, pose: {xyz: [0.04, 0, 0]}, width: 400, height: 300,
          rate: 10, noise_stddev: 0.007}}
      - {type: depth_camera, params: {link: lidar_link, width: 200, height: 150, rate: 10,
          image_topic: rgbd/image, info_topic: rgbd/camera_info}}
timeline:
  - {t: 0.05, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {angular: {z: 1.0}}}
"""


@pytest.mark.timeout(120)
def test_large_frames_go_through_shared_memory_into_the_recording_unchanged(
    write_scenario, tmp_path: Path
) -> None:
    """Frames over the shared-memory threshold (RGB 360 KB and 90 KB, points 480 KB, depth 120 KB), written
    in place into reused buffers, sent from Zenoh's shared memory, the largest recorded as chunks of their
    own: the MCAP holds, frame by frame, the bytes the same world publishes in-process (seeded noise, same
    poses)."""
    from runner.wire.transport import SHM_MIN_BYTES
    from tests.helpers import simulate

    path = write_scenario(LARGE, "big.yaml")
    mcap = tmp_path / "big.mcap"
    proc = run_cli("run", str(path), "--record", str(mcap), "-q", timeout=100)
    assert proc.returncode == 0, proc.stderr
    recorded: dict[str, list[tuple[int, bytes]]] = {}
    with open(mcap, "rb") as f:
        for _, channel, message in make_reader(f).iter_messages():
            recorded.setdefault(channel.topic, []).append((message.log_time, bytes(message.data)))
    _, bus = simulate(path)
    published: dict[str, list[bytes]] = {}
    for key, _type, payload, _att in bus.sent:
        published.setdefault(key, []).append(payload)
    big = [k for k, v in published.items() if len(v[0]) >= SHM_MIN_BYTES]
    assert sorted(big) == [
        "big/r1/camera/depth/image_raw",
        "big/r1/camera/image_raw",
        "big/r1/camera/points",
        "big/r1/rgbd/image",
    ]
    for key in big:
        frames = [data for _, data in recorded[key]]
        assert len(frames) == 6, key
        assert frames == published[key], key
        assert len(set(frames)) == 6, key  # the robot turns and the noise is new: every frame differs


def test_shared_memory_sender_copies_once_and_steps_aside_when_it_cannot() -> None:
    """A large payload is copied into a shared-memory buffer (sent from there); a pool too small for it, or
    one whose buffers are all still held by subscribers, gives None: the bytes are put as they are."""
    from runner.wire.transport import SharedMemorySender

    payload = bytearray(range(256)) * 800  # 200 KB
    sender = SharedMemorySender(pool_bytes=1 << 20)
    held = [sender.buffer(payload) for _ in range(5)]
    assert all(b is not None and bytes(b) == payload for b in held)
    assert sender.buffer(payload) is None  # all 1 MB held
    assert (sender.sent, sender.fallbacks, sender.ok) == (5, 1, True)
    del held
    assert sender.buffer(payload) is not None  # freed buffers are taken again
    small = SharedMemorySender(pool_bytes=500_000)
    assert small.buffer(payload) is None and not small.ok  # a pool for fewer than 4 frames is not used
