"""gps: a satellite receiver -> sensor_msgs/NavSatFix and its velocity, geometry_msgs/Vector3Stamped.

The true position of a link (its origin, world frame) is turned into latitude, longitude and altitude around
a reference point, on a flat earth tangent to the WGS84 ellipsoid there (exactly as hector_gazebo_plugins'
GPS does; against an ellipsoidal conversion, such as Gazebo's GPS sensor makes, latitude and longitude agree
to millimetres within kilometres, the altitude stays d²/2R too high, 8 cm at 1 km): with φ0 the reference
latitude, e² = 2f - f² (f = 1/298.257223563), a = 6378137 m,

    N = a / sqrt(1 - e² sin²φ0)          (prime vertical radius)
    R_north = N (1 - e²) / (1 - e² sin²φ0),   R_east = N cos φ0
    latitude  = lat0 + north / R_north,   longitude = lon0 + east / R_east,   altitude = alt0 + z

where north and east come from the world x and y and `reference_heading`, the compass bearing of the world's
+x axis (degrees clockwise from north: 90, the default, is ROS's ENU, x east and y north; hector's default
is 0, x north and y west).

Errors, per world axis x, y, z and as hector's SensorModel: a constant `*_offset`, a drifting bias (started
at N(0, `*_drift`), then a Gauss-Markov process of `*_drift_frequency`, see plugins/_drift.py) and white
noise `*_noise_stddev`; the velocity's drift is integrated into the position's, as hector does. The
position covariance (diagonal, known) is drift² + noise² per axis. The velocity is published in east, north,
up (`velocity_axes: ENU`, as Gazebo's GPS sensor) or north, west, up (`NWU`, as hector's GPS).
"""

from __future__ import annotations

import math
from typing import Literal

import mujoco
import numpy as np
from pydantic import Field

from plugins._drift import DriftingBias
from runner.plugin import BuildContext, Plugin, RatedParams, Topic
from runner.wire import msgs

Vector3 = tuple[float, float, float]

# WGS84
_A = 6378137.0
_F = 1.0 / 298.257223563
_E2 = 2 * _F - _F * _F


class GpsParams(RatedParams):
    rate: float = Field(4.0, gt=0, description="Publish rate, sim Hz.")
    link: str | None = Field(None, description="Link of the antenna (default: the root link).")
    topic: str = Field("fix", description="NavSatFix topic, relative to the robot's namespace.")
    velocity_topic: str | None = Field(
        "fix_velocity", description="Vector3Stamped velocity topic (null: not published)."
    )
    frame_id: str | None = Field(None, description="Frame id in the headers (default: <ns>/<link>).")
    reference_latitude: float = Field(0.0, ge=-90, le=90, description="Latitude of the world origin, deg.")
    reference_longitude: float = Field(
        0.0, ge=-180, le=180, description="Longitude of the world origin, deg."
    )
    reference_altitude: float = Field(0.0, description="Altitude of the world origin, metres.")
    reference_heading: float = Field(
        90.0,
        description="Compass bearing of the world's +x axis, degrees clockwise from north (90: x east, "
        "y north; 0: x north, y west).",
    )
    velocity_axes: Literal["ENU", "NWU"] = Field(
        "ENU", description="Axes of the published velocity: east-north-up or north-west-up."
    )
    status: int = Field(0, ge=-2, le=127, description="NavSatStatus.status (0: STATUS_FIX).")
    service: int = Field(1, ge=0, le=65535, description="NavSatStatus.service bits (1: SERVICE_GPS).")
    position_offset: Vector3 = Field((0.0, 0.0, 0.0), description="Constant error, world x y z, metres.")
    position_drift: Vector3 = Field(
        (0.0, 0.0, 0.0), description="Scale of the drifting error per world axis, metres."
    )
    position_drift_frequency: Vector3 = Field(
        (1 / 3600, 1 / 3600, 1 / 3600), description="Frequency of the drift (1 / correlation time), Hz."
    )
    position_noise_stddev: Vector3 = Field((0.0, 0.0, 0.0), description="White noise per world axis, metres.")
    velocity_offset: Vector3 = Field((0.0, 0.0, 0.0), description="Constant error, world x y z, m/s.")
    velocity_drift: Vector3 = Field((0.0, 0.0, 0.0), description="Scale of the drifting error, m/s.")
    velocity_drift_frequency: Vector3 = Field(
        (1 / 3600, 1 / 3600, 1 / 3600), description="Frequency of the velocity drift, Hz."
    )
    velocity_noise_stddev: Vector3 = Field((0.0, 0.0, 0.0), description="White noise per world axis, m/s.")


def earth_radii(latitude_deg: float) -> tuple[float, float]:
    """(north, east) radii of curvature of the WGS84 ellipsoid at a latitude, metres per radian."""
    s = math.sin(math.radians(latitude_deg))
    k = 1.0 / (1.0 - _E2 * s * s)
    prime = _A * math.sqrt(k)
    return prime * (1 - _E2) * k, prime * math.cos(math.radians(latitude_deg))


class Gps(Plugin):
    Params = GpsParams
    params: GpsParams

    @classmethod
    def build(cls, params: GpsParams, ctx: BuildContext, name: str) -> list[Topic]:
        if params.link:
            ctx.body(params.link)
        topics = [Topic(params.topic, "sensor_msgs/msg/NavSatFix", "pub", params.rate)]
        if params.velocity_topic:
            topics.append(
                Topic(params.velocity_topic, "geometry_msgs/msg/Vector3Stamped", "pub", params.rate)
            )
        return topics

    def setup(self) -> None:
        p = self.params
        r = self.ctx.robot
        link = p.link or r.root_link
        self.body = r.body_id(link)
        self.frame_id = p.frame_id or r.frame(link)
        self.fix_pub = self.ctx.publisher(p.topic, "sensor_msgs/msg/NavSatFix")
        self.vel_pub = (
            self.ctx.publisher(p.velocity_topic, "geometry_msgs/msg/Vector3Stamped")
            if (p.velocity_topic)
            else None
        )
        self.r_north, self.r_east = earth_radii(p.reference_latitude)
        h = math.radians(p.reference_heading)
        self.cos_h, self.sin_h = math.cos(h), math.sin(h)
        rng, dt = self.ctx.rng, 1.0 / p.rate
        self.dt = dt
        self.rng = rng
        # hector draws each drift's start from N(0, drift) when it is (re)set
        self.pos_drift = DriftingBias(
            rng,
            _start(rng, p.position_drift),
            p.position_drift,
            p.position_drift_frequency,
            dt,
        )
        self.vel_drift = DriftingBias(
            rng,
            _start(rng, p.velocity_drift),
            p.velocity_drift,
            p.velocity_drift_frequency,
            dt,
        )
        self.pos_offset = np.array(p.position_offset)
        self.vel_offset = np.array(p.velocity_offset)
        self.pos_noise = np.array(p.position_noise_stddev)
        self.vel_noise = np.array(p.velocity_noise_stddev)
        self.noisy = bool(self.pos_noise.any() or self.vel_noise.any())
        cov = np.zeros(9)
        cov[[0, 4, 8]] = np.array(p.position_drift) ** 2 + self.pos_noise**2
        T = msgs.T
        self.fix = T["sensor_msgs/msg/NavSatFix"](
            header=msgs.header(0, self.frame_id),
            status=T["sensor_msgs/msg/NavSatStatus"](status=p.status, service=p.service),
            latitude=0.0,
            longitude=0.0,
            altitude=0.0,
            position_covariance=cov,
            position_covariance_type=2,  # COVARIANCE_TYPE_DIAGONAL_KNOWN
        )
        self.vel6 = np.zeros(6)

    def after_step(self, now_ns: int) -> None:
        m, d = self.ctx.model, self.ctx.data
        p = self.params
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, self.body, self.vel6, 0)  # link origin
        vel = self.vel6[3:].copy()
        pos = d.xpos[self.body].copy()
        # as hector: both errors are updated, then the velocity's drift is integrated into the position's
        pos_err = self.pos_offset + self.pos_drift.update()
        vel_err = self.vel_offset + self.vel_drift.update()
        if self.noisy:
            noise = self.rng.standard_normal(6)
            pos_err = pos_err + noise[:3] * self.pos_noise
            vel_err = vel_err + noise[3:] * self.vel_noise
        pos += pos_err
        vel += vel_err
        if self.vel_drift.on:
            self.pos_drift.value = self.pos_drift.value + self.dt * self.vel_drift.value
        x, y, z = pos.tolist()
        c, s = self.cos_h, self.sin_h
        north, east = c * x + s * y, s * x - c * y
        fix = self.fix
        fix.header = msgs.header(now_ns, self.frame_id)
        fix.latitude = p.reference_latitude + math.degrees(north / self.r_north)
        fix.longitude = p.reference_longitude + math.degrees(east / self.r_east)
        fix.altitude = p.reference_altitude + z
        self.fix_pub.publish(fix, now_ns)
        if self.vel_pub is not None:
            vx, vy, vz = vel.tolist()
            vn, ve = c * vx + s * vy, s * vx - c * vy
            a, b = (ve, vn) if p.velocity_axes == "ENU" else (vn, -ve)
            msg = msgs.T["geometry_msgs/msg/Vector3Stamped"](
                header=msgs.header(now_ns, self.frame_id),
                vector=msgs.T["geometry_msgs/msg/Vector3"](x=a, y=b, z=vz),
            )
            self.vel_pub.publish(msg, now_ns)


def _start(rng: np.random.Generator, drift: Vector3) -> np.ndarray:
    """A drift's starting value, N(0, drift) per axis (drawn only where asked for)."""
    sd = np.array(drift, dtype=float)
    return rng.normal(0.0, sd) if sd.any() else np.zeros(3)
