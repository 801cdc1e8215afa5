"""The run's keeper: every process a runner starts ends when the runner ends, however it ends.

The runner starts its worlds, renderers, nodes and bridge each in a session of its own, so that a terminal's
Ctrl-C reaches the runner only and it stops them in order (runner.launch.supervisor). The price: nothing
reaches them when the runner is killed outright (kill -9, the OOM killer, a CI job's timeout killing the
runner's process group), and a `nodes:` command may itself start processes (a shell, a launch file). So,
with the kernel's means rather than hope:

- Each child the runner starts gets a parent-death signal (`dies_with_runner`, PR_SET_PDEATHSIG, set
  between fork and exec): SIGKILL for the runner's own processes (worlds, renderers: with the runner gone
  nothing of theirs can be recorded), SIGTERM for nodes and the bridge (a node may tidy up, as under a CI
  job's SIGTERM). The kernel sends it when the thread that forked the child ends: children are started by
  the supervisor's thread (the main thread of `scenario run`), which lives as long as the run.
- A keeper process (this file as a script) is started first, in a session of its own (a signal to the
  runner's process group does not reach it), and watches a pipe whose write end only the runner holds:
  end of file is the runner gone (or done). The runner puts a token of the run in the environment every
  process it starts inherits (`SCENARIO_KEEPER`), and tells the keeper each child's pid (its session: every
  child is a session leader). The keeper then ends, SIGTERM and after TERM_GRACE_S SIGKILL, every process
  that carries the token (`/proc/<pid>/environ`, the environment it was started with: a grandchild that
  double-forks or leaves its session with `setsid` still carries it) or lives in one of the run's sessions
  (a grandchild started with `env -i` stays in its session), until none is left.
- The recording's guard (runner.record.finisher) is the one process left to finish: it completes the MCAP
  of a runner killed outright, in milliseconds, and ends by itself. The keeper waits for it (at most
  FINISH_WAIT_S, then kills it) and then removes the recording's lock if nobody holds it any more (the guard
  killed too), with the recording if it holds nothing (a runner killed before its first write).

A run that ends normally closes the pipe last and waits for the keeper: a node's grandchild that its node
left behind is ended before `scenario run` returns. Not covered: a process that both drops its environment
(`env -i`) and leaves its session (`setsid`), and the runner and the keeper both killed (then the kernel
still ends the runner's children, but their own children are left).

Why a token and not a subreaper (PR_SET_CHILD_SUBREAPER): a subreaper adopts the orphans of its own
descendants only, so the keeper would have to be the parent of every child, taking their Popen objects
(output pipes, exit codes, signals) away from the runner; and the runner as the subreaper loses what it
adopted to PID 1 the moment it dies. The token reaches the same processes (an orphan keeps its
environment) with the runner still the parent of its children.

Kept to the standard library: the keeper runs this file as a script, isolated (`python -I -S`), so it
starts in milliseconds and nothing of the package is imported there.
"""

from __future__ import annotations

import contextlib
import functools
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

ENV = "SCENARIO_KEEPER"  # the tokens of the runs a process belongs to, space separated (runs may nest)
TERM_GRACE_S = 1.0  # after SIGTERM, how long the run's processes get before SIGKILL
KILL_S = 2.0  # how long SIGKILL is repeated (a process forking while it is swept) before giving up
FINISH_WAIT_S = 10.0  # how long the recording's guard may take to finish the file before it is killed
CLOSE_WAIT_S = 5.0  # how long a runner that ends normally waits for its keeper's sweep
PR_SET_PDEATHSIG = 1  # <linux/prctl.h>
EMPTY_BELOW = 8 + 9  # a recording shorter than the MCAP magic and one record's head holds nothing


# ------------------------------------------------------------------------------------ the runner's side
class Keeper:
    """The runner's side: starts the keeper and tells it what the run started. `close()` once the run has
    stopped everything it could: the keeper sweeps what is left and ends."""

    current: Keeper | None = None  # the keeper of the run in this process (`watch` and `wait_for` tell it)

    def __init__(self) -> None:
        self.token = os.urandom(8).hex()
        self._write: int | None = None
        self._env_before = os.environ.get(ENV)
        self.proc: subprocess.Popen[bytes] | None = None
        read, write = os.pipe()  # (not inherited: only this process holds the write end)
        try:
            self.proc = subprocess.Popen(
                [sys.executable, "-I", "-S", __file__, str(read), str(os.getpid()), self.token],
                stdin=subprocess.DEVNULL,
                pass_fds=(read,),
                start_new_session=True,  # a signal to the runner's process group does not reach it
            )
            self._write = write
        except OSError as e:  # no process to spare: the children still die with the runner (their signal)
            why = e.strerror or e
            print(f"runner: no keeper for the run's processes ({why})", file=sys.stderr, flush=True)
            os.close(write)
        finally:
            os.close(read)
        # every process started from now on carries the run's token, whatever environment it is given
        # (each is built from this one)
        os.environ[ENV] = f"{self._env_before} {self.token}" if self._env_before else self.token
        Keeper.current = self

    def _send(self, *item: str | int) -> None:
        if self._write is None:
            return
        try:
            os.write(self._write, json.dumps(item).encode() + b"\n")  # (short: written whole)
        except OSError:  # the keeper is gone: the children still die with the runner (their signal)
            with contextlib.suppress(OSError):
                os.close(self._write)
            self._write = None

    def close(self) -> None:
        """The run is over: the keeper ends whatever of it is left and ends; waited for (at most
        CLOSE_WAIT_S: it finishes on its own)."""
        if Keeper.current is self:
            Keeper.current = None
        if self._env_before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = self._env_before
        if self._write is not None:
            with contextlib.suppress(OSError):
                os.close(self._write)
            self._write = None
        if self.proc is not None:
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.proc.wait(timeout=CLOSE_WAIT_S)


def watch(pid: int) -> None:
    """A child the run started in a session of its own: the keeper ends the whole session."""
    if Keeper.current is not None:
        Keeper.current._send("session", pid)


def wait_for(pid: int, lock: Path | None = None) -> None:
    """A process the keeper leaves to end by itself (the recording's guard), and the lock file it may leave
    behind (removed once nobody holds it)."""
    if Keeper.current is not None:
        Keeper.current._send("wait", pid, str(lock) if lock is not None else "")


def dies_with_runner(sig: int) -> Callable[[], None] | None:
    """A `preexec_fn` that has the child sent `sig` when the runner's thread that starts it ends (kill -9
    included). prctl is looked up here, before the fork, so the child only calls it."""
    if not sys.platform.startswith("linux"):
        return None
    prctl = _libc().prctl
    parent = os.getpid()

    def in_child() -> None:
        prctl(PR_SET_PDEATHSIG, int(sig))
        if os.getppid() != parent:  # the runner died between the fork and here: no signal will come
            os.kill(os.getpid(), sig)

    return in_child


@functools.cache
def _libc() -> Any:
    import ctypes

    return ctypes.CDLL(None, use_errno=True)


# ------------------------------------------------------------------------------------------ the keeper
def _stat(pid: int) -> tuple[str, int] | None:
    """(state, session id) of a process, None if it is gone."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            stat = f.read()
    except OSError:
        return None
    fields = stat[stat.rindex(b")") + 2 :].split()  # (the command name may hold spaces and parentheses)
    return fields[0].decode(), int(fields[3])


def _carries(pid: int, token: bytes) -> bool:
    try:
        with open(f"/proc/{pid}/environ", "rb") as f:
            environ = f.read()
    except OSError:  # gone, or not ours to read
        return False
    prefix = ENV.encode() + b"="
    return any(e.startswith(prefix) and token in e[len(prefix) :].split() for e in environ.split(b"\0"))


def members(token: str, sessions: set[int], spare: set[int], own: set[int]) -> Iterator[int]:
    """The live processes of the run: those carrying its token, and those in its sessions (to which each
    session led by one carrying the token is added)."""
    tok = token.encode()
    for name in os.listdir("/proc"):
        if not name.isdigit() or int(name) in spare:
            continue
        pid = int(name)
        st = _stat(pid)
        if st is None or st[0] in ("Z", "X"):  # (a zombie is over: only its parent's wait is missing)
            continue
        if st[1] in sessions:
            yield pid
        elif _carries(pid, tok):
            if st[1] == pid and pid not in own:
                sessions.add(pid)
            yield pid


def sweep(token: str, sessions: set[int], spare: set[int], own: set[int]) -> int:
    """End every process of the run: SIGTERM, then SIGKILL to those still there after TERM_GRACE_S, until
    none is left (or KILL_S more have passed). How many there were."""
    ended: set[int] = set()
    start = time.monotonic()
    sig = signal.SIGTERM
    while True:
        found = list(members(token, sessions, spare, own))
        now = time.monotonic()
        if not found or now - start > TERM_GRACE_S + KILL_S:
            return len(ended)
        if sig == signal.SIGTERM and now - start > TERM_GRACE_S:
            sig = signal.SIGKILL
        for pid in found:
            if sig == signal.SIGKILL or pid not in ended:
                with contextlib.suppress(OSError):
                    os.kill(pid, sig)
                    if sig == signal.SIGTERM:
                        os.kill(pid, signal.SIGCONT)  # (a stopped process takes SIGTERM once continued)
            ended.add(pid)
        time.sleep(0.02)


def clear_stale_lock(lock: Path) -> bool:
    """Remove a recording's lock file nobody holds any more (its run and its guard gone), and the
    recording beside it if that holds nothing. The same as runner.record.claim does before a run records
    (this script imports nothing of the package): the file is removed while locked, and a run that opened
    it meanwhile finds, once it holds the lock, that the name is no longer its file, and opens it again."""
    import fcntl

    try:
        fd = os.open(lock, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        if os.stat(lock).st_ino != os.fstat(fd).st_ino:
            return False
        recording = lock.with_name(lock.name[1 : -len(".lock")])
        head = None  # (only the start of an MCAP file is removed: runner.record.claim.holds_nothing)
        with contextlib.suppress(OSError), open(recording, "rb") as f:
            head = f.read(EMPTY_BELOW)
        if head is not None and len(head) < EMPTY_BELOW and head[:8] == b"\x89MCAP0\r\n"[: len(head)]:
            with contextlib.suppress(OSError):
                recording.unlink()
        lock.unlink()
        return True
    except OSError:  # held: a live run's
        return False
    finally:
        os.close(fd)


def _alive(pid: int) -> bool:
    st = _stat(pid)
    return st is not None and st[0] not in ("Z", "X")


def main(argv: list[str]) -> int:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # it ends when the runner does, however it does
    fd, runner, token = int(argv[0]), int(argv[1]), argv[2]
    # never a session of the runner's own (its caller's: a terminal's, a CI job's) is swept
    own = {os.getsid(0)}
    with contextlib.suppress(OSError):
        own.add(os.getsid(runner))
    sessions: set[int] = set()
    waited: dict[int, str] = {}
    buf = b""
    while chunk := os.read(fd, 65536):  # until the runner is gone, or done
        buf += chunk
        *lines, buf = buf.split(b"\n")
        for line in lines:
            with contextlib.suppress(ValueError, TypeError, IndexError):
                item = json.loads(line)
                if item[0] == "session":
                    sessions.add(int(item[1]))
                elif item[0] == "wait":
                    waited[int(item[1])] = str(item[2])
    sessions -= own
    spare = {os.getpid(), runner, *waited}
    swept = sweep(token, sessions, spare, own)
    deadline = time.monotonic() + FINISH_WAIT_S
    while any(_alive(p) for p in waited) and time.monotonic() < deadline:
        time.sleep(0.02)
    for pid in waited:
        if _alive(pid):
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
    for lock in waited.values():
        if lock:
            clear_stale_lock(Path(lock))
    if swept and not _alive(runner):
        print(f"runner keeper: the runner is gone; ended {swept} process(es) of its run", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
