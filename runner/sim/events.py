"""Events played in the world (`events:`, compiled by runner.compile.events): at each step boundary where
something may fire, the events are looked at in their plan order, and each whose trigger holds fires: its
actions run at once, in order, and the firing is published on `<run>/_events`.

When triggers are looked at: a time (`at`) and a delayed `after` at the exact step of their time; `near`,
`enter` and `leave` every `TICK_NS` (10 ms of sim time; bodies are where the physics has them at that
step); `message` at the first boundary after a message for which its expression holds (published by a
sensor at that boundary, by an earlier event of the step, or received from a node); `assertion` when the
world's own copy of the judge decides it; `after` (no delay) in the same step, after the event it follows.

The step's order (runner.sim.world): sensors publish, the timeline, messages from other processes, then
events (actors move after them, on ticks), then controllers act on the commands, then the clock."""

from __future__ import annotations

import heapq
import json
import math
from collections.abc import Callable
from typing import Any, Protocol

import mujoco
import numpy as np

from runner.checks.judge import events_key
from runner.plan import EventPlan, RunPlan
from runner.scenario.schema import Region
from runner.sim.actors import TICK_NS, Actors
from runner.sim.event_actions import act
from runner.sim.faults import Fault
from runner.wire import msgs
from runner.wire.cdr import string_message

_EVENTS_STREAM = 1_000_003  # random streams of events' faults: (seed, this + event index)


class EventWorld(Protocol):
    """What events act on: the world (runner.sim.world.World)."""

    plan: RunPlan
    model: mujoco.MjModel
    data: mujoco.MjData

    def make_publisher(self, key: str, type_name: str) -> Any: ...
    def listen(
        self,
        key: str,
        type_name: str,
        callback: Callable[[Any, int], None],
        fields: list[str] | None = None,
    ) -> None: ...
    def plugin_at(self, index: int) -> Any: ...
    def set_rate(self, index: int, rate: float, now_ns: int) -> None: ...
    def end_here(self, why: str) -> None: ...


class _Event:
    def __init__(self, plan: EventPlan, index: int):
        self.plan = plan
        self.name = plan.name
        self.kind = plan.when["kind"]
        self.index = index
        self.done = False  # fired, and fires once
        self.pending: str | None = None  # fire at the next look, saying why
        self.due: list[int] = []  # times to fire (`at`, delayed `after`)
        self.inside: bool | None = None  # the last look's answer (near, enter, leave)
        self.spatial = self.kind in ("near", "enter", "leave")
        self.region = Region.model_validate(plan.when["region"]) if "region" in plan.when else None
        self.at = 0  # (spatial) where its body's (x, y) is in what `Events._where` gathers
        self.to_at = 0  # (near another body) where that body's is
        self.fired = 0
        # (spatial) `look(where)`: why it fires at this look, or None (made by `Events._looker`)
        self.look: Callable[[list[list[float]]], str | None] | None = None


class Events:
    """The events and actors of one world. `boundary(now)` when `now >= next_ns`."""

    def __init__(self, world: EventWorld):
        plan = world.plan
        self.world = world
        self.m, self.d = world.model, world.data
        self.actors = Actors(self.m, self.d, plan.actors) if plan.actors else None
        self.events = [_Event(p, i) for i, p in enumerate(plan.events)]
        self.by_name = {e.name: e for e in self.events}
        self.followers: dict[str, list[_Event]] = {}
        self.seed = plan.seed
        self.next_tick = 0
        self.next_ns = 0
        self.faults: dict[str, tuple[Fault, Any]] = {}  # key -> (fault, its Outgoing)
        self.pushes: list[tuple[int, int, np.ndarray]] = []  # (until_ns, body, force and torque on it)
        self.spatial = [e for e in self.events if e.kind in ("near", "enter", "leave")]
        self.out = world.make_publisher(events_key(plan.name), "std_msgs/msg/String") if self.events else None
        self.log: list[dict[str, Any]] = []
        self._messages: dict[int, tuple[Any, bytes]] = {}  # publish actions' messages, by the action's id
        self._bodies_at: list[int] = []  # what spatial triggers look at (see `_locator`)
        self._geoms_at: list[int] = []
        for e in self.events:
            when = e.plan.when
            if e.kind == "at":
                e.due.append(when["t_ns"])
            elif e.kind == "after":
                self.followers.setdefault(when["event"], []).append(e)
            elif e.kind == "message":
                self._listen_message(e)
            elif e.kind == "assertion":
                self._listen_assertion(e, plan)
            elif e.kind in ("near", "enter", "leave"):
                e.at = self._locator(when["body"])
                if e.kind == "near" and isinstance(when["to"], dict):
                    e.to_at = self._locator(when["to"])
        self._bodies = np.asarray(self._bodies_at, dtype=np.int64)
        self._geoms = np.asarray(self._geoms_at, dtype=np.int64)
        for e in self.spatial:
            e.look = self._looker(e)
        # what a boundary looks at, so that it does not walk every event at every step: the spatial
        # events not done (at ticks), those with times (`at`, delayed `after`), and those a message or an
        # assertion made pending since the last boundary (by plan index: they are looked at in plan order)
        self._spatial_queue = [e.index for e in self.spatial]  # those not done
        self._timed = [
            e for e in self.events if e.kind == "at" or (e.kind == "after" and e.plan.when["delay_ns"])
        ]
        self._flagged: list[int] = []
        self._queue: list[int] | None = None  # the indices still to look at in this boundary
        self._current = -1  # the index being looked at

    # -------------------------------------------------------------------------------- triggers
    def _locator(self, ref: dict[str, Any]) -> int:
        """Where the body's (or geom's) ground position will be in what `_where` gathers."""
        if "geom" in ref:
            self._geoms_at.append(mujoco.mj_name2id(self.m, mujoco.mjtObj.mjOBJ_GEOM, ref["geom"]))
            return -len(self._geoms_at)  # geoms from the end, bodies from the start
        self._bodies_at.append(mujoco.mj_name2id(self.m, mujoco.mjtObj.mjOBJ_BODY, ref["body"]))
        return len(self._bodies_at) - 1

    def _where(self) -> list[list[float]]:
        """The (x, y) of every body the spatial triggers look at, where the physics has them now: one
        array gather for all, then plain floats."""
        d = self.d
        xy: list[list[float]] = d.xpos[self._bodies, :2].tolist() if len(self._bodies) else []
        if len(self._geoms):
            xy += d.geom_xpos[self._geoms[::-1], :2].tolist()
        return xy

    def _listen_message(self, e: _Event) -> None:
        from runner.checks.expr import compile_expr

        when = e.plan.when
        expr = compile_expr(when["expr"])

        def on_message(msg: Any, stamp_ns: int) -> None:
            if e.done or e.pending is not None:
                return
            try:
                ok = expr.test(msg)
            except Exception:  # a reducer over nothing, a missing field: not true
                return
            if ok:
                e.pending = f"`{when['expr']}` on {when['topic']}"
                self._flag(e)
                self.next_ns = 0

        self.world.listen(when["key"], when["type"], on_message, sorted(expr.fields))

    def _listen_assertion(self, e: _Event, plan: RunPlan) -> None:
        from runner.checks import specs_from_plan
        from runner.checks.judge import Judge, judged_types

        when = e.plan.when
        spec = specs_from_plan([plan.assertions[when["index"]]])[0]
        key = plan.assertion_keys[when["index"]]
        judge = Judge([spec], [key])
        want = "pass" if when["becomes"] == "pass" else "fail"
        types = judged_types(plan)

        def on_message(msg: Any, stamp_ns: int) -> None:
            if e.done or e.pending is not None:
                return
            judge.feed(key, stamp_ns, msg)
            result = judge.checks[0].result
            if result is not None and result.status == want:
                e.pending = (
                    f"assertion {when['name']!r} {'passed' if want == 'pass' else 'failed'}: {result.message}"
                )
                self._flag(e)
                self.next_ns = 0

        self.world.listen(key, types[key], on_message)

    def _looker(self, e: _Event) -> Callable[[list[list[float]]], str | None]:
        """`look(where)` for a spatial event: whether its body came near, entered or left, at this look
        (`where`: what `_where` gathered at this step), with its numbers bound once."""
        when = e.plan.when
        at, who = e.at, when["body"]["name"]
        if e.kind == "near":
            within = when["within"]
            to_body = isinstance(when["to"], dict)
            to_at = e.to_at
            tx0, ty0 = (0.0, 0.0) if to_body else when["to"]

            def near(where: list[list[float]]) -> str | None:
                x, y = where[at]
                tx, ty = where[to_at] if to_body else (tx0, ty0)
                dist = math.hypot(x - tx, y - ty)
                now_in = dist <= within
                was, e.inside = e.inside, now_in
                if now_in and not was:
                    to = when["to"]["name"] if to_body else f"[{tx:g}, {ty:g}]"
                    return f"{who} within {within:g} m of {to} ({dist:.2f} m)"
                return None

            return near
        contains = e.region.contains  # type: ignore[union-attr]
        entering = e.kind == "enter"

        def crossing(where: list[list[float]]) -> str | None:
            x, y = where[at]
            now_in = contains(x, y)
            was, e.inside = e.inside, now_in
            if was is None or was == now_in:
                return None  # (the first look sets where it is: entering or leaving is a change)
            if entering and now_in:
                return f"{who} entered {when['label']} at ({x:.2f}, {y:.2f})"
            if not entering and not now_in:
                return f"{who} left {when['label']} at ({x:.2f}, {y:.2f})"
            return None

        return crossing

    # -------------------------------------------------------------------------------- the step
    def boundary(self, now: int) -> None:
        if self.faults:
            for key, (fault, out) in list(self.faults.items()):
                fault.release(out, now)
                if fault.until_ns is not None and now >= fault.until_ns:
                    out.fault = None  # over: new messages go straight out...
                    fault.until_ns = None
                if out.fault is not fault and not fault.held:  # ... and what it holds, each at its time
                    del self.faults[key]
        if self.pushes:
            for _until, body, wrench in [p for p in self.pushes if p[0] <= now]:
                self.d.xfrc_applied[body] -= wrench
            self.pushes = [p for p in self.pushes if p[0] > now]
        tick = now >= self.next_tick
        queue = self._spatial_queue[:] if tick else []  # (in plan order: a heap)
        if self._flagged:
            queue += self._flagged
            self._flagged = []
        for e in self._timed:
            if e.due and e.due[0] <= now:
                queue.append(e.index)
        if queue:
            heapq.heapify(queue)
            self._queue = queue
            self._look(queue, now, tick)
            self._queue = None
        if tick:
            if self.actors is not None:
                self.actors.tick(now)
            self.next_tick = (now // TICK_NS + 1) * TICK_NS
        self.next_ns = self._next(now)

    def _look(self, queue: list[int], now: int, tick: bool) -> None:
        """The events of `queue` (plan indices) in plan order, each fired if its trigger holds now: made
        pending (by a message, an assertion, the event it follows), due (its time has come), or, at a tick,
        its body near or across a border. Where the bodies are is gathered once, and again after a firing
        (a teleport moves one)."""
        events = self.events
        where = None
        last = -1
        while queue:
            i = heapq.heappop(queue)
            if i == last:
                continue
            last = self._current = i
            e = events[i]
            if e.done:
                continue
            if e.pending is not None:
                why, e.pending = e.pending, None
            elif e.due and e.due[0] <= now:
                e.due.pop(0)
                why = (
                    f"at {now / 1e9:g} s"
                    if e.kind == "at"
                    else f"{e.plan.when['delay_ns'] / 1e9:g} s after {e.plan.when['event']}"
                )
            elif tick and e.look is not None:
                if where is None:
                    where = self._where()
                why = e.look(where)
            else:
                continue
            if why is not None:
                self._fire(e, now, why)
                where = None

    def _flag(self, e: _Event) -> None:
        """`e` has become pending: looked at in this boundary if it comes later in the plan than the event
        being looked at (an event that follows another, by `after` or a message it publishes, does), else
        at the next boundary."""
        if self._queue is not None and e.index > self._current:
            heapq.heappush(self._queue, e.index)
        else:
            self._flagged.append(e.index)

    def _next(self, now: int) -> int:
        nxt = self.next_tick if (self.actors is not None or self.spatial) else 2**62
        for e in self._timed:
            if e.due and not e.done and e.due[0] < nxt:
                nxt = e.due[0]
        if self.faults:
            for fault, _out in self.faults.values():
                t = fault.next_ns()
                if t is not None and t < nxt:
                    nxt = t
        for until, _b, _w in self.pushes:
            if until < nxt:
                nxt = until
        return nxt if nxt > now else now + 1

    def _fire(self, e: _Event, now: int, why: str) -> None:
        e.fired += 1
        if not e.plan.repeat:
            e.done = True
            if e.spatial:
                self._spatial_queue = [x.index for x in self.spatial if not x.done]
        did = [self._do(e, a, now) for a in e.plan.do]
        end = next((a for a in e.plan.do if a["kind"] == "end"), None)
        entry = {"event": e.name, "t": now / 1e9, "why": why, "did": did, "n": e.fired}
        if end is not None:
            entry["end"] = {"result": end["result"], "message": end["message"]}
        self.log.append(entry)
        if self.out is not None:
            self.out.publish_encoded(string_message(json.dumps(entry)), None, now)
        for f in self.followers.get(e.name, ()):
            if f.done:
                continue
            delay = f.plan.when["delay_ns"]
            if delay == 0:
                f.pending = f"after {e.name}"
                self._flag(f)
            else:
                f.due.append(now + delay)
                f.due.sort()
        if end is not None:
            self.world.end_here(
                f"event {e.name}: {end['result']}" + (f" ({end['message']})" if end["message"] else "")
            )

    def _do(self, e: _Event, a: dict[str, Any], now: int) -> str:
        return act(self, e, a, now)

    def message_of(self, action: dict[str, Any]) -> tuple[Any, bytes]:
        """The message a `publish` action sends and its bytes, built once (its data never changes)."""
        built = self._messages.get(id(action))
        if built is None:
            msg = msgs.from_data(action["type"], action["data"])
            built = self._messages[id(action)] = (msg, msgs.encode(msg, action["type"]))
        return built

    def wake(self, t_ns: int) -> None:
        """Be looked at again at `t_ns` at the latest (a fault holds a message due then)."""
        self.next_ns = min(self.next_ns, t_ns)

    def fault_rng(self, e: _Event, k: int) -> np.random.Generator:
        return np.random.default_rng([self.seed, _EVENTS_STREAM + e.index, k])
