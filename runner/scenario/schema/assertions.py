"""The checks of a scenario (`assertions:`), judged live and from a recording: reach, stay_within,
no_collision, topic_rate, message, max_speed, max_tilt, distance_traveled; each (but reach) over a window
of sim time, and the regions they name."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field, NonNegativeFloat, PositiveFloat, field_validator, model_validator

from runner.scenario.schema.base import Strict

Vec2 = Annotated[tuple[float, float], Field(description="[x, y] in metres, world frame")]


class Region(Strict):
    """A region of the ground plane: a circle (`center` + `radius`) or a box (`min` + `max`)."""

    center: Vec2 | None = Field(None, description="Centre of a circular region.")
    radius: PositiveFloat | None = Field(None, description="Radius of a circular region, metres.")
    min: Vec2 | None = Field(None, description="Lower corner [x, y] of a box region.")
    max: Vec2 | None = Field(None, description="Upper corner [x, y] of a box region.")

    @field_validator("max")
    @classmethod
    def _box(cls, v: tuple[float, float] | None, info: Any) -> tuple[float, float] | None:
        lo = info.data.get("min")
        if v is not None and lo is not None and (v[0] <= lo[0] or v[1] <= lo[1]):
            raise ValueError(
                f"max {list(v)} must exceed min {list(lo)} on both axes: write the lower corner as min and "
                "the upper as max, e.g. {min: [0, 0], max: [1, 1]}"
            )
        return v

    @model_validator(mode="after")
    def _one_shape(self) -> Region:
        circle = self.center is not None or self.radius is not None
        box = self.min is not None or self.max is not None
        if circle and box:
            raise ValueError("a region is a circle (`center` + `radius`) or a box (`min` + `max`), not both")
        if circle and (self.center is None or self.radius is None):
            raise ValueError("a circular region needs both `center: [x, y]` and `radius:`")
        if box and (self.min is None or self.max is None):
            raise ValueError("a box region needs both `min: [x, y]` and `max: [x, y]`")
        if not (circle or box):
            raise ValueError("an empty region: give `center` + `radius`, or `min` + `max`")
        return self

    def contains(self, x: float, y: float) -> bool:
        if self.center is not None and self.radius is not None:
            return (x - self.center[0]) ** 2 + (y - self.center[1]) ** 2 <= self.radius**2
        if self.min is not None and self.max is not None:
            return self.min[0] <= x <= self.max[0] and self.min[1] <= y <= self.max[1]
        return False


class _AssertionBase(Strict):
    name: str = Field(description="Name of the check, as reported (JUnit testcase name).")


class _Window(Strict):
    after: NonNegativeFloat = Field(0.0, description="Start of the window, sim seconds.")
    until: NonNegativeFloat | None = Field(
        None, description="End of the window, sim seconds (default: the end)."
    )

    @field_validator("until")
    @classmethod
    def _after_until(cls, v: float | None, info: Any) -> float | None:
        start = info.data.get("after")
        if v is not None and start is not None and v < start:
            raise ValueError(
                f"the window ends (until: {v}) before it starts (after: {start}): "
                "write an `until:` later than `after:`"
            )
        return v


def _min_below_max(v: float | None, info: Any, unit: str) -> float | None:
    lo = info.data.get("min")
    if v is not None and lo is not None and v < lo:
        raise ValueError(f"max ({v} {unit}) is below min ({lo} {unit}): write a max above the min")
    return v


class Reach(_AssertionBase):
    """A robot's base comes within `tolerance` of `point` (or inside `region`) between sim times `after`
    and `by`; with `leave`, only once it has first gone that far from where it was at `after` (so "leave
    the start by 1 m, then come back within 0.3 m" is one assertion)."""

    type: Literal["reach"] = Field(description="Assertion kind.")
    robot: str = Field(description="Robot name.")
    point: Vec2 | None = Field(None, description="Goal point [x, y].")
    tolerance: PositiveFloat = Field(0.25, description="How close to `point` counts, metres.")
    region: Region | None = Field(None, description="Goal region, instead of a point.")
    after: NonNegativeFloat = Field(
        0.0, description="Sim seconds before which poses do not count (the start of the window)."
    )
    by: PositiveFloat | None = Field(
        None, description="Deadline in sim seconds (default: the end of the run)."
    )
    leave: PositiveFloat | None = Field(
        None,
        description="Reaching counts only after the robot has gone this far (metres) from where it was "
        "when the window opened.",
    )

    @model_validator(mode="after")
    def _goal(self) -> Reach:
        if (self.point is None) == (self.region is None):
            raise ValueError(
                "a reach assertion has either `point: [x, y]` or `region:`: write one of them, "
                "`point: [x, y]` (with `tolerance:`) or `region: {min: [x, y], max: [x, y]}`"
            )
        if self.by is not None and self.by <= self.after:
            raise ValueError(
                f"the deadline (by: {self.by:g}) is not after the window opens (after: {self.after:g}): "
                "write a `by:` later than `after:`"
            )
        return self


class StayWithin(_AssertionBase, _Window):
    """A robot stays inside `region` (or, with `inside: false`, out of it) during the window."""

    type: Literal["stay_within"] = Field(description="Assertion kind.")
    robot: str = Field(description="Robot name.")
    region: Region = Field(description="The region.")
    inside: bool = Field(True, description="Stay inside (true) or keep out (false).")


class NoCollision(_AssertionBase, _Window):
    """No contact between any two of the named robots and world models (from the physics' contacts)."""

    type: Literal["no_collision"] = Field(description="Assertion kind.")
    between: list[str] = Field(min_length=1, description="Robot and model names; `ground` is the ground.")
    others: bool = Field(
        False, description="Also fail on contact between a named body and any unnamed robot or model."
    )


class TopicRate(_AssertionBase, _Window):
    """A topic's rate in sim time stays within bounds after a warm-up (over the window)."""

    type: Literal["topic_rate"] = Field(description="Assertion kind.")
    topic: str = Field(description="Topic inside the run, e.g. `r1/scan`.")
    min: NonNegativeFloat | None = Field(None, description="Lowest acceptable rate, Hz.")
    max: PositiveFloat | None = Field(None, description="Highest acceptable rate, Hz.")
    after: NonNegativeFloat = Field(1.0, description="Warm-up in sim seconds before counting.")

    @field_validator("max")
    @classmethod
    def _range(cls, v: float | None, info: Any) -> float | None:
        return _min_below_max(v, info, "Hz")


class MessageCheck(_AssertionBase, _Window):
    """A predicate on message fields: `always`, `eventually` or `never` true during the window."""

    type: Literal["message"] = Field(description="Assertion kind.")
    topic: str = Field(description="Topic inside the run, e.g. `r1/scan`.")
    expr: str = Field(
        description="Predicate over the message's fields, e.g. `ranges.min() > 0.25`; comparisons, "
        "and/or/not, arithmetic, abs/len/min/max and .min() .max() .mean() .sum() .std()."
    )
    mode: Literal["always", "eventually", "never"] = Field("always", description="When it must hold.")


class MaxSpeed(_AssertionBase, _Window):
    type: Literal["max_speed"] = Field(
        description="Assertion kind: a robot's planar speed never exceeds `max`."
    )
    robot: str = Field(description="Robot name.")
    max: PositiveFloat = Field(description="Speed bound, m/s.")


class MaxTilt(_AssertionBase, _Window):
    type: Literal["max_tilt"] = Field(
        description="Assertion kind: a robot's base never tilts more than `max`."
    )
    robot: str = Field(description="Robot name.")
    max: PositiveFloat = Field(description="Tilt bound (angle from upright), radians.")


class DistanceTraveled(_AssertionBase, _Window):
    type: Literal["distance_traveled"] = Field(
        description="Assertion kind: the length of a robot's path over the window is within bounds."
    )
    robot: str = Field(description="Robot name.")
    min: NonNegativeFloat | None = Field(None, description="Shortest acceptable path, metres.")
    max: PositiveFloat | None = Field(None, description="Longest acceptable path, metres.")

    @field_validator("max")
    @classmethod
    def _range(cls, v: float | None, info: Any) -> float | None:
        return _min_below_max(v, info, "m")


Assertion = Annotated[
    Reach | StayWithin | NoCollision | TopicRate | MessageCheck | MaxSpeed | MaxTilt | DistanceTraveled,
    Field(discriminator="type"),
]
