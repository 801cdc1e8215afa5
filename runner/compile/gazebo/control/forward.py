"""Forward command controllers -> our `joint_controller` (a MuJoCo actuator per joint, claimed through
plugins/_actuators.py: the hardware's actuator of that command interface when it has one).

ROS 2 (ros2_controllers, Humble and Jazzy): forward_command_controller/ForwardCommandController (`joints`,
`interface_name`) and its families position_controllers/JointGroupPositionController,
velocity_controllers/JointGroupVelocityController, effort_controllers/JointGroupEffortController (`joints`):
`~/commands`, std_msgs/Float64MultiArray, one value per joint in the order of `joints` (a message of another
length is refused, forward_command_controller.cpp `update`); the command holds until the next one.
MultiInterfaceForwardCommandController runs when it names one interface, else it is said.

ROS 1 (ros_controllers, Noetic): `position_controllers/JointPositionController`,
`velocity_controllers/JointVelocityController`, `effort_controllers/JointEffortController` (`joint`,
`<name>/command`, std_msgs/Float64), their `JointGroup*Controller`s (`joints`, `<name>/command`,
Float64MultiArray), and the PID ones: `effort_controllers/JointPositionController` /
`JointVelocityController` (`pid: {p, i, d, i_clamp}`): a PD (or P on velocity) servo with those gains, the
force limit the URDF's `<limit effort>` as gazebo_ros_control's effort interface enforces it; the I term is
said (the servo runs in the physics step, with no integrator)."""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, Handler, param
from runner.compile.gazebo.control.params import check, line_of, read

_MODES = ("position", "velocity", "effort")


def _joints(ctx: ControlContext, spec: ControllerSpec, values: Any, key: str) -> list[str] | None:
    if isinstance(values, str):
        values = [values]
    joints = [str(j) for j in values or [] if j]
    if not joints:
        ctx.say(spec, f"controller {spec.name!r} ({spec.type}) names no joint (`{key}`): it is not run")
        return None
    return joints


def _run(
    ctx: ControlContext,
    spec: ControllerSpec,
    joints: list[str],
    mode: str,
    topic: str,
    array: bool = True,
    **gains: Any,
) -> bool:
    ctx.add(
        spec,
        "joint_controller",
        {
            "joints": joints,
            "mode": mode,
            "topic": ctx.topic(topic),
            "message": "float64_array" if array else "float64",
            **gains,
        },
    )
    return True


def forward_command_controller(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """ForwardCommandController: `joints` by `interface_name`, `~/commands` (Float64MultiArray)."""
    check(ctx, spec)
    p = read(spec)
    joints = _joints(ctx, spec, p["joints"], "joints")
    mode = str(p["interface_name"] or "")
    if joints is None:
        return False
    if mode not in _MODES:
        ctx.g.notices.add(
            f"forward_command_controller {spec.name!r}: interface_name {mode!r} is not position, velocity or "
            "effort (the command interfaces the joints have here): it is not run",
            spec.file,
            line_of(spec.params, "interface_name") or spec.line,
        )
        return False
    return _run(ctx, spec, joints, mode, "~/commands")


def _group(mode: str) -> Handler:
    def handler(ctx: ControlContext, spec: ControllerSpec) -> bool:
        """JointGroup{Position,Velocity,Effort}Controller: ROS 2 `~/commands`, ROS 1 `<name>/command`."""
        if spec.ros1 and spec.type.startswith("effort_controllers/JointGroupPosition"):
            return _ros1_pid_group(ctx, spec)
        check(ctx, spec)
        joints = _joints(ctx, spec, param(spec.params, "joints"), "joints")
        if joints is None:
            return False
        return _run(ctx, spec, joints, mode, "~/command" if spec.ros1 else "~/commands")

    return handler


def _ros1_joint(mode: str) -> Handler:
    def handler(ctx: ControlContext, spec: ControllerSpec) -> bool:
        """ROS 1 Joint{Position,Velocity,Effort}Controller: `joint`, `<name>/command` (Float64)."""
        check(ctx, spec)
        joints = _joints(ctx, spec, param(spec.params, "joint"), "joint")
        if joints is None:
            return False
        return _run(ctx, spec, joints[:1], mode, "~/command", array=False)

    return handler


def _pid(ctx: ControlContext, spec: ControllerSpec, block: Any, where: str) -> dict[str, float] | None:
    """The gains of a ROS 1 `pid:` block (control_toolbox::Pid): p, d used; i and its clamps said."""
    if not isinstance(block, dict) or not isinstance(block.get("p"), (int, float)):
        ctx.say(
            spec,
            f"controller {spec.name!r} ({spec.type}): no `{where}.p` gain: control_toolbox refuses to start "
            "without it; here the joint gets our default gains",
            hint=f"{where}: {{p: 100.0, i: 0.0, d: 10.0}}",
        )
        return {}
    i = block.get("i")
    if isinstance(i, (int, float)) and i != 0:
        ctx.g.notices.add(
            f"controller {spec.name!r}: `{where}.i` {i} is not run: the servo runs inside the physics step "
            "as a PD (P for velocity) with no integrator, so a constant load leaves a steady error of "
            "load / p",
            spec.file,
            line_of(spec.params, f"{where}.i") or spec.line,
            hint="raise `p` to shrink the steady error, or drop `i`",
        )
    gains = {"kp": float(block["p"])}
    d = block.get("d")
    if isinstance(d, (int, float)):
        gains["kv"] = float(d)
    return gains


def ros1_effort_position(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """ROS 1 effort_controllers/JointPositionController: effort = PID(position error), here a PD servo
    (kp = p, kv = d) in the physics step."""
    check(ctx, spec)
    p = read(spec)
    joints = _joints(ctx, spec, p["joint"], "joint")
    if joints is None:
        return False
    gains = _pid(ctx, spec, spec.params.get("pid"), "pid")
    if gains is None:
        return False
    return _run(ctx, spec, joints[:1], "position", "~/command", array=False, **gains)


def ros1_effort_velocity(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """ROS 1 effort_controllers/JointVelocityController: effort = PID(velocity error), here a velocity
    servo of gain p (d and i said when given)."""
    check(ctx, spec)
    p = read(spec)
    joints = _joints(ctx, spec, p["joint"], "joint")
    if joints is None:
        return False
    gains = _pid(ctx, spec, spec.params.get("pid"), "pid") or {}
    if "kv" in gains:
        ctx.g.notices.add(
            f"controller {spec.name!r}: `pid.d` of a velocity loop is not run (the servo is proportional)",
            spec.file,
            line_of(spec.params, "pid.d") or spec.line,
        )
    kp = gains.get("kp")
    return _run(ctx, spec, joints[:1], "velocity", "~/command", False, **({"kv": kp} if kp else {}))


def _ros1_pid_group(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """ROS 1 effort_controllers/JointGroupPositionController: `joints`, a `<joint>: {pid: ...}` block each."""
    check(ctx, spec)
    joints = _joints(ctx, spec, param(spec.params, "joints"), "joints")
    if joints is None:
        return False
    per_joint = [_pid(ctx, spec, param(spec.params, f"{j}.pid"), f"{j}.pid") or {} for j in joints]
    gains = per_joint[0]
    if any(g != gains for g in per_joint[1:]):
        ctx.say(
            spec,
            f"controller {spec.name!r}: the joints' PID gains differ: each joint gets gains from its inertia "
            "(our default servo) instead",
        )
        gains = {}
    return _run(ctx, spec, joints, "position", "~/command", **gains)


def multi_interface(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """MultiInterfaceForwardCommandController: one joint, several interfaces, `~/commands` (one value per
    interface). With one interface it is a forward command controller; with several it is said."""
    check(ctx, spec)
    p = read(spec)
    joints = _joints(ctx, spec, p["joint"], "joint")
    names = [str(i) for i in p["interface_names"] or []]
    if joints is None:
        return False
    if len(names) == 1 and names[0] in _MODES:
        return _run(ctx, spec, joints[:1], names[0], "~/commands")
    ctx.say(
        spec,
        f"multi_interface_forward_command_controller {spec.name!r} commands {names} at once on one joint: "
        "not run (a joint here takes one command interface at a time)",
        hint="use one forward_command_controller per interface",
    )
    return False


HANDLERS: dict[str, Handler] = {
    "forward_command_controller/ForwardCommandController": forward_command_controller,
    "forward_command_controller/MultiInterfaceForwardCommandController": multi_interface,
    "position_controllers/JointGroupPositionController": _group("position"),
    "velocity_controllers/JointGroupVelocityController": _group("velocity"),
    "effort_controllers/JointGroupEffortController": _group("effort"),
    "effort_controllers/JointGroupPositionController": _group("position"),
    "position_controllers/JointPositionController": _ros1_joint("position"),
    "velocity_controllers/JointVelocityController": _ros1_joint("velocity"),
    "effort_controllers/JointEffortController": _ros1_joint("effort"),
    "effort_controllers/JointPositionController": ros1_effort_position,
    "effort_controllers/JointVelocityController": ros1_effort_velocity,
}
