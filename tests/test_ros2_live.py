"""`ros2:`: a run seen the way a ROS 2 system on rmw_zenoh sees it. No ROS here: a plain Zenoh session does
what rmw_zenoh does (a liveliness query on `@ros2_lv/<domain>/**`, subscribers and publishers on the topic
keys, with rmw_zenoh's attachments), and checks every byte against `runner.wire.ros2`, whose format is pinned
by the golden tests of test_ros2_format.py."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest
import zenoh

from runner.wire import msgs, ros2
from tests.conftest import read_mcap
from tests.test_bridges import Listener, start_run

SCENE = """
name: rosrun
duration: 30
rate: realtime
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive, params: {odometry_source: world}}
      - {type: lidar, params: {link: lidar_link, samples: 16, rate: 10}}
ros2: {domain: 7}
"""


@pytest.mark.timeout(90)
def test_a_ros2_system_discovers_reads_and_drives_the_run(write_scenario, tmp_path: Path) -> None:
    path = write_scenario(SCENE)
    listener = Listener([])
    session = listener.session
    mcap = tmp_path / "ros.mcap"
    run = start_run(path, "--record", str(mcap), "--connect", listener.endpoint)
    try:
        # discovery, as rmw_zenoh's graph cache does it
        tokens: list[str] = []
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            tokens = [str(r.ok.key_expr) for r in session.liveliness().get("@ros2_lv/7/**") if r.ok]
            if any("%r1%scan" in t for t in tokens):
                break
            time.sleep(0.1)
        infos = [ros2.parse_token(t) for t in tokens]
        assert all(infos), tokens
        nodes = [i for i in infos if i and i.kind == "NN"]
        assert [(n.namespace, n.node) for n in nodes] == [("/", "rosrun")]
        entities = {(i.kind, i.topic, i.dds_type) for i in infos if i and i.kind != "NN"}
        assert ("MP", "/r1/scan", "sensor_msgs::msg::dds_::LaserScan_") in entities
        assert ("MP", "/clock", "rosgraph_msgs::msg::dds_::Clock_") in entities
        assert ("MP", "/r1/odom", "nav_msgs::msg::dds_::Odometry_") in entities
        assert ("MS", "/r1/cmd_vel", "geometry_msgs::msg::dds_::Twist_") in entities
        assert not any("_truth" in (t or "") for _k, t, _d in entities)  # the run's helpers stay hidden
        for i in infos:
            assert i is not None and i.zid == nodes[0].zid and i.node_id == nodes[0].node_id
            if i.kind != "NN":
                assert i.type_hash == ros2.type_hash(ros2.ros_type_from_dds(i.dds_type or "") or "")
        scan_token = next(t for t, i in zip(tokens, infos, strict=True) if i and i.topic == "/r1/scan")

        # ros2 topic echo /r1/scan
        got: list[tuple[bytes, bytes | None]] = []
        lock = threading.Lock()

        def on_scan(sample: zenoh.Sample) -> None:
            att = sample.attachment.to_bytes() if sample.attachment is not None else None
            with lock:
                got.append((sample.payload.to_bytes(), att))

        scan_key = ros2.topic_key(7, "/r1/scan", "sensor_msgs/msg/LaserScan")
        assert scan_key == "7/r1/scan/sensor_msgs::msg::dds_::LaserScan_/" + ros2.type_hash(
            "sensor_msgs/msg/LaserScan"
        )
        sub = session.declare_subscriber(scan_key, on_scan)
        deadline = time.monotonic() + 10
        while len(got) < 5 and time.monotonic() < deadline:
            time.sleep(0.05)
        sub.undeclare()
        assert len(got) >= 5
        seqs = []
        for payload, att in got:
            assert len(msgs.decode(payload, "sensor_msgs/msg/LaserScan").ranges) == 16
            parsed = ros2.unpack_attachment(att)
            assert parsed is not None, att
            seq, stamp, gid = parsed
            assert gid == ros2.gid(scan_token)
            assert abs(stamp - time.time_ns()) < 30e9  # wall clock, ns since the epoch
            seqs.append(seq)
        assert seqs == list(range(seqs[0], seqs[0] + len(seqs)))  # per publisher, one by one

        # ros2 topic pub /r1/cmd_vel geometry_msgs/msg/Twist "{linear: {x: 0.5}}"
        cmd_key = ros2.topic_key(7, "/r1/cmd_vel", "geometry_msgs/msg/Twist")
        pub_token = ros2.entity_token(
            7, str(session.zid()), 0, 1, "MP", "/", "teleop", "/r1/cmd_vel", "geometry_msgs/msg/Twist"
        )
        token = session.liveliness().declare_token(pub_token)
        pub = session.declare_publisher(cmd_key)
        twist = msgs.encode(
            msgs.from_data("geometry_msgs/msg/Twist", {"linear": {"x": 0.5}}), "geometry_msgs/msg/Twist"
        )
        for seq in range(1, 21):
            pub.put(twist, attachment=ros2.pack_attachment(seq, time.time_ns(), ros2.gid(pub_token)))
            time.sleep(0.05)
        time.sleep(1.5)
        pub.undeclare()
        token.undeclare()
    finally:
        run.send_signal(2)
        run.communicate(timeout=30)
        listener.close()
    records = read_mcap(mcap)
    commands = [m for topic, _t, _s, m in records if topic == "rosrun/r1/cmd_vel"]
    assert len(commands) == 20 and commands[0].linear.x == pytest.approx(0.5)
    xs = [m.pose.pose.position.x for topic, _t, _s, m in records if topic == "rosrun/r1/odom"]
    assert xs[-1] - xs[0] > 0.3, "the robot did not move"


@pytest.mark.timeout(90)
def test_the_run_joins_a_ros2_router_of_its_own(write_scenario, tmp_path: Path) -> None:
    """`ros2: {router: ...}`: the bridge also joins the ROS 2 side's Zenoh router (rmw_zenohd's role here is
    played by a plain Zenoh router), and a ROS 2 session that knows only that router sees the run."""
    from runner.wire.transport import free_port, make_config

    ros_router = f"tcp/127.0.0.1:{free_port()}"
    path = write_scenario(SCENE.replace("ros2: {domain: 7}", f'ros2: {{domain: 3, router: "{ros_router}"}}'))
    with (
        zenoh.open(make_config("router", listen=[ros_router])),
        zenoh.open(make_config("client", connect=[ros_router])) as ros_side,
    ):
        got: list[bytes] = []
        key = ros2.topic_key(3, "/r1/scan", "sensor_msgs/msg/LaserScan")
        sub = ros_side.declare_subscriber(key, lambda s: got.append(s.payload.to_bytes()))
        run = start_run(path, "--no-record")
        try:
            deadline = time.monotonic() + 30
            while len(got) < 3 and time.monotonic() < deadline:
                time.sleep(0.05)
            tokens = [str(r.ok.key_expr) for r in ros_side.liveliness().get("@ros2_lv/3/**") if r.ok]
        finally:
            run.send_signal(2)
            run.communicate(timeout=30)
            sub.undeclare()
    assert len(got) >= 3
    assert len(msgs.decode(got[0], "sensor_msgs/msg/LaserScan").ranges) == 16
    assert any(t.endswith("/NN/%/%/rosrun") for t in tokens), tokens


NODE_SCRIPT = """
from runner.node import Node

with Node() as node:
    status = node.publisher("status", "std_msgs/msg/String")
    while node.sleep(0.1):
        status.publish({"data": f"at {node.now:.1f}"})
"""


@pytest.mark.timeout(90)
def test_a_nodes_topics_appear_to_ros2_as_the_node_starts(write_scenario, tmp_path: Path) -> None:
    (tmp_path / "status_node.py").write_text(NODE_SCRIPT)
    path = write_scenario(SCENE + "nodes:\n  - {name: reporter, cmd: python status_node.py, namespace: r1}\n")
    listener = Listener([])
    got: list[tuple[bytes, bytes | None]] = []
    key = ros2.topic_key(7, "/r1/status", "std_msgs/msg/String")
    sub = listener.session.declare_subscriber(
        key,
        lambda s: got.append(
            (s.payload.to_bytes(), s.attachment.to_bytes() if s.attachment is not None else None)
        ),
    )
    run = start_run(path, "--no-record", "--connect", listener.endpoint)
    try:
        deadline = time.monotonic() + 30
        while len(got) < 3 and time.monotonic() < deadline:
            time.sleep(0.05)
        tokens = [str(r.ok.key_expr) for r in listener.session.liveliness().get("@ros2_lv/7/**") if r.ok]
    finally:
        run.send_signal(2)
        run.communicate(timeout=30)
        sub.undeclare()
        listener.close()
    assert len(got) >= 3
    assert msgs.decode(got[-1][0], "std_msgs/msg/String").data.startswith("at ")
    mp = next(t for t in tokens if "/MP/" in t and "%r1%status" in t)
    assert ros2.unpack_attachment(got[0][1])[2] == ros2.gid(mp)  # type: ignore[index]
