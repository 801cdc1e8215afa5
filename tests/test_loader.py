from __future__ import annotations

import textwrap

import pytest

from runner.errors import ScenarioError
from runner.loader import load_text


def test_positions_point_at_keys_and_items():
    doc = load_text(
        textwrap.dedent(
            """\
            name: x
            robots:
              - name: a
                plugins:
                  - type: lidar
                    params: {samples: 10}
            """
        )
    )
    assert doc.data["robots"][0]["plugins"][0]["params"]["samples"] == 10
    assert doc.locate(("robots",)).line == 2
    assert doc.locate(("robots", 0)).line == 3
    assert doc.locate(("robots", 0, "plugins", 0, "type")).line == 5
    assert doc.locate(("robots", 0, "plugins", 0, "params", "samples")).line == 6
    assert doc.locate(("robots", 0, "plugins", 0, "params", "samples")).column == 18
    # A path that does not exist falls back to its nearest ancestor.
    assert doc.locate(("robots", 0, "plugins", 0, "params", "nope")).line == 6


def test_duplicate_key_is_an_error_with_both_lines():
    with pytest.raises(ScenarioError) as e:
        load_text("name: a\nduration: 1\nname: b\n")
    text = e.value.render()
    assert ":3:1:" in text and "duplicate key 'name'" in text and "line 1" in text


def test_malformed_yaml_reports_line():
    with pytest.raises(ScenarioError) as e:
        load_text("name: a\nrobots: [\n  - x\n")
    assert "not valid YAML" in e.value.render()
    assert e.value.problems[0].location.line is not None


def test_anchors_and_merges_work():
    doc = load_text("a: &x {k: 1}\nb: *x\nc:\n  <<: *x\n  j: 2\n")
    assert doc.data == {"a": {"k": 1}, "b": {"k": 1}, "c": {"k": 1, "j": 2}}


def test_empty_document():
    assert load_text("").data == {}
