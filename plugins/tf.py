"""tf: the robot's link tree -> tf2_msgs/TFMessage (what robot_state_publisher does for a real robot).

Every link but the root is published relative to its parent link in the URDF tree (in MuJoCo: body parent
-> child), with namespaced frame ids (`<ns>/<link>`):

- links moved by a joint (revolute, continuous, prismatic, floating...) on `topic` at `rate`, one message
  per tick holding all of them. Poses are MuJoCo's `xpos`/`xquat` at the stamp (the world runs
  `mj_forward` before sensing hooks), so the transforms agree with `joint_states` of the same stamp;
- links on fixed joints once on `static_topic` at the first tick, and again every `static_period`
  seconds if set (on the first tick at or after each multiple; the transport has no latching, so a late
  subscriber otherwise misses them).

The root link's own pose (odom -> base) is the drive's job (diff_drive publishes it on `tf` too; both
plugins may publish on one topic). `include_root: true` adds `world` -> root: on `topic` for a mobile
robot, on `static_topic` for a welded (`fixed`) one.

A description whose root link is `world` (welded by it, as in Gazebo): that link is the frame `<ns>/world`,
the robot's own, distinct from the scenario's `world`; the links below it are published relative to it,
as robot_state_publisher publishes the URDF's `world` -> `base_link`, and `include_root` adds `world` ->
`<ns>/world` (the robot's pose in the scenario).
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
from pydantic import Field

from runner.plugin import BuildContext, Plugin, RatedParams, Topic
from runner.wire import msgs

TF_TYPE = "tf2_msgs/msg/TFMessage"
WORLD_FRAME = "world"
# the description's own root link `world` (MuJoCo's world body), named `<ns>/world` as the robot's links are
WORLD_LINK = "world"
_FROM_WORLD_LINK = -2  # an entry's parent: the description's world link


class TfParams(RatedParams):
    rate: float = Field(50.0, gt=0, description="Publish rate of the moving transforms, sim Hz.")
    topic: str = Field("tf", description="Topic of the moving transforms.")
    static_topic: str = Field("tf_static", description="Topic of the fixed transforms.")
    static_period: float = Field(
        0.0, ge=0, description="Publish the fixed transforms again this often, sim seconds (0: only once)."
    )
    include_root: bool = Field(False, description="Also publish world -> root link.")


def _moves(body: Any) -> bool:
    return len(body.joints) > 0


class Tf(Plugin):
    Params = TfParams
    params: TfParams

    @classmethod
    def build(cls, params: TfParams, ctx: BuildContext, name: str) -> list[Topic]:
        bodies = [b for b in ctx.spec.bodies if b.name and b.name != "world"]
        root = ctx.body(ctx.root)
        children = [b for b in bodies if b.name != root.name]
        with_root = params.include_root or ctx.world_link  # (the world link's children are URDF joints)
        moving = any(_moves(b) for b in children) or (with_root and _moves(root))
        fixed = (
            any(not _moves(b) for b in children)
            or (with_root and not _moves(root))
            or (params.include_root and ctx.world_link)
        )
        topics = []
        if moving:
            topics.append(Topic(params.topic, TF_TYPE, "pub", params.rate))
        if fixed:
            period = params.static_period
            topics.append(Topic(params.static_topic, TF_TYPE, "pub", 1.0 / period if period else None))
        return topics

    def setup(self) -> None:
        p = self.params
        r = self.ctx.robot
        m = self.ctx.model
        # (parent body, -1 for the world or _FROM_WORLD_LINK; child body, -1 for the world link itself;
        # parent frame, child frame)
        self.moving: list[tuple[int, int, str, str]] = []
        self.fixed: list[tuple[int, int, str, str]] = []
        world_link = r.world_link  # the description's `world` root link: pose in the scenario's world
        if world_link is not None and p.include_root:
            self.fixed.append((-1, -1, WORLD_FRAME, r.frame(WORLD_LINK)))
        for b in sorted(r.body_ids):
            link = m.body(b).name.removeprefix(r.prefix)
            moves = int(m.body_jntnum[b]) > 0
            if world_link is not None and int(m.body_parentid[b]) == 0:
                entry = (_FROM_WORLD_LINK, b, r.frame(WORLD_LINK), r.frame(link))
            elif b == r.root_body:
                if not p.include_root:
                    continue
                entry = (-1, b, WORLD_FRAME, r.frame(link))
            else:
                parent = int(m.body_parentid[b])
                entry = (parent, b, r.frame(m.body(parent).name.removeprefix(r.prefix)), r.frame(link))
            (self.moving if moves else self.fixed).append(entry)
        T = msgs.T
        self.Msg, self.Stamped, self.Transform = (
            T[TF_TYPE],
            T["geometry_msgs/msg/TransformStamped"],
            T["geometry_msgs/msg/Transform"],
        )
        self.Vec, self.Quat = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
        self.pub = self.ctx.publisher(p.topic, TF_TYPE) if self.moving else None
        self.static_pub = self.ctx.publisher(p.static_topic, TF_TYPE) if self.fixed else None
        # A fixed link's pose in its parent is a constant of the model; the world -> welded root pose is
        # read once from the data (the robot's placement).
        self._world_link_inv: tuple[np.ndarray, np.ndarray] | None = None
        if world_link is not None:
            inv = (np.zeros(3), np.zeros(4))
            mujoco.mju_negPose(inv[0], inv[1], *world_link)
            self._world_link_inv = inv
        self.static_poses = [self._static_pose(parent, b) for parent, b, _pf, _cf in self.fixed]
        self.static_period_ns = round(p.static_period * 1e9)
        self.next_static_ns: int | None = 0
        self._q = np.zeros(4)
        self._quat = np.zeros(4)
        if self.pub:
            # moving links: one message of fixed shape, written in place (stamps and transforms)
            zero = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
            template = self.Msg(
                transforms=[self._stamped(0, pf, cf, *zero) for _p, _b, pf, cf in self.moving]
            )
            self.layout = self.pub.layout(
                template, [f"transforms[{i}].header.stamp" for i in range(len(self.moving))]
            )
            self.out = [self.layout.view(f"transforms[{i}].transform") for i in range(len(self.moving))]

    def after_step(self, now_ns: int) -> None:
        if self.static_pub and self.next_static_ns is not None and now_ns >= self.next_static_ns:
            tfs = [
                self._stamped(now_ns, pf, cf, pos, quat)
                for (_p, _b, pf, cf), (pos, quat) in zip(self.fixed, self.static_poses, strict=True)
            ]
            self.static_pub.publish(self.Msg(transforms=tfs), now_ns)
            period = self.static_period_ns
            self.next_static_ns = (now_ns // period + 1) * period if period else None
        if self.pub:
            d = self.ctx.data
            for (parent, b, _pf, _cf), out in zip(self.moving, self.out, strict=True):
                if parent == _FROM_WORLD_LINK:
                    pos, quat = self._from_world_link(d.xpos[b], d.xquat[b])
                elif parent < 0:
                    pos, quat = d.xpos[b], d.xquat[b]
                else:
                    pos, quat = self._relative(d, parent, b)
                out[0:3] = pos  # translation xyz, rotation xyzw
                out[3:6] = quat[1:]
                out[6] = quat[0]
            self.pub.publish_cdr(self.layout.encode(*[now_ns] * len(self.out)), now_ns)

    def _static_pose(self, parent: int, b: int) -> tuple[np.ndarray, np.ndarray]:
        """A fixed entry's pose: the world link's in the world, a link's below the world link, a welded
        root's in the world (the robot's placement, from the data), or a fixed link's in its parent."""
        m, d = self.ctx.model, self.ctx.data
        if b < 0:
            assert self.ctx.robot.world_link is not None
            pos, quat = self.ctx.robot.world_link
            return np.array(pos), np.array(quat)
        if parent == _FROM_WORLD_LINK:
            pos, quat = self._from_world_link(m.body_pos[b], m.body_quat[b])
            return np.array(pos), np.array(quat)
        if parent < 0:
            return np.array(d.xpos[b]), np.array(d.xquat[b])
        return m.body_pos[b], m.body_quat[b]

    def _from_world_link(self, pos: Any, quat: Any) -> tuple[np.ndarray, np.ndarray]:
        """A pose in the scenario's world as one in the description's world link."""
        assert self._world_link_inv is not None
        out_pos, out_quat = np.zeros(3), np.zeros(4)
        mujoco.mju_mulPose(
            out_pos, out_quat, *self._world_link_inv, np.asarray(pos, float), np.asarray(quat, float)
        )
        return out_pos, out_quat

    def _relative(self, d: Any, parent: int, child: int) -> tuple[np.ndarray, np.ndarray]:
        """The child's pose in its parent's frame: p = R_pᵀ (x_c - x_p), q = q_p⁻¹ q_c."""
        rot = d.xmat[parent].reshape(3, 3)
        pos = rot.T @ (d.xpos[child] - d.xpos[parent])
        mujoco.mju_negQuat(self._q, d.xquat[parent])
        mujoco.mju_mulQuat(self._quat, self._q, d.xquat[child])
        return pos, self._quat

    def _stamped(self, now_ns: int, parent: str, child: str, pos: Any, q: Any) -> Any:
        return self.Stamped(
            header=msgs.header(now_ns, parent),
            child_frame_id=child,
            transform=self.Transform(
                translation=self.Vec(x=float(pos[0]), y=float(pos[1]), z=float(pos[2])),
                rotation=self.Quat(x=float(q[1]), y=float(q[2]), z=float(q[3]), w=float(q[0])),
            ),
        )
