"""The contact (bumper), tf and imu-bias plugins against real MuJoCo physics (world stepped in-process)."""

from __future__ import annotations

import math
from collections import defaultdict

import mujoco
import numpy as np
import pytest

from runner.record import Recorder
from runner.wire import msgs
from runner.wire.transport import unpack_attachment
from tests.conftest import read_mcap
from tests.helpers import messages, plan_of, simulate

# The wall's near face is at x = 2.0; the chassis' front is 0.10 m ahead of base_link, so the bumper
# touches when base_link reaches x = 1.90 (about 1.3 s at 0.3 m/s from x = 1.5).
BUMPER = """
name: t
duration: 2.5
rate: max
world:
  models:
    - {name: wall, shape: box, size: [0.1, 6, 1], pose: {xyz: [2.05, 0, 0.5]}}
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [1.5, 0, 0.06]}
    plugins:
      - {type: diff_drive}
      - {type: ground_truth, params: {rate: 100}}
      - {type: contact, params: {link: base_link}}
      - {type: contact, name: wheel_contact, params: {link: left_wheel, topic: wheel_bumper, frame_id: world}}
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.3}}}
"""

CONTACTS = "gazebo_msgs/msg/ContactsState"


def _normal_force(state) -> float:  # type: ignore[no-untyped-def]
    """Sum over the contact points of the force on the link along the contact normal."""
    return sum(
        w.force.x * n.x + w.force.y * n.y + w.force.z * n.z
        for w, n in zip(state.wrenches, state.contact_normals, strict=True)
    )


@pytest.mark.timeout(60)
def test_bumper_is_silent_before_the_wall_and_reports_it_while_pressing(write_scenario):
    _, bus = simulate(write_scenario(BUMPER))
    truth = {t: m.pose.pose.position.x for t, m in messages(bus, "r1/ground_truth")}
    bumps = messages(bus, "r1/bumper")
    assert len(bumps) == int(2.5 * 20) + 1  # a message every tick, touching or not (as gazebo_ros_bumper)
    front = {t: truth[t] + 0.10 for t, _ in bumps}  # the chassis' front face, x
    before = [m for t, m in bumps if front[t] < 1.99]
    pressing = [m for t, m in bumps if t >= 1.6e9]
    assert len(before) >= 20 and all(not m.states for m in before)
    assert abs(max(truth.values()) - 1.90) < 0.01  # stopped by the wall
    touching = [m for m in pressing if m.states]
    assert len(touching) >= 0.8 * len(pressing), f"{len(touching)}/{len(pressing)} ticks touch the wall"
    for m in touching:
        assert m.header.frame_id == "r1/base_link"
        for s in m.states:  # wheel-ground contacts belong to other links: never here
            assert (s.collision1_name, s.collision2_name) == ("r1/base_link_collision", "wall")
            n = len(s.depths)
            assert n >= 1 and len(s.wrenches) == len(s.contact_positions) == len(s.contact_normals) == n
            assert all(d >= 0 for d in s.depths)
            for normal, pos in zip(s.contact_normals, s.contact_positions, strict=True):
                assert normal.x == pytest.approx(-1.0, abs=1e-3)  # the wall pushes the link back (link frame)
                assert pos.x == pytest.approx(0.10, abs=5e-3)  # on the chassis' front face
            assert _normal_force(s) > 0
            total = s.total_wrench.force
            assert total.x == pytest.approx(sum(w.force.x for w in s.wrenches))
    mean_push = np.mean([-sum(s.total_wrench.force.x for s in m.states) for m in touching])
    assert mean_push > 1.0  # newtons: the drive really presses


@pytest.mark.timeout(60)
def test_wheel_bumper_reports_the_ground_in_world_frame(write_scenario):
    _, bus = simulate(write_scenario(BUMPER))
    rolling = [m for t, m in messages(bus, "r1/wheel_bumper") if 0.2e9 <= t <= 1.2e9]
    assert rolling and all(m.header.frame_id == "world" for m in rolling)
    forces = []
    for m in rolling:
        assert [(s.collision1_name, s.collision2_name) for s in m.states] == [
            ("r1/left_wheel_collision", "ground")
        ]
        s = m.states[0]
        for normal, pos in zip(s.contact_normals, s.contact_positions, strict=True):
            assert (normal.x, normal.y, normal.z) == pytest.approx((0.0, 0.0, 1.0), abs=1e-6)
            assert abs(pos.z) < 1e-3 and abs(pos.y - 0.13) < 0.02  # under the left wheel, on the ground
        forces.append(_normal_force(s))
    mass = 2.0 + 2 * 0.2 + 0.05 + 0.1 + 0.01  # diffbot links
    # the wheels carry most of the weight (the mass is slightly behind the axle, on the caster)
    assert 0.25 * mass * 9.81 < np.mean(forces) < 0.5 * mass * 9.81


@pytest.mark.timeout(30)
def test_contacts_state_type_is_registered_with_its_nested_definitions():
    text = msgs.msgdef(CONTACTS)
    assert text.startswith("std_msgs/Header header\ngazebo_msgs/ContactState[] states\n")
    for nested in (
        "gazebo_msgs/ContactState",
        "geometry_msgs/Wrench",
        "geometry_msgs/Vector3",
        "std_msgs/Header",
    ):
        assert f"\nMSG: {nested}\n" in text, nested
    assert "geometry_msgs/Wrench[] wrenches" in text and "float64[] depths" in text
    assert msgs.is_known("gazebo_msgs/ContactsState") and msgs.is_known("gazebo_msgs/msg/ContactState")
    msg = msgs.from_data(CONTACTS, {"header": {"frame_id": "a"}, "states": [{"depths": [0.5, 0.25]}]})
    back = msgs.decode(msgs.encode(msg, CONTACTS), CONTACTS)
    assert back.header.frame_id == "a" and list(back.states[0].depths) == [0.5, 0.25]


@pytest.mark.timeout(60)
def test_contacts_round_trip_through_an_mcap_file(write_scenario, tmp_path):
    _, bus = simulate(write_scenario(BUMPER.replace("duration: 2.5", "duration: 1.8")))
    path = tmp_path / "bumper.mcap"
    rec = Recorder(path, include=["t/**"])
    try:
        for key, type_name, payload, att in bus.sent:
            rec.write(key, type_name, payload, unpack_attachment(att))
    finally:
        rec.close()
    ours = messages(bus, "r1/bumper")
    theirs = [(t, m) for topic, typ, t, m in read_mcap(path) if topic == "t/r1/bumper"]
    assert {typ for topic, typ, _, _ in read_mcap(path) if topic == "t/r1/bumper"} == {CONTACTS}
    assert [t for t, _ in theirs] == [t for t, _ in ours]
    assert any(m.states for _, m in ours)
    for (_, a), (_, b) in zip(ours, theirs, strict=True):
        assert b.header.frame_id == a.header.frame_id and b.header.stamp.sec == a.header.stamp.sec
        assert len(b.states) == len(a.states)
        for sa, sb in zip(a.states, b.states, strict=True):
            assert (sb.collision1_name, sb.collision2_name, sb.info) == (
                sa.collision1_name,
                sa.collision2_name,
                sa.info,
            )
            assert list(sb.depths) == list(sa.depths)
            assert sb.total_wrench.force.x == sa.total_wrench.force.x
            assert [n.x for n in sb.contact_normals] == [n.x for n in sa.contact_normals]
            assert [w.torque.y for w in sb.wrenches] == [w.torque.y for w in sa.wrenches]


TF = """
name: t
duration: 1.0
rate: max
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins: [{type: diff_drive}, {type: tf}, {type: joint_states}]
timeline:
  - {t: 0.0, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.3}}}
"""

# parent of every link of scenarios/robots/diffbot.urdf.xacro (its <joint> elements)
URDF_PARENTS = {
    "left_wheel": "base_link",
    "right_wheel": "base_link",
    "caster": "base_link",
    "lidar_link": "base_link",
    "imu_link": "base_link",
}


def _angle(q1, q2) -> float:  # type: ignore[no-untyped-def]
    """Rotation angle between two geometry_msgs quaternions, in [0, pi]."""
    dot = abs(q1.w * q2.w + q1.x * q2.x + q1.y * q2.y + q1.z * q2.z)
    return 2 * math.acos(min(1.0, dot))


@pytest.mark.timeout(60)
def test_tf_publishes_every_link_once_with_urdf_parents(write_scenario):
    path = write_scenario(TF)
    plan = plan_of(path)
    links = set(plan.robots[0].links) - {plan.robots[0].root}
    assert links == set(URDF_PARENTS)
    _, bus = simulate(path)
    tf = messages(bus, "r1/tf")
    static = messages(bus, "r1/tf_static")
    assert [t for t, _ in static] == [0]  # once, at the first step
    children: dict[str, set[str]] = defaultdict(set)  # child -> topics it appears on
    parents: dict[str, set[str]] = defaultdict(set)
    for topic, msgs_ in (("tf", tf), ("tf_static", static)):
        for _t, m in msgs_:
            names = [x.child_frame_id for x in m.transforms]
            assert len(names) == len(set(names))  # no child twice in one message
            for x in m.transforms:
                children[x.child_frame_id].add(topic)
                parents[x.child_frame_id].add(x.header.frame_id)
    # diff_drive's odom -> base_link shares `tf`; the tf plugin adds no world -> root by default
    assert parents.pop("r1/base_link") == {"r1/odom"}
    assert children.pop("r1/base_link") == {"tf"}
    assert set(children) == {f"r1/{link}" for link in URDF_PARENTS}
    for link, parent in URDF_PARENTS.items():
        assert parents[f"r1/{link}"] == {f"r1/{parent}"}
        assert len(children[f"r1/{link}"]) == 1, (link, children[f"r1/{link}"])
    assert children["r1/left_wheel"] == children["r1/right_wheel"] == {"tf"}
    assert children["r1/lidar_link"] == children["r1/caster"] == children["r1/imu_link"] == {"tf_static"}
    fixed = {x.child_frame_id: x.transform.translation for x in static[0][1].transforms}
    assert (fixed["r1/lidar_link"].x, fixed["r1/lidar_link"].z) == pytest.approx((0.0, 0.10))
    assert (fixed["r1/caster"].x, fixed["r1/caster"].z) == pytest.approx((-0.17, -0.03))
    # the two plugins' messages on `tf`: 50 Hz each
    wheel_msgs = [(t, m) for t, m in tf if m.transforms[0].child_frame_id != "r1/base_link"]
    assert len(wheel_msgs) == len(tf) - len(wheel_msgs) == 51


@pytest.mark.timeout(60)
def test_tf_wheel_transforms_turn_with_the_wheel_joints(write_scenario):
    _, bus = simulate(write_scenario(TF))
    joints = {t: dict(zip(m.name, m.position, strict=True)) for t, m in messages(bus, "r1/joint_states")}
    wheel = {
        t: {x.child_frame_id: x.transform for x in m.transforms}
        for t, m in messages(bus, "r1/tf")
        if m.transforms[0].child_frame_id != "r1/base_link"
    }
    first = wheel[0]["r1/left_wheel"]
    turned = []
    for t, tfs in wheel.items():
        left = tfs["r1/left_wheel"]
        # the axle does not move in base_link; only the rotation about it changes
        assert (left.translation.x, left.translation.y, left.translation.z) == pytest.approx(
            (0.0, 0.13, 0.0), abs=1e-6
        )
        q = joints[t]["left_wheel_joint"]
        expected = abs(math.remainder(q - joints[0]["left_wheel_joint"], 2 * math.pi))
        assert _angle(first.rotation, left.rotation) == pytest.approx(expected, abs=1e-5)
        turned.append(expected)
    assert max(turned) > 2.0  # 0.3 m/s on 0.05 m wheels: ~6 rad in 1 s, so the transform really changes
    rot = [wheel[t]["r1/right_wheel"].rotation for t in sorted(wheel)]
    assert _angle(rot[0], rot[10]) > 0.5


@pytest.mark.timeout(60)
def test_tf_root_and_periodic_static(write_scenario):
    text = TF.replace("{type: tf}", "{type: tf, params: {include_root: true, static_period: 0.25}}")
    _, bus = simulate(write_scenario(text))
    # at 50 Hz, the first ticks at or after each multiple of 0.25 s (no drift)
    assert [t for t, _ in messages(bus, "r1/tf_static")] == [0, 260_000_000, 500_000_000, 760_000_000, 10**9]
    last = [m for _, m in messages(bus, "r1/tf") if len(m.transforms) == 3][-1]
    root = next(x for x in last.transforms if x.child_frame_id == "r1/base_link")
    assert root.header.frame_id == "world"
    assert 0.2 < root.transform.translation.x < 0.35  # driven ~0.3 m


IMU = """
name: t
duration: 1.0
rate: max
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: imu}
      - type: imu
        name: biased
        params:
          topic: imu_biased
          angular_velocity_bias: [0.01, -0.02, 0.03]
          linear_acceleration_bias: [0.1, 0.2, -0.3]
      - type: imu
        name: random_bias
        params:
          topic: imu_random
          angular_velocity_bias_stddev: 0.05
          linear_acceleration_bias_stddev: 0.5
"""


def _readings(bus, suffix: str) -> tuple[np.ndarray, np.ndarray]:  # type: ignore[no-untyped-def]
    ms = [m for _, m in messages(bus, suffix)]
    w = np.array([[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for m in ms])
    a = np.array([[m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z] for m in ms])
    return w, a


@pytest.mark.timeout(60)
def test_imu_bias_is_a_constant_offset_at_rest(write_scenario):
    path = write_scenario(IMU)
    _, bus = simulate(path)
    w0, a0 = _readings(bus, "r1/imu")
    w1, a1 = _readings(bus, "r1/imu_biased")
    assert len(w0) == len(w1) == 101
    assert np.allclose(w1 - w0, [0.01, -0.02, 0.03], atol=1e-12)
    assert np.allclose(a1 - a0, [0.1, 0.2, -0.3], atol=1e-12)
    rest = slice(50, None)  # settled on its wheels and caster
    assert np.allclose(a1[rest].mean(axis=0), [0.1, 0.2, 9.81 - 0.3], atol=0.05)
    assert np.allclose(w1[rest].mean(axis=0), [0.01, -0.02, 0.03], atol=1e-3)
    # a random bias: drawn once (constant over the run), of the asked size, repeatable with the seed
    w2, a2 = _readings(bus, "r1/imu_random")
    bw, ba = w2 - w0, a2 - a0
    assert np.allclose(bw, bw[0], atol=1e-12) and np.allclose(ba, ba[0], atol=1e-12)
    assert 0 < np.abs(bw[0]).max() < 5 * 0.05 and 0 < np.abs(ba[0]).max() < 5 * 0.5
    _, again = simulate(path)
    w3, a3 = _readings(again, "r1/imu_random")
    assert np.array_equal(w3, w2) and np.array_equal(a3, a2)


@pytest.mark.timeout(30)
def test_contact_and_tf_build_checks(write_scenario):
    from runner.errors import ScenarioError

    bad = TF.replace("{type: tf}", "{type: contact, params: {link: imu_link}}")
    with pytest.raises(ScenarioError, match="no collision geometry"):
        plan_of(write_scenario(bad))
    bad = TF.replace("{type: tf}", "{type: contact, params: {link: bumper_link}}")
    with pytest.raises(ScenarioError, match="no link 'bumper_link'"):
        plan_of(write_scenario(bad))
    plan = plan_of(write_scenario(TF))
    keys = {t.key: t for t in plan.topics()}
    assert keys["t/r1/tf"].type == keys["t/r1/tf_static"].type == "tf2_msgs/msg/TFMessage"
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    assert model.nbody == 7  # the tf plugin adds nothing to the model
