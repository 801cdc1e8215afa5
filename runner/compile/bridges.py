"""`bridges:` and `ros2:` -> resolved `BridgePlan`s, and the bridge process that runs them.

Each mapping is resolved here, against the topics the compiled worlds publish and subscribe to, so that a
name that matches nothing, or matches several robots, or a type that does not fit, is an error at its line
(of the scenario, or of the ros_gz_bridge file) before anything starts.

ros_gz_bridge files are taken as they are: a list of entries with `topic_name` (both sides) or
`ros_topic_name` + `gz_topic_name`, `ros_type_name`, `gz_type_name`, `direction` (`GZ_TO_ROS`,
`ROS_TO_GZ`, `BIDIRECTIONAL`, the default), `lazy`; queue sizes are read and not needed. A gz topic is one
of our sim topics (the names the robot's `<gazebo>` plugins gave them); a ROS topic is a Zenoh key, or an
rmw_zenoh topic with `ros2:`.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NamedTuple

import zenoh

from runner.compile.ros2_mirror import mirror_all, mirror_services
from runner.errors import Problem, ScenarioError, closest, did_you_mean
from runner.plan import BridgePlan, NodePlan, Ros2Plan, RunPlan, ServiceBridgePlan
from runner.scenario.loader import Document, PathKey, load_file
from runner.scenario.schema import Bridge, Ros2, Scenario
from runner.wire import msgs
from runner.wire.transport import hidden_topic

_GZ_DIRECTIONS = {"GZ_TO_ROS": "SIM_TO_ZENOH", "ROS_TO_GZ": "ZENOH_TO_SIM", "BIDIRECTIONAL": "BIDIRECTIONAL"}
_FILE_KEYS = {
    "topic_name",
    "ros_topic_name",
    "gz_topic_name",
    "ign_topic_name",
    "ros_type_name",
    "gz_type_name",
    "ign_type_name",
    "direction",
    "lazy",
    "subscriber_queue",
    "publisher_queue",
    "qos_profile",
}
# ros_gz_bridge's conversions for the types a simulation publishes: a pair it cannot convert is refused
# (by ros_gz_bridge at run time, here at validation)
_GZ_TYPES: dict[str, set[str]] = {
    "rosgraph_msgs/msg/Clock": {"Clock"},
    "geometry_msgs/msg/Twist": {"Twist"},
    "geometry_msgs/msg/TwistStamped": {"Twist"},
    "geometry_msgs/msg/Pose": {"Pose"},
    "geometry_msgs/msg/PoseStamped": {"Pose"},
    "geometry_msgs/msg/PoseArray": {"Pose_V"},
    "geometry_msgs/msg/Wrench": {"Wrench"},
    "nav_msgs/msg/Odometry": {"Odometry", "OdometryWithCovariance"},
    "sensor_msgs/msg/Imu": {"IMU"},
    "sensor_msgs/msg/LaserScan": {"LaserScan"},
    "sensor_msgs/msg/PointCloud2": {"PointCloudPacked"},
    "sensor_msgs/msg/Image": {"Image"},
    "sensor_msgs/msg/CameraInfo": {"CameraInfo"},
    "sensor_msgs/msg/JointState": {"Model"},
    "tf2_msgs/msg/TFMessage": {"Pose_V"},
    "std_msgs/msg/String": {"StringMsg"},
    "std_msgs/msg/Bool": {"Boolean"},
    "std_msgs/msg/Float64": {"Double"},
}


class _Topics:
    """The run's sim topics: key -> (type, directions)."""

    def __init__(self, plan: RunPlan):
        self.run = plan.name
        self.table: dict[str, tuple[str, set[str]]] = {}
        for part in plan.parts():
            for t in part.topics():
                entry = self.table.setdefault(t.key, (t.type, set()))
                entry[1].add(t.direction)

    def resolve(self, topic: str, namespace: str | None) -> list[str]:
        """Keys a (gz or scenario) topic name may mean: the robot's own first, then the run's, then any
        robot's of that name."""
        run, name = self.run, topic.strip("/")
        if name == run or name.startswith(run + "/"):
            name = name[len(run) + 1 :]
        for key in ([f"{run}/{namespace}/{name}"] if namespace else []) + [f"{run}/{name}"]:
            if key in self.table:
                return [key]
        return sorted(k for k in self.table if k.endswith("/" + name) and not hidden_topic(k[len(run) + 1 :]))

    def short(self) -> list[str]:
        """The topics without the run's name, as a scenario writes them (`r1/scan`)."""
        return sorted(k[len(self.run) + 1 :] for k in self.table if not hidden_topic(k[len(self.run) + 1 :]))

    def names(self) -> str:
        return ", ".join(self.short())


def _ros2_plan(setting: Ros2 | bool | None, default: Ros2 | None, run: str) -> Ros2Plan | None:
    from runner.wire.ros2 import valid_node_name

    if setting is False or (setting is None and default is None):
        return None
    chosen = setting if isinstance(setting, Ros2) else (default or Ros2())
    return Ros2Plan(
        domain=chosen.domain,
        node=chosen.node or valid_node_name(run),
        router=chosen.router,
        topics=chosen.topics,
    )


def _qualify(name: str, namespace: str | None) -> str:
    """A ROS name made absolute: relative names go under the namespace."""
    if name.startswith("/"):
        return "/" + name.strip("/")
    return "/" + "/".join(p for p in ((namespace or "").strip("/"), name.strip("/")) if p)


def attach_bridges(plan: RunPlan, sc: Scenario, doc: Document, unchecked: Sequence[str] = ()) -> None:
    """Resolve `bridges:` (and `ros2:`) into `plan.bridges`, and add the bridge process to the nodes.
    A bridge on a robot that did not load whole (its key prefix in `unchecked`, its mistakes reported)
    has only its type checked: the robot's topics are not known."""
    topics = _Topics(plan)
    problems: list[Problem] = []
    out: list[BridgePlan] = []
    robots = {r.name: r.ns for r in sc.robots}
    lost = {p.rstrip("/").rsplit("/", 1)[-1] for p in unchecked}  # the namespaces of those robots
    for i, b in enumerate(sc.bridges):
        where: PathKey = (
            ("bridges", i)
            if len(sc.bridges) > 1 or isinstance(doc.data.get("bridges"), list)
            else ("bridges",)
        )
        on = robots.get(b.robot or "") or next(
            (ns for ns in lost if f"/{ns}/" in f"/{(b.topic or '').strip('/')}/"), None
        )
        if on in lost:  # only what does not depend on the robot's topics
            if b.type is not None:
                _check_type(b.type, None, doc, (*where, "type"), problems)
            continue
        ros2 = _ros2_plan(b.ros2, sc.ros2, sc.name)
        if b.robot is not None and b.robot not in robots:
            at = (*where, "robot")
            problems.append(
                Problem(
                    f"no robot named {b.robot!r}",
                    doc.locate(at),
                    at,
                    expected="one of: " + ", ".join(robots) if robots else "a robot of this scenario",
                    hint=did_you_mean(b.robot, robots, "robots"),
                )
            )
            continue
        if b.file is not None:
            out += _from_file(b, doc, where, topics, robots.get(b.robot or ""), ros2, problems)
        else:
            out += _one(b, doc, where, topics, ros2, problems)
    if problems:
        raise ScenarioError(problems)
    run_ros2 = _ros2_plan(sc.ros2, None, sc.name)
    services: list[ServiceBridgePlan] = []
    if run_ros2 is not None and run_ros2.topics == "all":
        out += mirror_all(topics.table, topics.run, run_ros2, plan)
        services = mirror_services(plan, run_ros2)
    if plan.best_effort:
        drop = [zenoh.KeyExpr(e) for e in plan.best_effort]
        for b in out:
            b.best_effort = any(e.intersects(zenoh.KeyExpr(b.sim_key)) for e in drop)
    plan.bridges = out
    plan.service_bridges = services
    plan.ros2 = run_ros2
    if out or services:
        taken = {n.name for n in plan.nodes}
        name = next(n for n in ("bridge", "_bridge", "scenario_bridge") if n not in taken)
        spec = {
            "run": plan.name,
            "clocks": [p.clock_key for p in plan.parts()],
            "bridges": [b.model_dump(mode="json") for b in out],
            "services": [s.model_dump(mode="json") for s in services],
            # nodes' topics are known once they run: the bridge mirrors them as they appear
            "mirror_nodes": run_ros2.model_dump(mode="json")
            if run_ros2 is not None and run_ros2.topics == "all"
            else None,
        }
        plan.nodes.append(
            NodePlan(
                name=name,
                argv=[sys.executable, "-m", "runner.launch.bridge"],
                env={"SCENARIO_BRIDGE": json.dumps(spec)},
                cwd=str(doc.base_dir),
                required=True,  # a bridge lost is a run that no longer does what it says
            )
        )


def _check_type(
    type_name: str | None, known: str | None, doc: Document, at: PathKey, problems: list[Problem]
) -> str | None:
    if type_name is None:
        return known
    full = msgs.normalize_type(type_name)
    if not msgs.is_known(full):
        near = msgs.similar_types(full)
        problems.append(
            Problem(
                f"unknown message type {type_name!r}",
                doc.locate(at),
                at,
                hint=f"did you mean {', '.join(near)}?"
                if near
                else "a ROS 2 type, e.g. sensor_msgs/msg/LaserScan",
            )
        )
        return None
    if known is not None and known != full:
        problems.append(
            Problem(
                f"the sim topic is {known}, not {full}",
                doc.locate(at),
                at,
                expected=known,
                found=full,
                hint="a bridge passes messages on as they are; give the topic's own type",
            )
        )
        return None
    return full


def _sim_key(
    topic: str,
    namespace: str | None,
    direction: str,
    type_given: bool,
    topics: _Topics,
    doc: Document,
    at: PathKey,
    problems: list[Problem],
) -> str | None:
    keys = topics.resolve(topic, namespace)
    if len(keys) == 1:
        return keys[0]
    if len(keys) > 1:
        problems.append(
            Problem(
                f"{topic!r} is a topic of several robots: "
                + ", ".join(k[len(topics.run) + 1 :] for k in keys),
                doc.locate(at),
                at,
                hint="name the robot: `r1/scan` for one topic, or `robot: r1` beside `file:`",
            )
        )
        return None
    if type_given or direction == "ZENOH_TO_SIM":
        # a topic no plugin declares (a node's, or a command nothing in the world reads yet): taken as named
        name = topic.strip("/")
        return (
            f"{topics.run}/{namespace}/{name}"
            if namespace and not topic.startswith("/")
            else (f"{topics.run}/{name}")
        )
    problems.append(
        Problem(
            f"no sim topic named {topic!r}",
            doc.locate(at),
            at,
            expected="one of: " + topics.names(),
            hint=(f"did you mean {near!r}? " if (near := closest(topic.strip("/"), topics.short())) else "")
            + "for a topic a node publishes, give its `type:`",
        )
    )
    return None


def _one(
    b: Bridge, doc: Document, where: PathKey, topics: _Topics, ros2: Ros2Plan | None, problems: list[Problem]
) -> list[BridgePlan]:
    assert b.topic is not None
    n = len(problems)
    key = _sim_key(b.topic, None, b.direction, b.type is not None, topics, doc, (*where, "topic"), problems)
    known = topics.table.get(key, (None, set()))[0] if key else None
    type_name = _check_type(b.type, known, doc, (*where, "type"), problems)
    if key is None or len(problems) > n:
        return []
    if type_name is None:
        at = (*where, "type")
        hint = "add `type:` with the topic's ROS 2 type, e.g. geometry_msgs/msg/Twist"
        problems.append(Problem("the topic's type is not known here; give it", doc.locate(at), at, hint=hint))
        return []
    rel = key[len(topics.run) + 1 :]
    common = {"where": _where(doc, where), "sim_key": key, "type": type_name, "direction": b.direction}
    common |= {"rate": b.rate, "lazy": b.lazy}
    if ros2 is not None:
        if b.encoding != "cdr":
            at = (*where, "encoding")
            hint = "remove `encoding:` (or set it to cdr) on a bridge to ROS 2"
            problem = Problem(
                "ROS 2 speaks CDR", doc.locate(at), at, expected="cdr", found=b.encoding, hint=hint
            )
            problems.append(problem)
            return []
        return [BridgePlan(**common, ros_topic=_qualify(b.ros_topic or rel, None), ros2=ros2)]
    other = (b.key or rel).strip("/")
    if not _key_ok(other, b.direction, topics.run, doc, (*where, "key"), problems):
        return []
    return [BridgePlan(**common, key=other, encoding=b.encoding)]


def _key_ok(
    other: str, direction: str, run: str, doc: Document, at: PathKey, problems: list[Problem]
) -> bool:
    import zenoh

    try:
        expr = zenoh.KeyExpr(other)
    except Exception as e:
        hint = "chunks separated by '/', no empty chunk, no leading or trailing '/'"
        problems.append(
            Problem(f"{other!r} is not a Zenoh key expression: {e}", doc.locate(at), at, hint=hint)
        )
        return False
    if expr.intersects(zenoh.KeyExpr(f"{run}/**")) or other == run:
        problems.append(
            Problem(
                f"{other!r} is inside the run's own key space",
                doc.locate(at),
                at,
                hint="the bridged key must differ from the sim's keys, or the bridge would feed itself",
            )
        )
        return False
    if direction != "ZENOH_TO_SIM" and any(c in other for c in "*$"):
        problems.append(
            Problem(
                f"{other!r} has wildcards: the sim's messages need one key to go to",
                doc.locate(at),
                at,
                hint="wildcards are for ZENOH_TO_SIM (several sources into one sim topic)",
            )
        )
        return False
    return True


def _where(doc: Document, path: PathKey) -> str:
    from runner.errors import format_path

    return f"{doc.locate(path)} ({format_path(path)})"


def _from_file(
    b: Bridge,
    doc: Document,
    where: PathKey,
    topics: _Topics,
    namespace: str | None,
    ros2: Ros2Plan | None,
    problems: list[Problem],
) -> list[BridgePlan]:
    assert b.file is not None
    path = Path(b.file) if Path(b.file).is_absolute() else doc.base_dir / b.file
    if not path.is_file():
        at = (*where, "file")
        problems.append(
            Problem(f"file not found: {b.file}", doc.locate(at), at, hint="relative to the scenario's folder")
        )
        return []
    try:
        fdoc = load_file(path)
    except ScenarioError as e:
        problems += e.problems
        return []
    entries = fdoc.data
    if not isinstance(entries, list):
        problems.append(
            Problem(
                "a ros_gz_bridge file is a list of entries",
                fdoc.locate(()),
                expected="- ros_topic_name: ...\n    gz_topic_name: ...",
                found=type(entries).__name__,
                hint="write each entry as a list item starting with `- `, as ros_gz_bridge's config files do",
            )
        )
        return []
    out: list[BridgePlan] = []
    for j, entry in enumerate(entries):
        plan = _file_entry(entry, j, fdoc, b, topics, namespace, ros2, problems)
        if plan is not None:
            out.append(plan)
    return out


class _FileEntry(NamedTuple):
    """The fields of one entry of a ros_gz_bridge file, as written (checked for presence and form)."""

    gz_name: Any
    ros_name: Any
    ros_type: Any
    gz_type: Any
    direction: str
    lazy: bool


# What to do, for the mistakes of a ros_gz_bridge file entry that are always said the same way
_FILE_HINTS = {
    "an entry is a mapping": "give the entry's keys under its `- `, one per line",
    "services are not bridged (topics only)": "remove the entry; a node of the scenario can serve it instead",
    "topic_name names both sides": "drop ros_topic_name/gz_topic_name, or topic_name",
    "an entry names its topic": "add `topic_name:` when both sides use the same name",
    "ros_type_name is missing": "add `ros_type_name:`",
    "gz_type_name is missing": "add `gz_type_name:`",
    "lazy is true or false": "write `lazy: true` or `lazy: false`",
    "a Gazebo type is gz.msgs.<Name>": "write gz.msgs.<Name>, e.g. gz.msgs.LaserScan",
}
_DIRECTIONS_TEXT = "GZ_TO_ROS, ROS_TO_GZ or BIDIRECTIONAL"
_Report = Callable[..., None]  # problem(message, key=None, **Problem's keywords) at an entry (and key)


def _file_entry(
    entry: Any,
    j: int,
    fdoc: Document,
    b: Bridge,
    topics: _Topics,
    namespace: str | None,
    ros2: Ros2Plan | None,
    problems: list[Problem],
) -> BridgePlan | None:
    """Entry `j` of the ros_gz_bridge file of bridge `b` as a bridge (None: its problems are reported)."""

    def problem(message: str, key: str | None = None, **kw: Any) -> None:
        at: PathKey = (j, key) if key else (j,)
        kw.setdefault("hint", _FILE_HINTS.get(message, "see ros_gz_bridge's configuration file format"))
        problems.append(Problem(message, fdoc.locate(at), at, **kw))

    fields = _entry_fields(entry, problem, problems)
    if fields is None:
        return None
    full = _entry_type(fields, problem)
    if full is None:
        return None
    ours = _GZ_DIRECTIONS[fields.direction]
    at: PathKey = (j, "gz_topic_name" if "gz_topic_name" in entry else "topic_name")
    key = _sim_key(str(fields.gz_name), namespace, ours, False, topics, fdoc, at, problems)
    if key is None:
        return None
    known = topics.table.get(key, (None, set()))[0]
    if known is not None and known != full:
        problem(
            f"the sim topic {key[len(topics.run) + 1 :]} is {known}, not {full}",
            "ros_type_name",
            expected=known,
            found=full,
            hint="a bridge passes messages on as they are; give the topic's own type",
        )
        return None
    fq = _qualify(str(fields.ros_name), namespace)
    common = {"where": f"{fdoc.locate((j,))} ({b.file} entry {j})", "sim_key": key, "type": full}
    common |= {"direction": ours, "lazy": fields.lazy, "rate": b.rate}
    if ros2 is not None:
        return BridgePlan(**common, ros_topic=fq, ros2=ros2)
    other = fq.strip("/")
    if not _key_ok(other, ours, topics.run, fdoc, (j,), problems):
        return None
    return BridgePlan(**common, key=other, encoding=b.encoding)


def _entry_fields(entry: Any, problem: _Report, problems: list[Problem]) -> _FileEntry | None:
    """An entry's keys known, its topic named (`topic_name`, or both sides'), both types, its direction and
    `lazy` of the right form; None when any is not (each reported)."""
    if not isinstance(entry, dict):
        problem("an entry is a mapping", expected="ros_topic_name, gz_topic_name, ros_type_name, ...")
        return None
    if "service_name" in entry:
        problem("services are not bridged (topics only)", "service_name")
        return None
    n = len(problems)
    for k in entry:
        if k not in _FILE_KEYS:
            import difflib

            near = difflib.get_close_matches(str(k), sorted(_FILE_KEYS), n=1)
            problem(
                f"unknown key {k!r}",
                str(k),
                expected=", ".join(sorted(_FILE_KEYS)),
                hint=f"did you mean {near[0]!r}?" if near else "remove it",
            )
    gz_name = entry.get("gz_topic_name", entry.get("ign_topic_name"))
    ros_name = entry.get("ros_topic_name")
    if "topic_name" in entry:
        if ros_name is not None or gz_name is not None:
            problem("topic_name names both sides", "topic_name")
        gz_name = ros_name = entry["topic_name"]
    elif gz_name is None or ros_name is None:
        problem(
            "an entry names its topic",
            expected="topic_name (both sides), or ros_topic_name and gz_topic_name",
        )
    ros_type = entry.get("ros_type_name")
    gz_type = entry.get("gz_type_name", entry.get("ign_type_name"))
    if ros_type is None:
        problem("ros_type_name is missing", expected="a ROS 2 type, e.g. sensor_msgs/msg/LaserScan")
    if gz_type is None:
        problem("gz_type_name is missing", expected="a Gazebo type, e.g. gz.msgs.LaserScan")
    direction = entry.get("direction", "BIDIRECTIONAL")
    if not isinstance(direction, str) or direction not in _GZ_DIRECTIONS:
        near = closest(direction, _GZ_DIRECTIONS) if isinstance(direction, str) else None
        hint = (
            f"did you mean {near!r}?"
            if near
            else "one word, not a list: GZ_TO_ROS, ROS_TO_GZ or BIDIRECTIONAL"
        )
        problem(f"unknown direction {direction!r}", "direction", expected=_DIRECTIONS_TEXT, hint=hint)
    lazy = entry.get("lazy", False)
    if not isinstance(lazy, bool):
        problem("lazy is true or false", "lazy", found=repr(lazy))
    if len(problems) > n:
        return None
    return _FileEntry(gz_name, ros_name, ros_type, gz_type, direction, lazy)


def _entry_type(fields: _FileEntry, problem: _Report) -> str | None:
    """The entry's ROS type in full, when it is known and ros_gz_bridge converts it to the Gazebo type the
    entry names; None when not (reported)."""
    ros_type, gz_type = fields.ros_type, fields.gz_type
    full = msgs.normalize_type(str(ros_type))
    if not msgs.is_known(full):
        near = msgs.similar_types(full)
        hint = f"did you mean {', '.join(near)}?" if near else "a ROS 2 type, e.g. sensor_msgs/msg/LaserScan"
        problem(f"unknown message type {ros_type!r}", "ros_type_name", hint=hint)
        return None
    gz_short = str(gz_type).removeprefix("gz.msgs.").removeprefix("ignition.msgs.")
    if gz_short == str(gz_type):
        problem("a Gazebo type is gz.msgs.<Name>", "gz_type_name", found=str(gz_type))
        return None
    allowed = _GZ_TYPES.get(full)
    if allowed is not None and gz_short not in allowed:
        problem(
            f"ros_gz_bridge has no conversion between {full} and {gz_type}",
            "gz_type_name",
            expected=" or ".join(f"gz.msgs.{a}" for a in sorted(allowed)),
            found=str(gz_type),
            hint="use the Gazebo type ros_gz_bridge pairs with this ROS type (expected above)",
        )
        return None
    return full
