"""A message from another process larger than a plugin takes (8 MiB by default) is dropped before it is
decoded or queued, counted and reported with its reason like a NaN command (tests/test_nonfinite.py), and the
robot obeys the next command. In-process (a world stepped with MemoryBus) and in a real run with a stray
Zenoh session."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from runner.plugin import MAX_INBOUND_BYTES, too_large
from runner.wire.transport import encoding_for
from tests.conftest import read_mcap, scenario_cmd
from tests.test_nonfinite import DRIVE, TWIST, _join, _world, twist

TOO_LARGE = too_large(MAX_INBOUND_BYTES)
# a Twist (linear.x = 5) followed by 9 MiB of zeros: without the bound, decoded (and refused for its
# trailing bytes) at the world's next boundary, its reason then its size's
BIG = twist(5.0) + bytes(9 * 1024 * 1024)


def test_the_default_bound_and_its_reason_say_8_mib() -> None:
    assert MAX_INBOUND_BYTES == 8 * 1024 * 1024
    assert TOO_LARGE == "more than the 8 MiB limit for a message a plugin takes"


def test_an_oversized_command_is_dropped_before_decoding_and_the_next_one_is_obeyed(write_scenario) -> None:
    world, bus = _world(write_scenario, "big", 2.0)
    key = "big/r1/cmd_vel"
    truth: list[tuple[int, float]] = []
    world.listen("big/r1/ground_truth", "nav_msgs/msg/Odometry",
                 lambda m, t: truth.append((t, m.twist.twist.linear.x)))  # fmt: skip
    bus.inject(key, twist(0.3))
    sent = {"big": False, "next": False}

    def later(now_ns: int) -> None:
        if now_ns >= 500_000_000 and not sent["big"]:
            sent["big"] = True
            bus.inject(key, BIG)
            assert world._inbox.empty()  # dropped on arrival, never queued
        if now_ns >= 1_000_000_000 and not sent["next"]:
            sent["next"] = True
            bus.inject(key, twist(-0.2))

    from runner.sim.schedule import Hook

    world._after.append(Hook(later, 100_000_000))
    stats = world.run()
    assert stats.error is None
    assert stats.rejected == {key: {TOO_LARGE: 1}}
    at = dict(truth)
    assert 0.25 < at[950_000_000] < 0.35  # kept through the oversized one
    assert -0.25 < at[1_950_000_000] < -0.15  # the next command, obeyed


@pytest.mark.timeout(150)
def test_an_oversized_command_put_by_another_session_in_a_real_run_is_dropped_and_reported(
    write_scenario, tmp_path: Path
) -> None:
    """A stray Zenoh client puts 9 MiB on <run>/r1/cmd_vel, then a good Twist: the end table, stderr and
    the recording's metadata say the size reason; the robot drives as the good command says."""
    from mcap.reader import make_reader

    from runner.wire.transport import free_port

    port = free_port()
    path = write_scenario(DRIVE.format(name="big", duration=4, rate=1))
    mcap = tmp_path / "big.mcap"
    cmd = scenario_cmd("run", str(path), "--no-judge", "--listen", f"tcp/127.0.0.1:{port}",
                       "--record", str(mcap))  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        session = _join(port, "big")
        try:
            pub = session.declare_publisher("big/r1/cmd_vel", encoding=encoding_for(TWIST))
            pub.put(BIG)
            pub.put(twist(0.3))
            pub.undeclare()
        finally:
            session.close()
        out, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 0, out + err
    text = " ".join(out.split())
    assert f"rejected: 1 message(s) on big/r1/cmd_vel: {TOO_LARGE}" in text, out
    said = " ".join(err.split())
    assert f"big/r1/cmd_vel: a message of {len(BIG):,} bytes, more than the 8 MiB limit" in said, err
    with mcap.open("rb") as f:
        notes = {m.name: dict(m.metadata) for m in make_reader(f).iter_metadata()}
    rejected = json.loads(notes["scenario"]["rejected"])["big/r1/cmd_vel"]
    assert rejected[TOO_LARGE] == 1, rejected  # (the recorder says too that it did not record it)
    assert not any("do not decode" in why and "not recorded" not in why for why in rejected), rejected
    # the recorder neither decodes it (a valid 96 MB one would hold its callback for seconds) nor records it
    assert not any("do not decode" in why for why in rejected), rejected
    truth = [m for topic, _, _t, m in read_mcap(mcap) if topic == "big/r1/ground_truth"]
    assert abs(truth[-1].twist.twist.linear.x - 0.3) < 0.05, truth[-1].twist.twist


def test_a_plugin_may_ask_for_a_larger_bound_in_its_subscription(write_scenario) -> None:
    """`ctx.subscribe(..., max_bytes=...)`: 9 MiB reach the decoder on that key (here refused for what it
    is, not for its size); the default bound still holds on the drive's key."""
    world, bus = _world(write_scenario, "asks", 0.2)
    got: list[object] = []
    world._subscriber_factory("r1")("map", TWIST, lambda m, t: got.append(m), max_bytes=16 * 1024 * 1024)
    bus.inject("asks/r1/map", BIG)
    bus.inject("asks/r1/cmd_vel", BIG)
    stats = world.run()
    assert stats.rejected["asks/r1/cmd_vel"] == {TOO_LARGE: 1}
    assert list(stats.rejected["asks/r1/map"]) == [f"{len(BIG)} bytes that do not decode as {TWIST}"]
