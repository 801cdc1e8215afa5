"""ROS 2 services and actions called by a client that is not ours: `zenoh-ros2-sdk` (an independent rmw_zenoh
implementation in Python), in a process of its own (the SDK keeps one session per process).

    python ros2_sdk_services.py PORT DOMAIN SCRIPT.json OUT.json

SCRIPT is a list of steps run in order, each one of:
- `{"sleep": S}`: wait S wall seconds;
- `{"list": true}`: the services `ros2 service list -t` shows (the SDK's graph discovery; the action
  services among them);
- `{"call": NAME, "type": "pkg/srv/Name", "request": {...}}`: one call with the SDK's service client (it
  finds the service by the key its own type-hash code computes from the `.srv` definition, and declares
  its `SC` token), the response as data;
- `{"action": NAME, "type": "pkg/action/Name", "goal": {...}, "cancel_after_feedback": N | null,
   "then": STEP | null}`: an action goal as rclpy's ActionClient sends one, built from the SDK's service
  client and subscriber (`_action/send_goal`, `_action/feedback` filtered by goal id, `_action/status`,
  `_action/get_result`, `_action/cancel_goal`). The action services' type hashes are computed here with
  the SDK's REP-2016 code, under the names rosidl gives an action's services (`pkg/action/Name_SendGoal`;
  the SDK's own service helper assumes `pkg/srv/`), not with the runner's; `then` runs another step
  (a preempting goal) once the first feedback arrived.

Message and service definitions are written beforehand from the runner's registered Jazzy definitions
into the folder the SDK reads first (the SDK would otherwise fetch them with git), so nothing leaves this
machine; the definitions are texts, the hashing and the wire are the SDK's.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path
from typing import Any

# (run as a script: this folder is on sys.path; the first client's loopback settings and .msg spelling)
from ros2_sdk_client import LOOPBACK_ONLY, _field_type


def definition(name: str) -> tuple[str, list[str]]:
    """A message's `.msg` text (constants, fields) and the types it refers to."""
    from runner.wire.msgs import TYPESTORE

    consts, fields = TYPESTORE.fielddefs[name]
    lines = [f"{ctype} {cname}={value}" for cname, ctype, value in consts]
    refs: list[str] = []
    for fname, node in fields:
        if fname == "structure_needs_at_least_one_member":
            continue
        text, more = _field_type(node)
        lines.append(f"{text} {fname}")
        refs += more
    return "\n".join(lines) + "\n", refs


def write_definitions(folder: Path, services: list[str], messages: list[str]) -> None:
    todo, done = list(messages), set()
    for srv in services:
        req, r1 = definition(f"{srv}_Request")
        res, r2 = definition(f"{srv}_Response")
        path = folder / f"{srv}.srv"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(req + "---\n" + res)
        todo += r1 + r2
    while todo:
        name = todo.pop()
        if name in done:
            continue
        done.add(name)
        text, refs = definition(name)
        path = folder / f"{name}.msg"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
        todo += refs


def action_service_hash(folder: Path, srv: str) -> str:
    """REP-2016 hash of an action's service (`pkg/action/Name_SendGoal`) by the SDK's own code, with the
    type names rosidl gives it (the SDK's compute_service_type_hash spells them `pkg/srv/...`)."""
    from zenoh_ros2_sdk import utils as u

    req_t, res_t, event_t = f"{srv}_Request", f"{srv}_Response", f"{srv}_Event"
    type_map: dict[str, Any] = {}
    todo = [req_t, res_t]
    while todo:
        name = todo.pop()
        if name in type_map:
            continue
        text = (folder / f"{name}.msg").read_text()
        fields = u._parse_msg_definition(text)
        if not fields:
            fields = [
                {
                    "name": u.EMPTY_STRUCTURE_REQUIRED_MEMBER_NAME,
                    "type": "uint8",
                    "is_array": False,
                    "array_size": 0,
                }
            ]
        type_map[name] = u._serialize_type_description(name, fields)
        for f in type_map[name]["fields"]:
            nested = f["type"]["nested_type_name"]
            if nested:
                todo.append(nested)

    def nested(name: str, type_id: str, capacity: int = 0) -> dict[str, Any]:
        return {
            "type_id": u.FIELD_TYPE_NAME_TO_ID[type_id],
            "capacity": capacity,
            "string_capacity": 0,
            "nested_type_name": name,
        }

    def field(name: str, type_: dict[str, Any]) -> dict[str, Any]:
        return {"name": name, "type": type_, "default_value": ""}

    info = "service_msgs/msg/ServiceEventInfo"
    type_map[info] = u._serialize_type_description(
        info,
        u._parse_msg_definition(
            "uint8 event_type\nbuiltin_interfaces/Time stamp\nuint8[16] client_gid\nint64 sequence_number\n"
        ),
    )
    type_map["builtin_interfaces/msg/Time"] = u._serialize_type_description(
        "builtin_interfaces/msg/Time", u._parse_msg_definition("int32 sec\nuint32 nanosec\n")
    )
    type_map[event_t] = {
        "type_name": event_t,
        "fields": [
            field("info", nested(info, "FIELD_TYPE_NESTED_TYPE")),
            field("request", nested(req_t, "FIELD_TYPE_NESTED_TYPE_BOUNDED_SEQUENCE", 1)),
            field("response", nested(res_t, "FIELD_TYPE_NESTED_TYPE_BOUNDED_SEQUENCE", 1)),
        ],
    }
    type_map[srv] = {
        "type_name": srv,
        "fields": [
            field("request_message", nested(req_t, "FIELD_TYPE_NESTED_TYPE")),
            field("response_message", nested(res_t, "FIELD_TYPE_NESTED_TYPE")),
            field("event_message", nested(event_t, "FIELD_TYPE_NESTED_TYPE")),
        ],
    }
    return u._calculate_type_hash(u._extract_full_type_description(srv, type_map))


def to_data(msg: Any) -> Any:
    from runner.wire import msgs

    return msgs.to_data(msg)


class Client:
    def __init__(self, port: int, domain: int, folder: Path):
        self.where = {"domain_id": domain, "router_ip": "127.0.0.1", "router_port": port}
        self.folder = folder
        self.clients: dict[tuple[str, str], Any] = {}

    def service(self, name: str, srv: str, type_hash: str | None = None) -> Any:
        from zenoh_ros2_sdk import ROS2ServiceClient

        key = (name, srv)
        if key not in self.clients:
            from zenoh_ros2_sdk.message_registry import load_message_type

            req, res = (self.folder / f"{srv}.srv").read_text().split("---\n")
            # the types the request and response refer to, registered in the SDK's store first
            todo = [f"{srv}_Request", f"{srv}_Response"]
            seen: set[str] = set()
            while todo:
                t = todo.pop()
                if t in seen:
                    continue
                seen.add(t)
                _text, refs = definition(t)
                for r in refs:
                    todo.append(r)
                    load_message_type(r)
            self.clients[key] = ROS2ServiceClient(
                name,
                srv,
                # (the SDK takes an empty part as "not given"; a comment is the empty definition it hashes)
                request_definition=req if req.strip() else "# empty\n",
                response_definition=res if res.strip() else "# empty\n",
                type_hash=type_hash,
                timeout=60.0,
                **self.where,
            )
        return self.clients[key]

    def call(self, name: str, srv: str, request: dict[str, Any], type_hash: str | None = None) -> Any:
        client = self.service(name, srv, type_hash)
        from rosbags.typesys.base import Nodetype

        store = client.session_mgr.store
        fields = dict(store.fielddefs[client.request_store_type][1])
        whole = _build(store, (Nodetype.NAME, client.request_store_type), request)  # (defaults filled in)
        response = client.call(**{k: getattr(whole, k) for k in fields})
        if response is None:
            return None
        return _plain(response)


def _build(store: Any, node: tuple[Any, Any], value: Any) -> Any:
    """Plain data as the SDK's own (rosbags) message objects, field by field from its typestore."""
    import numpy as np
    from rosbags.typesys.base import Nodetype

    kind, detail = node
    if kind == Nodetype.NAME:
        fields = dict(store.fielddefs[detail][1])
        data = value or {}
        args = {}
        for fname, fnode in fields.items():
            if fname in data:
                args[fname] = _build(store, fnode, data[fname])
            else:
                args[fname] = _default(store, fnode)
        return store.types[detail](**args)
    if kind == Nodetype.BASE:
        return value
    inner, _n = detail
    if inner[0] == Nodetype.BASE and inner[1][0] not in ("string", "wstring"):
        return np.asarray(value, dtype=_NP[inner[1][0]])
    return [_build(store, inner, v) for v in value]


_NP = {
    "bool": "bool",
    "byte": "uint8",
    "char": "uint8",
    "int8": "int8",
    "uint8": "uint8",
    "int16": "int16",
    "uint16": "uint16",
    "int32": "int32",
    "uint32": "uint32",
    "int64": "int64",
    "uint64": "uint64",
    "float32": "float32",
    "float64": "float64",
}


def _default(store: Any, node: tuple[Any, Any]) -> Any:
    import numpy as np
    from rosbags.typesys.base import Nodetype

    kind, detail = node
    if kind == Nodetype.NAME:
        return _build(store, node, {})
    if kind == Nodetype.BASE:
        name = detail[0]
        return "" if name in ("string", "wstring") else (False if name == "bool" else 0)
    inner, n = detail
    if kind == Nodetype.ARRAY:
        if inner[0] == Nodetype.BASE and inner[1][0] not in ("string", "wstring"):
            return np.zeros(n, dtype=_NP[inner[1][0]])
        return [_default(store, inner) for _ in range(n)]
    if inner[0] == Nodetype.BASE and inner[1][0] not in ("string", "wstring"):
        return np.zeros(0, dtype=_NP[inner[1][0]])
    return []


def _plain(obj: Any) -> Any:
    """An SDK (rosbags) message object as plain data."""
    import numpy as np

    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, list | tuple):
        return [_plain(v) for v in obj]
    if hasattr(obj, "__dataclass_fields__"):
        return {k: _plain(getattr(obj, k)) for k in obj.__dataclass_fields__ if k != "__msgtype__"}
    return obj


def run_action(c: Client, step: dict[str, Any], log: list[Any]) -> dict[str, Any]:
    """One goal as rclpy's ActionClient sends it."""
    import numpy as np
    from zenoh_ros2_sdk import ROS2Subscriber

    name, action = step["action"], step["type"]
    goal_id = np.frombuffer(uuid.uuid4().bytes, dtype=np.uint8)
    feedback: list[Any] = []
    statuses: list[Any] = []
    lock = threading.Lock()

    def on_feedback(msg: Any) -> None:
        if bytes(np.asarray(msg.goal_id.uuid, dtype=np.uint8)) == goal_id.tobytes():
            with lock:
                feedback.append(_plain(msg.feedback))

    def on_status(msg: Any) -> None:
        with lock:
            for s in msg.status_list:
                if bytes(np.asarray(s.goal_info.goal_id.uuid, dtype=np.uint8)) == goal_id.tobytes():
                    statuses.append(int(s.status))

    subs = [
        ROS2Subscriber(f"{name}/_action/feedback", f"{action}_FeedbackMessage", on_feedback, **c.where),
        ROS2Subscriber(f"{name}/_action/status", "action_msgs/msg/GoalStatusArray", on_status, **c.where),
    ]
    hashes = {s: action_service_hash(c.folder, f"{action}{s}") for s in ("_SendGoal", "_GetResult")}
    out: dict[str, Any] = {"goal_id": goal_id.tolist()}
    sent = c.call(
        f"{name}/_action/send_goal",
        f"{action}_SendGoal",
        {"goal_id": {"uuid": goal_id}, "goal": step["goal"]},
        hashes["_SendGoal"],
    )
    out["accepted"] = bool(sent and sent["accepted"])
    if out["accepted"] and (step.get("cancel_after_feedback") or step.get("then")):
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            with lock:
                if len(feedback) >= (step.get("cancel_after_feedback") or 1):
                    break
            time.sleep(0.02)
        if step.get("then"):
            out["then"] = run_action(c, step["then"], log)
        if step.get("cancel_after_feedback"):
            zero = {"sec": 0, "nanosec": 0}
            out["cancel"] = c.call(
                f"{name}/_action/cancel_goal",
                "action_msgs/srv/CancelGoal",
                {"goal_info": {"goal_id": {"uuid": goal_id}, "stamp": zero}},
            )
    if out["accepted"]:
        out["result"] = c.call(
            f"{name}/_action/get_result",
            f"{action}_GetResult",
            {"goal_id": {"uuid": goal_id}},
            hashes["_GetResult"],
        )
    time.sleep(0.3)  # (the status array that follows the result is on its way)
    with lock:
        out["feedback"] = feedback[:3] + feedback[-3:]
        out["feedback_count"] = len(feedback)
        out["statuses"] = sorted(set(statuses))
    for s in subs:
        s.close()
    return out


def wait_topics(c: Client, step: dict[str, Any]) -> dict[str, Any]:
    """`ros2 topic list` until every name of `wait_for` is there and none of `absent` is (60 s at most)."""
    from zenoh_ros2_sdk.discovery import get_topic_names_and_types

    want, gone = set(step.get("wait_for", [])), set(step.get("absent", []))
    deadline = time.monotonic() + 60
    names: set[str] = set()
    found: list[Any] = []
    while time.monotonic() < deadline:
        found = get_topic_names_and_types(timeout=1.0, **c.where)
        names = {n for n, _t in found}
        if want <= names and not (gone & names):
            break
        time.sleep(0.2)
    return {"topics": [[n, t] for n, t in found]}


def publish(c: Client, step: dict[str, Any]) -> dict[str, Any]:
    """`ros2 topic pub -r RATE -t COUNT`: the message `data` of `type` on `publish`."""
    from rosbags.typesys.base import Nodetype
    from zenoh_ros2_sdk import ROS2Publisher

    type_name = step["type"]
    pub = ROS2Publisher(step["publish"], type_name, **c.where)
    store = pub.session_mgr.store
    whole = _build(store, (Nodetype.NAME, type_name), step["data"])
    fields = dict(store.fielddefs[type_name][1])
    for _ in range(int(step.get("count", 1))):
        pub.publish(**{k: getattr(whole, k) for k in fields})
        time.sleep(float(step.get("period", 0.1)))
    pub.close()
    return {"published": step["publish"], "count": step.get("count", 1)}


def echo(c: Client, step: dict[str, Any]) -> dict[str, Any]:
    """`ros2 topic echo --once`: the first message on `echo` (60 s at most)."""
    from zenoh_ros2_sdk import ROS2Subscriber

    got: list[Any] = []
    done = threading.Event()

    def on_msg(msg: Any) -> None:
        if not done.is_set():
            got.append(_plain(msg))
            done.set()

    sub = ROS2Subscriber(step["echo"], step["type"], on_msg, **c.where)
    done.wait(60.0)
    sub.close()
    return {"echo": step["echo"], "message": got[0] if got else None}


def main() -> int:
    port, domain = int(sys.argv[1]), int(sys.argv[2])
    script = json.loads(Path(sys.argv[3]).read_text())
    out_path = Path(sys.argv[4])
    folder = Path(tempfile.mkdtemp(prefix="ros2sdk-"))
    os.environ["ZENOH_ROS2_SDK_CACHE"] = str(folder / "cache")  # never used: all definitions are local
    os.environ["ZENOH_CONFIG_OVERRIDE"] = LOOPBACK_ONLY
    os.environ.pop("ZENOH_SESSION_CONFIG_URI", None)

    from runner.wire import interfaces

    services = list(interfaces.SERVICES)
    for action in interfaces.ACTIONS:
        services += [f"{action}_SendGoal", f"{action}_GetResult"]
    messages = [f"{a}_FeedbackMessage" for a in interfaces.ACTIONS] + ["action_msgs/msg/GoalStatusArray"]
    messages += ["geometry_msgs/msg/Twist", "nav_msgs/msg/Odometry"]
    messages += [
        f"{a}{s}_{part}"
        for a in interfaces.ACTIONS
        for s in ("_SendGoal", "_GetResult")
        for part in ("Request", "Response")
    ]
    write_definitions(folder / "msgs", services, messages)

    from zenoh_ros2_sdk.message_registry import get_registry

    get_registry(str(folder / "msgs"))
    c = Client(port, domain, folder / "msgs")
    log: list[Any] = []
    for step in script:
        if step.get("list"):
            from zenoh_ros2_sdk.discovery import get_service_names_and_types

            want = set(step.get("wait_for", []))
            deadline = time.monotonic() + 60
            found: list[Any] = []
            while time.monotonic() < deadline:
                found = get_service_names_and_types(timeout=1.0, **c.where)
                if want <= {n for n, _t in found}:
                    break
                time.sleep(0.2)
            log.append({"services": [[n, t] for n, t in found]})
        elif "sleep" in step:
            time.sleep(float(step["sleep"]))  # (wall time passing while the world is paused)
            log.append({"slept": step["sleep"]})
        elif "call" in step:
            log.append(
                {"call": step["call"], "response": c.call(step["call"], step["type"], step["request"])}
            )
        elif "action" in step:
            log.append(run_action(c, step, log))
        elif step.get("topics"):
            log.append(wait_topics(c, step))
        elif "publish" in step:
            log.append(publish(c, step))
        elif "echo" in step:
            log.append(echo(c, step))
        out_path.write_text(json.dumps(log, default=str))
    out_path.write_text(json.dumps(log, default=str))
    os._exit(0)  # (the SDK's session threads would keep the process)


if __name__ == "__main__":
    sys.exit(main())
