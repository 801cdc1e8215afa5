"""lidar: a planar laser scanner -> sensor_msgs/LaserScan, ray-cast with `mujoco.mj_multiRay`.

Like Gazebo's ray sensor: `samples` beams from `min_angle` to `max_angle` (inclusive), returns outside
`[range_min, range_max]` are +inf (no return) or -inf (too close), gaussian noise, optional range
resolution. The robot's own geoms and visual-only geoms are never hit.

A 3D lidar (or any, with `publish_points`) also publishes a PointCloud2 in the sensor frame, in one of two
layouts: `xyz` (x, y, z float32, one row per elevation) or `velodyne`, as velodyne_simulator's Gazebo plugin
and the velodyne driver publish it: x, y, z, intensity (float32), ring (uint16, 0 = lowest beam), time
(float32), 22 bytes a point, the rings of one azimuth after another; intensity and time are 0 (surfaces
have no retro-reflectivity here, and a scan is one instant). `organize_cloud` keeps every beam (NaN where
there is no return; `xyz` does by default) or only the returns (`velodyne` does by default).
`publish_scan: false` leaves the LaserScan out (velodyne_simulator publishes only the cloud).

`range_topic` publishes a sensor_msgs/Range, the nearest return of all beams, as one of three Gazebo
plugins computes it (`range_style`):

- `hector` (hector_gazebo_plugins' sonar): `range_max` when nothing is hit; else the nearest return with
  its own error (`range_offset`, a drifting bias `range_drift`, white noise `range_noise_stddev`, see
  plugins/_drift.py), clamped to `[range_min, range_max]`;
- `gazebo_ros_range` (gazebo_plugins' ROS 1 `libgazebo_ros_range.so`, gazebo_ros_range.cpp:302-316): the
  nearest *noise-free* ray (it reads the ray shape, not the sensor's noisy scan), `range_max` when nothing is
  hit; else plus N(0, `range_noise_stddev`), capped at `range_max` only (noise may take it below
  `range_min`);
- `gazebo_ros_ray_sensor` (gazebo_plugins' ROS 2 `<output_type>sensor_msgs/Range`, conversions/
  sensor_msgs.hpp:291-316): the nearest of the sensor's published ranges, each masked as Gazebo's ray
  sensor does (REP 117: +inf beyond `range_max`, -inf at or below `range_min`, else with the sensor's noise,
  clamped to the limits), so +inf when nothing is within range.

`noise_stddev`, `resolution` and `blind_sectors` may change while it runs (an event's `set:`): a sector
blinded by an event (mud on the window, a failed emitter) returns +inf on every beam whose azimuth lies in
it, in the scan, the cloud (NaN) and the Range alike.
"""

from __future__ import annotations

import math
import struct
from typing import Literal

import mujoco
import numpy as np
from pydantic import Field, PositiveFloat, PositiveInt, model_validator

from plugins._common import MountPose, add_site, pick_link
from plugins._drift import DriftingBias
from runner.plugin import PIECES_GROUP, RAY_GROUP, BuildContext, Plugin, RatedParams, Topic
from runner.wire import msgs

_EPS = 1e-4
_HIDDEN_GROUP = 1  # the geom group rays skip (URDF visuals live there already)
# Beams of one scan (samples x vertical_samples), at most: each costs ~100 bytes and a ray cast per scan.
MAX_BEAMS = 1_000_000


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
    blind_sectors: list[tuple[float, float]] = Field(
        default_factory=list,
        description="Azimuth sectors [from, to] (radians, the beams' own angles, from <= to) where every "
        "beam returns nothing (+inf): a blinded part of the scanner.",
    )
    vertical_samples: PositiveInt = Field(
        1, description="Beams per column; more than 1 makes a 3D lidar that also publishes a PointCloud2."
    )
    vertical_min_angle: float = Field(0.0, ge=-math.pi / 2, le=math.pi / 2, description="Lowest beam, rad.")
    vertical_max_angle: float = Field(0.0, ge=-math.pi / 2, le=math.pi / 2, description="Highest beam, rad.")
    points_topic: str | None = Field(
        None, description="PointCloud2 topic of a 3D lidar (default: <topic>/points)."
    )
    publish_scan: bool = Field(True, description="Publish the LaserScan (the row closest to horizontal).")
    publish_points: bool | None = Field(
        None, description="Publish the PointCloud2 (default: when vertical_samples > 1)."
    )
    points_format: Literal["xyz", "velodyne"] = Field(
        "xyz",
        description="PointCloud2 fields: x y z (float32), or velodyne_simulator's x y z intensity "
        "(float32) ring (uint16) time (float32).",
    )
    range_topic: str | None = Field(
        None, description="Also publish a sensor_msgs/Range here: the nearest return of all beams."
    )
    radiation_type: Literal["ultrasound", "infrared"] = Field("ultrasound", description="Range's radiation.")
    range_field_of_view: float = Field(0.0, ge=0, description="Range's field_of_view, rad.")
    range_offset: float = Field(0.0, description="Constant error of the Range, metres.")
    range_drift: float = Field(
        0.0, ge=0, description="Scale of the Range's drifting error (starts at N(0, drift)), metres."
    )
    range_drift_frequency: float = Field(1 / 3600, ge=0, description="Frequency of that drift, Hz.")
    range_noise_stddev: float = Field(0.0, ge=0, description="White noise on the Range, metres.")
    range_style: Literal["hector", "gazebo_ros_range", "gazebo_ros_ray_sensor"] = Field(
        "hector",
        description="How the Range is made of the rays, as which Gazebo plugin does it (see the module doc).",
    )
    organize_cloud: bool | None = Field(
        None,
        description="Keep every beam in the cloud, NaN where there is no return (true), or only the "
        "returns, one row (false). Default: true for xyz, false for velodyne (as velodyne_simulator).",
    )

    @model_validator(mode="after")
    def _angles(self) -> LidarParams:
        beams = self.samples * self.vertical_samples
        if beams > MAX_BEAMS:
            # 10^8 beams passed `validate` and ended the world in a MemoryError traceback at 3.2 GB (the
            # beams' directions alone are 2.4 GB)
            raise ValueError(
                f"{self.samples} x {self.vertical_samples} = {beams:,} beams per scan, more than "
                f"{MAX_BEAMS:,} (a 128-channel lidar has 128 x 2048 = 262,144)"
            )
        if self.max_angle < self.min_angle:
            raise ValueError(
                f"max_angle ({self.max_angle}) is below min_angle ({self.min_angle}): "
                "write the smaller angle as min_angle (radians, e.g. min_angle: -3.14, max_angle: 3.14)"
            )
        if self.range_max <= self.range_min:
            raise ValueError(f"range_max ({self.range_max}) must exceed range_min ({self.range_min})")
        for a, b in self.blind_sectors:
            if b < a:
                raise ValueError(
                    f"a blind sector goes from the smaller angle to the larger, found [{a}, {b}]"
                )
        if self.vertical_max_angle < self.vertical_min_angle:
            raise ValueError("vertical_max_angle is below vertical_min_angle")
        if not self.publish_scan and not self.points and not self.range_topic:
            raise ValueError(
                "publish_scan is false and neither a PointCloud2 nor a Range is published: the lidar "
                "publishes nothing"
            )
        return self

    @property
    def points(self) -> bool:
        """Whether the PointCloud2 is published."""
        return self.vertical_samples > 1 if self.publish_points is None else self.publish_points

    @property
    def organized(self) -> bool:
        return self.points_format == "xyz" if self.organize_cloud is None else self.organize_cloud


class Lidar(Plugin):
    Params = LidarParams
    params: LidarParams
    live = frozenset({"noise_stddev", "resolution", "blind_sectors"})

    @classmethod
    def build(cls, params: LidarParams, ctx: BuildContext, name: str) -> list[Topic]:
        link = pick_link(ctx, params.link, ("lidar", "laser", "scan"))
        add_site(ctx, link, name, params.pose)
        topics = []
        if params.publish_scan:
            topics.append(Topic(params.topic, "sensor_msgs/msg/LaserScan", "pub", params.rate))
        if params.points:
            points = params.points_topic or f"{params.topic}/points"
            topics.append(Topic(points, "sensor_msgs/msg/PointCloud2", "pub", params.rate))
        if params.range_topic:
            topics.append(Topic(params.range_topic, "sensor_msgs/msg/Range", "pub", params.rate))
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
        if p.points:
            self._setup_points()
        self._geom_tables()
        self.vec = np.zeros((n * nv, 3))
        self._blind_of: list[tuple[float, float]] | None = None  # the sectors `self.blind` was made for
        self.blind = np.zeros(n * nv, dtype=bool)
        if p.publish_scan:
            self._setup_scan()
        if p.range_topic:
            self._setup_range()

    def rebind(self) -> None:
        self._geom_tables()  # (per geom of the world: a spawned robot's geoms come after the old ends)

    def _geom_tables(self) -> None:
        ctx, m = self.ctx, self.ctx.model
        # Rays skip the robot's own geoms and visual-only geoms (URDF visuals are group 1, no contacts).
        skip = np.zeros(m.ngeom, dtype=bool)
        skip[ctx.robot.geom_ids] = True
        # ... but a world mesh split into convex pieces to collide is hit on its own faces (RAY_GROUP), never
        # on its pieces (PIECES_GROUP, left out of the rays' groups)
        skip |= (m.geom_contype == 0) & (m.geom_conaffinity == 0) & (m.geom_group != RAY_GROUP)
        self.skip = skip
        self.own = np.asarray(ctx.robot.geom_ids, dtype=np.int64)
        self.own_groups = m.geom_group[self.own].copy()
        self.geomgroup = np.array([1, 0, 1, 1, 1, 1], dtype=np.uint8)
        self.geomgroup[PIECES_GROUP] = 0
        self.geom_group = m.geom_group  # a view, looked up once
        # Rays may stop on a geom they should pass (a visual-only geom outside the hidden group) only if
        # the world has one: otherwise the per-scan check for it is skipped.
        visible = m.geom_group != _HIDDEN_GROUP
        visible[self.own] = False
        self.may_recast = bool((skip & visible).any())

    def _setup_scan(self) -> None:
        p = self.params
        self.pub = self.ctx.publisher(p.topic, "sensor_msgs/msg/LaserScan")
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

    def _setup_points(self) -> None:
        p = self.params
        self.points_pub = self.ctx.publisher(
            p.points_topic or f"{p.topic}/points", "sensor_msgs/msg/PointCloud2"
        )
        field = msgs.T["sensor_msgs/msg/PointField"]
        self.PointCloud2 = msgs.T["sensor_msgs/msg/PointCloud2"]
        n, nv = p.samples, p.vertical_samples
        if p.points_format == "xyz":
            self.fields = [field(name=c, offset=4 * i, datatype=7, count=1) for i, c in enumerate("xyz")]
            self.point_dtype = np.dtype({"names": list("xyz"), "formats": ["<f4"] * 3})
            # one row per elevation, as the rays are cast
            self.order = np.arange(n * nv)
            self.cloud_shape = (nv, n)
        else:
            self.fields = [
                field(name=name, offset=offset, datatype=datatype, count=1)
                for name, offset, datatype in _VELODYNE_FIELDS
            ]
            self.point_dtype = _VELODYNE_POINT
            # all rings of the first azimuth, then of the next... (the rays are cast row by row)
            self.order = np.arange(n * nv).reshape(nv, n).T.ravel()
            self.cloud_shape = (n, nv)
        self.cloud = np.zeros(n * nv, dtype=self.point_dtype)
        if p.points_format == "velodyne":
            self.cloud["ring"] = np.tile(np.arange(nv, dtype=np.uint16), n)
        self.local_ordered = self.local[:, self.order]

    def _setup_range(self) -> None:
        p = self.params
        rng = self.ctx.rng
        self.range_pub = self.ctx.publisher(p.range_topic, "sensor_msgs/msg/Range")
        template = msgs.T["sensor_msgs/msg/Range"](
            header=msgs.header(0, self.frame_id),
            radiation_type=0 if p.radiation_type == "ultrasound" else 1,
            field_of_view=p.range_field_of_view,
            min_range=p.range_min,
            max_range=p.range_max,
            range=p.range_max,
            variance=0.0,  # Jazzy's field: 0 is unknown, as the plugins publishing Range leave it
        )
        self.range_layout = self.range_pub.layout(template, ["header.stamp"])
        self.at_range = self.range_layout.spans["range"].offset
        start = [rng.normal(0.0, p.range_drift)] if p.range_drift else [0.0]
        self.range_bias = DriftingBias(rng, start, p.range_drift, p.range_drift_frequency, 1.0 / p.rate)

    def _range_rays(self, raw: np.ndarray, noisy: np.ndarray) -> np.ndarray:
        """The rays the Range is the minimum of, for the gazebo_ros styles (`raw`: noise-free distances)."""
        p = self.params
        if p.blind_sectors:
            raw[self._blind_mask(p.blind_sectors)] = np.inf
        if p.range_style == "gazebo_ros_range":
            return raw  # LaserShape()->GetRange(i): the ray shape's own, noise-free lengths
        # the ray sensor's scan (gazebo RaySensor::UpdateImpl): masked by the raw range, noisy within it
        out = np.clip(noisy, p.range_min, p.range_max)
        out[raw >= p.range_max] = np.inf
        out[raw <= p.range_min] = -np.inf
        return out

    def _publish_range(self, ranges: np.ndarray, now_ns: int) -> None:
        """The nearest return, as `range_style` says (see the module doc)."""
        p = self.params
        r = float(ranges.min()) if len(ranges) else math.inf
        if p.range_style == "gazebo_ros_ray_sensor":
            pass  # the nearest masked ray as it is: +inf when nothing is within range_max
        elif p.range_style == "gazebo_ros_range":
            if r < p.range_max:  # gazebo_ros_range.cpp:315-316
                if p.range_noise_stddev:
                    r += float(self.ctx.rng.normal(0.0, p.range_noise_stddev))
                r = min(r, p.range_max)
            else:
                r = p.range_max
        elif r < p.range_max:
            r += p.range_offset + float(self.range_bias.update()[0])
            if p.range_noise_stddev:
                r += float(self.ctx.rng.normal(0.0, p.range_noise_stddev))
            r = min(max(r, p.range_min), p.range_max)
        else:
            r = p.range_max
        struct.pack_into("<f", self.range_layout.buf, self.at_range, r)
        self.range_pub.publish_cdr(self.range_layout.encode(now_ns), now_ns)

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
        raw = every.copy() if p.range_topic and p.range_style != "hector" else None
        if p.noise_stddev > 0:
            noise = self.ctx.rng.standard_normal(len(every))
            noise *= p.noise_stddev
            every += noise
        if p.resolution > 0:
            every /= p.resolution
            np.round(every, out=every)
            every *= p.resolution
        if p.blind_sectors:
            every[self._blind_mask(p.blind_sectors)] = np.inf
        n = p.samples
        if p.points:
            self._publish_points(every, now_ns)
        if p.range_topic:
            self._publish_range(every if raw is None else self._range_rays(raw, every), now_ns)
        if not p.publish_scan:
            return
        out = self.out_ranges  # float32 view into the message bytes
        out[:] = every[self.scan_row * n : (self.scan_row + 1) * n]
        out[out > p.range_max] = np.inf  # REP 117: beyond range +inf, too close -inf
        out[out < p.range_min] = -np.inf
        self.pub.publish_cdr(self.layout.encode(now_ns), now_ns)

    def _blind_mask(self, sectors: list[tuple[float, float]]) -> np.ndarray:
        """The beams (every row) whose azimuth lies in a blind sector; made again only when the sectors
        change (an event swaps in new parameters)."""
        if sectors is not self._blind_of:
            az = np.zeros(len(self.angles), dtype=bool)
            for a, b in sectors:
                az |= (self.angles >= a) & (self.angles <= b)
            self.blind = np.tile(az, len(self.elevations))
            self._blind_of = sectors
        return self.blind

    def _publish_points(self, ranges: np.ndarray, now_ns: int) -> None:
        """The PointCloud2 in the sensor frame (`points_format`, `organize_cloud`: see the module doc)."""
        p = self.params
        r = ranges[self.order]
        valid = np.isfinite(r) & (r >= p.range_min) & (r <= p.range_max)
        r = np.where(valid, r, np.nan)
        xyz = (self.local_ordered * r).astype(np.float32)  # 3 x points
        cloud = self.cloud
        cloud["x"], cloud["y"], cloud["z"] = xyz
        if p.points_format == "velodyne":
            cloud["intensity"] = np.where(valid, np.float32(0.0), np.float32(np.nan))
        if p.organized:
            height, width = self.cloud_shape
            data = cloud
        else:
            data = cloud[valid]
            height, width = 1, len(data)
        step = self.point_dtype.itemsize
        msg = self.PointCloud2(
            header=msgs.header(now_ns, self.frame_id),
            height=height,
            width=width,
            fields=self.fields,
            is_bigendian=False,
            point_step=step,
            row_step=step * width,
            data=np.frombuffer(data.tobytes(), dtype=np.uint8),
            is_dense=bool(valid.all()) or not p.organized,
        )
        self.points_pub.publish(msg, now_ns)


# velodyne_simulator's point (as velodyne_pointcloud's): name, byte offset, PointField datatype
_VELODYNE_FIELDS = (
    ("x", 0, 7),
    ("y", 4, 7),
    ("z", 8, 7),
    ("intensity", 12, 7),
    ("ring", 16, 4),
    ("time", 18, 7),
)
_VELODYNE_POINT = np.dtype(
    {
        "names": [f[0] for f in _VELODYNE_FIELDS],
        "formats": ["<f4", "<f4", "<f4", "<f4", "<u2", "<f4"],
        "offsets": [f[1] for f in _VELODYNE_FIELDS],
        "itemsize": 22,
    }
)
