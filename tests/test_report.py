"""`scenario report`: one self-contained HTML page about a run, looked at in headless Chromium."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import SCENARIOS, run_cli, scenario_cmd


@pytest.mark.timeout(180)
def test_the_report_shows_the_verdict_the_plots_and_the_topics(tmp_path: Path) -> None:
    from PIL import Image

    mcap = tmp_path / "demo.mcap"
    r = subprocess.run(
        scenario_cmd("run", str(SCENARIOS / "two_robots.yaml"), "--record", str(mcap), "-q"),
        capture_output=True,
        text=True,
        timeout=90,
    )
    assert r.returncode == 0, r.stderr
    page = tmp_path / "report.html"
    # the scenario comes from the recording itself: no --scenario
    r = run_cli("report", str(mcap), "-o", str(page), timeout=60)
    assert r.returncode == 0, r.stderr
    assert "9/9 assertions pass, 5 signal plot(s)" in r.stdout  # speed, distance, tilt, 2 topic rates
    text = page.read_text()
    assert "9 of 9 assertions pass" in text
    for name in ("r1_reaches_its_corner", "lidar_at_10_hz", "r2_under_half_a_metre_per_second"):
        assert f"<td>{name}</td>" in text
    assert text.count("<svg") == 5 and 'src="data:image/png;base64,' in text
    assert "two_robots/r1/scan" in text and "_truth" not in text  # topics, helpers hidden
    assert not re.search(r'(src|href)="(https?:)?//', text)  # self-contained: nothing fetched
    # a rate plot draws its assertion's bounds, dashed and labelled
    rate = next(svg for svg in re.findall(r"<svg.*?</svg>", text) if "Rate of r1/scan" in svg)
    assert rate.count('class="bound"') == 2 and 'stroke-dasharray="6,4"' in rate
    assert "min 9.5 (lidar_at_10_hz)" in rate and "max 10.5 (lidar_at_10_hz)" in rate

    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    assert chromium, "headless Chromium is needed (Debian: apt-get install chromium; .ci/run installs it)"
    shot = tmp_path / "shot.png"
    subprocess.run(
        [chromium, "--headless", "--no-sandbox", "--disable-gpu", f"--screenshot={shot}",
         "--window-size=1100,1800", page.as_uri()],
        capture_output=True, timeout=90, check=True,
    )  # fmt: skip
    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    r_, g_, b_ = img[..., 0], img[..., 1], img[..., 2]
    # the plots' lines in the robots' colours (r1 red, r2 blue: their own, from the scenario) and the
    # verdict badge (#1a7f37 green) are drawn
    red = (abs(r_ - 0xD9) < 30) & (abs(g_ - 0x33) < 40) & (abs(b_ - 0x33) < 40)
    blue = (abs(r_ - 0x33) < 30) & (abs(g_ - 0x59) < 40) & (abs(b_ - 0xE6) < 40)
    green = (abs(r_ - 0x1A) < 20) & (abs(g_ - 0x7F) < 20) & (abs(b_ - 0x37) < 20)
    assert red.sum() > 200 and blue.sum() > 200 and green.sum() > 200, (red.sum(), blue.sum(), green.sum())


def _image(enc: str, w: int, h: int, data: bytes, step: int) -> object:
    from runner.wire import msgs

    return msgs.from_data(
        "sensor_msgs/msg/Image",
        {"height": h, "width": w, "encoding": enc, "step": step, "data": list(data)},
    )


def test_camera_images_become_pictures_whatever_their_encoding() -> None:
    from runner.tools.html import image_rgb

    px = np.array([[[255, 0, 0], [0, 255, 0]]], np.uint8)  # one row: red, green
    assert (image_rgb(_image("rgb8", 2, 1, px.tobytes(), 6)) == px).all()
    assert (image_rgb(_image("bgr8", 2, 1, px[..., ::-1].tobytes(), 6)) == px).all()
    rgba = np.concatenate([px, np.full((1, 2, 1), 9, np.uint8)], axis=2)
    padded = rgba.tobytes() + b"\0\0\0\0"  # a row step longer than the pixels
    assert (image_rgb(_image("rgba8", 2, 1, padded, 12)) == px).all()
    assert (image_rgb(_image("bgra8", 2, 1, rgba[..., [2, 1, 0, 3]].tobytes(), 8)) == px).all()
    grey = image_rgb(_image("mono8", 2, 1, bytes([7, 200]), 2))
    assert grey.shape == (1, 2, 3) and grey[0, 1].tolist() == [200, 200, 200]
    # depth: near bright, far dark, no return (NaN, 0) black
    depth = np.array([[1.0, 3.0, np.nan, 0.0]], "<f4")
    d = image_rgb(_image("32FC1", 4, 1, depth.tobytes(), 16))[0, :, 0]
    assert d[0] > d[1] > 0 and d[2] == d[3] == 0
    mm = np.array([[1000, 3000]], "<u2")
    d = image_rgb(_image("16UC1", 2, 1, mm.tobytes(), 4))[0, :, 0]
    assert d[0] > d[1] > 0
    assert image_rgb(_image("rgb8", 2, 2, px.tobytes(), 6)) is None  # data shorter than its header
    assert image_rgb(_image("yuv422", 2, 1, bytes(4), 4)) is None


CAMERA_SCENE = """
name: camreport
duration: 1.0
rate: max
world:
  models:
    - {name: red, shape: box, size: [0.6, 0.6, 0.6], pose: {xyz: [1.2, 0, 0.3]}, rgba: [1, 0, 0, 1]}
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.05]}
    plugins:
      - {type: camera, params: {pose: {xyz: [0.12, 0, 0.1]}, width: 64, height: 48, rate: 5}}
      - {type: depth_camera, params: {pose: {xyz: [0.12, 0, 0.1]}, width: 32, height: 24, rate: 5,
                                      publish_color: false, points_topic: null}}
"""


@pytest.mark.timeout(180)
def test_the_report_shows_camera_frames(write_scenario, tmp_path: Path) -> None:
    import base64
    import io

    from PIL import Image

    mcap = tmp_path / "cam.mcap"
    r = subprocess.run(
        scenario_cmd("run", str(write_scenario(CAMERA_SCENE)), "--record", str(mcap), "-q"),
        capture_output=True, text=True, timeout=120, env={**os.environ, "MUJOCO_GL": "egl"},
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    page = tmp_path / "report.html"
    r = run_cli("report", str(mcap), "-o", str(page), timeout=60)
    assert r.returncode == 0, r.stderr
    text = page.read_text()
    assert "<h2>Camera</h2>" in text and "camreport/r1/camera/image" in text  # colour before depth
    frames = re.findall(r'alt="camera frame" src="data:image/png;base64,([^"]+)"', text)
    assert len(frames) == 3  # first, middle and last of the run's 6 images
    img = np.asarray(Image.open(io.BytesIO(base64.b64decode(frames[-1]))).convert("RGB")).astype(int)
    assert img.shape == (48, 64, 3)
    red = (img[..., 0] > 120) & (img[..., 1] < 60) & (img[..., 2] < 60)
    assert red[:, 20:44].mean() > 0.3, "the red box ahead is not in the frame"


@pytest.mark.timeout(240)
def test_a_report_of_several_worlds_judges_and_plots_each_worlds_assertions(tmp_path: Path) -> None:
    """With `worlds:`, each world's plan holds its own assertions (topics inside the world): the page
    judges them all, and draws the rate plot of `arena/r1/scan` with its bounds."""
    mcap = tmp_path / "worlds.mcap"
    r = subprocess.run(
        scenario_cmd("run", str(SCENARIOS / "two_worlds.yaml"), "--record", str(mcap), "-q"),
        capture_output=True, text=True, timeout=180,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    page = tmp_path / "worlds.html"
    r = run_cli("report", str(mcap), "-o", str(page), timeout=60)
    assert r.returncode == 0, r.stderr
    assert "3/3 assertions pass, 2 signal plot(s)" in r.stdout  # speed, and the arena's lidar rate
    text = page.read_text()
    rate = next(svg for svg in re.findall(r"<svg.*?</svg>", text) if "Rate of arena/r1/scan" in svg)
    assert "min 9.5 (arena_lidar_at_10_hz)" in rate and "max 10.5 (arena_lidar_at_10_hz)" in rate
    assert 'alt="trajectory plot"' in text
