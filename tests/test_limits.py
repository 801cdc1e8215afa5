"""Large legitimate inputs are read, and the limits that refuse the rest count what they say they count:
a long plain timeline, a URDF with thousands of links, a mesh of millions of triangles (issue 35, point 4).
The timed claims (a 20,000-entry timeline in under 5 s...) are measured by `python -m bench --only limits`;
the bounds here are generous, to catch a return to quadratic time without failing on a loaded machine."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from bench.limits import (
    chain_urdf,
    random_triangles,
    sphere_triangles,
    timeline_scenario,
    write_obj,
    write_stl,
)
from runner.errors import ScenarioError
from runner.scenario.loader import MAX_ALIAS_VALUES, load_file, load_text


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


def test_an_alias_inside_its_own_anchor_is_located() -> None:
    with pytest.raises(ScenarioError) as err:
        load_text("name: x\nloop: &a [1, *a]\n")
    rendered = err.value.render()
    assert "<scenario>:2:14: this is not valid YAML: found an alias inside its own anchor 'a'" in rendered
    assert "hint:" in rendered


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


# ------------------------------------------------------------------------------------------------ URDF
def validate(tmp_path: Path, urdf: str, timeout: float = 120.0) -> tuple[int, str, float]:
    """`scenario validate` of a one-robot scenario around `urdf`, in its own process: (exit code, output,
    peak resident MB)."""
    from bench.limits import validate_measured

    (tmp_path / "robot.urdf").write_text(urdf)
    scenario = tmp_path / "s.yaml"
    scenario.write_text(
        "name: big\nduration: 1.0\nrobots:\n  - name: r1\n    description: {file: robot.urdf}\n"
        "    pose: {xyz: [0, 0, 0.1]}\n"
    )
    got = validate_measured(scenario, timeout=timeout)
    assert got["code"] != "timeout", f"validate ran past {timeout} s"
    return got["code"], " ".join(got["out"].split()), got["peak_mb"]


def test_a_10000_link_chain_is_refused_at_once_at_the_joint_past_mujocos_depth(tmp_path: Path) -> None:
    """MuJoCo compiles no tree deeper than 1023 bodies; it found that out after minutes (printing nothing
    for 300 s at 2.1 GB with 10,000 links). Now: the joint whose child is the 1024th link, named in the
    URDF, at once."""
    code, out, peak = validate(tmp_path, chain_urdf(10_000))
    assert code == 1 and "Traceback" not in out, out
    line = (
        chain_urdf(10_000)
        .splitlines()
        .index(next(x for x in chain_urdf(10_000).splitlines() if '"j1023"' in x))
    )
    assert f"robot.urdf:{line + 1}: the chain of links from 'l0' to 'l9999' is 10000 links deep" in out, out
    assert "at most 1023 bodies deep" in out and "hint:" in out
    assert peak < 2048, peak


def test_3000_links_on_fixed_joints(tmp_path: Path) -> None:
    """All on one link (a star): they are welded together, so neither MuJoCo nor Gazebo collides them -
    no contact exclusion is made (there were 4.5 M); MuJoCo's broad phase still overflows its default
    arena, which is raised, with a warning. As a chain: past MuJoCo's depth, refused at its line."""
    code, out, peak = validate(tmp_path, chain_urdf(3000, "fixed", star=True))
    assert code == 0 and "Traceback" not in out, out
    assert "MuJoCo's memory for this world raised to" in out and peak < 2048, peak
    code, out, _ = validate(tmp_path, chain_urdf(3000, "fixed"))
    assert code == 1 and "Traceback" not in out and "robot.urdf:" in out and "links deep" in out, out


def test_contact_exclusions_are_made_only_where_mujoco_does_not_filter() -> None:
    """Gazebo's no-self-collision rule: links welded together (fixed joints) and links joined by a joint
    are left out by MuJoCo itself (same weld; its parent filter) and get no exclusion (300 links on fixed
    joints made 44,551); any other pair of links that may move against each other does."""
    from runner.compile.packages import PackageMap
    from runner.compile.urdf.reader import urdf_to_model

    packages = PackageMap.for_scenario(Path.cwd(), {})
    welded = urdf_to_model(chain_urdf(300, "fixed", star=True), None, packages).spec.compile()
    assert welded.nexclude == 0
    hinged = urdf_to_model(chain_urdf(300), None, packages).spec.compile()
    assert hinged.nexclude == 300 * 299 // 2 - 299


# ---------------------------------------------------------------------------------------------- meshes
def test_a_binary_stl_over_the_budget_is_simplified_with_a_warning_at_its_urdf_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The budget lowered to 5,000 triangles (the mechanism of a 5 M-triangle mesh against 1 M, which the
    bench measures): a 20,000-triangle sphere is simplified to at most 5,000, keeps its size, and the
    warning names the URDF line and how to simplify it."""
    import os
    import subprocess
    import sys

    import numpy as np

    from runner.compile.meshes import prepare_mesh

    write_stl(tmp_path / "ball.stl", sphere_triangles(20_000))
    (tmp_path / "robot.urdf").write_text(chain_urdf(2, mesh="ball.stl"))
    (tmp_path / "s.yaml").write_text(
        "name: m\nduration: 1.0\nrobots:\n  - name: r1\n    description: {file: robot.urdf}\n"
        "    pose: {xyz: [0, 0, 0.5]}\n"
    )
    env = {**os.environ, "SCENARIO_MAX_MESH_TRIANGLES": "5000", "XDG_CACHE_HOME": str(tmp_path / "cache")}
    proc = subprocess.run(
        [sys.executable, "-m", "runner.cli", "validate", "s.yaml"],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
        env=env,
    )
    out = " ".join((proc.stdout + proc.stderr).split())
    assert proc.returncode == 0 and "Traceback" not in out, out
    assert f"warning: {tmp_path / 'robot.urdf'}:3: collision mesh 'ball.stl' has 20000 triangles, over" in out
    assert "the budget of 5000: simplified to" in out and "Quadric Edge Collapse" in out, out
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.setenv("SCENARIO_MAX_MESH_TRIANGLES", "5000")
    prepared = prepare_mesh(tmp_path / "ball.stl")
    assert prepared.simplified == 20000 and 1000 < prepared.triangles <= 5000
    assert np.allclose(prepared.extent, (0.2, 0.2, 0.2), atol=0.01)


def test_an_obj_over_the_budget_is_refused_before_it_is_parsed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from runner.compile.meshes import MeshError, prepare_mesh

    monkeypatch.setenv("SCENARIO_MAX_MESH_TRIANGLES", "5000")
    write_obj(tmp_path / "ball.obj", sphere_triangles(20_000))
    with pytest.raises(MeshError) as err:
        prepare_mesh(tmp_path / "ball.obj")
    assert "20000 triangles, over the budget of 5000" in str(err.value)
    assert "export it as binary STL" in (err.value.hint or "")


def test_random_triangles_are_simplified_within_bounds() -> None:
    """No structure to keep: the grid gets coarse, the result is small and still a mesh."""
    from runner.compile.meshes import simplify

    corners = random_triangles(50_000).reshape(-1, 3).astype("<f4")
    vertices, faces = simplify(corners, 2000)
    assert 0 < len(faces) <= 2000 and faces.max() < len(vertices)


def test_too_many_exclusions_are_a_located_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """Past MAX_EXCLUDES (lowered here: 3,000 hinged links on one link would need 4.5 M), the robot is
    refused with the count, at its <robot> line, with a hint, before any exclusion is made."""
    from runner.compile.packages import PackageMap
    from runner.compile.urdf import link_props
    from runner.compile.urdf.checks import DescriptionError
    from runner.compile.urdf.reader import urdf_to_model

    monkeypatch.setattr(link_props, "MAX_EXCLUDES", 100)
    with pytest.raises(DescriptionError) as err:
        urdf_to_model(chain_urdf(30, star=True), None, PackageMap.for_scenario(Path.cwd(), {}))
    text = str(err.value)
    assert "need 406 MuJoCo contact exclusions; at most 100 are made" in text, text
    assert err.value.line == 2 and "self_collide" in (err.value.hint or "")
