"""The judge: one piece of code that decides the scenario's assertions from a stream of messages.

It is fed live during `scenario run` (from the run's Zenoh traffic) and offline by `scenario check` (from
the MCAP file): `feed(key, t_ns, msg)` for every message on a key it asked for, then `finish(end_ns)`.
Each check reads one key and depends only on that key's messages in order, so both modes decide the same
way on the same data.

Data it reads: `<run>/<ns>/_truth` (the true pose and velocity of a robot's base, nav_msgs/Odometry, added
by the compiler for robots that assertions name), `<run>/_contacts` (contacts between named bodies,
gazebo_msgs/ContactsState, published by the world when a `no_collision` asks), and the topics that
`topic_rate` and `message` assertions name.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from runner.scenario.schema import (
    DistanceTraveled,
    MaxSpeed,
    MaxTilt,
    MessageCheck,
    NoCollision,
    Reach,
    StayWithin,
    TopicRate,
)

TRUTH_TOPIC = "_truth"
TRUTH_RATE = 50.0
CONTACTS_TOPIC = "_contacts"
CONTACTS_RATE = 100.0
EVENTS_TOPIC = "_events"


def truth_key(run: str, namespace: str) -> str:
    return f"{run}/{namespace}/{TRUTH_TOPIC}"


def contacts_key(run: str) -> str:
    return f"{run}/{CONTACTS_TOPIC}"


def events_key(run: str) -> str:
    """Where a world says what its events did (runner.sim.events): std_msgs/String, JSON."""
    return f"{run}/{EVENTS_TOPIC}"


def judged_types(plan: Any) -> dict[str, str]:
    """The ROS type of every key a judge of `plan` may read (the plan's topics, the world's contacts and
    its events)."""
    types: dict[str, str] = {}
    for part in plan.worlds or [plan]:  # several worlds: every world's keys (full keys, distinct)
        types.update({t.key: t.type for t in part.topics()})
        types[contacts_key(part.name)] = "gazebo_msgs/msg/ContactsState"
        types[events_key(part.name)] = "std_msgs/msg/String"
    return types


PASS, FAIL, UNDECIDED = "pass", "fail", "undecided"


@dataclass
class Result:
    name: str
    type: str
    status: str  # PASS, FAIL or UNDECIDED (the run never showed enough to decide; `message` says why)
    t_ns: int | None  # when it was decided (the failure's time), if it was
    value: str  # what was measured
    bound: str  # what it was held to
    message: str

    @property
    def passed(self) -> bool:
        return self.status == PASS

    @property
    def undecided(self) -> bool:
        return self.status == UNDECIDED

    @property
    def t(self) -> float | None:
        return None if self.t_ns is None else self.t_ns / 1e9

    def to_json(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "type": self.type,
            "status": self.status,
            "passed": self.passed,
            "t": self.t,
            "value": self.value,
            "bound": self.bound,
            "message": self.message,
        }


# How a run that did not reach its planned end ended (runner.launch.run's reasons, runner.interrupts.ending)
ENDINGS = {
    "interrupted": "interrupted",
    "terminated": "terminated (SIGTERM)",
    "stopped": "stopped early",
    "failed": "stopped by an error",
}


def stops(what: str, t_ns: int, cause: str) -> str:
    """Why the data stopped before the run's end: "the recording stops at t=12.300 s: disk full"."""
    return f"{what} stops at t={t_ns / 1e9:.3f} s: {cause}"


def ended_early(ending: str, sim_ns: int) -> str | None:
    """Why the assertions left open were not decided, for a run that ended `ending` at `sim_ns`; None for
    a run that completed."""
    if ending == "completed":
        return None
    return f"the run was {ENDINGS.get(ending, ending)} at t={sim_ns / 1e9:.3f} s"


@dataclass(frozen=True)
class Span:
    """What the run covered, for the checks deciding at its end: sim time up to `end_ns`, all of it
    (`complete`: the run reached its planned end) or not (`why`: "the run was interrupted at t=6.800 s")."""

    end_ns: int
    complete: bool = True
    why: str = ""

    @property
    def ended(self) -> str:
        """How the run ended, to say why a window it did not reach was not seen."""
        return self.why if not self.complete else f"after the run's end at t={self.end_ns / 1e9:.3f} s"


@dataclass
class _Check:
    spec: Any
    key: str
    result: Result | None = None  # set once decided
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def decided(self) -> bool:
        return self.result is not None

    def decide(self, passed: bool, t_ns: int | None, value: str, bound: str, message: str) -> None:
        if self.result is None:
            self.result = Result(
                self.spec.name, self.spec.type, PASS if passed else FAIL, t_ns, value, bound, message
            )

    def undecided(self, span: Span, value: str, bound: str, why: str) -> None:
        if self.result is None:
            self.result = Result(self.spec.name, self.spec.type, UNDECIDED, span.end_ns, value, bound, why)

    def window_ns(self) -> tuple[int, int | None]:
        """The window [after, until] in sim ns; None: to the end of the run."""
        after = getattr(self.spec, "after", 0.0) or 0.0
        until = getattr(self.spec, "until", None)
        if until is None:
            until = getattr(self.spec, "by", None)  # reach: its deadline
        return round(after * 1e9), None if until is None else round(until * 1e9)

    def in_window(self, t_ns: int) -> bool:
        a, u = self.window_ns()
        return t_ns >= a and (u is None or t_ns <= u)

    def unseen(self, span: Span) -> str | None:
        """Why the run did not show the whole window (then nothing that needs all of it can be decided)."""
        a, u = self.window_ns()
        end = span.end_ns
        if a > end:
            return f"the window opens at t={a / 1e9:g} s, {span.ended}"
        if u is None:
            return None if span.complete else span.why
        if u > end:
            return f"the window runs to t={u / 1e9:g} s, {span.ended}"
        return None

    def feed(self, t_ns: int, msg: Any) -> None:  # overridden
        raise NotImplementedError

    def finish(self, span: Span) -> None:  # overridden
        raise NotImplementedError

    def hold(self, span: Span, value: str, bound: str, *, data: bool = True, nothing: str = "") -> None:
        """The end of a check that fails only on something seen (`always`, `never`, a bound): it passed if
        the whole window was seen and held data (`data`); else it is not decided, saying why."""
        why = self.unseen(span)
        if why is None and not data:
            why = nothing
        if why is not None:
            self.undecided(span, value, bound, why)
        else:
            self.decide(True, None, value, bound, "held")


def _xy(msg: Any) -> tuple[float, float]:
    p = msg.pose.pose.position
    return float(p.x), float(p.y)


class _Reach(_Check):
    def feed(self, t_ns: int, msg: Any) -> None:
        s: Reach = self.spec
        if self.decided or not self.in_window(t_ns):
            return
        x, y = _xy(msg)
        if s.leave is not None and not self.extra.get("left"):
            start = self.extra.setdefault("start", (x, y))
            away = math.hypot(x - start[0], y - start[1])
            self.extra["farthest"] = max(self.extra.get("farthest", 0.0), away)
            if away < s.leave:
                self.extra["last"] = (x, y, t_ns)
                return
            self.extra["left"] = t_ns
        if s.region is not None:
            inside = s.region.contains(x, y)
            dist = 0.0 if inside else math.nan
        else:
            assert s.point is not None
            dist = math.hypot(x - s.point[0], y - s.point[1])
            inside = dist <= s.tolerance
            best = self.extra.get("best")
            if best is None or dist < best[0]:
                self.extra["best"] = (dist, x, y, t_ns)
        if inside:
            self.decide(True, t_ns, f"({x:.3f}, {y:.3f})", self._bound(), f"reached at t={t_ns / 1e9:.3f} s")
        self.extra["last"] = (x, y, t_ns)

    def _bound(self) -> str:
        s: Reach = self.spec
        by = f" by t={s.by:g} s" if s.by is not None else ""
        after = f" after t={s.after:g} s" if s.after else ""
        leave = f", having left the start by {s.leave:g} m" if s.leave is not None else ""
        if s.region is not None:
            return "inside the region" + after + by + leave
        return f"within {s.tolerance:g} m of ({s.point[0]:g}, {s.point[1]:g})" + after + by + leave  # type: ignore[index]

    def finish(self, span: Span) -> None:
        s: Reach = self.spec
        best = self.extra.get("best")
        last = self.extra.get("last")
        if s.leave is not None and not self.extra.get("left") and last is not None:
            value = f"never left the start by {s.leave:g} m (at most {self.extra.get('farthest', 0.0):.3f} m)"
        elif best is not None:
            value = f"closest {best[0]:.3f} m at t={best[3] / 1e9:.3f} s, at ({best[1]:.3f}, {best[2]:.3f})"
        elif last is not None:
            value = f"last at ({last[0]:.3f}, {last[1]:.3f})"
        else:
            value = "no pose received"
        why = self.unseen(span)
        if why is not None:
            self.undecided(span, value, self._bound(), why)
            return
        _, deadline = self.window_ns()
        at = min(deadline, span.end_ns) if deadline is not None else span.end_ns
        self.decide(False, at, value, self._bound(), "not reached")


class _StayWithin(_Check):
    def feed(self, t_ns: int, msg: Any) -> None:
        s: StayWithin = self.spec
        if self.decided or not self.in_window(t_ns):
            return
        self.extra["seen"] = True
        x, y = _xy(msg)
        if s.region.contains(x, y) != s.inside:
            where = "outside" if s.inside else "inside"
            self.decide(False, t_ns, f"({x:.3f}, {y:.3f})", self._bound(), f"{where} the region")

    def _bound(self) -> str:
        return "inside the region" if self.spec.inside else "outside the region"

    def finish(self, span: Span) -> None:
        self.hold(
            span, "", self._bound(), data=self.extra.get("seen", False), nothing="no pose in the window"
        )


class _NoCollision(_Check):
    def feed(self, t_ns: int, msg: Any) -> None:
        s: NoCollision = self.spec
        if self.decided or not self.in_window(t_ns):
            return
        self.extra["seen"] = True
        named = set(s.between)
        for st in msg.states:
            a, b = st.collision1_name, st.collision2_name
            if a == b:
                continue
            hit = (a in named and b in named) or (
                s.others and (a in named or b in named) and "ground" not in (a, b)
            )
            if hit:
                at = ""
                if len(st.contact_positions):
                    p = st.contact_positions[0]
                    at = f" at ({p.x:.2f}, {p.y:.2f}, {p.z:.2f})"
                self.decide(False, t_ns, f"{a} touched {b}{at}", "no contact", f"{a} touched {b}{at}")
                return

    def finish(self, span: Span) -> None:
        # the world publishes the contacts at 100 Hz, none or some: no message at all is no evidence
        seen = self.extra.get("seen", False)
        self.hold(span, "no contact", "no contact", data=seen, nothing="no contact report in the window")


class _TopicRate(_Check):
    def feed(self, t_ns: int, msg: Any) -> None:
        if not self.in_window(t_ns):
            return
        self.extra["n"] = self.extra.get("n", 0) + 1
        self.extra.setdefault("first", t_ns)
        self.extra["last"] = t_ns

    def finish(self, span: Span) -> None:
        s: TopicRate = self.spec
        n = self.extra.get("n", 0)
        first, last = self.extra.get("first"), self.extra.get("last")
        rate = (n - 1) / ((last - first) / 1e9) if n >= 2 and last > first else 0.0
        lo = s.min if s.min is not None else 0.0
        hi = s.max if s.max is not None else math.inf
        bound = f"{lo:g}..{hi:g} Hz" if s.max is not None else f">= {lo:g} Hz"
        value = f"{rate:.2f} Hz ({n} messages)"
        why = self.unseen(span)
        if why is None and n == 0 and not lo:
            why = f"no message on {s.topic} in the window"  # a bound on nothing: vacuous
        if why is not None:
            self.undecided(span, value, bound, why)
            return
        ok = lo <= rate <= hi
        self.decide(ok, None if ok else span.end_ns, value, bound, "held" if ok else "rate out of bounds")


class _Message(_Check):
    def feed(self, t_ns: int, msg: Any) -> None:
        s: MessageCheck = self.spec
        if self.decided or not self.in_window(t_ns):
            return
        expr = self.extra["expr"]
        try:
            value = expr.test(msg)
        except Exception as e:  # a reducer on an empty sequence, a missing field: it fails, with why
            self.decide(False, t_ns, f"error: {e}", s.expr, f"could not evaluate `{s.expr}`")
            return
        self.extra["seen"] = True
        if s.mode == "always" and not value:
            self.decide(
                False, t_ns, "false", f"always {s.expr}", f"`{s.expr}` was false at t={t_ns / 1e9:.3f} s"
            )
        elif s.mode == "never" and value:
            self.decide(
                False, t_ns, "true", f"never {s.expr}", f"`{s.expr}` was true at t={t_ns / 1e9:.3f} s"
            )
        elif s.mode == "eventually" and value:
            self.decide(True, t_ns, "true", f"eventually {s.expr}", f"true at t={t_ns / 1e9:.3f} s")

    def finish(self, span: Span) -> None:
        s: MessageCheck = self.spec
        seen = self.extra.get("seen", False)
        bound = f"{s.mode} {s.expr}"
        nothing = f"no message on {s.topic} in the window"
        if s.mode != "eventually":
            self.hold(span, "held" if seen else "no message", bound, data=seen, nothing=nothing)
            return
        why = self.unseen(span)
        if why is None and not seen:
            why = nothing
        if why is not None:
            self.undecided(span, "never true" if seen else "no message", bound, why)
        else:
            self.decide(False, span.end_ns, "never true", bound, f"`{s.expr}` never held")


class _Peak(_Check):
    """A bound on a quantity of the robot's ground truth (speed, tilt): fails the moment it is exceeded,
    passes if it never was over a whole window that carried poses."""

    unit = ""
    exceeded = ""

    def measure(self, msg: Any) -> float:  # overridden
        raise NotImplementedError

    def feed(self, t_ns: int, msg: Any) -> None:
        if self.decided or not self.in_window(t_ns):
            return
        value = self.measure(msg)
        self.extra["peak"] = max(self.extra.get("peak", 0.0), value)
        bound = self.spec.max
        if value > bound:
            self.decide(False, t_ns, f"{value:.3f} {self.unit}", f"<= {bound:g} {self.unit}", self.exceeded)

    def finish(self, span: Span) -> None:
        peak = self.extra.get("peak")
        self.hold(
            span,
            f"peak {peak or 0.0:.3f} {self.unit}",
            f"<= {self.spec.max:g} {self.unit}",
            data=peak is not None,
            nothing="no pose in the window",
        )


class _MaxSpeed(_Peak):
    unit, exceeded = "m/s", "too fast"

    def measure(self, msg: Any) -> float:
        v = msg.twist.twist.linear
        return math.hypot(float(v.x), float(v.y))


class _MaxTilt(_Peak):
    unit, exceeded = "rad", "tilted too far"

    def measure(self, msg: Any) -> float:
        q = msg.pose.pose.orientation
        # angle between the body's z axis and the world's: cos = 1 - 2 (x² + y²)
        return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (float(q.x) ** 2 + float(q.y) ** 2))))


class _Distance(_Check):
    def feed(self, t_ns: int, msg: Any) -> None:
        if not self.in_window(t_ns):
            return
        x, y = _xy(msg)
        last = self.extra.get("last")
        if last is not None:
            self.extra["d"] = self.extra.get("d", 0.0) + math.hypot(x - last[0], y - last[1])
        self.extra["last"] = (x, y)
        s: DistanceTraveled = self.spec
        if s.max is not None and self.extra.get("d", 0.0) > s.max:  # a path only grows: decided now
            self.decide(False, t_ns, f"{self.extra['d']:.3f} m", self._bound(), "path length out of bounds")

    def _bound(self) -> str:
        s: DistanceTraveled = self.spec
        lo = s.min if s.min is not None else 0.0
        return f"{lo:g}..{s.max:g} m" if s.max is not None else f">= {lo:g} m"

    def finish(self, span: Span) -> None:
        s: DistanceTraveled = self.spec
        d = self.extra.get("d", 0.0)
        value = f"{d:.3f} m"
        why = self.unseen(span)
        if why is None and "last" not in self.extra:
            why = "no pose in the window"
        if why is not None:
            self.undecided(span, value, self._bound(), why)
            return
        lo = s.min if s.min is not None else 0.0
        ok = d >= lo
        self.decide(
            ok,
            None if ok else span.end_ns,
            value,
            self._bound(),
            "held" if ok else "path length out of bounds",
        )


_CHECKS: dict[type, type[_Check]] = {
    Reach: _Reach,
    StayWithin: _StayWithin,
    NoCollision: _NoCollision,
    TopicRate: _TopicRate,
    MessageCheck: _Message,
    MaxSpeed: _MaxSpeed,
    MaxTilt: _MaxTilt,
    DistanceTraveled: _Distance,
}


@dataclass(frozen=True)
class _EventSpec:
    name: str
    type: str = "event"


class Judge:
    """Decides assertions from messages. `specs` are the scenario's assertion models; `keys[i]` is the
    Zenoh key the i-th one reads (from `assertion_keys`)."""

    def __init__(self, specs: list[Any], keys: list[str], events: Sequence[str] = ()):
        """`events`: the keys where worlds say what their events did (`events_key`): each firing is kept
        (`fired`), and one that ends the run (`end:`) is a result of its own, passed or failed."""
        from runner.checks.expr import compile_expr

        self.events_keys = set(events)
        self.fired: list[dict[str, Any]] = []

        self.checks: list[_Check] = []
        for spec, key in zip(specs, keys, strict=True):
            check = _CHECKS[type(spec)](spec, key)
            if isinstance(spec, MessageCheck):
                check.extra["expr"] = compile_expr(spec.expr)
            self.checks.append(check)
        self._by_key: dict[str, list[_Check]] = {}
        for c in self.checks:
            self._by_key.setdefault(c.key, []).append(c)

        # where the data stops before the run's end: key (None: every key) -> (sim ns, why)
        self.cuts: dict[str | None, tuple[int, str]] = {}

    @property
    def keys(self) -> set[str]:
        return set(self._by_key) | self.events_keys

    def data_stops(self, t_ns: int, why: str, keys: Iterable[str] | None = None) -> None:
        """The data of `keys` (None: of every key) stops at sim time `t_ns`, before the run's end, for
        `why` ("the recording stops at t=12.300 s: No space left on device"): the recording could not be
        written, it was cut, or the judge's feed lost messages. Then `finish` decides nothing that needs
        time after `t_ns`: a verdict reached before it stands, the rest is not decided, saying `why`.
        The earliest cut of a key is kept."""
        for key in [None] if keys is None else keys:
            if key not in self.cuts or t_ns < self.cuts[key][0]:
                self.cuts[key] = (t_ns, why)

    def _cut(self, key: str) -> tuple[int, str] | None:
        mine, every = self.cuts.get(key), self.cuts.get(None)
        if mine is None or (every is not None and every[0] <= mine[0]):
            return every
        return mine

    def feed(self, key: str, t_ns: int, msg: Any) -> None:
        if key in self.events_keys:
            self._event(t_ns, msg)
            return
        for c in self._by_key.get(key, ()):
            if not c.decided:  # topic_rate is decided only by finish()
                c.feed(t_ns, msg)

    def _event(self, t_ns: int, msg: Any) -> None:
        import json

        try:
            entry = json.loads(msg.data)
        except ValueError:
            return  # (not one of ours: someone else published there)
        if not isinstance(entry, dict) or "event" not in entry:
            return
        entry["t_ns"] = t_ns
        self.fired.append(entry)
        end = entry.get("end")
        if isinstance(end, dict):
            passed = end.get("result") == "pass"
            said = end.get("message") or ("the run ends here" if passed else "the run fails here")
            check = _Check(_EventSpec(f"event {entry['event']}"), key="")
            check.result = Result(
                check.spec.name,
                "event",
                PASS if passed else FAIL,
                t_ns,
                str(entry.get("why", "")),
                "end",
                said,
            )
            self.checks.append(check)

    def failed(self) -> bool:
        return any(c.result is not None and not c.result.passed for c in self.checks)

    def all_decided(self) -> bool:
        return all(c.decided for c in self.checks)

    def finish(self, end_ns: int, *, complete: bool = True, why: str = "") -> list[Result]:
        """Decide what is left, at the run's end: sim time `end_ns`, reached as planned (`complete`) or
        not (`why`, e.g. "the run was interrupted at t=6.800 s"). A check whose window the run did not
        show whole is not decided (UNDECIDED), never passed or failed by default; one whose data stops
        earlier (`data_stops`) is judged on the run up to there, with that reason."""
        span = Span(end_ns, complete, why)
        for c in self.checks:
            if not c.decided:
                cut = self._cut(c.key)
                if cut is None or cut[0] >= end_ns:
                    c.finish(span)
                    continue
                # its data stops before the run's end: it saw the run up to there only (data_stops), and
                # how the run ended (interrupted, stopped by an error) is said too
                c.finish(Span(cut[0], False, cut[1] + (f" ({why})" if why and not complete else "")))
        return [c.result for c in self.checks if c.result is not None]
