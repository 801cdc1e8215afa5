"""lidar: a planar laser scanner -> sensor_msgs/LaserScan, ray-cast with `mujoco.mj_multiRay`.

Like Gazebo's ray sensor: `samples` beams from `min_angle` to `max_angle` (inclusive), returns outside
`[range_min, range_max]` are +inf (no return) or -inf (too close), gaussian noise, optional range
resolution. The robot's own geoms and visual-only geoms are never hit.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
from pydantic import Field, PositiveFloat, PositiveInt, model_validator

from plugins._common import MountPose, add_site, pick_link
from runner import msgs
from runner.plugin import BuildContext, Plugin, RatedParams, Topic

_EPS = 1e-4
_HIDDEN_GROUP = 1  # the geom group rays skip (URDF visuals live there already)


class LidarParams(RatedParams):
    link: str | None = Field(
        None, description="Link the scanner is mounted on (default: a link named like lidar/laser/scan)."
    )
    pose: MountPose = Field(default_factory=MountPose, description="Mount pose relative to the link.")
    topic: str = Field("scan", description="Topic, relative to the robot's namespace.")
    frame_id: str | None = Field(None, description="Frame id in the header (default: <ns>/<link>).")
    samples: PositiveInt = Field(360, description="Beams per scan.")
    min_angle: float = Field(-math.pi, ge=-7.0, le=7.0, description="First beam angle, rad.")
    max_angle: float = Field(math.pi, ge=-7.0, le=7.0, description="Last beam angle, rad.")
    range_min: float = Field(0.12, ge=0, description="Closest valid return, metres.")
    range_max: PositiveFloat = Field(12.0, description="Farthest valid return, metres.")
    resolution: float = Field(0.0, ge=0, description="Range quantization step, metres (0: none).")
    noise_stddev: float = Field(0.0, ge=0, description="Gaussian noise on each range, metres.")
    vertical_samples: PositiveInt = Field(
        1, description="Beams per column; more than 1 makes a 3D lidar that also publishes a PointCloud2."
    )
    vertical_min_angle: float = Field(0.0, ge=-math.pi / 2, le=math.pi / 2, description="Lowest beam, rad.")
    vertical_max_angle: float = Field(0.0, ge=-math.pi / 2, le=math.pi / 2, description="Highest beam, rad.")
    points_topic: str | None = Field(
        None, description="PointCloud2 topic of a 3D lidar (default: <topic>/points)."
    )

    @model_validator(mode="after")
    def _angles(self) -> LidarParams:
        if self.max_angle < self.min_angle:
            raise ValueError(f"max_angle ({self.max_angle}) is below min_angle ({self.min_angle})")
        if self.range_max <= self.range_min:
            raise ValueError(f"range_max ({self.range_max}) must exceed range_min ({self.range_min})")
        if self.vertical_max_angle < self.vertical_min_angle:
            raise ValueError("vertical_max_angle is below vertical_min_angle")
        return self


class Lidar(Plugin):
    Params = LidarParams
    params: LidarParams

    @classmethod
    def build(cls, params: LidarParams, ctx: BuildContext, name: str) -> list[Topic]:
        link = pick_link(ctx, params.link, ("lidar", "laser", "scan"))
        add_site(ctx, link, name, params.pose)
        topics = [Topic(params.topic, "sensor_msgs/msg/LaserScan", "pub", params.rate)]
        if params.vertical_samples > 1:
            points = params.points_topic or f"{params.topic}/points"
            topics.append(Topic(points, "sensor_msgs/msg/PointCloud2", "pub", params.rate))
        return topics

    def setup(self) -> None:
        p = self.params
        ctx = self.ctx
        m = ctx.model
        self.site = ctx.robot.site_id(f"{self.name}_site")
        self.body = int(m.site_bodyid[self.site])
        link = m.body(self.body).name.removeprefix(ctx.robot.prefix)
        self.frame_id = p.frame_id or ctx.robot.frame(link)
        n = p.samples
        self.angles = np.linspace(p.min_angle, p.max_angle, n) if n > 1 else np.array([p.min_angle])
        self.increment = float(self.angles[1] - self.angles[0]) if n > 1 else 0.0
        nv = p.vertical_samples
        self.elevations = (
            np.linspace(p.vertical_min_angle, p.vertical_max_angle, nv) if nv > 1 else np.array([0.0])
        )
        # Rays row by row (one row per elevation), the scan row is the one closest to horizontal.
        el, az = np.meshgrid(self.elevations, self.angles, indexing="ij")
        self.local = np.stack(
            [(np.cos(el) * np.cos(az)).ravel(), (np.cos(el) * np.sin(az)).ravel(), np.sin(el).ravel()]
        )  # 3 x (nv*n)
        self.scan_row = int(np.argmin(np.abs(self.elevations)))
        self.geomid = np.zeros(n * nv, dtype=np.int32)
        self.dist = np.zeros(n * nv, dtype=np.float64)
        if nv > 1:
            self.points_pub = ctx.publisher(
                p.points_topic or f"{p.topic}/points", "sensor_msgs/msg/PointCloud2"
            )
            field = msgs.T["sensor_msgs/msg/PointField"]
            self.fields = [field(name=c, offset=4 * i, datatype=7, count=1) for i, c in enumerate("xyz")]
            self.PointCloud2 = msgs.T["sensor_msgs/msg/PointCloud2"]
        # Rays skip the robot's own geoms and visual-only geoms (URDF visuals are group 1, no contacts).
        skip = np.zeros(m.ngeom, dtype=bool)
        skip[ctx.robot.geom_ids] = True
        skip |= (m.geom_contype == 0) & (m.geom_conaffinity == 0)
        self.skip = skip
        self.own = np.asarray(ctx.robot.geom_ids, dtype=np.int64)
        self.own_groups = m.geom_group[self.own].copy()
        self.geomgroup = np.array([1, 0, 1, 1, 1, 1], dtype=np.uint8)
        self.geom_group = m.geom_group  # a view, looked up once
        # Rays may stop on a geom they should pass (a visual-only geom outside the hidden group) only if
        # the world has one: otherwise the per-scan check for it is skipped.
        visible = m.geom_group != _HIDDEN_GROUP
        visible[self.own] = False
        self.may_recast = bool((skip & visible).any())
        self.vec = np.zeros((n * nv, 3))
        self.pub = ctx.publisher(p.topic, "sensor_msgs/msg/LaserScan")
        template = msgs.T["sensor_msgs/msg/LaserScan"](
            header=msgs.header(0, self.frame_id),
            angle_min=p.min_angle,
            angle_max=p.max_angle,
            angle_increment=self.increment,
            time_increment=0.0,
            scan_time=1.0 / p.rate,
            range_min=p.range_min,
            range_max=p.range_max,
            ranges=np.zeros(p.samples, dtype=np.float32),
            intensities=np.zeros(0, dtype=np.float32),
        )
        self.layout = self.pub.layout(template, ["header.stamp"])
        self.out_ranges = self.layout.view("ranges")

    def scan(self) -> np.ndarray:
        """Distances along each beam (inf where nothing is hit within range_max)."""
        m, d = self.ctx.model, self.ctx.data
        p = self.params
        origin = d.site_xpos[self.site].copy()
        rot = d.site_xmat[self.site].reshape(3, 3)
        vec = self.vec  # n x 3, world frame
        np.dot(self.local.T, rot.T, out=vec)
        # The robot's own geoms go to an excluded group for this one call, so rays pass through them in C
        # instead of being re-cast one by one in Python (a 3D lidar sees its own chassis a lot).
        self.geom_group[self.own] = _HIDDEN_GROUP
        try:
            mujoco.mj_multiRay(
                m,
                d,
                origin,
                vec.reshape(-1),
                self.geomgroup,
                1,
                self.body,
                self.geomid,
                self.dist,
                None,
                len(self.dist),
                p.range_max,
            )
        finally:
            self.geom_group[self.own] = self.own_groups
        dist = self.dist.copy()
        redo = (
            np.nonzero((self.geomid >= 0) & self.skip[np.maximum(self.geomid, 0)])[0]
            if self.may_recast
            else ()
        )
        if len(redo):
            gid = np.zeros(1, dtype=np.int32)
            for i in redo:
                travelled = float(dist[i])
                while True:
                    start = origin + vec[i] * (travelled + _EPS)
                    dd = mujoco.mj_ray(m, d, start, vec[i], self.geomgroup, 1, self.body, gid)
                    if dd < 0:
                        dist[i] = -1.0
                        break
                    travelled += dd + _EPS
                    if not self.skip[gid[0]]:
                        dist[i] = travelled
                        break
        dist[dist < 0] = np.inf
        return dist

    def after_step(self, now_ns: int) -> None:
        p = self.params
        every = self.scan()  # inf where nothing is hit: noise and rounding leave those inf
        if p.noise_stddev > 0:
            noise = self.ctx.rng.standard_normal(len(every))
            noise *= p.noise_stddev
            every += noise
        if p.resolution > 0:
            every /= p.resolution
            np.round(every, out=every)
            every *= p.resolution
        n = p.samples
        if p.vertical_samples > 1:
            self._publish_points(every, now_ns)
        out = self.out_ranges  # float32 view into the message bytes
        out[:] = every[self.scan_row * n : (self.scan_row + 1) * n]
        out[out > p.range_max] = np.inf  # REP 117: beyond range +inf, too close -inf
        out[out < p.range_min] = -np.inf
        self.pub.publish_cdr(self.layout.encode(now_ns), now_ns)

    def _publish_points(self, ranges: np.ndarray, now_ns: int) -> None:
        """A PointCloud2 (x, y, z float32, sensor frame, one row per elevation); NaN where no return."""
        p = self.params
        valid = np.isfinite(ranges) & (ranges >= p.range_min) & (ranges <= p.range_max)
        r = np.where(valid, ranges, np.nan)
        xyz = (self.local * r).T.astype(np.float32)  # (nv*n) x 3
        n, nv = p.samples, p.vertical_samples
        msg = self.PointCloud2(
            header=msgs.header(now_ns, self.frame_id),
            height=nv,
            width=n,
            fields=self.fields,
            is_bigendian=False,
            point_step=12,
            row_step=12 * n,
            data=np.frombuffer(xyz.tobytes(), dtype=np.uint8),
            is_dense=bool(valid.all()),
        )
        self.points_pub.publish(msg, now_ns)
