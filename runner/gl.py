"""MuJoCo's OpenGL backend for offscreen rendering, chosen before `mujoco` is imported.

MuJoCo reads `MUJOCO_GL` once, at import, and a process cannot switch backends afterwards; a value that
cannot work makes `import mujoco` itself fail. So `import runner` calls `ensure_gl_backend()` before any of
our modules imports mujoco, and a runner that starts a rendering world process picks a backend that a test
render proved (`choose_gl_backend`). Nothing here imports mujoco.
"""

from __future__ import annotations

import ctypes.util
import glob
import os
import subprocess
import sys
from collections.abc import Callable, Mapping, MutableMapping

GL_ENV = "MUJOCO_GL"
GL_AUTO_ENV = "SCENARIO_GL_AUTO"  # "1": MUJOCO_GL was set by the runner, not by the user
GL_PROBED_ENV = "SCENARIO_GL_PROBED"  # a backend that a parent process saw render (no need to probe again)
GL_REQUESTED_ENV = "SCENARIO_GL_REQUESTED"  # the user's MUJOCO_GL, where it had to become 'disable'
HEADLESS_BACKENDS = ("egl", "osmesa")
GL_PACKAGES = {
    "egl": ("libegl1", "libegl-mesa0", "libgl1-mesa-dri", "libgbm1"),
    "osmesa": ("libosmesa6",),
}
GL_LIBRARY = {"egl": "EGL", "osmesa": "OSMesa"}
# MUJOCO_GL values mujoco accepts on Linux (any other makes `import mujoco` fail), and those turning GL off
GL_DISABLED = ("disable", "disabled", "off", "false", "0")
GL_KNOWN = ("", "enable", "enabled", "on", "true", "1", "glfw", "glx", "egl", "osmesa")

# Run by `probe_gl_backend` in a fresh interpreter with MUJOCO_GL set: import mujoco, make a context as
# CameraRenderer does, render and read a tiny frame. Exit 0 and print "ok" when it works; else print why.
_PROBE = """
import sys
try:
    import mujoco
except BaseException as e:
    print(f"importing mujoco failed: {type(e).__name__}: {e}".splitlines()[0]); sys.exit(3)
cls = getattr(mujoco, "GLContext", None)
if cls is None:
    print("mujoco has no OpenGL context class for this backend (its libraries could not be loaded)")
    sys.exit(3)
try:
    import numpy as np
    m = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='0.1'/></worldbody></mujoco>")
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    gl = cls(8, 8)
    gl.make_current()
    con = mujoco.MjrContext(m, mujoco.mjtFontScale.mjFONTSCALE_150)
    mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, con)
    scn = mujoco.MjvScene(m, maxgeom=10)
    cam = mujoco.MjvCamera()
    mujoco.mjv_updateScene(m, d, mujoco.MjvOption(), None, cam, mujoco.mjtCatBit.mjCAT_ALL, scn)
    rect = mujoco.MjrRect(0, 0, 8, 8)
    mujoco.mjr_render(rect, scn, con)
    mujoco.mjr_readPixels(np.zeros((8, 8, 3), np.uint8), np.zeros((8, 8), np.float32), rect, con)
    con.free()
    gl.free()
except BaseException as e:
    print(f"{type(e).__name__}: {e}".splitlines()[0]); sys.exit(4)
print("ok")
"""


def ensure_gl_backend(environ: MutableMapping[str, str] | None = None) -> str:
    """Choose MuJoCo's OpenGL backend for offscreen rendering, before `mujoco` is imported (in `environ`,
    default `os.environ`). Returns the `MUJOCO_GL` that mujoco will see.

    - unset: EGL, which renders headless on a GPU or on the CPU with Mesa's llvmpipe (Debian: libegl1
      libegl-mesa0 libgl1-mesa-dri libgbm1); OSMesa if only libOSMesa is installed; `disable` if neither
      is. Marked as our choice with `SCENARIO_GL_AUTO=1`;
    - set by the user: kept, except where `import mujoco` itself would fail: a value mujoco does not know,
      or egl/osmesa without its library (PyOpenGL then fails inside mujoco's import). Those become `disable`,
      so that runs without a camera still work, and the user's value is kept in `SCENARIO_GL_REQUESTED`
      for the cameras' error message.

    MuJoCo reads the variable once, when it is imported: `import runner` calls this first, and nothing in
    this module imports mujoco.
    """
    env = os.environ if environ is None else environ
    value = env.get(GL_ENV)
    if value is None:
        env[GL_AUTO_ENV] = "1"
        env[GL_ENV] = next((b for b in HEADLESS_BACKENDS if gl_library_present(b)), "disable")
        return env[GL_ENV]
    name = value.strip().lower()
    if name in GL_DISABLED:
        return value
    unusable = name not in GL_KNOWN or (name in HEADLESS_BACKENDS and not gl_library_present(name))
    if unusable:
        env[GL_REQUESTED_ENV] = value
        env[GL_ENV] = "disable"
    return env[GL_ENV]


def gl_backend_chosen_by_user(environ: Mapping[str, str] | None = None) -> bool:
    """Whether `MUJOCO_GL` is the user's choice (to be honoured as is), not a default set by the runner.

    A default is marked with `SCENARIO_GL_AUTO=1`. Without the mark, the variable counts as the user's when
    this process started with it (`/proc/self/environ` is the environment as the process was started, before
    `import runner` set a default; elsewhere: whenever it is set)."""
    env = os.environ if environ is None else environ
    if GL_ENV not in env:
        return False
    if env.get(GL_AUTO_ENV) == "1":
        return False
    if environ is None:
        try:
            with open("/proc/self/environ", "rb") as f:
                started_with = f.read().split(b"\0")
        except OSError:
            return True
        return any(item.startswith(GL_ENV.encode() + b"=") for item in started_with)
    return True


def gl_library_present(backend: str) -> bool:
    """Whether the shared library a headless backend needs is installed: in the dynamic loader's cache or
    on LD_LIBRARY_PATH. Not loaded here, so that it cannot get in the way of another backend."""
    name = GL_LIBRARY.get(backend)
    if not name:
        return False
    if ctypes.util.find_library(name):
        return True
    dirs = [d for d in os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep) if d]
    return any(glob.glob(os.path.join(d, f"lib{name}.so*")) for d in dirs)


def probe_gl_backend(
    backend: str, timeout: float = 60.0, environ: Mapping[str, str] | None = None
) -> str | None:
    """Try `backend` in a fresh interpreter: import mujoco with `MUJOCO_GL=backend`, make a context and
    render one tiny frame. Returns None when it works, else why not (one line; a crash is reported by its
    signal, as the probe is what crashes, not this process)."""
    env = dict(os.environ if environ is None else environ)
    env[GL_ENV] = backend
    env.pop(GL_PROBED_ENV, None)
    if backend in HEADLESS_BACKENDS:
        # PyOpenGL's platform must match: importing mujoco sets it, in this process, to the backend mujoco
        # loaded here, which the probe of another backend must not inherit.
        env["PYOPENGL_PLATFORM"] = backend
    try:
        done = subprocess.run(
            [sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        return f"a test render did not finish within {timeout:g} s"
    except OSError as e:
        return f"could not start a test process: {e}"
    if done.returncode == 0:
        return None
    said = (done.stdout.strip().splitlines() or [""])[-1]
    if done.returncode < 0:
        return f"a test render crashed (signal {-done.returncode})" + (f": {said}" if said else "")
    return said or f"a test render failed (exit status {done.returncode})"


def choose_gl_backend(
    environ: Mapping[str, str] | None = None, probe: Callable[[str], str | None] = probe_gl_backend
) -> str:
    """The `MUJOCO_GL` value a process that renders should be started with.

    The user's own `MUJOCO_GL` is returned as it is (not probed). Otherwise EGL if a probe renders with it,
    else OSMesa if libOSMesa is installed and a probe renders with it; if neither works, a `RuntimeError`
    naming the Debian packages to install. Costs one or two probe subprocesses (~0.4 s each): call it only
    for runs that have a camera. Unless the user chose it, the caller puts the result in the child's
    environment as `MUJOCO_GL` and `PYOPENGL_PLATFORM` (this process's own value is the backend mujoco loaded
    here), with `SCENARIO_GL_AUTO=1` and `SCENARIO_GL_PROBED=<backend>` (the child then does not probe
    again)."""
    env = os.environ if environ is None else environ
    if gl_backend_chosen_by_user(environ):
        return env[GL_ENV]
    tried: dict[str, str] = {}
    for backend in HEADLESS_BACKENDS:
        if backend != "egl" and not gl_library_present(backend):
            tried[backend] = f"lib{GL_LIBRARY[backend]} is not installed"
            continue
        why = probe(backend)
        if why is None:
            return backend
        tried[backend] = why
    raise RuntimeError(no_backend_message(tried))


def no_backend_message(tried: Mapping[str, str], requested: str | None = None) -> str:
    """A clear error: what failed, and the Debian packages that make headless rendering work."""
    what = "; ".join(f"{b}: {why}" for b, why in tried.items())
    chosen = f" with MUJOCO_GL={requested!r}" if requested is not None else ""
    text = (
        f"cannot render camera images: no OpenGL backend works{chosen} ({what}). Headless rendering needs "
        f"EGL (Debian packages: {' '.join(GL_PACKAGES['egl'])}) or OSMesa (Debian package: "
        f"{' '.join(GL_PACKAGES['osmesa'])}, used with MUJOCO_GL=osmesa): "
        f"`apt-get install {' '.join(GL_PACKAGES['egl'])}`."
    )
    if requested not in (None, "osmesa") and "osmesa" not in tried and gl_library_present("osmesa"):
        text += " libOSMesa is installed: try MUJOCO_GL=osmesa."
    return text
