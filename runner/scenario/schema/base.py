"""What every part of the scenario format shares: the `Strict` base model (unknown keys and NaN refused),
the name patterns (with what each means in words, for error messages: runner.scenario.validate) and the
small value types: vectors, colours, poses, run names, namespaces, the pacing rate."""

from __future__ import annotations

import re
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat

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
