"""Nothing outlives the run: every process a run starts (its world, renderer, bridge, nodes and what a node
starts in turn, its keeper and its recording's guard) ends when the runner ends, however it ends: kill -9,
a CI timeout killing its process group, its guard killed too, or a normal end. Stale locks and recordings
that hold nothing are cleaned up by the keeper or by the next run (runner.launch.keeper,
runner.record.claim). Real runs through the CLI, real processes."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from mcap.reader import make_reader

from tests.conftest import REPO, processes_of, run_cli, scenario_cmd, wait_recorded

NODE = """
from runner.node import Node

with Node() as node:
    while node.ok():
        node.sleep(0.1)
"""

SCENE = """
name: outlive
duration: {duration}
rate: realtime
renderers: process
robots:
  - name: r1
    description: {{file: "{{diffbot}}"}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive, params: {{odometry_source: world}}}}
      - {{type: camera, params: {{link: lidar_link, width: 32, height: 24, rate: 5}}}}
bridges:
  - {{topic: r1/odom, key: outside/r1/odom, encoding: json, rate: 5}}
nodes:
  - name: driver
    cmd: [sh, -c, "{shell}"]
"""


def _scene(write_scenario, tmp_path: Path, duration: float) -> tuple[Path, str]:
    """The scenario and the mark its node's own children carry on their command line (`sleep <mark>N`):
    a child in the node's session, one in a session of its own (setsid), one with an empty environment
    (env -i) and one double-forked (its parent gone at once: re-parented away from the run)."""
    (tmp_path / "node.py").write_text(NODE)
    mark = str(7_000_000 + os.getpid() % 100_000 * 10 + int(duration) % 10)
    sleep = shutil.which("sleep")
    shell = (
        f"sleep {mark}1 & setsid sleep {mark}2 & env -i {sleep} {mark}3 & (sleep {mark}4 &) ; "
        f"exec {sys.executable} node.py"
    )
    return write_scenario(SCENE.format(duration=duration, shell=shell)), mark


def _marked(mark: str) -> list[int]:
    out = subprocess.run(["pgrep", "-f", f"sleep {mark}"], capture_output=True, text=True).stdout
    return [int(p) for p in out.split()]


def _start_time(pid: int) -> str | None:
    """A process's start time (to tell it from a later one given its pid), None once it is gone or a
    zombie (over: only its parent's wait is missing)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = stat[stat.rindex(")") + 2 :].split()
    return None if fields[0] in ("Z", "X") else fields[19]


def _alive(procs: dict[int, str]) -> dict[int, str]:
    """Those of `procs` (pid -> start time) still alive, with their command lines."""
    out = {}
    for pid, started in procs.items():
        if _start_time(pid) == started:
            try:
                out[pid] = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
            except OSError:
                continue
    return out


# what a run with a node, a camera and a bridge runs as processes of its own (and the node's own children)
EXPECTED = {
    "world": r"runner\.sim /",
    "renderer": r"runner\.sim\.render",
    "bridge": r"runner\.launch\.bridge",
    "node": r"python.* node\.py",
    "keeper": r"runner/launch/keeper\.py",
    "guard": r"runner/record/finisher\.py",
}


def _start(write_scenario, tmp_path: Path) -> tuple[subprocess.Popen[str], Path, str, dict[str, list[int]]]:
    """The run, started in a process group of its own (as a CI job's), returned once all its processes are
    up and its world is recorded running: it, its recording, its mark, its processes by kind."""
    path, mark = _scene(write_scenario, tmp_path, 600)
    mcap = tmp_path / "run.mcap"
    proc = subprocess.Popen(
        scenario_cmd("run", str(path), "--record", str(mcap), "--no-judge"),
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
        start_new_session=True,
    )
    found: dict[str, list[int]] = {}
    deadline = time.monotonic() + 90
    while time.monotonic() < deadline and proc.poll() is None:
        found = {kind: processes_of(proc.pid, pattern) for kind, pattern in EXPECTED.items()}
        found["node's children"] = _marked(mark)
        if all(found.values()) and len(found["node's children"]) == 4:
            break
        time.sleep(0.2)
    missing = [kind for kind, pids in found.items() if not pids]
    if missing or proc.poll() is not None:
        err = _end(proc)
        pytest.fail(f"not every process of the run started: {missing}; {err[-2000:]}")
    assert wait_recorded(mcap, "outlive/clock", 5, time.monotonic() + 60), "the world did not run"
    return proc, mcap, mark, found


def _end(proc: subprocess.Popen[str]) -> str:
    """The run killed if it is still there (its process group); what it printed on stderr."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    return proc.communicate(timeout=30)[1] or ""


@pytest.mark.timeout(180)
@pytest.mark.parametrize("how", ["kill -9", "process group", "guard too"])
def test_nothing_of_a_run_outlives_its_runner(write_scenario, tmp_path: Path, how: str) -> None:
    """kill -9 of the runner, SIGKILL to its process group (a CI job's timeout), or kill -9 of the runner
    and its recording's guard: within 3 s no process of the run is left, the node's own children included
    (in its session, in a session of their own, with an empty environment, double-forked). Each used to
    live on (re-parented to PID 1, in sessions of their own that a process group's kill does not reach)."""
    proc, mcap, mark, found = _start(write_scenario, tmp_path)
    try:
        # every process of the run, known before the kill (after it they are re-parented): pid -> start time
        pids = {p for ps in found.values() for p in ps} | set(processes_of(proc.pid, "."))
        procs = {p: t for p in pids if (t := _start_time(p)) is not None}
        if how == "guard too":
            os.kill(found["guard"][0], signal.SIGKILL)
        if how == "process group":
            os.killpg(proc.pid, signal.SIGKILL)
        else:
            os.kill(proc.pid, signal.SIGKILL)
        killed = time.monotonic()
        left = _alive(procs)
        while left and time.monotonic() - killed < 3.0:
            time.sleep(0.05)
            left = _alive(procs)
        took = time.monotonic() - killed
    finally:
        _end(proc)
        for pid in _marked(mark):  # (what the test's run left behind, in any case)
            os.kill(pid, signal.SIGKILL)
    assert not left, f"alive {took:.1f} s after the kill: " + "; ".join(left.values())
    assert not _marked(mark)
    lock = mcap.with_name(f".{mcap.name}.lock")
    assert not lock.exists(), "the recording's lock is left behind"
    with mcap.open("rb") as f:  # finished by the guard (or, the guard killed too, readable to its last chunk)
        assert sum(1 for _ in make_reader(f).iter_messages()) > 0


@pytest.mark.timeout(120)
def test_a_run_that_ends_leaves_no_process_of_its_nodes_behind(write_scenario, tmp_path: Path) -> None:
    """A node that started processes of its own and left them behind (they used to live on after the
    run): `scenario run` ends them before it returns."""
    path, mark = _scene(write_scenario, tmp_path, 4)
    r = run_cli("run", str(path), "--no-record", "--no-judge", timeout=100, cwd=tmp_path)
    left = _marked(mark)
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert r.returncode == 0, r.stderr[-2000:]
    assert not left, "the node's own processes outlived the run"


def test_a_recording_that_cannot_begin_leaves_neither_file_nor_lock(tmp_path: Path) -> None:
    """A disk full before the first byte (here the file-size limit, which fails a write the same way): the
    run is refused with the reason ("cannot write the recording"), and no empty recording and no lock
    are left (they were: a 0-byte MCAP and its `.lock`)."""
    code = f"""
import resource, signal, sys
from pathlib import Path
from runner.record import Recorder

signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))
try:
    Recorder(Path({str(tmp_path / "out" / "run.mcap")!r}), ["**"], guarded=True)
except OSError as e:
    print("refused:", e.strerror)
    sys.exit(0)
sys.exit("recorded")
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, cwd=REPO)
    assert r.returncode == 0 and "refused: File too large" in r.stdout, r.stdout + r.stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == []


def _leave_behind(path: Path, *, content: bytes) -> None:
    """What a run killed with its guard leaves: the recording (`content`) and its lock, held by nobody."""
    code = f"""
import os, signal
from pathlib import Path
from runner.record.claim import claim

path, fd = claim(Path({str(path)!r}))
path.write_bytes({content!r})
os.kill(os.getpid(), signal.SIGKILL)
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=60, cwd=REPO)
    assert r.returncode == -signal.SIGKILL, r.stderr
    assert path.with_name(f".{path.name}.lock").exists()


@pytest.mark.timeout(120)
def test_the_next_run_clears_stale_locks_and_empty_recordings(tmp_path: Path) -> None:
    """Locks whose runs are gone are removed by the next run recording in the folder, with a recording
    beside one that holds nothing; a recording that holds something is kept (`scenario recover` completes
    it), and a live run's lock is left alone."""
    out = tmp_path / "out"
    out.mkdir()
    _leave_behind(out / "empty.mcap", content=b"")
    _leave_behind(out / "cut.mcap", content=b"\x89MCAP0\r\n" + bytes(4000))
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys; from pathlib import Path; from runner.record.claim import claim; "
         f"claim(Path({str(out / 'live.mcap')!r})); print('held', flush=True); sys.stdin.read()"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd=REPO,
    )  # fmt: skip
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "held\n"
        r = run_cli(
            "run", str(REPO / "scenarios" / "two_robots.yaml"), "--duration", "0.5", "--no-judge",
            "--record", str(out / "new.mcap"), timeout=100,
        )  # fmt: skip
        assert r.returncode == 0, r.stderr[-2000:]
        left = sorted(p.name for p in out.iterdir())
    finally:
        holder.communicate(input="", timeout=30)
    assert left == [".live.mcap.lock", "cut.mcap", "new.mcap"], left


LONG = """
name: long
duration: 600
rate: realtime
robots:
  - name: r1
    description: {file: "{diffbot}"}
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive}
"""


@pytest.mark.timeout(150)
def test_a_suite_killed_outright_takes_its_runs_along(write_scenario, tmp_path: Path) -> None:
    """kill -9 of `scenario test`: its run (a `scenario run` of its own, and that run's world, keeper and
    guard) is stopped as Ctrl-C stops it, its recording finished; it used to run on to its end."""
    path = write_scenario(LONG, "long.yaml")
    out = tmp_path / "runs"
    proc = subprocess.Popen(
        scenario_cmd("test", str(path), "--out", str(out)),
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    procs: dict[int, str] = {}
    try:
        assert wait_recorded(out / "long.mcap", "long/clock", 5, time.monotonic() + 90), "the run did not run"
        runs = processes_of(proc.pid, r"runner\.cli run", direct=True)
        assert len(runs) == 1, "the suite runs its scenario"
        procs = {p: t for p in processes_of(proc.pid, ".") if (t := _start_time(p)) is not None}
        os.kill(proc.pid, signal.SIGKILL)
        killed = time.monotonic()
        left = _alive(procs)
        while left and time.monotonic() - killed < 10.0:
            time.sleep(0.05)
            left = _alive(procs)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
        for pid in _alive(procs):
            os.kill(pid, signal.SIGKILL)
    assert not left, "alive after the suite was killed: " + "; ".join(left.values())
    with (out / "long.mcap").open("rb") as f:  # stopped in order: its summary written by the run itself
        summary = make_reader(f).get_summary()
        assert summary is not None and summary.statistics.message_count > 0
