"""Bad scenarios exit 1 with file:line, the scenario path, what was expected/found, and no traceback.

The one-mistake scenario cases live in tests/bad_inputs/ (tests/test_bad_input_corpus.py); here: the real
console script, and bad robot descriptions.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from runner.cli import app
from tests.conftest import run_cli

# The scenario cases that were here are files in tests/bad_inputs/ now (tests/test_bad_input_corpus.py).

BROKEN_URDF = """\
<?xml version="1.0"?>
<robot name="b">
  <link name="base_link"/>
  <joint name="j" type="revolute">
    <parent link="base_link"/><child link="ghost"/>
  </joint>
</robot>
"""


@pytest.mark.timeout(60)
def test_real_console_script_exits_1_without_traceback(tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("name: x\nrobots:\n  - name: r1\n    descripton: a.urdf\n")
    for verb in ("validate", "run"):
        proc = run_cli(verb, str(path))
        assert proc.returncode == 1, proc.stderr
        assert "Traceback" not in proc.stderr + proc.stdout
        assert f"{path}:4:5: robots[0].descripton: unknown key" in proc.stderr
        assert "did you mean 'description'" in proc.stderr


# Bad robot descriptions: each error names the file and line that caused it and gives a hint.
MESH_URDF = """<?xml version="1.0"?>
<robot name="m">
  <link name="base_link">
    <collision><geometry><mesh filename="{uri}"/></geometry></collision>
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
</robot>
"""

SYNTAX_XACRO = """<?xml version="1.0"?>
<robot name="s" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="w" value="1"/>
  <link name="base_link">
    <visual><geometry><box size="1 1 1"/></geometry>
  </link>
</robot>
"""

UNKNOWN_PLUGIN_URDF = """<?xml version="1.0"?>
<robot name="u">
  <link name="base_link">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <gazebo>
    <plugin name="x" filename="libgazebo_ros_teleporter.so"/>
  </gazebo>
</robot>
"""

DESCRIPTION_CASES = [
    # (id, files, command, substrings)
    (
        "missing_package",
        {"r.urdf": MESH_URDF.format(uri="package://ghost_description/meshes/base.stl")},
        "validate",
        ["r.urdf:4:", "package 'ghost_description' not found", "hint:", "searched"],
    ),
    (
        "missing_mesh",
        {"r.urdf": MESH_URDF.format(uri="meshes/nothing_here.stl")},
        "validate",
        ["r.urdf:4:", "nothing_here.stl", "not found", "hint:"],
    ),
    (
        "xacro_syntax_error",
        {"r.urdf.xacro": SYNTAX_XACRO},
        "validate",
        ["r.urdf.xacro:6:", "not well-formed", "mismatched tag", "hint:"],
    ),
    (
        "unknown_plugin_filename",
        {"r.urdf": UNKNOWN_PLUGIN_URDF},
        "validate",
        ["warning:", "r.urdf:7:", "libgazebo_ros_teleporter.so", "not supported", "hint:"],
    ),
    (
        "joint_missing_link",
        {"r.urdf": BROKEN_URDF},
        "validate",
        ["r.urdf:5:", "ghost", "not defined", "hint:", "defined links: base_link"],
    ),
]


@pytest.mark.parametrize(
    ("case", "files", "verb", "expect"), DESCRIPTION_CASES, ids=[c[0] for c in DESCRIPTION_CASES]
)
def test_bad_description(
    tmp_path: Path, case: str, files: dict[str, str], verb: str, expect: list[str]
) -> None:
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    robot = next(iter(files))
    path = tmp_path / "s.yaml"
    path.write_text(f"name: x\nrobots:\n  - name: r1\n    description: {robot}\n")
    result = CliRunner().invoke(app, [verb, str(path)])
    output = result.output
    assert "Traceback" not in output
    if case == "unknown_plugin_filename":
        assert result.exit_code == 0, output  # a warning, never fatal
    else:
        assert result.exit_code == 1, output
    for piece in expect:
        assert piece in output, f"{piece!r} not in:\n{output}"


# Seven independent mistakes of seven kinds, one per line, in an order the checks do not run in (the
# schema's own first, then compile's): one `validate` says all seven, in the file's order.
SEVEN = """\
name: seven
duration: 10
nodes:
  - {name: n1, cmd: "no_such_program_here --x"}
robots:
  - name: r1
    description: "{diffbot}"
    plugins:
      - {type: diff_drvie}
      - {type: lidar, params: {samples: many}}
  - name: r2
    description: "{diffbot}"
    pose: {xyz: [1, 2], rpy: [0, 0, 0]}
timeline:
  - {t: 1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {xx: 1}}}
bridges:
  - {ros_topic: /cmd, topic: r2/cmd_vel, type: geometry_msgs/msg/Twis, direction: ZENOH_TO_SIM}
assertions:
  - {name: a, type: reach, robot: r3, point: [1, 0], tolerance: 0.2, by: 8}
  - {name: b, type: message, topic: r1/odom, expr: "pose.pose.position.x >> 1"}
  - {name: c, type: reach, robot: r2, point: [1, 0], tolerance: 0.2, by: 8}
"""


@pytest.mark.timeout(60)
def test_every_independent_mistake_is_said_in_one_pass_in_line_order(write_scenario) -> None:
    path = write_scenario(SEVEN)
    proc = run_cli("validate", str(path))
    assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
    said = [ln for ln in proc.stderr.splitlines() if ln.startswith(f"{path}:")]
    expected = [
        (4, "nodes[0].cmd: command 'no_such_program_here' not found"),
        (9, "robots[0].plugins[0].type: unknown plugin type 'diff_drvie'"),
        (10, "robots[0].plugins[1].params.samples: wrong value"),
        (13, "robots[1].pose.xyz: expected 3 items, found 2"),
        (15, "timeline[0].data.linear.xx: geometry_msgs/msg/Vector3 has no field 'xx'"),
        (17, "bridges[0].type: unknown message type 'geometry_msgs/msg/Twis'"),
        (19, "assertions[0].robot: no robot named 'r3'"),
        (20, "assertions[1].expr: in `pose.pose.position.x >> 1` (column 22): the operator '>>'"),
    ]
    assert len(said) == len(expected), proc.stderr
    for (line, text), got in zip(expected, said, strict=True):
        assert got.startswith(f"{path}:{line}:") and text in got, (line, text, got)
    assert proc.stderr.startswith(f"error: {len(expected)} problems:"), proc.stderr


@pytest.mark.timeout(60)
def test_what_follows_from_a_refused_robot_is_not_reported(write_scenario) -> None:
    """A robot the schema refuses is taken out for the rest of the checks: an assertion or bridge on it is
    not reported as naming an unknown robot or topic, while a later item's mistake still is, at its own
    path (indexes past the refused item map back to the file)."""
    path = write_scenario(
        """
        name: refused
        duration: 5
        robots:
          - {name: r0, descripton: "{diffbot}"}
          - {name: r1, description: "{diffbot}", plugins: [{type: lidar, params: {samples: many}}]}
        bridges:
          - {topic: r0/cmd_vel, type: geometry_msgs/msg/Twist, direction: ZENOH_TO_SIM}
        assertions:
          - {name: a, type: reach, robot: r0, point: [1, 0], tolerance: 0.2}
          - {name: b, type: topic_rate, topic: r0/odom, min: 5}
        """
    )
    proc = run_cli("validate", str(path))
    assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
    said = [ln for ln in proc.stderr.splitlines() if ln.startswith(f"{path}:")]
    assert len(said) == 2, proc.stderr
    assert said[0].startswith(f"{path}:4:") and "robots[0].descripton: unknown key" in said[0]
    assert said[1].startswith(f"{path}:5:") and "robots[1].plugins[0].params.samples" in said[1]


@pytest.mark.timeout(60)
def test_checks_that_stop_early_say_so(write_scenario) -> None:
    """A mistake that makes later checks meaningless stops them, and the message says what waits."""
    cases = {
        "name: x\nrobots: [\n": "(nothing else is checked until the file reads as YAML)",
        "name: x\nrobots:\n  - {name: r1, description: a.urdf}\n  - {name: r1, description: a.urdf}\n": (
            "(robots, plugins, the timeline and the rest are checked once these are fixed)"
        ),
    }
    for k, (text, note) in enumerate(cases.items()):
        path = write_scenario(text, name=f"case{k}.yaml")
        proc = run_cli("validate", str(path))
        assert proc.returncode == 1 and "Traceback" not in proc.stderr, proc.stderr
        assert proc.stderr.rstrip().endswith(note), proc.stderr


# Names: the one meant, whatever the case or typo, and what there is when nothing is close.
def test_did_you_mean_names_the_closest_or_lists_what_there_is() -> None:
    from runner.errors import closest, did_you_mean

    assert closest("R1", ["r1", "r2"]) == "r1"  # case first
    assert closest("left_wheel_jiont", ["left_wheel_joint", "right_wheel_joint"]) == "left_wheel_joint"
    assert closest("zzz", ["r1", "r2"]) is None
    assert did_you_mean("rover_1", ["rover1", "walker"], "robots") == "did you mean 'rover1'?"
    assert did_you_mean("zzz", ["b", "a"], "robots") == "robots: a, b"
    assert did_you_mean("zzz", [], "actors") == "there are no actors to name here"
    many = did_you_mean("zzz", [f"n{k:02}" for k in range(30)], "topics")
    assert many.startswith("topics: n00, n01") and many.endswith("(30 in all)")


# Zenoh endpoints: Zenoh's configuration takes any text; these are what the run would refuse when it opens them.
@pytest.mark.parametrize(
    ("endpoint", "listen", "said"),
    [
        ("tcp/127.0.0.1:70000", True, "port 70000 is out of range (0-65535)"),
        ("tcp/127.0.0.1:0", False, "port 0 is out of range (1-65535)"),
        ("tcp/127.0.0.1", True, "no port"),
        ("tcp/[::1]", False, "no port"),
        ("tcp/:7447", True, "no address"),
        ("tcp/127.0.0.1:x", True, "the port 'x' is not a number"),
        ("tpc/127.0.0.1:7447", True, "unknown Zenoh protocol 'tpc': write tcp/127.0.0.1:7447"),
        ("tcp/300.0.0.1:7447", True, "'300.0.0.1' is not an IPv4 address"),
        ("tcp/[::1:7447", True, "an IPv6 address goes in brackets"),
        ("127.0.0.1:7447", True, "write it with its protocol, e.g. tcp/127.0.0.1:7447"),
    ],
)
def test_a_bad_zenoh_endpoint_is_said(endpoint: str, listen: bool, said: str) -> None:
    from runner.scenario.schema.network import endpoint_error

    error = endpoint_error(endpoint, listen)
    assert error is not None and said in error, error
    assert ": write " in error  # the fix, which the error's hint says


@pytest.mark.parametrize(
    "endpoint",
    [
        "tcp/127.0.0.1:7447",
        "tcp/[::1]:7447",
        "tls/localhost:7447",
        "udp/10.0.0.2:7447",
        "quic/127.0.0.1:7447",
        "ws/127.0.0.1:8000",
        "tcp/127.0.0.1:7447#iface=lo",
        "tcp/127.0.0.1:7447?prio=1",
        "unixsock-stream//tmp/zenoh.sock",
        "serial//dev/ttyUSB0#baudrate=115200",
    ],
)
def test_good_zenoh_endpoints_pass(endpoint: str) -> None:
    from runner.scenario.schema.network import endpoint_error

    assert endpoint_error(endpoint, listen=False) is None
    assert endpoint_error(endpoint, listen=True) is None
    assert endpoint_error("tcp/127.0.0.1:0", listen=True) is None  # any free port


@pytest.mark.timeout(60)
def test_a_record_folder_without_permission_is_said_by_validate(write_scenario) -> None:
    """/proc/1 takes no new files, for root too (procfs refuses them, whatever the permissions say):
    a recording there used to be found out only when the run started."""
    path = write_scenario("name: x\nrecord: {path: /proc/1/runs/x.mcap}\n")
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 1, result.output
    assert (
        f"{path}:2:" in result.output and "record.path: the recording '/proc/1/runs/x.mcap'" in result.output
    )
    assert "no permission to write in '/proc/1'" in result.output and "hint:" in result.output
    assert not Path("/proc/1/runs").exists()
    # ... while a folder to be made (several levels), a folder given with a trailing '/' and an existing file
    # pass, and `validate` makes none of them
    (path.parent / "old.mcap").write_bytes(b"")
    for k, given in enumerate(["deep/er/x.mcap", "outs/", "old.mcap"]):
        ok = write_scenario(f"name: x\nrecord: {{path: {given}}}\n", name=f"s{k}.yaml")
        result = CliRunner().invoke(app, ["validate", str(ok)])
        assert result.exit_code == 0, result.output
    assert not (path.parent / "deep").exists() and not (path.parent / "outs").exists()


@pytest.mark.timeout(120)
def test_run_refuses_an_unwritable_record_path_before_it_starts_unless_it_records_nothing(
    write_scenario,
) -> None:
    path = write_scenario("name: x\nduration: 0.2\nrecord: {path: /proc/1/runs/x.mcap}\n")
    refused = run_cli("run", str(path), timeout=60)
    assert refused.returncode == 1 and f"{path}:3:" in refused.stderr, refused.stderr
    assert "record.path" in refused.stderr and "running x" not in refused.stderr, refused.stderr
    unrecorded = run_cli("run", str(path), "--no-record", timeout=100)
    assert unrecorded.returncode == 0, unrecorded.stderr


@pytest.mark.timeout(60)
def test_node_scripts_are_found_as_the_launcher_finds_them(write_scenario, tmp_path: Path) -> None:
    """The node-script check resolves commands as the launcher does (runner/launch/nodes.py: Popen of the
    argv in the node's cwd): of these, only the one whose script is not there is refused."""
    (tmp_path / "ok.py").write_text("")
    (tmp_path / "okmod.py").write_text("")
    (tmp_path / "ok.sh").write_text("")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "inner.py").write_text("")
    path = write_scenario(
        """
        name: x
        nodes:
          - {name: a, cmd: python -c pass}
          - {name: b, cmd: python -m json.tool}
          - {name: c, cmd: python ./ok.py --rate 3}
          - {name: d, cmd: [python, -u, ok.py]}
          - {name: e, cmd: python -W ignore ok.py}
          - {name: f, cmd: python -m okmod}
          - {name: g, cmd: bash ok.sh}
          - {name: h, cmd: python, args: [ok.py]}
          - {name: i, cmd: python inner.py, cwd: sub}
          - {name: j, cmd: python ok.py, cwd: sub}
        """
    )
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 1, result.output
    said = [ln for ln in result.output.splitlines() if ln.startswith(("error: /", "/"))]
    assert len(said) == 1 and f"{path}:12:" in said[0], result.output
    assert "nodes[9].cmd: script 'ok.py' not found" in said[0], result.output


@pytest.mark.timeout(60)
def test_a_missing_script_is_said_where_it_is_written(write_scenario, tmp_path: Path) -> None:
    """In `args:` (its index there), in a `cmd:` list (its index), for bash as for Python."""
    path = write_scenario(
        """
        name: x
        nodes:
          - {name: a, cmd: python, args: [-u, gone.py]}
          - {name: b, cmd: [bash, gone.sh]}
        """
    )
    result = CliRunner().invoke(app, ["validate", str(path)])
    assert result.exit_code == 1, result.output
    assert f"{path}:3:" in result.output and "nodes[0].args[1]: script 'gone.py' not found" in result.output
    assert f"{path}:4:" in result.output and "nodes[1].cmd[1]: script 'gone.sh' not found" in result.output
