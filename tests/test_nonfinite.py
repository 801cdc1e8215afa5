"""A NaN or Inf never reaches the physics: commands holding one are dropped before any plugin (counted, in
the end table, the recording's metadata and the results; `--strict` fails the run), scenario data holding
one is a located error, a control that a plugin makes NaN stops the run naming it, and a publisher outside
the run is named with its count. Real runs on real Zenoh, and worlds stepped in-process (real MuJoCo)."""

from __future__ import annotations

import json
import math
import re
import subprocess
import threading
import time
from pathlib import Path

import mujoco
import pytest

from runner.sim.pubsub import NONFINITE
from runner.wire import msgs
from runner.wire.transport import MemoryBus, encoding_for
from tests.conftest import run_cli, scenario_cmd
from tests.helpers import plan_of

TWIST = "geometry_msgs/msg/Twist"


def twist(x: float, z: float = 0.0) -> bytes:
    return msgs.encode(msgs.from_data(TWIST, {"linear": {"x": x}, "angular": {"z": z}}), TWIST)


DRIVE = """
    name: {name}
    duration: {duration}
    rate: {rate}
    robots:
      - {{name: r1, description: "{{diffbot}}", pose: {{xyz: [0, 0, 0.06]}},
          plugins: [{{type: diff_drive}}, {{type: ground_truth, params: {{rate: 20}}}}]}}
    """


def _world(write_scenario, name: str, duration: float) -> tuple[object, MemoryBus]:
    from runner.sim.world import World

    bus = MemoryBus()
    return World(plan_of(write_scenario(DRIVE.format(name=name, duration=duration, rate="max"))), bus), bus


def test_a_nan_command_is_dropped_before_the_drive_and_the_next_one_is_obeyed(write_scenario) -> None:
    """In-process: a good command, then a NaN one, then another good one, each from "another process" (the
    bus's inbox). The NaN one is counted and never reaches diff_drive: the robot drives at the first
    command, then at the last (without the check, the NaN stayed in the drive's integral for good and the
    robot stopped obeying)."""
    world, bus = _world(write_scenario, "inproc", 3.0)
    key = "inproc/r1/cmd_vel"
    truth: list[tuple[int, float]] = []
    world.listen("inproc/r1/ground_truth", "nav_msgs/msg/Odometry",
                 lambda m, t: truth.append((t, m.twist.twist.linear.x)))  # fmt: skip
    bus.inject(key, twist(0.3))
    sent = {"nan": False, "next": False}

    def later(now_ns: int) -> None:
        if now_ns >= 1_000_000_000 and not sent["nan"]:
            sent["nan"] = True
            bus.inject(key, twist(math.nan))
        if now_ns >= 1_500_000_000 and not sent["next"]:
            sent["next"] = True
            bus.inject(key, twist(-0.2))

    from runner.sim.schedule import Hook

    world._after.append(Hook(later, 100_000_000))
    stats = world.run()
    assert stats.error is None
    assert stats.rejected == {key: {NONFINITE: 1}}
    at = dict(truth)
    assert 0.25 < at[1_000_000_000] < 0.35  # the first command
    assert 0.25 < at[1_450_000_000] < 0.35  # kept through the NaN
    assert -0.25 < at[2_950_000_000] < -0.15  # the next command, obeyed


def test_a_control_a_plugin_makes_nan_stops_the_run_naming_actuator_robot_and_time(write_scenario) -> None:
    """diff_drive's wheel-speed integral holding a NaN (what a NaN command once left there): its control is
    NaN. The world stops before the physics takes it, naming the actuator, the robot and the sim time
    (MuJoCo alone would zero every control of the world and go on)."""
    world, _bus = _world(write_scenario, "inner", 1.0)
    drive = world.plugins[0]
    from runner.sim.schedule import Hook

    def poison(now_ns: int) -> None:
        if now_ns >= 400_000_000:
            drive.integral[1] = math.nan

    world._after.append(Hook(poison, 100_000_000))
    stats = world.run()
    assert stats.error is not None
    assert (
        "actuator 'r1/diff_drive/right' of robot r1 was given a control of nan at t = 0.400 s" in stats.error
    )
    assert "Hint:" in stats.error
    assert stats.sim_ns == 400_000_000  # stopped there: nothing stepped with it


def test_a_huge_command_is_clamped_below_mujocos_limit_and_the_robot_recovers(write_scenario, capfd) -> None:
    """1e300 is finite (not dropped): the control it makes is clamped to 1e10, where MuJoCo would warn and
    zero every control of the world for that step; the next command is obeyed."""
    world, bus = _world(write_scenario, "huge", 2.0)
    key = "huge/r1/cmd_vel"
    truth: list[tuple[int, float]] = []
    world.listen("huge/r1/ground_truth", "nav_msgs/msg/Odometry",
                 lambda m, t: truth.append((t, m.twist.twist.linear.x)))  # fmt: skip
    bus.inject(key, twist(1e300))
    from runner.sim.schedule import Hook

    def later(now_ns: int) -> None:
        if now_ns == 500_000_000:
            bus.inject(key, twist(0.2))

    world._after.append(Hook(later, 100_000_000))
    stats = world.run()
    assert stats.error is None and not stats.rejected
    err = capfd.readouterr().err
    assert re.search(r"actuator 'r1/diff_drive/left' of robot r1 was given a control of \S+e\+30\d", err), err
    assert "clamped to ±1e+10" in err
    assert int(world.data.warning[mujoco.mjtWarning.mjWARN_BADCTRL].number) == 0
    assert 0.15 < dict(truth)[1_950_000_000] < 0.25


@pytest.mark.parametrize(
    ("value", "where", "found"),
    [(".nan", "timeline[1].data.linear.x", "nan"), ("-.inf", "timeline[1].data.linear.x", "-inf")],
)
def test_nan_or_inf_in_timeline_data_is_a_located_error(write_scenario, value, where, found) -> None:
    """YAML's .nan and .inf were taken (the plan's JSON made them null: a silent 0.0 in the world)."""
    path = write_scenario(
        DRIVE.format(name="tl", duration=2, rate="max")
        + f"""
    timeline:
      - {{t: 0.5, topic: r1/cmd_vel, type: geometry_msgs/Twist, data: {{linear: {{x: 0.2}}}}}}
      - t: 1.0
        topic: r1/cmd_vel
        type: geometry_msgs/Twist
        data:
          linear: {{x: {value}}}
    """
    )
    proc = run_cli("validate", str(path))
    assert proc.returncode == 1, proc.stdout
    text = " ".join(proc.stderr.split())
    line = next(i for i, text in enumerate(path.read_text().splitlines(), 1) if value in text)
    text = " ".join(proc.stderr.split())
    assert f"{path}:{line}:" in text and f"{where}: a message field must be a finite number" in text, text
    assert f"found: {found}" in text and "hint:" in text and "Traceback" not in proc.stderr


def test_nan_in_an_events_published_message_is_a_located_error(write_scenario) -> None:
    path = write_scenario(
        DRIVE.format(name="ev", duration=2, rate="max")
        + """
    events:
      - name: kick
        when: {at: 0.5}
        do:
          - publish: {topic: r1/cmd_vel, type: geometry_msgs/Twist, data: {angular: {z: .inf}}}
    """
    )
    proc = run_cli("validate", str(path))
    assert proc.returncode == 1, proc.stdout
    text = " ".join(proc.stderr.split())
    assert re.search(
        r"events\[0\]\.do\[0\]\.publish\.data\.angular\.z: a message field must be a finite", text
    ), text
    line = next(i for i, text in enumerate(path.read_text().splitlines(), 1) if ".inf" in text)
    assert f"{path}:{line}:" in text


def _join(port: int, run: str, deadline_s: float = 40.0):
    """A Zenoh session of the test's own (outside the run) on the run's router, once the world ticks."""
    import zenoh

    from runner.wire.transport import make_config

    session = None
    deadline = time.monotonic() + deadline_s
    while session is None and time.monotonic() < deadline:
        try:
            session = zenoh.open(make_config("client", connect=[f"tcp/127.0.0.1:{port}"]))
        except zenoh.ZError:
            time.sleep(0.1)
    assert session is not None, "the run's router never listened"
    ticking = threading.Event()
    clock = session.declare_subscriber(f"{run}/clock", lambda _s: ticking.set())
    if not ticking.wait(deadline_s):
        session.close()
        raise AssertionError("the world did not start")
    clock.undeclare()
    return session


@pytest.mark.timeout(150)
def test_a_nan_put_by_another_session_in_a_real_run_is_dropped_reported_and_fails_strict(
    write_scenario, tmp_path: Path
) -> None:
    """The issue's case, in a real run: a stray Zenoh client puts one Twist with linear.x = NaN on
    <run>/r1/cmd_vel, then a good one (and a burst of 2000 more of those). The robot drives as the good
    command says (read back from the MCAP); the end table and the recording's metadata count 1 rejected
    message on that topic and name the stray session (its Zenoh id, and the ROS node its liveliness token
    says) with its count; --strict exits 1."""
    from mcap.reader import make_reader

    from runner.wire.transport import free_port

    port = free_port()
    path = write_scenario(DRIVE.format(name="stray", duration=6, rate=1))
    mcap = tmp_path / "stray.mcap"
    results = tmp_path / "results.json"
    cmd = scenario_cmd("run", str(path), "--no-judge", "--strict", "--listen", f"tcp/127.0.0.1:{port}",
                       "--record", str(mcap), "--results-json", str(results))  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        session = _join(port, "stray")
        try:
            zid = str(session.zid())
            # what an rmw_zenoh node declares for itself (rmw_zenoh_cpp liveliness_utils.cpp: domain, zid,
            # node id, entity id, NN, enclave, namespace, name; "/" written "%")
            node = session.liveliness().declare_token(f"@ros2_lv/0/{zid}/0/0/NN/%/%robots/teleop_stray")
            pub = session.declare_publisher("stray/r1/cmd_vel", encoding=encoding_for(TWIST))
            pub.put(twist(math.nan))
            pub.put(twist(0.3))
            for _ in range(2000):
                pub.put(twist(0.3))
            pub.undeclare()
            node.undeclare()
        finally:
            session.close()
        out, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 1, out + err
    text = " ".join(out.split())
    assert "rejected: 1 message(s) on stray/r1/cmd_vel: NaN or Inf values" in text, out
    assert (
        "recorded 2002 message(s) on stray/r1/cmd_vel, 2002 from a publisher outside the run "
        f"(ROS node /robots/teleop_stray, zid {zid} from tcp/127.0.0.1:"
    ) in text, out
    assert text.count("outside:") == 1, out  # (the world's own topics carry the run's attachment)
    assert "--strict: 1 message(s) rejected, on stray/r1/cmd_vel" in " ".join(err.split())
    assert "stray/r1/cmd_vel at t = " in err and "linear.x is nan" in err
    with mcap.open("rb") as f:
        reader = make_reader(f)
        notes = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
    assert json.loads(notes["scenario"]["rejected"]) == {"stray/r1/cmd_vel": {NONFINITE: 1}}
    outside = json.loads(notes["scenario"]["outside"])
    assert outside["messages"] == {"stray/r1/cmd_vel": 2002} and zid in outside["from"][0]
    said = json.loads(results.read_text())
    assert said["properties"]["rejected.stray/r1/cmd_vel"] == f"1 {NONFINITE}"
    assert said["properties"]["outside.stray/r1/cmd_vel"] == "2002" and not said["passed"]
    # the robot obeyed the good command: it drives at 0.3 m/s to the end, and moved well over a metre
    from tests.conftest import read_mcap

    truth = [(t, m) for topic, _, t, m in read_mcap(mcap) if topic == "stray/r1/ground_truth"]
    assert abs(truth[-1][1].twist.twist.linear.x - 0.3) < 0.05, truth[-1][1].twist.twist
    assert truth[-1][1].pose.pose.position.x - truth[0][1].pose.pose.position.x > 1.0
