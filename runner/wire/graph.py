"""The run's graph: which process publishes and subscribes to which key, told by Zenoh liveliness tokens.

Every process of a run (worlds, renderers, nodes, bridges, the recorder, the command-line tools) declares
one token for itself and one for each publisher and subscriber it holds, so anyone on the run's network
can draw the graph (`scenario graph`) or count a topic's publishers (`scenario topics`) with one liveliness
query, and the tokens vanish with the process, whatever way it ends.

Token keys, under the run's verbatim `@meta` chunk:
- `<run>/@meta/graph/<process>/<role>` for the process;
- `<run>/@meta/graph/<process>/<role>/<pub|sub|srv>/<key>/<type>` for an endpoint (`srv`: a service
  it answers, its type `pkg/srv/Name`),
where each part is percent-quoted into one chunk (a key's `/` and wildcards included) and `<type>` is the
ROS 2 type or `-` when the endpoint does not say.
"""

from __future__ import annotations

import contextlib
import time
from dataclasses import dataclass, field
from typing import Any
from urllib.parse import quote, unquote

import zenoh

from runner.wire.transport import hidden_topic, meta_key

ROLES = ("world", "renderer", "node", "bridge", "recorder", "tool")


def _q(text: str) -> str:
    return quote(text, safe="")


@dataclass(frozen=True)
class Endpoint:
    process: str
    kind: str  # "pub" | "sub" | "srv"
    key: str  # a key expression (subscribers may use wildcards)
    type: str | None = None


# the service by which an action shows in the graph: rcl_action's `<name>/_action/send_goal`
ACTION_FACE = "/_action/send_goal"


@dataclass(frozen=True)
class Offered:
    """A service or an action server of the run: its key, type (pkg/srv/Name, pkg/action/Name; None when
    its server did not say), kind ("service" | "action") and the processes that answer it."""

    key: str
    type: str | None
    kind: str
    servers: list[str]


@dataclass
class Graph:
    run: str
    processes: dict[str, str] = field(default_factory=dict)  # name -> role
    endpoints: set[Endpoint] = field(default_factory=set)

    def add_token(self, token: str) -> None:
        """Take in one token key (anything not of the graph is ignored)."""
        prefix = meta_key(self.run, "graph") + "/"
        if not token.startswith(prefix):
            return
        parts = [unquote(p) for p in token[len(prefix) :].split("/")]
        if len(parts) >= 2:
            self.processes.setdefault(parts[0], parts[1])
        if len(parts) == 5 and parts[2] in ("pub", "sub", "srv"):
            self.endpoints.add(Endpoint(parts[0], parts[2], parts[3], None if parts[4] == "-" else parts[4]))

    def visible(self) -> Graph:
        """Without the run's own helper topics (`_truth`, `_contacts`: a chunk starting with `_`), which
        rqt_graph would hide as well."""
        prefix = self.run + "/"

        def shown(e: Endpoint) -> bool:
            rel = e.key.removeprefix(prefix)
            if e.kind == "srv" and rel.endswith(ACTION_FACE):
                rel = rel.removesuffix(ACTION_FACE)  # an action is shown by its send_goal service
            return not hidden_topic(rel)

        return Graph(self.run, dict(self.processes), {e for e in self.endpoints if shown(e)})

    def topics(self) -> dict[str, str | None]:
        """Every concrete key: published, or subscribed without wildcards; with its type when known."""
        out: dict[str, str | None] = {}
        for e in sorted(self.endpoints, key=lambda e: (e.key, e.kind != "pub")):
            if "*" in e.key or e.kind == "srv":
                continue
            if out.get(e.key) is None:
                out[e.key] = e.type
        return out

    def services(self) -> dict[str, str | None]:
        """Every service key, with its type when known."""
        return {e.key: e.type for e in sorted(self.endpoints, key=lambda e: e.key) if e.kind == "srv"}

    def servers(self, key: str) -> list[str]:
        return sorted({e.process for e in self.endpoints if e.kind == "srv" and e.key == key})

    def offered(self, every: bool = False) -> list[Offered]:
        """The services and actions answered in the run, by key. An action (rcl_action's three services
        under `<name>/_action/`) is one entry, of its action type, named by its `send_goal` service;
        `every`: each of its services as well, and the run's hidden ones (a chunk starting with `_`)."""
        out = []
        prefix = self.run + "/"
        for key, type_name in self.services().items():
            rel = key.removeprefix(prefix)
            if rel.endswith(ACTION_FACE):
                base = key.removesuffix(ACTION_FACE)
                action = type_name.removesuffix("_SendGoal") if type_name else None
                if every or not hidden_topic(base.removeprefix(prefix)):
                    out.append(Offered(base, action, "action", self.servers(key)))
                if not every:
                    continue
            if every or not hidden_topic(rel):
                out.append(Offered(key, type_name, "service", self.servers(key)))
        return sorted(out, key=lambda o: (o.key, o.kind))

    def publishers(self, key: str) -> list[str]:
        return sorted({e.process for e in self.endpoints if e.kind == "pub" and e.key == key})

    def subscribers(self, key: str) -> list[str]:
        return sorted({e.process for e in self.endpoints if e.kind == "sub" and intersects(e.key, key)})


def intersects(a: str, b: str) -> bool:
    if a == b:
        return True
    try:
        return bool(zenoh.KeyExpr(a).intersects(zenoh.KeyExpr(b)))
    except Exception:
        return False


def member_key(run: str, zid: str) -> str:
    """The liveliness token by which a Zenoh session says it is part of the run (its Zenoh id): the runner
    tells a publisher outside the run by its absence."""
    return meta_key(run, "member", zid)


class GraphTokens:
    """The tokens of one process. Declare endpoints as they are made; `close()` (or the process's end)
    withdraws them all."""

    def __init__(self, session: zenoh.Session, run: str, process: str, role: str):
        self.session = session
        self.base = f"{meta_key(run, 'graph')}/{_q(process)}/{_q(role)}"
        self._tokens: dict[str, Any] = {}
        self._declare(self.base)
        # this session is the run's (runner.launch.outside)
        self._declare(member_key(run, str(session.zid())))

    def _declare(self, key: str) -> None:
        if key not in self._tokens:
            self._tokens[key] = self.session.liveliness().declare_token(key)

    def publisher(self, key: str, type_name: str | None = None) -> None:
        self._declare(f"{self.base}/pub/{_q(key)}/{_q(type_name or '-')}")

    def subscriber(self, key: str, type_name: str | None = None) -> None:
        self._declare(f"{self.base}/sub/{_q(key)}/{_q(type_name or '-')}")

    def service(self, key: str, type_name: str | None = None) -> None:
        self._declare(f"{self.base}/srv/{_q(key)}/{_q(type_name or '-')}")

    def withdraw_subscriber(self, key: str, type_name: str | None = None) -> None:
        self.withdraw("sub", key, type_name)

    def withdraw(self, kind: str, key: str, type_name: str | None = None) -> None:
        """The token of an endpoint (`pub`, `sub`, `srv`) that is no more."""
        token = self._tokens.pop(f"{self.base}/{kind}/{_q(key)}/{_q(type_name or '-')}", None)
        if token is not None:
            with contextlib.suppress(Exception):
                token.undeclare()

    def close(self) -> None:
        for token in self._tokens.values():
            with contextlib.suppress(Exception):
                token.undeclare()
        self._tokens.clear()

    undeclare = close  # sits among a process's other Zenoh entities


def query_graph(session: zenoh.Session, run: str, timeout_s: float = 2.0) -> Graph:
    """The graph of a run as the network knows it now."""
    graph = Graph(run)
    replies = session.liveliness().get(meta_key(run, "graph", "**"), timeout=timeout_s)
    for reply in replies:
        with contextlib.suppress(Exception):
            graph.add_token(str(reply.ok.key_expr))
    return graph


def wait_for(session: zenoh.Session, run: str, check: Any, timeout_s: float = 5.0) -> Graph:
    """Query the graph until `check(graph)` holds (or the time is up): tokens of a process just started
    take a moment to reach the router."""
    deadline = time.monotonic() + timeout_s
    while True:
        graph = query_graph(session, run)
        if check(graph) or time.monotonic() > deadline:
            return graph
        time.sleep(0.05)
