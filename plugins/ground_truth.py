"""ground_truth: the true pose and velocity of a link in the world frame -> nav_msgs/Odometry.

Like gazebo_ros_p3d: frame_id `world`, child `<ns>/<link>`; the twist is expressed in the world frame.
Meant for tests and assertions, not for a robot's own navigation.
"""

from __future__ import annotations

import mujoco
import numpy as np
from pydantic import Field

from plugins._common import OdometryWriter
from runner.plugin import BuildContext, Plugin, RatedParams, Topic


class GroundTruthParams(RatedParams):
    rate: float = Field(50.0, gt=0, description="Publish rate, sim Hz.")
    link: str | None = Field(None, description="Link to track (default: the root link).")
    topic: str = Field("ground_truth", description="Topic, relative to the robot's namespace.")
    frame_id: str = Field("world", description="Frame of the pose.")


class GroundTruth(Plugin):
    Params = GroundTruthParams
    params: GroundTruthParams

    @classmethod
    def build(cls, params: GroundTruthParams, ctx: BuildContext, name: str) -> list[Topic]:
        if params.link:
            ctx.body(params.link)
        return [Topic(params.topic, "nav_msgs/msg/Odometry", "pub", params.rate)]

    def setup(self) -> None:
        r = self.ctx.robot
        link = self.params.link or r.root_link
        self.body = r.body_id(link)
        self.child = r.frame(link)
        self.out = OdometryWriter(
            self.ctx.publisher(self.params.topic, "nav_msgs/msg/Odometry"), self.params.frame_id, self.child
        )
        self.vel = np.zeros(6)

    def after_step(self, now_ns: int) -> None:
        m, d = self.ctx.model, self.ctx.data
        mujoco.mj_objectVelocity(
            m, d, mujoco.mjtObj.mjOBJ_XBODY, self.body, self.vel, 0
        )  # at the link origin
        self.out.publish(now_ns, d.xpos[self.body], d.xquat[self.body], self.vel[3:], self.vel[:3])
