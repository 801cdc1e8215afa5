"""`scenario render`: a recorded run rendered again from its recorded states, on the CPU."""

from __future__ import annotations

import itertools
import subprocess
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import SCENARIOS, run_cli, scenario_cmd


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    mcap = tmp_path_factory.mktemp("replay") / "demo.mcap"
    r = subprocess.run(
        scenario_cmd("run", str(SCENARIOS / "two_robots.yaml"), "--duration", "6", "--no-judge", "-q",
                     "--record", str(mcap)),
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    return mcap


def _robot_pixels(img: np.ndarray) -> tuple[int, int]:
    """Pixels of r1's red (0.85, 0.2, 0.2) and r2's blue (0.2, 0.35, 0.9), under any lighting."""
    r, g, b = (img[..., i].astype(int) for i in range(3))
    red = (r > 120) & (r > 2 * g) & (r > 2 * b)
    blue = (b > 120) & (b > 1.6 * r) & (b > 1.3 * g)
    return int(red.sum()), int(blue.sum())


@pytest.mark.timeout(120)
def test_the_video_moves_and_shows_both_robots(recording: Path, tmp_path: Path) -> None:
    import imageio_ffmpeg

    video = tmp_path / "run.mp4"
    r = run_cli("render", str(recording), "-o", str(video), "--size", "480x360", "--fps", "5", timeout=100)
    assert r.returncode == 0, r.stderr
    # one frame every 1/5 s of the 6 s run: it plays for 6 s
    assert "30 frames, plays 6.00 s at 5 fps" in r.stdout, r.stdout
    reader = imageio_ffmpeg.read_frames(str(video))
    meta = next(reader)
    assert tuple(meta["size"]) == (480, 360)
    frames = [np.frombuffer(f, np.uint8).reshape(360, 480, 3) for f in reader]
    assert len(frames) == 30
    first, last = frames[0], frames[-1]
    moved = (np.abs(first.astype(int) - last.astype(int)).max(axis=2) > 30).sum()
    assert moved > 100, moved  # the robots moved, their paths grew
    changed = [np.abs(a.astype(int) - b.astype(int)).max() > 40 for a, b in itertools.pairwise(frames)]
    assert sum(changed) > len(changed) // 2  # motion all along, not one jump
    red, blue = _robot_pixels(first)  # at t = 0 no path is drawn yet: these are the robots themselves
    assert red > 25 and blue > 25, (red, blue)
    red_end, blue_end = _robot_pixels(last)
    assert red_end > red and blue_end > blue  # and later their paths too


@pytest.mark.timeout(120)
def test_a_picture_a_gif_and_a_chase_camera(recording: Path, tmp_path: Path) -> None:
    from PIL import Image

    png = tmp_path / "end.png"
    assert run_cli("render", str(recording), "-o", str(png), timeout=60).returncode == 0
    with Image.open(png) as img:
        assert img.size == (960, 720)  # the default size
        assert min(_robot_pixels(np.asarray(img.convert("RGB")))) > 30
    gif = tmp_path / "chase.gif"
    r = run_cli(
        "render", str(recording), "-o", str(gif), "--camera", "chase:r2", "--fps", "2", "--size", "160x120"
    )
    assert r.returncode == 0, r.stderr
    with Image.open(gif) as img:
        # 12 frames at 2 per second: 6 s (a frame like the one before is merged into it, shown for longer)
        durations = []
        for frame in range(img.n_frames):
            img.seek(frame)
            durations.append(img.info["duration"])
        assert sum(durations) == 12 * 500 and img.size == (160, 120)
        for frame in (0, img.n_frames - 1):  # r2 starts at (2, 0) and ends metres away: the camera follows it
            img.seek(frame)
            middle = np.asarray(img.convert("RGB"))[40:80, 50:110]
            assert _robot_pixels(middle)[1] > 30, frame  # r2 is in the middle of the frame
    bad = run_cli("render", str(recording), "-o", str(tmp_path / "x.avi"))
    assert bad.returncode == 1 and "write .mp4, .gif or .png" in bad.stderr
    nobody = run_cli("render", str(recording), "-o", str(gif), "--camera", "chase:r9")
    assert nobody.returncode == 1 and "no robot 'r9'" in nobody.stderr and "r1, r2" in nobody.stderr


def test_only_the_scenarios_robots_get_paths() -> None:
    """An SDF world's models are named `<model>/...` like robots: the recorded plan tells them apart."""
    import mujoco

    from runner.tools.pictures import robot_bodies

    m = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody>"
        '<body name="cafe_table/link"><geom size="0.1"/></body>'
        '<body name="r1/base_link"><freejoint/><geom size="0.1"/></body>'
        "</worldbody></mujoco>"
    )
    assert [name for name, _b in robot_bodies(m)] == ["cafe_table", "r1"]  # without a plan: a guess
    assert [name for name, _b in robot_bodies(m, {"r1"})] == ["r1"]


SMALL_WORLD = """
name: small
duration: 1.0
rate: max
world:
  models:
    - {name: c1, shape: cylinder, size: [0.15, 0.5], pose: {xyz: [1.1, 1.1, 0.25]}}
    - {name: c2, shape: cylinder, size: [0.15, 0.5], pose: {xyz: [-1.1, 1.1, 0.25]}}
    - {name: c3, shape: cylinder, size: [0.15, 0.5], pose: {xyz: [1.1, -1.1, 0.25]}}
    - {name: c4, shape: cylinder, size: [0.15, 0.5], pose: {xyz: [-1.1, -1.1, 0.25]}}
robots:
  - {name: r1, description: "{diffbot}", pose: {xyz: [-2.0, -0.5, 0.06]}, plugins: [{type: diff_drive}]}
"""


@pytest.mark.timeout(120)
def test_a_small_worlds_floor_has_no_shadow_speckles(write_scenario, tmp_path: Path) -> None:
    """The sun's shadow map used to cover only the model's extent: beyond it, on the floor of a small
    world (turtlebot3_world), shadow acne drew a fan of black speckles."""
    from PIL import Image

    mcap = tmp_path / "small.mcap"
    r = subprocess.run(
        scenario_cmd("run", str(write_scenario(SMALL_WORLD)), "--record", str(mcap), "-q"),
        capture_output=True, text=True, timeout=90,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    png = tmp_path / "small.png"
    assert run_cli("render", str(mcap), "-o", str(png), timeout=60).returncode == 0
    a = np.asarray(Image.open(png).convert("L")).astype(int)
    c = a[1:-1, 1:-1]
    neighbours = np.minimum.reduce([a[:-2, 1:-1], a[2:, 1:-1], a[1:-1, :-2], a[1:-1, 2:]])
    speckles = int((neighbours - c > 25).sum())  # a pixel much darker than all four of its neighbours
    assert speckles < 50, speckles  # (was 1385)


@pytest.mark.timeout(120)
def test_a_model_far_away_is_left_out_of_the_overview_and_said(tmp_path: Path) -> None:
    """A world model posed 343 km away (a stray pose in a public world) framed with the rest would shrink
    the robots to nothing: the overview frames what is near the robots, and says what it left out."""
    from PIL import Image

    from tests.conftest import DIFFBOT

    scenario = tmp_path / "far.yaml"
    scenario.write_text(
        "name: far\nduration: 1\nworld:\n  models:\n"
        "    - {name: stray, shape: box, size: [1, 1, 1], pose: {xyz: [343000, 0, 0.5]}}\n"
        "    - {name: crate, shape: box, size: [0.5, 0.5, 0.5], pose: {xyz: [2, 0, 0.25]}}\n"
        f"robots:\n  - {{name: r1, description: '{DIFFBOT}', pose: {{xyz: [0, 0, 0.06]}}}}\n"
    )
    mcap = tmp_path / "far.mcap"
    r = run_cli("run", str(scenario), "--no-judge", "-q", "--record", str(mcap), timeout=100)
    assert r.returncode == 0, r.stderr
    png = tmp_path / "far.png"
    r = run_cli("render", str(mcap), "-o", str(png), timeout=100)
    assert r.returncode == 0, r.stderr
    assert "the overview leaves out stray" in r.stderr, r.stderr
    with Image.open(png) as img:
        red, _ = _robot_pixels(np.asarray(img.convert("RGB")))
    assert red > 100, red  # the robot is seen, not a dot in a grey field
