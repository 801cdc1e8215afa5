"""Who publishes on the run's keys without being part of the run.

Every Zenoh session of the run (worlds, renderers, nodes, bridges, the tools, the runners of other hosts)
holds a liveliness token `<run>/@meta/member/<zid>` (runner.wire.graph.member_key), and every message it
puts on a run key carries the run's (sequence, stamp) attachment. The recorder counts, per key, the samples
without one (runner.record.Recorder.outside); this part names who sent them: the sessions connected to the
runner's router that never said they were the run's, by Zenoh id, and by ROS node name when an rmw_zenoh
liveliness token of the same session says it (`@ros2_lv/<domain>/<zid>/<nid>/<eid>/NN/<enclave>/<ns>/<name>`,
rmw_zenoh_cpp's liveliness_utils.cpp). Nothing of this is on the message path: three listeners, told of
sessions and tokens as they come and go.
"""

from __future__ import annotations

import contextlib
import threading
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import zenoh

from runner.launch.parts import Part
from runner.wire.graph import member_key

if TYPE_CHECKING:
    from runner.launch.parts import Run

ROS_TOKENS = "@ros2_lv/**"


@dataclass
class Outsiders:
    """The sessions seen on the runner's router (Zenoh id -> its link's address), those that said they are
    the run's, and the ROS nodes the others declared."""

    own: str = ""
    connected: dict[str, str] = field(default_factory=dict)
    members: set[str] = field(default_factory=set)
    ros_nodes: dict[str, set[str]] = field(default_factory=dict)  # zid -> node names
    lock: threading.Lock = field(default_factory=threading.Lock)

    def foreign(self) -> list[str]:
        """Each session outside the run, named: `zid 1a2b... (tcp/127.0.0.1:40312)`, with its ROS nodes."""
        with self.lock:
            out = []
            for zid, where in sorted(self.connected.items()):
                if zid == self.own or zid in self.members:
                    continue
                nodes = sorted(self.ros_nodes.get(zid, ()))
                said = f"ROS node {', '.join(nodes)}, " if nodes else ""
                out.append(f"{said}zid {zid}" + (f" from {where}" if where else ""))
            return out


class OutsidePart(Part):
    """Listens to the runner's router for sessions, run members and ROS nodes (a `Part` of the supervisor)."""

    label = "outside publishers"
    poll_order = 9

    def __init__(self) -> None:
        self.seen = Outsiders()
        self._entities: list[Any] = []

    def start(self, run: Run) -> None:
        session, seen = run.session, self.seen
        seen.own = str(session.zid())

        def on_member(sample: zenoh.Sample) -> None:
            if sample.kind == zenoh.SampleKind.PUT:
                with seen.lock:
                    seen.members.add(str(sample.key_expr).rsplit("/", 1)[-1])

        def on_ros(sample: zenoh.Sample) -> None:
            parts = str(sample.key_expr).split("/")
            # @ros2_lv / domain / zid / nid / eid / NN / enclave / namespace / name: a node's own token
            if sample.kind == zenoh.SampleKind.PUT and len(parts) >= 9 and parts[5] == "NN":
                ns = parts[7].replace("%", "/").strip("/")
                with seen.lock:
                    seen.ros_nodes.setdefault(parts[2], set()).add(
                        f"/{ns}/{parts[8]}" if ns else f"/{parts[8]}"
                    )

        def on_transport(event: Any) -> None:
            with contextlib.suppress(Exception):
                zid = str(event.transport.zid)
                with seen.lock:
                    seen.connected.setdefault(zid, "")
                for link in session.info.links():
                    if str(link.zid) == zid:
                        with seen.lock:
                            seen.connected[zid] = str(link.dst)
                        break

        live = session.liveliness()
        self._entities.append(
            live.declare_subscriber(member_key(run.plan.name, "*"), on_member, history=True)
        )
        self._entities.append(live.declare_subscriber(ROS_TOKENS, on_ros, history=True))
        self._entities.append(session.info.declare_transport_events_listener(on_transport, history=True))
        # the runner's own session is the run's too (its recorder, judge and live view publish nothing on
        # the run's keys without the attachment, but say it for the other hosts' runners)
        self._entities.append(live.declare_token(member_key(run.plan.name, seen.own)))

    def close(self, run: Run) -> None:
        for entity in self._entities:
            with contextlib.suppress(Exception):
                entity.undeclare()
        self._entities.clear()
