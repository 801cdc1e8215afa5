"""Robots spawned into and deleted from a running world (`Grow`, a part of `World`): gazebo_ros's
`/spawn_entity` and `/delete_entity` (gazebo_ros_factory.cpp), ros_gz's `/world/<w>/create` and `/remove`
(gz-sim's UserCommands), and `World.spawn_robot` / `World.delete_robot` for our own nodes and the timeline.

Spawn. The robot is compiled against the world as it stands (runner.compile.spawn: its URDF's plugins and
hardware, its namespace, the pose asked for) and attached after everything else, so what was there keeps
its MuJoCo ids. MuJoCo cannot add a body to a compiled model: the world swaps its model and data for the
new ones, between two steps:
- the state carried over (positions, velocities, actuator states, controls, applied forces, warm start,
  sensor values, mocap poses, time) and what the plugins and the hardware changed of the model as they ran
  (gains, armature, force ranges: every number of the model that differs from the model as compiled);
- everything that holds the model or data given the new ones: robot handles, the hardware, the events
  and actors, the contact watch, the 3D view, and every plugin (`ctx.model`, `ctx.data`, then its
  `rebind()`: views, renderers, per-geom tables made again). A plugin that still holds a view of the old
  data or the old model after it is said on stderr, once, by name;
- the new robot's hardware started (its joints at their initial values, its servos holding them), its
  plugins made and set up as a run's are, its topics and services declared (the bridge shows them to ROS 2
  as they appear), its description and transforms in the 3D view.
reset_simulation keeps a spawned robot, at the pose it was spawned at (Gazebo keeps spawned models through
a reset); reset_world puts it back there.

Delete. MuJoCo cannot take a body out either, and taking one out would renumber what comes after it. So a
deleted robot's plugins are closed and its topics and services withdrawn (gone from the graph and from
ROS 2), its hardware no longer kept, and its bodies stay where they were, out of the world: no contacts
(contype and conaffinity 0), not drawn nor seen by cameras and rays (alpha 0: mj_ray skips a geom it cannot
see), held still (its joints put back at each boundary), removed from the 3D view. Its name can be taken
again: the next spawn renames its elements (`~deleted~r2/...`) as it compiles.
"""

from __future__ import annotations

import copy
import json
import sys
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from runner.compile.spawn import SpawnError, check_prefix, compile_spawn
from runner.plugin import RobotHandle

if TYPE_CHECKING:
    from runner.plan import RobotPlan, RunPlan
    from runner.plugin import Plugin


class Grow:
    """Spawn and delete (see the module's docstring). `World.__init__` calls `_init_grow` first."""

    plan: RunPlan
    model: mujoco.MjModel
    data: mujoco.MjData
    robots: list[RobotHandle]
    plugins: list[Plugin]
    now_ns: int

    def _init_grow(self) -> None:
        self.deleted: dict[str, RobotPlan] = {}  # deleted robots, by name (their bodies stay: module doc)
        self._renamed: list[str] = []  # their name prefixes, renamed out of the way at the next spawn
        self._frozen_q = np.zeros(0, dtype=np.int64)  # qpos / qvel addresses of deleted robots' joints
        self._frozen_v = np.zeros(0, dtype=np.int64)
        self._frozen_at = np.zeros(0)
        self.generation = 0  # how many times the model was swapped (the loop takes the new one then)
        # namespace -> (key, entry) of each subscription its plugins made (runner.sim.pubsub)
        self._subs_of: dict[str, list[tuple[str, Any]]] = {}
        self._stale_said: set[str] = set()
        self._generations: dict[int, bytes] = {}  # what renderer processes fetch (`_next_generation`)
        self._model_queryable: Any = None
        self.gone_counts: dict[str, int] = {}  # messages published on keys withdrawn (deleted robots)
        self._retired_renders: list[Any] = []  # a deleted robot's links to renderer processes

    # ------------------------------------------------------------------------------------------ spawn
    def entity_names(self) -> set[str]:
        """The names an entity may not take: robots, world models (bodies and static shapes)."""
        m = self.model
        names = {r.name for r in self.robots}
        names |= {n for b in range(1, m.nbody) if (n := m.body(b).name) and "/" not in n}
        names |= {n for g in range(m.ngeom) if (n := m.geom(g).name) and int(m.geom_bodyid[g]) == 0}
        return names

    def spawn_robot(
        self,
        name: str,
        xml: str,
        namespace: str | None = None,
        position: tuple[float, float, float] = (0.0, 0.0, 0.0),
        quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0),
    ) -> RobotPlan:
        """The robot `name` (URDF text) put into the running world (the module's docstring); SpawnError says
        why not."""
        if not name:
            raise SpawnError("the entity has no name")
        if name in self.entity_names():
            raise SpawnError(f"Entity [{name}] already exists.")
        ns = (namespace or "").strip("/") or name
        taken = {r.namespace for r in self.robots}
        if ns in taken:
            raise SpawnError(f"the namespace {ns!r} is robot {self._robot_of_ns(ns)!r}'s: give another one")
        if self.plan.spawn is None:
            raise SpawnError("this world was compiled without what a spawn needs (an older plan)")
        old = self.model
        spawned = compile_spawn(
            self.plan.mjcf,
            self.plan.spawn,
            self.plan.scenario_file,
            name=name,
            xml=xml,
            namespace=None if ns == name else ns,
            position=position,
            quat=quat,
            hidden=self._renamed,
        )
        model = mujoco.MjModel.from_xml_string(spawned.mjcf)
        moved = check_prefix(old, model)
        if moved is not None:  # (attaching last keeps every id: a MuJoCo that orders otherwise is caught)
            raise SpawnError(f"the robot cannot be added without renumbering the world ({moved})")
        for notice in spawned.notices:
            print(f"world: spawn {name}: {notice}", file=sys.stderr)
        self._renamed = []  # (renamed in this model: deleted robots' old names are free now)
        self._swap(model, spawned.mjcf, spawned.robot)
        return spawned.robot

    def _robot_of_ns(self, ns: str) -> str:
        return next((r.name for r in self.robots if r.namespace == ns), "?")

    def _swap(self, model: mujoco.MjModel, mjcf: str, robot: RobotPlan) -> None:
        w: Any = self  # (the World: its parts, without importing it)
        old_m, old_d = self.model, self.data
        model0 = copy.copy(model)  # as compiled: what reset_simulation puts back
        _carry_model(old_m, w._model0, model)
        data = mujoco.MjData(model)
        _carry_data(old_m, old_d, model, data)
        self.model, self.data = model, data
        w._model0 = model0
        self.plan.mjcf = mjcf
        self.plan.robots.append(robot)
        for h in self.robots:
            h.model = model
        handle = RobotHandle(model, robot)
        self.robots.append(handle)
        w.hardware.rebind(model, data)
        w.hardware.add([robot])
        self._apply_deleted()
        for plugin in self.plugins:
            plugin.ctx.model, plugin.ctx.data = model, data
            plugin.rebind()
            self._check_stale(plugin, old_m, old_d)
        events = w._events
        if events is not None:
            events.m, events.d = model, data
            if events.actors is not None:
                events.actors.data = data
        mujoco.mj_forward(model, data)
        if w._start_qpos is not None:  # reset_world puts the new robot back where it was spawned
            start = data.qpos.copy()
            start[: old_m.nq] = w._start_qpos
            w._start_qpos = start
        first = sum(len(r.plugins) for r in self.plan.robots[:-1])
        w._load_robot_plugins(handle, first, remote=bool(w.remote_renders))
        for plugin in self.plugins:
            if plugin.ctx.robot is handle:
                plugin.setup()
        self._refeed()
        self._next_generation()

    def _next_generation(self) -> None:
        """The model changed: the loop takes it, and renderer processes fetch it (`follow`) with the first
        state of the new generation (`_serve_generations`)."""
        self.generation += 1
        w: Any = self
        if not w.remote_renders:
            return
        payload = json.dumps(
            {
                "generation": self.generation,
                "mjcf": self.plan.mjcf,
                "robots": [r.model_dump(mode="json") for r in self.plan.robots],
                "deleted": sorted(self.deleted),
            }
        ).encode()
        self._generations[self.generation] = payload
        if self._model_queryable is None:
            from runner.wire.transport import meta_key

            session = w.bus.session
            key = meta_key(self.plan.name, "render", "model", "*")

            def on_query(query: Any) -> None:
                try:
                    found = self._generations.get(int(str(query.key_expr).rsplit("/", 1)[1]))
                    if found is not None:
                        query.reply(query.key_expr, found)
                finally:
                    query.drop()

            self._model_queryable = session.declare_queryable(key, on_query)

    def follow(self, payload: bytes) -> None:
        """In a renderer process: the world's model as the world has it now (a robot spawned or deleted):
        a new model where it grew, the spawned robots' rendering plugins made, every other one given the
        new model (`rebind`), the deleted robots' closed and their bodies out of sight."""
        from runner.plan import RobotPlan

        w: Any = self
        info = json.loads(payload)
        if info["mjcf"] != self.plan.mjcf:
            model = mujoco.MjModel.from_xml_string(info["mjcf"])
            data = mujoco.MjData(model)
            mujoco.mj_resetData(model, data)
            self.model, self.data = model, data
            w._model0 = copy.copy(model)
            self.plan.mjcf = info["mjcf"]
            for h in self.robots:
                h.model = model
            for plugin in self.plugins:
                plugin.ctx.model, plugin.ctx.data = model, data
                plugin.rebind()
            known = {r.name for r in self.plan.robots}
            for raw in info["robots"]:
                if raw["name"] in known:
                    continue
                robot = RobotPlan.model_validate(raw)
                first = sum(len(r.plugins) for r in self.plan.robots)
                self.plan.robots.append(robot)
                handle = RobotHandle(model, robot)
                self.robots.append(handle)
                w._load_robot_plugins(handle, first, remote=False)
                for plugin in self.plugins:
                    if plugin.ctx.robot is handle:
                        plugin.setup()
        for name in info["deleted"]:
            handle = next((h for h in self.robots if h.name == name), None)
            if handle is None:
                continue
            for index, plugin in list(w.render_plugins.items()):
                if plugin.ctx.robot is handle:
                    plugin.close()
                    del w.render_plugins[index]
                    self.plugins.remove(plugin)
            self.robots.remove(handle)
            self.deleted[name] = handle.plan  # type: ignore[assignment]
        self._apply_deleted()
        self.generation = int(info["generation"])

    def _refeed(self) -> None:
        """The contact watch and the 3D view made again from the world as it is now (their tables are per
        geom and per robot), in the same hooks."""
        w: Any = self
        from runner.sim.contacts import ContactWatch
        from runner.sim.scene import SceneFeed

        feed: SceneFeed | None = None
        for h in [*w._after, *w._before]:
            owner = getattr(h.fn, "__self__", None)
            if isinstance(owner, SceneFeed):
                if feed is None:
                    feed = SceneFeed(w, self.deleted_frames(), stamp_ns=self.now_ns)
                h.fn = getattr(feed, h.fn.__name__)
            elif isinstance(owner, ContactWatch):
                h.fn = ContactWatch(w, self.plan.contact_watch).publish

    def deleted_frames(self) -> list[str]:
        """The body names (3D view entities) of the deleted robots."""
        m = self.model
        prefixes = tuple(r.prefix for r in self.deleted.values())
        prefixes += tuple("~deleted~" + p for p in prefixes)
        return (
            [n for b in range(1, m.nbody) if (n := m.body(b).name or "").startswith(prefixes)]
            if prefixes
            else []
        )

    # ----------------------------------------------------------------------------------------- delete
    def delete_robot(self, name: str) -> None:
        """The robot `name` out of the world (the module's docstring); SpawnError says why not."""
        w: Any = self
        handle = next((h for h in self.robots if h.name == name), None)
        if handle is None:
            if name in self.entity_names():
                raise SpawnError(
                    f"[{name}] is a model of the world: only robots can be deleted (a world model's bodies "
                    "are part of the world's compiled model)"
                )
            raise SpawnError(f"Entity [{name}] does not exist")
        mine = [p for p in self.plugins if p.ctx.robot is handle]
        for plugin in mine:
            plugin.close()
        dead = {id(p) for p in mine}
        self.plugins[:] = [p for p in self.plugins if id(p) not in dead]
        places = [i for i, p in w._plugin_index.items() if id(p) in dead]
        first = 0
        for rp in self.plan.robots:  # (a rendering plugin of a renderer process: no plugin here)
            if rp.name == name:
                places += [first + k for k in range(len(rp.plugins)) if first + k in w.remote_renders]
            first += len(rp.plugins)
        for index in places:
            w._plugin_index.pop(index, None)
            hooks = w._hooks_of.pop(index, [])
            w._before[:] = [h for h in w._before if h not in hooks]
            w._after[:] = [h for h in w._after if h not in hooks]
            link = w.remote_renders.pop(index, None)
            if link is not None:  # its frames in flight published, its counts kept; the process goes on
                link.finish(lambda: False)
                w._retired_renders.append(link)
        self._withdraw(handle)
        m = self.model
        acts = {a for a in range(m.nu) if (m.actuator(a).name or "").startswith(handle.prefix)}
        joints = [j for j in range(m.njnt) if int(m.jnt_bodyid[j]) in handle.body_ids]
        dofs = {int(m.jnt_dofadr[j]) + k for j in joints for k in range(_dofs(m, j))}
        w.hardware.drop(acts, dofs)
        self.robots.remove(handle)
        self.deleted[name] = handle.plan  # type: ignore[assignment]
        self._renamed.append(handle.prefix)
        self._apply_deleted()
        self._refeed()
        self._next_generation()

    def _withdraw(self, handle: RobotHandle) -> None:
        """The robot's topics and services: gone from the bus, the graph and ROS 2. A key outside its
        namespace that one of its plugins took (an absolute topic) loses that plugin's subscription only."""
        w: Any = self
        prefix = f"{self.plan.name}/{handle.namespace}/"
        keys = {k for k in (*w._out, *w._services, *w._local) if k.startswith(prefix)}
        withdraw = getattr(w.bus, "withdraw", None)
        for key, entry in self._subs_of.pop(handle.namespace, []):
            subs = w._local.get(key)
            if subs is not None and not key.startswith(prefix):
                subs[:] = [s for s in subs if s is not entry]
                if not subs and key not in w._out:
                    keys.add(key)
        for key in sorted(keys):
            out = w._out.pop(key, None)
            if out is not None:  # (the end-of-run table counts what it published)
                self.gone_counts[key] = out.seq
            w._services.pop(key, None)
            subs = w._local.pop(key, None)
            if subs is not None:
                subs.clear()  # (the same list as a publisher's `local`)
            w._remote_subscribed.discard(key)
            w._checked.discard(key)
            w._max_bytes.pop(key, None)
            if withdraw is not None:
                withdraw(key)

    def _apply_deleted(self) -> None:
        """The deleted robots' bodies out of the world (the module's docstring), in the model as it is now
        (again after reset_simulation puts the compiled model back)."""
        if not self.deleted:
            return
        m, d = self.model, self.data
        prefixes = tuple(r.prefix for r in self.deleted.values())
        prefixes += tuple("~deleted~" + p for p in prefixes)
        bodies = {b for b in range(1, m.nbody) if (m.body(b).name or "").startswith(prefixes)}
        for g in range(m.ngeom):
            if int(m.geom_bodyid[g]) in bodies:
                m.geom_contype[g] = 0
                m.geom_conaffinity[g] = 0
                m.geom_matid[g] = -1
                m.geom_rgba[g, 3] = 0.0
                m.geom_group[g] = 5
        for a in range(m.nu):
            joint = int(m.actuator_trntype[a]) == int(mujoco.mjtTrn.mjTRN_JOINT)
            if joint and int(m.jnt_bodyid[int(m.actuator_trnid[a, 0])]) in bodies:
                m.actuator_gainprm[a] = 0.0
                m.actuator_biasprm[a] = 0.0
                d.ctrl[a] = 0.0
        joints = [j for j in range(m.njnt) if int(m.jnt_bodyid[j]) in bodies]
        q = [int(m.jnt_qposadr[j]) + k for j in joints for k in range(_qpos(m, j))]
        v = [int(m.jnt_dofadr[j]) + k for j in joints for k in range(_dofs(m, j))]
        self._frozen_q = np.array(q, dtype=np.int64)
        self._frozen_v = np.array(v, dtype=np.int64)
        self._frozen_at = d.qpos[self._frozen_q].copy()

    def _hold_deleted(self) -> None:
        """At each boundary: the deleted robots' joints put back where they were, at rest."""
        if len(self._frozen_q):
            d = self.data
            d.qpos[self._frozen_q] = self._frozen_at
            d.qvel[self._frozen_v] = 0.0

    def _check_stale(self, plugin: Plugin, old_m: mujoco.MjModel, old_d: mujoco.MjData) -> None:
        """Say (once per plugin type) a plugin that still holds the old model or data, or a view into the
        old data, after its `rebind`: it would read numbers that no longer move."""
        kind = type(plugin).__name__
        if kind in self._stale_said:
            return
        arrays = [
            v
            for k in dir(old_d)
            if not k.startswith("_") and isinstance(v := getattr(old_d, k, None), np.ndarray)
        ]
        for attr, value in vars(plugin).items():
            values = value if isinstance(value, list | tuple) else [value]
            for v in values:
                stale = v is old_m or v is old_d
                if not stale and isinstance(v, np.ndarray) and v.base is not None:
                    stale = any(np.shares_memory(v, a) for a in arrays if a.size)
                if stale:
                    self._stale_said.add(kind)
                    print(
                        f"world: plugin {plugin.name!r} ({kind}) still holds the old world's "
                        f"{'model' if v is old_m else 'data'} in `{attr}` after a robot was spawned: it "
                        "reads numbers that no longer change. Hint: make it again in the plugin's `rebind()`",
                        file=sys.stderr,
                    )
                    return


def _qpos(m: mujoco.MjModel, j: int) -> int:
    t = int(m.jnt_type[j])
    return 7 if t == int(mujoco.mjtJoint.mjJNT_FREE) else 4 if t == int(mujoco.mjtJoint.mjJNT_BALL) else 1


def _dofs(m: mujoco.MjModel, j: int) -> int:
    t = int(m.jnt_type[j])
    return 6 if t == int(mujoco.mjtJoint.mjJNT_FREE) else 3 if t == int(mujoco.mjtJoint.mjJNT_BALL) else 1


def _carry_model(old: mujoco.MjModel, compiled: mujoco.MjModel, new: mujoco.MjModel) -> None:
    """What the run changed of `old` (vs `compiled`, the same model as compiled) put into `new` at the same
    places: the world grew after the end of every array, so an entry of `old` is the same entry of `new`."""
    for name in dir(old):
        if name.startswith("_"):
            continue
        a = getattr(old, name, None)
        if not isinstance(a, np.ndarray) or not a.size or name.startswith("vis"):
            continue
        b, target = getattr(compiled, name), getattr(new, name)
        if a.shape != b.shape or not target.flags.writeable or a.shape[1:] != target.shape[1:]:
            continue
        if len(target) < len(a):
            continue
        changed = a != b
        if changed.any():
            target[: len(a)][changed] = a[changed]
    # (not `vis`: only renderers change it, per frame and for their own contexts, and they are made again)
    for struct in ("opt", "stat"):
        _carry_struct(getattr(old, struct), getattr(compiled, struct), getattr(new, struct))


def _carry_struct(old: Any, compiled: Any, new: Any, depth: int = 0) -> None:
    for name in dir(old):
        if name.startswith("_"):
            continue
        a, b = getattr(old, name), getattr(compiled, name)
        if isinstance(a, np.ndarray):
            if not np.array_equal(a, b):
                getattr(new, name)[...] = a
        elif isinstance(a, int | float):
            if a != b:
                setattr(new, name, a)
        elif depth < 2 and type(a).__module__.startswith("mujoco") and not callable(a):
            _carry_struct(a, b, getattr(new, name), depth + 1)


_STATE = (
    "qpos",
    "qvel",
    "act",
    "ctrl",
    "qacc_warmstart",
    "qfrc_applied",
    "xfrc_applied",
    "mocap_pos",
    "mocap_quat",
    "sensordata",
    "eq_active",
    "userdata",
    "plugin_state",
)


def _carry_data(old_m: mujoco.MjModel, old: mujoco.MjData, m: mujoco.MjModel, new: mujoco.MjData) -> None:
    """The state of `old` into `new` (the new robot's part is the model's start: its spawn pose)."""
    mujoco.mj_resetData(m, new)
    for name in _STATE:
        a = getattr(old, name, None)
        if a is None or not a.size:
            continue
        getattr(new, name)[: len(a)] = a
    new.time = old.time
