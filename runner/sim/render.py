"""A renderer process: `python -m runner.sim.render PLAN.json --connect ENDPOINT`.

Started by `scenario run` when the plan's cameras render in a process of their own (`renderers: process`,
or `auto` on a machine with more than one core). It builds the same world from the plan but runs only
the rendering plugins; for each frame the world sends the state (sim time, positions), this process poses
its copy of the world (`mj_kinematics`), runs the plugin (render, encode, publish under the plugin's own
topics, stamped with the world's sim time) and acknowledges with its message counts. Rendering thus runs
on another core while physics goes on; the world waits only when this process falls behind.

It exits when the world says stop, on SIGINT/SIGTERM, or when its parent dies.
"""

from __future__ import annotations

import contextlib
import json
import queue
import sys
import time
from typing import Any

import zenoh

from runner.sim.child import StopFlag, mujoco_warnings_to_stderr, parse, process_name
from runner.sim.links import STATE_HEAD
from runner.sim.world import World
from runner.wire.graph import GraphTokens
from runner.wire.transport import ZenohBus, make_config, meta_key

MATCH_TIMEOUT_S = 5.0


def main(argv: list[str] | None = None) -> int:
    plan, connect = parse("python -m runner.sim.render", argv)
    should_stop = StopFlag()
    mujoco_warnings_to_stderr()

    with zenoh.open(make_config("client", connect=connect)) as session:
        run = plan.name.split("/", 1)[0]
        bus = ZenohBus(
            session,
            GraphTokens(session, run, process_name(plan.name, "renderer"), "renderer"),
            plan.best_effort,
        )
        subs: list[Any] = []
        world: World | None = None
        try:
            world = World(plan, bus, role="renderer")
            if plan.record.enabled:
                # the recorder subscribes before anything starts: wait until it sees our publishers, so the
                # first frame is not published into the void
                deadline = time.monotonic() + MATCH_TIMEOUT_S
                while not bus.all_matched() and time.monotonic() < deadline:
                    time.sleep(0.005)
            inbox: queue.SimpleQueue[tuple[str, bytes]] = queue.SimpleQueue()

            def on_state(sample: zenoh.Sample) -> None:
                inbox.put((str(sample.key_expr), sample.payload.to_bytes()))

            block = zenoh.CongestionControl.BLOCK

            def ack_key(i: int) -> str:
                return meta_key(plan.name, "render", str(i), "done")

            acks = {
                i: session.declare_publisher(ack_key(i), congestion_control=block)
                for i in world.render_plugins
            }
            subs += list(acks.values())
            subs.append(session.declare_subscriber(meta_key(plan.name, "render", "*"), on_state))
            # last: the world starts stepping once it sees this token
            subs.append(session.liveliness().declare_token(meta_key(plan.name, "render", "alive")))
            prefix = meta_key(plan.name, "render", "")

            def fetch(generation: int) -> bytes:
                """The world's model at `generation` (runner.sim.grow serves it)."""
                key = meta_key(plan.name, "render", "model", str(generation))
                for _ in range(3):
                    for reply in session.get(key, timeout=10.0):
                        if reply.ok is not None:
                            return bytes(reply.ok.payload.to_bytes())
                raise RuntimeError(f"the world did not give its model at generation {generation}")

            frames = dict.fromkeys(world.render_plugins, 0)
            while not should_stop():
                try:
                    key, payload = inbox.get(timeout=0.2)
                except queue.Empty:
                    continue
                what = key[len(prefix) :]
                if what == "stop":
                    break
                index = int(what)
                now_ns, _frame, epoch_ns, generation = STATE_HEAD.unpack_from(payload)
                world.render(index, now_ns, payload[STATE_HEAD.size :], epoch_ns, generation, fetch)
                if index not in acks:  # a spawned robot's camera
                    acks[index] = session.declare_publisher(ack_key(index), congestion_control=block)
                    subs.append(acks[index])
                    frames[index] = 0
                frames[index] += 1
                acks[index].put(json.dumps({"n": frames[index], "published": world.published()}).encode())
        except Exception as e:  # reported on stderr, which the runner shows
            print(f"renderer: {type(e).__name__}: {e}", file=sys.stderr)
            return 1
        finally:
            for s in subs:
                with contextlib.suppress(Exception):
                    s.undeclare()
            for plugin in world.plugins if world else []:
                plugin.close()
            bus.undeclare_all()
    return should_stop.exit_code()


if __name__ == "__main__":
    sys.exit(main())
