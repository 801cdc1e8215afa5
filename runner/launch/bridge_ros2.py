"""The bridge's side on ROS 2: its node and publishers as rmw_zenoh announces and numbers them
(`runner.wire.ros2`)."""

from __future__ import annotations

import threading
import time
from typing import Any

import zenoh

from runner.plan import Ros2Plan
from runner.wire import msgs, ros2

TF = "tf2_msgs/msg/TFMessage"


class RosNode:
    """One ROS 2 node as rmw_zenoh announces it: its token, and ids for its entities."""

    def __init__(self, session: zenoh.Session, plan: Ros2Plan, node_id: int):
        self.session = session
        self.plan = plan
        self.zid = str(session.zid())
        self.node_id = node_id
        self.next_id = node_id + 1
        self.token = session.liveliness().declare_token(
            ros2.node_token(plan.domain, self.zid, node_id, "/", plan.node)
        )

    def entity(self, kind: str, topic: str, type_name: str, qos: ros2.Qos) -> tuple[Any, bytes]:
        """A publisher ("MP"), subscription ("MS") or service server ("SS") token; returns it and the
        entity's GID."""
        key = ros2.entity_token(
            self.plan.domain,
            self.zid,
            self.node_id,
            self.next_id,
            kind,
            "/",
            self.plan.node,
            topic,
            type_name,
            qos,
        )
        self.next_id += 1
        return self.session.liveliness().declare_token(key), ros2.gid(key)


class RosOut:
    """One ROS 2 publisher of the bridge's node: every mapping to its topic goes out through it (one
    entity per topic, as a node has), numbered in one sequence. On a TRANSIENT_LOCAL TFMessage topic
    (`/tf_static`), what it sends is the whole static tree received so far, each frame's latest transform,
    as tf2_ros' StaticTransformBroadcaster does: the one message a late subscriber gets from the cache
    holds every frame, whichever robot or world sent it; a sim key that no longer feeds it (a robot
    deleted) takes its frames out of it."""

    def __init__(self, key: str, type_name: str, pub: Any, token: Any, gid: bytes, merge_tf: bool):
        self.key = key
        self.type = type_name
        self.pub = pub
        self.token = token  # its rmw_zenoh `MP` liveliness token
        self.gid = gid
        self.seq = 0
        self.users = 0  # mappings sending through it (robots' `tf` on `/tf`): it goes with the last
        self.lock = threading.Lock()
        # child frame -> (the sim key that sent it, its latest transform)
        self.tree: dict[str, tuple[str, Any]] | None = {} if merge_tf else None

    def put(self, payload: bytes, source: str) -> None:
        """Send a message that came from the sim key `source`."""
        with self.lock:
            if self.tree is not None:
                for t in msgs.decode(payload, TF).transforms:
                    self.tree[t.child_frame_id] = (source, t)
                payload = self._whole_tree()
            self._send(payload)

    def forget(self, source: str) -> None:
        """`source` feeds it no more: its frames leave the static tree, and the smaller tree is sent (the
        one the cache keeps for late subscribers) while other sources still feed it."""
        with self.lock:
            if self.tree is None:
                return
            gone = [child for child, (src, _t) in self.tree.items() if src == source]
            for child in gone:
                del self.tree[child]
            if gone and self.tree and self.users > 0:
                self._send(self._whole_tree())

    def _whole_tree(self) -> bytes:
        assert self.tree is not None
        return msgs.encode(msgs.T[TF](transforms=[t for _src, t in self.tree.values()]), TF)

    def _send(self, payload: bytes) -> None:
        self.seq += 1  # rmw_zenoh numbers each publisher's messages from 1
        self.pub.put(payload, attachment=ros2.pack_attachment(self.seq, time.time_ns(), self.gid))
