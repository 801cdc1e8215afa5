"""A real multi-node Ray cluster on this machine's loopback, for tests: a head (`ray start --head`) and
worker nodes joining it (`ray start --address`), each with its own temp dir, everything on 127.0.0.1.

Ray 2.60 turns 127.0.0.1 (given as `--node-ip-address`, or in `--address`) into the machine's outward
address, and listens there, unless RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0 says the cluster is one machine's;
with that set, `ray start --address` refuses to start a second node ("multi-node clusters are not supported
on Windows and OSX"). So the head starts as Ray's own `ray start`, and a worker node through `python -m
tests.ray_cluster start ...`: the same `ray start`, told once that 127.0.0.1 is its address (and the
head's), while its processes keep the variable and stay on loopback.

Stopping: never `ray stop` (it stops every cluster of the machine, other suites' too): the processes whose
command line names this cluster's temp folder, and their children, are ended by pid.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

# On loopback, and without Ray's token authentication: Ray 2.60 turns it on for a head when a token lies in
# ~/.ray/auth_token (which a local `ray.init()` writes), and the tests neither read nor write the home folder
LOOPBACK_ENV = {
    "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0",
    "RAY_USAGE_STATS_ENABLED": "0",
    "RAY_AUTH_MODE": "disabled",
}


@dataclass
class Cluster:
    """A running cluster: its head's address, its temp folder, and its nodes' ids once up."""

    address: str
    base: Path
    nodes: list[str] = field(default_factory=list)

    def stop(self) -> None:
        stop_processes_under(self.base)
        shutil.rmtree(self.base, ignore_errors=True)


def start_cluster(nodes: int = 2, cpus: int = 1, timeout: float = 120) -> Cluster:
    """A head and `nodes - 1` workers, `cpus` CPUs each, up and registered."""
    from runner.wire.transport import free_port

    # short: Ray's unix sockets live under it (at most 107 bytes a path)
    base = Path(tempfile.mkdtemp(prefix="ray-", dir="/tmp"))
    port = free_port()
    cluster = Cluster(f"127.0.0.1:{port}", base)
    env = dict(os.environ, **LOOPBACK_ENV)
    common = ["--node-ip-address", "127.0.0.1", "--num-cpus", str(cpus), "--disable-usage-stats"]
    try:
        head = [str(Path(sys.executable).parent / "ray"), "start", "--head", "--port", str(port)]
        head += ["--include-dashboard=false", "--temp-dir", str(base / "head"), *common]
        _run(head, env, timeout)
        for i in range(1, nodes):
            worker = [sys.executable, "-m", "tests.ray_cluster", "start", "--address", cluster.address]
            _run([*worker, "--temp-dir", str(base / f"node{i}"), *common], env, timeout)
        cluster.nodes = _wait_for_nodes(cluster.address, nodes, env, timeout)
    except BaseException:
        cluster.stop()
        raise
    return cluster


def _run(cmd: list[str], env: dict[str, str], timeout: float) -> None:
    repo = Path(__file__).resolve().parents[1]
    proc = subprocess.run(cmd, env=env, cwd=repo, capture_output=True, text=True, timeout=timeout)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[:4])}... failed: {proc.stdout[-2000:]}{proc.stderr[-2000:]}")


_NODES = """
import sys, ray
ray.init(address=sys.argv[1], log_to_driver=False, logging_level="ERROR")
print(" ".join(sorted(n["NodeID"] for n in ray.nodes() if n["Alive"])))
"""


def _wait_for_nodes(address: str, n: int, env: dict[str, str], timeout: float) -> list[str]:
    deadline = time.monotonic() + timeout
    seen: list[str] = []
    while time.monotonic() < deadline:
        proc = subprocess.run(
            [sys.executable, "-c", _NODES, address], env=env, capture_output=True, text=True, timeout=timeout
        )
        seen = proc.stdout.split()
        if len(seen) >= n:
            return seen
        time.sleep(0.5)
    raise RuntimeError(f"only {len(seen)} of {n} Ray nodes came up at {address}")


def stop_processes_under(base: Path, grace: float = 3.0) -> list[int]:
    """End every process whose command line names `base` (the cluster's own: GCS, raylets, agents...) and
    every descendant of them (its workers, the runs they started): SIGTERM, then SIGKILL. The pids."""
    above = _ancestors(os.getpid())  # (a shell whose command line names the folder is not the cluster's)
    mine = {pid for pid, cmd in _processes().items() if str(base) in cmd} - above
    mine |= _descendants(mine)
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in mine:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, sig)
        deadline = time.monotonic() + grace
        while time.monotonic() < deadline and any(_alive(p) for p in mine):
            time.sleep(0.1)
    return sorted(mine)


def _processes() -> dict[int, str]:
    out: dict[int, str] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                out[int(entry.name)] = (
                    (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
                )
            except OSError:
                continue
    return out


def _descendants(roots: set[int]) -> set[int]:
    parent: dict[int, int] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
                parent[int(entry.name)] = int(stat[stat.rindex(")") + 2 :].split()[1])
            except (OSError, ValueError, IndexError):
                continue
    found: set[int] = set()
    frontier = set(roots)
    while frontier:
        frontier = {pid for pid, ppid in parent.items() if ppid in frontier} - found - roots
        found |= frontier
    return found


def _ancestors(pid: int) -> set[int]:
    """`pid` and the processes above it."""
    found = {pid}
    while pid > 1:
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
            pid = int(stat[stat.rindex(")") + 2 :].split()[1])
        except (OSError, ValueError, IndexError):
            break
        found.add(pid)
    return found


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2] != "Z"


def _start_node() -> None:
    """`ray start` for a worker node of a loopback cluster (see the module's docstring): the one check
    that refuses a second node under RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0 is passed, and 127.0.0.1 is kept
    as this node's address and the head's."""
    import ray._private.ray_constants as constants
    import ray._private.services as services
    from ray._common.network_utils import get_localhost_ip
    from ray.scripts.scripts import main

    constants.ENABLE_RAY_CLUSTER = True
    services.get_node_ip_address = lambda address=None: get_localhost_ip()
    sys.argv = ["ray", *sys.argv[1:]]
    main()


if __name__ == "__main__":
    _start_node()
