"""Helpers shared by the built-in plugins: choosing a link, mounting a site, pose parameters."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np
from pydantic import Field

from runner import msgs
from runner.geometry import rpy_to_quat
from runner.plugin import BuildContext, PluginConfigError, PluginParams, RatedParams, Topic


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
) -> Any:
    """A nav_msgs/Odometry from arrays (twist as given, no covariance)."""
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
    zeros = np.zeros(36)
    return T["nav_msgs/msg/Odometry"](
        header=msgs.header(now_ns, frame_id),
        child_frame_id=child,
        pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=zeros),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=zeros),
    )


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
