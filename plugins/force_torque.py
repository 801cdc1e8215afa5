"""force_torque: the wrench a link's parent exerts on it, at the link's origin (MuJoCo force and torque
sensors on a site there) -> geometry_msgs/WrenchStamped. ros2_control's force_torque_sensor_broadcaster
(runner.compile.gazebo.control.broadcasters) runs as this plugin at the joint its Gazebo force_torque sensor
sits on (the joint's child link): MuJoCo reports the interaction force between the child's subtree and its
parent in the child's frame, as Gazebo's sensor does with its defaults (`<frame>child</frame>`)."""

from __future__ import annotations

import mujoco
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


class ForceTorque(Lifecycle, Plugin):
    Params = ForceTorqueParams
    params: ForceTorqueParams

    @classmethod
    def build(cls, params: ForceTorqueParams, ctx: BuildContext, name: str) -> list[Topic]:
        site = add_site(ctx, pick_link(ctx, params.link, ("force", "ft", "wrench")), name, MountPose())
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
        link = self.ctx.model.body(int(self.ctx.model.site_bodyid[site])).name.removeprefix(r.prefix)
        self.frame_id = self.params.frame_id or r.frame(link)

    def after_step(self, now_ns: int) -> None:
        if not self.active:  # switched off by the controller_manager plugin
            return
        sd = self.ctx.data.sensordata
        f, t = sd[self.force], sd[self.torque]
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
