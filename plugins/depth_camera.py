"""depth_camera: a depth (RGB-D) camera -> depth image, point cloud and, optionally, colour image.

Like Gazebo's `depth`/`depth_camera`/`rgbd_camera` sensors with libgazebo_ros_depth_camera (openni_kinect).
Mounting, field of view, clip planes and CameraInfo are as for `camera` (see plugins/camera.py); each frame
publishes:

- `depth_topic`: `sensor_msgs/Image`, encoding `32FC1`, metres along the optical axis (not along the ray),
  +inf where nothing is within `far` (nothing hit, or too far); `depth_info_topic`: its CameraInfo;
- `points_topic` (unless null): `sensor_msgs/PointCloud2`, organized (height x width, one point per
  pixel, row-major like the image), float32 `x`, `y`, `z` in the ROS optical frame (z forward, x right,
  y down) and, when `publish_color`, a float32 `rgb` packed as 0x00RRGGBB. Pixels without a return are
  kept as NaN points (the PCL/ROS convention for invalid points), so `is_dense` is false. Points go through
  the rendered pixel centres, (u + 0.5 - width / 2) / fx;
- when `publish_color`: the colour image and its CameraInfo on `image_topic`/`info_topic`, as `camera`.

Depth limits of the ROS plugins (`min_depth`, `max_depth`, `out_of_range`), in the depth image and the
cloud alike: `inf` (ROS 2 gazebo_ros_camera: -inf at or below `min_depth`, +inf at or beyond `max_depth`
or where nothing is hit, and x = y = z = that infinity in the cloud) or `nan` (ROS 1 gazebo_ros_depth_camera
and openni_kinect: NaN outside `(min_depth, max_depth)`, in the image and the cloud). With the default,
`clip`, only the clip planes limit depth, as described above.

`noise_stddev` applies to the colour image only (the point colours are noise-free); depth is exact up to
the depth buffer's precision (well under a millimetre at a few metres with the default clip planes).
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import Field, PositiveFloat

from plugins._pixels import ImageOut
from plugins._render import CAMERA_INFO, IMAGE, POINT_CLOUD, CameraParams
from plugins.camera import Camera
from runner.plugin import Topic
from runner.wire import msgs


class DepthCameraParams(CameraParams):
    depth_topic: str = Field(
        "camera/depth/image_raw", description="Depth image topic (32FC1, metres), relative to the namespace."
    )
    depth_info_topic: str | None = Field(
        "camera/depth/camera_info", description="CameraInfo of the depth image (null: not published)."
    )
    points_topic: str | None = Field(
        "camera/points", description="PointCloud2 topic, relative to the namespace (null: not published)."
    )
    publish_color: bool = Field(
        True, description="Also publish the colour image and its CameraInfo (image_topic, info_topic)."
    )
    min_depth: float = Field(
        0.0, ge=0, description="Depths at or below this are out of range (metres; 0: only the clip plane)."
    )
    max_depth: PositiveFloat | None = Field(
        None, description="Depths at or beyond this are out of range (metres; null: only the far plane)."
    )
    out_of_range: Literal["clip", "inf", "nan"] = Field(
        "clip",
        description="What min_depth/max_depth do: nothing, only the clip planes limit depth (clip); "
        "-inf/+inf below/beyond them in the image and the cloud (inf, ROS 2 gazebo_ros_camera); NaN (nan, "
        "ROS 1 gazebo_ros_depth_camera and openni_kinect).",
    )

    def topic_params(self) -> dict[str, str | None]:
        topics: dict[str, str | None] = {
            "depth_topic": self.depth_topic,
            "depth_info_topic": self.depth_info_topic,
            "points_topic": self.points_topic,
        }
        if self.publish_color:
            topics.update(super().topic_params())
        return topics


_FLOAT32 = 7  # sensor_msgs/PointField.FLOAT32


class DepthCamera(Camera):
    Params = DepthCameraParams
    params: DepthCameraParams
    link_hints: ClassVar[tuple[str, ...]] = ("depth", "camera")

    @classmethod
    def topics(cls, p: CameraParams) -> list[Topic]:
        assert isinstance(p, DepthCameraParams)
        out = [Topic(p.depth_topic, IMAGE, "pub", p.rate)]
        if p.depth_info_topic is not None:
            out.append(Topic(p.depth_info_topic, CAMERA_INFO, "pub", p.rate))
        if p.points_topic is not None:
            out.append(Topic(p.points_topic, POINT_CLOUD, "pub", p.rate))
        if p.publish_color:
            out += super().topics(p)
        return out

    def setup(self) -> None:
        super().setup()
        p = self.params
        self.depth_pub = self.ctx.publisher(p.depth_topic, IMAGE)
        self.depth_info_pub = (
            self.ctx.publisher(p.depth_info_topic, CAMERA_INFO) if p.depth_info_topic else None
        )
        self.points_pub = self.ctx.publisher(p.points_topic, POINT_CLOUD) if p.points_topic else None
        self.ray_x, self.ray_y = self.intrinsics.rays()
        names = ["x", "y", "z", "rgb"] if p.publish_color else ["x", "y", "z"]
        Field_ = msgs.T["sensor_msgs/msg/PointField"]
        self.fields = [Field_(name=n, offset=4 * i, datatype=_FLOAT32, count=1) for i, n in enumerate(names)]
        self.point_step = 4 * len(names)
        self.PointCloud2 = msgs.T[POINT_CLOUD]
        # Each frame is written into its messages' bytes: the depth image, and the cloud's points
        self.depth_out = ImageOut(self.depth_pub, self.frame_id, p.height, p.width, "32FC1")
        self.depth_info_out = (
            self.depth_info_pub.layout(self.make_info(0, self.frame_id), ["header.stamp"])
            if self.depth_info_pub is not None
            else None
        )
        if self.points_pub is not None:
            template = self.point_cloud(0, np.zeros((p.height, p.width), np.float32), None)
            self.points_out = self.points_pub.layout(template, ["header.stamp"])
            data = self.points_out.view("data")
            self.points = data.view(np.float32).reshape(p.height, p.width, len(names))

    def color_pubs(self) -> None:
        if self.params.publish_color:
            super().color_pubs()

    def after_step(self, now_ns: int) -> None:
        p = self.params
        assert self.renderer is not None
        self.renderer.update(self.ctx.data)
        rgb = None
        depth = self.depth_out.pixels
        if p.publish_color:
            # one scene update, and one render for both when that gives the same depth (CameraRenderer.rgbd)
            rgb, _ = self.renderer.rgbd_views(depth)
            self.publish_color(rgb, now_ns)
        else:
            self.renderer.depth(depth)
        self._limit(depth)
        self.depth_pub.publish_cdr(self.depth_out.payload(now_ns), now_ns)
        if self.depth_info_out is not None:
            assert self.depth_info_pub is not None
            self.depth_info_pub.publish_cdr(self.depth_info_out.encode(now_ns), now_ns)
        if self.points_pub is not None:
            self.fill_points(self.points, depth, rgb)
            self.points_pub.publish_cdr(self.points_out.fill(now_ns), now_ns)

    def _limit(self, depth: np.ndarray) -> None:
        """The plugin's depth limits, in place (see the module doc)."""
        p = self.params
        if p.out_of_range == "clip" or (p.min_depth <= 0 and p.max_depth is None):
            return
        lo = depth <= p.min_depth
        hi = depth >= p.max_depth if p.max_depth is not None else None
        if p.out_of_range == "nan":
            depth[lo] = np.nan
            if hi is not None:
                depth[hi] = np.nan
        else:
            depth[lo] = -np.inf
            if hi is not None:
                depth[hi] = np.inf

    def fill_points(self, buf: np.ndarray, depth: np.ndarray, rgb: np.ndarray | None) -> np.ndarray:
        """An organized cloud's points (H x W x fields float32) in the optical frame from a depth image (and
        colours), written into `buf` by blocks of rows that stay in the cache; NaN where no return."""
        h, w = depth.shape
        block = min(h, 32)
        if getattr(self, "_scratch", None) is None or self._scratch[0].shape != (block, w):
            self._scratch = (np.empty((block, w), np.float32), np.empty((block, w), bool))
        z_all, finite_all = self._scratch
        packed = buf.view(np.uint8).reshape(h, w, self.point_step)[..., 12:16] if rgb is not None else None
        nan = np.float32(np.nan)
        for r0 in range(0, h, block):
            r1 = min(h, r0 + block)
            d, z, finite, b = depth[r0:r1], z_all[: r1 - r0], finite_all[: r1 - r0], buf[r0:r1]
            np.isfinite(d, out=finite)
            z.fill(nan)
            np.copyto(z, d, where=finite)
            b[..., 2] = z
            np.multiply(self.ray_x, z, out=b[..., 0])
            np.multiply(self.ray_y[r0:r1], z, out=b[..., 1])
            if self.params.out_of_range == "inf" and not finite.all():
                # ROS 2 gazebo_ros_camera: x = y = z = -inf / +inf for a depth out of range
                # (gazebo_ros_camera.cpp:757-768); no return at all reads +inf there too
                infinite = np.isinf(d)
                b[infinite] = np.where(d[infinite] > 0, np.float32(np.inf), np.float32(-np.inf))[:, None]
            if packed is not None and rgb is not None:
                # float32 `rgb` holding 0x00RRGGBB, little-endian: bytes B, G, R, 0
                p = packed[r0:r1]
                p[..., :3] = rgb[r0:r1, :, ::-1]
                p[..., 3] = 0
        return buf

    def point_cloud(self, now_ns: int, depth: np.ndarray, rgb: np.ndarray | None) -> Any:
        """An organized cloud in the optical frame from a depth image (and colours), as a message."""
        h, w = depth.shape
        buf = self.fill_points(np.empty((h, w, self.point_step // 4), dtype=np.float32), depth, rgb)
        return self.PointCloud2(
            header=msgs.header(now_ns, self.frame_id),
            height=h,
            width=w,
            fields=self.fields,
            is_bigendian=False,
            point_step=self.point_step,
            row_step=self.point_step * w,
            data=buf.reshape(-1).view(np.uint8),
            is_dense=False,
        )
