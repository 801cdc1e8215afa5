"""`ros2: {topics: all}` follows the run's graph as it changes: a robot spawned into a running world (its
plugins' publishers, subscribers and services announced as new world graph tokens) appears to ROS 2, and
goes again when it is deleted (`ZenohBus.withdraw`: its entities undeclared, its tokens withdrawn), and
comes back when spawned again; the same for a node or a renderer process that stops. What is followed
mid-run is mirrored as the plan mirrors what it knows from the start (checked against the compiler's own
`mirror_all` / `mirror_services`).

No scenario here: the bridge process (`python -m runner.launch.bridge`) joins a Zenoh router on loopback,
and a second session plays the world with the world's own transport (`ZenohBus` with `GraphTokens` of
role "world"), declaring and withdrawing a robot mid-run. A third session looks at it the way a ROS 2
system on rmw_zenoh does: the liveliness tokens under `@ros2_lv/<domain>/`, subscribers, publishers and
queries on the topic keys with rmw_zenoh's attachments (format pinned by test_ros2_format.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import pytest
import zenoh
import zenoh.ext

from runner.compile.plugins import action_topics
from runner.launch.bridge_follow import service_plan, topic_plans
from runner.plan import BridgePlan, Ros2Plan, TopicPlan
from runner.wire import interfaces, msgs, ros2
from runner.wire.graph import Endpoint, GraphTokens
from runner.wire.transport import (
    ZenohBus,
    free_port,
    make_config,
    meta_key,
    pack_attachment,
    topic_key,
)
from tests.conftest import SCENARIOS
from tests.helpers import plan_of

RUN = "dyn"
DOMAIN = 21
ODOM = "nav_msgs/msg/Odometry"
TWIST = "geometry_msgs/msg/Twist"
TF = "tf2_msgs/msg/TFMessage"
TRIGGER = "std_srvs/srv/Trigger"
FJT = "control_msgs/action/FollowJointTrajectory"
ACTION = "arm_controller/follow_joint_trajectory"
WAIT_S = 20.0
ROS = Ros2Plan(domain=DOMAIN, node=RUN)


def _dds(type_name: str) -> str:
    return ros2.dds_type_name(type_name)


class RosView:
    """The ROS 2 graph as rmw_zenoh's graph cache keeps it: every entity token, added and removed as
    liveliness samples come."""

    def __init__(self, session: zenoh.Session):
        self.tokens: dict[str, ros2.TokenInfo] = {}
        self.cond = threading.Condition()
        self.sub = session.liveliness().declare_subscriber(f"@ros2_lv/{DOMAIN}/**", self._on, history=True)

    def _on(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        info = ros2.parse_token(key)
        with self.cond:
            if sample.kind == zenoh.SampleKind.PUT and info is not None:
                self.tokens[key] = info
            else:
                self.tokens.pop(key, None)
            self.cond.notify_all()

    def entities(self) -> list[tuple[str, str | None, str | None]]:
        with self.cond:
            return self.entities_locked()

    def token_of(self, kind: str, topic: str) -> str:
        with self.cond:
            return next(k for k, i in self.tokens.items() if i.kind == kind and i.topic == topic)

    def wait(self, check: Callable[[list[tuple[str, str | None, str | None]]], bool], what: str) -> None:
        deadline = time.monotonic() + WAIT_S
        with self.cond:
            while not check(self.entities_locked()):
                left = deadline - time.monotonic()
                if left <= 0:
                    raise AssertionError(f"{what}: ROS 2 sees {self.entities_locked()}")
                self.cond.wait(left)

    def entities_locked(self) -> list[tuple[str, str | None, str | None]]:
        return sorted((i.kind, i.topic, i.dds_type) for i in self.tokens.values() if i.kind != "NN")


@dataclass
class Inbox:
    """What arrives on one key, with a wait for a condition on it."""

    got: list[tuple[bytes, bytes | None]] = field(default_factory=list)
    cond: threading.Condition = field(default_factory=threading.Condition)

    def __call__(self, sample: zenoh.Sample) -> None:
        with self.cond:
            att = sample.attachment.to_bytes() if sample.attachment is not None else None
            self.got.append((sample.payload.to_bytes(), att))
            self.cond.notify_all()

    def put(self, payload: bytes, attachment: bytes | None) -> None:
        with self.cond:
            self.got.append((payload, attachment))
            self.cond.notify_all()

    def wait_until(self, check: Callable[[list[tuple[bytes, bytes | None]]], bool], timeout: float) -> bool:
        with self.cond:
            return self.cond.wait_for(lambda: check(self.got), timeout)


def _keep_sending(send: Callable[[], None], inbox: Inbox, check: Callable[[Any], bool], what: str) -> None:
    """Send until `check` holds for what arrived: a subscription just announced takes a moment to reach
    the sender's router."""
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        send()
        if inbox.wait_until(check, 0.1):
            return
    raise AssertionError(f"{what}: nothing arrived")


def _odom(x: float) -> bytes:
    msg = msgs.from_data(ODOM, {"header": {"frame_id": "r9/odom"}, "pose": {"pose": {"position": {"x": x}}}})
    return msgs.encode(msg, ODOM)


def _tf(child: str) -> bytes:
    data = {"transforms": [{"header": {"frame_id": "world"}, "child_frame_id": child}]}
    return msgs.encode(msgs.from_data(TF, data), TF)


def _children(payload: bytes) -> set[str]:
    return {t.child_frame_id for t in msgs.decode(payload, TF).transforms}


class Robot:
    """A robot's endpoints as its plugins declare them in the world (`ZenohBus`)."""

    def __init__(self, bus: ZenohBus, ns: str):
        self.bus = bus
        self.keys = {n: f"{RUN}/{ns}/{n}" for n in ("odom", "cmd_vel", "tf", "tf_static", "do_it")}
        self.commands = Inbox()
        self.odom = bus.publisher(self.keys["odom"], ODOM)
        self.tf = bus.publisher(self.keys["tf"], TF)
        self.tf_static = bus.publisher(self.keys["tf_static"], TF)
        bus.subscribe(self.keys["cmd_vel"], lambda _k, p, a: self.commands.put(p, a), TWIST)

        def answer(payload: bytes, _att: bytes | None, respond: Any) -> None:
            msgs.decode(payload, f"{TRIGGER}_Request")
            res = msgs.T[f"{TRIGGER}_Response"](success=True, message=f"{ns} did it")
            respond(msgs.encode(res, f"{TRIGGER}_Response"), None)

        bus.queryable(self.keys["do_it"], answer, TRIGGER)
        # an action server, as runner.plugin.actions declares one: three services and two topics
        services, topics = interfaces.action_parts(FJT)
        for suffix, type_name in topics:
            self.keys[suffix] = f"{RUN}/{ns}/{ACTION}/{suffix}"
            bus.publisher(self.keys[suffix], type_name)
        for suffix, type_name in services:
            self.keys[suffix] = f"{RUN}/{ns}/{ACTION}/{suffix}"
            bus.queryable(self.keys[suffix], lambda _p, _a, respond: respond(None, "not here"), type_name)

    def delete(self) -> None:
        for key in self.keys.values():
            self.bus.withdraw(key)


@dataclass
class Rig:
    world: ZenohBus
    ros: zenoh.Session
    view: RosView


@pytest.fixture
def rig() -> Iterator[Rig]:
    """A router, the bridge of run `dyn` (with the plan's own mappings for robot r1: odom, tf), a world
    session and a ROS 2 session."""
    port = free_port()
    endpoint = f"tcp/127.0.0.1:{port}"
    plans = [
        BridgePlan(
            where="ros2 (r1/odom)",
            sim_key=f"{RUN}/r1/odom",
            type=ODOM,
            direction="SIM_TO_ZENOH",
            ros_topic="/r1/odom",
            ros2=ROS,
        ),
        BridgePlan(
            where="ros2 (r1/tf on /tf)",
            sim_key=f"{RUN}/r1/tf",
            type=TF,
            direction="SIM_TO_ZENOH",
            ros_topic="/tf",
            ros2=ROS,
        ),
    ]
    spec = {
        "run": RUN,
        "clocks": [f"{RUN}/clock"],
        "bridges": [p.model_dump(mode="json") for p in plans],
        "services": [],
        "mirror_nodes": ROS.model_dump(mode="json"),
    }
    env = {**os.environ, "SCENARIO_BRIDGE": json.dumps(spec), "SCENARIO_ENDPOINT": endpoint}
    with (
        zenoh.open(make_config("router", listen=[endpoint])) as router,
        zenoh.open(make_config("client", connect=[endpoint])) as world_session,
        zenoh.open(make_config("client", connect=[endpoint])) as ros,
    ):
        bridge = subprocess.Popen(
            [sys.executable, "-m", "runner.launch.bridge"], env=env, stderr=subprocess.PIPE, text=True
        )
        world = ZenohBus(world_session, GraphTokens(world_session, RUN, "world", "world"))
        view = RosView(ros)
        try:
            ready = threading.Event()
            alive = router.liveliness().declare_subscriber(
                meta_key(RUN, "bridge", "alive"), lambda _s: ready.set(), history=True
            )
            assert ready.wait(WAIT_S), "the bridge did not start"
            alive.undeclare()
            yield Rig(world, ros, view)
        finally:
            view.sub.undeclare()
            world.undeclare_all()
            bridge.send_signal(2)
            _out, err = bridge.communicate(timeout=30)
            assert bridge.returncode == 0, err
            assert "Traceback" not in err, err


def _r9_entities(view: RosView) -> set[tuple[str, str | None, str | None]]:
    return {e for e in view.entities() if e[1] is not None and e[1].startswith("/r9/")}


R9 = {
    ("MP", "/r9/odom", _dds(ODOM)),
    ("MS", "/r9/cmd_vel", _dds(TWIST)),
    ("MP", "/r9/tf", _dds(TF)),
    ("MP", "/r9/tf_static", _dds(TF)),
    ("SS", "/r9/do_it", _dds(TRIGGER)),
    *(("SS", f"/r9/{ACTION}/{suffix}", _dds(t)) for suffix, t in interfaces.action_parts(FJT)[0]),
    *(("MP", f"/r9/{ACTION}/{suffix}", _dds(t)) for suffix, t in interfaces.action_parts(FJT)[1]),
}


def _check_r9_works(rig: Rig, robot: Robot, x: float) -> None:
    """What ROS 2 does with a robot: reads its odometry and transforms, drives it, calls its service."""
    ros, view = rig.ros, rig.view
    # ros2 topic echo /r9/odom: the world's message, as it was, with rmw_zenoh's attachment
    odom = Inbox()
    sub = ros.declare_subscriber(ros2.topic_key(DOMAIN, "/r9/odom", ODOM), odom)
    _keep_sending(lambda: robot.odom(_odom(x), pack_attachment(0, 0)), odom, bool, "/r9/odom")
    sub.undeclare()
    payload, att = odom.got[0]
    assert msgs.decode(payload, ODOM).pose.pose.position.x == x
    parsed = ros2.unpack_attachment(att)
    assert parsed is not None and parsed[2] == ros2.gid(view.token_of("MP", "/r9/odom"))

    # r9's transforms on /tf, beside r1's (the plan's mapping to the same publisher)
    tf = Inbox()
    sub = ros.declare_subscriber(ros2.topic_key(DOMAIN, "/tf", TF), tf)
    _keep_sending(
        lambda: robot.tf(_tf("r9/base_link"), pack_attachment(0, 0)),
        tf,
        lambda got: any("r9/base_link" in _children(p) for p, _a in got),
        "/tf",
    )
    sub.undeclare()

    # ros2 topic pub /r9/cmd_vel: reaches the world's subscriber, checked and stamped
    token = ros2.entity_token(DOMAIN, str(ros.zid()), 0, 1, "MP", "/", "teleop", "/r9/cmd_vel", TWIST)
    held = ros.liveliness().declare_token(token)
    pub = ros.declare_publisher(ros2.topic_key(DOMAIN, "/r9/cmd_vel", TWIST))
    twist = msgs.encode(msgs.from_data(TWIST, {"linear": {"x": x}}), TWIST)
    seq = iter(range(1, 10_000))
    _keep_sending(
        lambda: pub.put(twist, attachment=ros2.pack_attachment(next(seq), time.time_ns(), ros2.gid(token))),
        robot.commands,
        bool,
        "/r9/cmd_vel",
    )
    pub.undeclare()
    held.undeclare()
    assert msgs.decode(robot.commands.got[-1][0], TWIST).linear.x == x

    # ros2 service call /r9/do_it std_srvs/srv/Trigger, as rmw_zenoh's client calls
    gid = ros2.gid(ros2.entity_token(DOMAIN, str(ros.zid()), 0, 2, "SC", "/", "teleop", "/r9/do_it", TRIGGER))
    request = msgs.encode(msgs.T[f"{TRIGGER}_Request"](), f"{TRIGGER}_Request")
    replies = list(
        ros.get(
            ros2.topic_key(DOMAIN, "/r9/do_it", TRIGGER),
            payload=request,
            attachment=ros2.pack_attachment(7, time.time_ns(), gid),
            target=zenoh.QueryTarget.ALL_COMPLETE,
            consolidation=zenoh.ConsolidationMode.NONE,
            timeout=WAIT_S,
        )
    )
    ok = [r.ok for r in replies if r.ok is not None]
    assert len(ok) == 1, [r.err.payload.to_string() for r in replies if r.err is not None]
    response = msgs.decode(ok[0].payload.to_bytes(), f"{TRIGGER}_Response")
    assert response.success and response.message == "r9 did it"
    answered = ros2.unpack_attachment(ok[0].attachment.to_bytes() if ok[0].attachment else None)
    assert answered is not None and answered[0] == 7 and answered[2] == gid


def _check_r9_gone(rig: Rig) -> None:
    """No ROS 2 entity of r9 left, and what is put on its sim key no longer reaches ROS 2: r1's odometry,
    put after it from the same session, arrives; r9's, had it been forwarded, would have come first."""
    ros, view = rig.ros, rig.view
    view.wait(lambda ents: not any(t and t.startswith("/r9/") for _k, t, _d in ents), "r9 withdrawn")
    r9, r1 = Inbox(), Inbox()
    subs = [
        ros.declare_subscriber(ros2.topic_key(DOMAIN, "/r9/odom", ODOM), r9),
        ros.declare_subscriber(ros2.topic_key(DOMAIN, "/r1/odom", ODOM), r1),
    ]
    stray = ros.declare_publisher(f"{RUN}/r9/odom")
    r1_pub = ros.declare_publisher(f"{RUN}/r1/odom")

    def send() -> None:
        stray.put(_odom(9.0), attachment=pack_attachment(0, 0))
        r1_pub.put(_odom(1.0), attachment=pack_attachment(0, 0))

    _keep_sending(send, r1, bool, "/r1/odom")
    for s in (*subs, stray, r1_pub):
        s.undeclare()
    assert r9.got == []
    assert ("MP", "/tf", _dds(TF)) in view.entities()  # r1 still feeds it


@pytest.mark.timeout(120)
def test_a_robot_spawned_mid_run_appears_to_ros2_goes_when_deleted_and_comes_back(rig: Rig) -> None:
    view = rig.view
    view.wait(lambda ents: ("MP", "/r1/odom", _dds(ODOM)) in ents, "the plan's r1/odom")
    # the world's endpoints the plan maps already are not mirrored twice
    r1_odom = rig.world.publisher(f"{RUN}/r1/odom", ODOM)
    for attempt in range(2):
        robot = Robot(rig.world, "r9")
        view.wait(lambda ents: set(ents) >= R9, f"r9 spawned ({attempt})")
        ents = view.entities()
        assert ents.count(("MP", "/r1/odom", _dds(ODOM))) == 1
        assert ents.count(("MP", "/tf", _dds(TF))) == 1
        for _kind, topic, _dds_type in R9:
            assert len([e for e in ents if e[1] == topic]) == 1, (topic, ents)
        _check_r9_works(rig, robot, 0.5 + attempt)
        robot.delete()
        _check_r9_gone(rig)
    del r1_odom


def _late_static_tree(ros: zenoh.Session, expected: set[str]) -> set[str]:
    """The frames a late TRANSIENT_LOCAL subscriber to `/tf_static` gets (tf2's static listener, RViz
    started now): what the publisher's cache holds, queried as rmw_zenoh's advanced subscriber does; asked
    again until it is `expected` (the cache is refreshed as the bridge hears of a change)."""
    deadline = time.monotonic() + WAIT_S
    frames: set[str] = set()
    while time.monotonic() < deadline:
        got = Inbox()
        sub = zenoh.ext.declare_advanced_subscriber(
            ros,
            ros2.topic_key(DOMAIN, "/tf_static", TF),
            got,
            history=zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=1),
        )
        try:
            assert got.wait_until(bool, WAIT_S), "nothing from the /tf_static cache"
            frames = _children(got.got[-1][0])
        finally:
            sub.undeclare()
        if frames == expected:
            break
    return frames


@pytest.mark.timeout(120)
def test_tf_stays_while_any_spawned_robot_feeds_it(rig: Rig) -> None:
    """`/tf` and `/tf_static` are one publisher each for every robot (and the plan's r1 on `/tf`): they
    stay while one is left; a deleted robot's frames leave the static tree a late subscriber gets."""
    view, ros = rig.view, rig.ros
    r8, r9 = Robot(rig.world, "r8"), Robot(rig.world, "r9")
    both = {("MP", f"/{ns}/{n}", _dds(TF)) for ns in ("r8", "r9") for n in ("tf", "tf_static")}
    view.wait(lambda ents: set(ents) >= both, "spawned")
    static = Inbox()
    sub = ros.declare_subscriber(ros2.topic_key(DOMAIN, "/tf_static", TF), static)
    for robot, frame in ((r8, "r8/base_link"), (r9, "r9/base_link")):
        _keep_sending(
            lambda robot=robot, frame=frame: robot.tf_static(_tf(frame), pack_attachment(0, 0)),
            static,
            lambda got, frame=frame: any(frame in _children(p) for p, _a in got),
            f"{frame} on /tf_static",
        )
    sub.undeclare()
    assert _late_static_tree(ros, {"r8/base_link", "r9/base_link"}) == {"r8/base_link", "r9/base_link"}
    r9.delete()
    view.wait(lambda ents: not any(t and t.startswith("/r9/") for _k, t, _d in ents), "r9 withdrawn")
    assert {("MP", "/tf", _dds(TF)), ("MP", "/tf_static", _dds(TF))} <= set(view.entities())
    assert _late_static_tree(ros, {"r8/base_link"}) == {"r8/base_link"}
    tf = Inbox()
    sub = ros.declare_subscriber(ros2.topic_key(DOMAIN, "/tf", TF), tf)
    _keep_sending(
        lambda: r8.tf(_tf("r8/base_link"), pack_attachment(0, 0)),
        tf,
        lambda got: any("r8/base_link" in _children(p) for p, _a in got),
        "r8 on /tf",
    )
    sub.undeclare()
    r8.delete()
    view.wait(lambda ents: not any(t and t.startswith("/r8/") for _k, t, _d in ents), "r8 withdrawn")
    assert ("MP", "/tf", _dds(TF)) in view.entities()  # the plan's r1 still feeds it
    assert ("MP", "/tf_static", _dds(TF)) not in view.entities()  # nothing does


@pytest.mark.timeout(120)
@pytest.mark.parametrize(("process", "role"), [("reporter", "node"), ("world-renderer", "renderer")])
def test_a_node_or_renderer_that_stops_takes_its_ros2_side_with_it(rig: Rig, process: str, role: str) -> None:
    """A node's topics and services (mirrored as the node starts), or a renderer's (a spawned robot's
    camera images), go when it withdraws them or ends."""
    view = rig.view
    session = rig.world.session
    node = ZenohBus(session, GraphTokens(session, RUN, process, role))
    node.publisher(f"{RUN}/r9/camera/image_raw", "sensor_msgs/msg/Image")
    node.queryable(f"{RUN}/r9/ping", lambda _p, _a, respond: respond(b"", None), "std_srvs/srv/Empty")
    mine = {
        ("MP", "/r9/camera/image_raw", _dds("sensor_msgs/msg/Image")),
        ("SS", "/r9/ping", _dds("std_srvs/srv/Empty")),
    }
    view.wait(lambda ents: set(ents) >= mine, f"the {role}'s endpoints")
    node.undeclare_all()
    view.wait(lambda ents: not (mine & set(ents)), f"the {role} stopped")
    assert ("MP", "/r1/odom", _dds(ODOM)) in view.entities()  # the plan's mappings stay


SPAWNABLE = """
name: same
duration: 5
worlds:
  - name: a
  - name: b
robots:
  - name: r1
    world: a
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins: [{type: diff_drive}, {type: lidar, params: {link: lidar_link, samples: 8, rate: 10}}]
  - name: arm
    world: b
    description: ARM
    controllers: [CONTROLLERS]
ros2: {domain: 4}
"""


def test_what_appears_mid_run_is_mirrored_as_the_plan_mirrors_it_from_the_start(write_scenario) -> None:
    """Each world endpoint, had it appeared mid-run, maps to what `mirror_all` and `mirror_services` make of
    it at compile time: the same ROS 2 names and directions, a robot's `tf` on `/tf` too, an action's hidden
    parts, services named under their own world (two worlds here)."""
    robot = SCENARIOS / "robots" / "bench_arm"
    text = SPAWNABLE.replace("ARM", str(robot / "urdf" / "bench_arm.urdf"))
    plan = plan_of(write_scenario(text.replace("CONTROLLERS", str(robot / "config" / "controllers.yaml"))))
    assert plan.ros2 is not None
    parts = [part.name for part in plan.parts()]
    planned = set()
    for b in plan.bridges:
        for d in ("SIM_TO_ZENOH", "ZENOH_TO_SIM"):
            if b.direction in (d, "BIDIRECTIONAL"):
                planned.add((b.sim_key, b.ros_topic, d))
    followed = set()
    for part in plan.parts():
        # what the world publishes: its plugins' topics, its actions', and the scene's for viewers
        scene = [TopicPlan(key=f"{part.name}/{n}", type=TF) for n in ("tf", "tf_static")]
        scene += [
            TopicPlan(key=topic_key(part.name, r.namespace, "robot_description"), type="std_msgs/msg/String")
            for r in part.robots
            if r.urdf
        ]
        assert part.foxglove.scene
        for t in [*part.topics(), *action_topics(part.services()), *scene]:
            e = Endpoint("a" if part.name.endswith("/a") else "b", t.direction, t.key, t.type)
            followed |= {
                (b.sim_key, b.ros_topic, b.direction) for b in topic_plans(e, "world", plan.name, plan.ros2)
            }
    assert followed == planned
    assert ("same/a/r1/tf", "/tf", "SIM_TO_ZENOH") in followed
    services = {(s.sim_key, s.type, s.ros_name) for s in plan.service_bridges}
    assert any("/_action/send_goal" in name for _k, _t, name in services)
    offered = set()
    for key, type_name, _name in services:
        sp = service_plan(Endpoint("b", "srv", key, type_name), "world", plan.name, parts, plan.ros2)
        assert sp is not None, key
        offered.add((sp.sim_key, sp.type, sp.ros_name))
    assert offered == services
