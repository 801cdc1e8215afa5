"""What running a suite on Ray costs (issue 23): 24 short variants (a matrix of one diff-drive robot with
a lidar and an IMU, 1 s sim at rate: max each) as `scenario test -j 2` and as `scenario test --ray` on the
same 2 cores: a Ray cluster of this machine (`ray start --head --num-cpus 2`, on loopback) started before,
and `--ray` alone, which starts its own local cluster and stops it (the laptop case: its start is paid by
the suite). Suite throughput in variants per minute, and Ray's overhead per variant: the extra slot-seconds
each variant costs (2 slots × the extra wall time / 24); for `--ray` alone also without its cluster's start
(as the command says it: `joined in N s`), which is paid once per suite, not per variant. The target: under
1 s.

The modes are run alternately, best of N each, so a machine busy with something else slows all of them.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from bench.common import DIFFBOT, REPO, say, table
from runner.wire.transport import free_port

VARIANTS = 24
SLOTS = 2
TARGET_S = 1.0  # Ray's overhead per variant, at most

_SUITE = """
name: sweep
duration: 1.0
rate: max
seed: 1
world:
  physics: {{timestep: 0.002}}
  models:
    - {{name: wall, shape: box, size: [0.1, 6, 0.5], pose: {{xyz: [3, 0, 0.25]}}}}
robots:
  - name: r1
    description: {{file: robots/diffbot.urdf.xacro}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive, params: {{rate: 50}}}}
      - {{type: lidar, params: {{link: lidar_link, samples: 180, rate: 10, range_max: 8.0,
          noise_stddev: 0.01}}}}
      - {{type: imu, params: {{link: imu_link, rate: 100, linear_acceleration_stddev: 0.01}}}}
timeline:
  - {{t: 0.1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.2}}}}}}
matrix:
  seed: {seeds}
  timeline[0].data.linear.x: [0.1, 0.2, 0.3, 0.4]
assertions:
  - {{name: clear_of_the_wall, type: no_collision, between: [r1, wall]}}
  - {{name: moves, type: distance_traveled, robot: r1, min: 0.05, max: 0.5}}
"""

# on loopback, without token authentication (Ray 2.60 writes ~/.ray/auth_token for a local cluster, and
# turns authentication on for any head started once it is there): nothing of the home folder read or written
_LOOPBACK = {
    "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0",
    "RAY_USAGE_STATS_ENABLED": "0",
    "RAY_AUTH_MODE": "disabled",
}


def _suite(folder: Path, variants: int) -> Path:
    (folder / "robots").mkdir(parents=True, exist_ok=True)
    (folder / "robots" / "diffbot.urdf.xacro").write_text(DIFFBOT.read_text())
    path = folder / "sweep.yaml"
    path.write_text(_SUITE.format(seeds=list(range(1, variants // 4 + 1))))
    return path


def _timed(args: list[str], cwd: Path, env: dict[str, str]) -> tuple[float, float]:
    """(wall seconds of `scenario ARGS`, which must pass; of them, the seconds it took to join or start the
    Ray cluster, as it says: 0 without --ray)."""
    t0 = time.perf_counter()
    cmd = [sys.executable, "-m", "runner.cli", *args]
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0 or f"{VARIANTS} passed, 0 failed" not in proc.stdout:
        raise SystemExit(f"bench suite failed: {' '.join(args)}\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}")
    joined = re.search(r"joined in ([0-9.]+) s", proc.stderr)
    return wall, float(joined.group(1)) if joined else 0.0


@contextlib.contextmanager
def _cluster(tmp: Path) -> Any:
    """A head node of this machine with 2 CPUs, on loopback, in a temp folder of its own: its address.
    Stopped by its own processes' pids (never `ray stop`, which stops every cluster here)."""
    base = Path(tempfile.mkdtemp(prefix="ray-bench-", dir="/tmp"))
    port = free_port()
    env = dict(os.environ, **_LOOPBACK)
    cmd = [str(Path(sys.executable).parent / "ray"), "start", "--head", "--node-ip-address", "127.0.0.1"]
    cmd += [
        "--port",
        str(port),
        "--num-cpus",
        str(SLOTS),
        "--include-dashboard=false",
        "--temp-dir",
        str(base),
    ]
    try:
        subprocess.run([*cmd, "--disable-usage-stats"], env=env, check=True, capture_output=True, timeout=120)
        yield f"127.0.0.1:{port}"
    finally:
        _stop(base)
        shutil.rmtree(base, ignore_errors=True)


def _stop(base: Path) -> None:
    procs: dict[int, tuple[int, str]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            with contextlib.suppress(OSError, ValueError, IndexError):
                stat = (entry / "stat").read_text()
                cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
                procs[int(entry.name)] = (int(stat[stat.rindex(")") + 2 :].split()[1]), cmd)
    above, me = set(), os.getpid()  # (never this process or those above it, whatever they name)
    while me > 1 and me in procs:
        above.add(me)
        me = procs[me][0]
    mine = {pid for pid, (_ppid, cmd) in procs.items() if str(base) in cmd} - above
    grown = True
    while grown:
        more = {pid for pid, (ppid, _cmd) in procs.items() if ppid in mine} - mine
        mine |= more
        grown = bool(more)
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in mine:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, sig)
        time.sleep(2.0)


def run(quick: bool, repeat: int) -> tuple[dict[str, Any], str]:
    rounds = 1 if quick else max(repeat, 2)
    walls: dict[str, list[float]] = {"local": [], "cluster": [], "laptop": []}
    joins: dict[str, list[float]] = {"cluster": [], "laptop": []}
    env = dict(os.environ, PYTHONPATH=str(REPO), **_LOOPBACK)
    with tempfile.TemporaryDirectory() as tmp_dir:
        tmp = Path(tmp_dir)
        suite = _suite(tmp / "suite", VARIANTS)
        laptop_env = dict(env, RAY_TMPDIR=str(tmp / "ray"))  # `--ray` alone: its cluster's files here
        with _cluster(tmp) as address:
            for i in range(rounds):  # alternating: whatever else the machine does slows all three
                modes = {
                    "local": (["test", str(suite), "-j", str(SLOTS), "--out", f"l{i}"], env),
                    "cluster": (["test", str(suite), "--ray", address, "--artifacts", f"c{i}"], env),
                    "laptop": (["test", str(suite), "--ray", "--artifacts", f"p{i}"], laptop_env),
                }
                for mode, (args, mode_env) in modes.items():
                    wall, joined = _timed(args, tmp, mode_env)
                    walls[mode].append(wall)
                    if mode in joins:
                        joins[mode].append(joined)
                say(f"  round {i + 1}: " + ", ".join(f"{k} {v[-1]:.1f} s" for k, v in walls.items()))
    return _results(walls, joins, rounds)


def _results(
    walls: dict[str, list[float]], joins: dict[str, list[float]], rounds: int
) -> tuple[dict[str, Any], str]:
    best = {k: min(v) for k, v in walls.items()}
    # the laptop's suite without its cluster's start (paid once, not per variant), in its best round
    started = joins["laptop"][walls["laptop"].index(best["laptop"])]
    per_min = {m: VARIANTS / v * 60 for m, v in best.items()}
    overhead = {m: SLOTS * (best[m] - best["local"]) / VARIANTS for m in ("cluster", "laptop")}
    overhead["laptop_after_start"] = SLOTS * (best["laptop"] - started - best["local"]) / VARIANTS
    rows = [
        (f"scenario test -j {SLOTS}", best["local"], per_min["local"], 1.0, ""),
        (
            f"--ray, a running cluster of {SLOTS} CPUs",
            best["cluster"],
            per_min["cluster"],
            per_min["cluster"] / per_min["local"],
            f"{overhead['cluster']:+.2f}",
        ),
        (
            f"--ray alone: starts its local cluster ({started:.1f} s), stops it",
            best["laptop"],
            per_min["laptop"],
            per_min["laptop"] / per_min["local"],
            f"{overhead['laptop']:+.2f} ({overhead['laptop_after_start']:+.2f} once started)",
        ),
    ]
    text = table(
        f"ray: {VARIANTS} variants of 1 s sim on {SLOTS} cores, best of {rounds} alternating",
        ("", "wall s", "variants/min", "vs -j 2", "Ray s/variant"),
        rows,
    )
    doc = {
        "variants": VARIANTS,
        "slots": SLOTS,
        "rounds": rounds,
        "wall_s": walls,
        "joined_s": joins,
        "best_wall_s": best,
        "variants_per_minute": per_min,
        "overhead_s_per_variant": overhead,
        "targets": {
            f"Ray's overhead per variant < {TARGET_S:g} s (a running cluster)": overhead["cluster"]
            < TARGET_S,
            f"... with --ray starting its own cluster, once started < {TARGET_S:g} s": (
                overhead["laptop_after_start"] < TARGET_S
            ),
        },
    }
    return doc, text


if __name__ == "__main__":  # a quick look: python -m bench.ray
    print(run(False, 2)[1])
