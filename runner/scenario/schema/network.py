"""The run beyond its world: the machines it spans (`hosts:`), what one run asks of a cluster
(`resources:`), the processes started with it (`nodes:`), its Zenoh configuration (`zenoh:`), how ROS 2
sees it over rmw_zenoh (`ros2:`) and the topics it re-exposes under other keys (`bridges:`, like
ros_gz_bridge)."""

from __future__ import annotations

import re
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, Field, NonNegativeInt, PositiveFloat, field_validator, model_validator

from runner.errors import closest
from runner.scenario.schema.base import IDENT_RE, NODE_NAME_RE, TOPIC_RE, Namespace, Strict

_ENDPOINT_PATTERN = r"^(tcp|udp|tls|quic|ws|unixsock-stream|unixpipe|serial|vsock)/\S+$"


_PROTOCOLS = ("tcp", "udp", "tls", "quic", "ws", "unixsock-stream", "unixpipe", "serial", "vsock")
_IP_PROTOCOLS = ("tcp", "udp", "tls", "quic", "ws")
_IPV4 = re.compile(r"^[\d.]+$")


def endpoint_error(value: str, listen: bool) -> str | None:
    """Why `value` is not a Zenoh endpoint, as "<what is wrong>: write <the fix>" (the hint), or None.
    Zenoh's configuration takes any text and the mistake shows only when the run opens it (a port of
    70000, a protocol misspelt): it is said here, at its line. An endpoint to listen on may have port 0
    (any free port); one to connect to may not."""
    text = value.strip()
    m = re.match(r"^([A-Za-z0-9-]+)/(.*)$", text)
    if m is None:
        example = text.split("/")[-1] or "10.0.0.2:7447"
        return f"not a Zenoh endpoint: write it with its protocol, e.g. tcp/{example}"
    proto, rest = m.group(1), m.group(2)
    if proto not in _PROTOCOLS:
        near = closest(proto.lower(), _PROTOCOLS)
        return f"unknown Zenoh protocol {proto!r}: write " + (
            f"{near}/{rest}" if near else f"one of {', '.join(_PROTOCOLS)}"
        )
    if proto not in _IP_PROTOCOLS:
        return None
    address = re.split(r"[?#]", rest, maxsplit=1)[0]
    host, colon, port = address.rpartition(":")
    if address.endswith("]"):  # an IPv6 address without its port
        host, colon, port = address, "", ""
    if not colon or not host or host == "[":
        if not colon:
            return f"no port: write {proto}/<address>:<port>, e.g. {proto}/{address or '127.0.0.1'}:7447"
        return f"no address: write {proto}/<address>:<port>, e.g. {proto}/127.0.0.1:{port or 7447}"
    if not port.isdigit():
        return f"the port {port!r} is not a number: write a port from 1 to 65535, e.g. {proto}/{host}:7447"
    low = 0 if listen else 1
    if not low <= int(port) <= 65535:
        return (
            f"port {int(port)} is out of range ({low}-65535): write a port from 1 to 65535, "
            f"e.g. {proto}/{host}:7447" + (" (or 0 for any free port)" if listen else "")
        )
    if host.startswith("[") != host.endswith("]"):
        return f"an IPv6 address goes in brackets: write {proto}/[::1]:{port}"
    if _IPV4.match(host) and (
        len(host.split(".")) != 4 or any(not o.isdigit() or int(o) > 255 for o in host.split("."))
    ):
        return f"{host!r} is not an IPv4 address: write four numbers 0-255, e.g. {proto}/127.0.0.1:{port}"
    return None


def _listen_endpoint(value: str) -> str:
    error = endpoint_error(value, listen=True)
    if error:
        raise ValueError(error)
    return value


def _connect_endpoint(value: str | None) -> str | None:
    error = endpoint_error(value, listen=False) if value is not None else None
    if error:
        raise ValueError(error)
    return value


class Host(Strict):
    """A machine of the run, by the Zenoh endpoint its runner listens on."""

    endpoint: str = Field(
        description="Zenoh endpoint of this host's runner, e.g. `tcp/10.0.0.2:7447`. The first host of "
        "`hosts:` is the main one: it records and judges; the others run `scenario run FILE --host NAME` "
        "and join it.",
        json_schema_extra={"pattern": _ENDPOINT_PATTERN},
    )

    @field_validator("endpoint")
    @classmethod
    def _an_endpoint(cls, value: str) -> str:
        if not re.match(_ENDPOINT_PATTERN, value):
            example = value.split("/")[-1] or "10.0.0.2:7447"
            raise ValueError(f"not a Zenoh endpoint: write it with its protocol, e.g. tcp/{example}")
        return _connect_endpoint(value)  # type: ignore[return-value]


class Node(Strict):
    """A process of the run: a controller, a planner, a bridge. It gets the run's Zenoh endpoint, name,
    its namespace and the clock key in its environment (`SCENARIO_ENDPOINT`, `SCENARIO_RUN`,
    `SCENARIO_NAMESPACE`, `SCENARIO_CLOCK`, `SCENARIO_NODE`); `runner.node.Node()` reads them."""

    name: Annotated[str, Field(pattern=NODE_NAME_RE.pattern)] = Field(
        description="Node name (letters, digits, '_', '-'): in logs, `lockstep:` and the run's report."
    )
    cmd: str | list[str] = Field(
        description="The command: a string split like a shell would (`python nodes/go_to_goal.py`), or a "
        "list. A leading `python` is this interpreter. Relative paths are relative to `cwd`."
    )
    args: list[str] = Field(default_factory=list, description="Extra arguments after the command.")
    publishes: dict[Annotated[str, Field(pattern=TOPIC_RE.pattern)], str] = Field(
        default_factory=dict,
        description="Topics the node publishes that assertions and events read: topic (relative to its "
        "namespace, or `/abs`) -> ROS 2 type, e.g. `{status: std_msgs/msg/String}`.",
    )
    env: dict[str, str] = Field(default_factory=dict, description="Extra environment variables.")
    cwd: str | None = Field(None, description="Working folder (default: the scenario's folder).")
    namespace: Namespace | None = Field(
        None, description="The robot namespace it works in (`SCENARIO_NAMESPACE`), e.g. `r1`."
    )
    respawn: Literal["never", "on-failure"] = Field(
        "never", description="Start it again when it exits with an error (up to `respawn_limit` times)."
    )
    respawn_limit: NonNegativeInt = Field(3, description="Restarts allowed with `respawn: on-failure`.")
    required: bool = Field(
        False, description="The run fails (exit 1) and stops when this node exits before the run ends."
    )
    host: str | None = Field(None, description="With `hosts:`, the host that runs it (default: the first).")
    world: str | None = Field(
        None,
        description="With `worlds:`, the world whose key space the node works in (`SCENARIO_RUN` is "
        "`<run>/<world>`; default: the world of the robot named by its namespace, else the first).",
    )


class Resources(Strict):
    """What one run of the scenario asks of a cluster (`scenario test --ray`): Ray schedules each run (each
    matrix variant) where these are free. Without it, a run asks one CPU per world, node and renderer
    process, and with `--gpus` a GPU when it has cameras."""

    num_cpus: PositiveFloat | None = Field(
        None, description="CPUs one run takes (fractions allowed, e.g. 0.5); default: its processes."
    )
    num_gpus: Annotated[float, Field(ge=0)] | None = Field(
        None,
        description="GPUs one run takes (fractions share one, e.g. 0.25); default: per `scenario test "
        "--gpus` (auto: 1 for a run with cameras when the cluster has GPUs).",
    )
    custom: dict[Annotated[str, Field(pattern=r"^[A-Za-z_][A-Za-z0-9_.:-]*$")], PositiveFloat] = Field(
        default_factory=dict,
        description="The cluster's own resources one run takes, by name (as `ray start --resources` "
        "declares them), e.g. `{lidar_box: 1}`.",
    )

    @field_validator("custom")
    @classmethod
    def _not_builtin(cls, v: dict[str, float]) -> dict[str, float]:
        for name in v:
            if name in ("CPU", "GPU", "memory", "object_store_memory"):
                fix = {"GPU": "`num_gpus: 1`", "CPU": "`num_cpus: 2`"}.get(name, "num_cpus / num_gpus only")
                raise ValueError(
                    f"custom.{name}: say it with num_cpus / num_gpus, not as a custom resource: write {fix}"
                )
        return v


class Ros2(Strict):
    """Be seen by ROS 2 over rmw_zenoh (no ROS needed here): topics under rmw_zenoh's keys
    (`<domain>/<name>/<type>/<hash>`), with its liveliness tokens and attachments, so `ros2 topic list`,
    `ros2 topic echo` and rclcpp/rclpy nodes running `RMW_IMPLEMENTATION=rmw_zenoh_cpp` see the run."""

    domain: Annotated[int, Field(ge=0, le=232)] = Field(0, description="ROS_DOMAIN_ID.")
    node: Annotated[str, Field(pattern=IDENT_RE.pattern)] | None = Field(
        None, description="The ROS 2 node name the simulation appears as (default: the run's name)."
    )
    router: Annotated[str | None, AfterValidator(_connect_endpoint)] = Field(
        None,
        description="Zenoh endpoint of a ROS 2 Zenoh router to join (e.g. `tcp/127.0.0.1:7447`, where "
        "`ros2 run rmw_zenoh_cpp rmw_zenohd` listens). Default: ROS 2 nodes join the run's own router "
        "(`scenario run FILE --listen tcp/127.0.0.1:7447` puts it where rmw_zenoh looks by default).",
    )
    topics: Literal["all", "bridged"] = Field(
        "all",
        description="`all`: every topic of the simulation appears as `/<namespace>/<topic>` (and "
        "`/clock`), in the directions the simulation uses it; `bridged`: only the `bridges:`.",
    )


class ZenohSettings(Strict):
    """The run's Zenoh configuration, passed to every session of the run (router, worlds, renderers,
    nodes, bridge, and the command-line tools that join it): TLS, access control, anything Zenoh has."""

    config: str | None = Field(
        None, description="A Zenoh configuration file (JSON5), relative to the scenario, taken first."
    )
    settings: dict[str, Any] = Field(
        default_factory=dict,
        description="Settings by their path in Zenoh's configuration, on top of the file, e.g. "
        "`transport/link/tls/root_ca_certificate: certs/ca.pem` (file paths relative to the scenario).",
    )
    listen: list[Annotated[str, AfterValidator(_listen_endpoint)]] = Field(
        default_factory=list,
        description="The run's router endpoints, e.g. `tls/127.0.0.1:7447` (default: a free TCP port on "
        "127.0.0.1: loopback only unless told otherwise; `--listen` overrides).",
    )


BridgeDirection = Literal["SIM_TO_ZENOH", "ZENOH_TO_SIM", "BIDIRECTIONAL"]


class Bridge(Strict):
    """A sim topic re-exposed under another key, encoding or direction; or (`file:`) a ros_gz_bridge
    configuration file, taken as it is."""

    topic: str | None = Field(
        None,
        description="The sim topic, as in the timeline (`r1/scan`, `/clock`); from a `file:`, the gz "
        "topic names resolve to the sim topic of the same name (in `robot`'s namespace, if given).",
    )
    file: str | None = Field(
        None,
        description="A ros_gz_bridge YAML file (relative to the scenario): `topic_name` / `ros_topic_name` "
        "/ `gz_topic_name`, `ros_type_name`, `gz_type_name`, `direction` (GZ_TO_ROS, ROS_TO_GZ, "
        "BIDIRECTIONAL), `lazy`. gz topics are our sim topics; ROS topics are Zenoh keys (or rmw_zenoh "
        "topics with `ros2:`).",
    )
    robot: str | None = Field(
        None,
        description="With `file:`: the robot whose topics the gz names are, and whose namespace relative "
        "ROS names go under (like ros_gz_bridge started in that namespace).",
    )
    key: str | None = Field(
        None,
        description="The Zenoh key expression on the other side (default: the topic's own name, outside "
        "the run: `r1/scan`). With `ros2:` the key is rmw_zenoh's and this is not used.",
    )
    ros_topic: str | None = Field(
        None, description="With `ros2:`, the ROS 2 topic name (default: `/<topic>`)."
    )
    type: str | None = Field(
        None, description="ROS 2 type (default: the sim topic's own), e.g. `geometry_msgs/msg/Twist`."
    )
    direction: BridgeDirection = Field(
        "SIM_TO_ZENOH",
        description="`SIM_TO_ZENOH` (the sim's messages out), `ZENOH_TO_SIM` (messages from outside into "
        "the sim, e.g. commands) or `BIDIRECTIONAL`.",
    )
    encoding: Literal["cdr", "json"] = Field(
        "cdr",
        description="On the other side: `cdr` (the same bytes as in the sim) or `json` (the message's "
        'fields as a JSON object, e.g. `{"linear": {"x": 0.5}}`).',
    )
    rate: PositiveFloat | None = Field(
        None, description="At most this many messages per sim second to the other side (a throttle)."
    )
    lazy: bool = Field(
        False,
        description="Forward only while someone subscribes on the other side (SIM_TO_ZENOH), like "
        "ros_gz_bridge's `lazy`.",
    )
    ros2: Ros2 | bool | None = Field(
        None,
        description="Use rmw_zenoh's format for this bridge (`true`: the scenario's `ros2:` settings, or "
        "the defaults). Default: the scenario's `ros2:`, if set.",
    )

    @model_validator(mode="after")
    def _one_source(self) -> Bridge:
        if (self.topic is None) == (self.file is None):
            raise ValueError(
                "a bridge has either `topic:` (one mapping) or `file:` (a ros_gz_bridge file): "
                "write one of them, in a bridge of its own"
            )
        if self.file is not None:
            extra = [f for f in ("key", "ros_topic", "type") if getattr(self, f) is not None]
            if extra:
                raise ValueError(f"{', '.join(extra)}: set per entry inside the file, not beside `file:`")
        elif self.robot is not None:
            raise ValueError("`robot:` goes with `file:`; for one topic write it in the topic (`r1/scan`)")
        return self
