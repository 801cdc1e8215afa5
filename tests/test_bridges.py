"""`bridges:`: sim topics re-exposed under other keys, encodings and directions, run by the bridge process;
ros_gz_bridge files taken as they are. Real runs, real Zenoh sessions, recordings read back."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import pytest
import zenoh

from runner.wire import msgs
from runner.wire.graph import query_graph
from runner.wire.transport import free_port, make_config, type_from_encoding
from tests.conftest import SCENARIOS, read_mcap, run_cli, scenario_cmd


class Listener:
    """A peer session listening on its own port, subscribed before the run joins it (`--connect`), so
    that nothing the run sends is missed."""

    def __init__(self, keys: list[str]):
        self.port = free_port()
        self.endpoint = f"tcp/127.0.0.1:{self.port}"
        self.session = zenoh.open(make_config("peer", listen=[self.endpoint]))
        self.got: dict[str, list[tuple[str | None, bytes, bytes | None]]] = defaultdict(list)
        self.lock = threading.Lock()
        self.subs = [self.session.declare_subscriber(k, self._on) for k in keys]

    def _on(self, sample: zenoh.Sample) -> None:
        att = sample.attachment.to_bytes() if sample.attachment is not None else None
        with self.lock:
            self.got[str(sample.key_expr)].append((str(sample.encoding), sample.payload.to_bytes(), att))

    def close(self) -> None:
        for s in self.subs:
            s.undeclare()
        self.session.close()


def start_run(path: Path, *args: str) -> subprocess.Popen[str]:
    """`scenario run PATH ARGS` in the background (stop it with SIGINT, then `communicate()`)."""
    return subprocess.Popen(
        scenario_cmd("run", str(path), "-q", *args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def _run(*args: str, timeout: float = 90) -> subprocess.CompletedProcess[str]:
    return subprocess.run(scenario_cmd(*args), capture_output=True, text=True, timeout=timeout)


@pytest.mark.timeout(150)
def test_the_seeds_ros_gz_bridge_file_as_is(tmp_path: Path) -> None:
    """harmonic_nav.yaml takes the seed's bridge file unmodified: each GZ_TO_ROS entry's ROS name is a key
    carrying every message of its sim topic, with its type."""
    bridge = SCENARIOS / "bridge" / "harmonic_bridge.yaml"
    expected = {  # ROS name (a key) -> the sim topic it carries
        "clock": "harmonic_nav/clock",
        "joint_states": "harmonic_nav/my_robot/joint_states",
        "odom": "harmonic_nav/my_robot/odom",
        "tf": "harmonic_nav/my_robot/tf",
        "imu": "harmonic_nav/my_robot/imu",
        "scan": "harmonic_nav/my_robot/scan",
        "camera/camera_info": "harmonic_nav/my_robot/camera/camera_info",
    }
    listener = Listener([*expected, "camera/image", "camera/depth_image"])
    mcap = tmp_path / "nav.mcap"
    try:
        r = _run(
            "run", str(SCENARIOS / "harmonic_nav.yaml"), "--duration", "0.5", "--no-judge", "-q",
            "--record", str(mcap), "--connect", listener.endpoint,
        )  # fmt: skip
        assert r.returncode == 0, r.stderr
        time.sleep(0.3)
    finally:
        listener.close()
    assert "cmd_vel" in bridge.read_text()  # the file is the seed's, with its ROS_TO_GZ entry
    recorded: dict[str, list[bytes]] = defaultdict(list)
    for topic, _type, _t, msg in read_mcap(mcap):
        recorded[topic].append(msg)
    for ros_key, sim_key in expected.items():
        got = listener.got.get(ros_key, [])
        assert got, f"nothing on {ros_key}"
        type_name = type_from_encoding(got[0][0])
        assert type_name is not None
        assert msgs.decode(got[0][1], type_name) is not None
        assert len(got) == len(recorded[sim_key]), (ros_key, len(got), len(recorded[sim_key]))
    # the images are not recorded (record.exclude) but bridged all the same: 100 Hz for 0.5 s
    assert len(listener.got["camera/image"]) >= 45
    assert type_from_encoding(listener.got["camera/image"][0][0]) == "sensor_msgs/msg/Image"


JSON_SCENE = """
name: jsonbridge
duration: 3.0
rate: realtime
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive, params: {odometry_source: world}}
bridges:
  - {topic: r1/cmd_vel, key: outside/r1/cmd_vel, direction: ZENOH_TO_SIM, encoding: json}
  - {topic: r1/odom, key: outside/r1/odom, encoding: json, rate: 5}
"""

PLAIN_PROGRAM = """
import json, sys, time
import zenoh

conf = zenoh.Config()
conf.insert_json5("mode", '"client"')
conf.insert_json5("connect/endpoints", json.dumps([sys.argv[1]]))
conf.insert_json5("scouting/multicast/enabled", "false")
with zenoh.open(conf) as session:
    pub = session.declare_publisher("outside/r1/cmd_vel")
    heard = []
    sub = session.declare_subscriber("outside/r1/odom", heard.append)
    deadline = time.monotonic() + 30
    while not heard and time.monotonic() < deadline:  # until the robot is heard: the run is under way
        time.sleep(0.02)
    for _ in range(int(float(sys.argv[2]) / 0.05)):
        pub.put(json.dumps({"linear": {"x": 0.4}, "angular": {"z": 0.0}}))
        time.sleep(0.05)
"""


@pytest.mark.timeout(90)
def test_json_twist_from_a_plain_zenoh_program_moves_the_robot(write_scenario, tmp_path: Path) -> None:
    path = write_scenario(JSON_SCENE)
    program = tmp_path / "plain.py"
    program.write_text(PLAIN_PROGRAM)
    listener = Listener(["outside/**"])
    mcap = tmp_path / "run.mcap"
    run = start_run(path, "--record", str(mcap), "--connect", listener.endpoint)
    try:
        # the program knows nothing of the run but the endpoint and the key
        subprocess.run([sys.executable, str(program), listener.endpoint, "2.5"], check=True, timeout=30)
        _out, err = run.communicate(timeout=60)
        assert run.returncode == 0, err
    finally:
        if run.poll() is None:
            run.kill()
        listener.close()
    records = read_mcap(mcap)
    commands = [m for topic, _type, _t, m in records if topic == "jsonbridge/r1/cmd_vel"]
    assert len(commands) >= 20 and commands[0].linear.x == pytest.approx(0.4)
    xs = [m.pose.pose.position.x for topic, _type, _t, m in records if topic == "jsonbridge/r1/odom"]
    assert xs[-1] - xs[0] > 0.3, "the robot did not move"
    # odom goes out as JSON, throttled to 5 per sim second (it is published at 50)
    odom = listener.got["outside/r1/odom"]
    assert odom and odom[0][0] == "application/json;nav_msgs/msg/Odometry"
    first = json.loads(odom[0][1])
    assert set(first) == {"header", "child_frame_id", "pose", "twist"}
    sim_s = 3.0
    assert 5 * sim_s - 2 <= len(odom) <= 5 * sim_s + 1, len(odom)


BIDI_SCENE = """
name: bidi
duration: 30.0
rate: realtime
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive, params: {odometry_source: world}}
      - {type: lidar, params: {link: lidar_link, samples: 8, rate: 10}}
timeline:
  - {t: 0.2, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.1}}}
bridges:
  - {topic: r1/cmd_vel, key: ext/cmd_vel, direction: BIDIRECTIONAL}
  - {topic: r1/scan, key: ext/scan, lazy: true}
"""


@pytest.mark.timeout(90)
def test_bidirectional_does_not_echo_and_lazy_subscribes_only_when_needed(write_scenario, tmp_path) -> None:
    path = write_scenario(BIDI_SCENE)
    listener = Listener(["ext/cmd_vel"])
    mcap = tmp_path / "bidi.mcap"
    run = start_run(path, "--record", str(mcap), "--connect", listener.endpoint)
    session = listener.session
    try:
        deadline = time.monotonic() + 30
        while not listener.got["ext/cmd_vel"] and time.monotonic() < deadline:
            time.sleep(0.05)
        # the timeline's command came out once (sim -> outside)
        assert len(listener.got["ext/cmd_vel"]) == 1

        def bridge_subs(graph: Any) -> set[str]:
            return {e.key for e in graph.endpoints if e.process == "bridge" and e.kind == "sub"}

        # lazy: nobody outside wants ext/scan, so the bridge does not even subscribe to the sim's scan
        assert "bidi/r1/scan" not in bridge_subs(query_graph(session, "bidi"))
        scans: list[bytes] = []
        sub = session.declare_subscriber("ext/scan", lambda s: scans.append(s.payload.to_bytes()))
        deadline = time.monotonic() + 10
        while len(scans) < 3 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert len(scans) >= 3
        assert "bidi/r1/scan" in bridge_subs(query_graph(session, "bidi"))
        sub.undeclare()
        deadline = time.monotonic() + 5
        while "bidi/r1/scan" in bridge_subs(query_graph(session, "bidi")) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert "bidi/r1/scan" not in bridge_subs(query_graph(session, "bidi"))
        # outside -> sim: one command in, and it does not come back out
        twist = msgs.encode(
            msgs.from_data("geometry_msgs/msg/Twist", {"angular": {"z": 0.7}}), "geometry_msgs/msg/Twist"
        )
        session.put("ext/cmd_vel", twist)
        time.sleep(1.0)
        # (this session hears its own put, without an attachment; the bridge's always have one)
        assert [a is not None for _e, _p, a in listener.got["ext/cmd_vel"]] == [True, False]
    finally:
        run.send_signal(2)
        run.communicate(timeout=30)
        listener.close()
    commands = [m for topic, _t, _s, m in read_mcap(mcap) if topic == "bidi/r1/cmd_vel"]
    assert [c.angular.z for c in commands] == [0.0, pytest.approx(0.7)]


TWO = """
name: two
duration: 1.0
robots:
  - {{name: r1, description: "{diffbot}", pose: {{xyz: [0, 0, 0.06]}}, plugins: [{{type: lidar, params: {{link: lidar_link}}}}]}}
  - {{name: r2, description: "{diffbot}", pose: {{xyz: [1, 0, 0.06]}}, plugins: [{{type: lidar, params: {{link: lidar_link}}}}]}}
bridges: {bridges}
"""


def _validate(write_scenario, bridges: str, extra: dict[str, str] | None = None) -> str:
    for name, text in (extra or {}).items():
        write_scenario(text, name)
    path = write_scenario(TWO.replace("{bridges}", bridges).replace("{{", "{").replace("}}", "}"))
    r = run_cli("validate", str(path))
    assert r.returncode == 1, r.stdout
    assert "Traceback" not in r.stderr
    return r.stderr


def test_bridge_errors_point_at_their_line(write_scenario) -> None:
    err = _validate(write_scenario, "[{topic: scan}]")
    assert "scenario.yaml:6" in err and "bridges[0].topic" in err
    assert "several robots: r1/scan, r2/scan" in err and "r1/scan" in err
    err = _validate(write_scenario, "[{topic: r1/nothing}]")
    assert "no sim topic named 'r1/nothing'" in err and "r1/scan" in err
    err = _validate(write_scenario, "[{topic: r1/scan, type: geometry_msgs/msg/Twist}]")
    assert "the sim topic is sensor_msgs/msg/LaserScan" in err
    err = _validate(write_scenario, "[{topic: r1/scan, key: two/r1/scan2}]")
    assert "inside the run's own key space" in err
    bad_file = (
        "- ros_topic_name: scan\n"
        "  gz_topic_name: scan\n"
        "  ros_type_name: sensor_msgs/msg/LaserScan\n"
        "  gz_type_name: gz.msgs.Twist\n"
        "  direction: GZ_TO_ROS\n"
        "- topic_name: cmd_vel\n"
        "  ros_type_name: geometry_msgs/msg/Twist\n"
        "  gz_type_name: gz.msgs.Twist\n"
        "  direction: SIDEWAYS\n"
    )
    err = _validate(write_scenario, "{file: bridge.yaml, robot: r1}", {"bridge.yaml": bad_file})
    assert (
        "bridge.yaml:4" in err and "no conversion between sensor_msgs/msg/LaserScan and gz.msgs.Twist" in err
    )
    assert "bridge.yaml:9" in err and "unknown direction 'SIDEWAYS'" in err
    err = _validate(write_scenario, "{file: missing.yaml}")
    assert "file not found: missing.yaml" in err


def test_a_bridge_file_resolves_under_its_robot(write_scenario) -> None:
    write_scenario(
        "- {topic_name: scan, ros_type_name: sensor_msgs/msg/LaserScan, gz_type_name: gz.msgs.LaserScan,"
        " direction: GZ_TO_ROS, lazy: true}\n",
        "bridge.yaml",
    )
    path = write_scenario(
        TWO.replace("{bridges}", "{file: bridge.yaml, robot: r2}").replace("{{", "{").replace("}}", "}")
    )
    from runner.compile import compile_plan
    from runner.scenario.loader import load_file
    from runner.scenario.validate import validate_scenario

    doc = load_file(path)
    plan = compile_plan(validate_scenario(doc), doc)
    (b,) = plan.bridges
    assert (b.sim_key, b.key, b.direction, b.lazy) == ("two/r2/scan", "r2/scan", "SIM_TO_ZENOH", True)
    assert any(n.argv[-2:] == ["-m", "runner.launch.bridge"] and n.required for n in plan.nodes)


def test_a_bridge_copy_keeps_its_topics_qos(write_scenario) -> None:
    """A bridged copy is reliable like its sim topic, and best effort only where `qos:` made the topic so."""
    path = write_scenario(
        TWO.replace(
            "{bridges}",
            "[{{topic: r1/scan}}, {{topic: r2/scan}}]\nqos: [{{topics: r1/scan, reliability: best_effort}}]",
        )
        .replace("{{", "{")
        .replace("}}", "}")
    )
    from runner.compile import compile_plan
    from runner.scenario.loader import load_file
    from runner.scenario.validate import validate_scenario

    doc = load_file(path)
    plan = compile_plan(validate_scenario(doc), doc)
    assert {b.sim_key: b.best_effort for b in plan.bridges} == {"two/r1/scan": True, "two/r2/scan": False}
