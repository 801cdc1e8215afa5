"""A recording opens in Foxglove as a 3D view with no set-up: the scene (foxglove.SceneUpdate), every
frame's transform from `world`, each robot's URDF. Checked here with the readers Foxglove's own formats
have (mcap + protobuf + ROS 2 decoders), against the scenario."""

from __future__ import annotations

import subprocess
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path
from typing import Any

import mujoco
import pytest
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory as ProtobufDecoders
from mcap_ros2.decoder import DecoderFactory as Ros2Decoders

from runner.compile import compile_plan
from runner.scenario.loader import load_file
from runner.scenario.validate import validate_scenario
from runner.sim.scene import scene_update
from tests.conftest import SCENARIOS, scenario_cmd


def _read(path: Path) -> list[tuple[str, str, Any]]:
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[ProtobufDecoders(), Ros2Decoders()])
        return [(ch.topic, schema.name, msg) for schema, ch, _m, msg in reader.iter_decoded_messages()]


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> tuple[Any, list[tuple[str, str, Any]]]:
    mcap = tmp_path_factory.mktemp("fox") / "demo.mcap"
    r = subprocess.run(
        scenario_cmd(
            "run",
            str(SCENARIOS / "two_robots.yaml"),
            "--duration",
            "1.5",
            "--no-judge",
            "-q",
            "--record",
            str(mcap),
        ),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 0, r.stderr
    doc = load_file(SCENARIOS / "two_robots.yaml")
    return compile_plan(validate_scenario(doc), doc), _read(mcap)


@pytest.mark.timeout(90)
def test_every_link_with_a_visual_has_geometry_in_the_scene(demo: Any) -> None:
    plan, messages = demo
    scenes = [m for topic, schema, m in messages if schema == "foxglove.SceneUpdate"]
    assert len(scenes) == 2  # at t = 0 and 1 s (rate 1 Hz): a viewer seeking anywhere finds one near
    entities = {e.frame_id: e for e in scenes[-1].entities}
    for robot in plan.robots:
        urdf = ET.fromstring(robot.urdf)
        with_visuals = [link.get("name") for link in urdf.iter("link") if link.find("visual") is not None]
        assert with_visuals, robot.name
        for link in with_visuals:
            e = entities.get(f"{robot.namespace}/{link}")
            assert e is not None, f"{robot.namespace}/{link} has no geometry in the scene"
            shapes = len(e.cubes) + len(e.spheres) + len(e.cylinders) + len(e.triangles)
            assert shapes >= 1 and e.frame_locked
    world = entities["world"]  # the arena: ground, four walls and a crate (boxes), a pillar (cylinder)
    assert len(world.cubes) >= 6 and len(world.cylinders) >= 1
    assert entities["ball"].spheres  # a free model has its own frame
    crate = next(c for c in world.cubes if abs(c.size.x - 0.6) < 1e-6)  # size: [0.6, 0.6, 0.6]
    assert crate.color.a == pytest.approx(1.0)


@pytest.mark.timeout(90)
def test_every_frame_has_one_parent_and_reaches_world(demo: Any) -> None:
    plan, messages = demo
    parents: dict[str, set[str]] = defaultdict(set)
    for _topic, schema, m in messages:
        if schema == "tf2_msgs/msg/TFMessage":
            for t in m.transforms:
                parents[t.child_frame_id].add(t.header.frame_id)
    assert all(len(p) == 1 for p in parents.values()), {k: v for k, v in parents.items() if len(v) > 1}
    frames = {e.frame_id for _t, s, m in messages if s == "foxglove.SceneUpdate" for e in m.entities}
    frames |= {
        m.header.frame_id
        for _t, s, m in messages
        if s in ("sensor_msgs/msg/LaserScan", "sensor_msgs/msg/Imu")
    }
    frames |= {f"{r.namespace}/{link}" for r in plan.robots for link in r.links}
    for frame in frames:
        seen, f = [], frame
        while f != "world":
            assert f in parents, f"{frame}: no transform to {f}'s parent ({' -> '.join([*seen, f])})"
            seen.append(f)
            f = next(iter(parents[f]))
            assert len(seen) < 50, f"a cycle: {seen}"


@pytest.mark.timeout(90)
def test_each_robot_has_its_urdf_on_robot_description(demo: Any) -> None:
    plan, messages = demo
    for robot in plan.robots:
        texts = [m.data for t, s, m in messages if t == f"{plan.name}/{robot.namespace}/robot_description"]
        assert texts, robot.name
        urdf = ET.fromstring(texts[-1])
        assert urdf.tag == "robot"
        # named as the transforms name them (robot_state_publisher's frame_prefix)
        assert {link.get("name") for link in urdf.iter("link")} == {
            f"{robot.namespace}/{link}" for link in robot.links
        }


def test_meshes_capsules_and_planes_become_foxglove_primitives() -> None:
    model = mujoco.MjModel.from_xml_string(
        """<mujoco><asset><mesh name="tet" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/></asset><worldbody>
        <geom type="plane" size="0 0 1" rgba="1 1 1 1"/>
        <body name="thing" pos="1 2 3"><freejoint/>
          <geom type="mesh" mesh="tet" rgba="0 1 0 1"/>
          <geom type="capsule" size="0.1 0.5" rgba="0 0 1 1"/>
          <geom type="box" size="0.1 0.1 0.1" group="3"/>
        </body></worldbody></mujoco>"""
    )
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    from mcap_protobuf.decoder import DecoderFactory  # noqa: F401  (protobuf available: decode below)

    from runner.record import foxglove_schema

    schema = foxglove_schema("foxglove.SceneUpdate")
    pool = descriptor_pool.DescriptorPool()
    for fd in descriptor_pb2.FileDescriptorSet.FromString(schema.data).file:
        pool.Add(fd)
    cls = message_factory.GetMessageClass(pool.FindMessageTypeByName("foxglove.SceneUpdate"))
    update = cls.FromString(scene_update(model, 5_000_000_000))
    ents = {e.frame_id: e for e in update.entities}
    assert set(ents) == {"world", "thing"}
    plane = ents["world"].cubes[0]
    assert plane.size.x == pytest.approx(20.0) and plane.size.z < 0.01  # infinite plane: drawn 20 m wide
    thing = ents["thing"]
    assert len(thing.triangles) == 1 and len(thing.triangles[0].points) == 4 * 3  # 4 faces of a tetrahedron
    assert len(thing.cylinders) == 1 and len(thing.spheres) == 2  # a capsule: a cylinder and two caps
    assert not thing.cubes  # the group-3 box is collision only: not drawn
    assert thing.timestamp.seconds == 5  # (protobuf's Timestamp)


def test_the_layout_in_docs_names_topics_the_demo_records(demo: Any) -> None:
    import json

    _plan, messages = demo
    recorded = {topic for topic, _s, _m in messages}
    layout = json.loads((SCENARIOS.parent / "docs" / "foxglove_layout.json").read_text())
    panels = layout["configById"]
    named = set(panels["3D!world"]["topics"])
    named |= {p["value"].split(".")[0] for p in panels["Plot!speeds"]["paths"]}
    named.add(panels["RawMessages!cmd"]["topicPath"])
    assert named and named <= recorded, named - recorded
    assert panels["3D!world"]["followTf"] == "world"
