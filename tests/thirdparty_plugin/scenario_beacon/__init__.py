"""beacon: publishes the distance from a link to a point in the world, as std_msgs/Float64."""

from __future__ import annotations

import math

from pydantic import Field

from runner.plugin import BuildContext, Plugin, RatedParams, Topic
from runner.wire import msgs


class BeaconParams(RatedParams):
    point: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="The beacon, in the world frame.")
    link: str | None = Field(None, description="Link whose distance is measured (default: the root).")
    topic: str = Field("beacon/distance", description="Topic, relative to the robot's namespace.")


class Beacon(Plugin):
    Params = BeaconParams
    params: BeaconParams

    @classmethod
    def build(cls, params: BeaconParams, ctx: BuildContext, name: str) -> list[Topic]:
        if params.link:
            ctx.body(params.link)  # a clear error, pointing at `params.link`, if the robot lacks it
        return [Topic(params.topic, "std_msgs/msg/Float64", "pub", params.rate)]

    def setup(self) -> None:
        robot = self.ctx.robot
        self.body = robot.body_id(self.params.link or robot.root_link)
        self.pub = self.ctx.publisher(self.params.topic, "std_msgs/msg/Float64")

    def after_step(self, now_ns: int) -> None:
        x, y, z = self.ctx.data.xpos[self.body]
        px, py, pz = self.params.point
        distance = math.sqrt((x - px) ** 2 + (y - py) ** 2 + (z - pz) ** 2)
        self.pub.publish(msgs.T["std_msgs/msg/Float64"](data=distance), now_ns)
