"""The world: steps MuJoCo, runs plugin hooks at their rates, applies the timeline, paces against wall time.

Time is integer nanoseconds of sim time, counted in whole physics steps (`now = steps * step_ns`), so
rates and timeline entries land on exact steps and a run is repeatable.

At each boundary time `t` where something is due, in this order:
  1. `after_step` hooks due at t. The step into t is split (`mj_step1` at t, `mj_step2` after the
     hooks), so sensors read positions, velocities, contacts and position/velocity sensor values of the
     state at t, at no extra cost; acceleration-stage values (accelerometers) are those of the step that
     led to t. A plugin that reads constraint forces sets `needs_forward` and gets an `mj_forward` first.
     (With the RK4 integrator, which cannot be split, every boundary with sensors due runs `mj_forward`.)
  2. timeline entries with time <= t (published, and delivered to local subscribers at once);
  3. messages from other processes that arrived since the last boundary (delivered in arrival order);
  4. `before_step` hooks due at t (controllers act on the commands);
  5. the clock, if due;
then MuJoCo finishes the step (`mj_step2`) and steps (`mj_step(..., nstep=n - 1)`, `mj_step1`) straight to
the next boundary: the loop costs nothing between boundaries, and nothing but the hooks at them.
"""

from __future__ import annotations

import contextlib
import gc
import json
import math
import queue
import struct
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import mujoco
import numpy as np

from runner.plan import RunPlan
from runner.plugin import Plugin, Publisher, RobotHandle, RuntimeContext, overrides
from runner.plugin.registry import load
from runner.wire import msgs
from runner.wire.cdr import Layout
from runner.wire.transport import ATTACHMENT as _ATT
from runner.wire.transport import Bus, topic_key

# Without anything due, the loop still stops this often (sim time) to take input and check for a stop.
MAX_BATCH_NS = 10_000_000


@dataclass
class _Hook:
    fn: Callable[[int], None]
    period_ns: int  # 0: every step
    next_ns: int = 0
    forward: bool = False  # needs mj_forward first (acceleration-stage values)


class _Outgoing:
    """One published key: sends CDR bytes with the (sequence, stamp) attachment and hands the message to
    subscribers inside this process (decoded only when there is one)."""

    __slots__ = ("key", "local", "send", "seq", "type")

    def __init__(self, key: str, type_name: str, send: Callable[[bytes, bytes], None]):
        self.key = key
        self.type = type_name
        self.send = send
        self.seq = 0
        self.local: list[tuple[str, Callable[[Any, int], None]]] = []

    def publish(self, msg: Any, stamp_ns: int) -> None:
        self.send(msgs.encode(msg, self.type), _ATT.pack(self.seq, stamp_ns))
        self.seq += 1
        for _type, cb in self.local:
            cb(msg, stamp_ns)

    def publish_cdr(self, payload: bytes, stamp_ns: int) -> None:
        self.send(payload, _ATT.pack(self.seq, stamp_ns))
        self.seq += 1
        if self.local:
            msg = msgs.decode(payload, self.type)
            for _type, cb in self.local:
                cb(msg, stamp_ns)


@dataclass
class WorldStats:
    steps: int = 0
    sim_ns: int = 0
    wall_s: float = 0.0
    published: dict[str, int] = field(default_factory=dict)
    error: str | None = None  # why the world stopped early on its own (physics went unstable)
    rejected: dict[str, dict[str, int]] = field(default_factory=dict)  # inbound samples dropped: key, why


# MuJoCo's warnings for NaN/Inf/huge positions, velocities, accelerations: it then resets the data and goes
# on as if nothing happened, so the world checks them after every batch of steps and stops instead
_UNSTABLE = (
    int(mujoco.mjtWarning.mjWARN_BADQPOS),
    int(mujoco.mjtWarning.mjWARN_BADQVEL),
    int(mujoco.mjtWarning.mjWARN_BADQACC),
)


class World:
    """The simulated world of a plan. `role="world"` steps physics and runs every plugin, except, with
    `plan.renderers == "process"` on a Zenoh bus, the rendering ones: their frames are made by a renderer
    process (`role="renderer"`, see runner/sim/render.py) from the state this world sends it."""

    def __init__(self, plan: RunPlan, bus: Bus, *, role: Literal["world", "renderer"] = "world"):
        self.plan = plan
        self.bus = bus
        self.role = role
        self.model = mujoco.MjModel.from_xml_string(plan.mjcf)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        # mj_step1/mj_step2 split the step around the hooks; RK4 cannot be split
        self._split = int(self.model.opt.integrator) != int(mujoco.mjtIntegrator.mjINT_RK4)
        self.step_ns = plan.step_ns
        self.now_ns = 0
        self.rng = np.random.default_rng(plan.seed)
        self._out: dict[str, _Outgoing] = {}
        self._local: dict[str, list[tuple[str, Callable[[Any, int], None]]]] = {}
        self._remote_subscribed: set[str] = set()
        self._inbox: queue.SimpleQueue[tuple[str, bytes, bytes | None]] = queue.SimpleQueue()
        self._received: dict[str, int] = {}  # messages from other processes, per key
        self._lockstep: Lockstep | None = None
        self.robots = [RobotHandle(self.model, r) for r in plan.robots]
        self.plugins: list[Plugin] = []
        self._before: list[_Hook] = []
        self._after: list[_Hook] = []
        session = getattr(bus, "session", None)
        remote = role == "world" and plan.renderers == "process" and session is not None
        self.remote_renders: dict[int, RemoteRender] = {}  # plugin index -> its renderer link
        self.render_plugins: dict[int, Plugin] = {}  # in a renderer: plugin index -> plugin
        index = -1
        for handle in self.robots:
            for pp in handle.plan.plugins:
                index += 1
                cls = load(pp.type)
                period = 0 if not pp.rate else round(1e9 / pp.rate)
                if role == "renderer" and not cls.renders:
                    continue
                if remote and cls.renders:
                    link = RemoteRender(session, plan.name, index)
                    self.remote_renders[index] = link
                    self._after.append(_Hook(self._render_hook(link), period))
                    continue
                params = cls.Params.model_validate(pp.params)
                # random numbers by the plugin's place in the plan, so a renderer process draws the same
                plugin = cls(params, self._context(handle, index), pp.name)
                self.plugins.append(plugin)
                if role == "renderer":
                    self.render_plugins[index] = plugin
                    continue
                if overrides(plugin, "before_step"):
                    control = period if pp.control_rate is None else round(1e9 / pp.control_rate)
                    self._before.append(_Hook(plugin.before_step, control))
                if overrides(plugin, "after_step"):
                    self._after.append(_Hook(plugin.after_step, period, forward=plugin.needs_forward))
        if role == "world" and plan.foxglove.scene:
            from runner.sim.scene import SceneFeed

            for fn, period in SceneFeed(self).hooks():
                self._after.append(_Hook(fn, period))
        if role == "renderer":
            for plugin in self.plugins:
                plugin.setup()
            return
        self._clock_sent = -1  # the last clock value published
        if plan.lockstep and session is not None:
            keys = self._remote_subscribed  # the same set: keys subscribed later count too
            self._lockstep = Lockstep(session, plan.name, plan.lockstep, self._received, keys)
        self._clock = self.make_publisher(plan.clock_key, "rosgraph_msgs/msg/Clock")
        self._clock_layout = Layout(
            self._clock.type, msgs.T[self._clock.type](clock=msgs.time_msg(0)), ["clock"]
        )
        self._clock_hook = _Hook(self._publish_clock, round(1e9 / plan.clock_rate))
        self._timeline = [
            (ev.t_ns, ev.key, ev.type, msgs.from_data(ev.type, ev.data)) for ev in plan.timeline
        ]
        self._timeline_i = 0
        if plan.contact_watch:
            self._setup_contacts(plan.contact_watch)
        for plugin in self.plugins:
            plugin.setup()

    def _context(self, handle: RobotHandle, stream: int) -> RuntimeContext:
        """What a plugin of this robot works with; its random numbers are the plan seed's stream `stream`."""
        return RuntimeContext(
            model=self.model,
            data=self.data,
            robot=handle,
            rng=np.random.default_rng([self.plan.seed, stream]),
            run=self.plan.name,
            _make_publisher=self._publisher_factory(handle.namespace),
            _subscribe=self._subscriber_factory(handle.namespace),
        )

    # ------------------------------------------------------------------------------------- pub / sub
    def make_publisher(self, key: str, type_name: str) -> _Outgoing:
        out = self._out.get(key)
        if out is None:
            out = _Outgoing(key, type_name, self.bus.publisher(key, type_name))
            out.local = self._local.setdefault(key, [])
            self._out[key] = out
        elif out.type != type_name:
            raise ValueError(f"{key} is published as {out.type} and as {type_name}")
        return out

    def publish(self, out: _Outgoing, msg: Any, stamp_ns: int) -> None:
        out.publish(msg, stamp_ns)

    def publish_cdr(self, out: _Outgoing, payload: bytes, stamp_ns: int) -> None:
        out.publish_cdr(payload, stamp_ns)

    def _publisher_factory(self, namespace: str) -> Callable[[str, str], Publisher]:
        def make(topic: str, type_name: str) -> Publisher:
            type_name = msgs.normalize_type(type_name)
            out = self.make_publisher(topic_key(self.plan.name, namespace, topic), type_name)
            return Publisher(out.key, type_name, out.publish, out.publish_cdr)

        return make

    def _subscriber_factory(self, namespace: str) -> Callable[[str, str, Callable[[Any, int], None]], None]:
        def subscribe(topic: str, type_name: str, callback: Callable[[Any, int], None]) -> None:
            key = topic_key(self.plan.name, namespace, topic)
            # the same list as the publisher's `local`, if this process also publishes the key
            self._local.setdefault(key, []).append((msgs.normalize_type(type_name), callback))
            if key not in self._remote_subscribed:
                self._remote_subscribed.add(key)
                self.bus.subscribe(key, self._on_remote, msgs.normalize_type(type_name))

        return subscribe

    def _on_remote(self, key: str, payload: bytes, att: bytes | None) -> None:
        """A message from another process (a Zenoh thread): queued for the next boundary, and counted, so
        lockstep knows when everything a node sent has arrived."""
        self._inbox.put((key, payload, att))
        self._received[key] = self._received.get(key, 0) + 1
        lockstep = self._lockstep
        if lockstep is not None:
            lockstep.poke()

    def _drain_inbox(self) -> None:
        while True:
            try:
                key, payload, _att = self._inbox.get_nowait()
            except queue.Empty:
                return
            for type_name, cb in self._local.get(key, ()):
                try:
                    msg = msgs.decode(payload, type_name)
                except Exception:
                    # not a message of the subscribed type: a foreign publisher's mistake, dropped and counted
                    reject = getattr(self.bus, "reject", None)
                    if reject is not None:
                        reject(key, f"{len(payload)} bytes that do not decode as {type_name}")
                    continue
                cb(msg, self.now_ns)

    # ------------------------------------------------------------------------------------------- loop
    def _boundary(self) -> None:
        now = self.now_ns
        due = [h for h in self._after if now >= h.next_ns]
        if due:
            if self._split is False or any(h.forward for h in due):
                mujoco.mj_forward(self.model, self.data)
            for h in due:
                h.fn(now)
                h.next_ns = _next_due(h, now)
        while self._timeline_i < len(self._timeline) and self._timeline[self._timeline_i][0] <= now:
            _t, key, type_name, msg = self._timeline[self._timeline_i]
            self.publish(self.make_publisher(key, type_name), msg, now)
            self._timeline_i += 1
        if self._lockstep is not None:
            # the nodes' answers to the clocks published so far come before their next wait message
            self._lockstep.wait(self._clock_sent, self._should_stop)
        self._drain_inbox()
        for h in self._before:
            if now >= h.next_ns:
                h.fn(now)
                h.next_ns = _next_due(h, now)
        clock = self._clock_hook
        if now >= clock.next_ns:
            clock.fn(now)
            clock.next_ns = _next_due(clock, now)

    # ------------------------------------------------------------------------------------ contacts
    def _setup_contacts(self, watch: list[str]) -> None:
        """Contacts between named robots and models, for `no_collision` assertions: each geom's owner is
        its robot's name, its model's name (the first chunk of a world body's name) or `ground`."""
        from runner.checks.judge import CONTACTS_RATE, contacts_key

        m = self.model
        owners: list[str] = []
        for g in range(m.ngeom):
            body = int(m.geom_bodyid[g])
            robot = next((r.name for r in self.robots if body in r.body_ids), None)
            if robot is not None:
                owners.append(robot)
            elif body == 0:
                owners.append((m.geom(g).name or "world").split("/")[0])
            else:
                owners.append((m.body(body).name or "world").split("/")[0])
        names = sorted(set(owners))  # ids in name order: pairs (lo, hi) by id are sorted by name
        self._owner_names = names
        self._owner_ids = np.array([names.index(o) for o in owners], dtype=np.int64)
        self._owner_list: list[int] = self._owner_ids.tolist()
        self._watched_list = [n in watch for n in names]
        self._contact_layouts: dict[tuple[int, ...], Layout] = {}
        self._contacts = self.make_publisher(contacts_key(self.plan.name), "gazebo_msgs/msg/ContactsState")
        self._after.append(_Hook(self._publish_contacts, round(1e9 / CONTACTS_RATE)))

    def _publish_contacts(self, now: int) -> None:
        """The pairs of owners in contact (one state each, sorted by name): the set changes rarely, so each
        distinct set is encoded once into a fixed layout and then only re-stamped."""
        d = self.data
        pairs: tuple[int, ...] = ()
        if d.ncon:
            # a few dozen contacts at most: plain Python over the list beats numpy's per-call overhead
            owner, watched, k = self._owner_list, self._watched_list, len(self._owner_names)
            found = set()
            for a, b in d.contact.geom.tolist():
                oa, ob = owner[a], owner[b]
                if oa != ob and (watched[oa] or watched[ob]):
                    found.add(oa * k + ob if oa < ob else ob * k + oa)
            if found:
                pairs = tuple(sorted(found))
        layout = self._contact_layouts.get(pairs)
        if layout is None:
            layout = self._contact_layouts[pairs] = self._contacts_layout(pairs)
        self.publish_cdr(self._contacts, layout.encode(now), now)

    def _contacts_layout(self, pairs: tuple[int, ...]) -> Layout:
        names, k = self._owner_names, len(self._owner_names)
        zero = msgs.from_data("geometry_msgs/msg/Wrench", {})
        state = msgs.T["gazebo_msgs/msg/ContactState"]
        states = [
            state(
                info="",
                collision1_name=names[code // k],
                collision2_name=names[code % k],
                wrenches=[],
                total_wrench=zero,
                contact_positions=[],
                contact_normals=[],
                depths=np.zeros(0),
            )
            for code in pairs
        ]
        msg = msgs.T["gazebo_msgs/msg/ContactsState"](header=msgs.header(0, "world"), states=states)
        return Layout(self._contacts.type, msg, ["header.stamp"])

    # ---------------------------------------------------------------------------- renderer processes
    def _render_hook(self, link: RemoteRender) -> Callable[[int], None]:
        def send(now: int) -> None:
            link.send(now, self._state_bytes(), self._should_stop)

        return send

    def _state_bytes(self) -> bytes:
        """What a renderer needs to pose the world: positions and mocap poses (velocities do not show)."""
        d = self.data
        return d.qpos.tobytes() + d.mocap_pos.tobytes() + d.mocap_quat.tobytes()

    def wait_for_renderers(self, timeout_s: float, should_stop: Callable[[], bool]) -> bool:
        """Until every renderer process listens (True), or the timeout or a stop (False)."""
        deadline = time.monotonic() + timeout_s
        while not all(link.listening() for link in self.remote_renders.values()):
            if time.monotonic() > deadline or should_stop():
                return False
            time.sleep(0.02)
        return True

    def render(self, index: int, now_ns: int, state: bytes) -> None:
        """In a renderer process: pose the world as the state says and run the plugin's hook."""
        m, d = self.model, self.data
        nq, nm = m.nq, m.nmocap
        values = np.frombuffer(state, dtype=np.float64)
        d.qpos[:] = values[:nq]
        if nm:
            d.mocap_pos[:] = values[nq : nq + 3 * nm].reshape(nm, 3)
            d.mocap_quat[:] = values[nq + 3 * nm : nq + 7 * nm].reshape(nm, 4)
        mujoco.mj_kinematics(m, d)
        mujoco.mj_camlight(m, d)
        self.now_ns = now_ns
        self.render_plugins[index].after_step(now_ns)

    def published(self) -> dict[str, int]:
        return {k: o.seq for k, o in self._out.items()}

    def _publish_clock(self, now: int) -> None:
        self.publish_cdr(self._clock, self._clock_layout.encode(now), now)
        self._clock_sent = now

    def _next_boundary(self, end_ns: int) -> int:
        nxt = min(end_ns, self.now_ns + MAX_BATCH_NS, self._clock_hook.next_ns)
        for h in self._after:
            nxt = min(nxt, h.next_ns)
        for h in self._before:
            nxt = min(nxt, h.next_ns)
        if self._timeline_i < len(self._timeline):
            nxt = min(nxt, self._timeline[self._timeline_i][0])
        return nxt

    def run(
        self,
        should_stop: Callable[[], bool] = lambda: False,
        on_progress: Callable[[int], None] | None = None,
    ) -> WorldStats:
        plan = self.plan
        m, d = self.model, self.data
        self._should_stop = should_stop
        # everything built so far lives for the whole run: out of the collector's way (shorter GC pauses)
        gc.freeze()
        if self._lockstep is not None:
            # every lockstep node set up (subscribed) and waiting, before the first sensor message
            self._lockstep.wait(-1, should_stop)
        end_ns = plan.duration_ns
        factor = {"realtime": 1.0, "max": None}.get(plan.rate, plan.rate)  # type: ignore[arg-type]
        wall0 = time.perf_counter()
        next_check = wall0
        steps = 0
        warnings = [d.warning[i] for i in _UNSTABLE]
        error = None
        while True:
            self._boundary()
            if self.now_ns >= end_ns:
                break
            target = self._next_boundary(end_ns)
            n = max(1, math.ceil((target - self.now_ns) / self.step_ns))
            if self._split:
                mujoco.mj_step2(m, d)  # finish the step begun at the boundary, with the new controls
                if n > 1:
                    mujoco.mj_step(m, d, nstep=n - 1)
                mujoco.mj_step1(m, d)  # positions, velocities, contacts at the next boundary
            else:
                mujoco.mj_step(m, d, nstep=n)
            steps += n
            if warnings[0].number or warnings[1].number or warnings[2].number:
                error = self._instability(self.now_ns, self.now_ns + n * self.step_ns)
                break
            self.now_ns += n * self.step_ns
            wall = time.perf_counter()
            if factor is not None:
                ahead = self.now_ns / 1e9 / factor - (wall - wall0)
                if ahead > 0:
                    _sleep_until(wall + ahead)
                    wall = time.perf_counter()
            if wall >= next_check:
                next_check = wall + 0.05
                if on_progress:
                    on_progress(self.now_ns)
                if should_stop():
                    break
        if self._lockstep is not None:
            # their answers to the last clock are part of the run (recorded), as every earlier one
            self._lockstep.wait(self._clock_sent, should_stop)
            self._lockstep.close()
        published = {k: o.seq for k, o in self._out.items()}
        for link in self.remote_renders.values():
            link.finish(should_stop)
            published.update(link.published)
        wall_s = time.perf_counter() - wall0
        for plugin in self.plugins:
            plugin.close()
        for link in self.remote_renders.values():
            link.close()
        gc.unfreeze()  # collectable again (a process that builds several worlds must not keep them all)
        rejected = {k: dict(v) for k, v in getattr(self.bus, "rejected", {}).items()}
        return WorldStats(
            steps=steps,
            sim_ns=self.now_ns,
            wall_s=wall_s,
            published=published,
            error=error,
            rejected=rejected,
        )

    def _instability(self, t0_ns: int, t1_ns: int) -> str:
        """What went unstable, where (the joint of the degree of freedom MuJoCo names, and its robot)."""
        m, d = self.model, self.data
        kinds = zip(("positions", "velocities", "accelerations"), _UNSTABLE, strict=True)
        kind, i = next((k, i) for k, i in kinds if d.warning[i].number)
        dof = int(d.warning[i].lastinfo)
        what = f"degree of freedom {dof}"
        if 0 <= dof < m.nv:
            jnt = int(m.dof_jntid[dof])
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, jnt)
            body = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.jnt_bodyid[jnt])) or ""
            what = f"joint {name}" if name else f"the free joint of body {body}"
            robot = next((r.name for r in self.plan.robots if (name or body).startswith(r.prefix)), None)
            if robot:
                what += f" (robot {robot})"
        return (
            f"the physics went unstable between t = {t0_ns / 1e9:.3f} s and {t1_ns / 1e9:.3f} s: NaN, Inf "
            f"or huge values in the {kind} of {what}; the run stops here (the recording keeps everything "
            "before). Hint: a smaller world.physics.timestep, or check the joint's limits, damping, masses"
        )


class RemoteRender:
    """The world's end of one rendering plugin that runs in a renderer process.

    At the plugin's times the world sends the state (`<run>/@meta/render/<i>`: sim time + positions);
    the renderer renders, publishes the frame under the plugin's own topics, and acknowledges
    (`.../<i>/done`, with its message counts). At most `DEPTH` frames are in flight: the world simulates on
    while a frame renders, and waits only when the renderer falls behind (lockstep, nothing dropped)."""

    DEPTH = 1
    TIMEOUT_S = 60.0

    def __init__(self, session: Any, run: str, index: int):
        import zenoh

        from runner.wire.transport import meta_key

        self.session = session
        self.alive_key = meta_key(run, "render", "alive")
        self.index = index
        self.sent = 0
        self.acked = 0
        self.published: dict[str, int] = {}
        self._cond = threading.Condition()
        self._pub = session.declare_publisher(
            meta_key(run, "render", str(index)),
            congestion_control=zenoh.CongestionControl.BLOCK,
            reliability=zenoh.Reliability.RELIABLE,
        )
        self._stop = session.declare_publisher(meta_key(run, "render", "stop"))
        self._sub = session.declare_subscriber(meta_key(run, "render", str(index), "done"), self._on_done)

    def listening(self) -> bool:
        """The renderer process holds its liveliness token once it is subscribed and ready."""
        replies = self.session.liveliness().get(self.alive_key, timeout=1.0)
        return any(r.ok is not None for r in replies)

    def _on_done(self, sample: Any) -> None:
        info = json.loads(sample.payload.to_bytes())
        with self._cond:
            self.acked = max(self.acked, int(info["n"]))
            self.published.update(info.get("published", {}))
            self._cond.notify_all()

    def _wait(self, acked: int, should_stop: Callable[[], bool]) -> None:
        deadline = time.monotonic() + self.TIMEOUT_S
        with self._cond:
            while self.acked < acked:
                if should_stop():
                    return
                if time.monotonic() > deadline:
                    raise RuntimeError(f"the renderer process did not answer for {self.TIMEOUT_S:.0f} s")
                self._cond.wait(0.05)

    def send(self, now_ns: int, state: bytes, should_stop: Callable[[], bool]) -> None:
        self._wait(self.sent - self.DEPTH + 1, should_stop)
        self._pub.put(_STATE_HEAD.pack(now_ns, self.sent) + state)
        self.sent += 1

    def finish(self, should_stop: Callable[[], bool]) -> None:
        """Wait for the frames in flight, so they are published before the world says it has ended."""
        self._wait(self.sent, should_stop)

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self._stop.put(b"")
        for ent in (self._sub, self._pub, self._stop):
            with contextlib.suppress(Exception):
                ent.undeclare()


_STATE_HEAD = struct.Struct("<qQ")  # sim time ns, frame number


class Lockstep:
    """The world's side of `lockstep:`. Each node named there says, whenever it goes to sleep, the sim
    time it sleeps until (`<run>/@meta/lockstep/<node>`, int64 ns; runner.node does it in `sleep()`).
    Before the world takes in commands at a boundary, it waits until every such node sleeps past the last
    clock it published: the node has seen that instant and answered it. A node whose liveliness token goes
    away (it died) is no longer waited for; one that never answers stops the run after `TIMEOUT_S`."""

    TIMEOUT_S = 30.0

    def __init__(self, session: Any, run: str, names: list[str], received: dict[str, int], keys: set[str]):
        from runner.wire.transport import meta_key

        self.waiting: dict[str, int] = {}  # node -> sim time it sleeps until
        self.sent: dict[str, dict[str, int]] = {}  # node -> messages it had published per key by then
        self.received = received  # the world's count of messages received per key
        self.keys = keys  # the keys the world subscribes to
        self.names = set(names)
        self._cond = threading.Condition()
        self._prefix = meta_key(run, "lockstep", "")
        self._node_prefix = meta_key(run, "node", "")
        self._seen: set[str] = set()
        self._subs = [
            session.declare_subscriber(meta_key(run, "lockstep", "*"), self._on_wait),
            session.liveliness().declare_subscriber(meta_key(run, "node", "*"), self._on_alive, history=True),
        ]

    def _on_wait(self, sample: Any) -> None:
        name = str(sample.key_expr)[len(self._prefix) :]
        data = sample.payload.to_bytes()
        (until,) = _WAIT.unpack_from(data)
        sent = json.loads(data[_WAIT.size :] or b"{}")
        with self._cond:
            if until >= self.waiting.get(name, until):
                self.waiting[name] = until
                self.sent[name] = sent
            self._cond.notify_all()

    def poke(self) -> None:
        with self._cond:
            self._cond.notify_all()

    def _answered(self, name: str, clock_sent: int) -> bool:
        """The node sleeps past the last clock and everything it published by then has arrived."""
        if self.waiting.get(name, -1) <= clock_sent:
            return False
        received = self.received
        return all(received.get(k, 0) >= n for k, n in self.sent.get(name, {}).items() if k in self.keys)

    def _on_alive(self, sample: Any) -> None:
        import zenoh

        name = str(sample.key_expr)[len(self._node_prefix) :]
        with self._cond:
            if sample.kind == zenoh.SampleKind.PUT:
                self._seen.add(name)
            elif name in self.names:
                self.names.discard(name)  # gone: not waited for any more
                print(
                    f"world: lockstep node {name!r} is gone; not waiting for it", file=sys.stderr, flush=True
                )
            self._cond.notify_all()

    def wait(self, clock_sent: int, should_stop: Callable[[], bool]) -> None:
        deadline = time.monotonic() + self.TIMEOUT_S
        with self._cond:
            while True:
                late = [n for n in self.names if not self._answered(n, clock_sent)]
                if not late or should_stop():
                    return
                if time.monotonic() > deadline:
                    who = ", ".join(sorted(late))
                    raise RuntimeError(f"lockstep node(s) {who} did not answer for {self.TIMEOUT_S:.0f} s")
                self._cond.wait(0.05)

    def close(self) -> None:
        for sub in self._subs:
            with contextlib.suppress(Exception):
                sub.undeclare()


_WAIT = struct.Struct("<q")


# The OS may oversleep by a fraction of a millisecond: sleep to just before the deadline, then yield until it.
_SPIN_S = 0.0005


def _sleep_until(deadline: float) -> None:
    """Wake at `deadline` (perf_counter time) within microseconds, not when the scheduler pleases: the
    last half millisecond yields instead of sleeping (`sleep(0)` releases the GIL, so the transport's
    threads can hand over messages meanwhile)."""
    rest = deadline - time.perf_counter()
    if rest > _SPIN_S:
        time.sleep(rest - _SPIN_S)
    while time.perf_counter() < deadline:
        time.sleep(0)


def _next_due(h: _Hook, now: int) -> int:
    if h.period_ns == 0:
        return now + 1
    nxt = h.next_ns + h.period_ns
    return nxt if nxt > now else (now // h.period_ns + 1) * h.period_ns
