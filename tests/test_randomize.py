"""Randomized scenarios: values drawn from the seed (`uniform`, `normal`, `choice`, a pose within a region),
`matrix: {samples: N}`, poses redrawn out of collisions, and the drawn values in every name a run is reported
under (runner.scenario.draws, runner.compile.placement)."""

from __future__ import annotations

import json
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import mujoco
import pytest
import yaml

from runner.cli.plans import load_variants
from runner.compile.placement import PENETRATION_M, load_drawn_plan
from runner.errors import ScenarioError
from runner.scenario.loader import load_text
from runner.scenario.matrix import variants
from tests.conftest import DIFFBOT, REPO, SCENARIOS, read_mcap, run_cli

HEAD = f"""
name: rnd
duration: 0.5
rate: max
seed: 5
robots:
  - name: r1
    description: {{file: {DIFFBOT}}}
    pose: {{within: {{center: [0, 0], radius: 1.5}}, z: 0.06, yaw: [-3, 3]}}
    plugins:
      - {{type: diff_drive}}
      - {{type: ground_truth, params: {{rate: {{choice: [20, 50]}}}}}}
"""


def _variants(text: str) -> list[tuple[str, Any]]:
    return variants(load_text(text, REPO / "scenario.yaml"))


def test_each_form_draws_a_value_of_its_kind():
    text = (
        HEAD
        + """
world:
  models:
    - {name: box, shape: box, size: [{uniform: [0.2, 0.4]}, 0.3, {normal: [0.3, 0.01]}],
       pose: {within: {min: [3, 3], max: [4, 5]}}}
timeline:
  - {t: 0.1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: {choice: [0.1, 0.2]}}}}
"""
    )
    [(label, doc)] = _variants(text)
    assert label == ""  # one run: no variant label, the values are printed as `drawn:`
    data = doc.data
    robot = data["robots"][0]["pose"]
    x, y, z = robot["xyz"]
    assert x**2 + y**2 <= 1.5**2 and z == 0.06 and -3 <= robot["rpy"][2] < 3 and robot["rpy"][:2] == [0, 0]
    assert data["robots"][0]["plugins"][1]["params"]["rate"] in (20, 50)
    size = data["world"]["models"][0]["size"]
    assert 0.2 <= size[0] < 0.4 and size[1] == 0.3 and abs(size[2] - 0.3) < 0.1
    assert all(round(v, 6) == v for v in size)  # rounded to 6 decimals
    box = data["world"]["models"][0]["pose"]
    assert (
        3 <= box["xyz"][0] < 4 and 3 <= box["xyz"][1] < 5 and box["xyz"][2] == 0 and box["rpy"] == [0, 0, 0]
    )
    assert data["timeline"][0]["data"]["linear"]["x"] in (0.1, 0.2)
    # in the file's order, each with its path
    assert [d.shown().split("=")[0] for d in doc.draws.items] == [
        "robots[0].pose",
        "robots[0].plugins[1].params.rate",
        "world.models[0].size[0]",
        "world.models[0].size[2]",
        "world.models[0].pose",
        "timeline[0].data.linear.x",
    ]
    plan = load_drawn_plan(doc)
    assert plan.drawn["robots[0].pose"] == data["robots"][0]["pose"]
    truth = next(p for p in plan.robots[0].plugins if p.type == "ground_truth")
    assert truth.rate == data["robots"][0]["plugins"][1]["params"]["rate"]


def test_same_seed_same_plans_other_seed_other_draws():
    def plans(text: str) -> list[str]:
        return [load_drawn_plan(doc).model_dump_json() for _, doc in _variants(text)]

    text = HEAD + "matrix: {samples: 3}\n"
    first, again = plans(text), plans(text)
    assert first == again  # the same file and seed: the same draws, the same compiled model, byte for byte
    assert len(set(first)) == 3  # each sample draws its own
    other = plans(text.replace("seed: 5", "seed: 6"))
    assert not set(other) & set(first)


def test_samples_make_variants_labelled_with_their_draws():
    found = _variants(HEAD + "matrix: {samples: 3, duration: [0.5, 1.0]}\n")
    labels = [label for label, _ in found]
    assert len(found) == 6 and len(set(labels)) == 6
    assert labels[0].startswith("duration=0.5,sample=0,robots[0].pose=[")
    assert labels[4].startswith("duration=1.0,sample=1,robots[0].pose=[")
    assert "yaw " in labels[0] and ",robots[0].plugins[1].params.rate=" in labels[0]
    # sample i draws the same whatever the other keys: [seed, i]
    assert found[0][1].data["robots"][0]["pose"] == found[3][1].data["robots"][0]["pose"]
    assert found[0][1].data["robots"][0]["pose"] != found[1][1].data["robots"][0]["pose"]


def test_a_matrix_seed_seeds_the_draws():
    found = _variants(HEAD + "matrix: {seed: [1, 2]}\n")
    assert [label.split(",")[0] for label, _ in found] == ["seed=1", "seed=2"]
    assert found[0][1].data["robots"][0]["pose"] != found[1][1].data["robots"][0]["pose"]


BAD = f"""
name: rnd
seed: 1
robots:
  - name: r1
    description: {{file: {DIFFBOT}}}
    pose: {{within: {{min: [1, 1], max: [0, 2]}}, height: 1, yaw: [2, 1]}}
world:
  models:
    - {{name: a, shape: box, size: [{{uniform: [2, 1]}}, 1, {{normal: [0, -1]}}]}}
    - {{name: b, shape: sphere, size: [{{choice: []}}]}}
    - {{name: c, shape: sphere, size: [{{uniform: [0, 1], also: 2}}], pose: {{within: [1, 2]}}}}
    - {{name: d, shape: sphere, size: [{{uniform: [a, 1]}}]}}
"""


def test_wrong_draws_are_located_all_at_once():
    with pytest.raises(ScenarioError) as e:
        _variants(BAD)
    got = [(p.location.line, ".".join(map(str, p.path)), p.message) for p in e.value.problems]
    paths = [path for _, path, _ in got]
    assert paths == [
        "robots.0.pose",  # unknown key `height`
        "robots.0.pose.within",  # max below min
        "robots.0.pose.yaw",  # lo > hi
        "world.models.0.size.0.uniform",
        "world.models.0.size.2.normal",
        "world.models.1.size.0.choice",
        "world.models.2.size.0",  # a key beside `uniform`
        "world.models.2.pose.within",  # not a region
        "world.models.3.size.0.uniform",  # not a number
    ], got
    assert [line for line, _, _ in got] == [7, 7, 7, 10, 10, 11, 12, 12, 13]
    text = e.value.render()
    assert "height" in text and "lower bound is above the upper one" in text and "stddev >= 0" in text
    assert "non-empty list" in text and "also" in text and "a region is" in text and "two numbers" in text


def test_wrong_samples_is_located():
    with pytest.raises(ScenarioError) as e:
        _variants(HEAD + "matrix: {samples: 0}\n")
    [p] = e.value.problems
    assert p.path == ("matrix", "samples") and "1 or more" in (p.expected or "")
    with pytest.raises(ScenarioError) as e:
        _variants(HEAD + "matrix: {samples: 600, seed: [1, 2]}\n")
    assert "1200 variants" in e.value.render()


CROWDED = """
name: crowded
seed: 3
world:
  models:
    - {name: block, shape: box, size: [1.6, 1.6, 0.4], pose: {xyz: [0, 0, 0.2]}}
    - {name: slab, shape: box, size: [0.3, 0.3, 0.3], pose: {within: {min: [-1, -1], max: [1, 1]}, z: 0.15}}
robots:
  - name: r1
    description: {file: DIFFBOT}
    pose: {within: {min: [-1.2, -1.2], max: [1.2, 1.2]}, z: 0.06, yaw: [-3, 3]}
matrix: {samples: 6}
""".replace("DIFFBOT", str(DIFFBOT))


def _penetration(plan: Any, names: set[str]) -> float:
    """The deepest overlap between the collision geoms of the robot and those named `names`."""
    m = mujoco.MjModel.from_xml_string(plan.mjcf)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    robot = [g for g in range(m.ngeom) if m.geom(g).name.startswith("r1/") and m.geom_contype[g]]
    named = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, n) for n in names]
    pairs = [(a, b) for a in robot for b in named] + [(named[0], named[1])]
    return min(mujoco.mj_geomDistance(m, d, a, b, 1.0, None) for a, b in pairs)


def test_poses_drawn_into_an_obstacle_are_drawn_again_to_a_free_spot():
    """Most of the region is a block: the robot's and the slab's first draws mostly land in it. Every
    placed variant is free (the robot of the block and the slab, the slab of the block: a static model is
    checked against static ones too), and placing again gives the same poses."""
    docs = variants(load_text(CROWDED, REPO / "s.yaml"))
    first = [json.dumps(doc.data) for _, doc in docs]
    plans = [load_drawn_plan(doc) for _, doc in docs]
    moved = [json.dumps(doc.data) != before for (_, doc), before in zip(docs, first, strict=True)]
    assert sum(moved) >= 3, moved  # most were redrawn
    for plan in plans:
        assert _penetration(plan, {"block", "slab"}) > -PENETRATION_M, plan.variant
        x, y, _ = plan.drawn["robots[0].pose"]["xyz"]
        assert max(abs(x), abs(y)) <= 1.2
    again = [load_drawn_plan(doc) for _, doc in variants(load_text(CROWDED, REPO / "s.yaml"))]
    assert [p.mjcf for p in again] == [p.mjcf for p in plans]
    # the labels are those of the placed poses
    assert [p.variant for p in plans] == [p.variant for p in again]
    for plan, (label, _) in zip(plans, docs, strict=True):
        assert plan.variant.split(",")[0] == label.split(",")[0]
        assert f"robots[0].pose=[{plan.drawn['robots[0].pose']['xyz'][0]:.3f}".rstrip("0") in plan.variant


def test_a_region_with_no_free_spot_is_a_located_error():
    text = CROWDED.replace("max: [1.2, 1.2]", "max: [-0.6, -0.6]").replace("[-1.2, -1.2]", "[-0.7, -0.7]")
    [(_, doc)] = variants(load_text(text.replace("matrix: {samples: 6}", ""), REPO / "s.yaml"))
    with pytest.raises(ScenarioError) as e:
        load_drawn_plan(doc)
    [p] = e.value.problems
    assert p.path == ("robots", 0, "pose") and p.location.line == 11
    assert "no collision-free pose in 100 draws" in p.message and "'block'" in p.message
    assert "larger region" in (p.hint or "")


def test_validate_prints_the_drawn_values(write_scenario):
    path = write_scenario(HEAD.replace(str(DIFFBOT), "{diffbot}"))
    proc = run_cli("validate", str(path))
    assert proc.returncode == 0, proc.stderr
    [line] = [ln for ln in proc.stdout.splitlines() if ln.startswith("drawn: ")]
    assert line.startswith("drawn: robots[0].pose=[") and "params.rate=" in line


def test_the_json_schema_takes_draws_and_refuses_wrong_ones():
    from jsonschema import Draft202012Validator

    schema = json.loads((REPO / "schemas" / "scenario.schema.json").read_text())
    check = Draft202012Validator(schema)
    good = yaml.safe_load((SCENARIOS / "random_start.yaml").read_text())
    assert not list(check.iter_errors(good))
    assert not list(check.iter_errors(yaml.safe_load(HEAD + "matrix: {samples: 3, seed: [1, 2]}")))
    for bad in (
        "duration: {uniform: [1]}",
        "duration: {uniform: [1, 2], also: 1}",
        "duration: {choice: []}",
        "matrix: {samples: 0}",
        "robots: [{name: r, description: x, pose: {within: {center: [0, 0]}, x: 1}}]",
    ):
        assert list(check.iter_errors(yaml.safe_load(f"name: x\n{bad}"))), bad


@pytest.mark.timeout(120)
def test_labels_reach_the_table_junit_report_and_recordings(write_scenario, tmp_path: Path):
    """`scenario test` of two samples: each run's name carries its drawn values (table, JUnit suite and
    testcase, HTML report), and the two recordings start from different poses."""
    text = HEAD.replace(str(DIFFBOT), "{diffbot}") + (
        "assertions:\n  - {name: upright, type: max_tilt, robot: r1, max: 0.5}\nmatrix: {samples: 2}\n"
    )
    path = write_scenario(text)
    labels = [label for label, _ in load_variants(path, None, None)]
    junit, out = tmp_path / "j.xml", tmp_path / "runs"
    proc = run_cli("test", str(path), "-j", "2", "--junit", str(junit), "--out", str(out), timeout=110)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    suites = ET.parse(junit).getroot().findall("testsuite")
    assert sorted(s.get("name") for s in suites) == sorted(f"scenario[{label}]" for label in labels)
    for s in suites:
        assert [c.get("classname") for c in s.findall("testcase")] == [s.get("name")]
    flat = " ".join(proc.stdout.split())
    assert "sample=0,robots[0].pose=" in flat  # the table (wrapped by rich: joined again)
    starts = []
    for i in range(2):
        page = (out / f"scenario-{i}.html").read_text()
        assert f"variant: {labels[i]}" in page
        truth = [m for t, _, _, m in read_mcap(out / f"scenario-{i}.mcap") if t.endswith("/ground_truth")]
        starts.append(round(truth[0].pose.pose.position.x, 3))
    assert starts[0] != starts[1]


@pytest.mark.timeout(120)
def test_pytest_runs_every_sample_of_the_example():
    """The pytest plugin on a randomized example: each assertion passes in every sample."""
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            str(SCENARIOS / "random_start.yaml"),
        ],
        capture_output=True,
        text=True,
        timeout=110,
        cwd=REPO,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "2 passed" in proc.stdout
