"""joint_states: positions, velocities and efforts of a robot's joints -> sensor_msgs/JointState.

Joint names are the URDF names (as robot_state_publisher expects), not the namespaced MuJoCo names.
"""

from __future__ import annotations

import mujoco
import numpy as np
from pydantic import Field

from runner.plugin import BuildContext, Plugin, PluginConfigError, RatedParams, Topic
from runner.wire import msgs

_MOVABLE = {int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)}


class JointStatesParams(RatedParams):
    rate: float = Field(50.0, gt=0, description="Publish rate, sim Hz.")
    topic: str = Field("joint_states", description="Topic, relative to the robot's namespace.")
    joints: list[str] | None = Field(
        None, description="Joints to publish (default: every revolute/prismatic)."
    )


class JointStates(Plugin):
    Params = JointStatesParams
    params: JointStatesParams

    @classmethod
    def build(cls, params: JointStatesParams, ctx: BuildContext, name: str) -> list[Topic]:
        for i, j in enumerate(params.joints or []):
            joint = ctx.joint(j, f"joints[{i}]")
            if int(joint.type) not in _MOVABLE:
                raise PluginConfigError(f"joint {j!r} is not revolute or prismatic", f"joints[{i}]")
        return [Topic(params.topic, "sensor_msgs/msg/JointState", "pub", params.rate)]

    def setup(self) -> None:
        m = self.ctx.model
        r = self.ctx.robot
        if self.params.joints is not None:
            ids = [r.joint_id(j) for j in self.params.joints]
        else:
            ids = [
                j
                for j in range(m.njnt)
                if int(m.jnt_bodyid[j]) in r.body_ids and int(m.jnt_type[j]) in _MOVABLE
            ]
        self.names = [m.joint(j).name.removeprefix(r.prefix) for j in ids]
        self.qadr = np.array([m.jnt_qposadr[j] for j in ids], dtype=np.int64)
        self.vadr = np.array([m.jnt_dofadr[j] for j in ids], dtype=np.int64)
        self.pub = self.ctx.publisher(self.params.topic, "sensor_msgs/msg/JointState")
        n = len(ids)
        template = msgs.T["sensor_msgs/msg/JointState"](
            header=msgs.header(0, ""),
            name=self.names,
            position=np.zeros(n),
            velocity=np.zeros(n),
            effort=np.zeros(n),
        )
        self.layout = self.pub.layout(template, ["header.stamp", "position", "velocity", "effort"])

    def after_step(self, now_ns: int) -> None:
        d = self.ctx.data
        self.pub.publish_cdr(
            self.layout.encode(now_ns, d.qpos[self.qadr], d.qvel[self.vadr], d.qfrc_actuator[self.vadr]),
            now_ns,
        )
