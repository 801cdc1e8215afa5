"""How a run went (`RunResult`): its ending, its sim and wall time, what was published, recorded and refused,
as `scenario run` reports it."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from runner.launch.parts import outside_of, published_of, rejected_of
from runner.record import TopicStats

if TYPE_CHECKING:
    from runner.launch.supervisor import Supervisor


@dataclass
class RunResult:
    reason: str  # completed | stopped | interrupted | failed
    sim_ns: int
    wall_s: float
    mcap: Path | None
    topics: list[TopicStats] = field(default_factory=list)
    published: dict[str, int] = field(default_factory=dict)
    error: str | None = None
    endpoints: list[str] = field(default_factory=list)
    rejected: dict[str, dict[str, int]] = field(default_factory=dict)  # inbound samples dropped: key, why
    outside: dict[str, int] = field(default_factory=dict)  # messages from publishers outside the run, per key
    outsiders: list[str] = field(default_factory=list)  # those publishers' sessions, named

    @property
    def exit_code(self) -> int:
        return {"completed": 0, "stopped": 0, "interrupted": 130}.get(self.reason, 1)

    @property
    def lost(self) -> dict[str, int]:
        """Messages published but not recorded, per topic (only topics that were recorded)."""
        got = {t.key: t.count for t in self.topics}
        return {k: n - got[k] for k, n in self.published.items() if k in got and n > got[k]}


def result_of(run: Supervisor) -> RunResult:
    """What a finished supervisor tells: how the run ended, its times, what was published and recorded."""
    infos = [w.end_info for w in run.worlds]
    walls = [float(i["wall_s"]) for i in infos if "wall_s" in i]
    recorder = run.recorder.recorder if run.recorder is not None else None
    outside, outsiders = outside_of(run)
    return RunResult(
        reason="interrupted" if run.signalled.is_set() else run.reason,  # (one that came while closing too)
        sim_ns=run.reached(),
        wall_s=max(walls) if len(walls) == len(infos) else time.perf_counter() - run.wall0,
        mcap=Path(run.plan.record.path) if recorder else None,
        topics=recorder.stats() if recorder else [],
        published=published_of(run),
        error=run.error,
        endpoints=run.listen,
        rejected=rejected_of(run),
        outside=outside,
        outsiders=outsiders,
    )
