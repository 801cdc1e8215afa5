"""Fixed-layout encoders (runner.wire.cdr) write exactly the bytes rosbags writes for the same message."""

from __future__ import annotations

from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest

from runner.plugin import Plugin, Topic, registry
from runner.sim.world import World
from runner.wire import msgs
from runner.wire.cdr import Layout, LayoutError, Peek, string_message
from runner.wire.transport import MemoryBus
from tests.helpers import messages, plan_of

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"

T = msgs.T
rng = np.random.default_rng(1)


def vec3(v: Any) -> Any:
    return T["geometry_msgs/msg/Vector3"](x=float(v[0]), y=float(v[1]), z=float(v[2]))


def quat(q: Any) -> Any:
    return T["geometry_msgs/msg/Quaternion"](x=float(q[0]), y=float(q[1]), z=float(q[2]), w=float(q[3]))


def imu(stamp: int, frame: str, q: Any, w: Any, a: Any) -> Any:
    return T["sensor_msgs/msg/Imu"](
        header=msgs.header(stamp, frame),
        orientation=quat(q),
        orientation_covariance=np.arange(9.0),
        angular_velocity=vec3(w),
        angular_velocity_covariance=np.full(9, 0.5),
        linear_acceleration=vec3(a),
        linear_acceleration_covariance=np.eye(3).ravel(),
    )


def odom(stamp: int, frame: str, child: str, pose: Any, twist: Any) -> Any:
    return T["nav_msgs/msg/Odometry"](
        header=msgs.header(stamp, frame),
        child_frame_id=child,
        pose=T["geometry_msgs/msg/PoseWithCovariance"](
            pose=T["geometry_msgs/msg/Pose"](
                position=T["geometry_msgs/msg/Point"](x=pose[0], y=pose[1], z=pose[2]),
                orientation=quat(pose[3:]),
            ),
            covariance=np.zeros(36),
        ),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T["geometry_msgs/msg/Twist"](linear=vec3(twist[:3]), angular=vec3(twist[3:])),
            covariance=np.linspace(0, 1, 36),
        ),
    )


def scan(stamp: int, frame: str, ranges: Any, intensities: Any) -> Any:
    return T["sensor_msgs/msg/LaserScan"](
        header=msgs.header(stamp, frame),
        angle_min=-3.1,
        angle_max=3.1,
        angle_increment=0.01,
        time_increment=0.0,
        scan_time=0.1,
        range_min=0.1,
        range_max=8.0,
        ranges=np.asarray(ranges, dtype=np.float32),
        intensities=np.asarray(intensities, dtype=np.float32),
    )


def joint_state(stamp: int, names: list[str], pos: Any, vel: Any, eff: Any) -> Any:
    return T["sensor_msgs/msg/JointState"](
        header=msgs.header(stamp, ""), name=names, position=pos, velocity=vel, effort=eff
    )


def tf(stamp: int, frames: list[tuple[str, str]], poses: list[Any]) -> Any:
    out = []
    for (parent, child), p in zip(frames, poses, strict=True):
        out.append(
            T["geometry_msgs/msg/TransformStamped"](
                header=msgs.header(stamp, parent),
                child_frame_id=child,
                transform=T["geometry_msgs/msg/Transform"](translation=vec3(p[:3]), rotation=quat(p[3:])),
            )
        )
    return T["tf2_msgs/msg/TFMessage"](transforms=out)


STAMPS = [0, 1, 999_999_999, 1_000_000_000, 12_345_678_901, 2**31 * 1_000_000_000 - 1]
# frame ids of every length mod 8, so every alignment of what follows them is exercised
FRAMES = ["", "a", "ab", "abc", "r1/imu", "r1/imu_l", "robot/imu_link", "very/long/frame_name/x"]


@pytest.mark.parametrize("frame", FRAMES)
def test_imu_layout_is_byte_identical(frame: str) -> None:
    layout = Layout("sensor_msgs/msg/Imu", imu(0, frame, [0, 0, 0, 1], [0] * 3, [0] * 3), [])
    enc = Layout(
        "sensor_msgs/msg/Imu",
        imu(0, frame, [0, 0, 0, 1], [0] * 3, [0] * 3),
        ["header.stamp", "orientation", "angular_velocity", "linear_acceleration"],
    )
    assert layout.encode() == msgs.encode(
        imu(0, frame, [0, 0, 0, 1], [0] * 3, [0] * 3), "sensor_msgs/msg/Imu"
    )
    for stamp in STAMPS:
        q, w, a = rng.normal(size=4), rng.normal(size=3), rng.normal(size=3) * 1e6
        assert enc.encode(stamp, q, w, a) == msgs.encode(imu(stamp, frame, q, w, a), "sensor_msgs/msg/Imu")


@pytest.mark.parametrize("frame", FRAMES[:4])
@pytest.mark.parametrize("child", FRAMES[3:7])
def test_odometry_layout_is_byte_identical(frame: str, child: str) -> None:
    enc = Layout(
        "nav_msgs/msg/Odometry",
        odom(0, frame, child, [0.0] * 7, [0.0] * 6),
        ["header.stamp", "pose.pose", "twist.twist"],
    )
    for stamp in STAMPS:
        pose, twist = rng.normal(size=7).tolist(), rng.normal(size=6).tolist()
        expected = msgs.encode(odom(stamp, frame, child, pose, twist), "nav_msgs/msg/Odometry")
        assert enc.encode(stamp, pose, twist) == expected


@pytest.mark.parametrize("n", [0, 1, 3, 360, 1081])
@pytest.mark.parametrize("with_intensities", [False, True])
def test_laserscan_layout_is_byte_identical(n: int, with_intensities: bool) -> None:
    ni = n if with_intensities else 0
    fields = ["header.stamp", "ranges"] + (["intensities"] if with_intensities else [])
    for frame in FRAMES:
        enc = Layout("sensor_msgs/msg/LaserScan", scan(0, frame, np.zeros(n), np.zeros(ni)), fields)
        for stamp in STAMPS[:3]:
            r = rng.uniform(0, 10, n).astype(np.float32)
            r[::7] = np.inf
            i = rng.uniform(0, 100, ni).astype(np.float32)
            values = [stamp, r] + ([i] if with_intensities else [])
            assert enc.encode(*values) == msgs.encode(scan(stamp, frame, r, i), "sensor_msgs/msg/LaserScan")


@pytest.mark.parametrize(
    "names", [[], ["a"], ["left_wheel_joint", "right_wheel_joint"], ["j1", "j22", "j333"]]
)
def test_joint_state_layout_is_byte_identical(names: list[str]) -> None:
    n = len(names)
    enc = Layout(
        "sensor_msgs/msg/JointState",
        joint_state(0, names, np.zeros(n), np.zeros(n), np.zeros(n)),
        ["header.stamp", "position", "velocity", "effort"],
    )
    for stamp in STAMPS:
        p, v, e = rng.normal(size=n), rng.normal(size=n), rng.normal(size=n)
        assert enc.encode(stamp, p, v, e) == msgs.encode(
            joint_state(stamp, names, p, v, e), "sensor_msgs/msg/JointState"
        )


@pytest.mark.parametrize("count", [1, 2, 5])
def test_tf_message_layout_is_byte_identical(count: int) -> None:
    frames = [(FRAMES[(i * 3) % 8], FRAMES[(i * 5 + 1) % 8]) for i in range(count)]
    zero = [[0.0] * 7] * count
    fields = [f"transforms[{i}].header.stamp" for i in range(count)]
    fields += [f"transforms[{i}].transform" for i in range(count)]
    enc = Layout("tf2_msgs/msg/TFMessage", tf(0, frames, zero), fields)
    for stamp in STAMPS:
        poses = rng.normal(size=(count, 7)).tolist()
        assert enc.encode(*([stamp] * count), *poses) == msgs.encode(
            tf(stamp, frames, poses), "tf2_msgs/msg/TFMessage"
        )


def test_views_write_into_the_message_and_stamp_only_layouts_reuse_them() -> None:
    template = imu(0, "r1/imu_link", [0, 0, 0, 1], [0] * 3, [0] * 3)
    layout = Layout("sensor_msgs/msg/Imu", template, ["header.stamp"])
    layout.view("angular_velocity")[:] = (1.0, 2.0, 3.0)
    layout.view("orientation")[:] = (0.0, 0.0, 0.6, 0.8)
    got = msgs.decode(layout.encode(5_000_000_001), "sensor_msgs/msg/Imu")
    assert (got.header.stamp.sec, got.header.stamp.nanosec) == (5, 1)
    assert (got.angular_velocity.x, got.angular_velocity.y, got.angular_velocity.z) == (1.0, 2.0, 3.0)
    assert (got.orientation.z, got.orientation.w) == (0.6, 0.8)
    assert got.header.frame_id == "r1/imu_link"


def test_layout_errors_name_the_field() -> None:
    layout = Layout("sensor_msgs/msg/Imu", imu(0, "x", [0, 0, 0, 1], [0] * 3, [0] * 3), [])
    with pytest.raises(LayoutError, match="no field 'orientaton'"):
        layout.view("orientaton")
    with pytest.raises(LayoutError, match="not a run of numbers"):
        layout.view("header")  # holds a string


def test_every_builtin_publisher_sends_what_rosbags_would_encode() -> None:
    """End to end: every message the demo world publishes (most through fixed layouts) decodes, and
    re-encoding it with rosbags gives the very same bytes."""
    plan = plan_of(SCENARIOS / "two_robots.yaml")
    plan.duration_ns = 1_000_000_000
    bus = MemoryBus()
    World(plan, bus).run()
    by_type: dict[str, int] = {}
    for _key, type_name, payload, _att in bus.sent:
        if type_name.startswith("foxglove."):
            continue  # the Foxglove scene: protobuf, made by foxglove-sdk (tests/test_foxglove.py)
        msg = msgs.decode(payload, type_name)
        assert msgs.encode(msg, type_name) == payload, type_name
        by_type[type_name] = by_type.get(type_name, 0) + 1
    for type_name in (
        "sensor_msgs/msg/LaserScan",
        "sensor_msgs/msg/Imu",
        "nav_msgs/msg/Odometry",
        "sensor_msgs/msg/JointState",
        "tf2_msgs/msg/TFMessage",
        "rosgraph_msgs/msg/Clock",
        "gazebo_msgs/msg/ContactsState",
    ):
        assert by_type.get(type_name, 0) > 0, type_name
    stamps = [t for t, _m in messages(bus, "r1/imu")]
    assert stamps == list(range(0, 1_000_000_001, 10_000_000))  # 100 Hz, on the dot, from 0 to 1 s


# ------------------------------------------------------------------- local subscribers of fixed layouts
class ScanListener(Plugin):
    """A plugin of the same world that subscribes to the lidar's scan (published through a fixed layout)."""

    heard: ClassVar[list[tuple[int, Any]]] = []

    @classmethod
    def build(cls, params: Any, ctx: Any, name: str) -> list[Topic]:
        return [Topic("scan", "sensor_msgs/msg/LaserScan", "sub")]

    def setup(self) -> None:
        self.ctx.subscribe(
            "scan", "sensor_msgs/msg/LaserScan", lambda msg, t: ScanListener.heard.append((t, msg))
        )


def test_a_local_subscriber_gets_the_fixed_layout_messages_decoded(
    monkeypatch: pytest.MonkeyPatch, write_scenario: Any
) -> None:
    group = registry.GROUP
    builtin = list(registry.entry_points(group=group))
    extra = EntryPoint(name="scan_listener", value="tests.test_cdr:ScanListener", group=group)
    monkeypatch.setattr(registry, "entry_points", lambda group: [*builtin, extra])
    registry._entry_points.cache_clear()
    registry.load.cache_clear()
    ScanListener.heard.clear()
    try:
        path = write_scenario(
            """
            name: local
            duration: 0.5
            rate: max
            robots:
              - name: r1
                description: "{diffbot}"
                pose: {xyz: [0, 0, 0.06]}
                plugins:
                  - {type: lidar, params: {link: lidar_link, samples: 90, rate: 10}}
                  - {type: scan_listener}
            """
        )
        bus = MemoryBus()
        World(plan_of(path), bus).run()
    finally:
        registry._entry_points.cache_clear()
        registry.load.cache_clear()
    sent = [(t, m) for t, m in messages(bus, "r1/scan")]
    assert len(sent) == 6 and len(ScanListener.heard) == 6
    for (t1, a), (t2, b) in zip(sent, ScanListener.heard, strict=True):
        assert t1 == t2
        assert msgs.encode(a, "sensor_msgs/msg/LaserScan") == msgs.encode(b, "sensor_msgs/msg/LaserScan")


def _same_field(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray):
        return type(b) is np.ndarray and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True)
    if hasattr(a, "__dataclass_fields__"):
        return type(a) is type(b) and all(
            _same_field(getattr(a, f), getattr(b, f)) for f in a.__dataclass_fields__
        )
    if isinstance(a, list):
        return type(b) is list and len(a) == len(b) and all(map(_same_field, a, b))
    return type(a) is type(b) and a == b


def _peek_cases() -> list[tuple[str, Any]]:
    rng = np.random.default_rng(5)
    cases = []
    for frame in FRAMES:
        cases.append(
            ("sensor_msgs/msg/Imu", imu(12_345, frame, rng.normal(size=4), rng.normal(size=3), [0, 0, 9.8]))
        )
        cases.append(
            (
                "nav_msgs/msg/Odometry",
                odom(7, frame, frame[::-1] + "x", rng.normal(size=7), rng.normal(size=6)),
            )
        )
    for n in (0, 1, 3, 360):
        for k in (0, n):
            cases.append(("sensor_msgs/msg/LaserScan", scan(5, "r1/l", rng.random(n), rng.random(k))))
    cases.append(
        (
            "sensor_msgs/msg/JointState",
            joint_state(3, ["a", "bb"], np.array([1.0, 2.0]), np.array([0.5, 0.0]), np.zeros(0)),
        )
    )
    cases.append(("sensor_msgs/msg/JointState", joint_state(3, [], np.zeros(0), np.zeros(0), np.zeros(0))))
    cases.append(
        (
            "tf2_msgs/msg/TFMessage",
            tf(
                9, [("w", "r1/b"), ("r1/b", "r1/wheel_l"), ("x", "y")], [rng.normal(size=7) for _ in range(3)]
            ),
        )
    )
    cases.append(("tf2_msgs/msg/TFMessage", tf(9, [("w", "r1/b")], [rng.normal(size=7)])))
    cases.append(
        (
            "sensor_msgs/msg/NavSatFix",
            msgs.from_data(
                "sensor_msgs/msg/NavSatFix",
                {"header": {"frame_id": "g"}, "status": {"status": 2}, "latitude": 1.5},
            ),
        )
    )
    return cases


@pytest.mark.parametrize("type_name, msg", _peek_cases())
def test_peek_reads_each_field_as_rosbags_decodes_it(type_name: str, msg: Any) -> None:
    """`Peek` (what message triggers read of each message) gives every top-level field, alone or with
    others, exactly as the full decode does: same class, same type, same values; fields it cannot peek at
    (after a sequence of messages) fall back to the full decode."""
    payload = msgs.encode(msg, type_name)
    full = msgs.decode(payload, type_name)
    names = [n for n, _ in msgs.TYPESTORE.get_msgdef(type_name).fields]
    for i, name in enumerate(names):
        for fields in ([name], [names[0], name], names[i:]):
            peek = Peek(type_name, fields)
            got = peek.peek(payload)
            assert type(got) is type(full)
            for f in fields:
                assert _same_field(getattr(got, f), getattr(full, f)), (type_name, fields, f)
    assert not Peek("sensor_msgs/msg/Imu", ["linear_acceleration"]).full
    assert Peek("sensor_msgs/msg/Imu", ["no_such_field"]).full
    assert not Peek("tf2_msgs/msg/TFMessage", ["transforms"]).full


@pytest.mark.parametrize(
    "text", ["", "a", "ab", "abc", "abcd", '{"event": "x", "why": "héllo ✓"}', "x" * 1000]
)
def test_string_message_is_what_rosbags_encodes(text: str) -> None:
    """The events' record (`<run>/_events`, one per firing) is written without a message object."""
    assert string_message(text) == msgs.encode(T["std_msgs/msg/String"](data=text), "std_msgs/msg/String")
