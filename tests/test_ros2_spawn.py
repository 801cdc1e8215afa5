"""Issue 37's spawn acceptance: a ROS 2 client that is not ours (zenoh-ros2-sdk, an independent rmw_zenoh
implementation, tests/clients/ros2_sdk_services.py in a process of its own) spawns a robot into a running
world through gazebo_ros's `/spawn_entity`, sees its topics appear in `ros2 topic list`, drives it with
`/r9/cmd_vel` and reads `/r9/odom`, deletes it (its topics go), and spawns one again through ros_gz's
`/world/<w>/create`. The recording has every request (who asked, what, when) and the robot's messages."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from runner.wire.transport import free_port
from tests.conftest import read_mcap
from tests.test_bridges import start_run
from tests.test_gazebo_parity import diffbot
from tests.test_ros2_services import run_client
from tests.test_sim_control import BOX

CLIENT = Path(__file__).parent / "clients" / "ros2_sdk_services.py"
DOMAIN = 13
TWIST = "geometry_msgs/msg/Twist"
ODOM = "nav_msgs/msg/Odometry"
STATE = "gazebo_msgs/srv/GetEntityState"


def _scenario(tmp_path: Path) -> Path:
    (tmp_path / "box.urdf").write_text(BOX)
    path = tmp_path / "sp.yaml"
    path.write_text(
        f"""
name: sp
duration: 300
rate: realtime
seed: 1
robots:
  - name: bot
    description: box.urdf
    pose: {{xyz: [0, 0, 0.05]}}
ros2: {{domain: {DOMAIN}}}
"""
    )
    return path


def _script() -> list[dict[str, Any]]:
    spawn = {
        "name": "r9",
        "xml": diffbot(),
        "initial_pose": {"position": {"x": 2.0, "y": 1.0, "z": 0.11}, "orientation": {"w": 1.0}},
    }
    return [
        # as `ros2 service call` waits for its service: the bridge offers one once the world answers it, and
        # the plan's topics (`/bot/tf`) are there before that; the SDK's client does not wait by itself
        {
            "list": True,
            "wait_for": ["/spawn_entity", "/delete_entity", "/get_entity_state", "/world/sp/create"],
        },
        {"call": "/spawn_entity", "type": "gazebo_msgs/srv/SpawnEntity", "request": spawn},
        {"topics": True, "wait_for": ["/r9/odom", "/r9/cmd_vel", "/r9/joint_states"]},
        {"echo": "/r9/odom", "type": ODOM},
        {"publish": "/r9/cmd_vel", "type": TWIST, "data": {"linear": {"x": 0.3}}, "count": 25, "period": 0.1},
        {"echo": "/r9/odom", "type": ODOM},
        {"call": "/get_entity_state", "type": STATE, "request": {"name": "r9"}},
        {"call": "/spawn_entity", "type": "gazebo_msgs/srv/SpawnEntity", "request": spawn},  # taken
        {"call": "/delete_entity", "type": "gazebo_msgs/srv/DeleteEntity", "request": {"name": "r9"}},
        {"topics": True, "absent": ["/r9/odom", "/r9/cmd_vel"]},
        {"call": "/get_entity_state", "type": STATE, "request": {"name": "r9"}},
        {
            "call": "/world/sp/create",
            "type": "ros_gz_interfaces/srv/SpawnEntity",
            "request": {
                "entity_factory": {"name": "r9", "sdf": diffbot(), "pose": {"position": {"x": -1.0}}}
            },
        },
        {"topics": True, "wait_for": ["/r9/odom"]},
        {"echo": "/r9/odom", "type": ODOM},
        {
            "call": "/world/sp/remove",
            "type": "ros_gz_interfaces/srv/DeleteEntity",
            "request": {"entity": {"name": "r9", "type": 2}},
        },
        {"call": "/delete_entity", "type": "gazebo_msgs/srv/DeleteEntity", "request": {"name": "r9"}},
    ]


@pytest.mark.timeout(300)
def test_a_ros2_client_spawns_drives_and_deletes_a_robot(tmp_path: Path) -> None:
    port = free_port()
    mcap = tmp_path / "sp.mcap"
    run = start_run(_scenario(tmp_path), "--listen", f"tcp/127.0.0.1:{port}", "--record", str(mcap))
    try:
        out = run_client(port, DOMAIN, _script(), tmp_path, timeout=240)
    finally:
        run.send_signal(2)
        _o, err = run.communicate(timeout=60)
    steps = dict(enumerate(json.loads(out.read_text())))
    assert steps[1]["response"]["success"], steps[1]
    topics = dict(steps[2]["topics"])
    assert topics["/r9/odom"] == [ODOM] and topics["/r9/cmd_vel"] == [TWIST], topics
    first, driven = steps[3]["message"], steps[5]["message"]
    assert first is not None and driven is not None, (steps[3], steps[5])
    x0 = first["pose"]["pose"]["position"]["x"]
    assert x0 == pytest.approx(2.0, abs=0.05)  # where it was spawned (gazebo_ros's odometry: world)
    # ~2.5 s of 0.3 m/s from ROS 2: it drove forward
    assert driven["pose"]["pose"]["position"]["x"] - x0 > 0.3, (first, driven)
    state = steps[6]["response"]
    assert state["success"] and state["state"]["pose"]["position"]["x"] > 2.3
    taken = steps[7]["response"]
    assert not taken["success"] and "already exists" in taken["status_message"]
    assert steps[8]["response"]["success"], steps[8]
    names = {n for n, _t in steps[9]["topics"]}
    assert "/r9/odom" not in names and "/r9/cmd_vel" not in names and "/bot/tf" in names
    assert steps[10]["response"]["success"] is False  # gone
    assert steps[11]["response"]["success"]  # ros_gz create, the name free again
    again = steps[13]["message"]
    assert again is not None and again["pose"]["pose"]["position"]["x"] == pytest.approx(-1.0, abs=0.05)
    assert steps[14]["response"]["success"]
    assert steps[15]["response"]["success"] is False
    assert "Traceback" not in err

    # the recording: who asked to spawn, and the robot's odometry from then on
    records = read_mcap(mcap)
    events = [m for topic, _t, _l, m in records if topic == "sp/spawn_entity/_service_event"]
    assert [e.info.event_type for e in events[:2]] == [1, 2]
    assert events[0].request[0].name == "r9" and bytes(events[0].info.client_gid) != bytes(16)
    assert sum(1 for topic, *_ in records if topic == "sp/r9/odom") > 20
