"""`scenario validate` says what matters first: warnings of one kind (a tag ignored in every sensor, every
timeline entry to a topic nothing takes) are one line with how many more and where; those that change what
the run does (a command that reaches nothing, next to what the drive listens on; a drive scaled by its
declared wheels) lead; `--all` says every one, `--json` keeps every one with its kind, and `--strict` still
fails on the scenario's own warnings."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from runner.errors import DRIVE_GEOMETRY, TAG_IGNORED, UNSUBSCRIBED, kind_of
from tests.conftest import run_cli
from tests.test_gazebo_parity import CLASSIC_DRIVE, diffbot

# the drive listens on r1/diff_cont/cmd_vel_unstamped (as a ros2_control launch remaps it) and declares
# its wheels 0.40 m apart, while its joints are 0.34 m apart
DRIVE = CLASSIC_DRIVE.replace(
    "<update_rate>50</update_rate>",
    "<update_rate>50</update_rate><ros><remapping>cmd_vel:=diff_cont/cmd_vel_unstamped</remapping></ros>",
).replace("<wheel_separation>0.34<", "<wheel_separation>0.40<")

SENSORS = 5
IMUS = "".join(
    f"""
  <gazebo reference="base_link">
    <sensor name="imu{i}" type="imu">
      <visualize>true</visualize>
      <update_rate>50</update_rate>
      <topic>imu{i}</topic>
    </sensor>
  </gazebo>"""
    for i in range(SENSORS)
)

COMMANDS = 6
SCENARIO = """name: t
duration: 1
rate: max
robots:
  - name: r1
    description: robot.urdf
    pose: {xyz: [0, 0, 0.1]}
timeline:
""" + "".join(
    f"  - {{t: {0.1 * (i + 1):.1f}, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {{linear: {{x: 0.1}}}}}}\n"
    for i in range(COMMANDS)
)


@pytest.fixture
def noisy(tmp_path: Path) -> Path:
    (tmp_path / "robot.urdf").write_text(diffbot(DRIVE, extra=IMUS))
    path = tmp_path / "scenario.yaml"
    path.write_text(SCENARIO)
    return path


def _said(proc: object) -> str:
    return " ".join(proc.stderr.split())  # type: ignore[attr-defined]  # (rich wraps long lines)


@pytest.mark.timeout(120)
def test_repeated_warnings_are_one_line_per_kind_and_all_says_every_one(noisy: Path) -> None:
    proc = run_cli("validate", str(noisy))
    assert proc.returncode == 0, proc.stderr
    text = _said(proc)
    assert text.count("<visualize> in <sensor") == 1, text
    assert f"(and {SENSORS - 1} more: " in text, text
    assert text.count("publishes on 'r1/cmd_vel'") == 1, text
    # the first command's line said whole, the others' after it
    lines = [i + 1 for i, line in enumerate(SCENARIO.splitlines()) if "topic: r1/cmd_vel" in line]
    assert f"scenario.yaml:{lines[0]}: timeline[0] publishes on 'r1/cmd_vel'" in text, text
    assert f"(and {COMMANDS - 1} more: {', '.join(map(str, lines[1:]))})" in text, text
    assert f"{COMMANDS + SENSORS + 1} warning(s), said once per kind" in text, text
    assert "--all" in text
    every = _said(run_cli("validate", str(noisy), "--all"))
    assert every.count("<visualize> in <sensor") == SENSORS, every
    assert every.count("publishes on 'r1/cmd_vel'") == COMMANDS, every
    assert "more: " not in every
    assert every.count("warning: ") == COMMANDS + SENSORS + 1
    # grouping is how they are printed, not what they count: --strict fails on each of the scenario's own
    strict = run_cli("validate", str(noisy), "--strict")
    assert strict.returncode == 1
    assert f"--strict: {COMMANDS} warning(s) about the scenario are errors" in strict.stderr
    assert "Traceback" not in strict.stderr


@pytest.mark.timeout(120)
def test_what_changes_the_run_is_said_first_with_what_the_drive_listens_on(noisy: Path) -> None:
    text = _said(run_cli("validate", str(noisy)))
    lead = text.index("what changes the run")
    command = text.index("timeline[0] publishes on 'r1/cmd_vel', which nothing in the run subscribes to")
    scaled = text.index("wheel_separation 0.400 m, but its wheel joints are 0.340 m apart")
    rest = text.index("the rest:")
    ignored = text.index("<visualize> in <sensor")
    assert lead < command < scaled < rest < ignored, text
    # the line that matters says where the commands should go
    said = text[command : text.index("hint:", command)]
    assert "diff_drive 'diff_drive' listens on 'r1/diff_cont/cmd_vel_unstamped'" in said, said


@pytest.mark.timeout(120)
def test_json_keeps_every_warning_with_its_kind(noisy: Path) -> None:
    proc = run_cli("validate", str(noisy), "--json")
    assert proc.returncode == 0, proc.stderr
    plan = json.loads(proc.stdout)
    items = plan["notice_items"]
    assert [n["text"] for n in items] == plan["notices"]  # every one, ungrouped, in order
    kinds = [n["kind"] for n in items]
    assert kinds.count(UNSUBSCRIBED) == COMMANDS
    assert {n["about"] for n in items if n["kind"] == UNSUBSCRIBED} == {"t/r1/cmd_vel"}
    assert kinds.count(DRIVE_GEOMETRY) == 1
    visualize = [n for n in items if n["kind"] == TAG_IGNORED and n["about"] == "<visualize>"]
    assert len(visualize) == SENSORS and all(
        n["file"].endswith("robot.urdf") and n["line"] for n in visualize
    )


def test_a_kind_is_the_message_with_what_varies_taken_out() -> None:
    a = kind_of("<always_on> in <sensor name='imu' type='imu'> is ignored (sensors are always on)")
    b = kind_of('<visualize> in <sensor name="cam" type="camera"> is ignored (sensors are always on)')
    assert a == b == "… in … is ignored (sensors are always on)"
    c = kind_of(
        "diff_drive_controller/DiffDriveController 'base': `publish_cmd` is not one of its parameters"
    )
    assert c == kind_of(
        "diff_drive_controller/DiffDriveController 'x': `use_sim_time` is not one of its parameters"
    )
    assert kind_of("link 'a': mass 0.001 kg") == kind_of("link 'b': mass 12 kg") != c


@pytest.mark.timeout(120)
def test_run_says_what_changes_the_run_at_its_start(noisy: Path) -> None:
    """`scenario run` says the warnings that change the run, grouped, and only how many the others are."""
    proc = run_cli("run", str(noisy), "--no-record", "--no-judge", timeout=100)
    assert proc.returncode == 0, proc.stderr
    text = _said(proc)
    start = text[: text.index("running t")]
    assert start.count("publishes on 'r1/cmd_vel'") == 1, start
    assert f"(and {COMMANDS - 1} more: " in start
    assert "listens on 'r1/diff_cont/cmd_vel_unstamped'" in start
    assert "<visualize>" not in start  # (validate lists those)
    assert f"{COMMANDS + SENSORS + 1} warning(s): `scenario validate` lists them" in start


def test_the_others_of_a_kind_are_said_by_line_and_what_names_them_apart() -> None:
    """A typo'd tag in each of four plugins: the others' lines with their tags; one line said several
    times (a macro expanded for each wheel) once, with how many; another file's path where it changes."""
    from runner.cli.notices import more_text
    from runner.plan import NoticePlan

    def notice(tag: str, line: int, file: str = "a.xacro") -> NoticePlan:
        return NoticePlan(message=f"<{tag}> is not a parameter of 'libx.so'", file=file, line=line)

    first = notice("topicName", 24)
    more = [notice("topic_name_twist", 29), notice("x", 30), notice("x", 30), notice("y", 3, "b.xacro")]
    assert more_text(first, more) == "(and 4 more: 29 <topic_name_twist>, 30 <x> (x2), b.xacro:3 <y>)"
    assert more_text(first, [first] * 12, shown=8) == "(and 12 more: 24 (x12))"
