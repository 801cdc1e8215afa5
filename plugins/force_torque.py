"""force_torque: the wrench a link's parent exerts on it, at the link's origin (MuJoCo force and torque
sensors on a site there) -> geometry_msgs/WrenchStamped. ros2_control's force_torque_sensor_broadcaster
(runner.compile.gazebo.control.broadcasters) runs as this plugin at the joint its Gazebo force_torque sensor
sits on (the joint's child link): MuJoCo reports the interaction force between the child's subtree and its
parent in the child's frame, as Gazebo's sensor does with its defaults (`<frame>child</frame>`).

As Gazebo's force_torque sensor (gz-sensors ForceTorqueSensor.cc:199-248) it may report the wrench in
another frame (`measure_frame`: `child`, the link's own, `parent`, the parent link's, or `sensor`, the
frame at `pose`), the other way round (`measure_direction`: `parent_to_child`, the wrench the parent
applies on the link, or `child_to_parent`, its opposite, which is Gazebo's default), with white noise and a
constant error per axis. The torque is about the sensor's origin (the link's origin, or `pose`)."""

from __future__ import annotations

from typing import Literal

import mujoco
import numpy as np
from pydantic import Field

from plugins._actuators import Lifecycle
from plugins._common import MountPose, add_site, pick_link
from runner.plugin import BuildContext, Plugin, RatedParams, Topic
from runner.wire import msgs


class ForceTorqueParams(RatedParams):
    rate: float = Field(100.0, gt=0, description="Publish rate, sim Hz.")
    link: str | None = Field(
        None,
        description="The link whose wrench from its parent is measured, a joint's child (default: a link "
        "named like force/ft/wrench, else the root).",
    )
    topic: str = Field("wrench", description="Topic, relative to the robot's namespace.")
    frame_id: str | None = Field(None, description="Frame id in the header (default: <ns>/<link>).")
    pose: MountPose = Field(
        default_factory=MountPose, description="The sensor frame relative to the link (torques are about it)."
    )
    measure_frame: Literal["child", "parent", "sensor"] = Field(
        "child", description="The frame the wrench is expressed in: the link's, its parent's, or `pose`'s."
    )
    measure_direction: Literal["parent_to_child", "child_to_parent"] = Field(
        "parent_to_child",
        description="The wrench the parent applies on the link, or (child_to_parent, Gazebo's default) the "
        "one the link applies on its parent.",
    )
    force_noise_stddev: tuple[float, float, float] = Field(
        (0.0, 0.0, 0.0), description="White noise per axis, N."
    )
    force_noise_mean: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="Constant error, N.")
    torque_noise_stddev: tuple[float, float, float] = Field(
        (0.0, 0.0, 0.0), description="White noise per axis, N m."
    )
    torque_noise_mean: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="Constant error, N m.")


class ForceTorque(Lifecycle, Plugin):
    Params = ForceTorqueParams
    params: ForceTorqueParams

    @classmethod
    def build(cls, params: ForceTorqueParams, ctx: BuildContext, name: str) -> list[Topic]:
        site = add_site(ctx, pick_link(ctx, params.link, ("force", "ft", "wrench")), name, params.pose)
        obj = mujoco.mjtObj.mjOBJ_SITE
        ctx.spec.add_sensor(
            name=f"{name}/force", type=mujoco.mjtSensor.mjSENS_FORCE, objtype=obj, objname=site
        )
        ctx.spec.add_sensor(
            name=f"{name}/torque", type=mujoco.mjtSensor.mjSENS_TORQUE, objtype=obj, objname=site
        )
        return [Topic(params.topic, "geometry_msgs/msg/WrenchStamped", "pub", params.rate)]

    def setup(self) -> None:
        r = self.ctx.robot
        self.force = r.sensor_slice(f"{self.name}/force")
        self.torque = r.sensor_slice(f"{self.name}/torque")
        self.pub = self.ctx.publisher(self.params.topic, "geometry_msgs/msg/WrenchStamped")
        site = r.site_id(f"{self.name}_site")
        self.site = site
        m = self.ctx.model
        self.body = int(m.site_bodyid[site])
        self.parent = int(m.body_parentid[self.body])
        link = m.body(self.body).name.removeprefix(r.prefix)
        self.frame_id = self.params.frame_id or r.frame(link)
        p = self.params
        self.sign = -1.0 if p.measure_direction == "child_to_parent" else 1.0
        self.noisy = any(p.force_noise_stddev) or any(p.torque_noise_stddev)
        self.sd = np.array([*p.force_noise_stddev, *p.torque_noise_stddev])
        self.mean = np.array([*p.force_noise_mean, *p.torque_noise_mean])

    def after_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        d = self.ctx.data
        sd = d.sensordata
        f, t = self.sign * sd[self.force], self.sign * sd[self.torque]  # in the site's frame
        frame = self.params.measure_frame
        if frame != "sensor":
            # site frame -> world -> the child's (the link's own) or the parent's frame
            site_rot = d.site_xmat[self.site].reshape(3, 3)
            target = d.xmat[self.body if frame == "child" else self.parent].reshape(3, 3)
            rot = target.T @ site_rot
            f, t = rot @ f, rot @ t
        if self.noisy or self.mean.any():
            w = np.concatenate([f, t]) + self.mean + self.ctx.rng.normal(0.0, 1.0, 6) * self.sd
            f, t = w[:3], w[3:]
        T = msgs.T
        vec = T["geometry_msgs/msg/Vector3"]
        self.pub.publish(
            T["geometry_msgs/msg/WrenchStamped"](
                header=msgs.header(now_ns, self.frame_id),
                wrench=T["geometry_msgs/msg/Wrench"](
                    force=vec(x=float(f[0]), y=float(f[1]), z=float(f[2])),
                    torque=vec(x=float(t[0]), y=float(t[1]), z=float(t[2])),
                ),
            ),
            now_ns,
        )
