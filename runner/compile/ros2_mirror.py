"""`ros2: {topics: all}`: what of a run ROS 2 sees, as `BridgePlan`s (topics) and `ServiceBridgePlan`s
(services; an action as its three services, its two topics among the topics)."""

from __future__ import annotations

from runner.compile.plugins import action_topics as action_topics_of
from runner.plan import BridgePlan, Ros2Plan, RunPlan, ServiceBridgePlan
from runner.wire import interfaces, msgs
from runner.wire.transport import hidden_topic, topic_key

TF = "tf2_msgs/msg/TFMessage"


def mirror_services(plan: RunPlan, ros2: Ros2Plan) -> list[ServiceBridgePlan]:
    """`ros2: {topics: all}`: every service the worlds answer as `/<ns>/<service>`, each action as its
    three services (its topics are mirrored with the others)."""
    out = []
    for part in plan.parts():
        for s in part.services():
            rel = s.key[len(part.name) + 1 :]
            pairs = (
                [(f"{s.key}/{suffix}", t) for suffix, t in interfaces.action_parts(s.type)[0]]
                if s.kind == "action"
                else [(s.key, s.type)]
            )
            for key, type_name in pairs:
                name = "/" + key[len(part.name) + 1 :]
                out.append(
                    ServiceBridgePlan(
                        where=f"ros2 ({rel}, {s.owner})",
                        sim_key=key,
                        type=type_name,
                        ros_name=name,
                        ros2=ros2,
                    )
                )
    return out


def mirror_all(
    table_in: dict[str, tuple[str, set[str]]], run: str, ros2: Ros2Plan, plan: RunPlan
) -> list[BridgePlan]:
    """`ros2: {topics: all}`: every sim topic as `/<ns>/<topic>`, in the directions the sim uses it; what
    the world publishes for viewers (the world's `tf`/`tf_static`, each robot's `robot_description`); and
    every robot's transforms on `/tf` and `/tf_static` too, where RViz, tf2 and `ros2 run tf2_ros
    tf2_echo` look for them (frames are namespaced, `r1/base_link`, so the robots' trees do not clash)."""
    table = dict(table_in)
    for part in plan.parts():
        if part.foxglove.scene:
            for name in ("tf", "tf_static"):
                table.setdefault(f"{part.name}/{name}", (TF, {"pub"}))
            for r in part.robots:
                if r.urdf:
                    key = topic_key(part.name, r.namespace, "robot_description")
                    table.setdefault(key, ("std_msgs/msg/String", {"pub"}))
    out = []
    # an action's topics are under `_action/`, hidden as ROS 2 hides them from `ros2 topic list`, but its
    # clients subscribe to them
    action_topics = {t.key for part in plan.parts() for t in action_topics_of(part.services())}
    for key, (type_name, directions) in sorted(table.items()):
        rel = key[len(run) + 1 :]
        if (hidden_topic(rel) and key not in action_topics) or not msgs.is_known(type_name):
            continue  # (the Foxglove scene is not a ROS 2 type)
        direction = (
            "BIDIRECTIONAL"
            if directions == {"pub", "sub"}
            else ("SIM_TO_ZENOH" if "pub" in directions else "ZENOH_TO_SIM")
        )
        out.append(
            BridgePlan(
                where=f"ros2 ({rel})",
                sim_key=key,
                type=type_name,
                direction=direction,  # type: ignore[arg-type]
                ros_topic="/" + rel,
                ros2=ros2,
            )
        )
        last = rel.rsplit("/", 1)[-1]
        if type_name == TF and "pub" in directions and last in ("tf", "tf_static") and rel != last:
            out.append(
                BridgePlan(
                    where=f"ros2 ({rel} on /{last})",
                    sim_key=key,
                    type=TF,
                    direction="SIM_TO_ZENOH",
                    ros_topic="/" + last,
                    ros2=ros2,
                )
            )
    return out
