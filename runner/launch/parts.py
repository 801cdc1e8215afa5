"""What the supervisor runs besides the worlds, each behind one small interface (`Part`): the nodes of this
host, the required nodes of other hosts (watched), the bridge, the recorder, the judge and the live view.

A part is started, asked whether it is ready, polled while the run goes (where it may end the run: one
call to `Supervisor.end`), stopped, finished and closed, in that order; a part that has nothing to do at a
step inherits the no-op. The worlds are parts too (runner.launch.worlds), with the run's time in them.
"""

from __future__ import annotations

import json
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import zenoh

from runner.errors import RunError
from runner.launch import keeper
from runner.launch.nodes import NodeError, Nodes
from runner.plan import NodePlan, RunPlan
from runner.record import Recorder
from runner.record.claim import lock_of
from runner.record.recorder import OTHER_KEYS
from runner.wire import msgs
from runner.wire.graph import GraphTokens
from runner.wire.transport import meta_key, unpack_attachment

if TYPE_CHECKING:
    from runner.launch.worlds import WorldPart

DRAIN_TIMEOUT_S = 3.0  # how long the recorder waits for messages still in flight at the end
DRAIN_HURRIED_S = 0.5  # ... when the run was interrupted (the 2 s a stop may take)


class Run(Protocol):
    """What a part sees of the run that supervises it (runner.launch.supervisor.Supervisor)."""

    plan: RunPlan
    session: Any  # the runner's Zenoh session
    subs: list[Any]  # what to undeclare once the run is done
    worlds: list[WorldPart]
    recorder: RecorderPart | None
    reason: str
    error: str | None
    hurry: threading.Event  # a second signal: stop waiting

    def end(self, reason: str, error: str | None = None, say: str | None = None) -> None: ...

    def announce(self, **changes: str) -> None: ...

    def wait(self, event: threading.Event, timeout_s: float) -> bool: ...

    def reached(self) -> int: ...

    def ending(self) -> str: ...


def wait_for_published(run: Run, counts: Callable[[], dict[str, int]], wanted: Callable[[str], bool]) -> None:
    """Wait until `counts()` holds, for every key `wanted` that a world says it published, as many messages
    as it published (or a timeout: DRAIN_TIMEOUT_S, DRAIN_HURRIED_S once interrupted, none after a second
    signal). What a part that takes the worlds' messages (the recorder, the judge's own subscriptions) does
    at the end, so that the last messages in flight are not lost to it."""
    hurried = run.reason == "interrupted"
    for world in run.worlds:
        if world.child is None and world.remote_host is None:
            continue  # never started (stopped while starting)
        # its end message comes just before it exits (it has by now): interrupted, do not linger
        if not run.wait(world.ended, 0.2 if hurried else 0.5) or run.hurry.is_set():
            continue
        published: dict[str, int] = world.end_info.get("published", {})
        deadline = time.monotonic() + (DRAIN_HURRIED_S if hurried else DRAIN_TIMEOUT_S)
        while time.monotonic() < deadline and not run.hurry.is_set():
            got = counts()
            if all(got.get(k, 0) >= n for k, n in published.items() if wanted(k)):
                break
            run.hurry.wait(0.01)


def published_of(run: Run) -> dict[str, int]:
    """What the worlds published, per key (each key is one world's: its name leads the key)."""
    published: dict[str, int] = {}
    for world in run.worlds:
        published.update(world.end_info.get("published", {}))
    return published


def rejected_of(run: Run) -> dict[str, dict[str, int]]:
    """The inbound messages dropped, per key and why: by the worlds (NaN or Inf values, another type) and
    by the recorder (not recorded)."""
    rejected: dict[str, dict[str, int]] = {}
    for i in (w.end_info for w in run.worlds):
        for key, whys in i.get("rejected", {}).items():
            for why, n in whys.items():
                rejected.setdefault(key, {})[why] = rejected.get(key, {}).get(why, 0) + n
    recorder = run.recorder.recorder if run.recorder is not None else None
    if recorder is not None:
        for key, whys in recorder.mistyped.items():
            for why, n in whys.items():
                rejected.setdefault(key, {}).setdefault(f"not recorded: {why}", n)
    return rejected


def outside_of(run: Run) -> tuple[dict[str, int], list[str]]:
    """The messages put on the run's keys by publishers outside the run (per key), and who they are."""
    recorder = run.recorder.recorder if run.recorder is not None else None
    counts = dict(recorder.outside) if recorder is not None else {}
    if len(counts) > OUTSIDE_SHOWN:  # the keys with most messages, the others together
        beyond = counts.pop(OTHER_KEYS, 0)  # (the recorder's own "more keys than it counts apart")
        top = sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))
        rest = top[OUTSIDE_SHOWN - 1 :]
        counts = dict(top[: OUTSIDE_SHOWN - 1])
        label = f"{'more than ' if beyond else ''}{len(rest)} other keys"
        counts[label] = sum(n for _, n in rest) + beyond
    part = getattr(run, "outside", None)
    return counts, part.seen.foreign() if part is not None and counts else []


OUTSIDE_SHOWN = 20  # keys of publishers outside the run named in the end table and the results, at most


class Part:
    """One supervised part of a run. Every method is a step of the run; the defaults do nothing."""

    label = "part"
    poll_order = -1  # polled before the worlds (< 0) or after them (> 0), in this order

    def start(self, run: Run) -> None:
        """Start processes, subscribe: the run is STARTING."""

    def ready(self) -> bool:
        """Up and listening: the worlds step once every part is."""
        return True

    def poll(self, run: Run) -> None:
        """Called every tick while the run goes (STARTING, RUNNING, STOPPING); may end the run."""

    def stop(self) -> None:
        """Asked to stop (the run is STOPPING)."""

    def close(self, run: Run) -> None:
        """Release what it holds (DONE): always called, however the run ended, once started or not."""


class NodesPart(Part):
    """The nodes of this host: started before the worlds (they connect and subscribe while the worlds
    start; lockstep nodes are waited for by the world itself), stopped after them."""

    label = "nodes"
    poll_order = -3

    def __init__(self, plan: RunPlan, endpoint: str):
        self.nodes = Nodes(plan, endpoint, host=None)

    def start(self, run: Run) -> None:
        try:
            self.nodes.start()
        except NodeError as e:
            raise RunError(str(e)) from None

    def poll(self, run: Run) -> None:
        # once the worlds have ended, nodes leave on their own (runner.node sees the end): no failure
        if run.error is not None or run.reason != "completed" or any(w.ended.is_set() for w in run.worlds):
            return
        ended_by = self.nodes.check()
        if ended_by is not None:
            reason, message = ended_by
            run.end(reason, message if reason == "failed" else None, say=message)

    def close(self, run: Run) -> None:
        self.nodes.stop()


class RemoteNodesPart(Part):
    """Required nodes of other hosts: their runner supervises them; here, their liveliness is watched."""

    label = "remote nodes"
    poll_order = -2

    def __init__(self, nodes: list[NodePlan]):
        self.nodes = nodes
        self.lost: list[str] = []

    def start(self, run: Run) -> None:
        plan = run.plan
        for n in self.nodes:
            world = next((w for w in plan.worlds if n.world and w.name.endswith("/" + n.world)), plan)

            def on_node(sample: zenoh.Sample, n: NodePlan = n) -> None:
                if sample.kind != zenoh.SampleKind.PUT:
                    self.lost.append(f"required node {n.name!r} on host {n.host!r} went away")

            alive_key = meta_key(world.name, "node", n.name)
            run.subs.append(run.session.liveliness().declare_subscriber(alive_key, on_node))

    def poll(self, run: Run) -> None:
        if not self.lost or run.error is not None or run.reason != "completed":
            return
        if not all(w.end_info.get("reason") == "completed" for w in run.worlds):
            run.end("failed", self.lost[0])


class BridgePart(Part):
    """The bridge process is a node; its liveliness token says it has subscribed, so the worlds start only
    then and it misses nothing."""

    label = "bridge"

    def __init__(self) -> None:
        self.up = threading.Event()

    def start(self, run: Run) -> None:
        def on_bridge(sample: zenoh.Sample) -> None:
            if sample.kind == zenoh.SampleKind.PUT:
                self.up.set()

        key = meta_key(run.plan.name, "bridge", "alive")
        run.subs.append(run.session.liveliness().declare_subscriber(key, on_bridge, history=True))

    def ready(self) -> bool:
        return self.up.is_set()


class RecorderPart(Part):
    """The MCAP recording: every key of the run, the compiled plan first; flushed as it goes (a kill loses
    at most a second), drained at the end until it holds what the worlds say they published, and closed
    with a note of how the run ended."""

    label = "recorder"
    poll_order = -4

    def __init__(self, plan: RunPlan, types: dict[str, str], inbound: set[str]):
        try:
            self.recorder = Recorder(
                Path(plan.record.path),
                plan.record.include,
                plan.record.exclude,
                types=types,
                inbound=inbound,
                guarded=True,
                compression=plan.record.compression,
            )
        except OSError as e:
            raise RunError(f"cannot write the recording {plan.record.path}: {e.strerror or e}") from None
        if self.recorder.guard_pid is not None:
            # the one process left to end by itself (it finishes the file of a runner killed outright);
            # then its lock, if the guard was killed too
            keeper.wait_for(self.recorder.guard_pid, lock_of(self.recorder.path))

    def start(self, run: Run) -> None:
        plan, recorder = run.plan, self.recorder
        if recorder.path != recorder.asked:
            print(
                f"another run is recording to {recorder.asked}: this one records to {recorder.path}",
                file=sys.stderr,
                flush=True,
            )
            plan.record.path = str(recorder.path)
            run.announce(recording=str(recorder.path))
        # the recorder's own FIFO subscriber, drained by its thread; undeclared (after recording what it
        # still queued) by recorder.close()
        recorder.subscribe(run.session, f"{plan.name}/**")
        # the scenario as compiled, so the recording can be judged and reported on by itself
        text = msgs.T["std_msgs/msg/String"](data=plan.model_dump_json())
        recorder.write(
            f"{plan.name}/_plan", "std_msgs/msg/String", msgs.encode(text, "std_msgs/msg/String"), (0, 0)
        )
        graph = GraphTokens(run.session, plan.name, "recorder", "recorder")
        graph.subscriber(f"{plan.name}/**")
        run.subs.append(graph)

    def poll(self, run: Run) -> None:
        recorder = self.recorder
        recorder.flush_stale(1.0)  # killed outright, the file loses at most a second
        if recorder.error is not None and run.error is None:
            # the disk is full (or the file cannot be written): nothing more can be kept
            why = recorder.error.strerror or str(recorder.error)
            run.end("failed", f"the recording stopped: {why} ({recorder.path})")

    def drain(self, run: Run) -> None:
        """Wait until the recorder holds every message each world says it published (or a timeout; a
        shorter one once interrupted, and none at all after a second signal)."""
        recorder = self.recorder
        wait_for_published(run, recorder.counts, recorder.wanted)

    def close(self, run: Run) -> None:
        # how the run ended, for judging the recording by itself later (`scenario check`)
        rejected = rejected_of(run)
        outside, outsiders = outside_of(run)
        said = {"rejected": json.dumps(rejected)} if rejected else {}  # (key -> why -> how many)
        if outside:  # (key -> how many, and who: the sessions outside the run)
            said["outside"] = json.dumps({"messages": outside, "from": outsiders})
        self.recorder.end_note(ended=run.ending(), sim_ns=str(run.reached()), **said)
        self.recorder.close()


class JudgePart(Part):
    """The live judge: fed every message it asks for, decoded (from the recorder, in its order and thread,
    for the keys it records; subscribed otherwise); with `stop_on`, it ends the run early."""

    label = "judge"
    poll_order = 1

    def __init__(self, judge: Any):
        self.judge = judge
        self.decided = threading.Event()
        self.own: dict[str, int] = {}  # messages taken by its own subscriptions (keys not recorded), per key
        self.fed: dict[str, tuple[int, int]] = {}  # key -> (messages fed to the judge, the last one's sim ns)
        self.tapped: list[str] = []  # the keys it reads from the recorder
        self._lock = threading.Lock()

    def feeder(self, plan: RunPlan) -> Callable[[str, int, bytes], None]:
        """What takes each message for the judge, `feed(key, sim ns, payload)`: decoded, counted (to know
        later whether it got all the worlds published, `close`), judged."""
        from runner.checks.judge import judged_types

        judge, types, lock, fed = self.judge, judged_types(plan), self._lock, self.fed

        def feed(key: str, stamp_ns: int, payload: bytes) -> None:
            msg = msgs.decode(payload, types[key])
            with lock:
                n, last = fed.get(key, (0, 0))
                fed[key] = (n + 1, max(last, stamp_ns))
                judge.feed(key, stamp_ns, msg)
                if (plan.stop_on == "first_failure" and judge.failed()) or (
                    plan.stop_on == "all_decided" and judge.all_decided()
                ):
                    self.decided.set()

        return feed

    def start(self, run: Run) -> None:
        judge, lock = self.judge, self._lock
        feed = self.feeder(run.plan)
        keys = sorted(judge.keys)
        if run.recorder is not None:
            tapped = [k for k in keys if run.recorder.recorder.wanted(k)]
            run.recorder.recorder.tap(tapped, feed)
            self.tapped = tapped
            keys = [k for k in keys if k not in tapped]
        own = self.own
        for key in keys:
            own[key] = 0

            def on_sample(sample: zenoh.Sample) -> None:
                att = sample.attachment
                parsed = unpack_attachment(att.to_bytes()) if att is not None else None
                if parsed is not None:
                    key = str(sample.key_expr)
                    feed(key, parsed[1], sample.payload.to_bytes())
                    with lock:
                        own[key] = own.get(key, 0) + 1

            run.subs.append(run.session.declare_subscriber(key, on_sample))

    def drain(self, run: Run) -> None:
        """As the recorder does: wait for the messages still in flight on the keys it subscribed itself
        (without a recording, every key it judges), so that the last ones are judged too."""
        own, lock = self.own, self._lock

        def counts() -> dict[str, int]:
            with lock:
                return dict(own)

        if own:
            wait_for_published(run, counts, own.__contains__)

    def poll(self, run: Run) -> None:
        if self.decided.is_set() and run.reason == "completed":
            run.end("stopped")

    def close(self, run: Run) -> None:
        """Tell the judge where its data stopped short of what the worlds ran: the recording it reads
        could not be written past a point (a full disk), or it got fewer messages on a key than the
        worlds published (its subscription lost them, the drain timed out). The world ran on past
        there, so what it did then is not decided on the data it had (which once failed a `reach` the
        full run passes)."""
        from runner.checks.judge import stops

        judge, recorder = self.judge, run.recorder.recorder if run.recorder is not None else None
        if recorder is not None and recorder.error is not None and recorder.stopped_ns is not None:
            cause = recorder.error.strerror or str(recorder.error)
            judge.data_stops(
                recorder.stopped_ns, stops("the recording", recorder.stopped_ns, cause), self.tapped
            )
        published = published_of(run)
        with self._lock:
            fed = dict(self.fed)
        for key in sorted(judge.keys - judge.events_keys):
            n, (got, last) = published.get(key, 0), fed.get(key, (0, 0))
            if got < n and key not in judge.cuts:
                why = f"it received {got} of the {n} messages published on {key}"
                judge.data_stops(last, stops("the judge's data", last, why), [key])


class LiveViewPart(Part):
    """`--foxglove PORT`: the run, live, to Foxglove (runner.launch.live)."""

    label = "live view"

    def __init__(self, session: zenoh.Session, run: str, port: int, origins: tuple[str, ...] = ()):
        from runner.launch.live import LiveView

        self.view = LiveView(session, run, port, origins=origins)
        print(f"Foxglove: connect to ws://127.0.0.1:{self.view.port}", file=sys.stderr, flush=True)

    def close(self, run: Run) -> None:
        self.view.close()
