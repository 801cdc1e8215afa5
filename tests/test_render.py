"""Offscreen rendering (plugins/_render.py): a slow camera costs nothing between its frames, a missing
OpenGL backend is a clear error naming the packages (never a crash), and RGB and depth from one update
agree."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np
import pytest

from plugins import _render
from plugins._render import CameraRenderer, choose_gl_backend, probe_gl_backend
from plugins.camera import Camera
from runner import gl
from runner.sim.world import World
from runner.wire.transport import MemoryBus
from tests.helpers import messages, plan_of

REPO = Path(__file__).resolve().parents[1]
EGL_PACKAGES = "libegl1 libegl-mesa0 libgl1-mesa-dri libgbm1"

WORLD = """
name: render
duration: {duration}
rate: max
world:
  ground: {{rgba: [0.1, 0.6, 0.1, 1]}}
  models:
    - {{name: red_box, shape: box, size: [0.5, 1.0, 1.0], pose: {{xyz: [2.25, 0, 0.5]}}, rgba: [1, 0, 0, 1]}}
robots:
  - name: r1
    description: {{file: "{{diffbot}}"}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive}}
      - {{type: imu, params: {{link: imu_link, rate: 100}}}}
{camera}
timeline:
  - {{t: 0.1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.2}}, angular: {{z: 0.5}}}}}}
"""
SLOW_CAMERA = "      - {type: camera, params: {link: lidar_link, width: 320, height: 240, rate: 1}}"


def _steps_per_s(path: Path, camera: bool) -> tuple[float, int]:
    """Steps per wall second of one run, leaving out the time spent inside the camera's own calls (its
    frames, and closing its GL context at the end, ~5 ms): what is left is the cost of the simulation
    between frames. Also returns the frames published."""
    bus = MemoryBus()
    world = World(plan_of(path), bus)
    in_camera = [0.0]

    def timed(fn: Callable[..., None]) -> Callable[..., None]:
        def call(*args: int) -> None:
            t0 = time.perf_counter()
            fn(*args)
            in_camera[0] += time.perf_counter() - t0

        return call

    for hook in world._after:
        if isinstance(getattr(hook.fn, "__self__", None), Camera):
            hook.fn = timed(hook.fn)
    for plugin in world.plugins:
        if isinstance(plugin, Camera):
            plugin.close = timed(plugin.close)  # type: ignore[method-assign]
    stats = world.run()
    frames = len(messages(bus, "r1/camera/image_raw"))
    assert camera == (frames > 0)
    return stats.steps / (stats.wall_s - in_camera[0]), frames


@pytest.mark.timeout(120)
def test_a_slow_camera_does_not_slow_the_simulation_between_frames(write_scenario):
    plain = write_scenario(WORLD.format(duration=2.0, camera=""), "plain.yaml")
    with_camera = write_scenario(WORLD.format(duration=2.0, camera=SLOW_CAMERA), "camera.yaml")
    best = {False: 0.0, True: 0.0}
    for _ in range(5):  # best of 5, alternating: the machine is shared and noisy
        for camera, path in ((False, plain), (True, with_camera)):
            rate, frames = _steps_per_s(path, camera)
            best[camera] = max(best[camera], rate)
            if camera:
                assert frames == 3  # 1 Hz over 2 s: t = 0, 1, 2
    assert best[True] >= 0.8 * best[False], best


def _run_camera_world(path: Path, **env: str) -> subprocess.CompletedProcess[str]:
    """Run a world with a camera in a fresh interpreter with `env` (MUJOCO_GL chosen before mujoco loads)."""
    script = textwrap.dedent(
        """
        import sys
        from pathlib import Path
        import runner
        from tests.helpers import simulate
        simulate(Path(sys.argv[1]))
        print("rendered")
        """
    )
    full = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    full.update(env)
    return subprocess.run(
        [sys.executable, "-c", script, str(path)],
        cwd=REPO,
        env=full,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.timeout(300)
@pytest.mark.parametrize(
    "env",
    [
        # the backend's libraries cannot be loaded (PyOpenGL bound to another platform): mujoco has no context
        {"MUJOCO_GL": "egl", "PYOPENGL_PLATFORM": "osmesa"},
        {"MUJOCO_GL": "osmesa", "PYOPENGL_PLATFORM": "egl"},
        # EGL loads but cannot make a context (no such device)
        {"MUJOCO_GL": "egl", "MUJOCO_EGL_DEVICE_ID": "99"},
        # rendering turned off
        {"MUJOCO_GL": "disable"},
        # what ensure_gl_backend makes of MUJOCO_GL=nonexistent, so that mujoco can still be imported
        {"MUJOCO_GL": "disable", "SCENARIO_GL_REQUESTED": "nonexistent"},
    ],
    ids=["egl-not-loadable", "osmesa-not-loadable", "egl-no-context", "disabled", "invalid-name"],
)
def test_no_working_backend_is_a_clear_error_naming_the_packages(write_scenario, env):
    path = write_scenario(WORLD.format(duration=0.1, camera=SLOW_CAMERA))
    done = _run_camera_world(path, **env)
    assert done.returncode == 1, (done.returncode, done.stderr[-2000:])  # an exception, not a signal
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("RuntimeError: cannot render camera images"), done.stderr[-2000:]
    assert EGL_PACKAGES in last and "libosmesa6" in last
    assert "rendered" not in done.stdout
    if env.get("SCENARIO_GL_REQUESTED"):
        assert "MUJOCO_GL='nonexistent'" in last and "not a backend MuJoCo knows" in last


@pytest.mark.timeout(120)
def test_an_invalid_backend_name_is_a_clear_error(write_scenario):
    path = write_scenario(WORLD.format(duration=0.1, camera=SLOW_CAMERA))
    done = _run_camera_world(path, MUJOCO_GL="nonexistent")
    assert done.returncode >= 0, done.returncode  # never a crash by signal
    last = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else ""
    # `import runner` checks MUJOCO_GL before mujoco is imported (which would reject the value itself)
    assert "invalid value for environment variable MUJOCO_GL" not in done.stderr
    assert last.startswith("RuntimeError: cannot render camera images"), done.stderr[-2000:]
    assert EGL_PACKAGES in last


@pytest.mark.timeout(120)
def test_probe_reports_a_backend_that_cannot_render(monkeypatch):
    assert probe_gl_backend(_render.gl_backend_in_use()) is None  # the backend these tests render with
    why = probe_gl_backend("egl", environ=dict(os.environ, MUJOCO_EGL_DEVICE_ID="99"))
    assert why is not None
    if probe_gl_backend("egl") is None:
        assert "MUJOCO_EGL_DEVICE_ID" in why
    # a driver that crashes the process crashes the probe, which says so
    monkeypatch.setattr(gl, "_PROBE", "import ctypes; ctypes.string_at(0)")
    why = probe_gl_backend("egl")
    assert why is not None and why.startswith("a test render crashed (signal")


@pytest.mark.timeout(30)
def test_default_backend_is_chosen_before_mujoco_is_imported(monkeypatch):
    installed = {"egl": True, "osmesa": True}
    monkeypatch.setattr(gl, "gl_library_present", lambda backend: installed[backend])
    env: dict[str, str] = {}
    assert gl.ensure_gl_backend(env) == "egl" and env == {"MUJOCO_GL": "egl", "SCENARIO_GL_AUTO": "1"}
    installed["egl"] = False
    env = {}
    assert gl.ensure_gl_backend(env) == "osmesa"
    installed["osmesa"] = False
    env = {}
    assert gl.ensure_gl_backend(env) == "disable"  # mujoco imports; a camera says what to install
    # the user's choice is kept, unless importing mujoco would fail with it
    installed.update(egl=True, osmesa=False)
    env = {"MUJOCO_GL": "egl"}
    assert gl.ensure_gl_backend(env) == "egl" and env == {"MUJOCO_GL": "egl"}
    env = {"MUJOCO_GL": "glfw"}
    assert gl.ensure_gl_backend(env) == "glfw"
    env = {"MUJOCO_GL": "osmesa"}
    assert gl.ensure_gl_backend(env) == "disable" and env["SCENARIO_GL_REQUESTED"] == "osmesa"
    env = {"MUJOCO_GL": "nonexistent"}
    assert gl.ensure_gl_backend(env) == "disable" and env["SCENARIO_GL_REQUESTED"] == "nonexistent"


@pytest.mark.timeout(30)
def test_backend_choice_honours_the_user_and_falls_back_to_osmesa(monkeypatch):
    works = {"egl": None, "osmesa": None}
    probe = works.get
    # the user's own choice is kept, without probing
    assert choose_gl_backend({"MUJOCO_GL": "osmesa"}, probe=lambda b: "not probed") == "osmesa"
    # our default (marked), or unset: EGL when it renders
    assert choose_gl_backend({"MUJOCO_GL": "egl", "SCENARIO_GL_AUTO": "1"}, probe=probe) == "egl"
    assert choose_gl_backend({}, probe=probe) == "egl"
    # EGL cannot make a context: OSMesa when its library is there and it renders
    works["egl"] = "Cannot initialize a EGL device display"
    monkeypatch.setattr(gl, "gl_library_present", lambda backend: True)
    assert choose_gl_backend({}, probe=probe) == "osmesa"
    # neither: an error naming the packages
    works["osmesa"] = "Failed to create OSMesa GL context"
    with pytest.raises(RuntimeError, match=EGL_PACKAGES) as err:
        choose_gl_backend({}, probe=probe)
    assert "libosmesa6" in str(err.value) and "Cannot initialize a EGL device display" in str(err.value)
    monkeypatch.setattr(gl, "gl_library_present", lambda backend: False)
    with pytest.raises(RuntimeError, match="libOSMesa is not installed"):
        choose_gl_backend({}, probe=probe)


SCENE = """
<mujoco>
  <visual><global offwidth="320" offheight="240"/></visual>
  <asset>{sky}</asset>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1" directional="true"/>
    <geom name="floor" type="plane" size="0 0 0.05" rgba="0.1 0.6 0.1 1"/>
    <geom name="box" type="box" size="0.3 1 0.5" pos="2.3 0 0.5" rgba="1 0 0 1"/>
    <geom name="pane" type="box" size="0.02 0.1 0.3" pos="1 0.45 0.4" rgba="0 0 1 {alpha}"/>
    <camera name="cam" pos="0 0 0.4" xyaxes="0 -1 0 0 0 1" fovy="45"/>
  </worldbody>
</mujoco>
"""
SKYBOX = (
    '<texture type="skybox" builtin="gradient" rgb1="0.6 0.6 0.6" rgb2="0.2 0.2 0.2" width="32" height="32"/>'
)


@pytest.mark.timeout(60)
@pytest.mark.parametrize(
    "sky, alpha", [("", "1"), ("", "0.5"), (SKYBOX, "1")], ids=["opaque", "transparent", "skybox"]
)
def test_rgb_and_depth_from_one_update_agree(sky, alpha):
    model = mujoco.MjModel.from_xml_string(SCENE.format(sky=sky, alpha=alpha))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "cam")
    r = CameraRenderer(model, cam, 160, 120, near=0.05, far=20.0)
    try:
        r.update(data)
        rgb, depth = (a.copy() for a in r.rgbd())
        # the same as rendering them apart, from the same update (one render where that is exact)
        assert np.array_equal(r.rgb(), rgb)
        assert np.array_equal(r.depth(), depth)
        assert r._depth_same_in_color_render() == (not sky and alpha == "1")
        px = rgb.astype(int)
        red = (px[..., 0] > 2 * px[..., 1] + 40) & (px[..., 0] > 2 * px[..., 2] + 40)
        green = px[..., 1] > px[..., 0] + 20
        # the box face is 2 m ahead, square to the optical axis: depth 2 wherever the image is red
        assert red.sum() > 500 and np.allclose(depth[red], 2.0, atol=2e-3)
        # the ground: finite depth, growing towards the horizon (rows further up are further away)
        assert green.sum() > 500 and np.isfinite(depth[green]).all()
        ground_rows = np.nonzero(green[:, 150])[0]
        assert len(ground_rows) > 20 and np.all(np.diff(depth[ground_rows, 150]) < 0)
        # nothing drawn (above the box): no depth, +inf, also where a skybox is drawn in the colour image
        assert np.isinf(depth[0, :]).all()
        finite = np.isfinite(depth)
        assert (depth[finite] >= 0.05).all() and (depth[finite] <= 20.0).all()
        # a pair from one update, after the world changed: both images change together
        model.geom_pos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "box")][0] = 3.3
        mujoco.mj_forward(model, data)
        r.update(data)
        rgb2, depth2 = r.rgbd()
        px2 = rgb2.astype(int)
        red2 = (px2[..., 0] > 2 * px2[..., 1] + 40) & (px2[..., 0] > 2 * px2[..., 2] + 40)
        assert red2.sum() > 200 and np.allclose(depth2[red2], 3.0, atol=3e-3)
    finally:
        r.close()
