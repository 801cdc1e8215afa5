"""Benchmark: the two-robot demo against the raw MuJoCo step rate of the same compiled model.

    python bench/two_robots.py [--seconds 20] [--repeat 3]

All figures come from the same run, so they are comparable on a noisy machine:
- raw MuJoCo: `mj_step` on the compiled model (plugins' actuators and sensors included, no Python
  hooks), once called per step from Python and once batched (`nstep`) in C: the limit;
- world in-process: our loop, all plugins publishing onto an in-memory bus (hooks + CDR encoding);
- full run: `scenario run` as users run it: world process, Zenoh, the recorder writing MCAP.
Results are printed as a table and written to bench/results/two_robots.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

# Run as a script, this folder comes first on sys.path, and bench/plugins.py would shadow the `plugins`
# package: put the repository first instead.
REPO = Path(__file__).resolve().parents[1]
if sys.path and Path(sys.path[0]).resolve() == REPO / "bench":
    sys.path[0] = str(REPO)

import mujoco  # noqa: E402

from runner.compile import compile_plan  # noqa: E402
from runner.launch import run_plan  # noqa: E402
from runner.loader import load_file  # noqa: E402
from runner.sim.world import World  # noqa: E402
from runner.transport import MemoryBus  # noqa: E402
from runner.validate import validate_scenario  # noqa: E402

HERE = Path(__file__).resolve().parent
SCENARIO = HERE.parent / "scenarios" / "two_robots.yaml"


def raw_rate(mjcf: str, steps: int, batched: bool) -> float:
    model = mujoco.MjModel.from_xml_string(mjcf)
    data = mujoco.MjData(model)
    t0 = time.perf_counter()
    if batched:
        mujoco.mj_step(model, data, nstep=steps)
    else:
        for _ in range(steps):
            mujoco.mj_step(model, data)
    return steps / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=20.0, help="sim seconds per measurement")
    ap.add_argument("--repeat", type=int, default=3, help="best of N for each figure")
    args = ap.parse_args()

    doc = load_file(SCENARIO)
    scenario = validate_scenario(doc)
    plan = compile_plan(scenario, doc)
    plan.rate = "max"
    plan.duration_ns = round(args.seconds * 1e9)
    steps = plan.duration_ns // plan.step_ns
    dt = plan.step_ns / 1e9

    raw_loop = max(raw_rate(plan.mjcf, steps, batched=False) for _ in range(args.repeat))
    raw_batch = max(raw_rate(plan.mjcf, steps, batched=True) for _ in range(args.repeat))

    inproc = 0.0
    for _ in range(args.repeat):
        world = World(plan, MemoryBus())
        stats = world.run()
        inproc = max(inproc, stats.steps / stats.wall_s)

    full = 0.0
    recorded = 0
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.repeat):
            plan.record.path = str(Path(tmp) / f"bench{i}.mcap")
            result = run_plan(plan)
            if result.reason != "completed":
                raise SystemExit(f"run failed: {result.error}")
            full = max(full, (result.sim_ns / plan.step_ns) / result.wall_s)
            recorded = sum(t.count for t in result.topics)

    rows = [
        ("raw MuJoCo, mj_step per call (Python loop)", raw_loop),
        ("raw MuJoCo, mj_step batched in C (the limit)", raw_batch),
        ("world in-process, all plugins, in-memory bus", inproc),
        ("scenario run: world process + Zenoh + MCAP recorder", full),
    ]
    print(
        f"two_robots: {len(plan.robots)} robots, step {dt * 1e3:g} ms, {args.seconds:g} s sim, "
        f"best of {args.repeat}"
    )
    print(f"{'':56s} {'steps/s':>10s} {'× real time':>12s} {'of limit':>9s}")
    for label, rate in rows:
        print(f"{label:56s} {rate:10.0f} {rate * dt:12.1f} {rate / raw_batch:9.2f}")
    print(f"messages recorded per run: {recorded} ({recorded / args.seconds:.0f} per sim second)")

    result_doc = {
        "benchmark": "two_robots",
        "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "machine": {
            "python": platform.python_version(),
            "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(),
            "cpus": os.cpu_count(),
            "mujoco": mujoco.__version__,
        },
        "sim_seconds": args.seconds,
        "step_s": dt,
        "steps_per_s": {
            "raw_loop": raw_loop,
            "raw_batched": raw_batch,
            "world_inprocess": inproc,
            "full_run_recorded": full,
        },
        "x_real_time": {
            "raw_batched": raw_batch * dt,
            "world_inprocess": inproc * dt,
            "full_run_recorded": full * dt,
        },
        "ratio_to_limit": {"world_inprocess": inproc / raw_batch, "full_run_recorded": full / raw_batch},
        "messages_recorded": recorded,
    }
    out = HERE / "results" / "two_robots.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(result_doc, indent=2) + "\n")
    print(f"wrote {out.relative_to(HERE.parent)}")


if __name__ == "__main__":
    main()
