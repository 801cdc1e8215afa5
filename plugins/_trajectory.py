"""The trajectory math of ros2_controllers' joint_trajectory_controller (Jazzy `trajectory.cpp`): a
JointTrajectory's points in the controller's joint order, sampled at a time with the spline whose degree the
points' fields give (positions only: linear; with velocities: cubic; with accelerations too: quintic), the
segment before the first point starting from the state the controller was in when the trajectory began.

Pure numpy, no physics: plugins/joint_trajectory_controller.py samples it every control update.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, NonNegativeFloat

Vec = np.ndarray


@dataclass
class Point:
    """A JointTrajectoryPoint in the controller's joint order; a field the message left empty is None."""

    t: float  # time_from_start, s
    positions: Vec | None = None
    velocities: Vec | None = None
    accelerations: Vec | None = None
    effort: Vec | None = None


@dataclass
class Sample:
    """The state a trajectory gives at a time: `segment` is the index of the point the sample heads for
    (0 before the first point), `len(points)` once the whole trajectory has played out."""

    positions: Vec
    velocities: Vec
    accelerations: Vec
    effort: Vec
    segment: int


def interpolate(t_a: float, a: Point, t_b: float, b: Point, t: float) -> tuple[Vec, Vec, Vec, Vec]:
    """Positions, velocities, accelerations, effort between two points at time t, as
    trajectory.cpp:interpolate_between_points (Jazzy, lines 256-400): linear in position when either point
    lacks velocities, cubic Hermite with velocities, quintic with velocities and accelerations; a time
    outside [t_a, t_b] is clamped to it and then interpolated linearly (no extrapolation). Effort linear."""
    assert a.positions is not None and b.positions is not None
    p0, p1 = a.positions, b.positions
    n = len(p0)
    T = t_b - t_a
    s = t - t_a
    has_vel = a.velocities is not None and b.velocities is not None
    has_acc = a.accelerations is not None and b.accelerations is not None
    if s < 0.0:
        s, has_vel, has_acc = 0.0, False, False
    if s > T:
        s, has_vel, has_acc = T, False, False
    zero = np.zeros(n)
    effort = zero.copy()
    if a.effort is not None and b.effort is not None:
        effort = a.effort + ((b.effort - a.effort) / T if T != 0.0 else zero) * s
    if has_vel and has_acc:
        assert a.velocities is not None and b.velocities is not None
        assert a.accelerations is not None and b.accelerations is not None
        v0, v1, a0, a1 = a.velocities, b.velocities, a.accelerations, b.accelerations
        c0, c1, c2 = p0, v0, 0.5 * a0
        if T != 0.0:
            c3 = (20 * (p1 - p0) - (8 * v1 + 12 * v0) * T - (3 * a0 - a1) * T**2) / (2 * T**3)
            c4 = (30 * (p0 - p1) + (14 * v1 + 16 * v0) * T + (3 * a0 - 2 * a1) * T**2) / (2 * T**4)
            c5 = (12 * (p1 - p0) - (6 * v1 + 6 * v0) * T - (a0 - a1) * T**2) / (2 * T**5)
        else:
            c3 = c4 = c5 = zero
        pos = c0 + c1 * s + c2 * s**2 + c3 * s**3 + c4 * s**4 + c5 * s**5
        vel = c1 + 2 * c2 * s + 3 * c3 * s**2 + 4 * c4 * s**3 + 5 * c5 * s**4
        acc = 2 * c2 + 6 * c3 * s + 12 * c4 * s**2 + 20 * c5 * s**3
        return pos, vel, acc, effort
    if has_vel:
        assert a.velocities is not None and b.velocities is not None
        v0, v1 = a.velocities, b.velocities
        if T != 0.0:
            c2 = (3 * (p1 - p0) - (2 * v0 + v1) * T) / T**2
            c3 = (2 * (p0 - p1) + (v0 + v1) * T) / T**3
        else:
            c2 = c3 = zero
        pos = p0 + v0 * s + c2 * s**2 + c3 * s**3
        vel = v0 + 2 * c2 * s + 3 * c3 * s**2
        acc = 2 * c2 + 6 * c3 * s
        return pos, vel, acc, effort
    slope = (p1 - p0) / T if T != 0.0 else zero
    return p0 + slope * s, slope.copy(), zero.copy(), effort


def deduce(a: Point, b: Point, dt: float) -> None:
    """Fill b's missing positions (and velocities) by integrating a's derivatives over dt, as
    trajectory.cpp:deduce_from_derivatives (`allow_integration_in_goal_trajectories`)."""
    n = len(a.positions) if a.positions is not None else 0
    if b.positions is not None or a.positions is None:
        return
    a_vel = a.velocities if a.velocities is not None else np.zeros(n)
    if b.velocities is None:
        a_acc = a.accelerations if a.accelerations is not None else np.zeros(n)
        b_acc = b.accelerations if b.accelerations is not None else np.zeros(n)
        b.velocities = a_vel + (a_acc + b_acc) * 0.5 * dt
    b.positions = a.positions + (a_vel + b.velocities) * 0.5 * dt


@dataclass
class Trajectory:
    """A trajectory being run: its points (controller joint order), the start time (s; None = the time it
    is first sampled, as a header stamp of 0 means "now"), and the state it starts from."""

    points: list[Point]
    start: float | None = None
    before_time: float = 0.0
    before: Point = field(default_factory=lambda: Point(0.0))
    sampled: bool = False

    def set_before(self, time: float, state: Point) -> None:
        """The state before the trajectory (trajectory.cpp:set_point_before_trajectory_msg): velocities and
        accelerations set to zero where the state has none but the first point does, so the first
        segment uses the spline degree of the rest."""
        first = self.points[0]
        n = len(state.positions) if state.positions is not None else 0
        self.before_time = time
        self.before = Point(
            0.0,
            None if state.positions is None else state.positions.copy(),
            state.velocities.copy()
            if state.velocities is not None
            else (np.zeros(n) if first.velocities is not None else None),
            state.accelerations.copy()
            if state.accelerations is not None
            else (np.zeros(n) if first.accelerations is not None else None),
        )

    @property
    def end_time(self) -> float:
        return (self.start or 0.0) + self.points[-1].t

    def sample(self, time: float, interpolate_splines: bool = True) -> Sample | None:
        """The state at `time` (trajectory.cpp:Trajectory::sample): None before the state-before time.
        Before the first point: from the state before to the first point; between points: their spline;
        after the last: the last point (missing velocities/accelerations zero)."""
        if not self.points:
            return None
        if not self.sampled:
            if not self.start:
                self.start = time
            self.sampled = True
        if time < self.before_time:
            return None
        start = self.start or 0.0
        first = self.points[0]
        t_first = start + first.t
        if time < t_first:
            if not interpolate_splines:
                b = self.before
                assert b.positions is not None
                n = len(b.positions)
                return Sample(
                    b.positions.copy(), _or0(b.velocities, n), _or0(b.accelerations, n), np.zeros(n), 0
                )
            deduce(self.before, first, t_first - self.before_time)
            p, v, a, e = interpolate(self.before_time, self.before, t_first, first, time)
            return Sample(p, v, a, e, 0)
        for i in range(len(self.points) - 1):
            pa, pb = self.points[i], self.points[i + 1]
            t0, t1 = start + pa.t, start + pb.t
            if t0 <= time < t1:
                if not interpolate_splines:
                    # no interpolation: the next waypoint is forwarded as it is
                    assert pb.positions is not None
                    n = len(pb.positions)
                    return Sample(
                        pb.positions.copy(),
                        _or0(pb.velocities, n),
                        _or0(pb.accelerations, n),
                        _or0(pb.effort, n),
                        i + 1,
                    )
                deduce(pa, pb, t1 - t0)
                p, v, a, e = interpolate(t0, pa, t1, pb, time)
                return Sample(p, v, a, e, i + 1)
        last = self.points[-1]
        if last.positions is None and len(self.points) > 1:
            prev = self.points[-2]
            deduce(prev, last, last.t - prev.t)
        if last.positions is None:
            return None
        n = len(last.positions)
        return Sample(
            last.positions.copy(),
            _or0(last.velocities, n),
            _or0(last.accelerations, n),
            _or0(last.effort, n),
            len(self.points),
        )


def _or0(values: Vec | None, n: int) -> Vec:
    return np.zeros(n) if values is None else values.copy()


def seconds(t: Any) -> float:
    """A builtin_interfaces Time / Duration in seconds."""
    return float(t.sec) + float(t.nanosec) * 1e-9


def validate_message(
    msg: Any,
    joints: list[str],
    now: float,
    *,
    partial: bool,
    nonzero_end: bool,
    integration: bool,
    effort: bool,
) -> str | None:
    """joint_trajectory_controller.cpp:validate_trajectory_msg (Jazzy lines 1671-1816): None, or why a
    trajectory_msgs/JointTrajectory is refused, in the controller's words."""
    names = list(msg.joint_names)
    if not partial and len(names) != len(joints):
        return "Joints on incoming trajectory don't match the controller joints."
    if not names:
        return "Empty joint names on incoming trajectory."
    if not msg.points:
        return "Empty trajectory received."
    for jn in names:
        if jn not in joints:
            return f"Incoming joint {jn} doesn't match the controller's joints."
    if not nonzero_end:
        for i, v in enumerate(msg.points[-1].velocities):
            if abs(float(v)) > 1.1920929e-07:
                return f"Velocity of last trajectory point of joint {names[i]} is not zero: {float(v):.15f}"
    start = seconds(msg.header.stamp)
    if start != 0.0:
        end = start + seconds(msg.points[-1].time_from_start)
        if end < now:
            return f"Received trajectory with non-zero start time ({start:f}) that ends in the past ({end:f})"
    previous = 0.0
    n = len(names)
    for i, pt in enumerate(msg.points):
        t = seconds(pt.time_from_start)
        if i > 0 and t <= previous:
            return (
                f"Time between points {i - 1} and {i} is not strictly increasing, it is {previous:f} "
                f"and {t:f} respectively"
            )
        previous = t
        fields = (
            ("positions", pt.positions),
            ("velocities", pt.velocities),
            ("accelerations", pt.accelerations),
        )
        if integration:
            if all(len(v) == 0 for _, v in fields):
                return "The given trajectory has no position, velocity, or acceleration points."
            allow_empty = {"positions", "velocities", "accelerations"}
        else:
            allow_empty = {"velocities", "accelerations"}
        for label, values in fields:
            if len(values) == 0 and label in allow_empty:
                continue
            if len(values) != n:
                return f"Mismatch between joint_names size ({n}) and {label} ({len(values)}) at point #{i}."
        if not effort and len(pt.effort) > 0:
            return (
                "Trajectories with effort fields are only supported for controllers using the 'effort' "
                "command interface."
            )
    return None


@dataclass
class Tol:
    """tolerances.hpp:StateTolerances: 0 is not checked."""

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass
class Tolerances:
    """tolerances.hpp:SegmentTolerances."""

    state: list[Tol]
    goal: list[Tol]
    goal_time: float


def within(err: Point, k: int, tol: Tol) -> bool:
    """tolerances.hpp:check_state_tolerance_per_joint: a tolerance of 0 is not checked."""
    assert err.positions is not None and err.velocities is not None
    ok_p = not (tol.position > 0.0 and abs(err.positions[k]) > tol.position)
    ok_v = not (tol.velocity > 0.0 and abs(err.velocities[k]) > tol.velocity)
    return ok_p and ok_v


def copy_point(p: Point) -> Point:
    return Point(
        p.t, *(None if v is None else v.copy() for v in (p.positions, p.velocities, p.accelerations))
    )


def resolve_tolerance(default: float, value: float) -> float:
    """tolerances.hpp:resolve_tolerance_source: >0 the goal's, -1 erased (0), 0 the default."""
    if value > 0.0:
        return value
    if abs(value + 1.0) < 1.2e-7:
        return 0.0
    if value < 0.0:
        raise ValueError("Illegal tolerance value.")
    return default


def goal_tolerances(
    base: Tolerances, joints: list[str], path: list[Any], goal: list[Any], goal_time: float
) -> Tolerances:
    """tolerances.hpp:get_segment_tolerances from an action goal (control_msgs/JointTolerance entries);
    raises ValueError for an unknown joint or an illegal value (the controller then uses `base`)."""
    out = Tolerances(
        [Tol(t.position, t.velocity, t.acceleration) for t in base.state],
        [Tol(t.position, t.velocity, t.acceleration) for t in base.goal],
        resolve_tolerance(base.goal_time, goal_time),
    )
    for given, into, defaults in ((path, out.state, base.state), (goal, out.goal, base.goal)):
        for tol in given:
            if tol.name not in joints:
                raise ValueError(f"joint {tol.name!r} in the goal's tolerances does not exist")
            k = joints.index(tol.name)
            into[k] = Tol(
                resolve_tolerance(defaults[k].position, float(tol.position)),
                resolve_tolerance(defaults[k].velocity, float(tol.velocity)),
                resolve_tolerance(defaults[k].acceleration, float(tol.acceleration)),
            )
    return out


# The controller's `constraints` and `gains` parameters (joint_trajectory_controller_parameters.yaml)
class JointConstraint(BaseModel):
    model_config = ConfigDict(extra="forbid")
    trajectory: NonNegativeFloat = Field(0.0, description="Path tolerance, rad or m (0: not checked).")
    goal: NonNegativeFloat = Field(0.0, description="Goal tolerance, rad or m (0: not checked).")


class Constraints(BaseModel):
    """`constraints`: two numbers and, per joint, `<joint>: {trajectory, goal}` (as the controller's
    parameters file writes them)."""

    model_config = ConfigDict(extra="allow")
    __pydantic_extra__: dict[str, JointConstraint] = Field(init=False)
    stopped_velocity_tolerance: NonNegativeFloat = Field(
        0.01, description="Velocity below which a joint at the goal counts as stopped."
    )
    goal_time: NonNegativeFloat = Field(
        0.0, description="Time after the last point allowed to reach the goal tolerance (0: no limit)."
    )

    def joint(self, name: str) -> JointConstraint:
        extra = self.__pydantic_extra__ or {}
        return extra.get(name) or JointConstraint()


class Gains(BaseModel):
    """`gains.<joint>`: the PID of a velocity- or effort-commanded joint (control_toolbox::Pid)."""

    model_config = ConfigDict(extra="forbid")
    p: float = Field(0.0, description="Proportional gain.")
    i: float = Field(0.0, description="Integral gain.")
    d: float = Field(0.0, description="Derivative gain.")
    i_clamp: float | None = Field(None, description="Integral limit (Humble); sets both i_clamp_max/min.")
    i_clamp_max: float | None = Field(None, description="Integral term's upper limit (default: none).")
    i_clamp_min: float | None = Field(None, description="Integral term's lower limit (default: none).")
    ff_velocity_scale: float = Field(0.0, description="Feed-forward scale of the sampled velocity.")
    u_clamp_max: float | None = Field(None, description="Output's upper limit (default: none).")
    u_clamp_min: float | None = Field(None, description="Output's lower limit (default: none).")
