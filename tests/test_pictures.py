"""The pictures of a run agree and can be read: one colour per robot in the trajectory plot, the report
and `scenario render`; the overview frames the whole world; a video plays as long as the run and holds
the frames it says."""

from __future__ import annotations

import colorsys
import math
import re
import subprocess
from pathlib import Path

import mujoco
import numpy as np
import pytest

from tests.conftest import SCENARIOS, run_cli, scenario_cmd


def _record(out: Path, scenario: str, seconds: float) -> Path:
    r = subprocess.run(
        scenario_cmd("run", str(SCENARIOS / scenario), "--duration", str(seconds), "--no-judge", "-q",
                     "--record", str(out)),
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    return out


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The two_robots demo, its first 4 s: both robots drive a metre or so."""
    return _record(tmp_path_factory.mktemp("pictures") / "demo.mcap", "two_robots.yaml", 4)


# --- colours -------------------------------------------------------------------------------------------

TWINS = """
<mujoco>
  <asset><material name="navy" rgba="0.1 0.1 0.6 1"/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="a/base_footprint"><freejoint/><geom type="sphere" size="0.001" rgba="0.5 0.5 0.5 1"/>
      <body name="a/base_link"><geom type="box" size="0.2 0.1 0.05" rgba="0.8 0.2 0.2 1"/></body></body>
    <body name="b/base_link" pos="1 0 0"><freejoint/><geom type="box" size="0.2 0.1 0.05" rgba="0.8 0.2 0.2 1"/>
      <geom type="box" size="0.2 0.1 0.05" rgba="0.1 0.1 0.9 1" group="3"/></body>
    <body name="c/base_link" pos="2 0 0"><freejoint/><geom type="box" size="0.2 0.1 0.05"/></body>
    <body name="d/base_link" pos="3 0 0"><freejoint/><geom type="box" size="0.2 0.1 0.05" material="navy"/></body>
  </worldbody>
</mujoco>
"""


def test_robots_of_one_colour_are_told_apart_the_same_way_every_time() -> None:
    from runner.tools.pictures import PALETTE, assign_colours, model_colours

    m = mujoco.MjModel.from_xml_string(TWINS)
    colours = model_colours(m)
    # a: its base link's red (not the grey millimetre marker of its base_footprint); b: the same red, so a
    # palette colour; c: MuJoCo's default grey (no colour of its own), a palette colour; d: its material's
    assert np.allclose(colours["a"], (0.8, 0.2, 0.2), atol=1e-6)
    assert colours["b"] in PALETTE and colours["c"] in PALETTE
    assert len({colours["a"], colours["b"], colours["c"]}) == 3
    assert np.allclose(colours["d"], (0.1, 0.1, 0.6), atol=1e-6)
    assert model_colours(mujoco.MjModel.from_xml_string(TWINS)) == colours  # deterministic
    # by the robots' order: the first of two twins keeps the colour
    swapped = assign_colours([("b", (0.8, 0.2, 0.2)), ("a", (0.8, 0.2, 0.2))])
    assert swapped["b"] == (0.8, 0.2, 0.2) and swapped["a"] in PALETTE


def test_a_colour_too_light_for_paper_keeps_its_hue() -> None:
    from runner.tools.pictures import MAX_LUMA, assign_colours

    yellow = assign_colours([("r", (1.0, 1.0, 0.0))])["r"]
    assert 0.2126 * yellow[0] + 0.7152 * yellow[1] + 0.0722 * yellow[2] <= MAX_LUMA + 1e-9
    assert colorsys.rgb_to_hsv(*yellow)[0] == pytest.approx(colorsys.rgb_to_hsv(1, 1, 0)[0])


def _hue_mask(img: np.ndarray, rgb: tuple[float, float, float]) -> np.ndarray:
    """Pixels of this colour under MuJoCo's lights: its hue, saturated, not dark."""
    from PIL import Image

    hsv = np.asarray(Image.fromarray(img).convert("HSV"), dtype=float)
    hue = colorsys.rgb_to_hsv(*rgb)[0] * 255
    near = np.minimum(np.abs(hsv[..., 0] - hue), 255 - np.abs(hsv[..., 0] - hue)) < 10
    return near & (hsv[..., 1] > 100) & (hsv[..., 2] > 70)


@pytest.mark.timeout(180)
def test_each_robot_has_one_colour_in_the_plot_the_report_and_the_render(demo: Path, tmp_path: Path) -> None:
    from PIL import Image

    from runner.tools import replay
    from runner.tools.html import load_plan, write_report
    from runner.tools.pictures import hex_colour, rgb255, run_colours
    from runner.tools.plot import trajectory_plot

    plan = load_plan(demo)
    colours = run_colours(plan)
    # the robots' own colours, from the scenario's xacro arguments, as the compiled model has them
    assert np.allclose(colours["r1"], (0.85, 0.2, 0.2), atol=1e-6)
    assert np.allclose(colours["r2"], (0.2, 0.35, 0.9), atol=1e-6)

    # the trajectory plot: each path drawn in exactly its robot's colour (the legend aside)
    png = trajectory_plot(plan, demo, [], tmp_path / "t.png")
    assert png is not None
    plot = np.asarray(Image.open(png).convert("RGB")).astype(int)
    paths = plot[:, : plot.shape[1] - 240]  # (the legend lies on the right)
    for name in ("r1", "r2"):
        exact = (np.abs(paths - rgb255(colours[name])).max(axis=2) == 0).sum()
        assert exact > 150, (name, exact)

    # the report: the speed plot's lines and labels
    page = tmp_path / "report.html"
    write_report(demo, page, plan)
    speed = next(
        svg for svg in re.findall(r"<svg.*?</svg>", page.read_text()) if "Speed of each robot" in svg
    )
    for name in ("r1", "r2"):
        colour = hex_colour(colours[name])
        assert re.search(rf'<polyline points="[^"]+" stroke="{colour}"', speed), (name, colour)
        assert f'fill="{colour}">{name}</text>' in speed

    # the render: the colours it draws the paths in, and the pixels of the paths
    rec = replay.load(demo)
    assert replay.colours(mujoco.MjModel.from_xml_string(rec.mjcf), rec) == colours
    first = next(replay.frames(rec, width=960, height=720))
    last = next(replay.frames(rec, width=960, height=720, last_only=True))
    for name in ("r1", "r2"):
        grown = int(_hue_mask(last, colours[name]).sum()) - int(_hue_mask(first, colours[name]).sum())
        assert grown > 60, (name, grown)  # its path, in its colour (at t = 0 only the robot itself)


# --- the overview ----------------------------------------------------------------------------------------


def _gl_project(scene: mujoco.MjvScene, points: np.ndarray, width: int, height: int) -> np.ndarray:
    """Pixels of points in the picture MuJoCo draws from `scene`'s camera (its OpenGL frustum, as
    mjr_render sets it up: the frustum's width follows the picture's aspect ratio)."""
    cam = scene.camera[0]
    pos, forward, up = (np.array(v, dtype=float) for v in (cam.pos, cam.forward, cam.up))
    right = np.cross(forward, up)
    rel = points - pos
    z = rel @ forward
    near, top, bottom = float(cam.frustum_near), float(cam.frustum_top), float(cam.frustum_bottom)
    half_h = (top - bottom) / 2
    half_w = float(cam.frustum_width) / 2 or half_h * width / height
    x = (rel @ right) / z * near - float(cam.frustum_center)
    y = (rel @ up) / z * near - (top + bottom) / 2
    return np.stack([(x / half_w + 1) / 2 * width, (1 - y / half_h) / 2 * height], axis=1)


def _model_centres(m: mujoco.MjModel, d: mujoco.MjData, robots: set[int]) -> dict[str, np.ndarray]:
    """The centre of each world model: a world-body geom (a scenario's model) or a top body (an SDF
    model), not the robots and not the ground planes."""
    out = {}
    for g in range(m.ngeom):
        if int(m.geom_bodyid[g]) == 0 and int(m.geom_type[g]) != int(mujoco.mjtGeom.mjGEOM_PLANE):
            out[m.geom(g).name or f"geom {g}"] = np.array(d.geom_xpos[g])
    for b in range(1, m.nbody):
        if int(m.body_parentid[b]) == 0 and b not in robots:
            out[m.body(b).name] = np.array(d.xipos[b])
    return out


@pytest.mark.timeout(240)
@pytest.mark.parametrize("scenario", ["two_robots.yaml", "mycar.yaml"])
def test_the_overview_frames_every_model_and_robot(scenario: str, demo: Path, tmp_path: Path) -> None:
    from PIL import Image

    from runner.tools import replay
    from runner.tools.pictures import robot_bodies

    mcap = demo if scenario == "two_robots.yaml" else _record(tmp_path / "run.mcap", scenario, 2)
    w, h = replay.DEFAULT_SIZE
    png = tmp_path / "overview.png"
    r = run_cli("render", str(mcap), "-o", str(png), timeout=120)
    assert r.returncode == 0, r.stderr
    picture = np.asarray(Image.open(png).convert("RGB")).astype(int)
    assert picture.shape == (h, w, 3)

    rec = replay.load(mcap)
    m = mujoco.MjModel.from_xml_string(rec.mjcf)
    d = mujoco.MjData(m)
    cam, _span = replay.overview_camera(m, d, rec, w, h)
    robots = {b: name for name, b in robot_bodies(m, rec.robots)}
    mujoco.mj_kinematics(m, d)  # (the models where they start)
    scene = mujoco.MjvScene(m, maxgeom=2000)
    mujoco.mjv_updateScene(m, d, mujoco.MjvOption(), None, cam, int(mujoco.mjtCatBit.mjCAT_ALL), scene)
    centres = _model_centres(m, d, set(robots))
    assert len(centres) >= 4, centres
    where = {}
    for state in rec.states[:: max(1, len(rec.states) // 20)] + rec.states[-1:]:  # the robots, all along
        d.qpos[:] = state[: m.nq]
        mujoco.mj_kinematics(m, d)
        for b, name in robots.items():
            where[f"{name} at some time"] = np.array(d.xpos[b])
    pts = {**centres, **where}
    uv = _gl_project(scene, np.array(list(pts.values())), w, h)
    for (name, _p), (u, v) in zip(pts.items(), uv, strict=True):
        assert 0 <= u < w and 0 <= v < h, (name, u, v)
    # whole: every corner of every model's box too, not only its centre
    mujoco.mj_kinematics(m, d)
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    for g in range(m.ngeom):
        plane = int(m.geom_type[g]) == int(mujoco.mjtGeom.mjGEOM_PLANE)
        if plane or int(m.body_rootid[int(m.geom_bodyid[g])]) in robots:
            continue
        box = m.geom_aabb[g][:3] + signs * m.geom_aabb[g][3:]
        corners = d.geom_xpos[g] + box @ d.geom_xmat[g].reshape(3, 3).T
        cuv = _gl_project(scene, corners, w, h)
        assert ((cuv >= 0) & (cuv < [w, h])).all(), (m.geom(g).name, cuv)
    # and what is framed fills the frame: the models spread over most of its width or height
    spread = uv[: len(centres)].max(axis=0) - uv[: len(centres)].min(axis=0)
    assert spread[0] > 0.6 * w or spread[1] > 0.6 * h, spread
    if scenario == "two_robots.yaml":  # the same camera drew the picture: the ball is where it projects
        ball = _gl_project(scene, np.array([centres["ball"] + [0, 0, 0.2]]), w, h)[0]
        r_, g_, b_ = picture[round(ball[1]), round(ball[0])]
        assert r_ > 150 and g_ > 150 and b_ < 120, (ball, picture[round(ball[1]), round(ball[0])])


def test_the_camera_fit_puts_every_point_in_the_picture_and_fills_it() -> None:
    from runner.tools.pictures import fit_camera, project

    rng = np.random.default_rng(3)
    for spread in ([10, 10, 0.5], [30, 4, 2], [2, 12, 0.2]):
        points = rng.uniform(-1, 1, (200, 3)) * spread + [5, -3, 0.5]
        view = {"azimuth": 90.0, "elevation": -60.0, "fovy": 45.0}
        lookat, distance = fit_camera(points, **view, aspect=4 / 3, margin=0.04)
        uv = project(points, lookat=lookat, distance=distance, **view, width=960, height=720)
        assert (uv >= 0).all() and (uv[:, 0] < 960).all() and (uv[:, 1] < 720).all()
        room = np.concatenate([uv.min(axis=0), [960, 720] - uv.max(axis=0)])
        assert room.min() < 0.05 * 720  # one side touches the margin: as large as it can be


# --- videos: the frames and the time they say are the ones they hold ----------------------------------


def test_gif_delays_add_up_to_the_run() -> None:
    from runner.tools.replay import frame_times, gif_delays

    assert len(frame_times(6_000_000_000, 5)) == 30 and len(frame_times(20_000_000_000, 15)) == 300
    for fps in (15.0, 7.0, 2.0, 12.5, 30.0, 50.0):
        n = len(frame_times(4_000_000_000, fps))
        delays = gif_delays(n, fps)
        assert len(delays) == n and all(d % 10 == 0 and d >= 20 for d in delays)
        assert sum(delays) == round(100 * n / fps) * 10
        assert abs(sum(delays) / 1000 - 4.0) < 1 / fps


def _said(stdout: str) -> tuple[int, float]:
    found = re.search(r": (\d+) frames.*?, plays ([\d.]+) s at", stdout)
    assert found, stdout
    return int(found[1]), float(found[2])


@pytest.mark.timeout(240)
def test_a_gif_and_an_mp4_hold_the_frames_and_play_the_time_they_say(demo: Path, tmp_path: Path) -> None:
    import imageio_ffmpeg
    from PIL import Image

    for fps in ("15", "7"):  # 6.67 and 14.29 hundredths of a second: not a GIF delay
        gif = tmp_path / f"run{fps}.gif"
        r = run_cli("render", str(demo), "-o", str(gif), "--fps", fps, "--size", "160x120", timeout=200)
        assert r.returncode == 0, r.stderr
        frames, seconds = _said(r.stdout)
        with Image.open(gif) as img:
            durations = []
            for i in range(img.n_frames):
                img.seek(i)
                durations.append(img.info["duration"])
            assert img.n_frames == frames, (img.n_frames, r.stdout)
        assert sum(durations) / 1000 == pytest.approx(seconds, abs=0.005)
        assert seconds == pytest.approx(4.0, abs=0.01)  # as long as the run (4 s sim)

    mp4 = tmp_path / "run.mp4"
    r = run_cli("render", str(demo), "-o", str(mp4), "--fps", "15", "--size", "160x120", timeout=200)
    assert r.returncode == 0, r.stderr
    frames, seconds = _said(r.stdout)
    counted, secs = imageio_ffmpeg.count_frames_and_secs(str(mp4))
    assert (counted, seconds) == (frames, pytest.approx(secs, abs=0.01)) and frames == 60
    assert math.isclose(seconds, 4.0, abs_tol=0.01)
