"""The bridge process: `python -m runner.launch.bridge`, started by `scenario run` as a node of the run when
the scenario has `bridges:` or `ros2:`.

It reads its mappings (`BridgePlan`s, resolved at compile time) from `SCENARIO_BRIDGE` and joins the run
at `SCENARIO_ENDPOINT` (and a ROS 2 Zenoh router, if one is named). For each mapping:
- SIM_TO_ZENOH: a subscriber on the sim key, a publisher on the other key; the message passes on as the
  same CDR bytes, or as JSON; throttled to `rate` messages per sim second (by the sim stamps); `lazy`
  subscribes to the sim only while something subscribes on the other side.
- ZENOH_TO_SIM: a subscriber on the other key (wildcards allowed), a publisher on the sim key; each message
  is checked against the type (JSON is converted to CDR) and stamped with the sim time, as the timeline
  and the command-line tools stamp theirs.
- with `ros2`, the other side speaks rmw_zenoh (`runner.wire.ros2`): its key, liveliness tokens for the node
  and each publisher/subscription (so `ros2 topic list` sees them), its attachment on every message.
- with `ros2: {topics: all}`, also what the worlds and nodes declare mid-run (a robot spawned, a node
  started), as their graph tokens appear, until they are withdrawn (a robot deleted, a node stopped):
  `runner.launch.bridge_follow`.

Subscriptions take only messages from other processes, so a BIDIRECTIONAL mapping never feeds itself.
The process is ready (and the run starts) once everything is declared: nothing the world publishes first
is missed. Copies keep the sim topic's QoS (reliable unless `qos:` says best effort). It stops on
SIGINT/SIGTERM (forwarding what is still on its way first) or when its runner goes away.
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import zenoh
import zenoh.ext

from runner.launch.bridge_follow import Holders, endpoint_of, service_plan, topic_plans
from runner.launch.bridge_ros2 import RosNode, RosOut
from runner.plan import BridgePlan, Ros2Plan, ServiceBridgePlan
from runner.wire import msgs, ros2
from runner.wire.graph import Endpoint, GraphTokens
from runner.wire.transport import (
    encoding_for,
    make_config,
    meta_key,
    pack_attachment,
    service_encoding,
    unpack_attachment,
)

REMOTE = zenoh.Locality.REMOTE
LINGER_QUIET_S = 0.2  # on stop, leave once nothing was forwarded for this long...
LINGER_MAX_S = 0.8  # ...or after this (within the runner's STOP_GRACE_S)
TF = "tf2_msgs/msg/TFMessage"
SERVICE_TIMEOUT_S = 30.0  # how long a request waits for the world (a paused world answers at once)


def _json_default(value: Any) -> Any:
    if isinstance(value, bytes | bytearray | memoryview):
        return base64.b64encode(bytes(value)).decode()
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON")


class _Complaints:
    """Bad input from outside is said once per mapping (then counted), never fatal."""

    def __init__(self) -> None:
        self.said: dict[str, int] = {}

    def __call__(self, where: str, message: str) -> None:
        n = self.said.get(where, 0)
        self.said[where] = n + 1
        if n == 0:
            print(f"bridge: {where}: {message} (dropped; said once)", file=sys.stderr, flush=True)


Ident = tuple[str, str, str]  # a mapping: (sim key, other side's key or ROS 2 topic, direction)


class Bridge:
    def __init__(
        self,
        session: zenoh.Session,
        run: str,
        clocks: list[str],
        plans: list[BridgePlan],
        services: Sequence[ServiceBridgePlan] = (),
        mirror: Ros2Plan | None = None,
    ):
        """`mirror` (`ros2: {topics: all}`): besides `plans` and `services`, what the worlds and nodes
        publish, subscribe to and answer as their graph tokens appear (a robot spawned, a node started),
        and no more once they are withdrawn (a robot deleted, a node stopped)."""
        self.session = session
        self.run = run
        self.sim_ns = 0
        self.complain = _Complaints()
        self.graph = GraphTokens(session, run, os.environ.get("SCENARIO_NODE", "bridge"), "bridge")
        self._keep: list[Any] = []
        self._ros_nodes: dict[tuple[int, str, str | None], RosNode] = {}
        self._ros_outs: dict[str, RosOut] = {}  # ROS 2 key -> its one publisher
        self.forwarded: dict[str, int] = {}
        self.last_forward = 0.0  # time.monotonic() of the last message forwarded, either way
        for clock in clocks:
            self._keep.append(session.declare_subscriber(clock, self._on_clock))
        # the worlds' names (`<run>`, or `<run>/<world>` each): a service is named under its world's
        self._parts = [c.removesuffix("/clock") for c in clocks]
        self._seen: set[Ident] = set()
        self._lock = threading.Lock()
        for p in plans:
            self._add(p)
        # the sim keys the plan mirrors to ROS 2: a world's (or its renderer's) endpoint on one of them is
        # the plan's to map
        self._planned = {p.sim_key for p in plans if p.ros2 is not None}
        self._served: set[str] = set()  # the sim keys of the services offered or waiting to be
        # a service is offered to ROS 2 once the world answers it (its graph token, declared after its
        # queryable): a client that finds the SS token and calls at once is answered, not left waiting
        self._pending: dict[str, ServiceBridgePlan] = {}
        for sp in services:
            self._served.add(sp.sim_key)
            self._pending[sp.sim_key] = sp
        self._mirror = mirror
        # what was mirrored as a token appeared, undone when the last token of its endpoint goes
        self._holders = Holders()
        self._dynamic: dict[Ident, list[Any]] = {}  # mapping -> its entities
        self._idents_of: dict[tuple[str, str], list[Ident]] = {}  # (pub|sub, sim key) -> its mappings
        self._dynamic_services: dict[str, list[Any]] = {}  # sim key -> its entities
        self._closing = False
        if self._pending or mirror is not None:
            # one subscription follows the run's graph for both
            key = meta_key(run, "graph", "**")
            self._keep.append(session.liveliness().declare_subscriber(key, self._on_token, history=True))

    def _on_token(self, sample: zenoh.Sample) -> None:
        found = endpoint_of(self.run, str(sample.key_expr))
        if found is None:
            return
        e, role = found
        put = sample.kind == zenoh.SampleKind.PUT
        with self._lock:
            if self._closing:
                return
            if put and e.kind == "srv":
                sp = self._pending.pop(e.key, None)
                if sp is not None:
                    try:
                        self._serve_ros(sp, self._keep)
                    except Exception as err:  # (the session closing as the run ends)
                        self.complain(sp.where, f"could not offer the service: {err}")
            if self._mirror is not None:
                (self._follow_endpoint if put else self._forget_endpoint)(e, role, self._mirror)

    def _follow_endpoint(self, e: Endpoint, role: str, ros: Ros2Plan) -> None:
        """A world's or node's endpoint that appeared, mirrored (under `self._lock`)."""
        if e.kind == "srv":
            sp = service_plan(e, role, self.run, self._parts, ros)
            if sp is None:
                return
            self._holders.hold(e)
            if e.key in self._served:
                return  # (the plan's, or a node's answering it too)
            self._served.add(e.key)
            held = self._dynamic_services[e.key] = []
            try:
                self._serve_ros(sp, held)
            except Exception as err:  # (the session closing as the run ends)
                self._undo(held)
                self._dynamic_services.pop(e.key, None)
                self._served.discard(e.key)
                self.complain(sp.where, f"could not offer the service: {err}")
            return
        plans = topic_plans(e, role, self.run, ros)
        if not plans or (role != "node" and e.key in self._planned):
            return  # (a world's topic the plan mirrors since the start, as it says)
        self._holders.hold(e)
        for p in plans:
            self._idents_of.setdefault((e.kind, e.key), []).extend(self._add(p, dynamic=True))

    def _forget_endpoint(self, e: Endpoint, _role: str, _ros: Ros2Plan) -> None:
        """A token withdrawn: once no world or node holds the endpoint any more, what it was mirrored as
        goes (under `self._lock`), and comes again with a new token (a robot spawned again)."""
        if not self._holders.let_go(e):
            return
        if e.kind == "srv":
            held = self._dynamic_services.pop(e.key, None)
            if held is not None:
                self._served.discard(e.key)
                self._undo(held)
            return
        for ident in self._idents_of.pop((e.kind, e.key), []):
            held = self._dynamic.pop(ident, None)
            self._seen.discard(ident)
            if held is not None:
                self._undo(held)

    @staticmethod
    def _undo(held: list[Any]) -> None:
        for ent in reversed(held):
            with contextlib.suppress(Exception):
                ent.undeclare()
        held.clear()

    def _add(self, p: BridgePlan, dynamic: bool = False) -> list[Ident]:
        """Map `p` in each of its directions not mapped yet; the mappings made. `dynamic`: each keeps its
        entities apart (in `_dynamic`), to be undone on its own."""
        other = p.ros_topic if p.ros2 else p.key
        directions = ("SIM_TO_ZENOH", "ZENOH_TO_SIM") if p.direction == "BIDIRECTIONAL" else (p.direction,)
        made = []
        for direction in directions:
            ident = (p.sim_key, str(other), direction)
            if ident in self._seen:
                continue
            self._seen.add(ident)
            held = self._keep if not dynamic else self._dynamic.setdefault(ident, [])
            try:
                (self._outbound if direction == "SIM_TO_ZENOH" else self._inbound)(p, held)
            except Exception as err:
                if not dynamic:
                    raise
                self._undo(held)  # (the session closing as the run ends)
                self._dynamic.pop(ident, None)
                self._seen.discard(ident)
                self.complain(p.where, f"could not mirror the topic: {err}")
                continue
            made.append(ident)
        return made

    def _on_clock(self, sample: zenoh.Sample) -> None:
        att = unpack_attachment(sample.attachment.to_bytes()) if sample.attachment is not None else None
        if att is not None and att[1] > self.sim_ns:
            self.sim_ns = att[1]

    def _ros_node(self, plan: Ros2Plan) -> RosNode:
        ident = (plan.domain, plan.node, plan.router)
        node = self._ros_nodes.get(ident)
        if node is None:
            node = self._ros_nodes[ident] = RosNode(self.session, plan, len(self._ros_nodes))
            self._keep.append(node.token)
        return node

    def _ros_entity(self, p: BridgePlan, kind: str, qos: ros2.Qos | None = None) -> tuple[str, bytes, Any]:
        """The rmw_zenoh key of a mapping's ROS 2 side, with its entity announced ("MP"/"MS") with `qos`
        (the default QoS if None); its GID, and its liveliness token."""
        assert p.ros2 is not None and p.ros_topic is not None
        token, gid = self._ros_node(p.ros2).entity(kind, p.ros_topic, p.type, qos or ros2.Qos())
        return ros2.topic_key(p.ros2.domain, p.ros_topic, p.type), gid, token

    def _ros_out(self, p: BridgePlan, keep: list[Any]) -> RosOut:
        """The ROS 2 publisher of a mapping's topic, made by the first mapping to it; it goes when the last
        mapping that uses it is undone (`keep` holds its part in that)."""
        assert p.ros2 is not None and p.ros_topic is not None
        key = ros2.topic_key(p.ros2.domain, p.ros_topic, p.type)
        out = self._ros_outs.get(key)
        if out is None:
            out = self._new_ros_out(p)
        out.users += 1
        keep.append(_Undeclare(lambda: self._release(out, p.sim_key)))
        return out

    def _release(self, out: RosOut, source: str) -> None:
        out.users -= 1
        if not self._closing:
            with contextlib.suppress(Exception):  # (the session closing as the run ends)
                out.forget(source)
        if out.users > 0 or self._ros_outs.get(out.key) is not out:
            return
        del self._ros_outs[out.key]
        for ent in (out.pub, out.token):
            with contextlib.suppress(Exception):
                ent.undeclare()
        self.graph.withdraw("pub", out.key, out.type)

    def _new_ros_out(self, p: BridgePlan) -> RosOut:
        assert p.ros_topic is not None
        qos = ros2.topic_qos(p.ros_topic)
        key, gid, token = self._ros_entity(p, "MP", qos)
        # as rmw_zenoh does for the KEEP_LAST history its tokens announce: drop rather than block
        drop = zenoh.CongestionControl.DROP
        latched = qos.durability == "transient_local"
        if latched:
            # as rmw_zenoh does for TRANSIENT_LOCAL: zenoh-ext's advanced publisher keeps the last `depth`
            # messages in a cache (a queryable under `<key>/@adv/pub/<zid>/...`) that a late subscriber
            # queries, and announces itself for publisher detection
            pub: Any = zenoh.ext.declare_advanced_publisher(
                self.session,
                key,
                congestion_control=drop,
                cache=zenoh.ext.CacheConfig(max_samples=qos.depth),
                publisher_detection=True,
            )
        else:
            pub = self.session.declare_publisher(key, congestion_control=drop)
        self.graph.publisher(key, p.type)
        out = self._ros_outs[key] = RosOut(key, p.type, pub, token, gid, merge_tf=latched and p.type == TF)
        return out

    # ---------------------------------------------------------------------------------- sim -> outside
    def _outbound(self, p: BridgePlan, keep: list[Any]) -> None:
        """`keep`: where what it declares is kept, to be undeclared in reverse order."""
        type_name = p.type
        ros_out: RosOut | None = None
        if p.ros2 is not None:
            ros_out = self._ros_out(p, keep)
            pub: Any = ros_out.pub
        else:
            pub = self._zenoh_out(p, keep)
        period_ns = round(1e9 / p.rate) if p.rate else 0
        state = {"seq": 0, "last": None}
        as_json = p.encoding == "json" and p.ros2 is None

        def on_sample(sample: zenoh.Sample) -> None:
            att = unpack_attachment(sample.attachment.to_bytes()) if sample.attachment is not None else None
            stamp = att[1] if att is not None else self.sim_ns
            last = state["last"]
            if period_ns and last is not None and stamp - last < period_ns:
                return
            state["last"] = stamp
            payload: bytes = sample.payload.to_bytes()
            if as_json:
                try:
                    data = msgs.to_data(msgs.decode(payload, type_name))
                except Exception as e:
                    self.complain(p.where, f"a message on {p.sim_key} does not decode as {type_name}: {e}")
                    return
                payload = json.dumps(data, default=_json_default, separators=(",", ":")).encode()
            if ros_out is not None:
                try:
                    ros_out.put(payload, p.sim_key)
                except Exception as e:  # (a TFMessage that does not decode, on a merged topic)
                    self.complain(p.where, f"a message on {p.sim_key} does not decode as {type_name}: {e}")
                    return
            else:
                state["seq"] += 1
                pub.put(payload, attachment=pack_attachment(state["seq"] - 1, stamp))
            self.forwarded[p.where] = self.forwarded.get(p.where, 0) + 1
            self.last_forward = time.monotonic()

        self._follow(p, pub, on_sample, keep)

    def _zenoh_out(self, p: BridgePlan, keep: list[Any]) -> Any:
        """The publisher of a mapping's other side on Zenoh (not ROS 2): CDR, or JSON with the type as its
        encoding's schema."""
        assert p.key is not None
        key, type_name = p.key, p.type
        encoding = (
            encoding_for(type_name)
            if p.encoding == "cdr"
            else zenoh.Encoding.APPLICATION_JSON.with_schema(type_name)
        )
        # the copy keeps the sim topic's QoS: reliable (it waits rather than lose a message, as the
        # world's own publisher does) unless `qos:` made the topic best effort
        pub = self.session.declare_publisher(
            key,
            encoding=encoding,
            congestion_control=zenoh.CongestionControl.DROP
            if p.best_effort
            else zenoh.CongestionControl.BLOCK,
            reliability=zenoh.Reliability.BEST_EFFORT if p.best_effort else zenoh.Reliability.RELIABLE,
        )
        keep.append(pub)
        self.graph.publisher(key, type_name)
        keep.append(_Undeclare(lambda: self.graph.withdraw("pub", key, type_name)))
        return pub

    def _follow(
        self, p: BridgePlan, pub: Any, on_sample: Callable[[zenoh.Sample], None], keep: list[Any]
    ) -> None:
        """Subscribe `on_sample` to the mapping's sim key: for good, or, when `lazy`, only while something
        subscribes to `pub` (a cache that late subscribers read is kept filled: a TRANSIENT_LOCAL topic is
        never lazy)."""
        session, type_name = self.session, p.type
        state: dict[str, Any] = {"sub": None}

        def subscribe() -> None:
            if state["sub"] is None:
                state["sub"] = session.declare_subscriber(p.sim_key, on_sample, allowed_origin=REMOTE)
                self.graph.subscriber(p.sim_key, type_name)  # (a lazy bridge: only while it is)

        def unsubscribe() -> None:
            sub, state["sub"] = state["sub"], None
            if sub is not None:
                self.graph.withdraw_subscriber(p.sim_key, type_name)
                with contextlib.suppress(Exception):
                    sub.undeclare()

        if p.lazy and not isinstance(pub, zenoh.ext.AdvancedPublisher):
            lock = threading.Lock()

            def on_matching(status: Any) -> None:
                with lock:
                    (subscribe if status.matching else unsubscribe)()

            keep.append(pub.declare_matching_listener(on_matching))
            with lock:
                if pub.matching_status.matching:
                    subscribe()
        else:
            subscribe()
        keep.append(_Undeclare(unsubscribe))

    # ---------------------------------------------------------------------------------- outside -> sim
    def _inbound(self, p: BridgePlan, keep: list[Any]) -> None:
        """`keep`: where what it declares is kept, to be undeclared in reverse order."""
        session, type_name = self.session, p.type
        if p.ros2 is not None:
            key, _gid, token = self._ros_entity(p, "MS")
            keep.append(token)
        else:
            assert p.key is not None
            key = p.key
        sim_pub = session.declare_publisher(
            p.sim_key,
            encoding=encoding_for(type_name),
            congestion_control=zenoh.CongestionControl.BLOCK,
            reliability=zenoh.Reliability.RELIABLE,
        )
        keep.append(sim_pub)
        self.graph.subscriber(key, type_name)
        self.graph.publisher(p.sim_key, type_name)
        keep.append(_Undeclare(lambda: self.graph.withdraw("sub", key, type_name)))
        keep.append(_Undeclare(lambda: self.graph.withdraw("pub", p.sim_key, type_name)))
        period_ns = round(1e9 / p.rate) if p.rate else 0
        state = {"seq": 0, "last": None}
        as_json = p.encoding == "json" and p.ros2 is None

        def on_sample(sample: zenoh.Sample) -> None:
            now = self.sim_ns
            last = state["last"]
            if period_ns and last is not None and now - last < period_ns:
                return
            raw = sample.payload.to_bytes()
            try:
                if as_json:
                    payload = msgs.encode(msgs.from_data(type_name, json.loads(raw)), type_name)
                else:
                    msgs.decode(raw, type_name)  # nothing malformed reaches the world
                    payload = raw
            except Exception as e:
                what = "JSON" if as_json else "CDR"
                self.complain(p.where, f"a message on {sample.key_expr} is not {what} of {type_name}: {e}")
                return
            state["last"] = now
            sim_pub.put(payload, attachment=pack_attachment(state["seq"], now))
            state["seq"] += 1
            self.forwarded[p.where] = self.forwarded.get(p.where, 0) + 1
            self.last_forward = time.monotonic()

        keep.append(session.declare_subscriber(key, on_sample, allowed_origin=REMOTE))

    # ---------------------------------------------------------------------------------- ROS 2 services
    def _serve_ros(self, sp: ServiceBridgePlan, keep: list[Any]) -> None:
        """A service the world answers, offered as rmw_zenoh's ServiceData offers one
        (rmw_zenoh_cpp/src/detail/rmw_service_data.cpp, rolling 2025): a queryable on the service's key
        declared `complete`, an `SS` liveliness token, and each reply carrying the request's sequence
        number, a new source timestamp and the client's GID (attachment_helpers.cpp). The request goes on
        to the world's queryable as it came (CDR, and the client's attachment, which the world records);
        the world's reply comes back the same way. An error from the world (a request that does not
        decode, a handler that failed) is a Zenoh error reply, which rmw_zenoh's client logs and drops.
        `keep`: where what it declares is kept, to be undeclared in reverse order."""
        node = self._ros_node(sp.ros2)
        token, _gid = node.entity("SS", sp.ros_name, sp.type, ros2.Qos())
        keep.append(token)
        key = ros2.topic_key(sp.ros2.domain, sp.ros_name, sp.type)
        # get_result waits for the end of the goal (rmw_zenoh's client waits for ever there, too)
        timeout = 10 * 365 * 86400.0 if sp.ros_name.endswith("/_action/get_result") else SERVICE_TIMEOUT_S
        session = self.session

        def on_query(query: zenoh.Query) -> None:
            att = query.attachment.to_bytes() if query.attachment is not None else None
            parsed = ros2.unpack_attachment(att)
            if parsed is None:
                self.complain(sp.where, f"a request on {key} without rmw_zenoh's attachment")
                query.reply_err("rmw_zenoh requests carry an attachment (sequence number, timestamp, GID)")
                query.drop()
                return
            seq, _stamp, gid = parsed
            payload = query.payload.to_bytes() if query.payload is not None else b""
            state = {"answered": False}
            lock = threading.Lock()

            def answer(reply: zenoh.Reply | None) -> None:
                with lock:
                    if state["answered"]:
                        return
                    state["answered"] = True
                try:
                    if reply is not None and reply.ok is not None:
                        out = reply.ok.payload.to_bytes()
                        query.reply(key, out, attachment=ros2.pack_attachment(seq, time.time_ns(), gid))
                    else:
                        why = (
                            reply.err.payload.to_string() if reply is not None and reply.err else "no answer"
                        )
                        query.reply_err(why)
                except Exception as e:  # (the client went away)
                    self.complain(sp.where, f"could not answer a request: {e}")
                finally:
                    query.drop()
                self.last_forward = time.monotonic()

            def on_reply(reply: zenoh.Reply) -> None:
                answer(reply)

            session.get(
                sp.sim_key,
                zenoh.handlers.Callback(on_reply, lambda: answer(None)),
                payload=payload,
                attachment=att,
                timeout=timeout,
                target=zenoh.QueryTarget.ALL_COMPLETE,
                consolidation=zenoh.ConsolidationMode.NONE,
                encoding=service_encoding(f"{sp.type}_Request"),
            )

        keep.append(session.declare_queryable(key, on_query, complete=True))
        self.graph.service(key, sp.type)
        keep.append(_Undeclare(lambda: self.graph.withdraw("srv", key, sp.type)))

    def close(self) -> None:
        with self._lock:
            self._closing = True  # (nothing followed any more, no smaller /tf_static tree sent)
            for held in [*self._dynamic.values(), *self._dynamic_services.values()]:
                self._undo(held)
            self._dynamic.clear()
            self._dynamic_services.clear()
        for ent in reversed(self._keep):
            with contextlib.suppress(Exception):
                ent.undeclare()
        self._keep.clear()
        self.graph.close()


class _Undeclare:
    def __init__(self, fn: Any):
        self.undeclare = fn


def main() -> int:
    try:
        spec = json.loads(os.environ["SCENARIO_BRIDGE"])
        endpoint = os.environ["SCENARIO_ENDPOINT"]
    except (KeyError, ValueError):
        print(
            "runner.launch.bridge is started by `scenario run` (SCENARIO_BRIDGE is not set)", file=sys.stderr
        )
        return 2
    plans = [BridgePlan.model_validate(b) for b in spec["bridges"]]
    services = [ServiceBridgePlan.model_validate(s) for s in spec.get("services", [])]
    routers = sorted(
        {p.ros2.router for p in plans if p.ros2 is not None and p.ros2.router}
        | {s.ros2.router for s in services if s.ros2.router}
    )
    stop = threading.Event()
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    parent = os.getppid()
    # a peer joins several routers (the run's and a ROS 2 one); a client only the first it reaches
    conf = make_config("peer" if routers else "client", connect=[endpoint, *routers])
    if any(p.ros2 is not None for p in plans) or services or spec.get("mirror_nodes"):
        # zenoh-ext's advanced publisher (TRANSIENT_LOCAL topics) stamps its samples, as rmw_zenoh's
        # sessions do (its default config enables timestamping)
        conf.insert_json5("timestamping/enabled", "true")
    with zenoh.open(conf) as session:
        # `mirror_nodes` (`ros2: {topics: all}`): the worlds' endpoints that come and go are followed too
        mirror = Ros2Plan.model_validate(spec["mirror_nodes"]) if spec.get("mirror_nodes") else None
        bridge = Bridge(session, spec["run"], list(spec["clocks"]), plans, services, mirror)
        ready = session.liveliness().declare_token(meta_key(spec["run"], "bridge", "alive"))
        try:
            while not stop.wait(0.2):
                if os.getppid() != parent:
                    break
            # asked to stop once the worlds have ended: what they published last may still be on its way
            # through here; forward it before leaving (until quiet, within the runner's grace period)
            asked = time.monotonic()
            while time.monotonic() - asked < LINGER_MAX_S:
                if time.monotonic() - max(asked, bridge.last_forward) >= LINGER_QUIET_S:
                    break
                time.sleep(0.02)
        finally:
            ready.undeclare()
            bridge.close()
    if bridge.complain.said:
        for where, n in bridge.complain.said.items():
            print(f"bridge: {where}: {n} message(s) dropped", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
