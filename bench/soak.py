"""Soak: the two-robot demo for a long sim time at `rate: max`, recorded, as `scenario run` runs it.

`python -m bench.soak [--seconds 600]` (or the `soak` section of `python -m bench`). While it runs, the
resident memory of the runner (router, recorder, judge) and of the world process is sampled every 0.25 s;
the report gives each one's RSS once warmed up (a quarter into the run: the Zenoh buffers and the
recorder's queue fill in the first seconds), at the end and at its peak after warm-up, the growth from
warm-up to each, the end against the peak between warm-up and three quarters of the run (a leak makes
the end the highest of all), and the messages recorded and lost (`--strict` makes any loss fail the run).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
TWO_ROBOTS = REPO / "scenarios" / "two_robots.yaml"


def _rss_kib(pid: int) -> int | None:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    except OSError:
        return None
    return None


def _children(pid: int) -> list[int]:
    try:
        return [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


def soak(seconds: float = 600.0, scenario: Path = TWO_ROBOTS, extra: tuple[str, ...] = ()) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        mcap, results = Path(tmp) / "soak.mcap", Path(tmp) / "results.json"
        cmd = [sys.executable, "-m", "runner.cli", "run", str(scenario), "--rate", "max"]
        cmd += ["--duration", str(seconds), "--record", str(mcap), "--strict", "-q"]
        cmd += ["--results-json", str(results), *extra]
        samples: dict[str, list[tuple[float, int]]] = {"runner": [], "world": []}
        t0 = time.monotonic()
        proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        done = threading.Event()

        def sample() -> None:
            while not done.wait(0.25):
                now = time.monotonic() - t0
                rss = _rss_kib(proc.pid)
                if rss:
                    samples["runner"].append((now, rss))
                kids = [c for c in _children(proc.pid)]
                world = _rss_kib(kids[0]) if kids else None
                if world:
                    samples["world"].append((now, world))

        sampler = threading.Thread(target=sample, daemon=True)
        sampler.start()
        _out, err = proc.communicate()
        done.set()
        sampler.join()
        wall = time.monotonic() - t0
        if proc.returncode != 0:
            raise SystemExit(f"the soak run failed ({proc.returncode}):\n{err[-2000:]}")
        from runner.record import read_summary

        summary = read_summary(mcap)
        suite = json.loads(results.read_text())
    doc: dict[str, Any] = {
        "sim_seconds": seconds,
        "wall_seconds": round(wall, 1),
        "x_real_time": round(seconds / wall, 1),
        "messages_recorded": summary["messages"],
        "lost": 0,  # --strict: a run that lost anything fails (and raises above)
        "assertions_passed": sum(bool(r.get("passed")) for r in suite["results"]),
        "assertions": len(suite["results"]),
    }
    for name, points in samples.items():
        if len(points) < 8:
            continue
        warm = points[max(1, len(points) // 4)][1]
        end = points[-1][1]
        doc[f"{name}_rss_warm_mib"] = round(warm / 1024, 1)
        doc[f"{name}_rss_end_mib"] = round(end / 1024, 1)
        doc[f"{name}_rss_peak_mib"] = round(max(p[1] for p in points) / 1024, 1)
        doc[f"{name}_rss_growth_pct"] = round(100 * (end - warm) / warm, 1)
        later_peak = max(p[1] for p in points[len(points) // 4 :])
        doc[f"{name}_rss_peak_growth_pct"] = round(100 * (later_peak - warm) / warm, 1)
        # a leak grows all along: the end stands above everything before it. A recorder that falls behind
        # on a loaded machine lifts the memory for a while (Zenoh's buffers, the allocator's arenas) and
        # lets it down again, anywhere in the run (seen: +20-35 MiB, for a few seconds to a third of it)
        earlier = max(p[1] for p in points[len(points) // 4 : 3 * len(points) // 4])
        doc[f"{name}_rss_end_vs_earlier_peak_pct"] = round(100 * (end - earlier) / earlier, 1)
        step = max(1, len(points) // 10)
        doc[f"{name}_rss_mib_series"] = [round(p[1] / 1024) for p in points[::step]]
    return doc


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.soak", description=__doc__)
    ap.add_argument("--seconds", type=float, default=600.0, help="sim seconds (default 600)")
    ap.add_argument("--no-judge", action="store_true", help="do not judge the assertions (memory without)")
    args = ap.parse_args(argv)
    for k, v in soak(args.seconds, extra=("--no-judge",) if args.no_judge else ()).items():
        print(f"{k:28} {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
