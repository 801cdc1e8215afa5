"""Large legitimate inputs are read, and the limits that refuse the rest count what they say they count:
a long plain timeline, a URDF with thousands of links, a mesh of millions of triangles (issue 35, point 4).
The timed claims (a 20,000-entry timeline in under 5 s...) are measured by `python -m bench --only limits`;
the bounds here are generous, to catch a return to quadratic time without failing on a loaded machine."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from runner.errors import ScenarioError
from runner.scenario.loader import MAX_ALIAS_VALUES, load_file, load_text

REPO = Path(__file__).resolve().parents[1]
DIFFBOT = REPO / "scenarios" / "robots" / "diffbot.urdf.xacro"


def timeline_scenario(entries: int) -> str:
    """A scenario with one diff-drive robot and `entries` timeline entries, written out (no anchors)."""
    rows = [
        "name: long_timeline",
        "duration: 30.0",
        "robots:",
        "  - name: r1",
        f"    description: {{file: {DIFFBOT}}}",
        "    pose: {xyz: [0, 0, 0.06]}",
        "    plugins:",
        "      - {type: diff_drive, params: {rate: 50}}",
        "timeline:",
    ]
    rows += [
        f"  - {{t: {i * 0.001:.3f}, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, "
        f"data: {{linear: {{x: {0.1 + (i % 7) * 0.01:.2f}}}, angular: {{z: {(i % 5) * 0.1:.1f}}}}}}}"
        for i in range(entries)
    ]
    return "\n".join(rows) + "\n"


# ------------------------------------------------------------------------------------------------ YAML
def test_plain_values_are_not_counted_as_alias_values() -> None:
    """200,000 values written out (no alias) are read: the alias limit counts what aliases produce."""
    doc = load_text("name: many\nvalues: [" + ", ".join(str(i % 10) for i in range(200_000)) + "]\n")
    assert len(doc.data["values"]) == 200_000
    assert doc.locate(("values", 199_999)).line == 2


def test_aliases_past_the_limit_are_refused_at_the_first_alias() -> None:
    """An anchor of 1,000 values used 101 times expands to more than MAX_ALIAS_VALUES: refused, at the
    first `*`, however few bytes the file has."""
    text = "name: x\nbase: &b [" + ", ".join(["1"] * 1000) + "]\nmany:\n" + "  - *b\n" * 101
    t0 = time.process_time()
    with pytest.raises(ScenarioError) as err:
        load_text(text)
    assert time.process_time() - t0 < 5.0
    rendered = err.value.render()
    assert f"<scenario>:4:5: aliases expand this YAML to more than {MAX_ALIAS_VALUES} values" in rendered
    # ...and under the limit they load, each use its own copy
    doc = load_text(text.replace("  - *b\n" * 101, "  - *b\n" * 99))
    assert len(doc.data["many"]) == 99 and doc.data["many"][0] is not doc.data["many"][1]


def test_merge_keys_take_the_anchors_keys_and_the_mappings_own_win() -> None:
    doc = load_text("base: &b {k: 1, j: 1}\nc:\n  j: 2\n  <<: *b\nd:\n  <<: [*b, {m: 3}]\n  k: 4\n")
    assert doc.data["c"] == {"j": 2, "k": 1} and doc.data["d"] == {"k": 4, "j": 1, "m": 3}
    assert doc.locate(("c", "k")).line == 1 and doc.locate(("d", "k")).line == 7


def test_a_20000_entry_timeline_validates(tmp_path: Path) -> None:
    """Read, checked by the schema and compiled (each entry's message data checked) - the whole of
    `scenario validate`. It was refused as an alias bomb after 14 s; now ~2 s of CPU (bench: limits)."""
    from runner.compile import load_plan

    path = tmp_path / "long.yaml"
    path.write_text(timeline_scenario(20_000))
    t0 = time.process_time()
    plan = load_plan(load_file(path))
    seconds = time.process_time() - t0
    assert len(plan.timeline) == 20_000
    assert plan.timeline[-1].data == {"linear": {"x": 0.1 + (19_999 % 7) * 0.01}, "angular": {"z": 0.4}}
    assert seconds < 30.0, seconds  # quadratic (or the pure-Python parser) would be far past this
