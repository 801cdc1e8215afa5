"""Helpers shared by the built-in plugins: choosing a link, mounting a site, pose parameters."""

from __future__ import annotations

import struct
from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np
from pydantic import Field

from runner.geometry import rpy_to_quat
from runner.plugin import BuildContext, PluginConfigError, PluginParams, Publisher, RatedParams, Topic
from runner.wire import msgs


class MountPose(PluginParams):
    xyz: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="Offset from the link, metres.")
    rpy: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="Rotation from the link, radians.")


def pick_link(ctx: BuildContext, link: str | None, hints: tuple[str, ...]) -> str:
    """The named link, or else the first link whose name contains one of `hints`, or else the root."""
    if link:
        ctx.body(link)  # raises a clear error if missing
        return link
    for name in ctx.links:
        if any(h in name.lower() for h in hints):
            return name
    return ctx.root


def add_site(ctx: BuildContext, link: str, name: str, pose: MountPose) -> str:
    body = ctx.body(link)
    site_name = f"{name}_site"
    if ctx.spec.site(site_name) is not None:
        raise PluginConfigError(
            f"a site named {site_name!r} already exists", hint="give the plugin a `name:`"
        )
    body.add_site(
        name=site_name,
        pos=list(pose.xyz),
        quat=list(rpy_to_quat(pose.rpy)),
        size=[0.005, 0.005, 0.005],
        group=4,
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
    )
    return site_name


def odometry(
    now_ns: int,
    frame_id: str,
    child: str,
    pos: Sequence[float],
    quat_wxyz: Sequence[float],
    lin: Sequence[float],
    ang: Sequence[float],
    pose_covariance: Sequence[float] | None = None,
    twist_covariance: Sequence[float] | None = None,
) -> Any:
    """A nav_msgs/Odometry from arrays (twist as given; covariances from their 6 diagonal values, as
    diff_drive_controller's `pose_covariance_diagonal` / `twist_covariance_diagonal`, else zero)."""
    T = msgs.T
    pose = T["geometry_msgs/msg/Pose"](
        position=T["geometry_msgs/msg/Point"](x=float(pos[0]), y=float(pos[1]), z=float(pos[2])),
        orientation=T["geometry_msgs/msg/Quaternion"](
            x=float(quat_wxyz[1]), y=float(quat_wxyz[2]), z=float(quat_wxyz[3]), w=float(quat_wxyz[0])
        ),
    )
    twist = T["geometry_msgs/msg/Twist"](
        linear=T["geometry_msgs/msg/Vector3"](x=float(lin[0]), y=float(lin[1]), z=float(lin[2])),
        angular=T["geometry_msgs/msg/Vector3"](x=float(ang[0]), y=float(ang[1]), z=float(ang[2])),
    )
    return T["nav_msgs/msg/Odometry"](
        header=msgs.header(now_ns, frame_id),
        child_frame_id=child,
        pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=_covariance(pose_covariance)),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=twist, covariance=_covariance(twist_covariance)
        ),
    )


def _covariance(diagonal: Sequence[float] | None) -> np.ndarray:
    out = np.zeros(36)
    if diagonal is not None:
        out[::7] = [float(v) for v in diagonal]
    return out


class BaseDriveParams(RatedParams):
    """What every base drive (diff_drive, skid_steer, planar_move) has: its topics and frames."""

    cmd_topic: str = Field("cmd_vel", description="Command topic (geometry_msgs/Twist).")
    odom_topic: str = Field("odom", description="Odometry topic (nav_msgs/Odometry).")
    tf_topic: str = Field("tf", description="TF topic (tf2_msgs/TFMessage).")
    publish_odom: bool = Field(True, description="Publish odometry.")
    publish_tf: bool = Field(True, description="Publish the odom -> base transform.")
    odom_frame: str = Field("odom", description="Odometry frame (namespaced: <ns>/odom).")
    base_frame: str | None = Field(None, description="Base frame (default: the root link, namespaced).")
    cmd_timeout: float = Field(
        0.0, ge=0, description="Stop when no command came for this long, s (0: never)."
    )


def drive_topics(params: BaseDriveParams) -> list[Topic]:
    """The topics of a base drive: `cmd_vel` in; `odom` and `tf` out when enabled."""
    topics = [Topic(params.cmd_topic, "geometry_msgs/msg/Twist", "sub")]
    if params.publish_odom:
        topics.append(Topic(params.odom_topic, "nav_msgs/msg/Odometry", "pub", params.rate))
    if params.publish_tf:
        topics.append(Topic(params.tf_topic, "tf2_msgs/msg/TFMessage", "pub", params.rate))
    return topics


_POSE = struct.Struct("<7d")  # position xyz, orientation xyzw
_TWIST = struct.Struct("<6d")  # linear xyz, angular xyz


class OdometryWriter:
    """Publishes nav_msgs/Odometry with fixed frames and covariances (zero unless given), written in place
    into a fixed layout: a few microseconds a message instead of building message objects."""

    def __init__(
        self,
        pub: Publisher,
        frame_id: str,
        child: str,
        pose_covariance: Sequence[float] | None = None,
        twist_covariance: Sequence[float] | None = None,
    ):
        self.pub = pub
        zero = (0.0, 0.0, 0.0)
        template = odometry(
            0, frame_id, child, zero, (1.0, 0.0, 0.0, 0.0), zero, zero, pose_covariance, twist_covariance
        )
        self.layout = pub.layout(template, ["header.stamp"])
        self.buf = self.layout.buf
        self.pose_at = self.layout.spans["pose.pose"].offset
        self.twist_at = self.layout.spans["twist.twist"].offset

    def publish(
        self,
        now_ns: int,
        pos: Sequence[float],
        quat_wxyz: Sequence[float],
        lin: Sequence[float],
        ang: Sequence[float],
    ) -> None:
        x, y, z = pos[0], pos[1], pos[2]
        w, qx, qy, qz = quat_wxyz[0], quat_wxyz[1], quat_wxyz[2], quat_wxyz[3]
        _POSE.pack_into(self.buf, self.pose_at, x, y, z, qx, qy, qz, w)
        _TWIST.pack_into(self.buf, self.twist_at, lin[0], lin[1], lin[2], ang[0], ang[1], ang[2])
        self.pub.publish_cdr(self.layout.encode(now_ns), now_ns)


def tf_message(now_ns: int, parent: str, child: str, pos: Sequence[float], quat_wxyz: Sequence[float]) -> Any:
    """A tf2_msgs/TFMessage holding one transform parent -> child."""
    return tf_transforms(now_ns, [(parent, child, pos, quat_wxyz)])


def tf_transforms(now_ns: int, entries: Sequence[tuple[str, str, Sequence[float], Sequence[float]]]) -> Any:
    """A tf2_msgs/TFMessage of (parent, child, position, quaternion wxyz) transforms."""
    T = msgs.T
    return T["tf2_msgs/msg/TFMessage"](
        transforms=[
            T["geometry_msgs/msg/TransformStamped"](
                header=msgs.header(now_ns, parent),
                child_frame_id=child,
                transform=T["geometry_msgs/msg/Transform"](
                    translation=T["geometry_msgs/msg/Vector3"](
                        x=float(pos[0]), y=float(pos[1]), z=float(pos[2])
                    ),
                    rotation=T["geometry_msgs/msg/Quaternion"](
                        x=float(q[1]), y=float(q[2]), z=float(q[3]), w=float(q[0])
                    ),
                ),
            )
            for parent, child, pos, q in entries
        ]
    )


class TransformWriter:
    """Publishes a tf2_msgs/TFMessage of one transform parent -> child, written in place."""

    def __init__(self, pub: Publisher, parent: str, child: str):
        self.pub = pub
        template = tf_message(0, parent, child, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
        self.layout = pub.layout(template, ["transforms[0].header.stamp"])
        self.buf = self.layout.buf
        self.at = self.layout.spans["transforms[0].transform"].offset

    def publish(self, now_ns: int, pos: Sequence[float], quat_wxyz: Sequence[float]) -> None:
        w, qx, qy, qz = quat_wxyz[0], quat_wxyz[1], quat_wxyz[2], quat_wxyz[3]
        _POSE.pack_into(self.buf, self.at, pos[0], pos[1], pos[2], qx, qy, qz, w)
        self.pub.publish_cdr(self.layout.encode(now_ns), now_ns)
