"""launch: host the run's Zenoh router, record, start the world process, and shut down in order.

The runner process holds the embedded Zenoh router (a Python session in router mode: no zenohd needed)
and the recorder. The world is a separate OS process that connects to the router as a client. On the
end of the run, a failure or Ctrl-C: the world is stopped (SIGINT, then SIGKILL after a grace period),
the recorder waits for the messages the world says it published, and the MCAP file is finished.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import zenoh

from runner.errors import RunError
from runner.interrupts import ending, interruptible
from runner.launch.announce import announce, update_announcement, withdraw
from runner.launch.nodes import NodeError, Nodes, OutputTail
from runner.plan import NodePlan, RunPlan
from runner.record.recorder import Recorder, TopicStats
from runner.wire import msgs
from runner.wire.graph import GraphTokens
from runner.wire.transport import free_port, make_config, meta_key, unpack_attachment, zenoh_reason

STOP_GRACE_S = 1.2  # after SIGINT, how long the world gets before SIGKILL
DRAIN_TIMEOUT_S = 3.0  # how long the recorder waits for messages still in flight at the end
# How long the parts of this host may take to start (compile, load MuJoCo, connect) before the run gives up:
# a guard against a hang, with room for a machine loaded by other runs.
START_TIMEOUT_S = 60.0
# How long the main host waits for the other hosts' runners (`scenario run FILE --host NAME`, started by
# hand or by another tool) to join. The worlds wait longer for the word to start (runner.sim).
HOST_JOIN_TIMEOUT_S = 180.0
HOST_WAIT_NOTICE_S = 5.0  # when the run says which hosts it waits for


def _check_start(parts: Sequence[_WorldPart], waited_s: float, waiting: set[str]) -> None:
    """While the parts start: say which other hosts the run waits for (once, after a few seconds), and give
    up on a part of this host after START_TIMEOUT_S, on another host's after HOST_JOIN_TIMEOUT_S."""
    late = [p for p in parts if not p.ready.is_set()]
    hosts = sorted({p.remote_host for p in late if p.remote_host is not None} - waiting)
    if hosts and waited_s > HOST_WAIT_NOTICE_S:
        waiting.update(hosts)
        names = ("hosts " if len(hosts) > 1 else "host ") + ", ".join(repr(h) for h in hosts)
        print(
            f"waiting for {names} to join (run `scenario run FILE --host NAME` there)",
            file=sys.stderr,
            flush=True,
        )
    here = [p.label for p in late if p.remote_host is None]
    if here and waited_s > START_TIMEOUT_S:
        raise RunError(f"not every part started within {START_TIMEOUT_S:.0f} s: {', '.join(here)}")
    far = [f"{p.label} on host {p.remote_host!r}" for p in late if p.remote_host is not None]
    if far and waited_s > HOST_JOIN_TIMEOUT_S:
        raise RunError(
            f"not every host joined within {HOST_JOIN_TIMEOUT_S:.0f} s: {', '.join(far)}\n"
            "  hint:     start `scenario run FILE --host NAME` on each of them; the main host's endpoint in "
            "`hosts:` must be reachable from there"
        )


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
            types.setdefault(ev.key, ev.type)
    return types, subs - pubs


@dataclass
class RunResult:
    reason: str  # completed | interrupted | failed
    sim_ns: int
    wall_s: float
    mcap: Path | None
    topics: list[TopicStats] = field(default_factory=list)
    published: dict[str, int] = field(default_factory=dict)
    error: str | None = None
    endpoints: list[str] = field(default_factory=list)
    rejected: dict[str, dict[str, int]] = field(default_factory=dict)  # inbound samples dropped: key, why

    @property
    def exit_code(self) -> int:
        return {"completed": 0, "stopped": 0, "interrupted": 130}.get(self.reason, 1)

    @property
    def lost(self) -> dict[str, int]:
        """Messages published but not recorded, per topic (only topics that were recorded)."""
        got = {t.key: t.count for t in self.topics}
        return {k: n - got[k] for k, n in self.published.items() if k in got and n > got[k]}


class _WorldPart:
    """One world of the run: its plan, its process (and renderer process), what it announced."""

    def __init__(self, plan: RunPlan, label: str, remote_host: str | None = None):
        self.plan = plan
        self.label = label  # "world" or "world <name>"
        self.remote_host = remote_host  # run by the runner of another host: watched by its liveliness
        self.gone = threading.Event()  # a remote world's liveliness token went away
        self.session: Any = None  # the runner's session, to acknowledge the world's end
        self.plan_file: str | None = None
        self.child: subprocess.Popen[bytes] | None = None
        self.tail: OutputTail | None = None
        self.renderer: subprocess.Popen[bytes] | None = None
        self.rtail: OutputTail | None = None
        self.ended = threading.Event()
        self.ready = threading.Event()
        self.end_info: dict[str, Any] = {}
        self.died = False

    def on_meta(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        if key.endswith("/world/end"):
            self.end_info.update(json.loads(sample.payload.to_bytes()))
            self.ended.set()
            if self.session is not None:  # all it published before has arrived: it may close
                self.session.put(meta_key(self.plan.name, "world", "end_ack"), b"")

    def start(self, endpoint: str) -> None:
        plan = self.plan
        with tempfile.NamedTemporaryFile("w", suffix=".plan.json", delete=False) as f:
            f.write(plan.model_dump_json())
            self.plan_file = f.name
        renders_apart = plan.renderers == "process" and plan.renders()
        if renders_apart:
            # cameras render in a process of their own, fed the world's state (runner/sim/render.py)
            rcmd = [sys.executable, "-m", "runner.sim.render", self.plan_file, "--connect", endpoint]
            self.renderer = subprocess.Popen(
                rcmd, stderr=subprocess.PIPE, start_new_session=True, env=_world_env(plan)
            )
            self.rtail = OutputTail(self.renderer.stderr, f"[{self.label.replace('world', 'render')}] ")
            self.rtail.start()
        world_env = dict(os.environ) if renders_apart else _world_env(plan)
        cmd = [sys.executable, "-m", "runner.sim", self.plan_file, "--connect", endpoint]
        # A session of its own: a terminal's Ctrl-C reaches only us, and we stop the world in order.
        self.child = subprocess.Popen(cmd, stderr=subprocess.PIPE, start_new_session=True, env=world_env)
        self.tail = OutputTail(self.child.stderr, f"[{self.label}] ")
        self.tail.start()

    def on_alive(self, sample: zenoh.Sample) -> None:
        """The world's liveliness token: up once it is set up and listening (state, so a late subscriber
        still sees it, unlike a message), gone when its process is."""
        if sample.kind == zenoh.SampleKind.PUT:
            self.ready.set()
        else:
            self.gone.set()

    def running(self) -> bool:
        if self.remote_host is not None:
            return not self.ended.is_set() and not self.gone.is_set()
        return self.child is not None and self.child.poll() is None

    def dead(self) -> bool:
        """Gone without saying it ended."""
        if self.remote_host is not None:
            return self.gone.is_set() and not self.ended.is_set()
        return self.child is not None and self.child.poll() not in (None, 0, 130)

    def stop(self) -> None:
        if self.remote_host is None and self.running():
            # a world still starting (importing, compiling) has nothing to finish: SIGTERM ends it quietly,
            # where SIGINT would print a KeyboardInterrupt from wherever Python was in its start-up
            started = self.ready.is_set()
            _stop(self.child, signal.SIGINT if started else signal.SIGTERM)  # type: ignore[arg-type]

    def renderer_error(self) -> str | None:
        r = self.renderer
        if r is None or r.poll() in (None, 0, 130):
            return None
        last = "\n".join(f"  | {ln}" for ln in list(self.rtail.lines)[-12:]) if self.rtail else ""
        return f"the renderer process exited with code {r.returncode}" + (f":\n{last}" if last else "")

    def finish(self, interrupted: bool) -> str | None:
        """After the world process exited: its error if it died, and the renderer stopped."""
        if self.remote_host is not None:
            self.died = self.dead() and not interrupted
            if self.died:
                return f"the {self.label} process on host {self.remote_host!r} went away (liveliness lost)"
            return None
        assert self.child is not None and self.tail is not None
        self.tail.join(timeout=1.0)
        error = None
        self.died = self.child.returncode not in (0, 130) and not interrupted
        if self.died:
            last = "\n".join(f"  | {ln}" for ln in list(self.tail.lines)[-12:])
            error = f"the {self.label} process exited with code {self.child.returncode}" + (
                f":\n{last}" if last else ""
            )
        if self.renderer is not None:
            try:
                # the world told it to stop; a world that died could not
                self.renderer.wait(timeout=0.0 if self.died else STOP_GRACE_S)
            except subprocess.TimeoutExpired:
                _stop(self.renderer)
            if self.rtail:
                self.rtail.join(timeout=1.0)
        if error is None and self.end_info.get("reason") == "failed":
            error = f"{self.label}: {self.end_info.get('error')}"  # stopped on its own, in order
        return error

    def cleanup(self) -> None:
        for proc in (self.child, self.renderer):  # (none for a remote part)
            if proc is not None and proc.poll() is None:
                proc.kill()
        if self.plan_file:
            os.unlink(self.plan_file)


def run_plan(
    plan: RunPlan,
    *,
    listen: Sequence[str] = (),
    connect: Sequence[str] = (),
    on_progress: Callable[[int, float], None] | None = None,
    judge: Any = None,
    host: str | None = None,
    foxglove_port: int | None = None,
) -> RunResult:
    """Run a plan (one world, or `plan.worlds`, each a process of its own behind one router and one
    recorder); with a `judge` (runner.checks.judge.Judge), feed it every message it asks for, live, and
    stop the worlds early when the plan's `stop_on` says so.

    With `plan.hosts`, this runner plays `host` (None: the first, main host, which records and judges);
    the parts placed on other hosts are run by their own `scenario run FILE --host NAME`, and joined."""
    interruptible()  # from here on, processes start: Ctrl-C stops them in order and keeps the recording
    if plan.hosts and host not in (None, plan.main_host):
        return _run_member(plan, host, connect=connect, listen=listen)  # type: ignore[arg-type]
    if plan.hosts and not listen:
        listen = [plan.hosts[plan.main_host]]  # type: ignore[index]
    listen = list(listen) or [f"tcp/127.0.0.1:{free_port()}"]
    if plan.renderers == "auto":
        # A renderer process pays where rendering does not already take every core: Mesa's llvmpipe renders
        # on all cores of a 2-core machine, and the two placements measure the same there (bench cameras).
        renderers = "process" if (os.cpu_count() or 1) > 2 else "world"
        plan = plan.model_copy(update={"renderers": renderers})
        if plan.worlds:
            plan.worlds = [w.model_copy(update={"renderers": renderers}) for w in plan.worlds]
    conf = make_config("router", listen=listen, connect=connect)
    try:
        session = zenoh.open(conf)
    except zenoh.ZError as e:
        raise RunError(f"cannot open the Zenoh network on {', '.join(listen)}: {zenoh_reason(e)}") from None

    live = None
    if foxglove_port is not None:  # `--foxglove PORT`: the run, live, to Foxglove
        from runner.launch.live import LiveView

        try:
            live = LiveView(session, plan.name, foxglove_port)
        except RunError:
            session.close()
            raise
        print(f"Foxglove: connect to ws://127.0.0.1:{live.port}", file=sys.stderr, flush=True)
    # `scenario echo/pub/topics` find the local run by it
    announced = announce(
        plan.name, listen, plan.zenoh, recording=plan.record.path if plan.record.enabled else None
    )
    parts = [
        _WorldPart(
            w,
            f"world {w.name.rsplit('/', 1)[-1]}" if plan.worlds else "world",
            None if plan.on_host(None, w.host) else w.host,
        )
        for w in plan.parts()
    ]
    recorder: Recorder | None = None
    latest = {"ns": 0}
    started = {"at": 0.0}
    subs: list[Any] = []
    nodes: Nodes | None = None
    reason = "completed"
    error: str | None = None
    wall0 = time.perf_counter()

    def reached() -> int:
        """The sim time the run reached: the least its worlds say they reached (one that said nothing,
        having died: the latest time recorded or seen)."""
        fallback = recorder.latest_ns if recorder else latest["ns"]
        return min(int(p.end_info.get("sim_ns", fallback)) for p in parts)

    try:
        if plan.record.enabled:
            try:
                types, inbound = _keys(plan)
                recorder = Recorder(
                    Path(plan.record.path),
                    plan.record.include,
                    plan.record.exclude,
                    types=types,
                    inbound=inbound,
                    guarded=True,
                )
            except OSError as e:
                raise RunError(f"cannot write the recording {plan.record.path}: {e.strerror or e}") from None
            if recorder.path != recorder.asked:
                print(
                    f"another run is recording to {recorder.asked}: this one records to {recorder.path}",
                    file=sys.stderr,
                    flush=True,
                )
                plan.record.path = str(recorder.path)
                update_announcement(announced, recording=str(recorder.path))
            # the recorder's own FIFO subscriber, drained by its thread; undeclared (after recording what
            # it still queued) by recorder.close()
            recorder.subscribe(session, f"{plan.name}/**")
            # the scenario as compiled, so the recording can be judged and reported on by itself
            text = msgs.T["std_msgs/msg/String"](data=plan.model_dump_json())
            recorder.write(
                f"{plan.name}/_plan", "std_msgs/msg/String", msgs.encode(text, "std_msgs/msg/String"), (0, 0)
            )
        else:

            def on_clock(sample: zenoh.Sample) -> None:
                att = sample.attachment
                parsed = unpack_attachment(att.to_bytes()) if att is not None else None
                if parsed:
                    latest["ns"] = max(latest["ns"], parsed[1])

            for part in parts:
                subs.append(session.declare_subscriber(part.plan.clock_key, on_clock))
        for part in parts:
            part.session = session
            subs.append(session.declare_subscriber(meta_key(part.plan.name, "**"), part.on_meta))
            alive = meta_key(part.plan.name, "world", "alive")
            subs.append(session.liveliness().declare_subscriber(alive, part.on_alive, history=True))
        if recorder is not None:
            graph = GraphTokens(session, plan.name, "recorder", "recorder")
            graph.subscriber(f"{plan.name}/**")
            subs.append(graph)
        bridge_ready = threading.Event()
        if plan.bridges:
            # the bridge process (a node) subscribes before the worlds start, so it misses nothing

            def on_bridge(sample: zenoh.Sample) -> None:
                if sample.kind == zenoh.SampleKind.PUT:
                    bridge_ready.set()

            bridge_key = meta_key(plan.name, "bridge", "alive")
            subs.append(session.liveliness().declare_subscriber(bridge_key, on_bridge, history=True))
        else:
            bridge_ready.set()
        stop_early = threading.Event()
        if judge is not None:
            subs += _judge_subscribers(session, plan, judge, stop_early, recorder)

        endpoint = _connectable(listen[0])
        # required nodes of other hosts: their runner supervises them; here, their liveliness is watched
        lost_nodes: list[str] = []
        for n in plan.nodes:
            if n.required and not plan.on_host(None, n.host):
                world = next((w for w in plan.worlds if n.world and w.name.endswith("/" + n.world)), plan)

                def on_node(sample: zenoh.Sample, n: NodePlan = n) -> None:
                    if sample.kind != zenoh.SampleKind.PUT:
                        lost_nodes.append(f"required node {n.name!r} on host {n.host!r} went away")

                alive_key = meta_key(world.name, "node", n.name)
                subs.append(session.liveliness().declare_subscriber(alive_key, on_node))
        if any(plan.on_host(None, n.host) for n in plan.nodes):
            # nodes first: they connect and subscribe while the world starts (lockstep nodes are waited for
            # by the world itself, before its first step)
            nodes = Nodes(plan, endpoint, host=None)
            try:
                nodes.start()
            except NodeError as e:
                raise RunError(str(e)) from None
        for part in parts:
            if part.remote_host is None:  # the others are started by their own host's runner
                part.start(endpoint)
        wall0 = time.perf_counter()
        interrupted = False
        waiting: set[str] = set()  # the other hosts this run said it waits for

        go: dict[str, Any] = {}

        def stop_all() -> None:
            token = go.pop("token", None)
            if token is not None:  # the word withdrawn: the worlds of other hosts stop too
                with contextlib.suppress(Exception):
                    token.undeclare()
            for p in parts:
                p.stop()

        try:
            while any(p.running() for p in parts):
                time.sleep(0.05)
                if recorder is not None:
                    recorder.flush_stale(1.0)  # killed outright, the file loses at most a second
                    if recorder.error is not None and error is None:
                        # the disk is full (or the file cannot be written): nothing more can be kept
                        why = recorder.error.strerror or str(recorder.error)
                        reason, error = "failed", f"the recording stopped: {why} ({recorder.path})"
                        print(error + "; stopping the run", file=sys.stderr, flush=True)
                        stop_all()
                all_ready = all(p.ready.is_set() for p in parts) and bridge_ready.is_set()
                if all_ready and not started["at"]:
                    started["at"] = time.perf_counter()
                    # every part is up (here and on other hosts): they start together, on this word
                    go["token"] = session.liveliness().declare_token(meta_key(plan.name, "go"))
                    subs.append(go["token"])
                # once the worlds have ended, nodes leave on their own (runner.node sees the end): no failure
                nodes_may_fail = nodes is not None and error is None and reason == "completed"
                if nodes_may_fail and not any(p.ended.is_set() for p in parts):
                    ended_by = nodes.check()  # type: ignore[union-attr]
                    if ended_by is not None:
                        reason, message = ended_by
                        if reason == "failed":
                            error = message
                        # said at once (the full report follows once everything has stopped)
                        print(message.splitlines()[0] + "; stopping the run", file=sys.stderr, flush=True)
                        stop_all()
                all_completed = all(p.end_info.get("reason") == "completed" for p in parts)
                if lost_nodes and error is None and reason == "completed" and not all_completed:
                    reason, error = "failed", lost_nodes[0]
                    print(error + "; stopping the run", file=sys.stderr, flush=True)
                    stop_all()
                for p in parts:
                    stopped_there = p.remote_host is not None and p.end_info.get("reason") == "stopped"
                    if stopped_there and error is None and reason == "completed":
                        # another host stopped its part (its node failed, it was interrupted): all stop
                        time.sleep(0.2)  # the cause (a lost node's liveliness) may be just behind
                        cause = (
                            lost_nodes[0]
                            if lost_nodes
                            else f"the {p.label} on host {p.remote_host!r} stopped"
                        )
                        reason, error = "failed", cause
                        print(cause + "; stopping the run", file=sys.stderr, flush=True)
                        stop_all()
                    died = p.dead()
                    if died and error is None and reason == "completed" and len(parts) > 1:
                        # one world died: said at once, the others stop too (the full report follows)
                        print(f"the {p.label} process died; stopping the run", file=sys.stderr, flush=True)
                        stop_all()
                    rerr = p.renderer_error()
                    if rerr is not None and error is None:
                        error, reason = rerr, "failed"
                        stop_all()
                if on_progress is not None and all_ready:
                    sim_ns = recorder.latest_ns if recorder else latest["ns"]
                    on_progress(sim_ns, time.perf_counter() - started["at"])
                if not all_ready:
                    _check_start(parts, time.perf_counter() - wall0, waiting)
                if stop_early.is_set() and reason == "completed":
                    reason = "stopped"
                    stop_all()
        except KeyboardInterrupt:
            reason = "interrupted"
            interrupted = True
            stop_all()
        for part in parts:
            perr = part.finish(interrupted or reason == "interrupted")
            if perr is not None and (error is None or reason == "completed"):
                reason, error = "failed", perr
                # said at once (the full report follows once everything has stopped)
                print(perr.splitlines()[0] + "; stopping the run", file=sys.stderr, flush=True)
            elif perr is not None and reason == "failed" and not error:
                error = perr
        if recorder is not None and not any(p.died for p in parts):
            try:
                for part in parts:
                    _drain(recorder, part.ended, part.end_info)
            except KeyboardInterrupt:
                reason = "interrupted"
    except KeyboardInterrupt:
        reason = "interrupted"
        for part in parts:
            part.stop()
    finally:
        if nodes is not None:
            nodes.stop()
        for part in parts:
            part.cleanup()
        for s in subs:
            with contextlib.suppress(Exception):
                s.undeclare()
        if recorder is not None:
            # how the run ended, for judging the recording by itself later (`scenario check`)
            how = ending(reason)
            if sys.exc_info()[0] is not None or (error is not None and how == "completed"):
                how = "failed"  # (a start-up that timed out...: leaving through an exception)
            recorder.end_note(ended=how, sim_ns=str(reached()))
            recorder.close()
        if live is not None:
            live.close()
        session.close()
        withdraw(announced)

    infos = [p.end_info for p in parts]
    sim_ns = reached()
    walls = [float(i["wall_s"]) for i in infos if "wall_s" in i]
    published: dict[str, int] = {}
    rejected: dict[str, dict[str, int]] = {}
    for i in infos:
        published.update(i.get("published", {}))
        for key, whys in i.get("rejected", {}).items():
            for why, n in whys.items():
                rejected.setdefault(key, {})[why] = rejected.get(key, {}).get(why, 0) + n
    if recorder is not None:
        for key, whys in recorder.mistyped.items():
            for why, n in whys.items():
                rejected.setdefault(key, {}).setdefault(f"not recorded: {why}", n)
    return RunResult(
        reason=reason,
        sim_ns=sim_ns,
        wall_s=max(walls) if len(walls) == len(infos) else time.perf_counter() - wall0,
        mcap=Path(plan.record.path) if recorder else None,
        topics=recorder.stats() if recorder else [],
        published=published,
        error=error,
        endpoints=listen,
        rejected=rejected,
    )


def _run_member(
    plan: RunPlan, host: str, *, connect: Sequence[str] = (), listen: Sequence[str] = ()
) -> RunResult:
    """`scenario run FILE --host NAME`: run the worlds and nodes placed on this host, joined to the main
    host's runner (which records and judges, and says when everything starts); end with them."""
    if host not in plan.hosts:
        raise RunError(f"no host named {host!r} in the scenario; hosts: {', '.join(plan.hosts)}")
    listen = list(listen) or [plan.hosts[host]]
    connect = list(connect) or [plan.hosts[plan.main_host]]  # type: ignore[index]
    try:
        session = zenoh.open(make_config("router", listen=listen, connect=connect))
    except zenoh.ZError as e:
        raise RunError(f"cannot open the Zenoh network on {', '.join(listen)}: {zenoh_reason(e)}") from None
    parts = [
        _WorldPart(w, f"world {w.name.rsplit('/', 1)[-1]}" if plan.worlds else "world")
        for w in plan.parts()
        if plan.on_host(host, w.host)
    ]
    subs = [session.declare_subscriber(meta_key(p.plan.name, "**"), p.on_meta) for p in parts]
    nodes = (
        Nodes(plan, _connectable(listen[0]), host=host) if any(n.host == host for n in plan.nodes) else None
    )
    reason, error = "completed", None
    wall0 = time.perf_counter()
    try:
        if nodes is not None:
            try:
                nodes.start()
            except NodeError as e:
                raise RunError(str(e)) from None
        for part in parts:
            part.start(_connectable(listen[0]))
        try:
            while any(p.running() for p in parts) or (
                not parts and nodes is not None and nodes.any_running()
            ):
                time.sleep(0.05)
                if nodes is not None and error is None and not any(p.ended.is_set() for p in parts):
                    ended_by = nodes.check()
                    if ended_by is not None:
                        reason, error = ended_by
                        print(
                            error.splitlines()[0] + "; stopping this host's part", file=sys.stderr, flush=True
                        )
                        for p in parts:
                            p.stop()
        except KeyboardInterrupt:
            reason = "interrupted"
            for p in parts:
                p.stop()
        if nodes is not None and error is None and reason != "interrupted":
            # a required node that died while the world was being stopped (by the main host) still fails
            ended_by = nodes.check()
            if ended_by is not None and ended_by[0] == "failed":
                reason, error = ended_by
                print(error.splitlines()[0], file=sys.stderr, flush=True)
        for part in parts:
            perr = part.finish(reason == "interrupted")
            if perr is not None and error is None:
                reason, error = "failed", perr
    finally:
        if nodes is not None:
            nodes.stop()
        for part in parts:
            part.cleanup()
        for sub in subs:
            with contextlib.suppress(Exception):
                sub.undeclare()
        session.close()
    infos = [p.end_info for p in parts]
    return RunResult(
        reason=reason if error is None or reason != "completed" else "failed",
        sim_ns=min((int(i.get("sim_ns", 0)) for i in infos), default=0),
        wall_s=max((float(i.get("wall_s", 0.0)) for i in infos), default=time.perf_counter() - wall0),
        mcap=None,
        published={k: v for i in infos for k, v in i.get("published", {}).items()},
        error=error,
        endpoints=listen,
    )


def _judge_subscribers(
    session: Any, plan: RunPlan, judge: Any, stop_early: threading.Event, recorder: Recorder | None = None
) -> list[Any]:
    """Decode what the judge reads and feed it; with `stop_on`, say when the run can end. Keys the recorder
    records come from it, in its order and thread (no subscription of their own); others are subscribed."""
    from runner.checks.judge import judged_types
    from runner.wire import msgs

    types = judged_types(plan)
    lock = threading.Lock()

    def feed(key: str, stamp_ns: int, payload: bytes) -> None:
        msg = msgs.decode(payload, types[key])
        with lock:
            judge.feed(key, stamp_ns, msg)
            if (plan.stop_on == "first_failure" and judge.failed()) or (
                plan.stop_on == "all_decided" and judge.all_decided()
            ):
                stop_early.set()

    keys = sorted(judge.keys)
    if recorder is not None:
        tapped = [k for k in keys if recorder.wanted(k)]
        recorder.tap(tapped, feed)
        keys = [k for k in keys if k not in tapped]
    subs = []
    for key in keys:

        def on_sample(sample: zenoh.Sample) -> None:
            att = sample.attachment
            parsed = unpack_attachment(att.to_bytes()) if att is not None else None
            if parsed is not None:
                feed(str(sample.key_expr), parsed[1], sample.payload.to_bytes())

        subs.append(session.declare_subscriber(key, on_sample))
    return subs


def _world_env(plan: RunPlan) -> dict[str, str]:
    """The world process's environment; with a camera, an OpenGL backend that a test render proved
    (EGL, else OSMesa), unless the user chose one with MUJOCO_GL."""
    from runner import gl
    from runner.plugin.registry import load

    env = dict(os.environ)
    if not any(load(p.type).renders for r in plan.robots for p in r.plugins):
        return env
    if gl.gl_backend_chosen_by_user():
        return env
    try:
        backend = gl.choose_gl_backend()
    except RuntimeError as e:
        raise RunError(str(e)) from None
    env.update(
        {gl.GL_ENV: backend, "PYOPENGL_PLATFORM": backend, gl.GL_AUTO_ENV: "1", gl.GL_PROBED_ENV: backend}
    )
    return env


def _connectable(endpoint: str) -> str:
    """A listen endpoint on all interfaces is reached through loopback from this host."""
    return endpoint.replace("0.0.0.0", "127.0.0.1").replace("[::]", "[::1]")


def _stop(child: subprocess.Popen[bytes], sig: int = signal.SIGINT) -> None:
    try:
        child.send_signal(sig)
        child.wait(timeout=STOP_GRACE_S)
    except subprocess.TimeoutExpired:
        child.kill()
        child.wait()
    except ProcessLookupError:
        pass


def _drain(recorder: Recorder, ended: threading.Event, end_info: dict[str, Any]) -> None:
    """Wait until the recorder holds every message the world says it published (or a timeout)."""
    if not ended.wait(timeout=0.5):
        return
    published: dict[str, int] = end_info.get("published", {})
    deadline = time.monotonic() + DRAIN_TIMEOUT_S
    while time.monotonic() < deadline:
        got = recorder.counts()
        if all(got.get(k, 0) >= n for k, n in published.items() if recorder.wanted(k)):
            return
        time.sleep(0.01)
