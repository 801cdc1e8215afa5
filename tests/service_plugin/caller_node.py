"""A lockstep node that asks the flipper plugin's services (tests/test_service_tools.py): three `flip`
calls, a `fail` call, a `grip` goal with feedback; what it got is published on `calls` (recorded)."""

from __future__ import annotations

from runner.node import Node, ServiceCallError

with Node() as node:
    out = node.publisher("calls", "std_msgs/msg/String")
    for i in range(3):
        node.sleep(0.05)
        response = node.call("flip", "std_srvs/srv/SetBool", {"data": i % 2 == 0})
        out.publish({"data": f"{response.success} {response.message} (asked at {node.now_ns})"})
    try:
        node.call("fail", "std_srvs/srv/Trigger")
    except ServiceCallError as e:
        out.publish({"data": f"error {e}"})
    feedback: list[float] = []
    grip = node.action_client("grip", "control_msgs/action/GripperCommand")
    goal = grip.send_goal({"command": {"position": 0.25}}, feedback=lambda fb: feedback.append(fb.position))
    end = goal.result()
    out.publish({"data": f"{goal.accepted} {end.status_name} {end.result.reached_goal} {len(feedback)}"})
    node.sleep(0.05)
