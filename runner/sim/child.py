"""What every process the runner starts for a plan shares: its command line and how it knows to stop."""

from __future__ import annotations

import argparse
import os
import signal
from pathlib import Path

from runner.plan import RunPlan


def parse(prog: str, argv: list[str] | None) -> tuple[RunPlan, list[str]]:
    """`PROG PLAN.json --connect ENDPOINT ...` -> (the plan, the endpoints of the run's router)."""
    ap = argparse.ArgumentParser(prog=prog)
    ap.add_argument("plan", type=Path)
    ap.add_argument("--connect", action="append", default=[], help="Zenoh endpoint of the run's router")
    args = ap.parse_args(argv)
    return RunPlan.model_validate_json(args.plan.read_text()), list(args.connect)


class StopFlag:
    """Set by SIGINT/SIGTERM (the runner stops its children in order) or by the parent's death."""

    def __init__(self) -> None:
        self.signal: int | None = None
        self._parent = os.getppid()
        signal.signal(signal.SIGINT, self._on_signal)
        signal.signal(signal.SIGTERM, self._on_signal)

    def _on_signal(self, signum: int, _frame: object) -> None:
        self.signal = signum

    def __call__(self) -> bool:
        return self.signal is not None or os.getppid() != self._parent

    def exit_code(self, ok: int = 0) -> int:
        return ok if self.signal is None else 130


def process_name(plan_name: str, role: str) -> str:
    """How a process of this plan is named in the run's graph: `world` (or the world's name, in a run of
    several worlds), `renderer` (or `<world>-renderer`)."""
    _run, _, world = plan_name.partition("/")
    if not world:
        return role
    return world if role == "world" else f"{world}-{role}"


def mujoco_warnings_to_stderr() -> None:
    """MuJoCo's warnings on stderr (the runner shows them, prefixed), not in a MUJOCO_LOG.TXT left in
    whatever folder the run was started from."""
    import sys

    import mujoco

    mujoco.set_mju_user_warning(lambda text: print(f"MuJoCo warning: {text}", file=sys.stderr, flush=True))
