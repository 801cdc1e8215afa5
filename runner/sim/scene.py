"""What the world publishes for a 3D view (`foxglove.scene`, on by default): a recording, or a live run,
opens in Foxglove showing the world and the robots moving, with no set-up.

- `<run>/scene`: `foxglove.SceneUpdate` (protobuf, from foxglove-sdk): one entity per body that has visual
  geometry, in that body's frame (`world`, `r1/base_link`, `ball`), its geoms as cubes, spheres,
  cylinders and triangle meshes, with their colours; frame-locked, so they move with the transforms;
- `<run>/tf_static` and `<run>/tf`: `world` -> each robot's odometry frame (where the robot started, for a
  robot whose drive publishes odom -> base), `world` -> the root of a robot that nothing else places (no
  drive, its own `tf` plugin without `include_root`), and `world` -> each body of the world's own models
  (moving ones at `tf_rate`);
- `<run>/<ns>/tf` and `<ns>/tf_static`: every link of a robot relative to its parent, beside its drive's
  odom -> base (the `tf` plugin that compilation adds as `robot_state_publisher` to a robot with none);
- `<run>/<ns>/robot_description`: the robot's URDF (std_msgs/String), its link names prefixed with the
  namespace as the transforms name them (`r1/base_link`: robot_state_publisher's `frame_prefix`);
- `<run>/_model` (once, the compiled MJCF) and `<run>/_state` (qpos and mocap poses, at `tf_rate`): what
  `scenario render` replays a recording from.

The scene, the static transforms and the URDFs are sent at t = 0 and again every `1/rate` sim seconds:
the transport has no latching, and a viewer that seeks into a recording needs them near where it lands.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol

import mujoco
import numpy as np

from plugins._common import tf_transforms
from runner.frames import prefixed_urdf
from runner.plugin.registry import drive_frames
from runner.wire import msgs
from runner.wire.cdr import Layout

if TYPE_CHECKING:
    from runner.plan import RunPlan
    from runner.plugin import RobotHandle


class Outgoing(Protocol):
    def publish(self, msg: Any, stamp_ns: int) -> None: ...

    def publish_cdr(self, payload: bytes, stamp_ns: int) -> None: ...


class WorldView(Protocol):
    """What the scene needs of the world process (runner.sim.world.World): its plan, model and data, its
    robots, and publishers of its own (counted and stamped as the world's)."""

    plan: RunPlan
    model: mujoco.MjModel
    data: mujoco.MjData
    robots: list[RobotHandle]

    def make_publisher(self, key: str, type_name: str) -> Outgoing: ...


TF = "tf2_msgs/msg/TFMessage"
STATE = "std_msgs/msg/Float64MultiArray"
WORLD = "world"
VISUAL_GROUPS = 2  # MuJoCo draws geom groups 0-2: world primitives (0) and URDF visuals (1)
PLANE_SIZE = 20.0  # an infinite MuJoCo plane, drawn this large (m)
MAX_MESH_FACES = 50_000  # per mesh, beyond that a mesh is drawn by its bounding box


def _fox() -> Any:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import foxglove.messages as fm
    return fm


def _frame(m: mujoco.MjModel, body: int) -> str:
    return WORLD if body == 0 else (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, body) or f"body{body}")


def scene_update(m: mujoco.MjModel, stamp_ns: int, gone: Sequence[str] = ()) -> bytes:
    """Every body's visual geometry as one SceneUpdate, encoded (protobuf); `gone`: the entities of deleted
    robots, deleted (a viewer keeps an entity until it is)."""
    fm = _fox()
    per_body: dict[int, dict[str, list[Any]]] = {}
    for g in range(m.ngeom):
        if int(m.geom_group[g]) > VISUAL_GROUPS:
            continue
        mat = int(m.geom_matid[g])
        rgba = m.mat_rgba[mat] if mat >= 0 else m.geom_rgba[g]
        if rgba[3] <= 0:
            continue
        prims = per_body.setdefault(
            int(m.geom_bodyid[g]), {"cubes": [], "spheres": [], "cylinders": [], "triangles": []}
        )
        _add_geom(fm, m, g, rgba, prims)
    sec, nsec = divmod(stamp_ns, 1_000_000_000)
    entities = [
        fm.SceneEntity(
            timestamp=fm.Timestamp(sec=sec, nsec=nsec),
            frame_id=_frame(m, body),
            id=_frame(m, body),
            frame_locked=True,
            **{k: v for k, v in prims.items() if v},
        )
        for body, prims in sorted(per_body.items())
    ]
    deletions = [
        fm.SceneEntityDeletion(
            timestamp=fm.Timestamp(sec=sec, nsec=nsec), type=fm.SceneEntityDeletionType.MatchingId, id=frame
        )
        for frame in gone
    ]
    return bytes(fm.SceneUpdate(entities=entities, deletions=deletions).encode())


def _pose(fm: Any, pos: Any, quat: Any) -> Any:
    return fm.Pose(
        position=fm.Vector3(x=float(pos[0]), y=float(pos[1]), z=float(pos[2])),
        orientation=fm.Quaternion(x=float(quat[1]), y=float(quat[2]), z=float(quat[3]), w=float(quat[0])),
    )


def _add_geom(fm: Any, m: mujoco.MjModel, g: int, rgba: Any, prims: dict[str, list[Any]]) -> None:
    t = int(m.geom_type[g])
    size, pos, quat = m.geom_size[g], m.geom_pos[g], m.geom_quat[g]
    color = fm.Color(r=float(rgba[0]), g=float(rgba[1]), b=float(rgba[2]), a=float(rgba[3]))
    pose = _pose(fm, pos, quat)
    G = mujoco.mjtGeom

    def vec(x: float, y: float, z: float) -> Any:
        return fm.Vector3(x=float(x), y=float(y), z=float(z))

    if t == G.mjGEOM_BOX:
        prims["cubes"].append(fm.CubePrimitive(pose=pose, size=vec(*(2 * size)), color=color))
    elif t == G.mjGEOM_PLANE:
        sx, sy = (s if s > 0 else PLANE_SIZE / 2 for s in size[:2])
        prims["cubes"].append(fm.CubePrimitive(pose=pose, size=vec(2 * sx, 2 * sy, 0.001), color=color))
    elif t in (G.mjGEOM_SPHERE, G.mjGEOM_ELLIPSOID):
        radii = size if t == G.mjGEOM_ELLIPSOID else (size[0],) * 3
        prims["spheres"].append(
            fm.SpherePrimitive(pose=pose, size=vec(*(2 * np.asarray(radii))), color=color)
        )
    elif t in (G.mjGEOM_CYLINDER, G.mjGEOM_CAPSULE):
        r, h = size[0], size[1]
        prims["cylinders"].append(
            fm.CylinderPrimitive(
                pose=pose, size=vec(2 * r, 2 * r, 2 * h), bottom_scale=1.0, top_scale=1.0, color=color
            )
        )
        if t == G.mjGEOM_CAPSULE:  # the two caps
            rot = np.zeros(9)
            mujoco.mju_quat2Mat(rot, quat)
            axis = rot.reshape(3, 3)[:, 2]
            for sign in (-1.0, 1.0):
                prims["spheres"].append(
                    fm.SpherePrimitive(
                        pose=_pose(fm, pos + sign * h * axis, quat),
                        size=vec(2 * r, 2 * r, 2 * r),
                        color=color,
                    )
                )
    elif t == G.mjGEOM_MESH:
        mesh = int(m.geom_dataid[g])
        faces = m.mesh_face[m.mesh_faceadr[mesh] : m.mesh_faceadr[mesh] + m.mesh_facenum[mesh]]
        verts = m.mesh_vert[m.mesh_vertadr[mesh] : m.mesh_vertadr[mesh] + m.mesh_vertnum[mesh]]
        if len(faces) > MAX_MESH_FACES:
            lo, hi = verts.min(axis=0), verts.max(axis=0)
            center = _pose(fm, pos + (lo + hi) / 2, quat)
            prims["cubes"].append(fm.CubePrimitive(pose=center, size=vec(*(hi - lo)), color=color))
            return
        points = [fm.Point3(x=float(x), y=float(y), z=float(z)) for x, y, z in verts[faces.reshape(-1)]]
        prims["triangles"].append(fm.TriangleListPrimitive(pose=pose, points=points, color=color))


class SceneFeed:
    """The world's hooks for the 3D view (see the module docstring)."""

    def __init__(self, world: WorldView, gone: Sequence[str] = (), stamp_ns: int = 0):
        """`gone`: the body frames of robots deleted (runner.sim.grow), deleted from the view."""
        plan, m, d = world.plan, world.model, world.data
        self.world = world
        deleted = getattr(world, "deleted", {})
        rate = plan.foxglove.rate
        self.period_ns = round(1e9 / rate)
        self.tf_period_ns = round(1e9 / plan.foxglove.tf_rate)
        make = world.make_publisher
        self.scene_out = make(f"{plan.name}/scene", "foxglove.SceneUpdate")
        self.scene_bytes = scene_update(m, stamp_ns, gone)
        self._model_due = True  # the model goes out once: at the start, and again when it changed
        self.descriptions = [
            (
                make(f"{plan.name}/{r.namespace}/robot_description", "std_msgs/msg/String"),
                prefixed_urdf(r.urdf, r.namespace),
            )
            for r in plan.robots
            if r.urdf and r.name not in deleted
        ]
        robot_bodies = {b for h in world.robots for b in h.body_ids}
        # world -> odom of each driven robot: where its base started (odometry starts at zero there)
        self.static: list[tuple[str, str, np.ndarray, np.ndarray]] = []
        self.moving: list[int] = []
        self._frames: list[str] = []
        for h in world.robots:
            frames = next(
                (f for p in h.plan.plugins if (f := drive_frames(p.type, p.params)) is not None), None
            )
            if frames is not None:
                odom = f"{h.namespace}/{frames[0]}" if h.namespace else frames[0]
                self.static.append(
                    (WORLD, odom, np.array(d.xpos[h.root_body]), np.array(d.xquat[h.root_body]))
                )
            elif not any(p.type == "tf" and p.params.get("include_root") for p in h.plan.plugins):
                # nobody says where this robot is (its own `tf` plugin leaves the root out): world -> root
                root = h.frame(h.root_link)
                if h.world_link is not None:
                    # the description's root link `world` is the robot's frame `<ns>/world` (its `tf`
                    # publishes the links below it): world -> <ns>/world, the robot's pose
                    pos, quat = h.world_link
                    self.static.append((WORLD, h.frame(WORLD), np.array(pos), np.array(quat)))
                    continue
                if int(m.body_jntnum[h.root_body]) > 0:
                    self.moving.append(h.root_body)
                    self._frames.append(root)
                else:
                    self.static.append(
                        (WORLD, root, np.array(d.xpos[h.root_body]), np.array(d.xquat[h.root_body]))
                    )
        # the world's own models: moving (a free ball) or not
        for b in range(1, m.nbody):
            if b in robot_bodies or int(m.body_parentid[b]) != 0:
                continue
            if int(m.body_jntnum[b]) > 0 or int(m.body_mocapid[b]) >= 0:  # free, or an actor
                self.moving.append(b)
                self._frames.append(_frame(m, b))
            else:
                self.static.append((WORLD, _frame(m, b), np.array(d.xpos[b]), np.array(d.xquat[b])))
        # for `scenario render`: the model (MJCF) once, and the state (qpos, mocap poses) at tf_rate
        self.model_out = make(f"{plan.name}/_model", "std_msgs/msg/String")
        self.mjcf = plan.mjcf
        self.state_out = make(f"{plan.name}/_state", STATE)
        self.static_out = make(f"{plan.name}/tf_static", TF) if self.static else None
        self.tf_out = make(f"{plan.name}/tf", TF) if self.moving else None
        T = msgs.T
        self._layout = T["std_msgs/msg/MultiArrayLayout"](
            dim=[
                T["std_msgs/msg/MultiArrayDimension"](label="qpos+mocap", size=m.nq + 7 * m.nmocap, stride=1)
            ],
            data_offset=0,
        )
        # both written in place every 1/tf_rate (twenty actors are twenty more transforms and poses)
        self._state = _FixedState(T[STATE](layout=self._layout, data=np.zeros(m.nq + 7 * m.nmocap)))
        self._tf = _FixedTf(self._frames) if self.moving else None
        self._bodies = np.asarray(self.moving, dtype=np.int64)

    def hooks(self) -> list[tuple[Any, int]]:
        return [(self.slow, self.period_ns), (self.fast, self.tf_period_ns)]

    def slow(self, now_ns: int) -> None:
        if self._model_due:
            self._model_due = False
            self.model_out.publish(msgs.T["std_msgs/msg/String"](data=self.mjcf), now_ns)
        self.scene_out.publish_cdr(self.scene_bytes, now_ns)
        for out, urdf in self.descriptions:
            out.publish(msgs.T["std_msgs/msg/String"](data=urdf), now_ns)
        if self.static_out is not None:
            self.static_out.publish(tf_transforms(now_ns, self.static), now_ns)

    def fast(self, now_ns: int) -> None:
        d = self.world.data
        self.state_out.publish_cdr(self._state.encode(d), now_ns)
        if self.tf_out is None or self._tf is None:
            return
        self.tf_out.publish_cdr(self._tf.encode(now_ns, d, self._bodies), now_ns)


class _FixedState:
    """`<run>/_state` written in place: qpos, then the mocap positions and orientations (the bytes rosbags
    would write for the message)."""

    def __init__(self, template: Any):
        self.layout = Layout(STATE, template, [])
        self.data = self.layout.view("data")

    def encode(self, d: mujoco.MjData) -> bytes:
        nq, nm = d.qpos.shape[0], d.mocap_pos.shape[0]
        out = self.data
        out[:nq] = d.qpos
        out[nq : nq + 3 * nm] = d.mocap_pos.reshape(-1)
        out[nq + 3 * nm :] = d.mocap_quat.reshape(-1)
        return bytes(self.layout.buf)


class _FixedTf:
    """`world` -> each moving world body (a free model, an actor), one TFMessage of fixed shape written in
    place with a few array operations, however many bodies: every transform's stamp and its seven numbers
    (translation, rotation xyzw) are put at their byte offsets at once."""

    def __init__(self, frames: list[str]):
        n = len(frames)
        zero = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
        self.layout = Layout(TF, tf_transforms(0, [(WORLD, f, *zero) for f in frames]), [])
        buf = self.layout.buf
        spans = self.layout.spans
        at = np.array([spans[f"transforms[{i}].transform"].offset for i in range(n)], dtype=np.int64)
        stamp = np.array([spans[f"transforms[{i}].header.stamp"].offset for i in range(n)], dtype=np.int64)
        # CDR aligns doubles to 8 and integers to 4 bytes after the 4-byte encapsulation header
        assert not ((at - 4) % 8).any() and not ((stamp - 4) % 4).any()
        self.f64 = np.frombuffer(buf, dtype="<f8", offset=4, count=(len(buf) - 4) // 8)
        self.u32 = np.frombuffer(buf, dtype="<u4", offset=4, count=(len(buf) - 4) // 4)
        self.at = ((at - 4) // 8)[:, None] + np.arange(7)
        self.sec = (stamp - 4) // 4
        self.nsec = self.sec + 1
        self.values = np.zeros((n, 7))

    def encode(self, now_ns: int, d: mujoco.MjData, bodies: np.ndarray) -> bytes:
        v = self.values
        v[:, :3] = d.xpos[bodies]
        q = d.xquat[bodies]
        v[:, 3:6] = q[:, 1:]
        v[:, 6] = q[:, 0]
        self.f64[self.at] = v
        self.u32[self.sec] = now_ns // 1_000_000_000
        self.u32[self.nsec] = now_ns % 1_000_000_000
        return bytes(self.layout.buf)
