"""imu: orientation, angular velocity and linear acceleration -> sensor_msgs/Imu.

Uses MuJoCo's own sensors on a site at the IMU link (gyro, accelerometer, framequat). As on a real IMU
and in Gazebo, linear acceleration includes the reaction to gravity (+9.81 m/s² up at rest).

Errors, per axis in the IMU frame: a constant bias (`*_bias`, plus a random part drawn once at setup from
`*_bias_stddev` with the plugin's seeded generator, so a run is repeatable) and white Gaussian noise
(`*_stddev`, drawn at every message). The covariances in the message are those of the white noise.
"""

from __future__ import annotations

import mujoco
import numpy as np
from pydantic import Field

from plugins._common import MountPose, add_site, pick_link
from runner import msgs
from runner.plugin import BuildContext, Plugin, RatedParams, Topic

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


class Imu(Plugin):
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
        return [Topic(params.topic, "sensor_msgs/msg/Imu", "pub", params.rate)]

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
        T = msgs.T
        self.Imu, self.Quat, self.Vec = (
            T["sensor_msgs/msg/Imu"],
            T["geometry_msgs/msg/Quaternion"],
            T["geometry_msgs/msg/Vector3"],
        )
        self.cov_o = np.eye(3).reshape(-1) * p.orientation_stddev**2
        self.cov_w = np.eye(3).reshape(-1) * p.angular_velocity_stddev**2
        self.cov_a = np.eye(3).reshape(-1) * p.linear_acceleration_stddev**2
        self.bias_w = np.array(p.angular_velocity_bias, dtype=float)
        self.bias_a = np.array(p.linear_acceleration_bias, dtype=float)
        # drawn only when asked for, so that the noise sequence of a scenario without them is unchanged
        if p.angular_velocity_bias_stddev:
            self.bias_w += self.ctx.rng.normal(0.0, p.angular_velocity_bias_stddev, 3)
        if p.linear_acceleration_bias_stddev:
            self.bias_a += self.ctx.rng.normal(0.0, p.linear_acceleration_bias_stddev, 3)

    def after_step(self, now_ns: int) -> None:
        p = self.params
        sd = self.ctx.data.sensordata
        rng = self.ctx.rng
        w = sd[self.gyro] + self.bias_w
        a = sd[self.accel] + self.bias_a
        q = sd[self.quat].copy()
        if p.angular_velocity_stddev:
            w += rng.normal(0.0, p.angular_velocity_stddev, 3)
        if p.linear_acceleration_stddev:
            a += rng.normal(0.0, p.linear_acceleration_stddev, 3)
        if p.orientation_stddev:
            dq = np.zeros(4)
            mujoco.mju_euler2Quat(dq, rng.normal(0.0, p.orientation_stddev, 3), "xyz")
            out = np.zeros(4)
            mujoco.mju_mulQuat(out, q, dq)
            q = out
        msg = self.Imu(
            header=msgs.header(now_ns, self.frame_id),
            orientation=self.Quat(x=q[1], y=q[2], z=q[3], w=q[0]),
            orientation_covariance=self.cov_o,
            angular_velocity=self.Vec(x=w[0], y=w[1], z=w[2]),
            angular_velocity_covariance=self.cov_w,
            linear_acceleration=self.Vec(x=a[0], y=a[1], z=a[2]),
            linear_acceleration_covariance=self.cov_a,
        )
        self.pub.publish(msg, now_ns)
