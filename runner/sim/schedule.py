"""When things happen in the world's loop: a plugin hook and its rate (`Hook`), when it is next due
(`next_due`: on whole multiples of its period, so rates land on exact steps), and the pacing sleep that
keeps sim time in step with wall time (`sleep_until`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass


@dataclass
class Hook:
    fn: Callable[[int], None]
    period_ns: int  # 0: every step
    next_ns: int = 0
    forward: bool = False  # needs mj_forward first (acceleration-stage values)


# The OS may oversleep by a fraction of a millisecond: sleep to just before the deadline, then yield until it.
_SPIN_S = 0.0005


def sleep_until(deadline: float) -> None:
    """Wake at `deadline` (perf_counter time) within microseconds, not when the scheduler pleases: the
    last half millisecond yields instead of sleeping (`sleep(0)` releases the GIL, so the transport's
    threads can hand over messages meanwhile)."""
    rest = deadline - time.perf_counter()
    if rest > _SPIN_S:
        time.sleep(rest - _SPIN_S)
    while time.perf_counter() < deadline:
        time.sleep(0)


def next_due(h: Hook, now: int) -> int:
    if h.period_ns == 0:
        return now + 1
    nxt = h.next_ns + h.period_ns
    return nxt if nxt > now else (now // h.period_ns + 1) * h.period_ns
