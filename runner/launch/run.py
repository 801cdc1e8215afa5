"""launch: run a compiled plan. The runner process hosts the run's Zenoh router (a Python session in router
mode: no zenohd needed) and the recorder; each world is an OS process of its own that connects to it.

`run_plan` is the entry: on the main host a `Supervisor` (runner.launch.supervisor) starts the parts, runs
them and stops them in order; on another host of a multi-host run, `run_member` (runner.launch.member) runs
the parts placed there. Either way the result is a `RunResult`.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from typing import Any

from runner.interrupts import interruptible
from runner.launch.result import RunResult, result_of
from runner.plan import RunPlan
from runner.wire.transport import free_port


def run_plan(
    plan: RunPlan,
    *,
    listen: Sequence[str] = (),
    connect: Sequence[str] = (),
    on_progress: Callable[[int, float], None] | None = None,
    judge: Any = None,
    host: str | None = None,
    foxglove_port: int | None = None,
    foxglove_origins: Sequence[str] = (),
) -> RunResult:
    """Run a plan (one world, or `plan.worlds`, each a process of its own behind one router and one
    recorder); with a `judge` (runner.checks.judge.Judge), feed it every message it asks for, live, and
    stop the worlds early when the plan's `stop_on` says so. `foxglove_port`: serve the run live to
    Foxglove there (runner.launch.live), to pages of the `foxglove_origins` besides the default ones.

    With `plan.hosts`, this runner plays `host` (None: the first, main host, which records and judges);
    the parts placed on other hosts are run by their own `scenario run FILE --host NAME`, and joined."""
    from runner.launch.supervisor import Supervisor

    interruptible()  # outside the supervisor (a member host), Ctrl-C raises; the supervisor takes it over
    if plan.hosts and host not in (None, plan.main_host):
        from runner.launch.member import run_member

        return run_member(plan, host, connect=connect, listen=listen)  # type: ignore[arg-type]
    if plan.hosts and not listen:
        listen = [plan.hosts[plan.main_host]]  # type: ignore[index]
    listen = list(listen) or [f"tcp/127.0.0.1:{free_port()}"]
    plan = _placed_renderers(plan)
    run = Supervisor(
        plan,
        listen,
        connect,
        on_progress=on_progress,
        judge=judge,
        foxglove_port=foxglove_port,
        foxglove_origins=tuple(foxglove_origins),
    )
    run.run()
    return result_of(run)


def _placed_renderers(plan: RunPlan) -> RunPlan:
    if plan.renderers != "auto":
        return plan
    # A renderer process pays where rendering does not already take every core: Mesa's llvmpipe renders on
    # all cores of a 2-core machine, and the two placements measure the same there (bench cameras).
    renderers = "process" if (os.cpu_count() or 1) > 2 else "world"
    plan = plan.model_copy(update={"renderers": renderers})
    if plan.worlds:
        plan.worlds = [w.model_copy(update={"renderers": renderers}) for w in plan.worlds]
    return plan
