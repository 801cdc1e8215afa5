"""Rendering helpers shared by the camera plugins (`camera`, `depth_camera`).

- the headless OpenGL backend: `ensure_gl_backend`, `choose_gl_backend`, `probe_gl_backend`,
  `gl_backend_in_use` (see "Backends" below);
- the parameters every camera has (`CameraParams`) and mounting a MuJoCo camera with Gazebo's convention
  (`add_camera`);
- `CameraRenderer`: one offscreen OpenGL context per camera, set up for speed (no MSAA, no shadows, no
  reflections), giving RGB images and metric depth, both from one render where that gives the same depth,
  as views of the pixels read (`rgb_view`, `rgbd_views`) that the camera writes straight into its messages;
- ROS message builders: `Image`, `CameraInfo` (pixel formats, the noise and images encoded in place are in
  `plugins._pixels`).

Conventions. A Gazebo camera looks along its link's +X axis with +Z up; a MuJoCo camera looks along its
own -Z with +Y up. Images are in the ROS optical frame (z forward, x right, y down; row 0 is the top).
Intrinsics: fx = fy = width / (2 tan(fov / 2)), cx = width / 2, cy = height / 2, no distortion.

Backends. MuJoCo picks its OpenGL backend from `MUJOCO_GL` once, when it is imported, and loads that
backend's libraries into the process (PyOpenGL binds itself to one platform, and MuJoCo's GL loader
resolves its functions once per process). So the backend cannot change after `import mujoco`: measured, an
OSMesa context made in a process that loaded EGL fails in MuJoCo's loader (`gladLoadGL error`). The choice
is therefore made before mujoco is imported, and checked in a subprocess where checking can crash:

- `MUJOCO_GL` set by the user is used as it is (`ensure_gl_backend` only replaces a value with which `import
  mujoco` itself would fail, by `disable`, keeping it for the error message);
- unset: EGL (`ensure_gl_backend`; `import runner` and `python -m runner.sim` inline a default before mujoco
  is imported), headless on a GPU or on the CPU with Mesa's llvmpipe; the default is marked
  (`SCENARIO_GL_AUTO=1`) so that child processes know it was not the user's choice;
- a process that starts one that renders (the launcher, before the world process) calls
  `choose_gl_backend()`: EGL if a probe subprocess renders with it, else OSMesa if its library is there and
  a probe renders with it, else a `RuntimeError` naming the missing Debian packages; the answer goes in the
  child's environment;
- in the rendering process, the first `CameraRenderer` probes the backend mujoco loaded in a subprocess
  (~0.4 s, once; not when a parent did: `SCENARIO_GL_PROBED`) before making a context itself, so that a
  backend that cannot render, or a driver that would crash the process, is a `RuntimeError` naming the
  packages, never a segfault. A process cannot switch to OSMesa itself once mujoco loaded EGL.
"""

from __future__ import annotations

import atexit
import contextlib
import math
import os
import weakref
from typing import Any, Literal

import mujoco
import numpy as np
from pydantic import Field, PositiveFloat, PositiveInt, model_validator

from plugins._common import MountPose
from runner.geometry import rpy_to_quat
from runner.gl import (  # noqa: F401  (re-exported for the camera plugins and tests)
    GL_AUTO_ENV,
    GL_DISABLED,
    GL_ENV,
    GL_KNOWN,
    GL_LIBRARY,
    GL_PACKAGES,
    GL_PROBED_ENV,
    GL_REQUESTED_ENV,
    HEADLESS_BACKENDS,
    choose_gl_backend,
    ensure_gl_backend,
    gl_backend_chosen_by_user,
    gl_library_present,
    no_backend_message,
    probe_gl_backend,
)
from runner.plugin import BuildContext, PluginConfigError, RatedParams
from runner.wire import msgs

# The compiler gives every world an offscreen framebuffer of at least 1280x960 (runner/compile/world.py);
# a larger camera grows it, up to this (what any GL implementation offers).
OFFSCREEN_MAX = (8192, 8192)

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
POINT_CLOUD = "sensor_msgs/msg/PointCloud2"

# Rotation of a MuJoCo camera (looks along -Z, +Y up) inside a Gazebo camera link (looks along +X, +Z up):
# columns are the MuJoCo camera's x (right = -Y), y (up = +Z) and z (backwards = -X) in link axes.
_GAZEBO_FROM_MUJOCO_CAMERA = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def gl_backend_in_use() -> str:
    """The backend mujoco loaded at import ('egl', 'osmesa', 'glfw', ...), from its GLContext class;
    'none' when it has none (MUJOCO_GL=disable, or the backend's libraries could not be loaded)."""
    ctx_cls = getattr(mujoco, "GLContext", None)
    if ctx_cls is None:
        return "none"
    return ctx_cls.__module__.rsplit(".", 1)[-1]


_probed: dict[str, str | None] = {}  # backend -> None (renders) or why not, once per process


def _gl_context_class() -> Any:
    """The OpenGL context class mujoco loaded, checked to work here; else a RuntimeError naming packages."""
    backend = gl_backend_in_use()
    requested = os.environ.get(GL_REQUESTED_ENV) or os.environ.get(GL_ENV, "")
    if backend == "none":
        name = requested.strip().lower()
        if name in GL_DISABLED:
            why = "rendering is disabled"
        elif name not in GL_KNOWN:
            why = "not a backend MuJoCo knows (egl, osmesa, glfw)"
        elif name in HEADLESS_BACKENDS and not gl_library_present(name):
            why = f"lib{GL_LIBRARY[name]} is not installed"
        elif name in HEADLESS_BACKENDS:
            why = f"mujoco could not load the {name} backend's libraries"
        else:
            why = "mujoco has no OpenGL context class"
        raise RuntimeError(no_backend_message({name or "unset": why}, requested))
    if backend == "glfw" and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise RuntimeError(
            "cannot render camera images: MuJoCo was imported with MUJOCO_GL unset (GLFW), which needs a "
            "display. Set MUJOCO_GL=egl (Debian packages: " + " ".join(GL_PACKAGES["egl"]) + ") or "
            "MUJOCO_GL=osmesa (libosmesa6) before mujoco is imported."
        )
    if backend in HEADLESS_BACKENDS and os.environ.get(GL_PROBED_ENV) != backend:
        if backend not in _probed:
            _probed[backend] = probe_gl_backend(backend)
        why = _probed[backend]
        if why is not None:
            raise RuntimeError(no_backend_message({backend: why}, requested))
    return mujoco.GLContext


# --------------------------------------------------------------------------------------------- params
class CameraParams(RatedParams):
    """Parameters of every camera (as Gazebo's camera sensor and libgazebo_ros_camera)."""

    link: str | None = Field(
        None,
        description="Link the camera is mounted on (default: the first link named like camera, else "
        "the root link). The camera looks along the link's +X axis, +Z up, as in Gazebo.",
    )
    pose: MountPose = Field(default_factory=MountPose, description="Mount pose relative to the link.")
    image_topic: str = Field(
        "camera/image_raw", description="Image topic, relative to the robot's namespace."
    )
    info_topic: str = Field(
        "camera/camera_info", description="CameraInfo topic, relative to the robot's namespace."
    )
    frame_id: str | None = Field(None, description="Frame id in the headers (default: <ns>/<link>).")
    width: PositiveInt = Field(320, description=f"Image width in pixels (at most {OFFSCREEN_MAX[0]}).")
    height: PositiveInt = Field(240, description=f"Image height in pixels (at most {OFFSCREEN_MAX[1]}).")
    fov: float = Field(1.047, gt=0.0, lt=math.pi, description="Horizontal field of view, radians.")
    near: PositiveFloat = Field(0.02, description="Near clip distance, metres: nothing closer is seen.")
    far: PositiveFloat = Field(100.0, description="Far clip distance, metres: nothing farther is seen.")
    format: Literal["rgb8", "bgr8", "mono8"] = Field("rgb8", description="Pixel format of the image.")
    noise_stddev: float = Field(
        0.0, ge=0.0, description="Gaussian noise added to each pixel intensity, in 0..1 units (as Gazebo)."
    )

    @model_validator(mode="after")
    def _check(self) -> CameraParams:
        if self.far <= self.near:
            raise ValueError(f"far ({self.far}) must exceed near ({self.near})")
        seen: dict[str, str] = {}
        for param, topic in self.topic_params().items():
            if topic is None:
                continue
            if topic in seen:
                raise ValueError(f"{seen[topic]} and {param} are the same topic {topic!r}")
            seen[topic] = param
        return self

    def topic_params(self) -> dict[str, str | None]:
        """The topic parameters in use (None: off); they must differ."""
        return {"image_topic": self.image_topic, "info_topic": self.info_topic}


def camera_name(plugin_name: str) -> str:
    """The MuJoCo camera of a plugin (un-prefixed: the robot's prefix is added when it is placed)."""
    return f"{plugin_name}_camera"


def fovy_degrees(fov: float, width: int, height: int) -> float:
    """MuJoCo's vertical field of view (degrees) for a horizontal `fov` (radians) and square pixels."""
    return math.degrees(2.0 * math.atan(math.tan(fov / 2.0) * height / width))


def add_camera(ctx: BuildContext, link: str, name: str, p: CameraParams) -> str:
    """Add the plugin's MuJoCo camera to `link`, mounted at `p.pose` with Gazebo's axes. Returns its name."""
    w, h = OFFSCREEN_MAX
    if p.width > w or p.height > h:
        param = "width" if p.width > w else "height"
        raise PluginConfigError(
            f"a {p.width}x{p.height} image does not fit the offscreen framebuffer ({w}x{h})",
            param,
            hint=f"use at most width {w} and height {h}",
        )
    # a full-HD camera (TurtleBot3 Waffle's R200 says 1920x1080) grows the framebuffer it renders into
    vis = ctx.spec.visual.global_
    vis.offwidth, vis.offheight = max(int(vis.offwidth), p.width), max(int(vis.offheight), p.height)
    body = ctx.body(link)
    cam_name = camera_name(name)
    if ctx.spec.camera(cam_name) is not None:
        raise PluginConfigError(
            f"a camera named {cam_name!r} already exists", hint="give the plugin a `name:`"
        )
    q_optical = np.zeros(4)
    mujoco.mju_mat2Quat(q_optical, _GAZEBO_FROM_MUJOCO_CAMERA.reshape(-1))
    quat = np.zeros(4)
    mujoco.mju_mulQuat(quat, rpy_to_quat(p.pose.rpy), q_optical)
    body.add_camera(
        name=cam_name,
        pos=list(p.pose.xyz),
        quat=list(quat),
        fovy=fovy_degrees(p.fov, p.width, p.height),
    )
    return cam_name


# ------------------------------------------------------------------------------------------- renderer
_FAR_MARGIN = 1.001
_open: weakref.WeakSet[CameraRenderer] = weakref.WeakSet()
_model_clip: weakref.WeakKeyDictionary[mujoco.MjModel, tuple[float, float]] = weakref.WeakKeyDictionary()
_atexit_registered = False


def _close_all() -> None:
    # A run that fails between setup() and close() would otherwise leave GL contexts to the garbage collector
    # at interpreter exit, after mujoco's EGL atexit handler terminated the display (EGL errors printed).
    # Registered after the first context is made, hence after that handler: atexit runs it first.
    for r in list(_open):
        r.close()


class CameraRenderer:
    """An offscreen renderer for one MuJoCo camera of size width x height.

    Renders the model's visible geoms (groups 0-2, as MuJoCo's default), no sites; the camera's own near/far
    clip planes are applied at each frame (MuJoCo has one near/far per model: `vis.map.znear/zfar`, in
    units of the model's extent, so they are set before each scene update, when they differ). Creating one
    turns off multisampling and the shadow map for all renderers of this model (`vis.quality`): the camera
    plugins do not draw shadows or reflections.

    Each renderer has its own OpenGL context (of the backend mujoco loaded, checked by `_gl_context_class`),
    MjrContext, scene and reused output buffers. `update()` takes the scene once per frame; then `rgb()`,
    `depth()` or `rgbd()` (both from one render when that gives the same depth: no skybox and nothing
    transparent; otherwise depth is rendered apart, in MuJoCo's segmentation mode, as `mujoco.Renderer`
    does). Depth is converted exactly as `mujoco.Renderer` does it.
    """

    def __init__(
        self, model: mujoco.MjModel, camera_id: int, width: int, height: int, near: float, far: float
    ):
        global _atexit_registered
        self._gl: Any = None
        self._con: Any = None
        bw, bh = int(model.vis.global_.offwidth), int(model.vis.global_.offheight)
        if width > bw or height > bh:
            raise RuntimeError(
                f"a {width}x{height} camera image does not fit the model's offscreen framebuffer "
                f"({bw}x{bh}): make the image smaller or the framebuffer (visual/global offwidth, "
                "offheight) larger"
            )
        ctx_cls = _gl_context_class()
        self.model = model
        self.camera_id = camera_id
        self.width, self.height = width, height
        self.near, self.far = float(near), float(far)
        model.vis.quality.offsamples = 0
        model.vis.quality.shadowsize = 0
        # MuJoCo builds the grid of an infinite ground plane when the context is made, from vis.map.zfar
        # (its size, and so the size of its cells): make every context from the model's own value, not from
        # whichever camera's far plane was set last, so that all cameras of a model see the same ground.
        clip = _model_clip.setdefault(model, (float(model.vis.map.znear), float(model.vis.map.zfar)))
        now = (float(model.vis.map.znear), float(model.vis.map.zfar))
        model.vis.map.znear, model.vis.map.zfar = clip
        try:
            self._gl = ctx_cls(width, height)
            self._gl.make_current()
            self._con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150)
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._con)
            self._con.readDepthMap = mujoco.mjtDepthMap.mjDEPTH_ZEROFAR
        except Exception as e:
            self.close()
            raise RuntimeError(
                no_backend_message(
                    {gl_backend_in_use(): f"making an offscreen context failed: {type(e).__name__}: {e}"},
                    os.environ.get(GL_ENV, ""),
                )
            ) from e
        finally:
            model.vis.map.znear, model.vis.map.zfar = now
        _open.add(self)
        if not _atexit_registered:
            atexit.register(_close_all)
            _atexit_registered = True
        self.scene = mujoco.MjvScene(model, maxgeom=10000)
        cam = mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        cam.fixedcamid = camera_id
        self._camera = cam
        opt = mujoco.MjvOption()
        opt.sitegroup[:] = 0  # sites are markers, not things a camera sees
        self.option = opt
        self._rect = mujoco.MjrRect(0, 0, width, height)
        self._has_skybox = bool(np.any(model.tex_type == mujoco.mjtTexture.mjTEXTURE_SKYBOX))
        # OpenGL rows run bottom-up: pixels are read into these, then flipped into the outputs.
        self._raw_rgb = np.empty((height, width, 3), dtype=np.uint8)
        self._raw_depth = np.empty((height, width), dtype=np.float32)
        self._depth64 = np.empty((min(height, 32), width), dtype=np.float64)  # a block of rows
        self._beyond = np.empty((min(height, 32), width), dtype=bool)
        self._rgb = np.empty((height, width, 3), dtype=np.uint8)
        self._depth = np.empty((height, width), dtype=np.float32)
        self._clip = (np.float32(0.0), np.float32(0.0))

    # ----------------------------------------------------------------------------------------- frames
    def update(self, data: mujoco.MjData) -> None:
        """Take the scene from `data` (call once per frame, before `rgb()`, `depth()` or `rgbd()`)."""
        m = self.model
        vmap = m.vis.map
        extent = float(m.stat.extent)
        znear = self.near / extent
        # A little beyond `far`: pixels where nothing is drawn read the far plane, which must stay
        # distinguishable from geometry at `far` (float32 round-off in the conversion is ~1e-4 of far).
        zfar = self.far * _FAR_MARGIN / extent
        if vmap.znear != np.float32(znear):
            vmap.znear = znear
        if vmap.zfar != np.float32(zfar):
            vmap.zfar = zfar
        # the clip distances this frame's projection uses (as mujoco.Renderer reads them for depth)
        self._clip = (np.float32(vmap.znear * extent), np.float32(vmap.zfar * extent))
        mujoco.mjv_updateScene(
            m, data, self.option, None, self._camera, mujoco.mjtCatBit.mjCAT_ALL, self.scene
        )
        flags = self.scene.flags
        flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False

    def rgb(self) -> np.ndarray:
        """The colour image of the last `update`, H x W x 3 uint8, row 0 at the top (a buffer reused)."""
        self._render(depth_too=False)
        np.copyto(self._rgb, self._raw_rgb[::-1])
        return self._rgb

    def rgb_view(self) -> np.ndarray:
        """`rgb()` without its copy: a view of the pixels as read, rows flipped (row 0 at the top; negative
        strides). Valid until the next render: the camera writes it straight into its message."""
        self._render(depth_too=False)
        return self._raw_rgb[::-1]

    def rgbd_views(self, depth_out: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """`rgbd()` with the colour image as `rgb_view()` gives it and the depth written into `depth_out`
        (H x W float32, e.g. the depth message's pixels) when given."""
        one = self._depth_same_in_color_render()
        self._render(depth_too=one)
        rgb = self._raw_rgb[::-1]
        if not one:
            self._render_depth()
        return rgb, self._convert_depth(depth_out)

    def depth(self, out: np.ndarray | None = None) -> np.ndarray:
        """Depth along the optical axis (metres, float32, H x W) of the last `update`: +inf where nothing
        is within `far` (nothing maps to far). A buffer reused, or `out`."""
        self._render_depth()
        return self._convert_depth(out)

    def rgbd(self) -> tuple[np.ndarray, np.ndarray]:
        """`rgb()` and `depth()` of the last `update`, from one render when the depth buffer of the colour
        render is the depth `depth()` gives (no skybox drawn, nothing transparent); else two renders."""
        one = self._depth_same_in_color_render()
        self._render(depth_too=one)
        np.copyto(self._rgb, self._raw_rgb[::-1])
        if not one:
            self._render_depth()
        return self._rgb, self._convert_depth()

    def _depth_same_in_color_render(self) -> bool:
        # Checked by rendering both ways: the depth buffers are identical unless a skybox is drawn (it
        # writes depth) or something is transparent (drawn differently in segmentation mode).
        m = self.model
        if self._has_skybox and self.scene.flags[mujoco.mjtRndFlag.mjRND_SKYBOX]:
            return False
        for rgba in (m.geom_rgba, m.mat_rgba, m.skin_rgba, m.flex_rgba):
            if len(rgba) and float(rgba[:, 3].min()) < 1.0:
                return False
        return True

    def _render(self, depth_too: bool) -> None:
        if self._con is None:
            raise RuntimeError("render cannot be called after close")
        self._gl.make_current()
        mujoco.mjr_render(self._rect, self.scene, self._con)
        mujoco.mjr_readPixels(self._raw_rgb, self._raw_depth if depth_too else None, self._rect, self._con)

    def _render_depth(self) -> None:
        # Segmentation mode, as mujoco.Renderer renders depth: no lighting or skybox, everything opaque.
        if self._con is None:
            raise RuntimeError("render cannot be called after close")
        flags = self.scene.flags
        seg, idc = mujoco.mjtRndFlag.mjRND_SEGMENT, mujoco.mjtRndFlag.mjRND_IDCOLOR
        old = (flags[seg], flags[idc])
        flags[seg] = flags[idc] = True
        try:
            self._gl.make_current()
            mujoco.mjr_render(self._rect, self.scene, self._con)
            mujoco.mjr_readPixels(None, self._raw_depth, self._rect, self._con)
        finally:
            flags[seg], flags[idc] = old

    def _convert_depth(self, out: np.ndarray | None = None) -> np.ndarray:
        # mujoco.Renderer's conversion (reversed Z, float32 coefficients, float64 arithmetic, float32
        # result), on the rows flipped top-down, into a reused buffer (or `out`), by blocks of rows that
        # stay in the cache.
        znear, zfar = self._clip
        raw = self._raw_depth[::-1]
        depth = self._depth if out is None else out
        ortho = bool(self.scene.camera[0].orthographic)
        c_coef = d_coef = np.float32(0)
        if not ortho:
            c_coef = -(zfar + znear) / (zfar - znear)
            d_coef = -(np.float32(2) * zfar * znear) / (zfar - znear)
            c_coef = np.float32(-0.5) * c_coef - np.float32(0.5)
            d_coef = np.float32(-0.5) * d_coef
        far, inf = np.float32(self.far), np.float32(np.inf)
        block = len(self._depth64)
        for r0 in range(0, raw.shape[0], block):
            r1 = min(raw.shape[0], r0 + block)
            d64, beyond, o = self._depth64[: r1 - r0], self._beyond[: r1 - r0], depth[r0:r1]
            if ortho:
                np.multiply(raw[r0:r1], zfar - znear, out=d64, dtype=np.float64)
                np.subtract(np.float64(zfar), d64, out=d64)
            else:
                np.add(raw[r0:r1], c_coef, out=d64, dtype=np.float64)
                np.divide(np.float64(d_coef), d64, out=d64)
            np.copyto(o, d64, casting="same_kind")
            np.greater(o, far, out=beyond)
            np.copyto(o, inf, where=beyond)
        return depth

    # ------------------------------------------------------------------------------------------ close
    def close(self) -> None:
        con, gl = self._con, self._gl
        self._con = self._gl = None
        # Errors are ignored: closing runs at exit too, when the display may already be gone.
        if con is not None:
            with contextlib.suppress(Exception):
                if gl is not None:
                    gl.make_current()  # the context's textures and buffers are freed in it
                con.free()
        if gl is not None:
            with contextlib.suppress(Exception):
                gl.free()
        _open.discard(self)

    def __del__(self) -> None:
        if getattr(self, "_con", None) is not None or getattr(self, "_gl", None) is not None:
            self.close()


# ------------------------------------------------------------------------------------------- messages
class Intrinsics:
    """Pinhole intrinsics of a camera of `width` x `height` pixels and horizontal field of view `fov`."""

    def __init__(self, width: int, height: int, fov: float):
        self.width, self.height = width, height
        self.fx = self.fy = width / (2.0 * math.tan(fov / 2.0))
        self.cx, self.cy = width / 2.0, height / 2.0

    @property
    def k(self) -> np.ndarray:
        return np.array([self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0])

    @property
    def p(self) -> np.ndarray:
        return np.array([self.fx, 0.0, self.cx, 0.0, 0.0, self.fy, self.cy, 0.0, 0.0, 0.0, 1.0, 0.0])

    def rays(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-pixel x/z and y/z in the optical frame (1 x W and H x 1), through the pixel centres as rendered
        (pixel u spans [u, u+1) around the optical axis at width/2)."""
        u = (np.arange(self.width, dtype=np.float64) + 0.5 - self.width / 2.0) / self.fx
        v = (np.arange(self.height, dtype=np.float64) + 0.5 - self.height / 2.0) / self.fy
        return u[None, :].astype(np.float32), v[:, None].astype(np.float32)


class InfoMaker:
    """Builds `sensor_msgs/CameraInfo` (plumb_bob, no distortion, R identity) for each stamp."""

    def __init__(self, intr: Intrinsics):
        T = msgs.T
        self.cls = T[CAMERA_INFO]
        self.intr = intr
        self.d = np.zeros(5)
        self.k = intr.k
        self.r = np.eye(3).reshape(-1)
        self.p = intr.p
        self.roi = T["sensor_msgs/msg/RegionOfInterest"](
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
        )

    def __call__(self, now_ns: int, frame_id: str) -> Any:
        return self.cls(
            header=msgs.header(now_ns, frame_id),
            height=self.intr.height,
            width=self.intr.width,
            distortion_model="plumb_bob",
            d=self.d,
            k=self.k,
            r=self.r,
            p=self.p,
            binning_x=0,
            binning_y=0,
            roi=self.roi,
        )


def image_msg(now_ns: int, frame_id: str, pixels: np.ndarray, encoding: str) -> Any:
    """A `sensor_msgs/Image` from an H x W (x C) array (uint8 or float32, little-endian)."""
    h, w = pixels.shape[:2]
    data = np.ascontiguousarray(pixels)
    row = data.reshape(h, -1).view(np.uint8)
    return msgs.T[IMAGE](
        header=msgs.header(now_ns, frame_id),
        height=h,
        width=w,
        encoding=encoding,
        is_bigendian=0,
        step=row.shape[1],
        data=row.reshape(-1),
    )


def encoding_channels(fmt: str) -> int:
    return 1 if fmt == "mono8" else 3
