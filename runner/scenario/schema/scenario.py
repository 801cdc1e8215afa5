"""The scenario file as a whole (`Scenario`): its name, duration, pacing and seed, and every section of
the format (world, robots, timeline, record, assertions, nodes, hosts, bridges...) from the modules beside
this one. `schemas/scenario.schema.json` is generated from it."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import ConfigDict, Field, PositiveFloat, field_validator

from runner.scenario.schema.assertions import Assertion, Region
from runner.scenario.schema.base import IDENT_RE, NODE_NAME_RE, Rate, RunName, Strict
from runner.scenario.schema.events import Event
from runner.scenario.schema.messages import Foxglove, QosRule, Record, TimelineEntry
from runner.scenario.schema.network import Bridge, Host, Node, Resources, Ros2, ZenohSettings
from runner.scenario.schema.robots import Robot
from runner.scenario.schema.world import NamedWorld, World

SCHEMA_VERSION = 1
MAX_DURATION = 2**31 - 1  # sim seconds: builtin_interfaces/Time counts seconds in an int32


class Scenario(Strict):
    """A robot-simulation scenario: a world, robots with plugins, a timeline, a recording."""

    model_config = ConfigDict(
        extra="forbid",
        allow_inf_nan=False,
        json_schema_extra={"$schema": "https://json-schema.org/draft/2020-12/schema"},
        title="Scenario",
    )

    version: Literal[1] = Field(1, description="Scenario format version.")
    name: RunName = Field(description="Run name: the first chunk of every key, e.g. `two_robots/r1/scan`.")
    description: str = Field("", description="Free text.")
    duration: PositiveFloat = Field(10.0, description="Sim seconds to run.")
    rate: Rate = "realtime"
    seed: int = Field(0, description="Seed of every random number (sensor noise...).")
    renderers: Literal["auto", "world", "process"] = Field(
        "auto",
        description="Where cameras render: `world` (in the physics process), `process` (a renderer process "
        "of its own, fed the world's state over Zenoh, rendering while physics goes on) or `auto` (a "
        "renderer process on a machine with more than two cores).",
    )
    packages: dict[str, str] = Field(
        default_factory=dict,
        description="ROS packages by name -> folder (relative to the scenario), for `$(find pkg)` and "
        "`package://pkg/...`. Folders with a package.xml beside the scenario are found without this.",
    )
    allow_paths: list[str] = Field(
        default_factory=list,
        description="Folders (relative to the scenario) that robot descriptions may also read from. By "
        "default a xacro file may include or load only files of the scenario's folder, of its own folder and "
        "of the packages (`packages:`, SCENARIO_PACKAGE_PATH).",
    )
    world: World = Field(default_factory=World, description="Physics, ground and primitive models.")
    worlds: list[NamedWorld] = Field(
        default_factory=list,
        description="Several worlds instead of one `world:`: each is simulated by a process of its own, in a "
        "key space of its own (`<run>/<world>/<ns>/...`); robots and nodes say which world they are in, and "
        "timeline and assertion topics start with the world's name (`arena/r1/cmd_vel`).",
    )
    robots: list[Robot] = Field(default_factory=list, description="Robots and their plugins.")
    timeline: list[TimelineEntry] = Field(
        default_factory=list, description="Messages to publish at sim times."
    )
    regions: dict[Annotated[str, Field(pattern=IDENT_RE.pattern)], Region] = Field(
        default_factory=dict, description="Named regions of the ground plane, for events (`enter`, `leave`)."
    )
    events: list[Event] = Field(
        default_factory=list,
        description="What happens when: a trigger (`when`: a time, a body entering a region or coming "
        "near, a message, another event, an assertion decided) and actions (`do`: publish, start an "
        "actor, teleport, push, change a parameter, inject a fault, block a wheel, end the run).",
    )
    record: Record = Field(default_factory=Record, description="What to record, and where.")
    assertions: list[Assertion] = Field(
        default_factory=list, description="Checks judged live during the run and from the recording."
    )
    matrix: dict[str, list[Any] | int] = Field(
        default_factory=dict,
        description="Parameter variants: paths into this scenario (`seed`, `robots[0].pose.xyz`, "
        "`timeline[0].data.linear.x`) mapped to lists of values; each combination is run and judged apart. "
        "`samples: N` runs each combination N times, drawing the file's random values "
        "(`{uniform: [lo, hi]}`, `{normal: [mean, stddev]}`, `{choice: [...]}`, `pose: {within: REGION}`) "
        "from [seed, sample].",
    )
    stop_on: Literal["never", "first_failure", "all_decided"] = Field(
        "never", description="End the run early when an assertion fails, or when every one is decided."
    )
    nodes: list[Node] = Field(
        default_factory=list, description="Processes started with the run (controllers, planners...)."
    )
    hosts: dict[Annotated[str, Field(pattern=NODE_NAME_RE.pattern)], Host] = Field(
        default_factory=dict,
        description="Machines of the run by name; worlds and nodes say where they run (`host:`). Without "
        "it, everything runs on this machine. `scenario run FILE` plays the first host (it records and "
        "judges), `scenario run FILE --host NAME` another one, `--local` all of them here.",
    )
    resources: Resources | None = Field(
        None,
        description="What one run asks of a cluster under `scenario test --ray` (CPUs, GPUs, custom "
        "resources); default: a CPU per process of the run, a GPU for cameras per `--gpus`.",
    )
    foxglove: Foxglove = Field(
        default_factory=Foxglove, description="The 3D view a recording carries (Foxglove-ready)."
    )
    zenoh: ZenohSettings | None = Field(
        None, description="Zenoh configuration for every session of the run (TLS, access control...)."
    )
    qos: list[QosRule] = Field(
        default_factory=list,
        description="Per-topic delivery: every topic is reliable (nothing lost: a publisher blocks rather "
        "than drop) unless a rule makes it `best_effort`.",
    )
    bridges: list[Bridge] = Field(
        default_factory=list,
        description="Topics re-exposed under other keys, encodings and directions (like ros_gz_bridge); "
        "`bridges: {file: bridge.yaml}` takes a ros_gz_bridge file as it is. Run by a bridge process.",
    )
    ros2: Ros2 | None = Field(
        None,
        description="Appear to ROS 2 over rmw_zenoh: every sim topic as `/<ns>/<topic>` (or only the "
        "bridges), discoverable with `ros2 topic list`.",
    )
    lockstep: list[str] = Field(
        default_factory=list,
        description="Nodes the world waits for: before acting on commands at each step, the world waits "
        "until each of these nodes has handled the clock it last published (a node made with runner.node "
        "says so when it sleeps). A slow controller cannot be outrun, and a `rate: max` run is repeatable.",
    )

    @field_validator("bridges", mode="before")
    @classmethod
    def _bridges(cls, v: Any) -> Any:
        return [v] if isinstance(v, dict) else v  # `bridges: {file: bridge.yaml}`: one entry

    @field_validator("rate", mode="before")
    @classmethod
    def _rate(cls, v: Any) -> Any:
        if v in ("realtime", "max"):
            return v
        if isinstance(v, bool) or not isinstance(v, int | float) or v <= 0:
            raise ValueError(
                "rate must be 'realtime', 'max' or a positive real-time factor (e.g. 2.0): "
                "write `rate: realtime`, `rate: max` or a number above 0 such as `rate: 2.0`"
            )
        return float(v)

    @field_validator("matrix")
    @classmethod
    def _matrix(cls, v: dict[str, list[Any] | int]) -> dict[str, list[Any] | int]:
        for key, values in v.items():
            if isinstance(values, int) and (key != "samples" or values < 1):
                raise ValueError(f"matrix.{key}: only `samples` takes a number (1 or more); paths take lists")
        return v

    @field_validator("seed")
    @classmethod
    def _seed(cls, v: int) -> int:
        if v < 0:
            raise ValueError(
                "a seed is 0 or more (random generators take non-negative seeds): write e.g. `seed: 42`"
            )
        return v

    @field_validator("duration")
    @classmethod
    def _duration(cls, v: float) -> float:
        if v > MAX_DURATION:
            raise ValueError(
                f"a run lasts at most {MAX_DURATION} s of sim time (the ROS clock counts seconds in an int32)"
                ": write a shorter duration, in seconds"
            )
        return v
