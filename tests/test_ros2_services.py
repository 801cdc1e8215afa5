"""Issue 37's acceptance: a run's services and actions used by ROS 2 clients that are not ours.

One run of the example bench arm with `ros2:` (realtime), a free box on the floor, and two clients:
- zenoh-ros2-sdk (an independent rmw_zenoh implementation, tests/clients/ros2_sdk_services.py, a process
  of its own) lists the services as `ros2 service list` does, calls the controller manager and the
  simulation's services (gazebo_ros's and ros_gz's names), and sends FollowJointTrajectory and
  GripperCommand goals as rclpy's ActionClient does (feedback, cancel, result, rejection);
- raw zenoh-python, following rmw_zenoh's design and sources (ros2/rmw_zenoh, rmw_zenoh_cpp/src/detail/:
  rmw_service_data.cpp at 028bbe30 and rmw_client_data.cpp at 03470ce8 (queryable `complete`, querier
  ALL_COMPLETE / consolidation NONE, reply attachment), liveliness_utils.cpp at 3411fdec (token layout),
  attachment_helpers.cpp (sequence number, source timestamp, GID)): the `SS` tokens field by field, a
  query with a hand-made attachment and the reply's attachment (the request's sequence number, a fresh
  source timestamp, the client's GID).
The recording holds every call as `<service>/_service_event` (who asked: the client's GID).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
import zenoh

from runner.wire import msgs, ros2
from runner.wire.transport import free_port, make_config
from tests.conftest import SCENARIOS, read_mcap
from tests.test_bridges import start_run

CLIENT = Path(__file__).parent / "clients" / "ros2_sdk_services.py"
DOMAIN = 12
ARM = ["pan", "shoulder", "elbow", "wrist"]
FJT = "control_msgs/action/FollowJointTrajectory"
GRIP = "control_msgs/action/GripperCommand"


def _scenario(tmp_path: Path) -> Path:
    robot = SCENARIOS / "robots" / "bench_arm"
    path = tmp_path / "svc.yaml"
    path.write_text(
        f"""
name: svc
duration: 300
rate: realtime
seed: 1
world:
  models:
    - {{name: crate, shape: box, size: [0.2, 0.2, 0.2], pose: {{xyz: [1.0, 0, 0.1]}}, static: false, mass: 1.0}}
robots:
  - name: arm
    description: {robot / "urdf" / "bench_arm.urdf"}
    controllers: [{robot / "config" / "controllers.yaml"}]
ros2: {{domain: {DOMAIN}}}
"""
    )
    return path


def _trajectory(positions: list[float], sec: int) -> dict[str, Any]:
    return {
        "trajectory": {
            "joint_names": ARM,
            "points": [{"positions": positions, "velocities": [0.0] * 4, "time_from_start": {"sec": sec}}],
        }
    }


SCRIPT: list[dict[str, Any]] = [
    {
        "list": True,
        "wait_for": [
            "/arm/arm_controller/follow_joint_trajectory/_action/send_goal",
            "/arm/gripper_controller/gripper_cmd/_action/send_goal",
            "/arm/controller_manager/list_controllers",
            "/reset_world",
            "/pause_physics",
        ],
    },
    {
        "call": "/arm/controller_manager/list_controllers",
        "type": "controller_manager_msgs/srv/ListControllers",
        "request": {},
    },
    {
        "action": "/arm/arm_controller/follow_joint_trajectory",
        "type": FJT,
        "goal": _trajectory([0.4, 0.3, 0.5, 0.3], 1),
    },
    {
        "action": "/arm/arm_controller/follow_joint_trajectory",
        "type": FJT,
        "goal": {"trajectory": {"joint_names": ["pan", "nope"], "points": [{"positions": [0.1, 0.1]}]}},
    },
    {
        "action": "/arm/arm_controller/follow_joint_trajectory",
        "type": FJT,
        "goal": _trajectory([1.2, 0.8, 1.0, -0.4], 6),
        "cancel_after_feedback": 3,
    },
    {
        "action": "/arm/gripper_controller/gripper_cmd",
        "type": GRIP,
        "goal": {"command": {"position": 0.03, "max_effort": 10.0}},
    },
    {
        "call": "/arm/controller_manager/switch_controller",
        "type": "controller_manager_msgs/srv/SwitchController",
        "request": {"deactivate_controllers": ["arm_controller"], "strictness": 2},
    },
    {
        "action": "/arm/arm_controller/follow_joint_trajectory",
        "type": FJT,
        "goal": _trajectory([0.0, 0.2, 0.4, 0.0], 1),
    },
    {
        "call": "/arm/controller_manager/switch_controller",
        "type": "controller_manager_msgs/srv/SwitchController",
        "request": {"activate_controllers": ["arm_controller"], "strictness": 2},
    },
    {"call": "/pause_physics", "type": "std_srvs/srv/Empty", "request": {}},
    {"call": "/get_entity_state", "type": "gazebo_msgs/srv/GetEntityState", "request": {"name": "crate"}},
    {"sleep": 0.5},
    {"call": "/get_entity_state", "type": "gazebo_msgs/srv/GetEntityState", "request": {"name": "crate"}},
    {
        "call": "/world/svc/control",
        "type": "ros_gz_interfaces/srv/ControlWorld",
        "request": {"world_control": {"pause": True, "multi_step": 25}},
    },
    {"call": "/get_entity_state", "type": "gazebo_msgs/srv/GetEntityState", "request": {"name": "crate"}},
    {
        "call": "/set_entity_state",
        "type": "gazebo_msgs/srv/SetEntityState",
        "request": {
            "state": {
                "name": "crate",
                "pose": {"position": {"x": 2.0, "y": 0.5, "z": 0.1}, "orientation": {"w": 1.0}},
            }
        },
    },
    {"call": "/get_entity_state", "type": "gazebo_msgs/srv/GetEntityState", "request": {"name": "crate"}},
    {
        "call": "/get_entity_state",
        "type": "gazebo_msgs/srv/GetEntityState",
        "request": {"name": "no_such_thing"},
    },
    {
        "call": "/set_entity_state",
        "type": "gazebo_msgs/srv/SetEntityState",
        "request": {"state": {"name": "crate", "pose": {"position": {"x": float("nan")}}}},
    },
    {"call": "/unpause_physics", "type": "std_srvs/srv/Empty", "request": {}},
    {"call": "/get_entity_state", "type": "gazebo_msgs/srv/GetEntityState", "request": {"name": "crate"}},
]


def run_client(port: int, domain: int, script: list[dict[str, Any]], tmp_path: Path, timeout: float) -> Path:
    """The zenoh-ros2-sdk client (its own process) run through `script`: the JSON file of its log."""
    path = tmp_path / "script.json"
    path.write_text(json.dumps(script))
    out = tmp_path / "out.json"
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[1])}
    client = subprocess.run(
        [sys.executable, str(CLIENT), str(port), str(domain), str(path), str(out)],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )
    assert client.returncode == 0, client.stderr[-3000:]
    return out


def _raw_checks(port: int) -> dict[str, Any]:
    """rmw_zenoh's service wire, by hand: the SS token, and a query's reply attachment."""
    session = zenoh.open(make_config("client", connect=[f"tcp/127.0.0.1:{port}"]))
    try:
        name, srv = "/arm/controller_manager/list_controllers", "controller_manager_msgs/srv/ListControllers"
        tokens = [str(r.ok.key_expr) for r in session.liveliness().get(f"@ros2_lv/{DOMAIN}/**") if r.ok]
        ss = [t for t in tokens if "/SS/" in t and "%list_controllers/" in t]
        key = ros2.topic_key(DOMAIN, name, srv)
        gid = bytes(range(100, 116))
        request = msgs.encode(msgs.T[f"{srv}_Request"](), f"{srv}_Request")
        before = time.time_ns()
        replies = list(
            session.get(
                key,
                payload=request,
                attachment=ros2.pack_attachment(42, before, gid),
                target=zenoh.QueryTarget.ALL_COMPLETE,
                consolidation=zenoh.ConsolidationMode.NONE,
                timeout=10.0,
            )
        )
        ok = [r.ok for r in replies if r.ok is not None]
        att = ros2.unpack_attachment(ok[0].attachment.to_bytes()) if ok and ok[0].attachment else None
        response = msgs.decode(ok[0].payload.to_bytes(), f"{srv}_Response") if ok else None
        return {
            "ss": ss,
            "key": key,
            "replies": len(ok),
            "attachment": [att[0], att[1] - before, att[2].hex()] if att else None,
            "gid": gid.hex(),
            "controllers": [c.name for c in response.controller] if response else None,
        }
    finally:
        session.close()


@pytest.mark.timeout(240)
def test_ros2_clients_call_services_and_send_goals(tmp_path: Path) -> None:
    port = free_port()
    mcap = tmp_path / "svc.mcap"
    run = start_run(_scenario(tmp_path), "--listen", f"tcp/127.0.0.1:{port}", "--record", str(mcap))
    try:
        out = run_client(port, DOMAIN, SCRIPT, tmp_path, timeout=180)
        raw = _raw_checks(port)
    finally:
        run.send_signal(2)
        _o, err = run.communicate(timeout=60)
    log = json.loads(out.read_text())
    steps = dict(enumerate(log))

    services = dict(steps[0]["services"])
    assert services["/arm/arm_controller/follow_joint_trajectory/_action/send_goal"] == [f"{FJT}_SendGoal"]
    assert services["/reset_simulation"] == ["std_srvs/srv/Empty"]
    controllers = {c["name"]: c for c in steps[1]["response"]["controller"]}
    assert controllers["arm_controller"]["state"] == "active"
    assert controllers["arm_controller"]["type"] == "joint_trajectory_controller/JointTrajectoryController"

    done = steps[2]  # a goal followed to its end, with feedback
    assert done["accepted"] and done["result"]["status"] == 4, done
    assert done["result"]["result"]["error_code"] == 0 and done["feedback_count"] > 10
    assert done["feedback"][-1]["joint_names"] == ARM
    assert {2, 4} <= set(done["statuses"])  # EXECUTING, SUCCEEDED on _action/status
    assert not steps[3]["accepted"]  # a joint the controller does not have
    canceled = steps[4]
    assert canceled["accepted"] and canceled["cancel"]["return_code"] == 0
    assert canceled["result"]["status"] == 5, canceled  # CANCELED
    grip = steps[5]
    assert grip["accepted"] and grip["result"]["status"] == 4 and grip["result"]["result"]["reached_goal"]
    assert steps[6]["response"]["ok"] and not steps[7]["accepted"]  # inactive: goals rejected
    assert steps[8]["response"]["ok"]

    # paused: sim time stands still; 25 steps of ros_gz's ControlWorld move it 25 steps (2 ms each)
    t = [s["response"]["header"]["stamp"] for s in (steps[10], steps[12], steps[14])]
    ns = [x["sec"] * 1_000_000_000 + x["nanosec"] for x in t]
    assert ns[0] == ns[1] and ns[2] - ns[1] == 25 * 2_000_000, ns
    assert steps[13]["response"]["success"]
    assert steps[15]["response"]["success"]
    moved = steps[16]["response"]["state"]["pose"]["position"]
    assert (moved["x"], moved["y"]) == pytest.approx((2.0, 0.5), abs=1e-6)
    assert steps[17]["response"]["success"] is False  # unknown entity: the reply gazebo_ros gives
    assert steps[18]["response"] is None  # a NaN pose: an error reply, never reaching physics
    after = steps[20]["response"]
    assert after["success"] and after["state"]["pose"]["position"]["x"] == pytest.approx(2.0, abs=0.05)

    # rmw_zenoh's wire, by hand
    assert raw["replies"] == 1 and "arm_controller" in (raw["controllers"] or [])
    seq, dt, gid = raw["attachment"]
    assert seq == 42 and gid == raw["gid"] and 0 <= dt < 10e9
    (token,) = raw["ss"]
    info = ros2.parse_token(token)
    assert info is not None and info.kind == "SS" and info.domain == DOMAIN
    assert info.topic == "/arm/controller_manager/list_controllers"
    assert info.dds_type == "controller_manager_msgs::srv::dds_::ListControllers_"
    assert raw["key"].endswith(info.type_hash or "-")

    # the recording says who asked what, and when
    records = read_mcap(mcap)
    events = [m for topic, _t, _l, m in records if topic == "svc/set_entity_state/_service_event"]
    assert [e.info.event_type for e in events[:2]] == [1, 2]
    assert events[0].request[0].state.name == "crate" and bytes(events[0].info.client_gid) != bytes(16)
    assert "Traceback" not in err
