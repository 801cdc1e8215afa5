"""Nothing lost under load or faults: unstable physics, killed processes, lost messages, a long run."""

from __future__ import annotations

import subprocess

import pytest

from tests.conftest import REPO, read_mcap, scenario_cmd

WOBBLY = REPO / "tests" / "data" / "unstable" / "wobbly.urdf"  # a hinge with negative damping: it blows up


@pytest.mark.timeout(60)
def test_unstable_physics_stops_the_run_naming_the_joint_and_keeps_the_recording(write_scenario, tmp_path):
    path = write_scenario(
        f"""
        name: wobble
        duration: 5
        rate: max
        robots:
          - {{name: w1, description: {WOBBLY}, pose: {{xyz: [0, 0, 0.1]}}, fixed: true}}
        """
    )
    mcap = tmp_path / "w.mcap"
    r = subprocess.run(
        scenario_cmd("run", str(path), "--record", str(mcap)), capture_output=True, text=True, timeout=50
    )
    assert r.returncode == 1, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    err = " ".join(r.stderr.split())
    assert "the physics went unstable between t = 0.4" in err
    assert "accelerations of joint w1/spin (robot w1)" in err and "smaller world.physics.timestep" in err
    clock = [t for topic, _type, t, _m in read_mcap(mcap) if topic == "wobble/clock"]
    assert clock and 0.4e9 <= clock[-1] <= 0.5e9  # everything up to the blow-up, nothing after


GAPPY_NODE = """
import os, struct, time
import zenoh
from runner import msgs
from runner.transport import encoding_for, make_config

run, endpoint = os.environ["SCENARIO_RUN"], os.environ["SCENARIO_ENDPOINT"]
with zenoh.open(make_config("client", connect=[endpoint])) as s:
    pub = s.declare_publisher(f"{run}/gappy", encoding=encoding_for("std_msgs/msg/String"))
    time.sleep(0.5)
    for seq in (0, 1, 3, 4):  # number 2 never arrives: lost on the way, as the recorder must tell
        pub.put(msgs.encode(msgs.from_data("std_msgs/msg/String", {"data": str(seq)}), "std_msgs/msg/String"),
                attachment=struct.pack("<Qq", seq, 0))
    time.sleep(0.5)
"""


@pytest.mark.timeout(60)
def test_strict_fails_a_run_that_lost_a_message_and_the_table_says_where(write_scenario, tmp_path) -> None:
    (tmp_path / "gappy.py").write_text(GAPPY_NODE)
    path = write_scenario(
        """
        name: gaps
        duration: 2.5
        rate: realtime
        nodes:
          - {name: gappy, cmd: python gappy.py}
        """
    )
    base = ["run", str(path), "--record", str(tmp_path / "g.mcap")]
    plain = subprocess.run(scenario_cmd(*base), capture_output=True, text=True, timeout=50)
    assert plain.returncode == 0, plain.stderr
    row = next(line for line in plain.stdout.splitlines() if "gaps/gappy" in line)
    cells = [c.strip() for c in row.split("│")[1:-1]]  # topic, type, published, recorded, rate, lost
    assert (cells[2], cells[3], cells[5]) == ("-", "4", "1"), row
    strict = subprocess.run(scenario_cmd(*base, "--strict"), capture_output=True, text=True, timeout=50)
    assert strict.returncode == 1, strict.stdout
    assert "--strict: 1 message(s) published but not recorded, on gaps/gappy" in " ".join(
        strict.stderr.split()
    )


def test_best_effort_topics_drop_and_every_other_topic_blocks() -> None:
    import zenoh

    from runner.transport import ZenohBus, make_config

    with zenoh.open(make_config("peer")) as session:
        bus = ZenohBus(session, best_effort=["run/*/camera/**"])
        bus.publisher("run/r1/camera/image", "sensor_msgs/msg/Image")
        bus.publisher("run/r1/scan", "sensor_msgs/msg/LaserScan")
        image, scan = bus._pubs
        assert image.congestion_control == zenoh.CongestionControl.DROP
        assert image.reliability == zenoh.Reliability.BEST_EFFORT
        assert scan.congestion_control == zenoh.CongestionControl.BLOCK
        assert scan.reliability == zenoh.Reliability.RELIABLE
        bus.undeclare_all()
