"""The world process: `python -m runner.sim PLAN.json --connect ENDPOINT`.

Started by `scenario run` (one per world). Joins the run's Zenoh network as a client, steps the world,
and on the end of the run, a SIGINT/SIGTERM, or the death of its parent, announces how many messages it
published on each topic and exits.
"""

from __future__ import annotations

import json
import sys
import threading
import time
from typing import Any

import zenoh

from runner.plan import RunPlan
from runner.sim.child import StopFlag, mujoco_warnings_to_stderr, parse, process_name
from runner.sim.world import World, WorldStats
from runner.wire.graph import GraphTokens
from runner.wire.transport import ZenohBus, make_config, meta_key

READY_TIMEOUT_S = 60.0  # the runner (of this host) listening; parts of other hosts may come late
# every part of the run up, other hosts included: longer than the main runner waits for them
# (runner.launch.run.HOST_JOIN_TIMEOUT_S), so that it is the runner that gives up and says why
START_TIMEOUT_S = 240.0
END_ACK_TIMEOUT_S = 10.0


def main(argv: list[str] | None = None) -> int:
    plan, connect = parse("python -m runner.sim", argv)
    should_stop = StopFlag()
    mujoco_warnings_to_stderr()

    with zenoh.open(make_config("client", connect=connect)) as session:
        run = plan.name.split("/", 1)[0]  # a world of several is named <run>/<world>
        bus = ZenohBus(
            session, GraphTokens(session, run, process_name(plan.name, "world"), "world"), plan.best_effort
        )
        try:
            end_pub = session.declare_publisher(
                meta_key(plan.name, "world", "end"), congestion_control=zenoh.CongestionControl.BLOCK
            )
            code = _wait_for_runner(end_pub, should_stop)
            if code is not None:
                return code
            world = World(plan, bus)
            if world.remote_renders and not world.wait_for_renderers(READY_TIMEOUT_S, should_stop):
                if should_stop():
                    return 130
                print("world: the renderer process is not listening; giving up", file=sys.stderr)
                return 1
            # subscribed and set up: the runner counts the world ready, and nodes (runner.node) wait for this
            # before they publish anything
            alive = session.liveliness().declare_token(meta_key(plan.name, "world", "alive"))
            # Every part of the run (worlds here and on other hosts) starts on the runner's word, and stops
            # when that word is withdrawn (the runner stopped, or its host went away): together.
            go, gone = threading.Event(), threading.Event()

            def on_go(sample: zenoh.Sample) -> None:
                (go if sample.kind == zenoh.SampleKind.PUT else gone).set()

            go_sub = session.liveliness().declare_subscriber(meta_key(run, "go"), on_go, history=True)
            code = _wait_for_go(go, should_stop)
            if code is not None:
                return code
            stats = world.run(should_stop=lambda: should_stop() or gone.is_set())
            go_sub.undeclare()
            _announce_end(session, plan, end_pub, stats, _reason(plan, stats, gone, should_stop), should_stop)
            end_pub.undeclare()
            alive.undeclare()
        finally:
            bus.undeclare_all()
    return should_stop.exit_code()


def _wait_for_runner(end_pub: Any, should_stop: StopFlag) -> int | None:
    """Start only once the runner listens, so that nothing published is missed by the recorder: None then,
    else the exit code (the runner never came, or we were stopped)."""
    deadline = time.monotonic() + READY_TIMEOUT_S
    while not end_pub.matching_status.matching:
        if time.monotonic() > deadline:
            print("world: the runner is not listening; giving up", file=sys.stderr)
            return 1
        if should_stop():
            return 130
        time.sleep(0.005)
    return None


def _wait_for_go(go: threading.Event, should_stop: StopFlag) -> int | None:
    """Until the runner says go (None), or the exit code if it never does or we are stopped."""
    deadline = time.monotonic() + START_TIMEOUT_S
    while not go.wait(0.01):
        if should_stop():
            return 130
        if time.monotonic() > deadline:
            print("world: the runner did not say go; giving up", file=sys.stderr)
            return 1
    return None


def _reason(plan: RunPlan, stats: WorldStats, gone: threading.Event, should_stop: StopFlag) -> str:
    """How the run ended for this world, as its end message says it."""
    # (an event's `end:` completes the run where it fires)
    reason = "completed" if stats.sim_ns >= plan.duration_ns or stats.ended else "stopped"
    if stats.error is not None:
        reason = "failed"  # the runner reports it (the end message carries it)
    if reason == "stopped" and gone.is_set() and not should_stop():
        print(
            f"world: the runner went away at {stats.sim_ns / 1e9:.2f} s sim; stopping",
            file=sys.stderr,
        )
    return reason


def _announce_end(
    session: zenoh.Session, plan: RunPlan, end_pub: Any, stats: WorldStats, reason: str, should_stop: StopFlag
) -> None:
    """Send the end message and wait for the runner's acknowledgement: it comes after everything published
    before it, so once acknowledged nothing of this world is still in flight, and the session may close."""
    acked = threading.Event()
    ack_sub = session.declare_subscriber(meta_key(plan.name, "world", "end_ack"), lambda _s: acked.set())
    end_pub.put(
        json.dumps(
            {
                "reason": reason,
                "sim_ns": stats.run_ns,  # (the recording's time: it goes on over a reset_simulation)
                "steps": stats.steps,
                "wall_s": stats.wall_s,
                "published": stats.published,
                "rejected": stats.rejected,
                "error": stats.error,
                "ended": stats.ended,
            }
        ).encode()
    )
    deadline = time.monotonic() + END_ACK_TIMEOUT_S
    while not acked.wait(0.02):
        if should_stop():  # the runner is gone (or stops us): nobody will acknowledge
            break
        if time.monotonic() > deadline:
            print("world: the runner did not acknowledge the end; closing anyway", file=sys.stderr)
            break
    ack_sub.undeclare()


if __name__ == "__main__":
    sys.exit(main())
