"""The world parts of a run: each world (and its renderer) is an OS process of its own, started here and
watched by its process and its liveliness token; a world placed on another host is watched by its token
alone (its own host's runner starts it).

A world says it is up with a liveliness token (`<run>/@meta/world/alive`) and how it ended with a message
(`<run>/@meta/world/end`: reason, sim time, what it published), which the runner acknowledges so that the
world may close knowing everything it sent has arrived.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
from collections.abc import Sequence
from typing import Any

import zenoh

from runner.errors import RunError
from runner.launch import keeper
from runner.launch.nodes import OutputTail
from runner.plan import RunPlan
from runner.wire.transport import meta_key

STOP_GRACE_S = 1.2  # after SIGINT, how long the world gets before SIGKILL
# How long the parts of this host may take to start (compile, load MuJoCo, connect) before the run gives up:
# a guard against a hang, with room for a machine loaded by other runs.
START_TIMEOUT_S = 60.0
# How long the main host waits for the other hosts' runners (`scenario run FILE --host NAME`, started by
# hand or by another tool) to join. The worlds wait longer for the word to start (runner.sim).
HOST_JOIN_TIMEOUT_S = 180.0
HOST_WAIT_NOTICE_S = 5.0  # when the run says which hosts it waits for


class WorldPart:
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

    def watch(self, session: zenoh.Session) -> list[Any]:
        """Subscribe to what the world says (its end) and to its liveliness; the subscribers, to undeclare."""
        self.session = session
        alive = meta_key(self.plan.name, "world", "alive")
        return [
            session.declare_subscriber(meta_key(self.plan.name, "**"), self.on_meta),
            session.liveliness().declare_subscriber(alive, self.on_alive, history=True),
        ]

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
                rcmd,
                stderr=subprocess.PIPE,
                start_new_session=True,
                env=world_env(plan),
                preexec_fn=keeper.dies_with_runner(signal.SIGKILL),
            )
            keeper.watch(self.renderer.pid)
            self.rtail = OutputTail(self.renderer.stderr, f"[{self.label.replace('world', 'render')}] ")
            self.rtail.start()
        env = dict(os.environ) if renders_apart else world_env(plan)
        cmd = [sys.executable, "-m", "runner.sim", self.plan_file, "--connect", endpoint]
        # A session of its own: a terminal's Ctrl-C reaches only us, and we stop the world in order. Killed
        # outright, we take it along (runner.launch.keeper): what it would publish could not be recorded.
        self.child = subprocess.Popen(
            cmd,
            stderr=subprocess.PIPE,
            start_new_session=True,
            env=env,
            preexec_fn=keeper.dies_with_runner(signal.SIGKILL),
        )
        keeper.watch(self.child.pid)
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
            stop_process(self.child, signal.SIGINT if started else signal.SIGTERM)  # type: ignore[arg-type]

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
        if self.child is None:  # never started (the run was stopped while starting)
            return None
        assert self.tail is not None
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
                stop_process(self.renderer)
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
            self.plan_file = None


def world_parts(plan: RunPlan, host: str | None) -> list[WorldPart]:
    """The worlds of the run as `host` (None: the main host) sees them: the main host watches every world
    (those of other hosts by their tokens), another host only its own."""
    parts = []
    for w in plan.parts():
        label = f"world {w.name.rsplit('/', 1)[-1]}" if plan.worlds else "world"
        here = plan.on_host(host, w.host)
        if host is None:
            parts.append(WorldPart(w, label, None if here else w.host))
        elif here:
            parts.append(WorldPart(w, label))
    return parts


def _check_start(parts: Sequence[WorldPart], waited_s: float, waiting: set[str]) -> None:
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


def world_env(plan: RunPlan) -> dict[str, str]:
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


def connectable(endpoint: str) -> str:
    """A listen endpoint on all interfaces is reached through loopback from this host."""
    return endpoint.replace("0.0.0.0", "127.0.0.1").replace("[::]", "[::1]")


def stop_process(child: subprocess.Popen[bytes], sig: int = signal.SIGINT) -> None:
    try:
        child.send_signal(sig)
        child.wait(timeout=STOP_GRACE_S)
    except subprocess.TimeoutExpired:
        child.kill()
        child.wait()
    except ProcessLookupError:
        pass
