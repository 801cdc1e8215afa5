"""What ROS 2's rmw_zenoh puts on a Zenoh network, written byte for byte without ROS installed.

rmw_zenoh_cpp (ROS 2 Jazzy and later) maps every ROS 2 topic to one Zenoh key expression, announces each
node, publisher and subscription with a Zenoh liveliness token whose key spells out the entity, and sends
every message as plain CDR (with its 4-byte encapsulation header, no Zenoh encoding set) together with a
33-byte attachment: sequence number, source timestamp and the publisher's GID. The keys, tokens and
attachments built here are meant to let a process that is not ROS show up in `ros2 node list` /
`ros2 topic list` and be read by `ros2 topic echo` run with `RMW_IMPLEMENTATION=rmw_zenoh_cpp` (checked
against the sources below and their published examples, not against a running ROS 2). This module only
formats and parses; it opens no session and sends nothing.

Sources (repository and file):
- ros2/rmw_zenoh, docs/design.md: "Topic and Service name mapping to Zenoh key expressions" (topic keys,
  the DDS type name `pkg::msg::dds_::Name_`), "Graph Cache" (liveliness token layout, with examples),
  "Publishers" (attachment layout).
- ros2/rmw_zenoh, rmw_zenoh_cpp/src/detail/liveliness_utils.cpp: token assembly, `mangle_name`,
  `qos_to_keyexpr` / `keyexpr_to_qos`, topic key (`TopicInfo`), the GID as XXH3-128 of the token key.
- ros2/rmw_zenoh, rmw_zenoh_cpp/src/detail/qos.cpp: the defaults that the QoS chunk leaves out (depth 42).
- ros2/rmw_zenoh, rmw_zenoh_cpp/src/detail/attachment_helpers.cpp and rmw_publisher_data.cpp: the
  attachment (zenoh-ext serializer: int64, int64, then the 16-byte GID as a length-prefixed sequence; the
  sequence number starts at 1 per publisher).
- eclipse-zenoh/zenoh-cpp, include/zenoh/api/ext/serialization.hxx: `std::array` is serialized as a
  sequence (LEB128 length, then the elements).
- ros2/rmw, rmw/include/rmw/types.h: the QoS policy enum values.
- REP-2016 (type hashes, `RIHS01_<sha256 hex>`), computed here by rosbags' `hash_rihs01`.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass
from functools import cache

import xxhash

from runner.wire import interfaces  # (registers the service and action types hashed here)
from runner.wire.msgs import TYPESTORE, normalize_type

ADMIN_SPACE = "@ros2_lv"
DEFAULT_DEPTH = 10  # what rclcpp/rclpy give a publisher or subscription created with a plain depth
ENTITY_KINDS = ("NN", "MP", "MS", "SS", "SC")
ATTACHMENT_SIZE = 33
GID_SIZE = 16

# rmw_zenoh's own defaults (qos.cpp); a QoS field equal to its default is left empty in the token.
_ZENOH_DEFAULT_DEPTH = 42
# rmw/types.h enum values, as the token writes them.
_RELIABILITY = {"reliable": 1, "best_effort": 2}
_DURABILITY = {"transient_local": 1, "volatile": 2}
_HISTORY = {"keep_last": 1, "keep_all": 2}
_SYSTEM_DEFAULT = 0

_DDS_TYPE = re.compile(r"^([A-Za-z0-9_]+)::([A-Za-z0-9_]+)::dds_::([A-Za-z0-9_]+)_$")
_NODE_NAME_BAD = re.compile(r"[^A-Za-z0-9_]")
_NODE_NAME_MAX = 255  # RMW_NODE_NAME_MAX_NAME_LENGTH


@dataclass(frozen=True)
class Qos:
    """The QoS fields a liveliness token carries that this module writes (deadline, lifespan and
    liveliness always stay at rmw_zenoh's defaults: infinite, infinite, automatic)."""

    reliability: str = "reliable"  # or "best_effort"
    durability: str = "volatile"  # or "transient_local"
    history: str = "keep_last"  # or "keep_all"
    depth: int = DEFAULT_DEPTH

    def __post_init__(self) -> None:
        for field, value, allowed in (
            ("reliability", self.reliability, _RELIABILITY),
            ("durability", self.durability, _DURABILITY),
            ("history", self.history, _HISTORY),
        ):
            if value not in allowed:
                raise ValueError(f"QoS {field} {value!r} is not one of {', '.join(allowed)}")
        if isinstance(self.depth, bool) or not isinstance(self.depth, int) or self.depth < 0:
            raise ValueError(f"QoS depth must be a non-negative integer, not {self.depth!r}")


@dataclass(frozen=True)
class TokenInfo:
    """A parsed liveliness token. `namespace` is `/` for the root namespace, `enclave` is `""` when the
    token's enclave chunk is `%`; `topic`, `dds_type`, `type_hash` and `qos` are None for a node."""

    domain: int
    zid: str
    node_id: int
    entity_id: int
    kind: str
    enclave: str
    namespace: str
    node: str
    topic: str | None
    dds_type: str | None
    type_hash: str | None
    qos: Qos | None


# ---------------------------------------------------------------------------------------------- types
def _split_type(ros_type: str) -> tuple[str, str, str]:
    parts = normalize_type(ros_type).split("/")
    if len(parts) != 3 or not all(parts):
        raise ValueError(f"{ros_type!r} is not a ROS 2 type name (pkg/msg/Name)")
    return parts[0], parts[1], parts[2]


def dds_type_name(ros_type: str) -> str:
    """`std_msgs/msg/String` (or `std_msgs/String`) -> `std_msgs::msg::dds_::String_`."""
    pkg, kind, name = _split_type(ros_type)
    return f"{pkg}::{kind}::dds_::{name}_"


def ros_type_from_dds(dds: str) -> str | None:
    """`std_msgs::msg::dds_::String_` -> `std_msgs/msg/String`; None for anything else."""
    match = _DDS_TYPE.match(dds)
    return f"{match[1]}/{match[2]}/{match[3]}" if match else None


@cache
def type_hash(ros_type: str) -> str:
    """The REP-2016 type hash, `RIHS01_` + 64 lowercase hex, of a type in `runner.wire.msgs.TYPESTORE`."""
    name = "/".join(_split_type(ros_type))
    try:
        return str(TYPESTORE.hash_rihs01(name))
    except KeyError:
        raise KeyError(f"unknown message type {name!r}") from None


# ---------------------------------------------------------------------------------------------- names
def _namespace(namespace: str) -> str:
    """A node namespace in its canonical form: `/` for the root, else `/a/b` (no trailing slash)."""
    inner = namespace.strip("/")
    return "/" + inner if inner else "/"


def qualified_name(namespace: str, name: str) -> str:
    """ROS 2 name resolution without remapping: an absolute name is kept, a relative one is put under the
    namespace. The result starts with `/` and has no trailing `/`. Private (`~`) names are refused."""
    if not name or name in ("/", "~") or name.startswith("~"):
        raise ValueError(f"{name!r} is not a topic name that can be resolved without a node")
    if name.startswith("/"):
        return "/" + name.strip("/")
    ns = _namespace(namespace)
    return ns.rstrip("/") + "/" + name.strip("/")


def topic_key(domain: int, fq_name: str, ros_type: str) -> str:
    """`<domain>/<name without leading slash>/<dds type>/<type hash>`, the key a topic's data goes on; for a
    service type (`pkg/srv/Name`, `pkg/action/Name_SendGoal`), the key its queryable is declared on."""
    _check_domain(domain)
    inner = fq_name.strip("/")
    if not inner:
        raise ValueError(f"{fq_name!r} is not a topic name")
    return f"{domain}/{inner}/{dds_type_name(ros_type)}/{type_hash(ros_type)}"


def mangle(name: str) -> str:
    """Every `/` becomes `%`; an empty name is `%` (so the namespace `/` and no enclave are both `%`)."""
    return name.replace("/", "%") if name else "%"


def demangle(text: str) -> str:
    """The inverse of `mangle`: `%` alone is `""`, otherwise every `%` becomes `/`."""
    return "" if text == "%" else text.replace("%", "/")


def valid_node_name(name: str) -> str:
    """Any text as a valid ROS 2 node name: `[A-Za-z_][A-Za-z0-9_]*`, at most 255 characters."""
    out = _NODE_NAME_BAD.sub("_", name)
    if not out or out[0].isdigit():
        out = "_" + out
    return out[:_NODE_NAME_MAX]


# ---------------------------------------------------------------------------------------------- QoS
def _uint(text: str) -> int | None:
    """A decimal made of ASCII digits only (`str.isdigit` alone also takes `²`, which `int` refuses)."""
    return int(text) if text.isascii() and text.isdigit() else None


def qos_chunk(qos: Qos) -> str:
    """rmw_zenoh's `qos_to_keyexpr`: `<rel>:<dur>:<hist>,<depth>:<deadline s,ns>:<lifespan s,ns>:
    <liveliness,lease s,ns>`, each field empty when it is rmw_zenoh's default. Depth 0 is written as the
    default, as rmw_zenoh replaces it with 42 before it builds the token."""
    reliability = _RELIABILITY[qos.reliability]
    durability = _DURABILITY[qos.durability]
    history = _HISTORY[qos.history]
    depth = qos.depth or _ZENOH_DEFAULT_DEPTH
    rel = "" if reliability == _RELIABILITY["reliable"] else str(reliability)
    dur = "" if durability == _DURABILITY["volatile"] else str(durability)
    hist = "" if history == _HISTORY["keep_last"] else str(history)
    dep = "" if depth == _ZENOH_DEFAULT_DEPTH else str(depth)
    return f"{rel}:{dur}:{hist},{dep}:,:,:,,"


def _policy(text: str, values: dict[str, int], default: str) -> str | None:
    if text in ("", str(_SYSTEM_DEFAULT)):
        return default
    for name, value in values.items():
        if text == str(value):
            return name
    return None


def parse_qos_chunk(text: str) -> Qos | None:
    """The inverse of `qos_chunk` (deadline, lifespan and liveliness are checked for form, not kept);
    None when the text is not a QoS chunk or holds a policy this module cannot represent."""
    parts = text.split(":")
    if len(parts) < 6:
        return None
    history_parts = parts[2].split(",")
    times = [history_parts, parts[3].split(","), parts[4].split(","), parts[5].split(",")]
    if any(len(p) < n for p, n in zip(times, (2, 2, 2, 3), strict=True)):
        return None
    if not all(c == "" or _uint(c) is not None for p in times for c in p):
        return None
    reliability = _policy(parts[0], _RELIABILITY, "reliable")
    durability = _policy(parts[1], _DURABILITY, "volatile")
    history = _policy(history_parts[0], _HISTORY, "keep_last")
    if reliability is None or durability is None or history is None:
        return None
    depth = int(history_parts[1]) if history_parts[1] else _ZENOH_DEFAULT_DEPTH
    return Qos(reliability=reliability, durability=durability, history=history, depth=depth)


# Topics ROS 2 publishes with TRANSIENT_LOCAL durability, depth 1: tf2_ros' static broadcaster
# (`/tf_static`) and robot_state_publisher (`robot_description`); a late subscriber gets the last message.
LATCHED_TOPICS = ("tf_static", "robot_description")
TF_DEPTH = 100  # tf2_ros' TransformBroadcaster and TransformListener


def topic_qos(fq_topic: str) -> Qos:
    """The QoS a ROS 2 publisher of this topic uses: TRANSIENT_LOCAL depth 1 for `tf_static` and
    `robot_description` (at any namespace), depth 100 for `tf`, the default (reliable, volatile, depth 10)
    otherwise."""
    last = fq_topic.rstrip("/").rsplit("/", 1)[-1]
    if fq_topic.rstrip("/").endswith("/_action/status"):
        # rcl_action's rcl_action_qos_profile_status_default: reliable, TRANSIENT_LOCAL, keep last 1
        return Qos(durability="transient_local", depth=1)
    if last in LATCHED_TOPICS:
        return Qos(durability="transient_local", depth=1)
    if last == "tf":
        return Qos(depth=TF_DEPTH)
    return Qos()


# ---------------------------------------------------------------------------------------------- tokens
def _check_domain(domain: int) -> None:
    if isinstance(domain, bool) or not isinstance(domain, int) or domain < 0:
        raise ValueError(f"domain id must be a non-negative integer, not {domain!r}")


def _node_chunks(
    domain: int, zid: str, node_id: int, entity_id: int, kind: str, namespace: str, node: str, enclave: str
) -> list[str]:
    _check_domain(domain)
    if not zid or "/" in zid:
        raise ValueError(f"{zid!r} is not a Zenoh session id")
    for what, value in (("node id", node_id), ("entity id", entity_id)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise ValueError(f"{what} must be a non-negative integer, not {value!r}")
    if not node:
        raise ValueError("a node needs a name")
    enclave_chunk = mangle(enclave.rstrip("/"))
    namespace_chunk = mangle(_namespace(namespace).rstrip("/"))
    ids = [str(domain), zid, str(node_id), str(entity_id)]
    return [ADMIN_SPACE, *ids, kind, enclave_chunk, namespace_chunk, mangle(node)]


def node_token(domain: int, zid: str, node_id: int, namespace: str, node: str, enclave: str = "") -> str:
    """The liveliness token key of a node: `@ros2_lv/<domain>/<zid>/<node_id>/<node_id>/NN/<enclave>/
    <namespace>/<node>`; `zid` is the session id as `str(session.zid())` writes it."""
    return "/".join(_node_chunks(domain, zid, node_id, node_id, "NN", namespace, node, enclave))


def entity_token(
    domain: int,
    zid: str,
    node_id: int,
    entity_id: int,
    kind: str,
    namespace: str,
    node: str,
    fq_topic: str,
    ros_type: str,
    qos: Qos = Qos(),  # frozen, so one shared default is safe
    enclave: str = "",
) -> str:
    """The liveliness token key of a publisher (`MP`), subscription (`MS`), service server (`SS`) or client
    (`SC`): the node's chunks with the entity id, then `<mangled name>/<dds type>/<type hash>/<qos>`. A
    relative `fq_topic` is resolved in the node's namespace. For a service, `ros_type` is the service type
    (`std_srvs/srv/Empty`, an action's `pkg/action/Name_SendGoal`): its DDS name without `Request_` /
    `Response_` and its service hash, as rmw_zenoh's ServiceData / ClientData::make write them
    (rmw_zenoh_cpp/src/detail/rmw_service_data.cpp, rmw_client_data.cpp)."""
    if kind not in ("MP", "MS", "SS", "SC"):
        raise ValueError(f"entity kind must be one of MP, MS, SS, SC, not {kind!r}")
    if kind in ("SS", "SC"):
        try:
            interfaces.service_type(ros_type)
        except KeyError as e:
            raise ValueError(f"a service's token needs a service type: {e.args[0]}") from None
    chunks = _node_chunks(domain, zid, node_id, entity_id, kind, namespace, node, enclave)
    topic = qualified_name(namespace, fq_topic)
    chunks += [mangle(topic), dds_type_name(ros_type), type_hash(ros_type), qos_chunk(qos)]
    return "/".join(chunks)


def parse_token(key: str) -> TokenInfo | None:
    """Read a liveliness token key (any entity kind, chunks after the QoS chunk ignored); None when the key
    is not an rmw_zenoh token."""
    parts = key.split("/")
    if len(parts) < 9 or parts[0] != ADMIN_SPACE or not all(parts):
        return None
    domain, node_id, entity_id = _uint(parts[1]), _uint(parts[3]), _uint(parts[4])
    kind = parts[5]
    if domain is None or node_id is None or entity_id is None or kind not in ENTITY_KINDS:
        return None
    topic: str | None = None
    dds_type: str | None = None
    hash_: str | None = None
    qos: Qos | None = None
    if kind != "NN":
        if len(parts) < 13:
            return None
        qos = parse_qos_chunk(parts[12])
        if qos is None:
            return None
        topic, dds_type, hash_ = demangle(parts[9]), demangle(parts[10]), demangle(parts[11])
    return TokenInfo(
        domain=domain,
        zid=parts[2],
        node_id=node_id,
        entity_id=entity_id,
        kind=kind,
        enclave=demangle(parts[6]),
        namespace=demangle(parts[7]) or "/",
        node=demangle(parts[8]),
        topic=topic,
        dds_type=dds_type,
        type_hash=hash_,
        qos=qos,
    )


# ---------------------------------------------------------------------------------------------- data
def gid(token: str) -> bytes:
    """An entity's 16-byte GID: XXH3-128 (seed 0) of its token key, low 64 bits then high 64 bits, each
    little-endian (what rmw_zenoh memcpy's on a little-endian machine)."""
    return xxhash.xxh3_128_intdigest(token.encode()).to_bytes(GID_SIZE, "little")


def pack_attachment(seq: int, stamp_ns: int, gid: bytes) -> bytes:
    """The attachment of a published message: int64 sequence number (the publisher's first message is 1),
    int64 source timestamp (ns since the UNIX epoch), then the GID as a sequence (length byte 16, 16 bytes),
    little-endian throughout; 33 bytes."""
    if len(gid) != GID_SIZE:
        raise ValueError(f"a GID is {GID_SIZE} bytes, not {len(gid)}")
    try:
        head = struct.pack("<qqB", seq, stamp_ns, GID_SIZE)
    except struct.error as exc:
        raise ValueError(f"sequence number and timestamp must fit int64: {exc}") from None
    return head + bytes(gid)


def unpack_attachment(data: bytes | None) -> tuple[int, int, bytes] | None:
    """`(seq, stamp_ns, gid)` from an attachment, or None when it is missing or not 33 bytes of that form."""
    if data is None:
        return None
    raw = bytes(data)
    if len(raw) != ATTACHMENT_SIZE or raw[16] != GID_SIZE:
        return None
    seq, stamp = struct.unpack_from("<qq", raw)
    return seq, stamp, raw[17:]
