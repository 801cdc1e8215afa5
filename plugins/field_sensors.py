"""Gazebo's environment sensors, as gz-sensors computes them (and ros_gz_bridge hands them to ROS):

- `magnetometer` -> sensor_msgs/MagneticField: the world's magnetic field (`field`, tesla, in the world
  frame; SDF's default world `<magnetic_field>`) rotated into the sensor frame (gz-sensors
  MagnetometerSensor.cc:162-165), plus per-axis white noise and a constant mean (:174-196);
  As hector_gazebo_plugins' magnetometer (`libhector_gazebo_ros_magnetic.so`, gazebo_ros_magnetic.cpp:
  121-130, 167-173), the message may be a geometry_msgs/Vector3Stamped (`message`), and the error a drifting
  bias per axis (`drift`, `drift_frequency`: hector's SensorModel, plugins/_drift.py) on top of the
  constant `noise_mean` and the white noise;
- `air_pressure` -> sensor_msgs/FluidPressure: the pressure (Pa) of the standard atmosphere at the height
  `reference_altitude` + the sensor's world z, as gz-sensors AirPressureSensor.cc:165-182 (after RotorS:
  geopotential height, a linear temperature lapse from 288.15 K at sea level), plus white noise; the
  message's variance is what gz-sensors writes there, sqrt(stddev) (AirPressureSensor.cc:193-200);
- `altimeter` -> ros_gz_interfaces/msg/Altimeter (ros_gz_bridge's mapping of gz.msgs.Altimeter): the
  sensor's world z less its z at the start (`vertical_reference`; gz-sim Altimeter.cc:210-212, 265), its
  world vertical velocity (:266), each with white noise and a constant mean.

The sensors read MuJoCo's state at a site on `link` (at `pose`), after each step they run at.
"""

from __future__ import annotations

import math
from typing import Literal

import mujoco
import numpy as np
from pydantic import Field

from plugins._common import MountPose, add_site, pick_link
from plugins._drift import DriftingBias
from runner.plugin import BuildContext, Plugin, RatedParams, Topic
from runner.wire import msgs

Vector3 = tuple[float, float, float]

# SDF's default world <magnetic_field>, tesla, east-north-up (sdformat world.sdf)
SDF_MAGNETIC_FIELD: Vector3 = (5.5645e-6, 22.8758e-6, -42.3884e-6)

# the standard atmosphere of gz-sensors AirPressureSensor.cc:43-52 (from RotorS)
_R = 8314.32  # N m / (kmol K)
_M = 28.9644  # kg / kmol
_G = 9.80665
_EARTH_RADIUS = 6356766.0
_P0 = 101325.0
_T0 = 288.15
_LAPSE = 0.0065  # K / m
_EXPONENT = _G * _M / (_R * -_LAPSE)


def air_pressure(height: float) -> float:
    """The pressure (Pa) gz-sensors computes at `height` metres above sea level."""
    geo = _EARTH_RADIUS * height / (_EARTH_RADIUS + height)
    return _P0 * math.exp(_EXPONENT * math.log(_T0 / (_T0 - _LAPSE * geo)))


class _SiteParams(RatedParams):
    rate: float = Field(50.0, gt=0, description="Publish rate, sim Hz.")
    link: str | None = Field(None, description="Link of the sensor (default: the root link).")
    pose: MountPose = Field(default_factory=MountPose, description="Mount pose relative to the link.")
    frame_id: str | None = Field(None, description="Frame id in the header (default: <ns>/<link>).")


class _SiteSensor(Plugin):
    """A sensor at a site of its own: where it is, in the world."""

    link_hints: tuple[str, ...] = ()
    message: str = ""

    @classmethod
    def build(cls, params: _SiteParams, ctx: BuildContext, name: str) -> list[Topic]:  # type: ignore[override]
        add_site(ctx, pick_link(ctx, params.link, cls.link_hints), name, params.pose)
        return [Topic(params.topic, cls.message, "pub", params.rate)]  # type: ignore[attr-defined]

    def setup(self) -> None:
        r = self.ctx.robot
        self.site = r.site_id(f"{self.name}_site")
        link = self.ctx.model.body(int(self.ctx.model.site_bodyid[self.site])).name.removeprefix(r.prefix)
        self.frame_id = self.params.frame_id or r.frame(link)  # type: ignore[attr-defined]
        self.pub = self.ctx.publisher(self.params.topic, self.message)  # type: ignore[attr-defined]

    def _white(self, stddev: float, n: int | None = None) -> np.ndarray | float:
        if not stddev:
            return np.zeros(n) if n else 0.0
        return self.ctx.rng.normal(0.0, stddev, n) if n else float(self.ctx.rng.normal(0.0, stddev))


class MagnetometerParams(_SiteParams):
    topic: str = Field("magnetometer", description="Topic, relative to the robot's namespace.")
    field: Vector3 = Field(
        SDF_MAGNETIC_FIELD, description="The world's magnetic field, tesla, in the world frame (x east)."
    )
    noise_stddev: Vector3 = Field((0.0, 0.0, 0.0), description="White noise per sensor axis, tesla.")
    noise_mean: Vector3 = Field((0.0, 0.0, 0.0), description="Constant error per sensor axis, tesla.")
    drift: Vector3 = Field(
        (0.0, 0.0, 0.0),
        description="Scale of a drifting error per axis (from N(0, drift)), as hector's.",
    )
    drift_frequency: Vector3 = Field(
        (1 / 3600, 1 / 3600, 1 / 3600), description="Frequency of that drift per axis, Hz."
    )
    message: Literal["sensor_msgs/msg/MagneticField", "geometry_msgs/msg/Vector3Stamped"] = Field(
        "sensor_msgs/msg/MagneticField",
        description="The message type (hector's magnetometer publishes a Vector3Stamped by default).",
    )


class Magnetometer(_SiteSensor):
    Params = MagnetometerParams
    params: MagnetometerParams
    link_hints = ("mag", "magnetometer", "compass")
    message = "sensor_msgs/msg/MagneticField"

    @classmethod
    def build(cls, params: MagnetometerParams, ctx: BuildContext, name: str) -> list[Topic]:  # type: ignore[override]
        add_site(ctx, pick_link(ctx, params.link, cls.link_hints), name, params.pose)
        return [Topic(params.topic, params.message, "pub", params.rate)]

    def setup(self) -> None:
        self.message = self.params.message
        super().setup()
        p = self.params
        self.field = np.array(p.field, dtype=float)
        self.sd = np.array(p.noise_stddev, dtype=float)
        self.mean = np.array(p.noise_mean, dtype=float)
        rng = self.ctx.rng
        start = rng.normal(0.0, 1.0, 3) * np.array(p.drift) if any(p.drift) else np.zeros(3)
        self.bias = DriftingBias(rng, start, p.drift, p.drift_frequency, 1.0 / p.rate)

    def after_step(self, now_ns: int) -> None:
        rot = self.ctx.data.site_xmat[self.site].reshape(3, 3)
        local = rot.T @ self.field + self.mean  # MagnetometerSensor.cc:163-165: world -> sensor frame
        local = local + self.bias.update()  # hector's drifting error (constant when its frequency is 0)
        if self.sd.any():
            local = local + self.ctx.rng.normal(0.0, 1.0, 3) * self.sd
        T = msgs.T
        vec = T["geometry_msgs/msg/Vector3"](x=float(local[0]), y=float(local[1]), z=float(local[2]))
        header = msgs.header(now_ns, self.frame_id)
        if self.message == "geometry_msgs/msg/Vector3Stamped":
            msg = T[self.message](header=header, vector=vec)
        else:  # ros_gz_bridge and hector leave the covariance unset (all zero: unknown)
            msg = T[self.message](header=header, magnetic_field=vec, magnetic_field_covariance=np.zeros(9))
        self.pub.publish(msg, now_ns)


class AirPressureParams(_SiteParams):
    topic: str = Field("air_pressure", description="Topic, relative to the robot's namespace.")
    reference_altitude: float = Field(0.0, description="Altitude of the world's z = 0, metres.")
    noise_stddev: float = Field(0.0, ge=0, description="White noise, Pa.")
    noise_mean: float = Field(0.0, description="Constant error, Pa.")


class AirPressure(_SiteSensor):
    Params = AirPressureParams
    params: AirPressureParams
    link_hints = ("baro", "pressure", "air")
    message = "sensor_msgs/msg/FluidPressure"

    def after_step(self, now_ns: int) -> None:
        p = self.params
        z = float(self.ctx.data.site_xpos[self.site][2])
        pressure = air_pressure(p.reference_altitude + z)
        variance = 0.0
        if p.noise_stddev or p.noise_mean:
            pressure += p.noise_mean + float(self._white(p.noise_stddev))
            variance = math.sqrt(p.noise_stddev)  # as gz-sensors writes it (AirPressureSensor.cc:199)
        self.pub.publish(
            msgs.T[self.message](
                header=msgs.header(now_ns, self.frame_id), fluid_pressure=pressure, variance=variance
            ),
            now_ns,
        )


class AltimeterParams(_SiteParams):
    topic: str = Field("altimeter", description="Topic, relative to the robot's namespace.")
    position_noise_stddev: float = Field(0.0, ge=0, description="White noise on the position, metres.")
    position_noise_mean: float = Field(0.0, description="Constant error of the position, metres.")
    velocity_noise_stddev: float = Field(0.0, ge=0, description="White noise on the velocity, m/s.")
    velocity_noise_mean: float = Field(0.0, description="Constant error of the velocity, m/s.")


class Altimeter(_SiteSensor):
    Params = AltimeterParams
    params: AltimeterParams
    link_hints = ("alti", "baro")
    message = "ros_gz_interfaces/msg/Altimeter"

    def setup(self) -> None:
        super().setup()
        # the sensor's world z where it starts (gz-sim Altimeter.cc:210-212: at the sensor's creation)
        self.reference = float(self.ctx.data.site_xpos[self.site][2])
        self.vel = np.zeros(6)

    def after_step(self, now_ns: int) -> None:
        p = self.params
        m, d = self.ctx.model, self.ctx.data
        z = float(d.site_xpos[self.site][2])
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_SITE, self.site, self.vel, 0)
        position = z - self.reference + p.position_noise_mean + float(self._white(p.position_noise_stddev))
        velocity = float(self.vel[5]) + p.velocity_noise_mean + float(self._white(p.velocity_noise_stddev))
        self.pub.publish(
            msgs.T[self.message](
                header=msgs.header(now_ns, self.frame_id),
                vertical_position=position,
                vertical_velocity=velocity,
                vertical_reference=self.reference,
            ),
            now_ns,
        )
