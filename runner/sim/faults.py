"""Faults an event injects on a topic the world publishes (`fault:`): while one is on, every message of
the key goes through it: dropped (all, or each with a probability), delayed (held, then sent at the
first step at or after its time plus the delay, its contents untouched: a late message carries its old
stamp), frozen (the last message before the fault, sent again in place of each new one), or corrupted
(Gaussian noise on number fields). Subscribers in the world, the recording and every client see the same
faulty stream. Random choices come from the event's own generator (the scenario's seed): a run repeats."""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np

from runner.wire import msgs


class Fault:
    def __init__(
        self,
        spec: dict[str, Any],
        rng: np.random.Generator,
        out: Any,
        now_ns: int,
        wake: Callable[[int], None],
    ):
        """`wake(t)`: the world must stop at sim time `t` (a held message is due then)."""
        self.spec = spec
        self.wake = wake
        self.rng = rng
        self.drop = spec.get("drop")
        self.delay_ns = int(spec.get("delay_ns") or 0)
        self.noise = spec.get("noise")
        self.fields = spec.get("fields")
        self.frozen = bytes(out.last) if spec.get("freeze") and out.last is not None else None
        self.freeze = bool(spec.get("freeze"))
        self.held: deque[tuple[int, bytes, Any]] = deque()
        self.until_ns = now_ns + spec["duration_ns"] if spec.get("duration_ns") else None
        self.dropped = 0

    def take(self, out: Any, payload: bytes, msg: Any, stamp_ns: int) -> None:
        if self.drop is not None:
            if self.drop >= 1.0 or self.rng.random() < self.drop:
                self.dropped += 1
                return
            out.deliver(payload, msg, stamp_ns)
        elif self.delay_ns:
            self.held.append((stamp_ns + self.delay_ns, bytes(payload), msg))
            self.wake(stamp_ns + self.delay_ns)
        elif self.freeze:
            if self.frozen is not None:  # (nothing sent before it: nothing to repeat)
                out.deliver(self.frozen, None, stamp_ns)
        else:
            noisy = _corrupt(
                msg if msg is not None else msgs.decode(payload, out.type), self.noise, self.fields, self.rng
            )
            out.deliver(msgs.encode(noisy, out.type), noisy, stamp_ns)

    def release(self, out: Any, now_ns: int) -> None:
        """Send the held messages whose time has come (stamped now, when they go out)."""
        held = self.held
        while held and held[0][0] <= now_ns:
            _due, payload, msg = held.popleft()
            out.deliver(payload, msg, now_ns)

    def next_ns(self) -> int | None:
        """The next time this fault must be looked at: a held message due, or its end."""
        due = [t for t in (self.held[0][0] if self.held else None, self.until_ns) if t is not None]
        return min(due) if due else None


def _corrupt(msg: Any, stddev: float, fields: list[str] | None, rng: np.random.Generator) -> Any:
    """A copy of `msg` with noise added to the named fields (dotted paths), or to every number and array
    of numbers but the header's."""
    if fields is None:
        return _noisy(msg, stddev, rng, top=True)
    for path in fields:
        msg = _set_path(msg, path.split("."), stddev, rng)
    return msg


def _set_path(msg: Any, parts: list[str], stddev: float, rng: np.random.Generator) -> Any:
    value = getattr(msg, parts[0])
    new = _noise_value(value, stddev, rng) if len(parts) == 1 else _set_path(value, parts[1:], stddev, rng)
    return dataclasses.replace(msg, **{parts[0]: new})


def _noise_value(value: Any, stddev: float, rng: np.random.Generator) -> Any:
    if isinstance(value, np.ndarray) and value.dtype.kind == "f":
        return (value + rng.normal(0.0, stddev, value.shape)).astype(value.dtype)
    if isinstance(value, float):
        return value + float(rng.normal(0.0, stddev))
    if dataclasses.is_dataclass(value):
        return _noisy(value, stddev, rng, top=False)
    return value


def _noisy(msg: Any, stddev: float, rng: np.random.Generator, top: bool) -> Any:
    changes = {}
    for f in dataclasses.fields(msg):
        if top and f.name == "header":
            continue
        value = getattr(msg, f.name)
        if f.name == "__msgtype__":
            continue
        if isinstance(value, list):
            changes[f.name] = [_noise_value(v, stddev, rng) for v in value]
        else:
            changes[f.name] = _noise_value(value, stddev, rng)
    return dataclasses.replace(msg, **changes)
