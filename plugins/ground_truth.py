"""ground_truth: the true pose and velocity of a link in the world frame -> nav_msgs/Odometry.

Like gazebo_ros_p3d: frame_id `world`, child `<ns>/<link>`; the twist is expressed in the world frame.
Meant for tests and assertions, and for the world-odometry plugins of public descriptions, which it
serves with their options (runner.compile.gazebo.drives3p):

- `reference_link`: the pose relative to another link of the robot, as p3d computes it with a
  `<frameName>` that names a link (gazebo_ros_p3d.cpp:278-297 of noetic-devel: position rotated into the
  link's frame, orientation `q · q_ref⁻¹`, velocities `R_ref · (v - v_ref)`, all as the source has them);
- `xyz_offset`, `rpy_offset`: constant offsets added to the position and pre-multiplied onto the
  orientation (p3d's `<xyzOffset>`, `<rpyOffset>`);
- `twist_noise`: white gaussian noise of this stddev on each of the six twist components (p3d's
  `<gaussianNoise>`; the pose is not noised);
- `linear_velocity_frame`, `angular_velocity_frame`: `world` (p3d) or `body` (the link's own frame, as
  PAL's and Robotnik's world-odometry plugins and gz-sim's OdometryPublisher give them);
- `child_frame_id`, `publish_tf`: another child frame, and the same transform on `tf` (Robotnik's
  `<frameName>`, `<broadcastTF>`).
"""

from __future__ import annotations

from typing import Literal

import mujoco
import numpy as np
from pydantic import Field, NonNegativeFloat

from plugins._common import OdometryWriter, TransformWriter
from runner.plugin import BuildContext, Plugin, RatedParams, Topic

Frame = Literal["world", "body"]


class GroundTruthParams(RatedParams):
    rate: float = Field(50.0, gt=0, description="Publish rate, sim Hz.")
    link: str | None = Field(None, description="Link to track (default: the root link).")
    topic: str = Field("ground_truth", description="Topic, relative to the robot's namespace.")
    frame_id: str = Field("world", description="Frame of the pose.")
    child_frame_id: str | None = Field(None, description="Child frame (default: the link's, namespaced).")
    reference_link: str | None = Field(
        None,
        description="Give the pose relative to this link of the robot (p3d's <frameName> naming a link).",
    )
    xyz_offset: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="Added to the position, m.")
    rpy_offset: tuple[float, float, float] = Field(
        (0.0, 0.0, 0.0), description="Roll, pitch, yaw pre-multiplied onto the orientation, rad."
    )
    twist_noise: NonNegativeFloat = Field(
        0.0, description="Stddev of white gaussian noise on each twist component (m/s, rad/s)."
    )
    linear_velocity_frame: Frame = Field("world", description="Frame of the twist's linear part.")
    angular_velocity_frame: Frame = Field("world", description="Frame of the twist's angular part.")
    publish_tf: bool = Field(False, description="Also publish frame_id -> child_frame_id on `tf_topic`.")
    tf_topic: str = Field("tf", description="TF topic (tf2_msgs/TFMessage), when `publish_tf`.")
    offset_frame: Frame = Field(
        "world",
        description="`world`: the offsets are added in the world frame (p3d); `body`: composed after the "
        "link's pose, `pose * offset` (gz-sim's OdometryPublisher).",
    )
    planar: bool = Field(
        False,
        description="2D odometry (gz-sim OdometryPublisher's `<dimensions>2`): no z, no roll or pitch rate, "
        "no vertical velocity (their noise only).",
    )


class GroundTruth(Plugin):
    Params = GroundTruthParams
    params: GroundTruthParams

    @classmethod
    def build(cls, params: GroundTruthParams, ctx: BuildContext, name: str) -> list[Topic]:
        for link in (params.link, params.reference_link):
            if link:
                ctx.body(link)
        topics = [Topic(params.topic, "nav_msgs/msg/Odometry", "pub", params.rate)]
        if params.publish_tf:
            topics.append(Topic(params.tf_topic, "tf2_msgs/msg/TFMessage", "pub", params.rate))
        return topics

    def setup(self) -> None:
        p = self.params
        r = self.ctx.robot
        link = p.link or r.root_link
        self.body = r.body_id(link)
        self.ref = r.body_id(p.reference_link) if p.reference_link else None
        self.child = p.child_frame_id or r.frame(link)
        cov = [p.twist_noise**2] * 6 if p.twist_noise else None  # the source's variance, p3d :378-391
        self.out = OdometryWriter(
            self.ctx.publisher(p.topic, "nav_msgs/msg/Odometry"), p.frame_id, self.child, cov, cov
        )
        tf_pub = self.ctx.publisher(p.tf_topic, "tf2_msgs/msg/TFMessage") if p.publish_tf else None
        self.tf_out = TransformWriter(tf_pub, p.frame_id, self.child) if tf_pub else None
        self.offset = np.array(p.xyz_offset, dtype=float)
        self.rot_offset = np.empty(4)
        mujoco.mju_euler2Quat(self.rot_offset, np.array(p.rpy_offset, dtype=float), "XYZ")
        self.plain = not any(p.xyz_offset) and not any(p.rpy_offset) and self.ref is None
        self.rng = self.ctx.rng if p.twist_noise else None
        self.vel = np.zeros(6)
        self.ref_vel = np.zeros(6)

    def after_step(self, now_ns: int) -> None:
        p = self.params
        m, d = self.ctx.model, self.ctx.data
        # at the link origin, in the world frame (flg_local 0)
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, self.body, self.vel, 0)
        pos, quat = d.xpos[self.body], d.xquat[self.body]
        lin, ang = self.vel[3:].copy(), self.vel[:3].copy()
        if not self.plain:
            pos, quat = pos.copy(), quat.copy()
            if self.ref is not None:
                pos, quat, lin, ang = self._relative(pos, quat, lin, ang)
            out = np.empty(4)
            if p.offset_frame == "body":  # gz-sim OdometryPublisher.cc:386: rawPose * offset
                rot = np.empty(9)
                mujoco.mju_quat2Mat(rot, quat)
                pos = pos + rot.reshape(3, 3) @ self.offset
                mujoco.mju_mulQuat(out, quat, self.rot_offset)
            else:
                pos += self.offset
                mujoco.mju_mulQuat(out, self.rot_offset, quat)
            mujoco.mju_normalize4(out)
            quat = out
        frame = d.xmat[self.body].reshape(3, 3)
        if p.linear_velocity_frame == "body":
            lin = frame.T @ lin
        if p.angular_velocity_frame == "body":
            ang = frame.T @ ang
        if p.planar:  # OdometryPublisher.cc:387-425: x, y and the yaw rate only
            pos = np.array([pos[0], pos[1], 0.0])
            lin = np.array([lin[0], lin[1], 0.0])
            ang = np.array([0.0, 0.0, ang[2]])
        if self.rng is not None:
            noise = self.rng.normal(0.0, p.twist_noise, 6)
            lin, ang = lin + noise[:3], ang + noise[3:]
        self.out.publish(now_ns, pos, quat, lin, ang)
        if self.tf_out:
            self.tf_out.publish(now_ns, pos, quat)

    def _relative(
        self, pos: np.ndarray, quat: np.ndarray, lin: np.ndarray, ang: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """p3d's reference frame, as gazebo_ros_p3d.cpp:291-296 computes it: position rotated into the
        reference link, orientation q · q_ref⁻¹, velocity differences rotated BY the reference's rotation."""
        m, d = self.ctx.model, self.ctx.data
        ref = self.ref
        mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, ref, self.ref_vel, 0)
        rot = d.xmat[ref].reshape(3, 3)
        rel = rot.T @ (pos - d.xpos[ref])
        inv = np.empty(4)
        mujoco.mju_negQuat(inv, d.xquat[ref])
        q = np.empty(4)
        mujoco.mju_mulQuat(q, quat, inv)
        return rel, q, rot @ (lin - self.ref_vel[3:]), rot @ (ang - self.ref_vel[:3])
