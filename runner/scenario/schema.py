"""The scenario file format (v1): the single source of truth.

Pydantic models with `extra="forbid"` and a description on every field. `schemas/scenario.schema.json`
is generated from `Scenario` (`scenario schema`); a test fails when the committed copy is stale.
No I/O happens here: files named in a scenario are read by the compile pass.
"""

from __future__ import annotations

import re
from typing import Annotated, Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    NonNegativeFloat,
    NonNegativeInt,
    PositiveFloat,
    field_validator,
    model_validator,
)

SCHEMA_VERSION = 1
MAX_DURATION = 2**31 - 1  # sim seconds: builtin_interfaces/Time counts seconds in an int32

RUN_NAME_RE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.\-]*$")
# ROS 2 style names (so that the same names work over rmw_zenoh later); nested namespaces allowed.
NAMESPACE_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*$")
TOPIC_RE = re.compile(r"^/?[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*$")
IDENT_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")  # world names, ROS 2 node names
NODE_NAME_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_-]*$")  # nodes and hosts

# What each pattern means, in words, and the characters it allows besides letters, digits and '_'
# (for error messages: runner.scenario.validate).
PATTERN_WORDS: dict[str, tuple[str, str]] = {
    RUN_NAME_RE.pattern: (
        "letters, digits, '_', '-' and '.', not starting with '-' or '.' (e.g. my_run)",
        "-.",
    ),
    NAMESPACE_RE.pattern: (
        "a ROS-style name: letters, digits and '_', starting with a letter; nested with '/' (e.g. fleet/r1)",
        "/",
    ),
    TOPIC_RE.pattern: (
        "a topic name: chunks of letters, digits and '_' separated by '/', none starting with a digit "
        "(e.g. r1/cmd_vel)",
        "/",
    ),
    IDENT_RE.pattern: ("letters, digits and '_', not starting with a digit (e.g. arena_2)", ""),
    NODE_NAME_RE.pattern: (
        "letters, digits, '_' and '-', starting with a letter or '_' (e.g. controller)",
        "-",
    ),
}


class Strict(BaseModel):
    # NaN and infinity are never a meaningful duration, rate or size: refused like any wrong value.
    model_config = ConfigDict(extra="forbid", populate_by_name=False, allow_inf_nan=False)


Vec3 = Annotated[tuple[float, float, float], Field(description="[x, y, z]")]
Rgba = Annotated[
    tuple[float, float, float, float],
    Field(description="[red, green, blue, alpha], each 0..1"),
]
RunName = Annotated[
    str,
    Field(
        pattern=RUN_NAME_RE.pattern,
        description="Letters, digits, '_', '-', '.'; the first chunk of every Zenoh key of the run.",
    ),
]
Namespace = Annotated[
    str,
    Field(
        pattern=NAMESPACE_RE.pattern,
        description="A ROS-style name: letters, digits, '_' (may be nested with '/', e.g. 'fleet/r1').",
    ),
]
Rate = Annotated[
    Literal["realtime", "max"] | PositiveFloat,
    Field(
        description="Pacing against wall time: 'realtime', 'max' (as fast as possible) "
        "or a real-time factor (2 = twice as fast as real time)."
    ),
]


class Pose(Strict):
    """A pose: position and roll-pitch-yaw (radians, fixed axes X then Y then Z, as in URDF)."""

    xyz: Vec3 = Field((0.0, 0.0, 0.0), description="Position in metres.")
    rpy: Vec3 = Field((0.0, 0.0, 0.0), description="Roll, pitch, yaw in radians.")


class Physics(Strict):
    timestep: PositiveFloat = Field(0.002, le=0.1, description="Physics step in seconds.")
    gravity: Vec3 = Field((0.0, 0.0, -9.81), description="Gravity in m/s².")
    integrator: Literal["euler", "implicitfast", "implicit", "rk4"] = Field(
        "implicitfast", description="MuJoCo integrator; implicitfast is stable with velocity actuators."
    )
    friction_cone: Literal["elliptic", "pyramidal"] = Field(
        "elliptic",
        description="MuJoCo friction cone. Elliptic is exact; MuJoCo's default pyramidal cone makes high "
        "friction (Gazebo descriptions use mu up to 100) soften contacts until wheels carry no load.",
    )


class Ground(Strict):
    enabled: bool = Field(True, description="Add an infinite ground plane at z = 0.")
    friction: PositiveFloat = Field(1.0, description="Sliding friction coefficient of the ground.")
    rgba: Rgba = Field((0.55, 0.57, 0.6, 1.0), description="Colour of the ground.")


class WorldModel(Strict):
    """A primitive shape in the world: a wall, an obstacle, a box to push."""

    name: Namespace = Field(description="Unique name of the model (its body is named after it).")
    shape: Literal["box", "cylinder", "sphere"] = Field(description="Primitive shape.")
    size: list[PositiveFloat] = Field(
        description="box: [x, y, z] full lengths; cylinder: [radius, length]; sphere: [radius] (metres).",
    )
    pose: Pose = Field(default_factory=Pose, description="Pose of the shape's centre in the world.")
    rgba: Rgba = Field((0.7, 0.7, 0.7, 1.0), description="Colour.")
    static: bool = Field(True, description="A static model never moves; otherwise it is free and has `mass`.")
    mass: PositiveFloat | None = Field(None, description="Mass in kg of a non-static model (default 1).")
    friction: PositiveFloat = Field(1.0, description="Sliding friction coefficient.")

    @field_validator("size")
    @classmethod
    def _size_len(cls, v: list[float], info: Any) -> list[float]:
        need = {"box": 3, "cylinder": 2, "sphere": 1}.get(info.data.get("shape", ""))
        if need is not None and len(v) != need:
            shape = info.data["shape"]
            form = {"box": "[x, y, z]", "cylinder": "[radius, length]", "sphere": "[radius]"}[shape]
            raise ValueError(f"a {shape} needs {need} number(s) {form}, found {len(v)}")
        return v


class World(Strict):
    sdf: str | None = Field(
        None,
        description="An SDF (1.4-1.9) or Gazebo .world file to load, relative to the scenario's folder; "
        "`models` are added to it.",
    )
    physics: Physics = Field(default_factory=Physics, description="Physics settings.")
    ground: Ground = Field(default_factory=Ground, description="The ground plane.")
    models: list[WorldModel] = Field(default_factory=list, description="Primitive models in the world.")
    clock_rate: PositiveFloat = Field(
        100.0, description="How often sim time is published on `<run>/clock`, in sim Hz."
    )
    host: str | None = Field(None, description="With `hosts:`, the host simulating it (default: the first).")


class NamedWorld(World):
    """One of several worlds: simulated by a process of its own, in a key space of its own."""

    name: Annotated[str, Field(pattern=IDENT_RE.pattern)] = Field(
        description="World name (letters, digits, '_'): the second chunk of its keys (`run/arena/r1/scan`)."
    )


XacroArg = str | int | float | bool


class Description(Strict):
    """Where a robot comes from."""

    file: str = Field(
        description="A URDF (.urdf) or xacro (.xacro, .urdf.xacro) file, relative to the scenario's folder."
    )
    args: dict[str, XacroArg] = Field(
        default_factory=dict, description="xacro arguments (`$(arg name)`), as `name: value`."
    )


class PluginEntry(Strict):
    """A plugin attached to a robot: `{type: lidar, params: {...}}`."""

    type: str = Field(description="Plugin type, e.g. diff_drive, lidar, imu, joint_states, ground_truth.")
    name: str | None = Field(None, description="Instance name (default: the type); unique per robot.")
    params: dict[str, Any] = Field(
        default_factory=dict, description="Parameters, checked against the plugin's own model at compile."
    )


class Robot(Strict):
    name: Namespace = Field(description="Unique robot name.")
    namespace: Namespace | None = Field(
        None, description="Namespace of its topics and frames (default: the name): `<run>/<ns>/scan`."
    )
    description: Description | str = Field(
        description="The robot's URDF/xacro file, or `{file: ..., args: {...}}` to pass xacro arguments."
    )
    pose: Pose = Field(default_factory=Pose, description="Spawn pose of the robot's root link.")
    fixed: bool = Field(
        False, description="Weld the root link to the world (an arm on a table) instead of a free base."
    )
    plugins: list[PluginEntry] = Field(
        default_factory=list,
        description="Plugins of this robot. They add to the sensors and plugins its description declares in "
        "<gazebo> tags, and replace those of the same name (or type).",
    )
    world: str | None = Field(
        None, description="With `worlds:`, the world this robot is in (default: the first world)."
    )
    plugins_from_description: bool = Field(
        True, description="Use the plugins and sensors declared in the description's <gazebo> tags."
    )
    controllers: list[str] = Field(
        default_factory=list,
        description="ros_control / ros2_control controllers files (the YAML a launch file loads for "
        "gazebo_ros_control), relative to the scenario: their diff drive and joint state controllers run "
        "as in Gazebo (`<controller>/cmd_vel`, `<controller>/odom`, `joint_states`).",
    )

    @property
    def ns(self) -> str:
        return self.namespace or self.name

    @property
    def desc(self) -> Description:
        return (
            self.description
            if isinstance(self.description, Description)
            else Description(file=self.description)
        )


class TimelineEntry(Strict):
    """At sim time `t`, publish a message on a topic of the run."""

    t: NonNegativeFloat = Field(description="Sim time in seconds.")
    topic: str = Field(
        pattern=TOPIC_RE.pattern,
        description="Topic inside the run's key space, e.g. `r1/cmd_vel` (-> `<run>/r1/cmd_vel`).",
    )
    type: str = Field(description="ROS 2 message type, e.g. `geometry_msgs/msg/Twist`.")
    data: dict[str, Any] = Field(
        default_factory=dict, description="Message fields as YAML; omitted fields are zero."
    )


class Record(Strict):
    enabled: bool = Field(True, description="Record the run to MCAP.")
    path: str | None = Field(
        None,
        description="MCAP file to write, relative to the scenario's folder (default: `runs/<name>.mcap` "
        "in the current folder).",
    )
    include: list[str] = Field(
        default_factory=lambda: ["**"],
        description="Zenoh key expressions relative to the run (`*/scan`, `r1/**`) of topics to record.",
    )
    exclude: list[str] = Field(default_factory=list, description="Key expressions of topics not to record.")


# ------------------------------------------------------------------------------------------ assertions
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
            raise ValueError(f"max {list(v)} must exceed min {list(lo)} on both axes")
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
            raise ValueError(f"the window ends (until: {v}) before it starts (after: {start})")
        return v


def _min_below_max(v: float | None, info: Any, unit: str) -> float | None:
    lo = info.data.get("min")
    if v is not None and lo is not None and v < lo:
        raise ValueError(f"max ({v} {unit}) is below min ({lo} {unit})")
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
            raise ValueError("a reach assertion has either `point: [x, y]` or `region:`")
        if self.by is not None and self.by <= self.after:
            raise ValueError(
                f"the deadline (by: {self.by:g}) is not after the window opens (after: {self.after:g})"
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


_ENDPOINT_PATTERN = r"^(tcp|udp|tls|quic|ws|unixsock-stream|unixpipe|serial|vsock)/\S+$"


class Host(Strict):
    """A machine of the run, by the Zenoh endpoint its runner listens on."""

    endpoint: str = Field(
        description="Zenoh endpoint of this host's runner, e.g. `tcp/10.0.0.2:7447`. The first host of "
        "`hosts:` is the main one: it records and judges; the others run `scenario run FILE --host NAME` "
        "and join it.",
        json_schema_extra={"pattern": _ENDPOINT_PATTERN},
    )

    @field_validator("endpoint")
    @classmethod
    def _an_endpoint(cls, value: str) -> str:
        if not re.match(_ENDPOINT_PATTERN, value):
            example = value.split("/")[-1] or "10.0.0.2:7447"
            raise ValueError(f"not a Zenoh endpoint: write it with its protocol, e.g. tcp/{example}")
        return value


class Node(Strict):
    """A process of the run: a controller, a planner, a bridge. It gets the run's Zenoh endpoint, name,
    its namespace and the clock key in its environment (`SCENARIO_ENDPOINT`, `SCENARIO_RUN`,
    `SCENARIO_NAMESPACE`, `SCENARIO_CLOCK`, `SCENARIO_NODE`); `runner.node.Node()` reads them."""

    name: Annotated[str, Field(pattern=NODE_NAME_RE.pattern)] = Field(
        description="Node name (letters, digits, '_', '-'): in logs, `lockstep:` and the run's report."
    )
    cmd: str | list[str] = Field(
        description="The command: a string split like a shell would (`python nodes/go_to_goal.py`), or a "
        "list. A leading `python` is this interpreter. Relative paths are relative to `cwd`."
    )
    args: list[str] = Field(default_factory=list, description="Extra arguments after the command.")
    env: dict[str, str] = Field(default_factory=dict, description="Extra environment variables.")
    cwd: str | None = Field(None, description="Working folder (default: the scenario's folder).")
    namespace: Namespace | None = Field(
        None, description="The robot namespace it works in (`SCENARIO_NAMESPACE`), e.g. `r1`."
    )
    respawn: Literal["never", "on-failure"] = Field(
        "never", description="Start it again when it exits with an error (up to `respawn_limit` times)."
    )
    respawn_limit: NonNegativeInt = Field(3, description="Restarts allowed with `respawn: on-failure`.")
    required: bool = Field(
        False, description="The run fails (exit 1) and stops when this node exits before the run ends."
    )
    host: str | None = Field(None, description="With `hosts:`, the host that runs it (default: the first).")
    world: str | None = Field(
        None,
        description="With `worlds:`, the world whose key space the node works in (`SCENARIO_RUN` is "
        "`<run>/<world>`; default: the world of the robot named by its namespace, else the first).",
    )


class Ros2(Strict):
    """Be seen by ROS 2 over rmw_zenoh (no ROS needed here): topics under rmw_zenoh's keys
    (`<domain>/<name>/<type>/<hash>`), with its liveliness tokens and attachments, so `ros2 topic list`,
    `ros2 topic echo` and rclcpp/rclpy nodes running `RMW_IMPLEMENTATION=rmw_zenoh_cpp` see the run."""

    domain: Annotated[int, Field(ge=0, le=232)] = Field(0, description="ROS_DOMAIN_ID.")
    node: Annotated[str, Field(pattern=IDENT_RE.pattern)] | None = Field(
        None, description="The ROS 2 node name the simulation appears as (default: the run's name)."
    )
    router: str | None = Field(
        None,
        description="Zenoh endpoint of a ROS 2 Zenoh router to join (e.g. `tcp/127.0.0.1:7447`, where "
        "`ros2 run rmw_zenoh_cpp rmw_zenohd` listens). Default: ROS 2 nodes join the run's own router "
        "(`scenario run FILE --listen tcp/127.0.0.1:7447` puts it where rmw_zenoh looks by default).",
    )
    topics: Literal["all", "bridged"] = Field(
        "all",
        description="`all`: every topic of the simulation appears as `/<namespace>/<topic>` (and "
        "`/clock`), in the directions the simulation uses it; `bridged`: only the `bridges:`.",
    )


class Foxglove(Strict):
    """What the world publishes so that a recording (or a live run) opens in Foxglove as a 3D view with no
    set-up: the world's and robots' geometry, every link's transform, each robot's URDF."""

    scene: bool = Field(
        True,
        description="Publish `scene` (foxglove.SceneUpdate: boxes, cylinders, spheres, meshes of every "
        "body), `tf_static`/`tf` (every link, from `world`: a `robot_state_publisher` `tf` plugin is added "
        "to each robot without a `tf` plugin) and `<ns>/robot_description` (URDF, links named "
        "`<ns>/<link>`).",
    )
    rate: PositiveFloat = Field(
        1.0, description="How often (per sim second) the scene, static transforms and URDFs are sent again."
    )
    tf_rate: PositiveFloat = Field(30.0, description="Transforms of moving links per sim second.")


class ZenohSettings(Strict):
    """The run's Zenoh configuration, passed to every session of the run (router, worlds, renderers,
    nodes, bridge, and the command-line tools that join it): TLS, access control, anything Zenoh has."""

    config: str | None = Field(
        None, description="A Zenoh configuration file (JSON5), relative to the scenario, taken first."
    )
    settings: dict[str, Any] = Field(
        default_factory=dict,
        description="Settings by their path in Zenoh's configuration, on top of the file, e.g. "
        "`transport/link/tls/root_ca_certificate: certs/ca.pem` (file paths relative to the scenario).",
    )
    listen: list[str] = Field(
        default_factory=list,
        description="The run's router endpoints, e.g. `tls/127.0.0.1:7447` (default: a free TCP port on "
        "127.0.0.1: loopback only unless told otherwise; `--listen` overrides).",
    )


class QosRule(Strict):
    """How the publishers of some topics behave when a subscriber falls behind."""

    topics: str = Field(
        description="Key expression inside the run (`*/camera/**`, `r1/scan`): the topics this rule is for."
    )
    reliability: Literal["reliable", "best_effort"] = Field(
        description="`reliable` (the default for every topic): a publisher waits rather than drop a message, "
        "so nothing recorded is ever lost and a slow subscriber slows the simulation down; `best_effort`: "
        "it drops instead (cameras for a live viewer: the simulation never waits; the recorder counts "
        "what was lost)."
    )


BridgeDirection = Literal["SIM_TO_ZENOH", "ZENOH_TO_SIM", "BIDIRECTIONAL"]


class Bridge(Strict):
    """A sim topic re-exposed under another key, encoding or direction; or (`file:`) a ros_gz_bridge
    configuration file, taken as it is."""

    topic: str | None = Field(
        None,
        description="The sim topic, as in the timeline (`r1/scan`, `/clock`); from a `file:`, the gz "
        "topic names resolve to the sim topic of the same name (in `robot`'s namespace, if given).",
    )
    file: str | None = Field(
        None,
        description="A ros_gz_bridge YAML file (relative to the scenario): `topic_name` / `ros_topic_name` "
        "/ `gz_topic_name`, `ros_type_name`, `gz_type_name`, `direction` (GZ_TO_ROS, ROS_TO_GZ, "
        "BIDIRECTIONAL), `lazy`. gz topics are our sim topics; ROS topics are Zenoh keys (or rmw_zenoh "
        "topics with `ros2:`).",
    )
    robot: str | None = Field(
        None,
        description="With `file:`: the robot whose topics the gz names are, and whose namespace relative "
        "ROS names go under (like ros_gz_bridge started in that namespace).",
    )
    key: str | None = Field(
        None,
        description="The Zenoh key expression on the other side (default: the topic's own name, outside "
        "the run: `r1/scan`). With `ros2:` the key is rmw_zenoh's and this is not used.",
    )
    ros_topic: str | None = Field(
        None, description="With `ros2:`, the ROS 2 topic name (default: `/<topic>`)."
    )
    type: str | None = Field(
        None, description="ROS 2 type (default: the sim topic's own), e.g. `geometry_msgs/msg/Twist`."
    )
    direction: BridgeDirection = Field(
        "SIM_TO_ZENOH",
        description="`SIM_TO_ZENOH` (the sim's messages out), `ZENOH_TO_SIM` (messages from outside into "
        "the sim, e.g. commands) or `BIDIRECTIONAL`.",
    )
    encoding: Literal["cdr", "json"] = Field(
        "cdr",
        description="On the other side: `cdr` (the same bytes as in the sim) or `json` (the message's "
        'fields as a JSON object, e.g. `{"linear": {"x": 0.5}}`).',
    )
    rate: PositiveFloat | None = Field(
        None, description="At most this many messages per sim second to the other side (a throttle)."
    )
    lazy: bool = Field(
        False,
        description="Forward only while someone subscribes on the other side (SIM_TO_ZENOH), like "
        "ros_gz_bridge's `lazy`.",
    )
    ros2: Ros2 | bool | None = Field(
        None,
        description="Use rmw_zenoh's format for this bridge (`true`: the scenario's `ros2:` settings, or "
        "the defaults). Default: the scenario's `ros2:`, if set.",
    )

    @model_validator(mode="after")
    def _one_source(self) -> Bridge:
        if (self.topic is None) == (self.file is None):
            raise ValueError("a bridge has either `topic:` (one mapping) or `file:` (a ros_gz_bridge file)")
        if self.file is not None:
            extra = [f for f in ("key", "ros_topic", "type") if getattr(self, f) is not None]
            if extra:
                raise ValueError(f"{', '.join(extra)}: set per entry inside the file, not beside `file:`")
        elif self.robot is not None:
            raise ValueError("`robot:` goes with `file:`; for one topic write it in the topic (`r1/scan`)")
        return self


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
    record: Record = Field(default_factory=Record, description="What to record, and where.")
    assertions: list[Assertion] = Field(
        default_factory=list, description="Checks judged live during the run and from the recording."
    )
    matrix: dict[str, list[Any]] = Field(
        default_factory=dict,
        description="Parameter variants: paths into this scenario (`seed`, `robots[0].pose.xyz`, "
        "`timeline[0].data.linear.x`) mapped to lists of values; each combination is run and judged apart.",
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
            raise ValueError("rate must be 'realtime', 'max' or a positive real-time factor (e.g. 2.0)")
        return float(v)

    @field_validator("seed")
    @classmethod
    def _seed(cls, v: int) -> int:
        if v < 0:
            raise ValueError("a seed is 0 or more (random generators take non-negative seeds)")
        return v

    @field_validator("duration")
    @classmethod
    def _duration(cls, v: float) -> float:
        if v > MAX_DURATION:
            raise ValueError(
                f"a run lasts at most {MAX_DURATION} s of sim time (the ROS clock counts seconds in an int32)"
            )
        return v
