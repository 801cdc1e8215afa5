"""The robots of a scenario (`robots:`): where each comes from (a URDF or xacro file, with its arguments),
where it spawns, and the plugins attached to it."""

from __future__ import annotations

from typing import Any

from pydantic import Field

from runner.scenario.schema.base import Namespace, Pose, Strict

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
        False,
        description="Weld the root link to the world (an arm on a table) instead of a free base. A "
        "description whose root link is `world` is welded by it, as in Gazebo, without this.",
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
    spawn: list[str] | None = Field(
        None,
        description="The controllers the robot's launch file spawns, by name (default: every controller "
        "of its controllers files). Those left out are not run, as a controller no spawner loads; one "
        "spawned `--inactive` is left out too.",
    )
    controller_types: dict[str, str] = Field(
        default_factory=dict,
        description="Controller types a spawner gives on its command line (`-t` / `--controller-type`), by "
        "controller name: for controllers files that give parameters but no `type:`.",
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
