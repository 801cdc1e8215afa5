"""A ROS 2 client that is not ours: `zenoh-ros2-sdk` (an independent rmw_zenoh implementation in Python),
run by tests/test_ros2_tf.py in a process of its own (the SDK keeps one session per process).

    python ros2_sdk_client.py PORT DOMAIN OUT.json

It joins the run's router at tcp/127.0.0.1:PORT, lists the ROS 2 topics as `ros2 topic list` does, then,
as a late subscriber, subscribes to `/tf_static` with TRANSIENT_LOCAL durability (what tf2's listener
does), counting what arrives before the subscription is even set up (the publishers' caches, queried by
the SDK as rmw_zenoh does), then to `/tf` and one scan's frame. "Late": once `/clock` says the run is 2 s in. It writes what it received as JSON.

The SDK fetches message definitions with git when it lacks them; here they are written beforehand from
rosbags' own ROS 2 Jazzy store into a folder the SDK reads first, so nothing leaves this machine.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

TYPES = ("tf2_msgs/msg/TFMessage", "sensor_msgs/msg/LaserScan", "rosgraph_msgs/msg/Clock")
LATE_S = 2.0  # sim seconds the run has been going when the late subscriber comes
LOOPBACK_ONLY = (
    'listen/endpoints=["tcp/127.0.0.1:0"];scouting/multicast/enabled=false;scouting/gossip/enabled=false'
)


def _field_type(node: tuple[Any, Any]) -> tuple[str, list[str]]:
    """(the .msg spelling of a field type, the message types it refers to)."""
    from rosbags.typesys.base import Nodetype

    kind, detail = node
    if kind == Nodetype.BASE:
        name, bound = detail
        return (f"{name}<={bound}" if bound else name), []
    if kind == Nodetype.NAME:
        return detail, [detail]
    inner, length = detail
    text, refs = _field_type(inner)
    if kind == Nodetype.ARRAY:
        return f"{text}[{length}]", refs
    return (f"{text}[<={length}]" if length else f"{text}[]"), refs


def write_definitions(folder: Path, types: tuple[str, ...]) -> None:
    """Each type and everything it refers to, as `<pkg>/msg/<Name>.msg` files."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    todo, done = list(types), set()
    while todo:
        name = todo.pop()
        if name in done:
            continue
        done.add(name)
        consts, fields = store.fielddefs[name]
        lines = [f"{ctype} {cname}={value}" for cname, ctype, value in consts]
        for fname, node in fields:
            text, refs = _field_type(node)
            lines.append(f"{text} {fname}")
            todo += refs
        path = folder / f"{name}.msg"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("\n".join(lines) + "\n")


def _transforms(msg: Any) -> list[list[str]]:
    return [[t.header.frame_id, t.child_frame_id] for t in msg.transforms]


def main() -> int:
    port, domain, out = int(sys.argv[1]), int(sys.argv[2]), Path(sys.argv[3])
    folder = Path(tempfile.mkdtemp(prefix="ros2sdk-"))
    os.environ["ZENOH_ROS2_SDK_CACHE"] = str(folder / "cache")  # never used: all definitions are local
    os.environ["ZENOH_CONFIG_OVERRIDE"] = LOOPBACK_ONLY
    os.environ.pop("ZENOH_SESSION_CONFIG_URI", None)
    write_definitions(folder / "msgs", TYPES)

    from zenoh_ros2_sdk import ROS2Subscriber
    from zenoh_ros2_sdk.discovery import get_topic_names_and_types
    from zenoh_ros2_sdk.message_registry import get_registry
    from zenoh_ros2_sdk.qos import QosDurability, QosProfile

    get_registry(str(folder / "msgs"))  # the registry the subscribers use reads this folder first
    where = {"domain_id": domain, "router_ip": "127.0.0.1", "router_port": port}
    result: dict[str, Any] = {}

    topics: list[tuple[str, list[str]]] = []
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        topics = get_topic_names_and_types(timeout=1.0, **where)
        names = {t for t, _ in topics}
        if {"/tf", "/tf_static", "/r1/scan"} <= names:
            break
        time.sleep(0.2)
    result["topics"] = [[name, types] for name, types in topics]

    lock = threading.Lock()
    clock: list[float] = []

    def on_clock(msg: Any) -> None:
        with lock:
            clock.append(msg.clock.sec + msg.clock.nanosec * 1e-9)

    ticks = ROS2Subscriber("/clock", "rosgraph_msgs/msg/Clock", on_clock, **where)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        with lock:
            if clock and clock[-1] >= LATE_S:
                break
        time.sleep(0.05)
    ticks.close()
    result["clock_at_subscribe"] = clock[-1] if clock else None

    static: list[list[list[str]]] = []
    moving: list[list[list[str]]] = []
    scans: list[str] = []

    def on_static(msg: Any) -> None:
        with lock:
            static.append(_transforms(msg))

    # late: the run has been publishing for a while; TRANSIENT_LOCAL depth 1, as tf2's static listener
    latched = QosProfile(durability=QosDurability.TRANSIENT_LOCAL, history_depth=1)
    sub = ROS2Subscriber("/tf_static", "tf2_msgs/msg/TFMessage", on_static, qos=latched, **where)
    with lock:
        result["static_at_subscribe"] = list(static)  # from the publishers' caches, before any new one

    def on_tf(msg: Any) -> None:
        with lock:
            moving.append(_transforms(msg))

    def on_scan(msg: Any) -> None:
        with lock:
            scans.append(msg.header.frame_id)

    subs = [
        sub,
        ROS2Subscriber("/tf", "tf2_msgs/msg/TFMessage", on_tf, **where),
        ROS2Subscriber("/r1/scan", "sensor_msgs/msg/LaserScan", on_scan, **where),
    ]
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        with lock:
            if len(moving) >= 20 and scans:
                break
        time.sleep(0.1)
    with lock:
        result["tf"] = moving
        result["scan_frames"] = scans[:5]
    for s in subs:
        s.close()
    out.write_text(json.dumps(result))
    os._exit(0)  # the SDK's session threads are not daemons


if __name__ == "__main__":
    sys.exit(main())
