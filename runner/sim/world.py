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

The loop lives here; beside it: what the world publishes and takes in (`runner.sim.pubsub`), hooks and
pacing (`runner.sim.schedule`), the contacts it reports (`runner.sim.contacts`), and its links to renderer
processes and lockstep nodes (`runner.sim.links`).
"""

from __future__ import annotations

import gc
import math
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import mujoco
import numpy as np

from runner.plan import RunPlan, TimelinePlan
from runner.plugin import Plugin, RobotHandle, RuntimeContext, overrides
from runner.plugin.registry import load
from runner.sim.contacts import ContactWatch
from runner.sim.control import Control
from runner.sim.grow import Grow
from runner.sim.hardware import Hardware
from runner.sim.links import Lockstep, RemoteRender
from runner.sim.pubsub import PubSub
from runner.sim.schedule import Hook, next_due, sleep_until
from runner.sim.services import Services
from runner.sim.spawn_services import SpawnServices

if TYPE_CHECKING:
    from runner.sim.events import Events
from runner.wire import interfaces, msgs
from runner.wire.cdr import Layout, Peek
from runner.wire.transport import Bus

# Without anything due, the loop still stops this often (sim time) to take input and check for a stop.
MAX_BATCH_NS = 10_000_000


@dataclass
class WorldStats:
    steps: int = 0
    sim_ns: int = 0
    wall_s: float = 0.0
    published: dict[str, int] = field(default_factory=dict)
    error: str | None = None  # why the world stopped early on its own (physics went unstable)
    ended: str | None = None  # an event ended the run (`end:`), and how
    # the sim time run in all (`sim_ns` plus what reset_simulation took back): the recording's last log time
    run_ns: int = 0
    rejected: dict[str, dict[str, int]] = field(default_factory=dict)  # inbound samples dropped: key, why


# MuJoCo's warnings for NaN/Inf/huge positions, velocities, accelerations: it then resets the data and goes
# on as if nothing happened, so the world checks them after every batch of steps and stops instead
_UNSTABLE = (
    int(mujoco.mjtWarning.mjWARN_BADQPOS),
    int(mujoco.mjtWarning.mjWARN_BADQVEL),
    int(mujoco.mjtWarning.mjWARN_BADQACC),
)


# MuJoCo treats a control beyond this as "huge" (mjMAXVAL, engine_util_misc.h: mju_isBad): it warns,
# zeroes every control of the world for that step, and goes on. A finite control beyond it is clamped here
# (an actuator with a ctrlrange is clamped by MuJoCo anyway); a NaN or Inf stops the run, naming it.
CTRL_MAX = 1e10
_BADCTRL = int(mujoco.mjtWarning.mjWARN_BADCTRL)


class World(PubSub, Services, Control, Grow, SpawnServices):
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
        self._init_pubsub()
        self._init_services()
        self._init_control()
        self._init_grow()
        self._lockstep: Lockstep | None = None
        self.robots = [RobotHandle(self.model, r) for r in plan.robots]
        session = getattr(bus, "session", None)
        self.remote_renders: dict[int, RemoteRender] = {}  # plugin index -> its renderer link
        self.render_plugins: dict[int, Plugin] = {}  # in a renderer: plugin index -> plugin
        if role == "world" and plan.lockstep and session is not None:
            keys = self._remote_subscribed  # the same set: keys subscribed later count too
            self._lockstep = Lockstep(session, plan.name, plan.lockstep, self._received, keys)
        self._build(remote=role == "world" and plan.renderers == "process" and session is not None)
        if role == "world":
            self._serve_control()

    def _build(self, remote: bool) -> None:
        """Everything of the world that a run starts with beside the model: the hardware's start state,
        the plugins and their hooks, the clock, the timeline, the events. Made again, the same way, by
        `reset_simulation` (runner.sim.control), which is why it is apart from `__init__`: what it makes
        from the seed and the plan alone comes out the same each time."""
        plan = self.plan
        self.rng = np.random.default_rng(plan.seed)
        # the hardware's start state and gains come before any plugin (a controller reads its start there)
        live = [r for r in plan.robots if r.name not in self.deleted]
        self.hardware = Hardware(self.model, self.data, live)
        self.plugins: list[Plugin] = []
        self._plugin_index: dict[int, Plugin] = {}  # by place in the plan (events change their parameters)
        self._hooks_of: dict[int, list[Hook]] = {}
        self._ended: str | None = None
        self._before: list[Hook] = []
        self._after: list[Hook] = []
        self._load_plugins(remote=remote)
        if self.role == "world" and plan.foxglove.scene:
            from runner.sim.scene import SceneFeed

            for fn, period in SceneFeed(self, self.deleted_frames()).hooks():
                self._after.append(Hook(fn, period))
        if self.role == "renderer":
            for plugin in self.plugins:
                plugin.setup()
            return
        self._clock_sent = -1  # the last clock value published
        self._clock = self.make_publisher(plan.clock_key, "rosgraph_msgs/msg/Clock")
        self._clock_layout = Layout(
            self._clock.type, msgs.T[self._clock.type](clock=msgs.time_msg(0)), ["clock"]
        )
        self._clock_hook = Hook(self._publish_clock, round(1e9 / plan.clock_rate))
        self._timeline = [(ev.t_ns, ev.key, ev.type, self._timeline_message(ev)) for ev in plan.timeline]
        self._timeline_i = 0
        if plan.contact_watch:
            for fn, period in ContactWatch(self, plan.contact_watch).hooks():
                self._after.append(Hook(fn, period))
        self._events: Events | None = None
        if plan.actors or plan.events:
            from runner.sim.events import Events

            self._events = Events(self)
        for plugin in self.plugins:
            plugin.setup()

    def _timeline_message(self, ev: TimelinePlan) -> Any:
        """A timeline entry's message, or with `call` its request."""
        if ev.call:
            return msgs.from_data(interfaces.service_type(ev.type).request, ev.data)
        return msgs.from_data(ev.type, ev.data)

    def _load_plugins(self, remote: bool) -> None:
        """Every robot's plugins, in plan order, and their hooks. In a renderer process only the rendering
        ones (no hooks: `render` runs them); with `remote`, a rendering plugin runs in the renderer process
        and its hook here sends the state there."""
        handles = {h.name: h for h in self.robots}
        index = 0
        for rp in self.plan.robots:
            handle = handles.get(rp.name)
            if handle is not None:  # (a deleted robot's plugins keep their places: events name them by it)
                self._load_robot_plugins(handle, index, remote)
            index += len(rp.plugins)

    def _load_robot_plugins(self, handle: RobotHandle, first: int, remote: bool) -> None:
        """One robot's plugins, the first at place `first` in the plan, and their hooks."""
        role, session = self.role, getattr(self.bus, "session", None)
        index = first - 1
        for pp in handle.plan.plugins:
            index += 1
            cls = load(pp.type)
            period = 0 if not pp.rate else round(1e9 / pp.rate)
            if role == "renderer" and not cls.renders:
                continue
            if remote and cls.renders:
                link = self.remote_renders.get(index) or RemoteRender(session, self.plan.name, index)
                self.remote_renders[index] = link
                self._after.append(Hook(self._render_hook(link), period))
                self._hooks_of[index] = [self._after[-1]]
                continue
            params = cls.Params.model_validate(pp.params)
            # random numbers by the plugin's place in the plan, so a renderer process draws the same
            plugin = cls(params, self._context(handle, index), pp.name)
            self.plugins.append(plugin)
            self._plugin_index[index] = plugin
            if role == "renderer":
                self.render_plugins[index] = plugin
                continue
            hooks = self._hooks_of.setdefault(index, [])
            if overrides(plugin, "before_step"):
                control = period if pp.control_rate is None else round(1e9 / pp.control_rate)
                hooks.append(Hook(plugin.before_step, control))
                self._before.append(hooks[-1])
            if overrides(plugin, "after_step"):
                hooks.append(Hook(plugin.after_step, period, forward=plugin.needs_forward))
                self._after.append(hooks[-1])

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
            _serve=self._service_factory(handle.namespace),
            _plugins=lambda: [p for p in self.plugins if p.ctx.robot is handle],
        )

    # ------------------------------------------------------------------------------------------- loop
    def _boundary(self) -> None:
        now = self.now_ns
        due = [h for h in self._after if now >= h.next_ns]
        if due:
            if self._split is False or any(h.forward for h in due):
                mujoco.mj_forward(self.model, self.data)
            for h in due:
                h.fn(now)
                h.next_ns = next_due(h, now)
        while self._timeline_i < len(self._timeline) and self._timeline[self._timeline_i][0] <= now:
            _t, key, type_name, msg = self._timeline[self._timeline_i]
            if not self.plan.timeline[self._timeline_i].call:
                self.publish(self.make_publisher(key, type_name), msg, now)
            elif self._timeline_i not in self.calls_made:  # (once per run: not again after a reset)
                self.calls_made.add(self._timeline_i)
                self.request(key, msg)  # answered below, with the requests from outside
            self._timeline_i += 1
        if self._lockstep is not None:
            # the nodes' answers to the clocks published so far come before their next wait message
            self._lockstep.wait(self._clock_sent, self._should_stop, self._drain_requests)
        self._hold_deleted()
        self._drain_inbox()
        self._drain_requests()  # after the messages: a service sees what a controller sees
        events = self._events
        if events is not None and now >= events.next_ns:
            events.boundary(now)
            if self._asked:  # an event called a service: answered in this step, as the timeline's are
                self._drain_requests()
        for h in self._before:
            if now >= h.next_ns:
                h.fn(now)
                h.next_ns = next_due(h, now)
        self.hardware.boundary(now)  # last: it sees the controls the controllers wrote
        clock = self._clock_hook
        if now >= clock.next_ns:
            clock.fn(now)
            clock.next_ns = next_due(clock, now)

    # ---------------------------------------------------------------------------- renderer processes
    def _render_hook(self, link: RemoteRender) -> Callable[[int], None]:
        def send(now: int) -> None:
            link.send(now, self._state_bytes(), self._should_stop, self._epoch[0], self.generation)

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

    def render(
        self,
        index: int,
        now_ns: int,
        state: bytes,
        epoch_ns: int = 0,
        generation: int = 0,
        fetch: Callable[[int], bytes] | None = None,
    ) -> None:
        """In a renderer process: pose the world as the state says and run the plugin's hook. A new
        `epoch_ns`: the world was reset (reset_simulation): the rendering plugins are made again, as the
        world's own are (their noise streams from the start), and stamp their messages' log time on. A new
        `generation`: a robot was spawned or deleted: the world's model as it is now (`fetch(generation)`,
        runner.sim.grow) is taken first."""
        if generation != self.generation and fetch is not None:
            self.follow(fetch(generation))
        if epoch_ns != self._epoch[0]:
            self.renderer_reset(epoch_ns)
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

    # ----------------------------------------------------------------------- what events act on
    def listen(
        self,
        key: str,
        type_name: str,
        callback: Callable[[Any, int], None],
        fields: Sequence[str] | None = None,
    ) -> None:
        """`callback(msg, stamp_ns)` for each message on a full key: handed over at once when this world
        publishes it, else at the next boundary from other processes (a node's topic, `publishes:`).
        With `fields`, the callback reads only those top-level fields of what this world publishes: they
        alone are read from the bytes (`Peek`), unless the message object is at hand."""
        plan = self.plan
        own = {t.key for r in plan.robots for p in r.plugins for t in p.topics if t.direction == "pub"}
        own |= set(self._out) | {ev.key for ev in plan.timeline if not ev.call}
        own |= {a["key"] for e in plan.events for a in e.do if a["kind"] == "publish"}
        own.add(f"{plan.name}/_contacts")  # (not a node's topic, though a node declares it: `publishes:`)
        if key in own:
            peek = Peek(type_name, fields).peek if fields else None
            self._local.setdefault(key, []).append((type_name, callback, peek))
        else:
            self._subscriber_factory("", checked=False)("/" + key.split("/", 1)[1], type_name, callback)

    def plugin_at(self, index: int) -> Plugin | None:
        return self._plugin_index.get(index)

    def set_rate(self, index: int, rate: float, now_ns: int) -> None:
        """A plugin's rate changed by an event: its hooks run at the new period from the next multiple."""
        period = round(1e9 / rate)
        for h in self._hooks_of.get(index, ()):
            h.period_ns = period
            h.next_ns = (now_ns // period + 1) * period

    def end_here(self, why: str) -> None:
        self._ended = why

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
        if self._events is not None:
            nxt = min(nxt, self._events.next_ns)
        return min(nxt, self.hardware.next_ns(self.now_ns))

    def run(
        self,
        should_stop: Callable[[], bool] = lambda: False,
        on_progress: Callable[[int], None] | None = None,
    ) -> WorldStats:
        self._should_stop = should_stop
        self._start_loop(should_stop)
        end_ns = self.plan.duration_ns
        factor = {"realtime": 1.0, "max": None}.get(self.plan.rate, self.plan.rate)  # type: ignore[arg-type]
        next_check = wall0 = time.perf_counter()
        # the pacing's origin: sim time `pace_ns` at wall time `pace_wall` (moved on by a pause and a reset:
        # the world never runs fast to catch up the time it stood still, or the sim time a reset took back)
        pace_ns, pace_wall = self.now_ns, wall0
        steps = 0
        m, d, warnings, badctrl, ctrl, abs_ctrl, nu = self._loop_locals()
        self._clamped: set[int] = set()
        error = None
        generation = self.generation
        while True:
            self._boundary()
            if self.generation != generation:  # a robot spawned: the new model and data from here on
                generation = self.generation
                m, d, warnings, badctrl, ctrl, abs_ctrl, nu = self._loop_locals()
                pace_ns, pace_wall = self.now_ns, time.perf_counter()  # (compiling it took wall time)
            if self._rewind is not None:
                self._rewound()
                pace_ns, pace_wall = 0, time.perf_counter()
                continue  # the boundary at t = 0, as a fresh run's first
            if self._stepped and not self.steps_left:
                self._steps_taken()
            # the hooks' controls, checked before physics takes them (a NaN fails `<=` too), in ~1 µs
            if nu and not np.abs(ctrl, out=abs_ctrl).max() <= CTRL_MAX and (error := self._bad_controls()):
                break
            if self.now_ns >= end_ns or self._ended is not None:
                break
            if self.paused and not self.steps_left:
                if not self._idle(should_stop):
                    break
                pace_ns, pace_wall = self.now_ns, time.perf_counter()
                if self.generation != generation:  # spawned while paused
                    generation = self.generation
                    m, d, warnings, badctrl, ctrl, abs_ctrl, nu = self._loop_locals()
                if self._rewind is not None:  # asked while paused: reset now (it stays paused)
                    self._rewound()
                    pace_ns = 0
                    continue  # the boundary at t = 0
            target = self._next_boundary(end_ns)
            if self.steps_left:  # step N while paused: stop there, paused again
                target = min(target, self.now_ns + self.steps_left * self.step_ns)
            n = max(1, math.ceil((target - self.now_ns) / self.step_ns))
            if self._split:
                mujoco.mj_step2(m, d)  # finish the step begun at the boundary, with the new controls
                if n > 1:
                    mujoco.mj_step(m, d, nstep=n - 1)
                mujoco.mj_step1(m, d)  # positions, velocities, contacts at the next boundary
            else:
                mujoco.mj_step(m, d, nstep=n)
            steps += n
            if warnings[0].number or warnings[1].number or warnings[2].number or badctrl.number:
                error = self._instability(self.now_ns, self.now_ns + n * self.step_ns)
                break
            self.now_ns += n * self.step_ns
            if self.steps_left:
                self.steps_left = max(0, self.steps_left - n)
            wall = time.perf_counter()
            if factor is not None:
                ahead = (self.now_ns - pace_ns) / 1e9 / factor - (wall - pace_wall)
                if ahead > 0:
                    sleep_until(wall + ahead)
                    wall = time.perf_counter()
            if wall >= next_check:
                next_check = wall + 0.05
                if on_progress:
                    on_progress(self.now_ns)
                if should_stop():
                    break
        return self._finish(steps, wall0, error, should_stop)

    def _start_loop(self, should_stop: Callable[[], bool]) -> None:
        # everything built so far lives for the whole run: out of the collector's way (shorter GC pauses)
        gc.freeze()
        if self._lockstep is not None:
            # every lockstep node set up (subscribed) and waiting, before the first sensor message
            self._lockstep.wait(-1, should_stop)

    def _loop_locals(
        self,
    ) -> tuple[mujoco.MjModel, mujoco.MjData, list[Any], Any, np.ndarray, np.ndarray, int]:
        """What the loop reads at every step, looked up once (again when a spawn swapped the model)."""
        m, d = self.model, self.data
        warnings = [d.warning[i] for i in _UNSTABLE]
        return m, d, warnings, d.warning[_BADCTRL], d.ctrl, np.empty(m.nu), m.nu

    def _finish(
        self, steps: int, wall0: float, error: str | None, should_stop: Callable[[], bool]
    ) -> WorldStats:
        """The loop is over: the last lockstep answers, renderers and plugins closed, the run's numbers."""
        if self._lockstep is not None:
            # their answers to the last clock are part of the run (recorded), as every earlier one
            self._lockstep.wait(self._clock_sent, should_stop)
            self._lockstep.close()
        published = {**self.gone_counts, **{k: o.seq for k, o in self._out.items()}}
        for link in self.remote_renders.values():
            link.finish(should_stop)
        for link in [*self._retired_renders, *self.remote_renders.values()]:
            published.update(link.published)
        wall_s = time.perf_counter() - wall0
        for plugin in self.plugins:
            plugin.close()
        for link in [*self.remote_renders.values(), *self._retired_renders]:
            link.close()
        gc.unfreeze()  # collectable again (a process that builds several worlds must not keep them all)
        rejected = {k: dict(v) for k, v in getattr(self.bus, "rejected", {}).items()}
        return WorldStats(
            steps=steps,
            sim_ns=self.now_ns,
            run_ns=self._epoch[0] + self.now_ns,
            wall_s=wall_s,
            published=published,
            error=error,
            rejected=rejected,
            ended=self._ended,
        )

    def _rewound(self) -> None:
        """A reset_simulation asked at this boundary: done, and its askers answered (at t = 0)."""
        answers, self._rewind = self._rewind or [], None
        self.reset_simulation()
        for answer in answers:
            answer()

    def _idle(self, should_stop: Callable[[], bool]) -> bool:
        """Paused: take messages and answer services, sim time standing still, until unpaused, a step or a
        reset is asked (True), or the run is stopped (False)."""
        check = time.perf_counter()
        while self.paused and not self.steps_left and self._rewind is None:
            self._drain_inbox()
            self._drain_requests()
            if self._requests.empty() and self._inbox.empty():
                time.sleep(0.001)
            now = time.perf_counter()
            if now >= check:
                check = now + 0.05
                if should_stop():
                    return False
        return True

    def _bad_controls(self) -> str | None:
        """Controls beyond CTRL_MAX: a NaN or Inf stops the run (the error, naming the actuator, its robot
        and the sim time), a finite one is clamped to ±CTRL_MAX (said once per actuator)."""
        ctrl = self.data.ctrl
        for i in np.flatnonzero(~(np.abs(ctrl) <= CTRL_MAX)).tolist():
            value = float(ctrl[i])
            if not math.isfinite(value):
                return self._bad_control(i, str(value), self.now_ns)
            ctrl[i] = math.copysign(CTRL_MAX, value)
            if i not in self._clamped:
                self._clamped.add(i)
                name, robot = self._actuator(i)
                print(
                    f"world: actuator {name}{robot} was given a control of {value:g} at t = "
                    f"{self.now_ns / 1e9:.3f} s: clamped to ±{CTRL_MAX:g} (MuJoCo would zero every control)",
                    file=sys.stderr,
                )
        return None

    def _actuator(self, i: int) -> tuple[str, str]:
        """An actuator's name and ` of robot <name>` (empty when no robot's)."""
        name = mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, i) or f"#{i}"
        robot = next((r.name for r in self.plan.robots if name.startswith(r.prefix)), None)
        return repr(name), f" of robot {robot}" if robot else ""

    def _bad_control(self, i: int, value: str, now_ns: int) -> str:
        name, robot = self._actuator(i)
        return (
            f"actuator {name}{robot} was given a control of {value} at t = {now_ns / 1e9:.3f} s (sim): the "
            "physics never takes a NaN or Inf (MuJoCo would zero every control, or reset the world), so the "
            "run stops here (the recording keeps everything before). Hint: one of the robot's plugins "
            "computed it: check its parameters and the commands it was given"
        )

    def _instability(self, t0_ns: int, t1_ns: int) -> str:
        """What went unstable, where (the joint of the degree of freedom MuJoCo names, and its robot)."""
        m, d = self.model, self.data
        if d.warning[_BADCTRL].number:  # (the check before each step keeps controls good: not a hook's)
            return self._bad_control(int(d.warning[_BADCTRL].lastinfo), "NaN, Inf or huge", t0_ns)
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
