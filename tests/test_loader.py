from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from runner.errors import ScenarioError
from runner.scenario.loader import load_file, load_text


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


@pytest.mark.parametrize(
    ("text", "pieces"),
    [
        ("a: !!python/object:os.system 1\n", [":1:4:", "cannot be read", "plain YAML"]),
        ("a: !!timestamp nope\n", [":1:4:", "'nope' cannot be read as !!timestamp"]),
        ("a: !!float abc\n", [":1:4:", "cannot be read as !!float"]),
        ("[" * 3000 + "]" * 3000 + "\n", [":1:65:", "nested more than 64 levels"]),
    ],
)
def test_values_yaml_cannot_build_are_errors_not_crashes(text: str, pieces: list[str]) -> None:
    with pytest.raises(ScenarioError) as e:
        load_text(text)
    rendered = e.value.render()
    for piece in pieces:
        assert piece in rendered, rendered


def test_dates_and_binary_stay_text() -> None:
    # Nothing in a scenario is a date: `2024-01-01` is kept as written, not turned into a datetime.date.
    assert load_text("a: 2024-01-01\nb: !!binary aGk=\n").data == {"a": "2024-01-01", "b": "aGk="}


@pytest.mark.parametrize(
    ("text", "line", "column", "words"),
    [
        ("name: x\nrobots: [\n  {a: 1},\n", 2, 9, "'[' is never closed"),
        ("name: x\nw: {a: [1, 2], b: 1\nc: 2\n", 2, 4, "'{' is never closed"),
        ("name: 'abc\n", 1, 7, "a quoted string is never closed"),
        ("name: x\n\tduration: 1\n", 2, 1, "a tab character"),
    ],
)
def test_yaml_syntax_errors_point_where_the_mistake_starts(
    text: str, line: int, column: int, words: str
) -> None:
    with pytest.raises(ScenarioError) as e:
        load_text(text)
    problem = e.value.problems[0]
    assert (problem.location.line, problem.location.column) == (line, column), problem.render()
    assert words in problem.message
    assert problem.hint


def test_the_terminal_prints_file_colon_line_as_written() -> None:
    """rich turns `:100:` into an emoji unless told not to: `world.sdf:100: ...` must stay as written."""
    from runner.cli import err, out

    for console in (out, err):
        with console.capture() as cap:
            console.print("warning: my_world.sdf:100: SDF <wind> ignored", markup=False)
            console.print("world.sdf:1:  warning:smile:")
        assert "my_world.sdf:100: SDF" in cap.get() and ":smile:" in cap.get()


def test_an_alias_bomb_is_refused_at_once_at_its_alias(tmp_path: Path) -> None:
    """A "billion laughs" YAML (a few hundred bytes, 9^9 values once aliases are expanded) is refused
    before it is built: in well under a second, with little memory, at the first alias."""
    import time
    import tracemalloc

    rows = ['a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for prev, name in zip("abcdefgh", "bcdefghi", strict=True):
        rows.append(f"{name}: &{name} [{','.join([f'*{prev}'] * 9)}]")
    path = tmp_path / "bomb.yaml"
    path.write_text("name: bomb\n" + "\n".join(rows) + "\n")
    t0 = time.process_time()  # CPU time: another run beside this one does not count against it
    with pytest.raises(ScenarioError) as err:
        load_file(path)
    seconds = time.process_time() - t0
    tracemalloc.start()
    with pytest.raises(ScenarioError):
        load_file(path)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert seconds < 2.0 and peak < 200e6, (seconds, peak)
    text = err.value.render()
    assert f"{path.resolve()}:3:8: aliases expand this YAML to more than" in text, text
    assert "hint:" in text


def test_size_and_nesting_limits_are_said_with_their_lines(tmp_path: Path) -> None:
    deep = tmp_path / "deep.yaml"
    deep.write_text("name: deep\nx: " + "[" * 100 + "]" * 100 + "\n")
    with pytest.raises(ScenarioError) as err:
        load_file(deep)
    assert "deep.yaml:2:" in err.value.render() and "nested more than 64 levels" in err.value.render()
    big = tmp_path / "big.yaml"
    big.write_text("name: big\ntimeline:\n" + "  - {t: 1, topic: a/b, type: std_msgs/msg/Empty}\n" * 100_000)
    with pytest.raises(ScenarioError) as err:
        load_file(big)
    assert "a scenario may be at most 4 MB" in err.value.render() and "hint:" in err.value.render()


def test_a_file_that_is_not_utf8_is_located_at_its_byte(tmp_path: Path) -> None:
    path = tmp_path / "latin1.yaml"
    path.write_bytes("name: x\ndescription: caf\xe9\n".encode("latin-1"))
    with pytest.raises(ScenarioError) as err:
        load_file(path)
    text = err.value.render()
    assert f"{path.resolve()}:2:17: not a UTF-8 text file: byte 0xe9" in text, text
    assert "hint:" in text
