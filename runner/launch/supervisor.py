"""The run as a small supervisor: explicit states, one interface for every part, one transition per cause.

    (compiling) -> STARTING -> RUNNING -> STOPPING -> DRAINING -> DONE
                      \\__________________/^

- compiling happens before the supervisor exists (`scenario run` loads and compiles): nothing is started
  or recorded, so Ctrl-C/SIGTERM end the command at once (runner.interrupts.exit_at_once).
- STARTING: the router session, the live view, the recorder, the subscribers, the nodes, then the worlds;
  once every part is ready the word to step is given (a liveliness token every world waits for) -> RUNNING.
- RUNNING: every tick (50 ms) each part is polled; the run ends on the first cause: the worlds reached the
  end of time, a signal, a part that died or failed, the judge's early stop, a required node that finished.
  Each is one call, `end(reason, error)`, which stops the worlds -> STOPPING.
- STOPPING: the worlds (and their renderers) stop; how each ended is collected -> DRAINING.
- DRAINING: the recorder waits for every message the worlds say they published -> DONE.
- DONE: the nodes stop, subscribers and the session close, the recording is finished with a note of how
  the run ended. Always reached, whatever happened before (an error escaping a step included). Last, the
  run's keeper (runner.launch.keeper) ends whatever the parts left behind (a node's own children).

Every process the run starts ends with the runner however the runner ends (kill -9, the OOM killer, a CI
job's timeout killing its process group): the kernel signals each child when the runner dies, and the
keeper, a process started first in a session of its own, ends their children (runner.launch.keeper).

Signals never raise inside the supervisor: SIGINT/SIGTERM set a flag the loop reads at its next tick (any
state), so nothing is cut half-way (a recording being closed, a process being started). A second signal
while stopping or draining hurries: no more waiting for messages in flight. A stop takes at most the
worlds' grace period (1.2 s) plus a short drain.
"""

from __future__ import annotations

import contextlib
import enum
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import zenoh

from runner import interrupts
from runner.errors import RunError
from runner.launch.announce import announce, update_announcement, withdraw
from runner.launch.keeper import Keeper
from runner.launch.outside import OutsidePart
from runner.launch.parts import (
    BridgePart,
    JudgePart,
    LiveViewPart,
    NodesPart,
    Part,
    RecorderPart,
    RemoteNodesPart,
)
from runner.launch.worlds import _check_start, connectable, world_parts
from runner.plan import RunPlan
from runner.wire import msgs
from runner.wire.transport import make_config, meta_key, unpack_attachment, zenoh_reason

TICK_S = 0.05


class State(enum.Enum):
    STARTING = "starting"
    RUNNING = "running"
    STOPPING = "stopping"
    DRAINING = "draining"
    DONE = "done"


class Supervisor:
    """Runs one plan on the main host (see the module docstring). `run()` once; then the fields say how it
    went (`reason`, `error`, `reached()`, the recorder's statistics)."""

    def __init__(
        self,
        plan: RunPlan,
        listen: Sequence[str],
        connect: Sequence[str] = (),
        on_progress: Callable[[int, float], None] | None = None,
        judge: Any = None,
        foxglove_port: int | None = None,
        foxglove_origins: tuple[str, ...] = (),
    ):
        self.plan = plan
        self.listen = list(listen)
        self.connect = list(connect)
        self.on_progress = on_progress
        self.judge = judge
        self.foxglove_port = foxglove_port
        self.foxglove_origins = foxglove_origins
        self.state = State.STARTING
        self.reason = "completed"  # completed | stopped | interrupted | failed
        self.error: str | None = None
        self.signalled = threading.Event()  # SIGINT/SIGTERM arrived: the loop ends the run at its next tick
        self.hurry = threading.Event()  # a second one, while stopping or draining: stop waiting
        self.worlds = world_parts(plan, None)
        self.parts: list[Part] = []
        self.recorder: RecorderPart | None = None
        self.outside: OutsidePart | None = None
        self.subs: list[Any] = []
        self.session: Any = None
        self.endpoint = connectable(self.listen[0])
        self.latest_ns = 0  # the latest sim time seen (from the clock, when nothing records)
        self.wall0 = time.perf_counter()  # (again once the worlds are started)
        self.started_at = 0.0
        self._announced: Path | None = None
        self._go: Any = None
        self._failed_by: BaseException | None = None
        self.trace = _tracer()

    # -- the states ------------------------------------------------------------------------------------

    def run(self) -> None:
        """Start, run, stop, drain, finish; a RunError of a step is raised after everything is closed."""
        with self._signals():
            self.trace(self.state)
            # first: every process started after it ends with the run, however the runner ends
            keeper = Keeper()
            try:
                self._start()
                self._supervise()
                self._stop()
                self._drain()
                if self.signalled.is_set():  # (a signal while stopping or draining: still interrupted)
                    self.reason = "interrupted"
            except BaseException as e:
                self._failed_by = e
                self._stop_quietly()
                raise
            finally:
                try:
                    self._close()
                finally:
                    keeper.close()  # (last: what the parts left behind, a node's own children, ends)

    def _start(self) -> None:
        plan = self.plan
        try:
            self.session = zenoh.open(make_config("router", listen=self.listen, connect=self.connect))
        except zenoh.ZError as e:
            raise RunError(
                f"cannot open the Zenoh network on {', '.join(self.listen)}: {zenoh_reason(e)}"
            ) from None
        self.outside = OutsidePart()  # (first: it hears of every session that joins)
        self.parts.append(self.outside)
        if self.foxglove_port is not None:
            self.parts.append(
                LiveViewPart(self.session, plan.name, self.foxglove_port, self.foxglove_origins)
            )
        # `scenario echo/pub/topics` find the local run by it
        recording = plan.record.path if plan.record.enabled else None
        self._announced = announce(plan.name, self.listen, plan.zenoh, recording=recording)
        if plan.record.enabled:
            self.recorder = RecorderPart(plan, *_keys(plan))
            self.parts.append(self.recorder)
        if plan.bridges:
            self.parts.append(BridgePart())
        if self.judge is not None:
            self.parts.append(JudgePart(self.judge))
        remote = [n for n in plan.nodes if n.required and not plan.on_host(None, n.host)]
        if remote:
            self.parts.append(RemoteNodesPart(remote))
        if any(plan.on_host(None, n.host) for n in plan.nodes):
            self.parts.append(NodesPart(plan, self.endpoint))
        if self.recorder is None:
            for w in self.worlds:
                self.subs.append(self.session.declare_subscriber(w.plan.clock_key, self._on_clock))
        for w in self.worlds:
            self.subs += w.watch(self.session)
        for part in self.parts:  # the nodes last of these: they connect while the worlds start
            if self.signalled.is_set():
                return
            part.start(self)
        for w in self.worlds:
            if w.remote_host is None and not self.signalled.is_set():  # the others: their host's runner
                w.start(self.endpoint)
        self.wall0 = time.perf_counter()

    def _supervise(self) -> None:
        """STARTING and RUNNING: tick until the worlds have ended (or the run ends another way)."""
        waiting: set[str] = set()  # the other hosts this run said it waits for
        # polled in the order the causes are told apart: the recording, the nodes, the worlds, the judge
        before = sorted((p for p in self.parts if p.poll_order < 0), key=lambda p: p.poll_order)
        after = sorted((p for p in self.parts if p.poll_order > 0), key=lambda p: p.poll_order)
        while any(w.running() for w in self.worlds) and not self.signalled.is_set():
            self.signalled.wait(TICK_S)
            if self.signalled.is_set():
                break
            ready = self.ready()
            if ready and self.state is State.STARTING:
                self._go_on()
            for part in before:
                part.poll(self)
            self._poll_worlds()
            for part in after:
                part.poll(self)
            if ready and self.on_progress is not None:
                sim_ns = self.recorder.recorder.latest_ns if self.recorder else self.latest_ns
                self.on_progress(sim_ns, time.perf_counter() - self.started_at)
            if not ready:
                _check_start(self.worlds, time.perf_counter() - self.wall0, waiting)
        if self.signalled.is_set():
            self.end("interrupted")

    def _stop(self) -> None:
        """STOPPING: every world stopped (already, when the end of time came); how each ended."""
        self._set(State.STOPPING)
        self._stop_worlds()
        interrupted = self.reason == "interrupted"
        for w in self.worlds:
            err = w.finish(interrupted)
            if err is not None and (self.error is None or self.reason == "completed"):
                self.reason, self.error = "failed", err
                # said at once (the full report follows once everything has stopped)
                print(err.splitlines()[0] + "; stopping the run", file=sys.stderr, flush=True)
            elif err is not None and self.reason == "failed" and not self.error:
                self.error = err

    def _drain(self) -> None:
        self._set(State.DRAINING)
        if any(w.died for w in self.worlds):
            return
        if self.recorder is not None:
            self.recorder.drain(self)
        for part in self.parts:
            if isinstance(part, JudgePart):
                part.drain(self)

    def _close(self) -> None:
        """DONE: everything released in order, whatever happened before."""
        self._set(State.DONE)
        for part in reversed(self.parts):  # the nodes first, the recorder and the live view last
            if not isinstance(part, RecorderPart | LiveViewPart):
                _quietly(part.close, self)
        for w in self.worlds:
            w.cleanup()
        for s in self.subs:
            with contextlib.suppress(Exception):
                s.undeclare()
        if self.recorder is not None:
            self.recorder.close(self)
        for part in self.parts:
            if isinstance(part, LiveViewPart):
                _quietly(part.close, self)
        if self.session is not None:
            self.session.close()
        if self._announced is not None:
            withdraw(self._announced)

    # -- transitions -----------------------------------------------------------------------------------

    def end(self, reason: str, error: str | None = None, say: str | None = None) -> None:
        """End the run: `reason` (stopped, failed, interrupted) with its error; the cause is said at once
        (the full report follows once everything has stopped) and the worlds are stopped."""
        if reason != "interrupted":
            self.reason = reason
            if error is not None:
                self.error = error
            message = say or error
            if message:
                print(message.splitlines()[0] + "; stopping the run", file=sys.stderr, flush=True)
        else:
            self.reason = "interrupted"
        self._set(State.STOPPING)
        self._stop_worlds()

    def ready(self) -> bool:
        return all(w.ready.is_set() for w in self.worlds) and all(p.ready() for p in self.parts)

    def _go_on(self) -> None:
        """Every part is up (here and on other hosts): they start together, on this word."""
        self.started_at = time.perf_counter()
        self._go = self.session.liveliness().declare_token(meta_key(self.plan.name, "go"))
        self.subs.append(self._go)
        self._set(State.RUNNING)

    def _poll_worlds(self) -> None:
        for w in self.worlds:
            stopped_there = w.remote_host is not None and w.end_info.get("reason") == "stopped"
            if stopped_there and self.error is None and self.reason == "completed":
                # another host stopped its part (its node failed, it was interrupted): all stop
                time.sleep(0.2)  # the cause (a lost node's liveliness) may be just behind
                lost = [msg for p in self.parts if isinstance(p, RemoteNodesPart) for msg in p.lost]
                self.end("failed", lost[0] if lost else f"the {w.label} on host {w.remote_host!r} stopped")
            if w.dead() and self.error is None and self.reason == "completed" and len(self.worlds) > 1:
                # one world died: said at once, the others stop too (the full report follows)
                print(f"the {w.label} process died; stopping the run", file=sys.stderr, flush=True)
                self._stop_worlds()
            rerr = w.renderer_error()
            if rerr is not None and self.error is None:
                self.reason, self.error = "failed", rerr
                self._stop_worlds()

    def _stop_worlds(self) -> None:
        if self._go is not None:  # the word withdrawn: the worlds of other hosts stop too
            with contextlib.suppress(Exception):
                self._go.undeclare()
            self._go = None
        for w in self.worlds:
            w.stop()

    def _stop_quietly(self) -> None:
        """An error escaped a step: the worlds stop (no report of theirs: the error is the report)."""
        with contextlib.suppress(Exception):
            self._stop_worlds()

    def _set(self, state: State) -> None:
        if state is not self.state:
            self.state = state
            self.trace(state)

    # -- what parts ask ----------------------------------------------------------------------------------

    def reached(self) -> int:
        """The sim time the run reached: the least its worlds say they reached (one that said nothing,
        having died: the latest time recorded or seen)."""
        fallback = self.recorder.recorder.latest_ns if self.recorder else self.latest_ns
        return min(int(w.end_info.get("sim_ns", fallback)) for w in self.worlds)

    def ending(self) -> str:
        """How the run ended, as the recording notes it."""
        how = interrupts.ending("interrupted" if self.signalled.is_set() else self.reason)
        if self._failed_by is not None and not isinstance(self._failed_by, KeyboardInterrupt):
            how = "failed"  # (a start-up that timed out...: leaving through an error)
        elif self.error is not None and how == "completed":
            how = "failed"
        return how

    def announce(self, **changes: str) -> None:
        if self._announced is not None:
            update_announcement(self._announced, **changes)

    def wait(self, event: threading.Event, timeout_s: float) -> bool:
        """Wait for `event`, but not past a second signal."""
        deadline = time.monotonic() + timeout_s
        while not event.is_set() and not self.hurry.is_set() and time.monotonic() < deadline:
            event.wait(min(TICK_S, max(0.0, deadline - time.monotonic())))
        return event.is_set()

    def _on_clock(self, sample: zenoh.Sample) -> None:
        att = sample.attachment
        parsed = unpack_attachment(att.to_bytes()) if att is not None else None
        if parsed:
            self.latest_ns = max(self.latest_ns, parsed[1])

    @contextlib.contextmanager
    def _signals(self) -> Iterator[None]:
        """SIGINT/SIGTERM as a transition: a flag for the loop (a second one hurries the stop); the
        command's own handlers are back once the run is done. (A run in a thread other than the main one,
        a test's, cannot set handlers: there, the caller stops it.)"""
        if threading.current_thread() is not threading.main_thread():
            yield
            return

        def on_signal(signum: int, _frame: Any) -> None:
            interrupts.note(signum)
            if self.signalled.is_set() or self.state in (State.STOPPING, State.DRAINING, State.DONE):
                self.hurry.set()
            self.signalled.set()

        before = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM)}
        try:
            yield
        finally:
            for s, handler in before.items():
                signal.signal(s, handler)


def _keys(plan: RunPlan) -> tuple[dict[str, str], set[str]]:
    """The type of each key the plan's worlds publish or subscribe (what the recorder accepts there), and
    the keys they subscribe without publishing them: what other processes send them."""
    types: dict[str, str] = {}
    subs, pubs = set(), set()
    for part in plan.every_plan():
        for robot in part.robots:
            for p in robot.plugins:
                for t in p.topics:
                    types.setdefault(t.key, msgs.normalize_type(t.type))
                    (subs if t.direction == "sub" else pubs).add(t.key)
        for ev in part.timeline:
            if not ev.call:  # (a call's key is a service's)
                types.setdefault(ev.key, ev.type)
    return types, subs - pubs


def _quietly(fn: Callable[..., None], *args: Any) -> None:
    try:
        fn(*args)
    except Exception as e:  # one part failing to close must not keep the others (the recording) open
        print(f"while closing: {e}", file=sys.stderr, flush=True)


def _tracer() -> Callable[[State], None]:
    """`SCENARIO_TRACE=states` prints each state as the run enters it (for tests and for debugging)."""
    import os

    if "states" not in os.environ.get("SCENARIO_TRACE", "").split(","):
        return lambda _state: None
    return lambda state: print(f"[supervisor] {state.value}", file=sys.stderr, flush=True)
