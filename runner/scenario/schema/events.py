"""What happens in a scenario besides physics: actors (world models that move on their own, kinematically)
and events (`events: [{name, when, do}]`: a trigger, and what to do when it fires), with the named regions
they share with assertions (`regions:`)."""

from __future__ import annotations

import itertools
from typing import Annotated, Any, Literal

from pydantic import Field, NonNegativeFloat, PositiveFloat, field_validator, model_validator

from runner.scenario.schema.assertions import Region
from runner.scenario.schema.base import IDENT_RE, TOPIC_RE, Namespace, Pose, Rgba, Strict, Vec3

EventName = Annotated[str, Field(pattern=IDENT_RE.pattern, description="Letters, digits and '_'.")]
Topic = Annotated[str, Field(pattern=TOPIC_RE.pattern, description="A topic of the run, e.g. `r1/scan`.")]

PERSON_RADIUS = 0.25  # m: a standing person, about 0.5 m wide
PERSON_HEIGHT = 1.75  # m


def _exactly_one(model: Strict, kinds: tuple[str, ...], what: str) -> None:
    given = [k for k in kinds if getattr(model, k) is not None]
    if len(given) != 1:
        listed = ", ".join(f"`{k}`" for k in kinds)
        found = f"found {', '.join(given)}" if given else "found none"
        raise ValueError(f"{what} has exactly one of {listed} ({found})")


# ------------------------------------------------------------------------------------------------ actors
class Waypoint(Strict):
    """A point of an actor's path; `t` (sim seconds after the actor starts) or the actor's `speed`."""

    xyz: list[float] = Field(
        description="Where the actor's origin passes, world frame, metres: [x, y] (z: the pose's) or "
        "[x, y, z]."
    )
    t: NonNegativeFloat | None = Field(None, description="When it is there, seconds after the actor starts.")

    @field_validator("xyz")
    @classmethod
    def _xyz(cls, v: list[float]) -> list[float]:
        if len(v) not in (2, 3):
            raise ValueError(f"a waypoint is [x, y] or [x, y, z], found {len(v)} numbers")
        return v


class Hinge(Strict):
    """A joint-driven model: the actor turns about a hinge line, from its `pose` (closed) by `angle`, over
    `duration` seconds once started (a door that opens)."""

    at: Vec3 = Field((0.0, 0.0, 0.0), description="A point of the hinge line, in the model's frame.")
    axis: Vec3 = Field((0.0, 0.0, 1.0), description="Direction of the hinge line, in the model's frame.")
    angle: float = Field(1.5708, ge=-6.3, le=6.3, description="How far it turns, radians (sign: the side).")
    duration: PositiveFloat = Field(2.0, description="Seconds from closed to open.")


class Actor(Strict):
    """A world model that moves on its own, kinematically (a MuJoCo mocap body): it follows its path
    whatever is in the way, pushes robots, and is seen by lidars and cameras."""

    name: Namespace = Field(description="Unique name (its body and frame are named after it).")
    shape: Literal["person", "box", "cylinder", "sphere", "capsule", "mesh"] = Field(
        "person",
        description="`person`: a standing capsule 1.75 m tall, 0.5 m wide, its origin at its feet; the "
        "others as world models (origin at the centre); `mesh`: the `mesh` file.",
    )
    size: list[PositiveFloat] | None = Field(
        None,
        description="box: [x, y, z]; cylinder and capsule: [radius, length]; sphere: [radius]; person: "
        "[radius, height] (default [0.25, 1.75]).",
    )
    mesh: str | None = Field(None, description="A mesh file (STL/OBJ), relative to the scenario's folder.")
    scale: Vec3 = Field((1.0, 1.0, 1.0), description="Scale of the mesh.")
    rgba: Rgba = Field((0.85, 0.45, 0.2, 1.0), description="Colour.")
    pose: Pose | None = Field(
        None, description="Where it stands before it starts (default: its first waypoint)."
    )
    waypoints: list[Waypoint | Annotated[list[float], Field(min_length=2, max_length=3)]] = Field(
        default_factory=list,
        description="Its path: points `[x, y]`, `[x, y, z]` or `{xyz, t}` (z defaults to the pose's).",
    )
    speed: PositiveFloat = Field(1.0, description="m/s along waypoints that have no `t`.")
    loop: bool = Field(False, description="Walk the path again and again (back to its first point).")
    heading: Literal["fixed", "travel"] = Field(
        "fixed", description="`travel`: it turns to face where it goes (yaw), plus its pose's yaw."
    )
    start: NonNegativeFloat | Literal["event"] = Field(
        0.0, description="When it starts moving, sim seconds; `event`: when an event says `start: NAME`."
    )
    hinge: Hinge | None = Field(None, description="Turn about a hinge instead of following waypoints.")

    @field_validator("waypoints", mode="before")
    @classmethod
    def _points(cls, v: Any) -> Any:
        if not isinstance(v, list):
            return v
        return [{"xyz": p} if isinstance(p, list | tuple) else p for p in v]  # `[x, y]`: a point

    @property
    def path(self) -> list[Waypoint]:
        """The waypoints, each a `Waypoint` (a `[x, y]` given in the file became one on validation)."""
        return [w if isinstance(w, Waypoint) else Waypoint(xyz=w) for w in self.waypoints]

    @model_validator(mode="after")
    def _shape(self) -> Actor:
        need = {"box": 3, "cylinder": 2, "capsule": 2, "sphere": 1, "person": 2}.get(self.shape)
        if need is not None and self.size is not None and len(self.size) != need:
            raise ValueError(f"a {self.shape} actor's size has {need} number(s), found {len(self.size)}")
        if self.shape not in ("person", "mesh") and self.size is None:
            raise ValueError(f"a {self.shape} actor needs `size`")
        if (self.shape == "mesh") != (self.mesh is not None):
            raise ValueError("`mesh:` goes with `shape: mesh`, and `shape: mesh` needs `mesh:`")
        if self.hinge is not None and self.waypoints:
            raise ValueError("an actor turns about a `hinge` or follows `waypoints`, not both")
        if self.pose is None and not self.waypoints:
            raise ValueError("an actor needs a `pose` or `waypoints`")
        timed = [w.t is not None for w in self.path]
        if any(timed) and not all(timed):
            raise ValueError("give `t` on every waypoint or on none (then `speed` sets the times)")
        times = [w.t for w in self.path if w.t is not None]
        if any(b <= a for a, b in itertools.pairwise(times)):
            raise ValueError(f"waypoint times must increase, found {times}")
        return self


# ------------------------------------------------------------------------------------------------ when
RegionRef = str | Region


class Place(Strict):
    body: str = Field(description="A robot, actor or world model.")
    region: RegionRef = Field(description="A region of `regions:` by name, or one given here.")


class Near(Strict):
    body: str = Field(description="A robot, actor or world model.")
    to: str | list[float] = Field(description="A point [x, y] or another body's name.")
    within: PositiveFloat = Field(description="Distance on the ground plane, metres.")

    @field_validator("to")
    @classmethod
    def _point(cls, v: str | list[float]) -> str | list[float]:
        if isinstance(v, list) and len(v) not in (2, 3):
            raise ValueError(f"a point is [x, y] (or [x, y, z]), found {len(v)} numbers")
        return v


class OnMessage(Strict):
    topic: Topic
    expr: str = Field(description="An expression over the message's fields, e.g. `min(ranges) < 0.5`.")


class After(Strict):
    event: EventName = Field(description="The event whose firing this follows.")
    delay: NonNegativeFloat = Field(0.0, description="Seconds after it; 0: in the same step, after it.")


class OnAssertion(Strict):
    assertion: str = Field(description="The name of an assertion of this scenario.")
    becomes: Literal["fail", "pass"] = Field("fail", description="The state it changes to.")


class When(Strict):
    """The trigger: exactly one kind."""

    at: NonNegativeFloat | None = Field(None, description="A sim time, seconds.")
    enter: Place | None = Field(None, description="A body comes into a region.")
    leave: Place | None = Field(None, description="A body goes out of a region.")
    near: Near | None = Field(None, description="A body comes within a distance of a point or body.")
    message: OnMessage | None = Field(None, description="A message on a topic for which `expr` holds.")
    after: After | None = Field(None, description="Another event fired (with an optional delay).")
    assertion: OnAssertion | None = Field(None, description="An assertion is decided (fail or pass).")

    @field_validator("after", mode="before")
    @classmethod
    def _after(cls, v: Any) -> Any:
        return {"event": v} if isinstance(v, str) else v  # `after: other_event`

    @model_validator(mode="after")
    def _one(self) -> When:
        _exactly_one(self, TRIGGERS, "a trigger")
        return self

    @property
    def kind(self) -> str:
        return next(k for k in TRIGGERS if getattr(self, k) is not None)


TRIGGERS = ("at", "enter", "leave", "near", "message", "after", "assertion")


# ------------------------------------------------------------------------------------------------ do
class Publish(Strict):
    topic: Topic
    type: str = Field(description="ROS 2 message type, e.g. geometry_msgs/msg/Twist.")
    data: dict[str, Any] = Field(default_factory=dict, description="Message fields.")


class Call(Strict):
    service: Topic = Field(
        description="A service of the world, e.g. `/reset_simulation`, `/world/<world>/control` "
        "(`scenario validate` lists them). Called once per run: a reset does not make the call again."
    )
    data: dict[str, Any] = Field(default_factory=dict, description="The request's fields.")


class Teleport(Strict):
    body: str = Field(description="A robot, actor or free world model.")
    pose: Pose = Field(description="Where it is put (its velocity is zeroed).")


class Push(Strict):
    body: str = Field(description="A robot or free world model.")
    force: Vec3 = Field((0.0, 0.0, 0.0), description="Newtons, world frame, at its centre of mass.")
    torque: Vec3 = Field((0.0, 0.0, 0.0), description="N·m, world frame.")
    duration: PositiveFloat = Field(0.1, description="Seconds the force lasts.")


class Impulse(Strict):
    body: str = Field(description="A robot or free world model.")
    linear: Vec3 = Field(description="N·s, world frame: its velocity changes by this over its mass.")


class SetParam(Strict):
    robot: str = Field(description="The robot.")
    plugin: str = Field(description="The plugin's name (as `scenario validate` lists it).")
    param: str = Field(description="`rate`, or a parameter the plugin lets change while it runs.")
    value: Any = Field(description="The new value.")


class Fault(Strict):
    """A fault on a topic the world publishes: every message while it lasts is dropped, delayed, frozen
    (the last one before it, again) or corrupted with noise."""

    topic: Topic
    drop: float | bool | None = Field(
        None, description="Drop messages: `true` (all) or a probability in (0, 1]."
    )
    delay: PositiveFloat | None = Field(None, description="Deliver each message this many seconds late.")
    freeze: bool = Field(False, description="Send the last message before the fault again, instead.")
    noise: PositiveFloat | None = Field(None, description="Gaussian noise (stddev) on number fields.")
    fields: list[str] | None = Field(
        None, description="The fields `noise` corrupts (default: every number but the header's)."
    )
    duration: PositiveFloat | None = Field(None, description="Seconds it lasts (default: to the end).")

    @field_validator("drop")
    @classmethod
    def _drop(cls, v: float | bool | None) -> float | bool | None:
        if v is False or (not isinstance(v, bool) and v is not None and not 0 < v <= 1):
            raise ValueError("drop is `true` or a probability in (0, 1]")
        return v

    @model_validator(mode="after")
    def _some(self) -> Fault:
        kinds = [self.drop is not None, self.delay is not None, self.freeze, self.noise is not None]
        if sum(kinds) != 1:
            raise ValueError("a fault is one of `drop`, `delay`, `freeze: true`, `noise` (one per fault)")
        if self.fields is not None and self.noise is None:
            raise ValueError("`fields` goes with `noise`")
        return self


class JointRef(Strict):
    robot: str = Field(description="The robot.")
    joint: str = Field(description="A joint of its description (e.g. its left wheel's).")


class End(Strict):
    result: Literal["pass", "fail"] = Field(description="How the run is judged for this event.")
    message: str = Field("", description="Said in the results.")


class Action(Strict):
    """What an event does: exactly one kind per entry of `do:`."""

    publish: Publish | None = Field(None, description="Publish a message.")
    start: str | None = Field(None, description="Start (or resume) an actor.")
    stop: str | None = Field(None, description="Stop an actor where it is.")
    teleport: Teleport | None = Field(None, description="Put a body at a pose.")
    push: Push | None = Field(None, description="Apply a force for a while.")
    impulse: Impulse | None = Field(None, description="Change a body's velocity at once.")
    set: SetParam | None = Field(None, description="Change a plugin parameter while it runs.")
    fault: Fault | None = Field(None, description="Inject a fault on a topic.")
    block: JointRef | None = Field(None, description="Block a joint (a jammed wheel).")
    cut: JointRef | None = Field(None, description="Cut the motor of a joint (it turns freely).")
    end: End | None = Field(None, description="End the run here, judged pass or fail.")
    call: Call | None = Field(None, description="Call a service of the world (pause, reset...).")

    @model_validator(mode="after")
    def _one(self) -> Action:
        _exactly_one(self, ACTIONS, "an action")
        return self

    @property
    def kind(self) -> str:
        return next(k for k in ACTIONS if getattr(self, k) is not None)


ACTIONS = (
    "publish",
    "start",
    "stop",
    "teleport",
    "push",
    "impulse",
    "set",
    "fault",
    "block",
    "cut",
    "end",
    "call",
)


class Event(Strict):
    """When something happens (`when`), do things (`do`), at an exact step, once unless `repeat`."""

    name: EventName
    when: When = Field(
        description="The trigger: `at`, `enter`, `leave`, `near`, `message`, `after` or `assertion`."
    )
    do: list[Action] = Field(min_length=1, description="What it does, in order.")
    repeat: bool = Field(
        False,
        description="Fire again each time the trigger holds anew (a body re-enters, a message matches "
        "again, the event followed fires again); otherwise once.",
    )
