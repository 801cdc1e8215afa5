"""What the three drawings of a run's graph share: the topics (sorted, grouped by namespace), the
processes with their roles, the edges publisher -> topic -> subscriber, the services and actions with
the processes that answer them, and the colours of each role.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from runner.wire.graph import Graph, Offered

# role -> (fill, outline); anything else (a process only seen through its endpoints) is grey
ROLE_COLORS: dict[str, tuple[str, str]] = {
    "world": ("#cfe2ff", "#1f5fbf"),
    "renderer": ("#e6d5f7", "#6f42c1"),
    "node": ("#d3f0d8", "#2b8a3e"),
    "bridge": ("#ffe3c4", "#d9480f"),
    "recorder": ("#f9d2d2", "#c92a2a"),
    "tool": ("#fff1a8", "#b08800"),
}
UNKNOWN_COLORS = ("#e9ecef", "#6c757d")
LEFT_ROLES = ("world", "renderer", "bridge")  # where a process goes when its edges do not decide

TOPIC_FILL, TOPIC_LINE = "#f8f9fa", "#495057"
EDGE = (60, 70, 85)
EDGE_WILD = (165, 175, 190)
EDGE_BACK = (214, 88, 16)
EDGE_BACK_WILD = (240, 175, 130)
TEXT, TEXT_DIM = (33, 37, 41), (90, 98, 108)


@dataclass(frozen=True)
class Topic:
    key: str  # the full key
    rel: str  # the key inside the run
    type: str | None
    group: str  # first chunk of `rel` when it has several ("r1"), "" for the run's own topics


@dataclass(frozen=True)
class Edge:
    process: str
    key: str
    kind: str  # "pub" (process -> topic) | "sub" (topic -> process)
    wildcard: bool  # a subscription only through a wildcard key expression


@dataclass
class GraphModel:
    run: str
    topics: list[Topic]
    processes: dict[str, str]  # name -> role ("?" when unknown), sorted by name
    edges: list[Edge]
    wildcards: dict[str, list[str]] = field(default_factory=dict)  # process -> its wildcard subscriptions
    # services and actions (an action once, by its name: `Graph.offered`), with the processes answering
    services: list[Offered] = field(default_factory=list)


def relative_key(run: str, key: str) -> str:
    """`<run>/r1/scan` -> `r1/scan`; a key outside the run stays whole."""
    return key[len(run) + 1 :] if key.startswith(run + "/") else key


def short_type(type_name: str | None) -> str:
    """`sensor_msgs/msg/LaserScan` -> `sensor_msgs/LaserScan`; "" when unknown."""
    if not type_name:
        return ""
    parts = type_name.split("/")
    if len(parts) == 3 and parts[1] == "msg":
        return f"{parts[0]}/{parts[2]}"
    return type_name


def build_model(graph: Graph) -> GraphModel:
    topics = []
    for key, type_name in graph.topics().items():
        rel = relative_key(graph.run, key)
        chunks = rel.split("/")
        topics.append(Topic(key, rel, type_name, chunks[0] if len(chunks) > 1 else ""))
    topics.sort(key=lambda t: (t.group != "", t.group, t.rel))

    processes = dict(graph.processes)
    for e in graph.endpoints:
        processes.setdefault(e.process, "?")
    processes = dict(sorted(processes.items()))

    exact_subs = {(e.process, e.key) for e in graph.endpoints if e.kind == "sub"}
    edges = []
    for t in topics:
        edges += [Edge(p, t.key, "pub", False) for p in graph.publishers(t.key)]
        edges += [Edge(p, t.key, "sub", (p, t.key) not in exact_subs) for p in graph.subscribers(t.key)]

    wildcards: dict[str, list[str]] = {}
    for e in sorted(graph.endpoints, key=lambda e: (e.process, e.key)):
        if e.kind == "sub" and "*" in e.key:
            wildcards.setdefault(e.process, []).append(relative_key(graph.run, e.key))
    return GraphModel(graph.run, topics, processes, edges, wildcards, graph.offered())
