"""The controllers of ros_control / ros2_control, as gazebo_ros_control (ROS 1), gazebo_ros2_control and
gz_ros2_control (ROS 2) run them: each controller of a controllers file (`ControllerSpec`, read by
runner.compile.gazebo.controllers) goes to the handler of its type, which adds the plugin(s) that run it.

One module per family, each with `HANDLERS: {controller type: handler}`:
- `.broadcasters`: joint_state_broadcaster (ROS 1 joint_state_controller), imu / force-torque broadcasters;
- `.drives`: diff_drive_controller and the other mobile-base controllers;
- `.forward`: forward_command_controller and its position/velocity/effort families (ROS 1's
  `*_controllers/Joint*Controller`);
- `.trajectory`: joint_trajectory_controller;
- `.gripper`: gripper_action_controller, parallel_gripper_action_controller.

A handler reads the controller's parameters as the controller does (defaults included), adds plugins with
`ctx.add`, says what it does not run at the controller's own line (`ctx.say`), and returns whether it runs
the controller. Any type without a handler is said with its type at its line.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.info import DescribedPlugin, Where


@dataclass
class ControllerSpec:
    """One controller of a controllers file."""

    name: str  # the controller's name: its topics are `<name>/...`
    type: str  # e.g. "joint_trajectory_controller/JointTrajectoryController"
    params: dict[str, Any]  # its parameters (ROS 2: its `ros__parameters`; ROS 1: its block)
    file: Path | None = None
    line: int | None = None  # the line of its name (or its `type:`) in `file`
    ros1: bool = False
    update_rate: float | None = None  # the controller manager's update_rate (ROS 2)

    @property
    def where(self) -> Where:
        return (self.file, self.line)


@dataclass
class Remap:
    """One `<ros><remapping>` rule of the control plugin: `from:=to`, or `node:from:=to` for one node only
    (rcl's remap rules, which the controller manager and every controller node it loads are given)."""

    src: str
    dst: str
    node: str | None = None


@dataclass
class ControlContext:
    """What a controller handler works with: the Gazebo reader, the control plugin's location, and the
    names the plugin's `<ros><remapping>` / `<ros><namespace>` give the controllers' topics."""

    g: ReaderBase
    plugin_where: Where
    remap: dict[str, str] = field(default_factory=dict)  # `<name>/cmd_vel_unstamped` -> `cmd_vel`...
    rules: list[Remap] = field(default_factory=list)  # the plugin's remappings as written (`~/`, `/`...)
    namespace: str = ""  # the plugin's `<ros><namespace>` (the robot's namespace stands for it)
    node: str | None = None  # the controller being read: `~` in a name is this node's own namespace

    def expand(self, name: str, node: str | None = None) -> str:
        """A ROS name as rcl expands it for a controller node (`~/x` -> `<node>/x`, `x` -> `x`, `/x` -> `x`),
        relative to the robot's namespace, which stands for the plugin's (an absolute name under the
        plugin's `<namespace>` loses that prefix: the scenario places every robot's topics under its own)."""
        name = name.strip()
        node = node or self.node
        if name.startswith("~"):
            rest = name[1:].lstrip("/")
            name = f"{node}/{rest}" if node else rest
        elif name.startswith("/"):
            name = name.strip("/")
            ns = self.namespace.strip("/")
            if ns and (name == ns or name.startswith(ns + "/")):
                name = name[len(ns) :]
        return "/".join(part for part in name.split("/") if part)

    def topic(self, relative: str) -> str:
        """A controller's topic (`<controller>/cmd_vel`, `joint_states`, or as the controller names it:
        `~/cmd_vel`) as the control plugin's remappings name it. As rcl does, both
        sides of a rule are expanded for the node that uses the name (`~/x:=y` applies to every
        controller's own `x`), and the first rule that matches wins (rcl_remap_first_match, remap.c:104 on
        Humble; the replacement expanded, :215)."""
        name = self.expand(relative)
        for rule in self.rules:
            if rule.node is not None and rule.node != self.node:
                continue
            if self.expand(rule.src) == name:
                return self.expand(rule.dst)
        return self.remap.get(name, name)

    def frame(self, name: str | None) -> str | None:
        return self.g.frame(name)

    def add(
        self, spec: ControllerSpec, type_name: str, params: dict[str, Any], name: str | None = None
    ) -> None:
        """Run the controller (or part of it) as our plugin `type_name` with `params` (None: left out)."""
        clean = {k: v for k, v in params.items() if v is not None}
        self.g.info.plugins.append(
            DescribedPlugin(type_name, self.g.unique(name or spec.name), clean, *spec.where)
        )

    def say(self, spec: ControllerSpec, message: str, hint: str | None = None) -> None:
        """A notice at the controller's line in its controllers file."""
        self.g.notices.add(message, *spec.where, hint)


def param(params: dict[str, Any], dotted: str) -> Any:
    """A parameter written `a.b.c: v` or nested (`a: {b: {c: v}}`), as ROS 2 parameter files allow both."""
    if dotted in params:
        return params[dotted]
    node: Any = params
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


Handler = Callable[[ControlContext, ControllerSpec], bool]


def handlers() -> dict[str, Handler]:
    """Every controller type we run -> its handler."""
    from runner.compile.gazebo.control import broadcasters, drives, forward, gripper, trajectory

    out: dict[str, Handler] = {}
    for module in (broadcasters, drives, forward, trajectory, gripper):
        out.update(module.HANDLERS)
    return out


def fork_of(type_name: str) -> str | None:
    """The controller type a vendor's fork copies, by its class name and package: `clearpath_mecanum_drive_
    controller/MecanumDriveController` is ros2_controllers' `mecanum_drive_controller/MecanumDriveController`
    (a copy with extra parameters). None when no known type's package is part of this one's."""
    name = type_name.strip().replace("::", "/")
    if "/" not in name:
        return None
    package, cls = name.rsplit("/", 1)
    for known in sorted(handlers(), key=len, reverse=True):
        kpackage, kcls = known.rsplit("/", 1)
        if kcls == cls and kpackage != package and kpackage in package:
            return known
    return None


def handler_for(type_name: str) -> Handler | None:
    """The handler of a controller type, by its full name (`pkg/Class`); ROS 1's `pkg::Class` too."""
    found = handlers()
    name = type_name.strip().replace("::", "/")
    return found.get(name)
