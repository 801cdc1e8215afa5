"""The seed examples in scenarios/ (robots written from ../shared/seeds, Gazebo tags as the seeds write
them) run 10 sim seconds: every sensor the descriptions declare publishes under its robot's namespace at
its declared rate and decodes, and every robot moves as its timeline commands.

Cameras render at a reduced size here (their rates stay as declared): the seeds ask for up to 800x600
RGB-D at 100 Hz, which is minutes of CPU rendering and gigabytes per run. tests/test_cameras.py covers
rendering itself.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from runner.compile import compile_plan
from runner.errors import Notices
from runner.geometry import quat_to_yaw
from runner.scenario.loader import load_file
from runner.scenario.matrix import variants
from runner.scenario.schema import PluginEntry, Scenario
from runner.scenario.validate import validate_scenario
from runner.sim.world import World
from runner.wire import msgs
from runner.wire.transport import MemoryBus, unpack_attachment
from tests.conftest import SCENARIOS

SEEDS = ["block_robot", "atom_mapping", "lift_robot", "harmonic_nav", "mycar"]
CAMERAS = ("camera", "depth_camera")
# Warnings a seed description may produce: only tags we truly ignore.
IGNORABLE = (
    # what the URDF ledger says nothing reads (an SDF <pose> in a URDF <link>, <axis rpy>: the atom seed
    # robot), true by construction (tests/test_urdf_ledger.py)
    ") is not read: Gazebo's URDF reader does not read it either",
    "(GUI only)",
    "(sensors are always on)",
    "(ROS debug level)",
    "is replaced by the robot's namespace",
    "(wheel order is taken from the joint names)",
    "(wheel TF comes from joint_states)",
    "(stereo baseline (mono camera))",
    "ros_control controllers are not run",
    "(ODE contact parameter",
    "(contacts are critically damped",
    "(anisotropic friction is not supported)",
    "(no ROS services)",
    "(use the sensor's <noise>)",
    "(MuJoCo excludes parent-child contacts)",
    "(images are not distorted)",
    "(only a whole model can be static, in Gazebo too)",
    ": Gazebo ignores it too",
)


def _shrunk_plan(name: str) -> Any:
    """The example's plan with its cameras at 48x36 (their rates unchanged)."""
    doc = variants(load_file(SCENARIOS / f"{name}.yaml"))[0][1]  # (its first draws, if it draws)
    scenario = validate_scenario(doc)
    plan = compile_plan(scenario, doc)
    for robot_plan, robot in zip(plan.robots, scenario.robots, strict=True):
        extra = [
            PluginEntry(type=p.type, name=p.name, params={"width": 48, "height": 36})
            for p in robot_plan.plugins
            if p.type in CAMERAS
        ]
        robot.plugins = [*robot.plugins, *extra]
    return compile_plan(scenario, doc)


def _run(name: str) -> tuple[Scenario, Any, MemoryBus, Notices]:
    doc = variants(load_file(SCENARIOS / f"{name}.yaml"))[0][1]  # (its first draws, if it draws)
    scenario = validate_scenario(doc)
    notices = Notices()
    plan = compile_plan(scenario, doc, notices=notices)
    # same scenario, cameras shrunk (scenario plugins merge into the description's by name) and a
    # ground-truth tracker on every robot
    for robot_plan, robot in zip(plan.robots, scenario.robots, strict=True):
        extra = [
            PluginEntry(type=p.type, name=p.name, params={"width": 48, "height": 36})
            for p in robot_plan.plugins
            if p.type in CAMERAS
        ]
        robot.plugins = [*robot.plugins, *extra, PluginEntry(type="ground_truth", name="truth_for_test")]
    small = compile_plan(scenario, doc)
    bus = MemoryBus()
    World(small, bus).run()
    return scenario, plan, bus, notices


def _messages(bus: MemoryBus, key: str) -> list[tuple[int, Any]]:
    out = []
    for k, type_name, payload, att in bus.sent:
        if k == key:
            out.append((unpack_attachment(att)[1], msgs.decode(payload, type_name)))  # type: ignore[index]
    return out


def _commanded(scenario: Scenario, robot: Any) -> tuple[float, float]:
    """Path length and heading change that the timeline's Twist commands ask of a robot, through the
    acceleration limit its drive declares (a wheel acceleration limit ramps the commanded speeds)."""
    ns = robot.namespace
    cmds = sorted(
        (e.t, e.data)
        for e in scenario.timeline
        if e.topic.strip("/").startswith(ns + "/") and e.topic.endswith("cmd_vel")
    )
    if not cmds:
        return 0.0, 0.0
    drive = next((p for p in robot.plugins if p.type in ("diff_drive", "skid_steer")), None)
    acc = (drive.params.get("max_wheel_acceleration") or 0.0) if drive else 0.0
    radius = (drive.params.get("wheel_radius") or 0.0) if drive else 0.0
    sep = (drive.params.get("wheel_separation") or 0.0) if drive else 0.0
    a_lin = acc * radius if acc and radius else math.inf
    a_ang = acc * radius / (sep / 2) if acc and radius and sep else math.inf
    dt = 0.001
    v = w = dist = turn = 0.0
    for k in range(round(scenario.duration / dt)):
        t = k * dt
        data = next((d for tt, d in reversed(cmds) if tt <= t), {})
        lin = data.get("linear", {})
        v_cmd = math.hypot(lin.get("x", 0.0), lin.get("y", 0.0)) * math.copysign(1, lin.get("x", 0.0) or 1)
        w_cmd = data.get("angular", {}).get("z", 0.0)
        v += max(-a_lin * dt, min(a_lin * dt, v_cmd - v))
        w += max(-a_ang * dt, min(a_ang * dt, w_cmd - w))
        dist += abs(v) * dt
        turn += w * dt
    return dist, turn


@pytest.fixture(scope="module", params=SEEDS)
def seed(request: pytest.FixtureRequest) -> tuple[str, Scenario, Any, MemoryBus, Notices]:
    return (request.param, *_run(request.param))


@pytest.mark.timeout(240)
def test_every_declared_sensor_publishes_at_its_rate_and_decodes(seed):
    name, scenario, plan, bus, _ = seed
    checked = 0
    robots = tuple(f"{plan.name}/{robot.namespace}/" for robot in plan.robots)
    # per key: a key several plugins publish on (a robot's `tf`: its drive and robot_state_publisher)
    # carries the sum of their rates
    for topic in plan.topics():
        if topic.direction != "pub" or not topic.rate or not topic.key.startswith(robots):
            continue
        got = _messages(bus, topic.key)
        expected = topic.rate * scenario.duration
        publishers = topic.owner.count(",") + 1  # each publishes at t = 0 too
        assert abs(len(got) - expected) <= 0.05 * expected + publishers, (topic.key, len(got), expected)
        checked += 1
    assert checked >= 3, name


@pytest.mark.timeout(240)
def test_every_robot_moves_as_its_timeline_commands(seed):
    name, scenario, plan, bus, _ = seed
    moved = 0
    for robot in plan.robots:
        track = _messages(bus, f"{plan.name}/{robot.namespace}/ground_truth")
        dist_cmd, turn_cmd = _commanded(scenario, robot)
        pos = np.array([[m.pose.pose.position.x, m.pose.pose.position.y] for _, m in track])
        yaws = np.unwrap(
            [
                quat_to_yaw(
                    [
                        m.pose.pose.orientation.w,
                        m.pose.pose.orientation.x,
                        m.pose.pose.orientation.y,
                        m.pose.pose.orientation.z,
                    ]
                )
                for _, m in track
            ]
        )
        dist = float(np.sum(np.linalg.norm(np.diff(pos, axis=0), axis=1)))
        turn = float(yaws[-1] - yaws[0])
        if dist_cmd == 0 and turn_cmd == 0:
            assert dist < 0.02 and abs(turn) < 0.02, (name, robot.name, dist, turn)  # told nothing: stays
            continue
        moved += 1
        assert abs(dist - dist_cmd) <= 0.1 * dist_cmd + 0.02, (name, robot.name, dist, dist_cmd)
        assert abs(turn - turn_cmd) <= 0.1 * abs(turn_cmd) + 0.02, (name, robot.name, turn, turn_cmd)
    assert moved >= 1


@pytest.mark.timeout(240)
def test_warnings_list_only_tags_we_truly_ignore(seed):
    name, _, plan, _, notices = seed
    for n in notices:
        if "/robots/" not in str(n.location.file):
            continue  # world files: tested in tests/test_sdf.py
        text = n.render()
        assert any(reason in text for reason in IGNORABLE), f"{name}: unexpected warning: {text}"
        assert n.location.file is not None and n.location.line is not None, text
    assert plan.notices == [n.render() for n in notices]


@pytest.mark.timeout(240)
def test_block_robot_commands_reach_only_their_robot_and_both_cameras_see_change():
    _, plan, bus, _ = _run("block_robot")
    for ns in ("br", "br1"):
        cams = [
            t.key
            for r in plan.robots
            for p in r.plugins
            for t in p.topics
            if p.type == "camera" and r.namespace == ns and t.type == "sensor_msgs/msg/Image"
        ]
        assert cams, ns
        frames = dict(_messages(bus, cams[0]))
        at1, at9 = frames[1_000_000_000], frames[9_000_000_000]
        assert not np.array_equal(at1.data, at9.data), ns
    br = _messages(bus, "block_robot/br/ground_truth")
    br1 = _messages(bus, "block_robot/br1/ground_truth")
    p = br[-1][1].pose.pose.position
    q = br1[-1][1].pose.pose.position
    assert math.hypot(p.x, p.y) > 1.0  # br drove
    assert math.hypot(q.x - 0.0, q.y - 1.0) < 0.01  # br1 did not
