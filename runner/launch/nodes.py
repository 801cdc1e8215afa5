"""The run's node processes (`nodes:`): started before the world, watched while it runs, stopped in order.

Each node gets the run in its environment (`SCENARIO_ENDPOINT`, `SCENARIO_RUN`, `SCENARIO_NAMESPACE`,
`SCENARIO_NODE`, `SCENARIO_CLOCK`), its output is shown prefixed with its name, and its exit is noticed
within one poll of the runner (50 ms): a `required` node ends the run (exit 1 unless it ended with 0),
`respawn: on-failure` starts a failed node again up to `respawn_limit` times.
"""

from __future__ import annotations

import collections
import contextlib
import os
import signal
import subprocess
import sys
import threading
import time
from typing import Any

from runner.launch import keeper
from runner.plan import NodePlan, RunPlan

STOP_GRACE_S = 3.0
# A line of a child's output is shown up to this many bytes; the rest of it is counted, not kept: a node
# that wrote 800 MB without a newline (binary data on stdout) took the runner to 2.6 GB.
LINE_MAX = 64 * 1024


class OutputTail(threading.Thread):
    """Forwards a child process's output (a node's, a world's stderr) line by line, prefixed with its
    name, and keeps the last lines for the error report."""

    def __init__(self, stream: Any, prefix: str):
        super().__init__(daemon=True)
        self.stream = stream
        self.prefix = prefix
        self.lines: collections.deque[str] = collections.deque(maxlen=30)
        # set once the runner stops the process with SIGINT: a Python traceback that ends in
        # `KeyboardInterrupt` is then the stop being obeyed (a script interrupted before it set up its own
        # handling), not news, and is left out
        self.stopping = False
        self._held: list[str] = []

    def run(self) -> None:
        left_out: int | None = None  # bytes of an over-long line not shown so far (None: not in one)
        for raw in iter(lambda: self.stream.readline(LINE_MAX), b""):
            ended = raw.endswith(b"\n")
            if left_out is not None:
                left_out += len(raw)
                if ended:
                    self._line(f"(the line above went on for {left_out} more bytes, not shown)")
                    left_out = None
                continue
            if not ended and len(raw) >= LINE_MAX:
                left_out = 0
            self._line(raw.decode(errors="replace").rstrip())
        if left_out is not None:
            self._line(f"(the line above went on for {left_out} more bytes, not shown)")
        self._flush()

    def _line(self, line: str) -> None:
        if self._held or (self.stopping and line.startswith("Traceback (most recent call last):")):
            if line == "KeyboardInterrupt":
                self._held.clear()
                return
            self._held.append(line)
            if line.startswith((" ", "Traceback")):
                return
            self._flush()  # the traceback ended otherwise: shown whole
            return
        self._show(line)

    def _flush(self) -> None:
        held, self._held = self._held, []
        for line in held:
            self._show(line)

    def _show(self, line: str) -> None:
        self.lines.append(line)
        print(f"{self.prefix}{line}", file=sys.stderr, flush=True)


class NodeProcess:
    def __init__(self, plan: NodePlan, env: dict[str, str]):
        self.plan = plan
        self.env = env
        self.restarts = 0
        self.finished: int | None = None  # exit code once it is over for good
        self.proc: subprocess.Popen[bytes] | None = None
        self.output: OutputTail | None = None

    def start(self) -> None:
        try:
            self.proc = subprocess.Popen(
                self.plan.argv,
                cwd=self.plan.cwd,
                env=self.env,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                start_new_session=True,  # Ctrl-C reaches the runner only; it stops the nodes in order
                # ...and a runner killed outright takes them along (runner.launch.keeper)
                preexec_fn=keeper.dies_with_runner(signal.SIGTERM),
            )
        except OSError as e:
            what = f"node {self.plan.name!r} cannot start {self.plan.argv[0]!r}"
            raise NodeError(f"{what}: {e.strerror}") from None
        keeper.watch(self.proc.pid)
        self.output = OutputTail(self.proc.stdout, f"[{self.plan.name}] ")
        self.output.start()

    def last_lines(self, n: int = 12) -> str:
        lines = list(self.output.lines)[-n:] if self.output else []
        return "\n".join(f"  | {ln}" for ln in lines)


class NodeError(RuntimeError):
    pass


class Nodes:
    """The nodes of one host of the run (`host`: None is the main host)."""

    def __init__(self, plan: RunPlan, endpoint: str, host: str | None = None):
        self.procs: list[NodeProcess] = []
        for node in plan.nodes:
            if not plan.on_host(host, node.host):
                continue
            env = dict(os.environ)
            # with several worlds, a node works in its world's key space (`<run>/<world>/...`)
            world = next((w for w in plan.worlds if node.world and w.name.endswith("/" + node.world)), plan)
            env.update(
                {
                    "SCENARIO_ENDPOINT": endpoint,
                    "SCENARIO_RUN": world.name,
                    "SCENARIO_NAMESPACE": node.namespace or "",
                    "SCENARIO_NODE": node.name,
                    "SCENARIO_CLOCK": world.clock_key,
                    "PYTHONUNBUFFERED": "1",
                    # runner.node keeps the world's message order for a node the world waits for
                    "SCENARIO_LOCKSTEP": "1" if node.name in world.lockstep else "0",
                }
            )
            env.update(node.env)
            self.procs.append(NodeProcess(node, env))

    def start(self) -> None:
        for p in self.procs:
            p.start()

    def check(self) -> tuple[str, str] | None:
        """Exits since the last check: restarts what may be restarted; (reason, message) when a required
        node ended, which ends the run ("failed", or "stopped" if it ended with 0)."""
        for p in self.procs:
            if p.finished is not None or p.proc is None or p.proc.poll() is None:
                continue
            code = p.proc.returncode
            if p.output:
                p.output.join(timeout=0.5)
            name = p.plan.name
            if p.plan.required:
                p.finished = code
                if code == 0:
                    return "stopped", f"node {name!r} finished; it is required, so the run ends"
                last = p.last_lines()
                message = f"required node {name!r} exited with code {code}"
                return "failed", message + (f":\n{last}" if last else "")
            if code != 0 and p.plan.respawn == "on-failure" and p.restarts < p.plan.respawn_limit:
                p.restarts += 1
                print(
                    f"node {name!r} exited with code {code}; starting it again "
                    f"({p.restarts}/{p.plan.respawn_limit})",
                    file=sys.stderr,
                    flush=True,
                )
                p.start()
                continue
            p.finished = code
            if code != 0:
                print(f"node {name!r} exited with code {code}", file=sys.stderr, flush=True)
        return None

    def any_running(self) -> bool:
        return any(p.proc is not None and p.proc.poll() is None for p in self.procs)

    def stop(self) -> None:
        """SIGINT to every node still running, then SIGKILL to those still there after a grace period."""
        running = [p.proc for p in self.procs if p.proc is not None and p.proc.poll() is None]
        for p in self.procs:
            if p.output is not None:
                p.output.stopping = True
        for proc in running:
            with contextlib.suppress(ProcessLookupError):
                proc.send_signal(signal.SIGINT)
        deadline = time.monotonic() + STOP_GRACE_S
        for proc in running:
            try:
                proc.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        for p in self.procs:
            if p.output:
                p.output.join(timeout=1.0)
