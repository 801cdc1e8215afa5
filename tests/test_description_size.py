"""A description file (URDF, xacro and each file it includes, SDF) larger than 16 MiB is refused before it
is read or parsed, with its file, the scenario path that loads it and a hint: a xacro file with a 50 MB
attribute once took 109 s to be refused. Each file here is a valid description padded past the bound with
blanks (without the bound, each validates); each is refused in seconds."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from runner.compile.filesize import MAX_DESCRIPTION_BYTES
from tests.conftest import run_cli

URDF = '<robot name="big"><link name="base"><inertial><mass value="1"/>' \
    '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>\n'  # fmt: skip
XACRO = '<robot name="big" xmlns:xacro="http://www.ros.org/wiki/xacro">\n  <xacro:include filename="part.xacro"/>\n</robot>\n'
PART = '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="base"><inertial><mass value="1"/>' \
    '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>\n'  # fmt: skip
SDF = '<?xml version="1.0"?>\n<sdf version="1.7"><world name="w"></world></sdf>\n'


def _padded(path: Path, text: str, size: int) -> Path:
    """`text` then comments up to `size` bytes: still the same valid description (in lines of 1 KB:
    libxml2 refuses a single text run past 10 MB of its own)."""
    line = "<!--" + "x" * 1017 + "-->\n"
    rest = size - len(text)
    with path.open("w") as f:
        f.write(text)
        f.write(line * (rest // len(line)))
        f.write(" " * (rest % len(line)))
    return path


def _validate(tmp_path: Path, robot: str, world: str = "") -> tuple[str, float]:
    scenario = tmp_path / "s.yaml"
    scenario.write_text(f"name: s\nduration: 1.0\n{world}robots:\n  - {{name: r1, description: {robot}}}\n")
    start = time.monotonic()
    proc = run_cli("validate", str(scenario), timeout=120)
    took = time.monotonic() - start
    text = " ".join(proc.stderr.split())
    assert proc.returncode == 1, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr
    return text, took


@pytest.mark.parametrize("size", [MAX_DESCRIPTION_BYTES + 1])
def test_a_urdf_past_the_bound_is_refused_before_it_is_parsed(tmp_path: Path, size: int) -> None:
    _padded(tmp_path / "big.urdf", URDF, size)
    text, took = _validate(tmp_path, "big.urdf")
    assert f"big.urdf: big.urdf is {size:,} bytes, more than the 16 MiB a description file may be" in text, (
        text
    )
    assert "robots[0].description" in text and "keep meshes in mesh files" in text, text
    assert took < 20, took


def test_a_urdf_at_the_bound_is_read(tmp_path: Path) -> None:
    """The bound is the file's size: one at it is read (and validates)."""
    _padded(tmp_path / "big.urdf", URDF, MAX_DESCRIPTION_BYTES)
    scenario = tmp_path / "s.yaml"
    scenario.write_text("name: s\nduration: 1.0\nrobots:\n  - {name: r1, description: big.urdf}\n")
    proc = run_cli("validate", str(scenario), timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_a_xacro_include_past_the_bound_is_refused_at_its_include_line(tmp_path: Path) -> None:
    (tmp_path / "big.xacro").write_text(XACRO)
    _padded(tmp_path / "part.xacro", PART, MAX_DESCRIPTION_BYTES + 1)
    text, took = _validate(tmp_path, "big.xacro")
    assert f"big.xacro:2: part.xacro is {MAX_DESCRIPTION_BYTES + 1:,} bytes, more than the 16 MiB" in text, (
        text
    )
    assert "robots[0].description" in text and "keep meshes in mesh files" in text, text
    assert took < 20, took


def test_an_sdf_world_past_the_bound_is_refused_before_it_is_parsed(tmp_path: Path) -> None:
    _padded(tmp_path / "big.sdf", SDF, MAX_DESCRIPTION_BYTES + 1)
    _padded(tmp_path / "r.urdf", URDF, len(URDF))
    text, took = _validate(tmp_path, "r.urdf", "world: {sdf: big.sdf}\n")
    assert f"big.sdf is {MAX_DESCRIPTION_BYTES + 1:,} bytes, more than the 16 MiB" in text, text
    assert "keep meshes in mesh files" in text, text
    assert took < 20, took


def test_one_value_past_the_xml_readers_10_mb_says_so(tmp_path: Path) -> None:
    """Under the file bound, one attribute of 11 MB: libxml2 refuses it ("Buffer size limit exceeded, try
    XML_PARSE_HUGE"), which is no syntax mistake: the hint says what the limit is and what to do."""
    big = '<robot name="big"><link name="base"/><gazebo><x a="' + "x" * 11_000_000 + '"/></gazebo></robot>\n'
    (tmp_path / "big.urdf").write_text(big)
    out, _ = _validate(tmp_path, "big.urdf")
    assert "big.urdf:1: not well-formed XML: Resource limit exceeded" in out, out
    assert "more than 10 MB, the most the XML reader takes" in out, out
    assert "Traceback" not in out
