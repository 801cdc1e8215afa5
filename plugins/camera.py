"""camera: a colour camera -> sensor_msgs/Image + sensor_msgs/CameraInfo, rendered offscreen by MuJoCo.

Like Gazebo's camera sensor with libgazebo_ros_camera: the camera looks along its link's +X axis (+Z up),
`width` x `height` pixels, horizontal field of view `fov`, clip planes `near`/`far`, gaussian intensity
noise. CameraInfo is an ideal pinhole: fx = fy = width / (2 tan(fov / 2)), cx = width / 2,
cy = height / 2, plumb_bob distortion with zeros, R identity, P = [K | 0].

Rendering needs an OpenGL backend: headless, MUJOCO_GL=egl (set by `python -m runner.sim` when unset), or
MUJOCO_GL=osmesa; see "Backends" in `plugins._render`. Where none works, `setup` raises a RuntimeError naming
the Debian packages to install. The image shows the world's geoms in MuJoCo's visible groups (0-2), the
robot's own included, with lights but no shadows or reflections. A camera costs nothing between its frames.
"""

from __future__ import annotations

from typing import ClassVar

import mujoco
import numpy as np

from plugins._common import pick_link
from plugins._pixels import ImageOut, PixelNoise, to_format
from plugins._render import (
    CAMERA_INFO,
    IMAGE,
    CameraParams,
    CameraRenderer,
    InfoMaker,
    Intrinsics,
    add_camera,
    camera_name,
)
from runner.plugin import BuildContext, Plugin, Topic


class Camera(Plugin):
    Params = CameraParams
    params: CameraParams
    link_hints: ClassVar[tuple[str, ...]] = ("camera",)
    renders: ClassVar[bool] = True

    @classmethod
    def build(cls, params: CameraParams, ctx: BuildContext, name: str) -> list[Topic]:
        link = pick_link(ctx, params.link, cls.link_hints)
        add_camera(ctx, link, name, params)
        return cls.topics(params)

    @classmethod
    def topics(cls, p: CameraParams) -> list[Topic]:
        return [Topic(p.image_topic, IMAGE, "pub", p.rate), Topic(p.info_topic, CAMERA_INFO, "pub", p.rate)]

    def setup(self) -> None:
        p = self.params
        ctx = self.ctx
        r = ctx.robot
        m = ctx.model
        cam = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_CAMERA, r.prefix + camera_name(self.name))
        if cam < 0:
            raise KeyError(f"camera {r.prefix + camera_name(self.name)!r} not in the model")
        link = m.body(int(m.cam_bodyid[cam])).name.removeprefix(r.prefix)
        self.frame_id = p.frame_id or r.frame(link)
        self.intrinsics = Intrinsics(p.width, p.height, p.fov)
        self.make_info = InfoMaker(self.intrinsics)
        self.renderer: CameraRenderer | None = None
        self.camera_id = cam
        self.renderer = CameraRenderer(m, cam, p.width, p.height, p.near, p.far)
        self.color_pubs()

    def rebind(self) -> None:
        """A new model (a robot spawned): a renderer of it (its meshes and textures, the new robot's too)."""
        p = self.params
        if self.renderer is not None:
            self.renderer.close()
        self.renderer = None
        self.renderer = CameraRenderer(self.ctx.model, self.camera_id, p.width, p.height, p.near, p.far)

    def color_pubs(self) -> None:
        p = self.params
        self.image_pub = self.ctx.publisher(p.image_topic, IMAGE)
        self.info_pub = self.ctx.publisher(p.info_topic, CAMERA_INFO)
        # the frame is written straight into its message's bytes (flipped, converted, noisy in one pass)
        self.image_out = ImageOut(self.image_pub, self.frame_id, p.height, p.width, p.format)
        self.info_out = self.info_pub.layout(self.make_info(0, self.frame_id), ["header.stamp"])
        self.noise = PixelNoise(p.noise_stddev, self.ctx.rng) if p.noise_stddev > 0 else None
        if self.noise is not None:  # its table is drawn now, not in the first frame (~0.1 s)
            self.noise.table(16 * self.image_out.pixels[0].size)

    def publish_color(self, rgb: np.ndarray, now_ns: int) -> None:
        """Publish an RGB frame (H x W x 3 uint8, any strides) in the configured format, with noise, and its
        CameraInfo."""
        p = self.params
        pixels = self.image_out.pixels
        if self.noise is None:
            to_format(rgb, p.format, pixels)
        elif p.format == "mono8":
            self.noise.apply(to_format(rgb, p.format, pixels), pixels)
        else:
            self.noise.apply(rgb if p.format == "rgb8" else rgb[..., ::-1], pixels)
        self.image_pub.publish_cdr(self.image_out.payload(now_ns), now_ns)
        self.info_pub.publish_cdr(self.info_out.encode(now_ns), now_ns)

    def after_step(self, now_ns: int) -> None:
        assert self.renderer is not None
        self.renderer.update(self.ctx.data)
        self.publish_color(self.renderer.rgb_view(), now_ns)

    def close(self) -> None:
        if getattr(self, "renderer", None) is not None:
            self.renderer.close()  # type: ignore[union-attr]
            self.renderer = None
