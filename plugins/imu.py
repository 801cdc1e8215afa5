"""imu: orientation, angular velocity and linear acceleration -> sensor_msgs/Imu.

Uses MuJoCo's own sensors on a site at the IMU link (gyro, accelerometer, framequat). As on a real IMU
and in Gazebo, linear acceleration includes the reaction to gravity (+9.81 m/s² up at rest).

Errors, per axis in the IMU frame: a constant bias (`*_bias`, plus a random part drawn once at setup with
the plugin's seeded generator, so a run is repeatable) and white Gaussian noise (`*_stddev`, drawn at every
message). The random part is Gazebo's IMU noise bias: drawn from N(`*_bias_mean`, `*_bias_stddev`) and, where
`*_bias_mean` is not zero, negated with probability 1/2 (SDF `<bias_mean>`, `<bias_stddev>`). The covariances
in the message are those of the white noise.

As hector_gazebo_plugins' IMU does: with `*_bias_drift_frequency`, the random part of a bias is not constant
but drifts (see plugins/_drift.py); `yaw_bias` (+ a random part, which may drift too) turns the reported
orientation about the vertical, and `orientation_tilt_from_bias` tilts it as an AHRS levelling with the
biased accelerometer would (roll and pitch of the accelerometer bias over gravity); `bias_topic` publishes
the current biases as a sensor_msgs/Imu (rates, accelerations, and the orientation error as a quaternion).
"""

from __future__ import annotations

import struct

import mujoco
import numpy as np
from pydantic import Field

from plugins._actuators import Lifecycle
from plugins._common import MountPose, add_site, pick_link
from plugins._drift import DriftingBias
from runner.plugin import BuildContext, Plugin, Publisher, RatedParams, Topic
from runner.wire import msgs

Vector3 = tuple[float, float, float]


class ImuParams(RatedParams):
    rate: float = Field(100.0, gt=0, description="Publish rate, sim Hz.")
    link: str | None = Field(
        None, description="Link of the IMU (default: a link named like imu, else the root)."
    )
    pose: MountPose = Field(default_factory=MountPose, description="Mount pose relative to the link.")
    topic: str = Field("imu", description="Topic, relative to the robot's namespace.")
    frame_id: str | None = Field(None, description="Frame id in the header (default: <ns>/<link>).")
    angular_velocity_stddev: float = Field(0.0, ge=0, description="Gaussian noise, rad/s.")
    linear_acceleration_stddev: float = Field(0.0, ge=0, description="Gaussian noise, m/s².")
    orientation_stddev: float = Field(0.0, ge=0, description="Gaussian noise on roll/pitch/yaw, rad.")
    angular_velocity_bias: Vector3 = Field((0.0, 0.0, 0.0), description="Constant bias per axis, rad/s.")
    linear_acceleration_bias: Vector3 = Field((0.0, 0.0, 0.0), description="Constant bias per axis, m/s².")
    angular_velocity_bias_stddev: float = Field(
        0.0, ge=0, description="Random bias per axis, drawn once at start (Gaussian), rad/s."
    )
    linear_acceleration_bias_stddev: float = Field(
        0.0, ge=0, description="Random bias per axis, drawn once at start (Gaussian), m/s²."
    )
    angular_velocity_bias_mean: Vector3 = Field(
        (0.0, 0.0, 0.0),
        description="Mean of the random bias per axis, rad/s; its sign is drawn at start (+ or -, as "
        "Gazebo's <bias_mean>).",
    )
    linear_acceleration_bias_mean: Vector3 = Field(
        (0.0, 0.0, 0.0),
        description="Mean of the random bias per axis, m/s²; its sign is drawn at start (+ or -, as "
        "Gazebo's <bias_mean>).",
    )
    angular_velocity_bias_drift_frequency: float = Field(
        0.0,
        ge=0,
        description="The random gyro bias drifts as a Gauss-Markov process of this frequency (Hz, 1 / "
        "correlation time) and scale `angular_velocity_bias_stddev`, as hector's IMU (0: constant).",
    )
    linear_acceleration_bias_drift_frequency: float = Field(
        0.0,
        ge=0,
        description="The random accelerometer bias drifts likewise, scale `linear_acceleration_bias_stddev`.",
    )
    yaw_bias: float = Field(0.0, description="Constant heading error of the orientation, rad.")
    yaw_bias_stddev: float = Field(
        0.0, ge=0, description="Random heading error, drawn once at start (Gaussian), rad."
    )
    yaw_bias_drift_frequency: float = Field(
        0.0, ge=0, description="The random heading error drifts likewise, scale `yaw_bias_stddev` (Hz)."
    )
    orientation_tilt_from_bias: bool = Field(
        False,
        description="Tilt the orientation by the accelerometer bias (roll and pitch of bias / gravity), as "
        "an AHRS levelling with that accelerometer would, and hector's IMU does.",
    )
    bias_topic: str | None = Field(
        None,
        description="Also publish the current biases (sensor_msgs/Imu: gyro and accelerometer bias, "
        "orientation error) on this topic, as hector's IMU does on <topic>/bias (null: not published).",
    )


class Imu(Lifecycle, Plugin):
    Params = ImuParams
    params: ImuParams

    @classmethod
    def build(cls, params: ImuParams, ctx: BuildContext, name: str) -> list[Topic]:
        link = pick_link(ctx, params.link, ("imu",))
        site = add_site(ctx, link, name, params.pose)
        obj = mujoco.mjtObj.mjOBJ_SITE
        for kind, suffix in (
            (mujoco.mjtSensor.mjSENS_GYRO, "gyro"),
            (mujoco.mjtSensor.mjSENS_ACCELEROMETER, "accel"),
            (mujoco.mjtSensor.mjSENS_FRAMEQUAT, "quat"),
        ):
            ctx.spec.add_sensor(name=f"{name}/{suffix}", type=kind, objtype=obj, objname=site)
        topics = [Topic(params.topic, "sensor_msgs/msg/Imu", "pub", params.rate)]
        if params.bias_topic:
            topics.append(Topic(params.bias_topic, "sensor_msgs/msg/Imu", "pub", params.rate))
        return topics

    def setup(self) -> None:
        p = self.params
        r = self.ctx.robot
        site = r.site_id(f"{self.name}_site")
        link = self.ctx.model.body(int(self.ctx.model.site_bodyid[site])).name.removeprefix(r.prefix)
        self.frame_id = p.frame_id or r.frame(link)
        self.gyro = r.sensor_slice(f"{self.name}/gyro")
        self.accel = r.sensor_slice(f"{self.name}/accel")
        self.quat = r.sensor_slice(f"{self.name}/quat")
        self.pub = self.ctx.publisher(p.topic, "sensor_msgs/msg/Imu")
        self.cov_o = np.eye(3).reshape(-1) * p.orientation_stddev**2
        self.cov_w = np.eye(3).reshape(-1) * p.angular_velocity_stddev**2
        self.cov_a = np.eye(3).reshape(-1) * p.linear_acceleration_stddev**2
        self.bias_w = np.array(p.angular_velocity_bias, dtype=float)
        self.bias_a = np.array(p.linear_acceleration_bias, dtype=float)
        # drawn only when asked for, so that the noise sequence of a scenario without them is unchanged
        self.bias_w += _random_bias(
            self.ctx.rng, p.angular_velocity_bias_mean, p.angular_velocity_bias_stddev
        )
        self.bias_a += _random_bias(
            self.ctx.rng, p.linear_acceleration_bias_mean, p.linear_acceleration_bias_stddev
        )
        T = msgs.T
        template = T["sensor_msgs/msg/Imu"](
            header=msgs.header(0, self.frame_id),
            orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=self.cov_o,
            angular_velocity=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
            angular_velocity_covariance=self.cov_w,
            linear_acceleration=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
            linear_acceleration_covariance=self.cov_a,
        )
        # the message is written in place: the fields below are views into its bytes
        self.layout = self.pub.layout(template, ["header.stamp"])
        self.at_q = self.layout.spans["orientation"].offset  # x y z w
        self.at_w = self.layout.spans["angular_velocity"].offset
        self.at_a = self.layout.spans["linear_acceleration"].offset
        self.noise = _Noise(self.ctx.rng, p.angular_velocity_stddev, p.linear_acceleration_stddev)
        self._views()
        self.bw, self.ba = self.bias_w.tolist(), self.bias_a.tolist()
        self._setup_drift()

    def _views(self) -> None:
        sd = self.ctx.data.sensordata  # views into it, made once (again when the world grows: `rebind`)
        self.sd_w, self.sd_a, self.sd_q = sd[self.gyro], sd[self.accel], sd[self.quat]

    def rebind(self) -> None:
        self._views()

    def _setup_drift(self) -> None:
        """hector's error model: drifting biases, a heading error, the tilt of the accelerometer bias and
        the bias topic. Nothing is drawn unless asked for, so other scenarios keep their noise sequence."""
        p = self.params
        rng, dt = self.ctx.rng, 1.0 / p.rate
        const_w, const_a = np.array(p.angular_velocity_bias), np.array(p.linear_acceleration_bias)
        self.drift_w = DriftingBias(
            rng,
            self.bias_w - const_w,
            p.angular_velocity_bias_stddev,
            p.angular_velocity_bias_drift_frequency,
            dt,
        )
        self.drift_a = DriftingBias(
            rng,
            self.bias_a - const_a,
            p.linear_acceleration_bias_stddev,
            p.linear_acceleration_bias_drift_frequency,
            dt,
        )
        self.const_w, self.const_a = const_w, const_a
        yaw0 = [rng.normal(0.0, p.yaw_bias_stddev)] if p.yaw_bias_stddev else [0.0]
        self.drift_yaw = DriftingBias(rng, yaw0, p.yaw_bias_stddev, p.yaw_bias_drift_frequency, dt)
        g = float(np.linalg.norm(self.ctx.model.opt.gravity))
        self.tilt = p.orientation_tilt_from_bias and g > 0 and bool(self.bias_a.any() or self.drift_a.on)
        self.gravity = g
        self.orientation_error = bool(p.yaw_bias or p.yaw_bias_stddev or self.tilt)
        self.q_err = np.array([1.0, 0.0, 0.0, 0.0])
        self.bias_pub: Publisher | None = None
        if p.bias_topic:
            self.bias_pub = self.ctx.publisher(p.bias_topic, "sensor_msgs/msg/Imu")
            T = msgs.T
            zero = np.zeros(9)
            template = T["sensor_msgs/msg/Imu"](
                header=msgs.header(0, self.frame_id),
                orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=zero,
                angular_velocity=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                angular_velocity_covariance=zero,
                linear_acceleration=T["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0),
                linear_acceleration_covariance=zero,
            )
            self.bias_layout = self.bias_pub.layout(template, ["header.stamp"])

    def _drift(self) -> None:
        """The biases of this reading (hector updates them before using them)."""
        if self.drift_w.on:
            self.bw = (self.const_w + self.drift_w.update()).tolist()
        if self.drift_a.on:
            self.ba = (self.const_a + self.drift_a.update()).tolist()
        self.drift_yaw.update()

    def _with_orientation_error(self, q: np.ndarray) -> np.ndarray:
        """`q` (wxyz, world frame) turned by the heading error and, with `orientation_tilt_from_bias`, tilted
        by the accelerometer bias expressed in the world frame (roll +b_y / g, pitch -b_x / g)."""
        yaw = self.params.yaw_bias + float(self.drift_yaw.value[0])
        err = np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)])
        if self.tilt:
            rot = np.zeros(9)
            mujoco.mju_quat2Mat(rot, q)
            b = rot.reshape(3, 3) @ np.array(self.ba)
            tilt = np.array([1.0, 0.5 * b[1] / self.gravity, -0.5 * b[0] / self.gravity, 0.0])
            tilt /= np.linalg.norm(tilt)
            mujoco.mju_mulQuat(err, err.copy(), tilt)
        self.q_err = err
        out = np.zeros(4)
        mujoco.mju_mulQuat(out, err, q)
        return out

    def _publish_bias(self, now_ns: int) -> None:
        buf = self.bias_layout.buf
        spans = self.bias_layout.spans
        qw, qx, qy, qz = self.q_err.tolist()
        _QUAT.pack_into(buf, spans["orientation"].offset, qx, qy, qz, qw)
        _VEC.pack_into(buf, spans["angular_velocity"].offset, *self.bw)
        _VEC.pack_into(buf, spans["linear_acceleration"].offset, *self.ba)
        assert self.bias_pub is not None
        self.bias_pub.publish_cdr(self.bias_layout.encode(now_ns), now_ns)

    def after_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        # three numbers each: plain floats and one struct pack per field beat numpy's per-call overhead
        p = self.params
        buf = self.layout.buf
        self._drift()
        wx, wy, wz = self.sd_w.tolist()
        ax, ay, az = self.sd_a.tolist()
        bw, ba = self.bw, self.ba
        wx, wy, wz, ax, ay, az = wx + bw[0], wy + bw[1], wz + bw[2], ax + ba[0], ay + ba[1], az + ba[2]
        if self.noise.on:
            nwx, nwy, nwz, nax, nay, naz = self.noise.next()
            wx, wy, wz, ax, ay, az = wx + nwx, wy + nwy, wz + nwz, ax + nax, ay + nay, az + naz
        _VEC.pack_into(buf, self.at_w, wx, wy, wz)
        _VEC.pack_into(buf, self.at_a, ax, ay, az)
        q = self.sd_q
        if self.orientation_error:
            q = self._with_orientation_error(q)
        if p.orientation_stddev:
            dq = np.zeros(4)
            mujoco.mju_euler2Quat(dq, self.ctx.rng.normal(0.0, p.orientation_stddev, 3), "xyz")
            out = np.zeros(4)
            mujoco.mju_mulQuat(out, q, dq)
            q = out
        qw, qx, qy, qz = q.tolist()
        _QUAT.pack_into(buf, self.at_q, qx, qy, qz, qw)
        self.pub.publish_cdr(self.layout.encode(now_ns), now_ns)
        if self.bias_pub is not None:
            self._publish_bias(now_ns)


def _random_bias(rng: np.random.Generator, mean: Vector3, stddev: float) -> np.ndarray:
    """Gazebo's noise bias, per axis: N(mean, stddev), negated with probability 1/2 (the sign is drawn only
    where the mean is not zero: a zero-mean bias is symmetric already)."""
    bias = np.array(mean, dtype=float)
    if stddev:
        bias += rng.normal(0.0, stddev, 3)
    if any(mean):
        bias *= np.where(rng.random(3) < 0.5, -1.0, 1.0)
    return bias


_VEC = struct.Struct("<3d")
_QUAT = struct.Struct("<4d")


class _Noise:
    """White noise for the gyro and the accelerometer, drawn from the plugin's generator in blocks (one
    call per 256 messages instead of two per message)."""

    BLOCK = 256

    def __init__(self, rng: np.random.Generator, w_std: float, a_std: float):
        self.rng = rng
        self.scale = np.array([w_std] * 3 + [a_std] * 3)
        self.on = bool(w_std or a_std)
        self.i = self.BLOCK
        self.block: list[list[float]] = []

    def next(self) -> list[float]:
        """Gyro xyz then accelerometer xyz."""
        if self.i == self.BLOCK:
            self.block = (self.rng.standard_normal((self.BLOCK, 6)) * self.scale).tolist()
            self.i = 0
        row = self.block[self.i]
        self.i += 1
        return row
