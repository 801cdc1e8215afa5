"""contact: a bumper on one link -> gazebo_msgs/ContactsState (like Gazebo's contact sensor with
libgazebo_ros_bumper).

At each tick the contacts that MuJoCo found between the link's collision geoms and anything else
(`data.contact`, forces from `mj_contactForce`) are grouped by pair of geoms into one `ContactState`
each; a message is published every tick, with no states when the link touches nothing (as
gazebo_ros_bumper does). Contacts between the robot's own bodies are left out unless `with_robot`.

Per state: `collision1_name` is the link's geom and `collision2_name` the other one (the MuJoCo geom
name, `<ns>/<collision name>`: a URDF `<collision>` without a name is `<link>_collision` as Gazebo names
it, e.g. `r1/base_link_collision`; the body's name for an unnamed geom of a world model); per contact
point: `contact_positions`, `contact_normals` (unit, pointing from the other object into the link: the
direction the link is pushed), `depths` (penetration, metres, >= 0) and `wrenches` (the contact force on
the link and its torque about the link's origin); `total_wrench` is their sum.

Vectors are expressed in the link's frame (the default `frame_id`, `<ns>/<link>`), or in the world frame
when `frame_id: world` (what gazebo_ros_bumper reports by default).
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
from pydantic import Field

from runner.plugin import BuildContext, Plugin, PluginConfigError, RatedParams, Topic
from runner.wire import msgs

CONTACTS_TYPE = "gazebo_msgs/msg/ContactsState"


class ContactParams(RatedParams):
    link: str = Field(description="Link whose contacts are reported.")
    rate: float = Field(20.0, gt=0, description="Publish rate, sim Hz.")
    topic: str = Field("bumper", description="Topic, relative to the robot's namespace.")
    frame_id: str | None = Field(
        None,
        description="Frame id in the header (default: <ns>/<link>). Positions, normals and wrenches are "
        "expressed in the link's frame, or in the world frame when this is `world`.",
    )
    with_robot: bool = Field(False, description="Also report contacts with the robot's own bodies.")


def _collides(m: Any, g: int) -> bool:
    return bool(m.geom_contype[g] or m.geom_conaffinity[g])


class Contact(Plugin):
    needs_forward = True  # contact forces come from the constraint solver
    Params = ContactParams
    params: ContactParams

    @classmethod
    def build(cls, params: ContactParams, ctx: BuildContext, name: str) -> list[Topic]:
        body = ctx.body(params.link)
        if not any(g.contype or g.conaffinity for g in body.geoms):
            raise PluginConfigError(
                f"link {params.link!r} has no collision geometry, so it can touch nothing",
                "link",
                hint="give the link a <collision> in the URDF, or pick another link",
            )
        return [Topic(params.topic, CONTACTS_TYPE, "pub", params.rate)]

    def setup(self) -> None:
        p = self.params
        r = self.ctx.robot
        self.body = r.body_id(p.link)
        self.frame_id = p.frame_id or r.frame(p.link)
        self.in_world = p.frame_id == "world"
        self._tables()
        self.pub = self.ctx.publisher(p.topic, CONTACTS_TYPE)
        T = msgs.T
        self.States, self.State = T[CONTACTS_TYPE], T["gazebo_msgs/msg/ContactState"]
        self.Wrench, self.Vec = T["geometry_msgs/msg/Wrench"], T["geometry_msgs/msg/Vector3"]
        self._f6 = np.zeros(6)

    def rebind(self) -> None:
        self._tables()  # (a spawned robot's geoms have ids past the old tables' ends)

    def _tables(self) -> None:
        """Per geom of the world: the link's own collision geoms, the robot's, every geom's name."""
        r, m = self.ctx.robot, self.ctx.model
        self.own = np.zeros(m.ngeom, dtype=bool)  # the link's collision geoms
        for g in range(m.ngeom):
            if int(m.geom_bodyid[g]) == self.body and _collides(m, g):
                self.own[g] = True
        self.robot = np.zeros(m.ngeom, dtype=bool)
        self.robot[r.geom_ids] = True
        self.names = [m.geom(g).name or m.body(int(m.geom_bodyid[g])).name for g in range(m.ngeom)]

    def contacts(self) -> list[tuple[int, int, np.ndarray, np.ndarray, float, np.ndarray, np.ndarray]]:
        """(link geom, other geom, position, normal into the link, depth, force on the link, contact
        torque on the link), all in world coordinates, for every active contact of the link now."""
        m, d = self.ctx.model, self.ctx.data
        n = int(d.ncon)
        if n == 0:
            return []
        con = d.contact
        geoms = np.asarray(con.geom[:n], dtype=np.int64)
        mine1, mine2 = self.own[geoms[:, 0]], self.own[geoms[:, 1]]
        hit = (mine1 | mine2) & (np.asarray(con.exclude[:n]) == 0)
        if not self.params.with_robot:
            other = np.where(mine1, geoms[:, 1], geoms[:, 0])
            hit &= ~self.robot[other]
        out = []
        for i in np.flatnonzero(hit):
            frame = np.asarray(con.frame[i]).reshape(3, 3)  # rows: normal (geom1 -> geom2), tangents
            mujoco.mj_contactForce(m, d, int(i), self._f6)
            # the force/torque in the contact frame is what geom1 exerts on geom2
            sign = -1.0 if mine1[i] else 1.0
            mine, other = (geoms[i, 0], geoms[i, 1]) if mine1[i] else (geoms[i, 1], geoms[i, 0])
            out.append(
                (
                    int(mine),
                    int(other),
                    np.array(con.pos[i]),
                    sign * frame[0],
                    max(0.0, -float(con.dist[i])),
                    sign * (frame.T @ self._f6[:3]),
                    sign * (frame.T @ self._f6[3:]),
                )
            )
        return out

    def after_step(self, now_ns: int) -> None:
        d = self.ctx.data
        origin = np.array(d.xpos[self.body])
        rot = np.eye(3) if self.in_world else np.array(d.xmat[self.body]).reshape(3, 3).T  # world -> out
        groups: dict[tuple[int, int], list[Any]] = {}
        for c in self.contacts():
            groups.setdefault((c[0], c[1]), []).append(c)
        states = []
        for (mine, other), points in groups.items():
            wrenches, positions, normals, depths = [], [], [], []
            total_f, total_t = np.zeros(3), np.zeros(3)
            for _mine, _other, pos, normal, depth, force, torque in points:
                tq = np.cross(pos - origin, force) + torque  # about the link's origin
                f_out, t_out = rot @ force, rot @ tq
                total_f += f_out
                total_t += t_out
                wrenches.append(self.Wrench(force=self._vec(f_out), torque=self._vec(t_out)))
                positions.append(self._vec(pos if self.in_world else rot @ (pos - origin)))
                normals.append(self._vec(rot @ normal))
                depths.append(depth)
            states.append(
                self.State(
                    info=f"{self.names[mine]} touches {self.names[other]} at {len(points)} point(s)",
                    collision1_name=self.names[mine],
                    collision2_name=self.names[other],
                    wrenches=wrenches,
                    total_wrench=self.Wrench(force=self._vec(total_f), torque=self._vec(total_t)),
                    contact_positions=positions,
                    contact_normals=normals,
                    depths=np.array(depths, dtype=np.float64),
                )
            )
        self.pub.publish(self.States(header=msgs.header(now_ns, self.frame_id), states=states), now_ns)

    def _vec(self, v: np.ndarray) -> Any:
        return self.Vec(x=float(v[0]), y=float(v[1]), z=float(v[2]))
