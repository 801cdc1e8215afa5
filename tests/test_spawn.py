"""Spawning robots into a running world and deleting them (runner.sim.grow), through the world's own
services as gazebo_ros and ros_gz name them, in process (the ROS 2 side: tests/test_ros2_spawn.py)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from runner.sim.world import World
from runner.wire import msgs
from runner.wire.transport import MemoryBus
from tests.helpers import plan_of, robot_scenario
from tests.test_gazebo_parity import diffbot
from tests.test_sim_control import BOX, PLUGINS, WORLD, _answer, _call

SPAWN = "gazebo_msgs/srv/SpawnEntity"
DELETE = "gazebo_msgs/srv/DeleteEntity"
TWIST = "geometry_msgs/msg/Twist"
ODOM = "nav_msgs/msg/Odometry"


def _world(tmp_path: Path, duration: float = 2.0) -> tuple[World, MemoryBus]:
    path = robot_scenario(tmp_path, BOX, plugins=PLUGINS, world=WORLD, xyz=(0, 0, 0.5), duration=duration)
    bus = MemoryBus()
    world = World(plan_of(path), bus)
    world._should_stop = lambda: False
    return world, bus


def _spawn(world: World, bus: MemoryBus, name: str, x: float = 2.0, y: float = 1.0, **extra: Any) -> Any:
    request = {
        "name": name,
        "xml": diffbot(),
        "initial_pose": {"position": {"x": x, "y": y, "z": 0.11}},
        **extra,
    }
    answers = _call(bus, "g/spawn_entity", SPAWN, request)
    world._boundary()
    return _answer(answers, SPAWN)


def _drive(world: World, name: str, v: float = 0.3) -> None:
    cmd = msgs.from_data(TWIST, {"linear": {"x": v}})
    world.publish(world.make_publisher(f"g/{name}/cmd_vel", TWIST), cmd, world.now_ns)


def _sent(bus: MemoryBus, key: str, type_name: str) -> list[Any]:
    return [msgs.decode(p, type_name) for k, _t, p, _a in bus.sent if k == key]


def _root(world: World, name: str) -> np.ndarray:
    return np.array(world.data.xpos[next(h for h in world.robots if h.name == name).root_body])


def test_a_spawned_robot_starts_its_plugins_and_drives(tmp_path: Path) -> None:
    world, bus = _world(tmp_path)
    before = world.model.nbody
    answer = _spawn(world, bus, "r9")
    assert answer.success, answer.status_message
    assert world.model.nbody > before
    assert [r.name for r in world.robots] == ["bot", "r9"]
    start = _root(world, "r9")
    assert start[:2] == pytest.approx([2.0, 1.0], abs=1e-6)
    _drive(world, "r9")
    world.run()
    end = _root(world, "r9")
    # its diff drive took the command: 0.3 m/s for about 2 s, straight ahead (+x)
    assert 0.4 < end[0] - start[0] < 0.62, end - start
    assert abs(end[1] - start[1]) < 0.02
    odom = _sent(bus, "g/r9/odom", ODOM)
    assert len(odom) > 10
    # (gazebo_ros_diff_drive's odometry source is the world by default: the robot's pose in the world)
    assert odom[-1].pose.pose.position.x == pytest.approx(end[0], abs=0.03)
    assert any(k == "g/r9/robot_description" for k, *_ in bus.sent)


def test_the_plugins_already_running_read_the_new_world(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """The box's IMU reads its sensor values through views into the data: after the swap they must be
    views into the new data (the box falls, lands, and the accelerometer then reads gravity)."""
    world, bus = _world(tmp_path, duration=1.5)
    assert _spawn(world, bus, "r9").success
    imu = next(p for p in world.plugins if type(p).__name__ == "Imu")
    assert np.shares_memory(imu.sd_a, world.data.sensordata)
    world.run()
    readings = _sent(bus, "g/bot/imu", "sensor_msgs/msg/Imu")
    assert readings[-1].linear_acceleration.z == pytest.approx(9.81, abs=0.6)
    assert "still holds the old world" not in capsys.readouterr().err


def test_delete_takes_the_robot_out_and_its_name_can_be_taken_again(tmp_path: Path) -> None:
    world, bus = _world(tmp_path)
    assert _spawn(world, bus, "r9").success
    _drive(world, "r9")
    for _ in range(50):
        world.now_ns += world.step_ns
        mujoco.mj_step(world.model, world.data)
        world._boundary()
    answers = _call(bus, "g/delete_entity", DELETE, {"name": "r9"})
    world._boundary()
    answer = _answer(answers, DELETE)
    assert answer.success, answer.status_message
    assert [r.name for r in world.robots] == ["bot"]
    assert {"g/r9/odom", "g/r9/cmd_vel", "g/r9/tf"} <= set(bus.withdrawn)
    sent = len(_sent(bus, "g/r9/odom", ODOM))
    with pytest.raises(ValueError, match="does not exist"):
        world.entity_state("r9")
    m = world.model
    gone = [g for g in range(m.ngeom) if (m.body(int(m.geom_bodyid[g])).name or "").startswith("r9/")]
    assert gone and all(m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0 for g in gone)
    assert all(m.geom_rgba[g, 3] == 0 for g in gone)
    again = _spawn(world, bus, "r9", x=-1.0, y=-1.0)
    assert again.success, again.status_message
    assert _root(world, "r9")[:2] == pytest.approx([-1.0, -1.0], abs=1e-6)
    world.run()
    assert len(_sent(bus, "g/r9/odom", ODOM)) > sent + 5  # the new one publishes
    # a second delete of a name that is gone says so
    answers = _call(bus, "g/delete_entity", DELETE, {"name": "nobody"})
    world._boundary()
    assert not _answer(answers, DELETE).success


def test_reset_simulation_keeps_a_spawned_robot_where_it_was_spawned(tmp_path: Path) -> None:
    world, bus = _world(tmp_path, duration=1.0)
    assert _spawn(world, bus, "r9").success
    assert _spawn(world, bus, "r8", x=-2.0, y=0.0).success
    answers = _call(bus, "g/delete_entity", DELETE, {"name": "r8"})
    world._boundary()
    assert _answer(answers, DELETE).success
    _drive(world, "r9")
    world.run()
    assert _root(world, "r9")[0] > 2.1
    world.reset_simulation()
    assert world.now_ns == 0
    assert [r.name for r in world.robots] == ["bot", "r9"]
    assert _root(world, "r9")[:2] == pytest.approx([2.0, 1.0], abs=1e-6)
    m = world.model
    r8 = [g for g in range(m.ngeom) if (m.body(int(m.geom_bodyid[g])).name or "").startswith("r8/")]
    assert r8 and all(m.geom_contype[g] == 0 for g in r8)  # still out of the world
    assert sum(1 for p in world.plugins if p.ctx.robot.name == "r8") == 0


@pytest.mark.parametrize(
    ("request_", "said"),
    [
        ({"name": "bot"}, "already exists"),
        ({"name": "crate"}, "already exists"),
        ({"name": "r7", "xml": "<robot name='x'><link name='a'>"}, ""),
        ({"name": "r7", "xml": "<?xml version='1.0'?><sdf version='1.9'><model name='m'/></sdf>"}, "SDF"),
        ({"name": "r7", "xml": ""}, "empty"),
        ({"name": "bad name"}, ""),
        ({"name": "r7", "reference_frame": "nowhere"}, "not found"),
    ],
)
def test_bad_spawn_requests_are_refused_and_the_world_goes_on(
    tmp_path: Path, request_: dict[str, Any], said: str
) -> None:
    world, bus = _world(tmp_path, duration=0.2)
    request = {"xml": diffbot(), **request_}
    answers = _call(bus, "g/spawn_entity", SPAWN, request)
    world._boundary()
    answer = _answer(answers, SPAWN)
    assert not answer.success
    assert said in answer.status_message
    assert answer.status_message
    assert [r.name for r in world.robots] == ["bot"]
    world.run()
    assert world.now_ns >= world.plan.duration_ns


def test_a_pose_with_a_nan_gets_an_error_reply(tmp_path: Path) -> None:
    world, bus = _world(tmp_path, duration=0.2)
    request = {"name": "r7", "xml": diffbot(), "initial_pose": {"position": {"x": math.nan}}}
    answers = _call(bus, "g/spawn_entity", SPAWN, request)
    world._boundary()
    assert answers == [(None, "initial_pose.position.x is not a finite number")]
    assert [r.name for r in world.robots] == ["bot"]


def test_ros_gz_create_and_remove(tmp_path: Path) -> None:
    world, bus = _world(tmp_path, duration=0.2)
    create = "ros_gz_interfaces/srv/SpawnEntity"
    key = f"g/world/{world.plan.name}/create"
    key = next(s.key for s in world.plan.world_services if s.key.endswith("/create"))
    factory = {"entity_factory": {"name": "bot", "allow_renaming": True, "sdf": diffbot()}}
    answers = _call(bus, key, create, factory)
    world._boundary()
    assert _answer(answers, create).success
    assert [r.name for r in world.robots] == ["bot", "bot_1"]
    # without a name: the URDF's own
    answers = _call(bus, key, create, {"entity_factory": {"sdf": diffbot()}})
    world._boundary()
    assert _answer(answers, create).success
    assert [r.name for r in world.robots] == ["bot", "bot_1", "testbot"]
    remove = "ros_gz_interfaces/srv/DeleteEntity"
    key = next(s.key for s in world.plan.world_services if s.key.endswith("/remove"))
    answers = _call(bus, key, remove, {"entity": {"name": "bot_1", "type": 2}})
    world._boundary()
    assert _answer(answers, remove).success
    assert [r.name for r in world.robots] == ["bot", "testbot"]
    # a file outside the scenario's folders is not read
    answers = _call(
        bus,
        next(s.key for s in world.plan.world_services if s.key.endswith("/create")),
        create,
        {"entity_factory": {"name": "x", "sdf_filename": "/etc/hostname"}},
    )
    world._boundary()
    assert not _answer(answers, create).success


# a 0.4 m red block, spawned in front of r1's camera and deleted again by the timeline
BLOCK = (
    "<robot name='block'><link name='base'><inertial><mass value='5'/>"
    "<inertia ixx='0.1' iyy='0.1' izz='0.1' ixy='0' ixz='0' iyz='0'/></inertial>"
    "<visual><geometry><box size='0.4 0.4 0.4'/></geometry><material name='red'><color rgba='1 0 0 1'/>"
    "</material></visual><collision><geometry><box size='0.4 0.4 0.4'/></geometry></collision></link></robot>"
)
# a box with a camera of its own (a Gazebo camera sensor with gazebo_ros's plugin), spawned facing r1
EYE = (
    "<robot name='eye'><link name='base'><inertial><mass value='2'/>"
    "<inertia ixx='0.01' iyy='0.01' izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial>"
    "<collision><geometry><box size='0.1 0.1 0.1'/></geometry></collision></link>"
    "<gazebo reference='base'><sensor type='camera' name='eye_cam'><update_rate>20</update_rate>"
    "<camera><horizontal_fov>1.0</horizontal_fov><image><width>16</width><height>12</height></image></camera>"
    "<plugin name='cam' filename='libgazebo_ros_camera.so'/></sensor></gazebo></robot>"
)
CAMERA_SCENE = """
name: sp
duration: 0.8
rate: max
seed: 3
renderers: {renderers}
robots:
  - name: r1
    description: {{file: "{{diffbot}}"}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive}}
      - {{type: camera, params: {{link: lidar_link, width: 32, height: 24, rate: 20}}}}
timeline:
  - {{t: 0.3, call: /spawn_entity, data: {{name: r2, xml: "{block}", initial_pose: {{position: {{x: 1.2, z: 0.2}}}}}}}}
  - {{t: 0.55, call: /delete_entity, data: {{name: r2}}}}
  - {{t: 0.3, call: /spawn_entity, data: {{name: r3, xml: "{eye}", initial_pose: {{position: {{x: 2.0, z: 0.1}}, orientation: {{z: 1.0, w: 0.0}}}}}}}}
"""


@pytest.mark.timeout(240)
@pytest.mark.parametrize("renderers", ["process", "world"])
def test_a_camera_sees_a_spawned_robot_and_not_a_deleted_one(
    write_scenario: Any, tmp_path: Path, renderers: str
) -> None:
    """The spawned block shows in r1's camera from the spawn on and is gone after its delete, whether the
    camera renders in the world's process or in a renderer process (which takes the world's new model)."""
    from mcap.reader import make_reader

    from tests.conftest import run_cli

    path = write_scenario(CAMERA_SCENE.format(renderers=renderers, block=BLOCK, eye=EYE), f"{renderers}.yaml")
    mcap = tmp_path / f"{renderers}.mcap"
    proc = run_cli("run", str(path), "--record", str(mcap), "-q", "--no-judge", timeout=200)
    assert proc.returncode == 0, proc.stderr
    with open(mcap, "rb") as f:
        images = [
            (ch.topic, m.log_time, msgs.decode(bytes(m.data), "sensor_msgs/msg/Image"))
            for _s, ch, m in make_reader(f).iter_messages(log_time_order=True)
            if ch.topic.endswith("image_raw")
        ]
    frames = [(t, i) for topic, t, i in images if topic == "sp/r1/camera/image_raw"]
    assert len(frames) >= 14
    # the spawned camera renders too (in the renderer process when cameras render there), from its spawn
    eye = [(t, i) for topic, t, i in images if topic.startswith("sp/r3/")]
    assert len(eye) >= 8 and min(t for t, _ in eye) >= 300_000_000, [topic for topic, *_ in images][-5:]
    assert (eye[-1][1].width, eye[-1][1].height) == (16, 12)
    assert len(set(bytes(eye[-1][1].data))) > 1  # it sees something (r1, the ground), not a blank frame

    def pixels(img: Any) -> np.ndarray:
        return np.asarray(img.data, dtype=np.uint8).reshape(img.height, img.width, 3).astype(float)

    first = pixels(frames[0][1])
    # how far each frame is from the first (mean absolute difference, 0-255), by when
    before = [np.abs(pixels(i) - first).mean() for t, i in frames if t < 300_000_000]
    during = [np.abs(pixels(i) - first).mean() for t, i in frames if 350_000_000 <= t < 550_000_000]
    after = [np.abs(pixels(i) - first).mean() for t, i in frames if t >= 600_000_000]
    print(before, during, after)
    assert max(before) < 1.0 and max(after) < 1.0, (before, after)
    assert min(during) > 5.0, during
