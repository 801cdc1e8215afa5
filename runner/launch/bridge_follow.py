"""What of the run's graph the bridge mirrors to ROS 2 as it changes (`ros2: {topics: all}`).

The plan (runner.compile.ros2_mirror) says what is mirrored from the start. What the worlds and nodes
declare later (a robot spawned into a running world, a node started) is announced by their graph tokens
(`runner.wire.graph`): each is mirrored as `mirror_all` / `mirror_services` mirror the plan's, and goes
when the last process holding its token withdraws it (a robot deleted with `ZenohBus.withdraw`, a node
stopped)."""

from __future__ import annotations

from runner.plan import BridgePlan, Ros2Plan, ServiceBridgePlan
from runner.wire import interfaces, msgs
from runner.wire.graph import Endpoint, Graph
from runner.wire.transport import hidden_topic

TF = "tf2_msgs/msg/TFMessage"
# the processes whose endpoints are followed as they come and go (a renderer process publishes the
# cameras' images of its world)
MIRRORED_ROLES = ("world", "renderer", "node")
# an action's topics and services are under `<name>/_action/`: hidden, as ROS 2 hides them from `ros2 topic
# list`, but its clients use them (`mirror_all`'s `action_topics`, `mirror_services`' `action_parts`)
ACTION_TOPICS = tuple("/" + suffix for suffix, _t in interfaces.ACTION_TOPICS)
ACTION_SERVICES = tuple("/" + suffix for suffix, _t in interfaces.ACTION_SERVICES)


def endpoint_of(run: str, token: str) -> tuple[Endpoint, str] | None:
    """The endpoint a graph token announces and its process's role; None for a process's own token or
    one of a process not followed."""
    graph = Graph(run)
    graph.add_token(token)
    if not graph.endpoints:
        return None
    e = next(iter(graph.endpoints))
    role = graph.processes.get(e.process, "")
    return (e, role) if role in MIRRORED_ROLES else None


def _rel(run: str, key: str) -> str:
    return key[len(run) + 1 :] if key.startswith(run + "/") else ""


def topic_plans(e: Endpoint, role: str, run: str, ros: Ros2Plan) -> list[BridgePlan]:
    """A published (SIM_TO_ZENOH) or subscribed (ZENOH_TO_SIM) topic as `/<ns>/<topic>`, a robot's `tf`
    and `tf_static` on `/tf` and `/tf_static` too; nothing for a hidden topic (but an action's), a
    wildcard, or a type ROS 2 would not know."""
    rel = _rel(run, e.key)
    if e.kind not in ("pub", "sub") or not rel or "*" in rel or not e.type or not msgs.is_known(e.type):
        return []
    if hidden_topic(rel) and not rel.endswith(ACTION_TOPICS):
        return []
    out = [
        BridgePlan(
            where=f"ros2 (/{rel}, {role} {e.process})",
            sim_key=e.key,
            type=e.type,
            direction="SIM_TO_ZENOH" if e.kind == "pub" else "ZENOH_TO_SIM",
            ros_topic="/" + rel,
            ros2=ros,
        )
    ]
    last = rel.rsplit("/", 1)[-1]
    if e.kind == "pub" and e.type == TF and last in ("tf", "tf_static") and rel != last:
        out.append(
            BridgePlan(
                where=f"ros2 (/{rel} on /{last}, {role} {e.process})",
                sim_key=e.key,
                type=TF,
                direction="SIM_TO_ZENOH",
                ros_topic="/" + last,
                ros2=ros,
            )
        )
    return out


def service_plan(
    e: Endpoint, role: str, run: str, parts: list[str], ros: Ros2Plan
) -> ServiceBridgePlan | None:
    """A service (an action's three services each, as the world declares them) as `/<ns>/<service>`,
    named under its world as `mirror_services` names it (`parts`: the worlds' names, `<run>` or
    `<run>/<world>`), a node's under the run; None for a hidden one, a wildcard or an unknown type."""
    rel = _rel(run, e.key)
    if e.kind != "srv" or not rel or "*" in rel or not e.type or not interfaces.known_service(e.type):
        return None
    if hidden_topic(rel) and not rel.endswith(ACTION_SERVICES):
        return None
    part = run
    if role == "world":
        part = next((p for p in sorted(parts, key=len, reverse=True) if e.key.startswith(p + "/")), run)
    return ServiceBridgePlan(
        where=f"ros2 (/{rel}, {role} {e.process})",
        sim_key=e.key,
        type=e.type,
        ros_name="/" + e.key[len(part) + 1 :],
        ros2=ros,
    )


class Holders:
    """Which processes hold each endpoint's token: what is mirrored of it goes with the last."""

    def __init__(self) -> None:
        self._of: dict[tuple[str, str], set[str]] = {}

    def hold(self, e: Endpoint) -> None:
        self._of.setdefault((e.kind, e.key), set()).add(e.process)

    def let_go(self, e: Endpoint) -> bool:
        """Whether `e`'s process was the last to hold it."""
        held = self._of.get((e.kind, e.key))
        if held is None:
            return False
        held.discard(e.process)
        if held:
            return False
        del self._of[(e.kind, e.key)]
        return True
