"""Simulation control (`Control`, a part of `World`): pause, unpause, step N while paused, reset, get and
set an entity's pose and twist, as World methods and as the world's own services (`RunPlan.world_services`,
runner.plan.control_services) under gazebo_ros's names and ros_gz's.

Pause: the loop keeps taking messages and answering services while paused (`_idle`); sim time stands
still, and the pacing against wall time starts again from where it stood (it never runs fast to catch up).
The run's `duration` is sim time: a paused run goes on until it is unpaused or stopped.

reset_simulation (gazebo_ros_init.cpp:294-299, World::Reset): time back to 0 and everything as at the start:
the model's data reset (`mj_resetData`, the same MjData), the hardware's start state, every plugin made
again from its parameters with its random stream seeded again, the clock, timeline and events from their
start (`World._build`). What the world publishes after it is byte for byte what a fresh run publishes. The
recording's log time (the attachment's stamp) keeps going forward: it is the sim time run since the start
of the run, resets included (`Outgoing.epoch`), while the messages' own times (the clock, headers) start
again from 0; the reset request's `_service_event` marks the place.

reset_world (gazebo_ros_init.cpp:301-306, World::ResetEntities(Base::MODEL)): every body back to its
start pose with no velocity, time goes on; the plugins keep their state (Gazebo also calls each model
plugin's Reset(); ours have none).

get/set entity state (gazebo_ros_state.cpp:183-239 and 241-312): an entity is a robot (its root link), a
world model, or `model::link`; `reference_frame` empty or `world` is the world frame, another entity's name
its frame (pose relative to it, velocities rotated into it), anything else fails. The twist is the body's
origin's, both vectors in the world frame (in the reference's with one). Set moves a free body (a robot
that is not welded to the world, a world model that is not static) or an actor's mocap body.
"""

from __future__ import annotations

import copy
import math
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from runner.wire import msgs

if TYPE_CHECKING:
    from runner.plan import RunPlan
    from runner.plugin import RobotHandle

Reply = Callable[[Any], None]


class EntityError(ValueError):
    """A request about an entity that cannot be answered: unknown, not movable."""


class Control:
    """Pause, step, reset and entity state (see the module's docstring). `World.__init__` calls
    `_init_control` before anything else of it, and `_serve_control` once everything is made."""

    plan: RunPlan
    model: mujoco.MjModel
    data: mujoco.MjData
    now_ns: int
    step_ns: int
    robots: list[RobotHandle]
    _epoch: list[int]

    def _init_control(self) -> None:
        self._model0 = copy.copy(self.model)  # as compiled (reset_simulation puts it back)
        self.paused = False
        self.steps_left = 0  # physics steps still to run while paused (step N)
        self._rewind: list[Callable[[], None]] | None = None  # a reset_simulation due: who to answer then
        self._stepped: list[Callable[[], None]] = []  # step requests answered once their steps are taken
        self.resets = 0  # reset_simulation done so far
        self.calls_made: set[int] = set()  # the timeline's `call` entries made (once per run)
        self.event_calls_made: set[tuple[int, int]] = set()  # (event, action) of events' calls made
        self._start_qpos: np.ndarray | None = None
        self._rebuilding = False

    # ------------------------------------------------------------------------------ the operations
    def pause(self) -> None:
        self.paused = True

    def unpause(self) -> None:
        self.paused = False
        self.steps_left = 0

    def step(self, n: int) -> None:
        """Run `n` physics steps, then stand still again; only while paused."""
        if not self.paused:
            raise EntityError("the world is running: pause it first (a step is taken only while paused)")
        if n < 1:
            raise EntityError(f"a step of {n} physics steps: expected 1 or more")
        self.steps_left += n

    def reset_simulation(self) -> None:
        """Time back to 0 and the world as at the start (the module's docstring). Called at a step boundary
        by the loop (a service asks for it with `_rewind`); then the loop runs the boundary at t = 0."""
        w: Any = self  # (the World: its parts, without importing it)
        for plugin in w.plugins:
            plugin.close()
        for out in w._out.values():
            out.fault = None  # (an event's fault on a topic: the events start again)
        for subscribers in w._local.values():
            subscribers.clear()  # (the same lists as the publishers' `local`: emptied in place)
        m, d = self.model, self.data
        # the model as compiled: the hardware and plugins change some of it as they start (armature,
        # gains, damping), after the start's mj_forward; they change it again as they start again
        restore_model(m, self._model0)
        mujoco.mj_resetData(m, d)
        w._apply_deleted()  # (deleted robots stay out: Gazebo's reset does not bring a deleted model back)
        mujoco.mj_forward(m, d)
        self._epoch[0] += self.now_ns
        self.now_ns = 0
        self.resets += 1
        self.steps_left = 0  # (steps asked before the reset are not taken after it; paused stays paused)
        self._rebuilding = True
        try:
            w._build(remote=bool(w.remote_renders))
        finally:
            self._rebuilding = False

    def renderer_reset(self, epoch_ns: int) -> None:
        """In a renderer process: the world it renders for was reset (`reset_simulation`), its sim time run
        before that now `epoch_ns`: the rendering plugins made again from the model as compiled."""
        w: Any = self
        for plugin in w.plugins:
            plugin.close()
        for subscribers in w._local.values():
            subscribers.clear()
        restore_model(self.model, self._model0)
        mujoco.mj_resetData(self.model, self.data)
        mujoco.mj_forward(self.model, self.data)
        self._epoch[0] = epoch_ns
        self._rebuilding = True
        try:
            w._build(remote=False)
        finally:
            self._rebuilding = False

    def reset_world(self) -> None:
        """Bodies back to their start poses, at rest; time and plugins go on."""
        m, d = self.model, self.data
        if self._start_qpos is None:
            raise EntityError("the world's start state is not known")
        d.qpos[:] = self._start_qpos
        d.qvel[:] = 0
        d.act[:] = 0
        d.qacc_warmstart[:] = 0
        for b in range(m.nbody):
            mocap = int(m.body_mocapid[b])
            if mocap >= 0:
                d.mocap_pos[mocap] = m.body_pos[b]
                d.mocap_quat[mocap] = m.body_quat[b]
        mujoco.mj_forward(m, d)

    def remember_start(self) -> None:
        """The positions `reset_world` puts back: those at the start, the hardware's start state included."""
        self._start_qpos = self.data.qpos.copy()

    # ---------------------------------------------------------------------------------- entities
    def body_of(self, name: str) -> int:
        """The MuJoCo body of an entity name: a robot (its root link), `robot::link`, a world model, or
        `model::link` of an SDF world's model."""
        m = self.model
        for r in self.robots:
            if name == r.name:
                return r.root_body
            if name.startswith(r.name + "::"):
                b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, r.prefix + name[len(r.name) + 2 :])
                if b >= 0:
                    return b
        for candidate in (name, name.replace("::", "/")):
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, candidate)
            if b > 0:
                return b
        known = [r.name for r in self.robots] + [
            n for b in range(1, m.nbody) if (n := m.body(b).name) and "/" not in n
        ]
        known += [n for g in range(m.ngeom) if (n := m.geom(g).name) and self._static_geom(n) >= 0]
        raise EntityError(f"entity [{name}] does not exist (known: {', '.join(sorted(known)) or 'none'})")

    def _frame(self, reference: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
        """A reference frame's (pos, 3x3 rotation, linear and angular velocity), None for the world."""
        if reference in ("", "world"):
            return None
        g = self._static_geom(reference)
        if g >= 0:
            d = self.data
            return d.geom_xpos[g].copy(), d.geom_xmat[g].reshape(3, 3).copy(), np.zeros(3), np.zeros(3)
        try:
            b = self.body_of(reference)
        except EntityError:
            raise EntityError(f"reference entity [{reference}] not found") from None
        lin, ang = self._velocity(b)
        return self.data.xpos[b].copy(), self.data.xmat[b].reshape(3, 3).copy(), lin, ang

    def _velocity(self, b: int) -> tuple[np.ndarray, np.ndarray]:
        """The body's origin's linear and angular velocity, in the world frame."""
        v = np.zeros(6)
        mujoco.mj_objectVelocity(self.model, self.data, mujoco.mjtObj.mjOBJ_BODY, b, v, 0)
        return v[3:].copy(), v[:3].copy()

    def _static_geom(self, name: str) -> int:
        """A static world model (a shape of the world body, named as the model), or -1."""
        g = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, name)
        return g if g >= 0 and int(self.model.geom_bodyid[g]) == 0 and name != "ground" else -1

    def entity_state(self, name: str, reference: str = "") -> dict[str, Any]:
        """`{pose: {position, orientation}, twist: {linear, angular}}` (gazebo_msgs/EntityState's fields)."""
        d = self.data
        g = self._static_geom(name)
        if g >= 0:
            pos, rot = d.geom_xpos[g].copy(), d.geom_xmat[g].reshape(3, 3).copy()
            lin, ang = np.zeros(3), np.zeros(3)
        else:
            b = self.body_of(name)
            pos, rot = d.xpos[b].copy(), d.xmat[b].reshape(3, 3).copy()
            lin, ang = self._velocity(b)
        frame = self._frame(reference)
        if frame is not None:  # gazebo_ros_state.cpp:203-213: pose - frame, velocities into the frame
            fpos, frot, flin, fang = frame
            pos, rot = frot.T @ (pos - fpos), frot.T @ rot
            lin, ang = frot.T @ (lin - flin), frot.T @ (ang - fang)
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, rot.ravel())
        return {
            "pose": {"position": _xyz(pos), "orientation": _quat(quat)},
            "twist": {"linear": _xyz(lin), "angular": _xyz(ang)},
        }

    def set_entity_state(
        self,
        name: str,
        position: Any,
        orientation: Any,
        linear: Any = None,
        angular: Any = None,
        reference: str = "",
    ) -> None:
        """Move an entity (gazebo_ros_state.cpp:241-312): a zero quaternion counts as no rotation, others
        are normalised; velocities are in the reference's frame (None: left as they are)."""
        if self._static_geom(name) >= 0:
            raise EntityError(f"entity [{name}] is a static model: it does not move")
        b = self.body_of(name)
        m, d = self.model, self.data
        pos = np.asarray(position, float)
        quat = np.asarray(orientation, float)  # w x y z
        values = [
            *pos,
            *quat,
            *(linear if linear is not None else ()),
            *(angular if angular is not None else ()),
        ]
        if not all(math.isfinite(float(v)) for v in values):
            raise EntityError("the pose or twist holds a NaN or Inf")
        norm = float(np.linalg.norm(quat))
        quat = np.array([1.0, 0, 0, 0]) if norm < 1e-12 else quat / norm
        frame = self._frame(reference)
        lin = None if linear is None else np.asarray(linear, float)
        ang = None if angular is None else np.asarray(angular, float)
        if frame is not None:  # gazebo_ros_state.cpp:268-275: pose + frame, velocities out of the frame
            frot = frame[1]
            pos, quat = out_of_frame(frame, pos, quat)
            lin = None if lin is None else frot @ lin
            ang = None if ang is None else frot @ ang
        mocap = int(m.body_mocapid[b])
        jnt = int(m.body_jntadr[b])
        if mocap >= 0:
            d.mocap_pos[mocap] = pos
            d.mocap_quat[mocap] = quat
        elif jnt >= 0 and int(m.jnt_type[jnt]) == int(mujoco.mjtJoint.mjJNT_FREE):
            qa, va = int(m.jnt_qposadr[jnt]), int(m.jnt_dofadr[jnt])
            d.qpos[qa : qa + 3] = pos
            d.qpos[qa + 3 : qa + 7] = quat
            if lin is not None:
                d.qvel[va : va + 3] = lin
            if ang is not None:  # a free joint's angular velocity is in the body's frame
                rot = np.zeros(9)
                mujoco.mju_quat2Mat(rot, quat)
                d.qvel[va + 3 : va + 6] = rot.reshape(3, 3).T @ ang
        else:
            what = m.body(b).name
            raise EntityError(
                f"entity [{name}] cannot be moved: its body {what!r} is welded to the world or to its parent "
                "(a fixed robot, a static model, or a link inside a model: Gazebo would move the link alone)"
            )
        mujoco.mj_forward(m, d)

    # -------------------------------------------------------------------------------- the services
    def _serve_control(self) -> None:
        w: Any = self  # (the World: its parts, without importing it)
        handlers: dict[str, Callable[[Any, Reply], None]] = {
            "reset_simulation": self._srv_reset_simulation,
            "reset_world": self._srv_reset_world,
            "pause_physics": self._srv_pause,
            "unpause_physics": self._srv_unpause,
            "get_entity_state": self._srv_get_state,
            "set_entity_state": self._srv_set_state,
            "spawn_entity": self._srv_spawn,
            "delete_entity": self._srv_delete,
            "control": self._srv_control,
            "set_pose": self._srv_set_pose,
            "create": self._srv_create,
            "remove": self._srv_remove,
        }
        for sp in self.plan.world_services:
            w.serve(sp.key, sp.type, handlers[sp.key.rsplit("/", 1)[1]])
        self.remember_start()

    def _steps_taken(self) -> None:
        """The steps asked are taken (or dropped by an unpause or a reset): their requests answered."""
        answers, self._stepped = self._stepped, []
        for answer in answers:
            answer()

    def _empty(self, reply: Reply) -> None:
        reply(msgs.T["std_srvs/srv/Empty_Response"]())

    def _srv_reset_simulation(self, _req: Any, reply: Reply) -> None:
        self._rewind = [*(self._rewind or []), lambda: self._empty(reply)]

    def _srv_reset_world(self, _req: Any, reply: Reply) -> None:
        self.reset_world()
        self._empty(reply)

    def _srv_pause(self, _req: Any, reply: Reply) -> None:
        self.pause()
        self._empty(reply)

    def _srv_unpause(self, _req: Any, reply: Reply) -> None:
        self.unpause()
        self._empty(reply)

    def _srv_get_state(self, req: Any, reply: Reply) -> None:
        header = {"stamp": _stamp(self.now_ns), "frame_id": req.reference_frame}
        try:
            state = self.entity_state(req.name, req.reference_frame)
        except EntityError as e:
            self._said(f"get_entity_state: {e}")
            reply(msgs.from_data("gazebo_msgs/srv/GetEntityState_Response", {"header": header}))
            return
        state.update(name=req.name, reference_frame=req.reference_frame)
        response = {"header": header, "state": state, "success": True}
        reply(msgs.from_data("gazebo_msgs/srv/GetEntityState_Response", response))

    def _srv_set_state(self, req: Any, reply: Reply) -> None:
        s = req.state
        p, o, tl, ta = s.pose.position, s.pose.orientation, s.twist.linear, s.twist.angular
        try:
            self.set_entity_state(
                s.name,
                (p.x, p.y, p.z),
                (o.w, o.x, o.y, o.z),
                (tl.x, tl.y, tl.z),
                (ta.x, ta.y, ta.z),
                s.reference_frame,
            )
            ok = True
        except EntityError as e:
            self._said(f"set_entity_state: {e}")
            ok = False
        reply(msgs.T["gazebo_msgs/srv/SetEntityState_Response"](success=ok))

    def _srv_set_pose(self, req: Any, reply: Reply) -> None:
        """ros_gz SetEntityPose: by name (an id is not ours to know: it is refused); velocities untouched."""
        p, o = req.pose.position, req.pose.orientation
        try:
            if not req.entity.name:
                raise EntityError("an entity by id only: give its name (ids are Gazebo Sim's)")
            self.set_entity_state(req.entity.name, (p.x, p.y, p.z), (o.w, o.x, o.y, o.z))
            ok = True
        except EntityError as e:
            self._said(f"set_pose: {e}")
            ok = False
        reply(msgs.T["ros_gz_interfaces/srv/SetEntityPose_Response"](success=ok))

    def _srv_control(self, req: Any, reply: Reply) -> None:
        """ros_gz ControlWorld, as gz-sim's SimulationRunner takes a WorldControl (gz-sim8
        src/SimulationRunner.cc:1331-1372 OnWorldControlState, 1433-1466 ProcessWorldControl): `pause` sets
        the state every time (false runs the world); `multi_step` (or `step`: 1) steps are taken only when
        the request leaves the world paused, then it stands still again; `reset.all` or `reset.time_only`
        rewinds (reset_simulation: gz-sim rewinds for both); `run_to_sim_time` runs the world until then and
        pauses it. Where we differ, on purpose: `reset.model_only` (gz-sim: "not supported", nothing done)
        is reset_world here; the answer comes once the steps are taken (gz-sim answers at once), so a
        script that steps and then reads sees the world after the steps. `seed` is said and ignored, as
        gz-sim does."""
        c = req.world_control
        response = msgs.T["ros_gz_interfaces/srv/ControlWorld_Response"]
        if c.seed != 0:
            self._said('control: `seed` is not supported (gz-sim: "Changing seed is not supported.")')
        until_ns = int(c.run_to_sim_time.sec) * 1_000_000_000 + int(c.run_to_sim_time.nanosec)
        steps = c.multi_step or (1 if c.step else 0)
        if c.reset.model_only and not (c.reset.all or c.reset.time_only):
            self.reset_world()
        if c.pause:
            self.pause()
        else:
            self.unpause()

        def answer() -> None:
            taken = 0
            if c.pause and steps:
                taken = steps
            elif not c.pause and until_ns > self.now_ns:
                # run until then and pause (as a paused world stepped to that time)
                self.pause()
                taken = math.ceil((until_ns - self.now_ns) / self.step_ns)
            if taken:
                self.step(taken)
                # answered once the steps are taken (at the boundary they end at, its sensors published)
                self._stepped.append(lambda: reply(response(success=True)))
            else:
                reply(response(success=True))

        if c.reset.all or c.reset.time_only:  # the rewind first (at the end of this step), then the rest
            self._rewind = [*(self._rewind or []), answer]
            return
        answer()

    def _said(self, text: str) -> None:
        """A refused request, on stderr (as gazebo_ros logs RCLCPP_ERROR), at its sim time."""
        print(f"world: t = {self.now_ns / 1e9:.3f} s: {text}", file=sys.stderr)


def out_of_frame(
    frame: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], pos: np.ndarray, quat: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A pose given in `frame` (`Control._frame`'s: position, rotation, ...) in the world: the frame's pose
    composed with it (gazebo_ros_state.cpp:268-275, gazebo_ros_factory.cpp:174-188)."""
    fpos, frot = frame[0], frame[1]
    fq, q = np.zeros(4), np.zeros(4)
    mujoco.mju_mat2Quat(fq, frot.ravel())
    mujoco.mju_mulQuat(q, fq, quat)
    return fpos + frot @ pos, q


def restore_model(m: mujoco.MjModel, m0: mujoco.MjModel) -> None:
    """Every number of `m` (arrays, options, visual, statistics) set back to `m0`'s, in place: plugins keep
    the model they hold. (Both are the same compiled model: same sizes.)"""
    for name in dir(m0):
        if name.startswith("_"):
            continue
        value = getattr(m0, name, None)
        if isinstance(value, np.ndarray) and value.size:
            target = getattr(m, name)
            if target.flags.writeable:
                target[...] = value
    for struct in ("opt", "vis", "stat"):
        _restore_struct(getattr(m, struct), getattr(m0, struct))


def _restore_struct(target: Any, source: Any, depth: int = 0) -> None:
    """MjOption, MjVisual (nested), MjStatistic: their numbers and arrays, from `source`."""
    for name in dir(source):
        if name.startswith("_"):
            continue
        value = getattr(source, name)
        if isinstance(value, np.ndarray):
            getattr(target, name)[...] = value
        elif isinstance(value, int | float):
            setattr(target, name, value)
        elif depth < 2 and type(value).__module__.startswith("mujoco") and not callable(value):
            _restore_struct(getattr(target, name), value, depth + 1)


def _xyz(v: Any) -> dict[str, float]:
    return {"x": float(v[0]), "y": float(v[1]), "z": float(v[2])}


def _quat(q: Any) -> dict[str, float]:
    return {"w": float(q[0]), "x": float(q[1]), "y": float(q[2]), "z": float(q[3])}


def _stamp(ns: int) -> dict[str, int]:
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}
