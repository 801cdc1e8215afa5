"""The scenario file format (v1): the single source of truth.

Pydantic models with `extra="forbid"` and a description on every field. `schemas/scenario.schema.json`
is generated from `Scenario` (`scenario schema`); a test fails when the committed copy is stale.
No I/O happens here: files named in a scenario are read by the compile pass.

One module per section of the format: `base` (the shared base model, name patterns, vectors, poses),
`world`, `robots`, `assertions`, `messages` (timeline, qos, record, foxglove), `network` (hosts, nodes,
resources, zenoh, ros2, bridges) and `scenario` (the file as a whole). Every model is importable from here.
"""

from runner.scenario.schema.assertions import (
    Assertion,
    DistanceTraveled,
    MaxSpeed,
    MaxTilt,
    MessageCheck,
    NoCollision,
    Reach,
    Region,
    StayWithin,
    TopicRate,
    Vec2,
)
from runner.scenario.schema.base import (
    IDENT_RE,
    NAMESPACE_RE,
    NODE_NAME_RE,
    PATTERN_WORDS,
    RUN_NAME_RE,
    TOPIC_RE,
    Namespace,
    Pose,
    Rate,
    Rgba,
    RunName,
    Strict,
    Vec3,
)
from runner.scenario.schema.events import (
    ACTIONS,
    TRIGGERS,
    Action,
    Actor,
    Event,
    Fault,
    Hinge,
    Waypoint,
    When,
)
from runner.scenario.schema.messages import Foxglove, QosRule, Record, TimelineEntry
from runner.scenario.schema.network import (
    Bridge,
    BridgeDirection,
    Host,
    Node,
    Resources,
    Ros2,
    ZenohSettings,
)
from runner.scenario.schema.robots import Description, PluginEntry, Robot, XacroArg
from runner.scenario.schema.scenario import MAX_DURATION, SCHEMA_VERSION, Scenario
from runner.scenario.schema.world import Ground, NamedWorld, Physics, World, WorldModel

__all__ = [
    "ACTIONS",
    "IDENT_RE",
    "MAX_DURATION",
    "NAMESPACE_RE",
    "NODE_NAME_RE",
    "PATTERN_WORDS",
    "RUN_NAME_RE",
    "SCHEMA_VERSION",
    "TOPIC_RE",
    "TRIGGERS",
    "Action",
    "Actor",
    "Assertion",
    "Bridge",
    "BridgeDirection",
    "Description",
    "DistanceTraveled",
    "Event",
    "Fault",
    "Foxglove",
    "Ground",
    "Hinge",
    "Host",
    "MaxSpeed",
    "MaxTilt",
    "MessageCheck",
    "NamedWorld",
    "Namespace",
    "NoCollision",
    "Node",
    "Physics",
    "PluginEntry",
    "Pose",
    "QosRule",
    "Rate",
    "Reach",
    "Record",
    "Region",
    "Resources",
    "Rgba",
    "Robot",
    "Ros2",
    "RunName",
    "Scenario",
    "StayWithin",
    "Strict",
    "TimelineEntry",
    "TopicRate",
    "Vec2",
    "Vec3",
    "Waypoint",
    "When",
    "World",
    "WorldModel",
    "XacroArg",
    "ZenohSettings",
]
