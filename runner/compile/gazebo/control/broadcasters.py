"""Broadcasters: joint_state_broadcaster (ROS 2) and joint_state_controller (ROS 1) -> `joint_states`."""

from __future__ import annotations

from runner.compile.gazebo.control import ControlContext, ControllerSpec, Handler


def joint_state_broadcaster(ctx: ControlContext, spec: ControllerSpec) -> bool:
    p = spec.params
    rate = p.get("publish_rate") if spec.ros1 else spec.update_rate
    js = {"topic": ctx.topic("joint_states"), "joints": p.get("joints") or None, "rate": rate}
    ctx.add(spec, "joint_states", {k: v for k, v in js.items() if v})
    return True


HANDLERS: dict[str, Handler] = {
    "joint_state_broadcaster/JointStateBroadcaster": joint_state_broadcaster,
    "joint_state_controller/JointStateController": joint_state_broadcaster,
}
