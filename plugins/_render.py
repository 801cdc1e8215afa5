"""Rendering helpers shared by the camera plugins (`camera`, `depth_camera`).

- the headless OpenGL backend (`ensure_gl_backend`);
- the parameters every camera has (`CameraParams`) and mounting a MuJoCo camera with Gazebo's convention
  (`add_camera`);
- `CameraRenderer`: one offscreen `mujoco.Renderer` per camera, set up for speed (no MSAA, no shadows, no
  reflections), giving RGB images and metric depth;
- ROS message builders: `Image`, `CameraInfo`, pixel formats and intensity noise.

Conventions. A Gazebo camera looks along its link's +X axis with +Z up; a MuJoCo camera looks along its
own -Z with +Y up. Images are in the ROS optical frame (z forward, x right, y down; row 0 is the top).
Intrinsics: fx = fy = width / (2 tan(fov / 2)), cx = width / 2, cy = height / 2, no distortion.
"""

from __future__ import annotations

import atexit
import math
import os
import weakref
from typing import Any, Literal

import mujoco
import numpy as np
from pydantic import Field, PositiveFloat, PositiveInt, model_validator

from plugins._common import MountPose
from runner import msgs
from runner.geometry import rpy_to_quat
from runner.plugin import BuildContext, PluginConfigError, RatedParams

# The compiler gives every world an offscreen framebuffer of this size (runner/compile/__init__.py):
# no camera image can be larger.
OFFSCREEN_MAX = (1280, 960)

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
POINT_CLOUD = "sensor_msgs/msg/PointCloud2"

# Rotation of a MuJoCo camera (looks along -Z, +Y up) inside a Gazebo camera link (looks along +X, +Z up):
# columns are the MuJoCo camera's x (right = -Y), y (up = +Z) and z (backwards = -X) in link axes.
_GAZEBO_FROM_MUJOCO_CAMERA = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def ensure_gl_backend() -> str:
    """Choose MuJoCo's OpenGL backend for offscreen rendering, before `mujoco` is imported.

    Sets `MUJOCO_GL=egl` when it is unset: EGL renders headless, on a GPU or on the CPU with Mesa's
    llvmpipe (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri libgbm1). A user can choose another one by
    setting the variable first: `MUJOCO_GL=osmesa` is the fallback where EGL does not work (needs
    libosmesa6, slower), `glfw` needs a display.

    MuJoCo reads the variable once, when it is imported (`import mujoco` loads its GL context class), so
    this has an effect only before that: importing this module already imports mujoco, so the entry points
    inline the same line at their very top (`python -m runner.sim`: `os.environ.setdefault("MUJOCO_GL",
    "egl")`). `CameraRenderer` reports a clear error when mujoco was imported with GLFW and no display.
    Returns the backend that will be asked for.
    """
    return os.environ.setdefault("MUJOCO_GL", "egl")


def gl_backend_in_use() -> str:
    """The backend mujoco loaded at import ('egl', 'osmesa', 'glfw', ...), from its GLContext class."""
    ctx_cls = getattr(mujoco, "GLContext", None)
    if ctx_cls is None:
        return "none"
    return ctx_cls.__module__.rsplit(".", 1)[-1]


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


@atexit.register
def _close_all() -> None:
    # A run that fails between setup() and close() would otherwise leave EGL contexts to the garbage
    # collector at interpreter exit, which prints EGL errors. Registered after mujoco's own atexit handlers,
    # so it runs before them.
    for r in list(_open):
        r.close()


class CameraRenderer:
    """An offscreen renderer for one MuJoCo camera of size width x height.

    Renders the model's visible geoms (groups 0-2, as MuJoCo's default), no sites; the camera's own near/far
    clip planes are applied at each frame (MuJoCo has one near/far per model: `vis.map.znear/zfar`, in
    units of the model's extent, so they are set before each render). Creating one turns off
    multisampling and the shadow map for all renderers of this model (`vis.quality`): the camera
    plugins do not draw shadows or reflections.
    """

    def __init__(
        self, model: mujoco.MjModel, camera_id: int, width: int, height: int, near: float, far: float
    ):
        backend = gl_backend_in_use()
        if backend == "glfw" and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise RuntimeError(
                "cannot render camera images: MuJoCo was imported with MUJOCO_GL unset (GLFW), which needs a "
                "display. Set MUJOCO_GL=egl (or MUJOCO_GL=osmesa) before mujoco is imported."
            )
        bw, bh = int(model.vis.global_.offwidth), int(model.vis.global_.offheight)
        if width > bw or height > bh:
            raise RuntimeError(
                f"a {width}x{height} camera image does not fit the model's offscreen framebuffer "
                f"({bw}x{bh}): make the image smaller or the framebuffer (visual/global offwidth, "
                "offheight) larger"
            )
        self.model = model
        self.camera_id = camera_id
        self.width, self.height = width, height
        self.near, self.far = float(near), float(far)
        model.vis.quality.offsamples = 0
        model.vis.quality.shadowsize = 0
        try:
            self._r: Any = mujoco.Renderer(model, height, width)
        except Exception as e:
            raise RuntimeError(
                f"cannot create an offscreen renderer (MUJOCO_GL={os.environ.get('MUJOCO_GL', '')!r}, "
                f"backend {backend}): {type(e).__name__}: {e}. Headless rendering needs EGL (Debian: libegl1 "
                "libegl-mesa0 libgl1-mesa-dri libgbm1) or MUJOCO_GL=osmesa with libosmesa6."
            ) from e
        _open.add(self)
        opt = mujoco.MjvOption()
        opt.sitegroup[:] = 0  # sites are markers, not things a camera sees
        self.option = opt
        self._rgb = np.empty((height, width, 3), dtype=np.uint8)
        self._depth = np.empty((height, width), dtype=np.float32)

    def update(self, data: mujoco.MjData) -> None:
        """Take the scene from `data` (call once per frame, before `rgb()` and `depth()`)."""
        m = self.model
        extent = float(m.stat.extent)
        m.vis.map.znear = self.near / extent
        # A little beyond `far`: pixels where nothing is drawn read the far plane, which must stay
        # distinguishable from geometry at `far` (float32 round-off in the conversion is ~1e-4 of far).
        m.vis.map.zfar = self.far * _FAR_MARGIN / extent
        self._r.update_scene(data, self.camera_id, self.option)
        flags = self._r.scene.flags
        flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False

    def rgb(self) -> np.ndarray:
        """The colour image of the last `update`, H x W x 3 uint8, row 0 at the top (a buffer reused)."""
        self._r.disable_depth_rendering()
        return self._r.render(out=self._rgb)

    def depth(self) -> np.ndarray:
        """Depth along the optical axis (metres, float32, H x W) of the last `update`: +inf where nothing
        is within `far` (MuJoCo's Renderer turns the depth buffer into metric depth; nothing maps to far)."""
        self._r.enable_depth_rendering()
        try:
            depth = self._r.render(out=self._depth)
        finally:
            self._r.disable_depth_rendering()
        depth[depth > np.float32(self.far)] = np.inf
        return depth

    def close(self) -> None:
        r = getattr(self, "_r", None)
        if r is not None:
            r.close()
            self._r = None
        _open.discard(self)


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


def to_format(rgb: np.ndarray, fmt: str) -> np.ndarray:
    """An RGB uint8 image in the pixel format `fmt` (`rgb8`, `bgr8` or `mono8`: ITU-R BT.601 luma)."""
    if fmt == "rgb8":
        return rgb.copy()
    if fmt == "bgr8":
        return np.ascontiguousarray(rgb[..., ::-1])
    luma = rgb.astype(np.uint16) @ np.array([77, 150, 29], dtype=np.uint16)  # weights sum to 256
    return ((luma + 128) >> 8).astype(np.uint8)


def add_noise(img: np.ndarray, stddev: float, rng: np.random.Generator) -> np.ndarray:
    """Gaussian noise on uint8 intensities, `stddev` in 0..1 units, clamped to 0..255."""
    if stddev <= 0:
        return img
    noisy = img.astype(np.float32) + rng.normal(0.0, stddev * 255.0, img.shape).astype(np.float32)
    return np.clip(np.rint(noisy), 0, 255).astype(np.uint8)


def encoding_channels(fmt: str) -> int:
    return 1 if fmt == "mono8" else 3
