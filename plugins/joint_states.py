"""joint_states: positions, velocities and efforts of a robot's joints -> sensor_msgs/JointState.

Joint names are the URDF names (as robot_state_publisher expects), not the namespaced MuJoCo names.

Also ros2_control's joint_state_broadcaster (runner.compile.gazebo.control.broadcasters): `extra_joints`
(published with state 0), `interfaces` (the state interfaces each joint has: a field of joint_states whose
interface a joint lacks is NaN, as the broadcaster fills it), `frame_id`, and `dynamic_topic`, where every
joint's interfaces are published as control_msgs/DynamicJointState (joint_state_broadcaster.cpp on Jazzy:
`dynamic_joint_states`, the interface names and values of each joint, in the order it found them).
"""

from __future__ import annotations

import mujoco
import numpy as np
from pydantic import Field

from plugins._actuators import Lifecycle
from runner.plugin import BuildContext, Plugin, PluginConfigError, RatedParams, Topic
from runner.wire import msgs

_FIELDS = ("position", "velocity", "effort")
_MOVABLE = {int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)}


class JointStatesParams(RatedParams):
    rate: float = Field(50.0, gt=0, description="Publish rate, sim Hz.")
    topic: str = Field("joint_states", description="Topic, relative to the robot's namespace.")
    joints: list[str] | None = Field(
        None, description="Joints to publish (default: every revolute/prismatic)."
    )
    extra_joints: list[str] = Field(
        default_factory=list, description="Names published too, with position, velocity and effort 0."
    )
    interfaces: dict[str, list[str]] | None = Field(
        None,
        description="State interfaces of each joint (position, velocity, effort; default: all three): a "
        "field a joint lacks is NaN in joint_states.",
    )
    frame_id: str = Field("", description="Frame id of the messages' header.")
    dynamic_topic: str | None = Field(
        None,
        description="Also publish control_msgs/DynamicJointState (each joint's interfaces by name) here.",
    )


class JointStates(Lifecycle, Plugin):  # joint_state_broadcaster: publishes while active
    Params = JointStatesParams
    params: JointStatesParams

    @classmethod
    def build(cls, params: JointStatesParams, ctx: BuildContext, name: str) -> list[Topic]:
        for i, j in enumerate(params.joints or []):
            joint = ctx.joint(j, f"joints[{i}]")
            if int(joint.type) not in _MOVABLE:
                raise PluginConfigError(f"joint {j!r} is not revolute or prismatic", f"joints[{i}]")
        for j, names in (params.interfaces or {}).items():
            bad = [n for n in names if n not in _FIELDS]
            if bad:
                raise PluginConfigError(
                    f"joint {j!r}: state interface(s) {bad} are not position, velocity or effort",
                    "interfaces",
                )
        out = [Topic(params.topic, "sensor_msgs/msg/JointState", "pub", params.rate)]
        if params.dynamic_topic:
            out.append(Topic(params.dynamic_topic, "control_msgs/msg/DynamicJointState", "pub", params.rate))
        return out

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
        extra = [j for j in self.params.extra_joints if j not in self.names]
        n, total = len(ids), len(ids) + len(extra)
        # per field, 1 where the joint has that state interface, NaN where it lacks it (extra joints: 0)
        have = self.params.interfaces or {}
        self.mask = np.ones((3, n))
        for k, name in enumerate(self.names):
            if name in have:
                for f, field in enumerate(_FIELDS):
                    if field not in have[name]:
                        self.mask[f, k] = np.nan
        self.pad = np.zeros(len(extra))
        template = msgs.T["sensor_msgs/msg/JointState"](
            header=msgs.header(0, self.params.frame_id),
            name=self.names + extra,
            position=np.zeros(total),
            velocity=np.zeros(total),
            effort=np.zeros(total),
        )
        self.layout = self.pub.layout(template, ["header.stamp", "position", "velocity", "effort"])
        self.dynamic = None
        if self.params.dynamic_topic:
            self.dynamic = self.ctx.publisher(self.params.dynamic_topic, "control_msgs/msg/DynamicJointState")
            self.joint_fields = [
                [f for f, field in enumerate(_FIELDS) if name not in have or field in have[name]]
                for name in self.names
            ] + [[0, 1, 2]] * len(extra)
            self.dynamic_names = self.names + extra

    def after_step(self, now_ns: int) -> None:
        if not self.active:
            return
        d = self.ctx.data
        values = (d.qpos[self.qadr], d.qvel[self.vadr], d.qfrc_actuator[self.vadr])
        fields = [np.concatenate([v * self.mask[f], self.pad]) for f, v in enumerate(values)]
        self.pub.publish_cdr(self.layout.encode(now_ns, *fields), now_ns)
        if self.dynamic is not None:
            value = msgs.T["control_msgs/msg/InterfaceValue"]
            self.dynamic.publish(
                msgs.T["control_msgs/msg/DynamicJointState"](
                    header=msgs.header(now_ns, self.params.frame_id),
                    joint_names=self.dynamic_names,
                    interface_values=[
                        value(
                            interface_names=[_FIELDS[f] for f in fs],
                            values=np.array([fields[f][k] for f in fs], dtype=np.float64),
                        )
                        for k, fs in enumerate(self.joint_fields)
                    ],
                ),
                now_ns,
            )
