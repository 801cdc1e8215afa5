"""Another host of a multi-host run (`scenario run FILE --host NAME`): run the worlds and nodes placed on
this host, joined to the main host's runner, which records, judges and says when everything starts
(runner.launch.supervisor); end with them. Ctrl-C here stops this host's part; the main host sees its worlds
stop and ends the run.
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Sequence

import zenoh

from runner.errors import RunError
from runner.launch.keeper import Keeper
from runner.launch.nodes import NodeError, Nodes
from runner.launch.result import RunResult
from runner.launch.worlds import connectable, world_parts
from runner.plan import RunPlan
from runner.wire.graph import member_key
from runner.wire.transport import make_config, meta_key, zenoh_reason


def run_member(
    plan: RunPlan, host: str, *, connect: Sequence[str] = (), listen: Sequence[str] = ()
) -> RunResult:
    """`scenario run FILE --host NAME`: run the worlds and nodes placed on this host, joined to the main
    host's runner (which records and judges, and says when everything starts); end with them."""
    if host not in plan.hosts:
        raise RunError(f"no host named {host!r} in the scenario; hosts: {', '.join(plan.hosts)}")
    listen = list(listen) or [plan.hosts[host]]
    connect = list(connect) or [plan.hosts[plan.main_host]]  # type: ignore[index]
    try:
        session = zenoh.open(make_config("router", listen=listen, connect=connect))
    except zenoh.ZError as e:
        raise RunError(f"cannot open the Zenoh network on {', '.join(listen)}: {zenoh_reason(e)}") from None
    keeper = Keeper()  # every process started here ends with this runner, however it ends
    parts = world_parts(plan, host)
    subs = [session.declare_subscriber(meta_key(p.plan.name, "**"), p.on_meta) for p in parts]
    subs.append(session.liveliness().declare_token(member_key(plan.name, str(session.zid()))))  # (the run's)
    nodes = (
        Nodes(plan, connectable(listen[0]), host=host) if any(n.host == host for n in plan.nodes) else None
    )
    reason, error = "completed", None
    wall0 = time.perf_counter()
    try:
        if nodes is not None:
            try:
                nodes.start()
            except NodeError as e:
                raise RunError(str(e)) from None
        for part in parts:
            part.start(connectable(listen[0]))
        try:
            while any(p.running() for p in parts) or (
                not parts and nodes is not None and nodes.any_running()
            ):
                time.sleep(0.05)
                if nodes is not None and error is None and not any(p.ended.is_set() for p in parts):
                    ended_by = nodes.check()
                    if ended_by is not None:
                        reason, error = ended_by
                        print(
                            error.splitlines()[0] + "; stopping this host's part", file=sys.stderr, flush=True
                        )
                        for p in parts:
                            p.stop()
        except KeyboardInterrupt:
            reason = "interrupted"
            for p in parts:
                p.stop()
        if nodes is not None and error is None and reason != "interrupted":
            # a required node that died while the world was being stopped (by the main host) still fails
            ended_by = nodes.check()
            if ended_by is not None and ended_by[0] == "failed":
                reason, error = ended_by
                print(error.splitlines()[0], file=sys.stderr, flush=True)
        for part in parts:
            perr = part.finish(reason == "interrupted")
            if perr is not None and error is None:
                reason, error = "failed", perr
    finally:
        if nodes is not None:
            nodes.stop()
        for part in parts:
            part.cleanup()
        for sub in subs:
            with contextlib.suppress(Exception):
                sub.undeclare()
        session.close()
        keeper.close()
    infos = [p.end_info for p in parts]
    return RunResult(
        reason=reason if error is None or reason != "completed" else "failed",
        sim_ns=min((int(i.get("sim_ns", 0)) for i in infos), default=0),
        wall_s=max((float(i.get("wall_s", 0.0)) for i in infos), default=time.perf_counter() - wall0),
        mcap=None,
        published={k: v for i in infos for k, v in i.get("published", {}).items()},
        error=error,
        endpoints=listen,
    )
