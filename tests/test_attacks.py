"""Hostile inputs beyond a scenario's own checks: names that are markup, terminal escapes or XML poison,
on every way out (terminal, JUnit XML)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from typer.testing import CliRunner

from runner.checks.judge import Result
from runner.cli import app
from runner.cli.results import print_results
from runner.tools.report import Suite, write_junit

# markup rich would parse (a closing tag it cannot match: MarkupError), a link, terminal escapes (clear the
# screen, set the window title), a bidirectional override, and characters XML 1.0 cannot hold
HOSTILE = "a [/x] [link=https://example.org]b[/link] \x1b[2J\x1b]0;pwn\x07 \u202eevil \x01\ufffe ]]> <c>"


def _result(name: str) -> Result:
    return Result(name, "stay_within", "fail", 1_000_000_000, "(1.000, 0.000)", "inside the region", "out")


def test_an_assertion_named_like_markup_is_printed_as_it_is(capsys: pytest.CaptureFixture[str]) -> None:
    print_results([_result(HOSTILE)])  # raised rich's MarkupError (a traceback at the run's very end)
    text = capsys.readouterr().out
    assert "\x1b" not in text and "\u202e" not in text and "\x07" not in text  # shown, not obeyed
    assert "a [/x] [link=https://example.org]b[/link] \\x1b[2J\\x1b]0;pwn\\x07 \\u202eevil" in text


def test_a_recording_with_a_hostile_topic_is_listed(tmp_path: Path) -> None:
    from mcap.writer import Writer

    mcap = tmp_path / "evil.mcap"
    with mcap.open("wb") as f:
        w = Writer(f)
        w.start("ros2", "test")
        schema = w.register_schema("std_msgs/msg/String", "ros2msg", b"string data")
        channel = w.register_channel(HOSTILE, "cdr", schema)
        for t in (0, 1_000_000_000):
            w.add_message(channel, t, b"\x00\x01\x00\x00\x01\x00\x00\x00\x00", t)
        w.finish()
    result = CliRunner().invoke(app, ["info", str(mcap)])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == 0, result.output
    assert "\x1b" not in result.output
    assert "[/x]" in result.output and "\\x1b[2J" in result.output


def test_junit_xml_of_hostile_names_is_well_formed(tmp_path: Path) -> None:
    path = tmp_path / "junit.xml"
    suite = Suite(HOSTILE.replace(" ", "_"), [_result(HOSTILE)], error=f"node said: {HOSTILE}")
    write_junit(path, [suite])
    root = ET.parse(path).getroot()  # control characters made the whole file unreadable
    names = [case.get("name") for case in root.iter("testcase")]
    assert (
        "a [/x] [link=https://example.org]b[/link] \\x1b[2J\\x1b]0;pwn\\x07 \u202eevil \\x01\\ufffe ]]> <c>"
        in (names)
    )
    assert "\\x01" in (root.find("testsuite/testcase/error").text or "")


@pytest.mark.timeout(60)
def test_a_stray_publisher_naming_a_new_type_each_time_is_said_a_bounded_number_of_times(
    capfd: pytest.CaptureFixture[str],
) -> None:
    """Another session names a different (escape-laden) type in each sample on a world's command key: the
    world's reasons, stderr lines and counts stay bounded and show the escapes instead of obeying them."""
    import time

    import zenoh

    from runner.wire.transport import MAX_REASONS, OTHER_REASONS, ZenohBus, free_port, make_config

    port = free_port()
    key = "attack/r1/cmd_vel"
    delivered: list[bytes] = []
    with zenoh.open(make_config("peer", listen=[f"tcp/127.0.0.1:{port}"])) as world:
        bus = ZenohBus(world)
        bus.subscribe(key, lambda _k, payload, _a: delivered.append(payload), "geometry_msgs/msg/Twist")
        with zenoh.open(make_config("peer", connect=[f"tcp/127.0.0.1:{port}"])) as stray:
            pub = stray.declare_publisher(key)
            deadline = time.monotonic() + 30
            while not pub.matching_status.matching and time.monotonic() < deadline:
                time.sleep(0.02)  # the world's subscription has reached the stray session
            n = 200
            for i in range(n):
                encoding = zenoh.Encoding.APPLICATION_CDR.with_schema(f"x\x1b]0;pwn{i}\x07\x1b[2J/msg/T{i}")
                pub.put(b"\x00\x01\x00\x00" + bytes(48), encoding=encoding)
            while sum(bus.rejected.get(key, {}).values()) < n and time.monotonic() < deadline:
                time.sleep(0.02)
    counts = bus.rejected[key]
    assert sum(counts.values()) == n and not delivered
    assert len(counts) == MAX_REASONS + 1 and counts[OTHER_REASONS] == n - MAX_REASONS  # was 200 kinds
    err = capfd.readouterr().err
    said = [line for line in err.splitlines() if line.startswith("world: dropping messages on")]
    assert len(said) == MAX_REASONS + 1, err  # was a line per sample
    assert "\x1b" not in err and "\x07" not in err and "x\\x1b]0;pwn0\\x07\\x1b[2J/msg/T0" in err


RECORDS_TO = """
name: records_to
duration: 0.3
robots:
  - name: r1
    description: {file: "{diffbot}"}
    pose: {xyz: [0, 0, 0.06]}
record: {path: home/notes}
"""


@pytest.mark.timeout(120)
def test_a_scenario_recording_into_a_users_folder_overwrites_and_removes_nothing_of_theirs(
    write_scenario, tmp_path: Path
) -> None:
    """`record.path` names a user's file: it is not overwritten (it was, with MCAP bytes). Recording into a
    folder clears only stale locks of recordings: a user's `.notes.lock` and the short `notes` beside it,
    `..npmrc.lock` and `.npmrc`, were removed as if they were a killed run's."""
    from tests.conftest import run_cli

    home = tmp_path / "home"
    home.mkdir()
    theirs = {"notes": b"todo\n", ".notes.lock": b"", ".npmrc": b"k=v\n", "..npmrc.lock": b""}
    for name, content in theirs.items():
        (home / name).write_bytes(content)
    # a run from before lock files said whose they are, killed: its empty lock and empty recording go
    (home / ".old.mcap.lock").write_bytes(b"")
    (home / "old.mcap").write_bytes(b"")
    r = run_cli("run", str(write_scenario(RECORDS_TO)), "--no-judge", "-q", timeout=100)
    assert r.returncode == 1, r.stderr[-2000:]
    assert "Traceback" not in r.stderr
    assert f"cannot write the recording {home / 'notes'}" in r.stderr or "home/notes" in r.stderr, r.stderr
    assert "exists and is not an MCAP recording: it is not overwritten" in r.stderr, r.stderr
    assert {p.name: p.read_bytes() for p in home.iterdir()} == {
        **theirs,
        ".old.mcap.lock": b"",
        "old.mcap": b"",
    }
    r = run_cli(
        "run", str(write_scenario(RECORDS_TO.replace("home/notes", "home/new.mcap"))), "--no-judge", "-q"
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert {p.name: p.read_bytes() for p in home.iterdir() if p.name != "new.mcap"} == theirs


def test_a_recording_is_never_written_over_a_device(tmp_path: Path) -> None:
    from runner.record.claim import refuse_foreign

    with pytest.raises(FileExistsError, match="not a regular file"):
        refuse_foreign(Path("/dev/null"))
    refuse_foreign(tmp_path / "new.mcap")  # (not there: fine)
    (tmp_path / "empty.mcap").write_bytes(b"")
    refuse_foreign(tmp_path / "empty.mcap")
    (tmp_path / "cut.mcap").write_bytes(b"\x89MCAP0\r\n" + bytes(100))
    refuse_foreign(tmp_path / "cut.mcap")  # a recording of an earlier run: written over, as always


@pytest.mark.timeout(60)
def test_validate_reads_no_more_of_an_endless_file_than_a_scenario_may_hold() -> None:
    # /dev/zero is no regular file (its size says 0): it was read whole, to a MemoryError at 3.4 GB
    result = CliRunner().invoke(app, ["validate", "/dev/zero"])
    assert result.exit_code == 1 and "Traceback" not in result.output
    assert "/dev/zero:1:1: this file goes on past 4 MB, the most a scenario may be" in result.output


@pytest.mark.timeout(120)
def test_a_damaged_recording_is_reported_as_damaged_without_a_traceback(
    write_scenario, tmp_path: Path
) -> None:
    from tests.conftest import run_cli

    mcap = tmp_path / "run.mcap"
    scenario = write_scenario(RECORDS_TO.replace("home/notes", str(mcap)).replace("0.3", "1.0"))
    assert run_cli("run", str(scenario), "--no-judge", "-q").returncode == 0
    data = mcap.read_bytes()
    mcap.write_bytes(data[: len(data) // 2])  # cut mid-record (a copy cut short, a disk gone bad)
    result = CliRunner().invoke(app, ["report", str(mcap), "-o", str(tmp_path / "r.html")])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == 1, result.output
    assert f"error: {mcap}: cannot read it as MCAP: " in " ".join(result.output.split())


LIDAR = """
name: big_lidar
duration: 1
robots:
  - name: r1
    description: {file: "{diffbot}"}
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: lidar, params: {link: lidar_link, samples: 100000000}}
"""


def test_a_lidar_of_a_hundred_million_beams_is_refused_where_it_is_written(write_scenario) -> None:
    # it passed validate, and the run's world ended in a MemoryError traceback (3.2 GB at a 4 GB limit)
    path = write_scenario(LIDAR)
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 1 and "Traceback" not in result.output
    text = " ".join(result.output.split())
    assert f"{path}:8:" in text and "robots[0].plugins[0].params: 100000000 x 1 = 100,000,000 beams" in text


def test_a_link_in_a_description_folder_reads_nothing_outside_and_says_where_it_points(
    tmp_path: Path,
) -> None:
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "parts.xacro").write_text(
        '<?xml version="1.0"?><robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:property name="w" value="0.5"/></robot>'
    )
    desc = tmp_path / "scenario" / "pkg" / "urdf"
    desc.mkdir(parents=True)
    (desc / "linked").symlink_to(outside)
    (desc / "robot.xacro").write_text(
        '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        '  <xacro:include filename="linked/parts.xacro"/>\n'
        '  <link name="base_link"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>\n</robot>\n'
    )
    scenario = tmp_path / "scenario" / "s.yaml"
    scenario.write_text("name: s\nduration: 1\nrobots:\n  - {name: r1, description: pkg/urdf/robot.xacro}\n")
    result = CliRunner().invoke(app, ["validate", str(scenario)])
    assert result.exit_code == 1, result.output
    text = " ".join(result.output.split())
    assert (
        f"robot.xacro:3: {desc / 'linked' / 'parts.xacro'} (a link to {outside / 'parts.xacro'}) is outside"
        in text
    ), text


@pytest.mark.timeout(90)
def test_a_stray_session_putting_on_thousands_of_keys_is_told_in_twenty_lines(tmp_path: Path) -> None:
    """A stray session put one message on each of 20,000 keys of its own under the run: 20,000 'outside:'
    lines in the end table and 20,000 results properties. The recorder counts 1000 keys apart, the rest
    together; the table and the results name the 19 busiest and fold the others into one line."""
    import time
    from types import SimpleNamespace

    import zenoh

    from runner.launch.parts import OUTSIDE_SHOWN, outside_of
    from runner.record import Recorder
    from runner.record.recorder import OTHER_KEYS, OUTSIDE_KEYS
    from runner.wire.transport import free_port, make_config

    port = free_port()
    n = OUTSIDE_KEYS + 500
    recorder = Recorder(tmp_path / "run.mcap", ["**"])
    with zenoh.open(make_config("peer", listen=[f"tcp/127.0.0.1:{port}"])) as run_session:
        recorder.subscribe(run_session, "run/**")
        with zenoh.open(make_config("peer", connect=[f"tcp/127.0.0.1:{port}"])) as stray:
            probe = stray.declare_publisher("run/probe")
            deadline = time.monotonic() + 30
            while not probe.matching_status.matching and time.monotonic() < deadline:
                time.sleep(0.02)  # the recorder's subscription has reached the stray session
            for _ in range(3):
                probe.put(b"x")  # the busiest key
            for i in range(n):
                stray.put(f"run/junk{i:05d}", b"\x00\x01\x00\x00" + bytes(8))
            while sum(recorder.outside.values()) < n + 3 and time.monotonic() < deadline:
                time.sleep(0.02)
        recorder.close()
    assert sum(recorder.outside.values()) == n + 3
    assert len(recorder.outside) == OUTSIDE_KEYS + 1 and recorder.outside[OTHER_KEYS] == n + 1 - OUTSIDE_KEYS
    counts, _who = outside_of(SimpleNamespace(recorder=SimpleNamespace(recorder=recorder)))
    assert len(counts) == OUTSIDE_SHOWN and sum(counts.values()) == n + 3
    assert counts["run/probe"] == 3
    assert counts[f"more than {OUTSIDE_KEYS - (OUTSIDE_SHOWN - 1)} other keys"] == n + 3 - 3 - (
        OUTSIDE_SHOWN - 2
    )


def test_a_refused_origin_is_said_with_its_escapes_shown(capsys: pytest.CaptureFixture[str]) -> None:
    # a client that is no browser sends any bytes as its Origin; the runner said them to its terminal as is
    from runner.launch.live import _say_refused

    _say_refused("http://evil.example\x1b]0;pwned\x07\x1b[2J")
    err = capsys.readouterr().err
    assert "\x1b" not in err and "origin http://evil.example\\x1b]0;pwned\\x07\\x1b[2J: not an allowed" in err


LOUD_NODE = """
name: loud
duration: 0.5
robots:
  - name: r1
    description: {file: "{diffbot}"}
    pose: {xyz: [0, 0, 0.06]}
nodes:
  - name: loud
    cmd: python loud.py
"""


@pytest.mark.timeout(120)
def test_a_node_writing_megabytes_without_a_newline_is_shown_cut(write_scenario, tmp_path: Path) -> None:
    """Its output was read a line at a time, however long: 800 MB without a newline took the runner to
    2.6 GB. A line is shown up to 64 KiB and the rest counted."""
    from runner.launch.nodes import LINE_MAX
    from tests.conftest import run_cli

    (tmp_path / "loud.py").write_text(
        "import sys\nsys.stdout.write('x' * 4_000_000 + '\\nafter\\n')\nsys.stdout.flush()\n"
    )
    r = run_cli("run", str(write_scenario(LOUD_NODE)), "--no-judge", "--no-record", timeout=100)
    assert r.returncode == 0, r.stderr[-2000:]
    lines = r.stderr.splitlines()
    shown = next(line for line in lines if line.startswith("[loud] xxx"))
    assert len(shown) == len("[loud] ") + LINE_MAX
    assert f"[loud] (the line above went on for {4_000_000 - LINE_MAX + 1} more bytes, not shown)" in lines
    assert "[loud] after" in lines
