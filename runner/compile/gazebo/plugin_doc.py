"""The records of the plugin catalogue (runner.compile.gazebo.catalogue): a plugin's entry (`PluginDoc`) and
each of its parameters (`Param`: as in Gazebo, approximated, or said and ignored), with the helpers the
catalogue's tables are written with."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

Status = Literal["same", "approx", "ignored"]


@dataclass(frozen=True)
class Param:
    names: tuple[str, ...]  # every spelling the plugin reads (ROS 1 camelCase, ROS 2 snake_case)
    status: Status
    how: str = ""  # approx: how; ignored: what Gazebo does with it and why we do not


@dataclass(frozen=True)
class PluginDoc:
    bases: tuple[
        str, ...
    ]  # `plugin_base()` of its filenames (`gazebo_ros_diff_drive`, `gz-sim-diff-drive-system`)
    kind: Literal["model", "sensor"]
    origin: str  # the package and distribution, and the source file it is read from
    becomes: str  # what it is here (our plugin type, or why nothing)
    params: tuple[Param, ...] = field(default_factory=tuple)

    def names(self) -> set[str]:
        return {n for p in self.params for n in p.names}

    def ignored(self) -> dict[str, str]:
        return {n: p.how for p in self.params if p.status == "ignored" for n in p.names}


def p(names: str, status: Status = "same", how: str = "") -> Param:
    """A parameter by its spellings (space-separated)."""
    return Param(tuple(names.split()), status, how)


# what most gazebo_ros plugins read besides their own parameters
COMMON = (
    p("alwaysOn always_on", "ignored", "sensors and plugins are always on"),
    p("robotNamespace", "approx", "the robot's namespace is the scenario's (said when it differs)"),
    p("ros", "approx", "`<remapping>` kept; `<namespace>` replaced by the robot's (said)"),
    p("rosDebugLevel", "ignored", "ROS debug level"),
)
