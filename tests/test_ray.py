"""`scenario test --ray` on a real two-node Ray cluster on loopback (tests/ray_cluster.py): a matrix suite
spread over both nodes, with the same verdicts and recordings as the suite run here with -j 2; a worker
killed mid-run, a run over --timeout, Ctrl-C on the driver; the scenario's folder (a mesh, a node script)
shipped to workers that run elsewhere. One cluster for the module, stopped by its own pids."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import textwrap
import time
import uuid
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

from tests.conftest import DIFFBOT, run_cli, scenario_cmd
from tests.ray_cluster import LOOPBACK_ENV, Cluster, start_cluster

SWEEP = """
name: sweep
duration: 1.0
rate: max
seed: 1
world:
  physics: {timestep: 0.002}
  models:
    - {name: wall, shape: box, size: [0.1, 6, 0.5], pose: {xyz: [3, 0, 0.25]}}
robots:
  - name: r1
    description: {file: robots/diffbot.urdf.xacro}
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive, params: {rate: 50}}
      - {type: lidar, params: {link: lidar_link, samples: 90, rate: 10, range_max: 8.0, noise_stddev: 0.01}}
      - {type: imu, params: {link: imu_link, rate: 100, linear_acceleration_stddev: 0.01}}
timeline:
  - {t: 0.1, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 0.2}}}
matrix:
  seed: [1, 2, 3]
  timeline[0].data.linear.x: [0.1, 0.2, 0.3, 0.4]
assertions:
  - {name: clear_of_the_wall, type: no_collision, between: [r1, wall]}
  - {name: moves, type: distance_traveled, robot: r1, min: 0.05, max: 0.5}
"""

# realtime runs of a given length: a run that lasts (`duration`), on purpose
SLOW = """
name: {name}
duration: 1.0
rate: realtime
seed: 1
robots:
  - name: r1
    description: {{file: robots/diffbot.urdf.xacro}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins: [{{type: diff_drive, params: {{rate: 50}}}}]
matrix:
  duration: {durations}
assertions:
  - {{name: stays_near, type: stay_within, robot: r1, region: {{center: [0, 0], radius: 1}}}}
"""


@pytest.fixture(scope="module")
def cluster() -> Any:
    """The cluster, and the drivers the tests start (they inherit this environment) told it has no token
    authentication (tests/ray_cluster.py)."""
    saved = os.environ.get("RAY_AUTH_MODE")
    os.environ["RAY_AUTH_MODE"] = LOOPBACK_ENV["RAY_AUTH_MODE"]
    c = start_cluster(nodes=2, cpus=1)
    try:
        yield c
    finally:
        c.stop()
        if saved is None:
            os.environ.pop("RAY_AUTH_MODE", None)
        else:
            os.environ["RAY_AUTH_MODE"] = saved


def _folder(root: Path, files: dict[str, str]) -> Path:
    """A scenario folder of its own: the files given, and the robot under robots/."""
    root.mkdir(parents=True, exist_ok=True)
    (root / "robots").mkdir(exist_ok=True)
    (root / "robots" / "diffbot.urdf.xacro").write_text(DIFFBOT.read_text())
    for name, text in files.items():
        (root / name).write_text(textwrap.dedent(text).lstrip())
    return root


def _suites(junit: Path) -> dict[str, ET.Element]:
    return {s.get("name", ""): s for s in ET.parse(junit).getroot().findall("testsuite")}


def _verdicts(suite: ET.Element) -> list[tuple[str, str, str]]:
    """(testcase, sim time of its verdict, its failure or error text) of a JUnit suite."""
    out = []
    for case in suite.findall("testcase"):
        bad = case.find("failure") if case.find("failure") is not None else case.find("error")
        out.append(
            (case.get("name", ""), case.get("time", ""), "" if bad is None else bad.get("message", ""))
        )
    return out


def _props(suite: ET.Element) -> dict[str, str]:
    return {p.get("name", ""): p.get("value", "") for p in suite.findall("properties/property")}


def _messages(mcap: Path, folder: Path) -> list[tuple[str, str, int, int, bytes]]:
    """Every message of a recording (topic, schema, log and publish time, bytes), read back with the mcap
    reader. The compiled plan (`<run>/_plan`) names where the scenario was read from and where the run
    recorded to: those two are put as `<scenario folder>` and `<recording>`, the rest is kept as it is."""
    out = []
    with open(mcap, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
            data = bytes(message.data)
            if channel.topic.endswith("/_plan"):
                plan = json.loads(data[data.index(b"{") : data.rindex(b"}") + 1])  # (a CDR string)
                text = json.dumps(plan, sort_keys=True).replace(str(folder.resolve()), "<scenario folder>")
                text = text.replace(json.dumps(plan["record"]["path"]), '"<recording>"')
                data = text.encode()
            out.append(
                (channel.topic, schema.name if schema else "", message.log_time, message.publish_time, data)
            )
    return out


def _plan_folder(mcap: Path) -> Path:
    """The folder the run read its scenario from, as its recording says."""
    with open(mcap, "rb") as f:
        for _schema, channel, message in make_reader(f).iter_messages():
            if channel.topic.endswith("/_plan"):
                data = bytes(message.data)
                return Path(
                    json.loads(data[data.index(b"{") : data.rindex(b"}") + 1])["scenario_file"]
                ).parent
    raise AssertionError(f"{mcap}: no _plan")


@pytest.mark.timeout(420)
def test_a_matrix_suite_runs_on_both_nodes_as_it_runs_here(cluster: Cluster, tmp_path: Path) -> None:
    folder = _folder(tmp_path / "suite", {"sweep.yaml": SWEEP})
    elsewhere = tmp_path / "cwd"  # the driver's folder: not the scenarios'
    elsewhere.mkdir()
    art, here = elsewhere / "art", tmp_path / "here"
    j_ray, j_here = tmp_path / "ray.xml", tmp_path / "here.xml"
    ray_run = run_cli(
        "test", str(folder), "--ray", cluster.address, "--artifacts", "art", "--junit", str(j_ray),
        timeout=300, cwd=elsewhere,
    )  # fmt: skip
    assert ray_run.returncode == 0, ray_run.stdout[-3000:] + ray_run.stderr[-3000:]
    local = run_cli("test", str(folder), "-j", "2", "--out", str(here), "--junit", str(j_here), timeout=300)
    assert local.returncode == 0, local.stdout[-3000:] + local.stderr[-3000:]

    on_ray, on_here = _suites(j_ray), _suites(j_here)
    assert len(on_ray) == 12 and set(on_ray) == set(on_here), (sorted(on_ray), sorted(on_here))
    for name, suite in on_ray.items():  # the same verdicts, decided at the same sim times
        assert _verdicts(suite) == _verdicts(on_here[name]), name
        assert len(_verdicts(suite)) == 2 and suite.get("failures") == "0" and suite.get("errors") == "0"
    nodes = {_props(s)["ray.node"] for s in on_ray.values()}
    assert nodes == set(cluster.nodes), (nodes, cluster.nodes)  # every variant ran, on both nodes
    assert all(_props(s)["ray.attempts"] == "1" for s in on_ray.values())

    for i in range(12):  # the same recordings, message by message, byte by byte
        mine, theirs = art / f"sweep-{i}" / f"sweep-{i}.mcap", here / f"sweep-{i}.mcap"
        assert (art / f"sweep-{i}" / f"sweep-{i}.html").is_file()
        worker_folder = _plan_folder(mine)
        assert worker_folder != folder.resolve() and "working_dir_files" in str(worker_folder)
        a, b = _messages(mine, worker_folder), _messages(theirs, folder)
        assert len(a) > 100 and a == b, i

    page = (art / "summary.html").read_text()
    assert "12 of 12 passed (100%)" in page
    for name in on_ray:  # every run listed, linked to its report and recording
        assert name.replace("'", "&#x27;") in page or name in page, name
    assert page.count("report</a>") == 12 and page.count("recording</a>") == 12
    assert "<td>timeline[0].data.linear.x</td><td>0.3</td><td>3 / 3</td>" in page
    assert "<td>seed</td><td>2</td><td>4 / 4</td>" in page
    assert "Slowest runs" in page
    assert "art/sweep-11/sweep-11.html" in ray_run.stdout  # the table links each report
    assert "summary: art/summary.html" in ray_run.stdout


def _pids(*parts: str) -> list[int]:
    """The processes whose command line holds every one of `parts`."""
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                cmd = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            except OSError:
                continue
            if all(p in cmd for p in parts) and "pytest" not in cmd:
                out.append(int(entry.name))
    return out


def _parent(pid: int) -> int:
    stat = Path(f"/proc/{pid}/stat").read_text()
    return int(stat[stat.rindex(")") + 2 :].split()[1])


def _gone(pids: list[int], within: float) -> bool:
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        if not any(Path(f"/proc/{p}").exists() for p in pids):
            return True
        time.sleep(0.2)
    return False


def _start(*args: str, cwd: Path, log: Path) -> subprocess.Popen[bytes]:
    """`scenario ARGS` in the background, its output in `log` (read as it comes)."""
    with open(log, "wb") as f:
        return subprocess.Popen(
            scenario_cmd(*args), cwd=cwd, stdout=f, stderr=subprocess.STDOUT,
            env=dict(os.environ, PYTHONUNBUFFERED="1"),
        )  # fmt: skip


def _wait_for(predicate: Any, within: float, every: float = 0.1) -> bool:
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(every)
    return False


@pytest.mark.timeout(300)
def test_a_run_whose_worker_is_killed_is_retried_and_passes(cluster: Cluster, tmp_path: Path) -> None:
    marker = f"killed_{uuid.uuid4().hex[:8]}"  # (its runs' command lines name it: no other suite's)
    folder = _folder(tmp_path / "suite", {f"{marker}.yaml": SLOW.format(name="slow", durations="[3.0, 1.0]")})
    junit, log = tmp_path / "j.xml", tmp_path / "log"
    proc = _start("test", str(folder), "--ray", cluster.address, "--junit", str(junit), cwd=tmp_path, log=log)
    try:
        assert _wait_for(lambda: _pids(f"{marker}.yaml", "--variant 0"), 120), log.read_text()
        run = _pids(f"{marker}.yaml", "--variant 0")[0]
        worker = _parent(run)
        assert Path(f"/proc/{worker}/cmdline").read_bytes().startswith(b"ray::"), worker
        os.kill(worker, signal.SIGKILL)  # the Ray worker running variant 0 dies mid-run
        assert _gone([run], 30), "the run outlived the worker that started it"
        proc.wait(timeout=240)
    finally:
        proc.kill()
        proc.wait()
    text = log.read_text()
    assert proc.returncode == 0, text[-3000:]
    suites = _suites(junit)
    assert len(suites) == 2 and all(
        s.get("errors") == "0" and s.get("failures") == "0" for s in suites.values()
    )
    attempts = {name: _props(s)["ray.attempts"] for name, s in suites.items()}
    assert attempts == {f"{marker}[duration=3.0]": "2", f"{marker}[duration=1.0]": "1"}, attempts
    assert f"{marker}[duration=3.0]: retried: its worker died; attempt 2 ran it to its end" in text, text[
        -3000:
    ]
    assert "(2 attempts)" in text


@pytest.mark.timeout(300)
def test_a_run_over_its_timeout_is_an_error_and_the_others_pass(cluster: Cluster, tmp_path: Path) -> None:
    folder = _folder(
        tmp_path / "suite", {"slow.yaml": SLOW.format(name="slow", durations="[1.0, 600.0, 2.0]")}
    )
    junit = tmp_path / "j.xml"
    proc = run_cli(
        "test", str(folder), "--ray", cluster.address, "--timeout", "15", "--artifacts", str(tmp_path / "art"),
        "--junit", str(junit), timeout=240, cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 1, proc.stdout[-3000:] + proc.stderr[-3000:]
    suites = _suites(junit)
    assert set(suites) == {"slow[duration=1.0]", "slow[duration=600.0]", "slow[duration=2.0]"}, sorted(suites)
    error = suites["slow[duration=600.0]"].find("testcase[@name='run']/error")
    assert error is not None, ET.tostring(suites["slow[duration=600.0]"])
    assert "timed out: still running after 15 s of wall time (--timeout), stopped" in (error.text or "")
    for name in ("slow[duration=1.0]", "slow[duration=2.0]"):
        assert suites[name].get("errors") == "0" and suites[name].get("failures") == "0", name
        assert len(suites[name].findall("testcase")) == 1
    # stopped in order: its recording is finished and readable, up to where it was stopped
    with open(tmp_path / "art" / "slow-1" / "slow-1.mcap", "rb") as f:
        assert sum(1 for _ in make_reader(f).iter_messages()) > 10


@pytest.mark.timeout(300)
def test_ctrl_c_on_the_driver_cancels_every_run_and_still_writes_junit(
    cluster: Cluster, tmp_path: Path
) -> None:
    marker = f"cancelled_{uuid.uuid4().hex[:8]}"
    folder = _folder(
        tmp_path / "suite", {f"{marker}.yaml": SLOW.format(name="slow", durations="[600.0, 1.0, 1.5, 2.0]")}
    )
    junit, log = tmp_path / "j.xml", tmp_path / "log"
    proc = _start("test", str(folder), "--ray", cluster.address, "--junit", str(junit), cwd=tmp_path, log=log)
    try:
        assert _wait_for(lambda: "[1/4]" in log.read_text(), 180), log.read_text()
        assert _pids(f"{marker}.yaml", "--variant 0")  # the long run is going
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=120)
    finally:
        proc.kill()
        proc.wait()
    text = log.read_text()
    assert proc.returncode == 130, text[-3000:]
    assert _gone(_pids(f"{marker}.yaml"), 30), "a run outlived the cancelled suite"
    suites = _suites(junit)
    assert len(suites) == 4, sorted(suites)
    long_one = suites[f"{marker}[duration=600.0]"].find("testcase[@name='run']/error")
    assert long_one is not None and (long_one.text or "").startswith("cancelled"), text[-3000:]
    done = [line.split("] ", 1)[1].split(": ")[0] for line in text.splitlines() if line.startswith("[")]
    for name, suite in suites.items():  # each run passed, or was cancelled
        error = suite.find("testcase[@name='run']/error")
        if error is None:
            assert suite.get("failures") == "0" and name in done, name
        else:
            assert (error.text or "").startswith("cancelled"), (name, error.text)
    assert "interrupted" in text


GOAL = """
name: goal
duration: 12.0
rate: max
seed: 1
robots:
  - name: r1
    description: {file: robots/meshbot.urdf.xacro}
    pose: {xyz: [-1.0, -1.0, 0.06]}
    plugins:
      - {type: diff_drive, params: {rate: 50, odometry_source: world}}
nodes:
  - {name: controller, cmd: python nodes/go_to_goal.py, args: ["--x", "2.0", "--y", "1.5"], namespace: r1, required: true}
lockstep: [controller]
assertions:
  - {name: r1_reaches_the_goal, type: reach, robot: r1, point: [1.0, 0.5], tolerance: 0.15, by: 12}
"""


@pytest.mark.timeout(240)
def test_the_scenario_folder_reaches_workers_that_run_elsewhere(cluster: Cluster, tmp_path: Path) -> None:
    """A robot whose chassis is a mesh (meshes/chassis.stl) and a controller node script (nodes/), beside
    the scenario: the workers run them from the copy Ray shipped to their node, not from the driver's
    folder, and the driver runs from a folder of its own."""
    import trimesh

    from tests.conftest import SCENARIOS

    folder = _folder(tmp_path / "suite", {"goal.yaml": GOAL})
    (folder / "meshes").mkdir()
    trimesh.creation.box(extents=(0.30, 0.20, 0.08)).export(folder / "meshes" / "chassis.stl")
    box = '<geometry><box size="${chassis_l} ${chassis_w} ${chassis_h}"/></geometry>'
    robot = DIFFBOT.read_text()
    assert robot.count(box) == 2  # the chassis' visual and collision
    robot = robot.replace(box, '<geometry><mesh filename="../meshes/chassis.stl"/></geometry>')
    (folder / "robots" / "meshbot.urdf.xacro").write_text(robot)
    (folder / "nodes").mkdir()
    (folder / "nodes" / "go_to_goal.py").write_text((SCENARIOS / "nodes" / "go_to_goal.py").read_text())
    driver = tmp_path / "driver"
    driver.mkdir()
    junit, shared = tmp_path / "j.xml", tmp_path / "shared"  # a folder every node mounts: file://
    proc = run_cli(
        "test", str(folder / "goal.yaml"), "--ray", cluster.address, "--artifacts", shared.as_uri(),
        "--junit", str(junit), timeout=200, cwd=driver,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    suite = _suites(junit)["goal"]
    assert _verdicts(suite) == [
        ("r1_reaches_the_goal", suite.find("testcase").get("time"), "")
    ]  # the node drove it
    assert (shared / "goal" / "goal.html").is_file() and (shared / "summary.html").is_file()
    assert f"summary: {shared.as_uri()}/summary.html" in proc.stdout
    assert (
        "goal.yaml: a CPU for each of a run's 2 processes would be more than any node has: each run asks 1"
        in (" ".join(proc.stderr.split()))
    )
    assert "goal/goal.html" in (shared / "summary.html").read_text()  # relative: beside the page
    with open(shared / "goal" / "goal.mcap", "rb") as f:
        plans = [m for _s, c, m in make_reader(f).iter_messages() if c.topic == "goal/_plan"]
    data = bytes(plans[0].data)
    plan = json.loads(data[data.index(b"{") : data.rindex(b"}") + 1])
    shipped = Path(plan["scenario_file"]).parent
    assert shipped != folder and "runtime_resources/working_dir_files" in str(shipped), shipped
    assert plan["robots"][0]["description_file"] == str(shipped / "robots" / "meshbot.urdf.xacro")
    assert f'file="{shipped / "meshes" / "chassis.stl"}"' in plan["mjcf"]  # the mesh read there
    assert plan["nodes"][0]["cwd"] == str(shipped) and plan["nodes"][0]["argv"][1] == "nodes/go_to_goal.py"
    assert not (driver / "runs").exists()  # nothing went to the driver's folder


def test_without_ray_installed_the_error_says_how_to_install_it(tmp_path: Path) -> None:
    shim = tmp_path / "shim" / "ray"
    shim.mkdir(parents=True)
    (shim / "__init__.py").write_text("raise ImportError(\"No module named 'ray'\")\n")
    from tests.conftest import REPO, SCENARIOS

    env = dict(os.environ, PYTHONPATH=f"{shim.parent}{os.pathsep}{REPO}")
    proc = subprocess.run(
        scenario_cmd("test", str(SCENARIOS / "two_robots.yaml"), "--ray"),
        capture_output=True, text=True, timeout=60, env=env, cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.strip() == (
        'error: --ray needs Ray, an optional extra: pip install "scenario-runner[ray]" (in a checkout: '
        'pip install -e ".[ray]")'
    ), proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize(
    ("args", "code", "says"),
    [
        (["--artifacts", "x"], 2, "--artifacts goes with --ray"),
        (["--gpus", "1"], 2, "--gpus goes with --ray"),
        (["--ray", "--gpus", "many"], 2, "--gpus 'many': expected auto or a number of GPUs"),
        (
            ["--ray", "--artifacts", "nosuchscheme://bucket/runs"],
            1,
            "--artifacts nosuchscheme://bucket/runs:",
        ),
        (["--ray", "--artifacts", "s3://bucket/runs"], 1, "--artifacts s3://bucket/runs: Install s3fs"),
    ],
)
def test_ray_options_are_checked_before_anything_runs(args: list[str], code: int, says: str) -> None:
    from tests.conftest import SCENARIOS

    proc = run_cli("test", str(SCENARIOS / "two_robots.yaml"), *args, timeout=60)
    assert proc.returncode == code, proc.stdout + proc.stderr
    assert says in " ".join(proc.stderr.split()), proc.stderr
    assert "Traceback" not in proc.stderr


def test_the_rayjob_example_runs_scenario_test_with_options_it_takes() -> None:
    """docs/rayjob.yaml (shown in docs/ray.md): a RayJob whose entrypoint is a `scenario test --ray` that
    the command parses, on the Ray version the project pins."""
    import re
    import shlex
    from importlib.metadata import version

    import yaml
    from typer.main import get_command

    from runner.cli import app
    from tests.conftest import REPO

    text = (REPO / "docs" / "rayjob.yaml").read_text()
    doc = yaml.safe_load(text)
    assert (doc["apiVersion"], doc["kind"]) == ("ray.io/v1", "RayJob")
    spec = doc["spec"]
    assert spec["rayClusterSpec"]["rayVersion"] == version("ray")
    images = {
        c["image"]
        for g in [spec["rayClusterSpec"]["headGroupSpec"], *spec["rayClusterSpec"]["workerGroupSpecs"]]
        for c in g["template"]["spec"]["containers"]
    }
    assert len(images) == 1  # the head and the workers run the same project
    argv = shlex.split(spec["entrypoint"])
    assert argv[:2] == ["scenario", "test"]
    ctx = get_command(app).commands["test"].make_context("test", argv[2:])  # type: ignore[attr-defined]
    assert ctx.params["ray"] == "" and ctx.params["artifacts"].startswith("s3://")
    assert ctx.params["paths"] == [Path("scenarios")] and ctx.params["timeout"] == 900
    page = (REPO / "docs" / "ray.md").read_text()
    shown = re.search(r"```yaml\n# docs/rayjob.yaml[^\n]*\n(.*?)```", page, re.S)
    assert shown is not None and shown.group(1) == text.split("\n", 1)[1]  # the page shows the file
    assert f"FROM rayproject/ray:{version('ray')}-py311" in page


CAMERA_BOT = """
name: {name}
duration: 1.0
rate: max
renderers: process
robots:
  - name: r1
    description: {{file: robots/diffbot.urdf.xacro}}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive}}
      - {{type: camera, params: {{link: lidar_link, width: 64, height: 48, rate: 5}}}}
nodes:
  - {{name: idle, cmd: python -c "pass"}}
{resources}
"""


def _cluster_of(cpus: list[float], gpus: float = 0.0, **custom: float) -> dict[str, Any]:
    """A cluster as `fanout.cluster_info` describes one: nodes with these CPUs, GPUs and custom resources."""
    nodes = {f"n{i}": ("127.0.0.1", {"CPU": c}) for i, c in enumerate(cpus)}
    return {"nodes": nodes, "total": {"CPU": sum(cpus), **({"GPU": gpus} if gpus else {}), **custom}}


def test_what_a_run_asks_of_the_cluster(tmp_path: Path) -> None:
    """A CPU per process (the world, its renderer, the node), capped at the largest node; a GPU for cameras
    with --gpus auto on a cluster with GPUs, none without or with --gpus 0; `resources:` wins; what no node
    has is an error before anything is sent."""
    from runner.errors import RunError
    from runner.tools.fanout import plan_jobs
    from runner.tools.suite import Variant

    folder = _folder(
        tmp_path,
        {
            "cam.yaml": CAMERA_BOT.format(name="cam", resources=""),
            "own.yaml": CAMERA_BOT.format(
                name="own", resources="resources: {num_cpus: 0.5, num_gpus: 0.25, custom: {lidar_box: 1}}"
            ),
            "sweep.yaml": SWEEP,
        },
    )
    cam, own, sweep = (Variant(folder / f"{n}.yaml", None, "") for n in ("cam", "own", "sweep"))
    jobs, notes = plan_jobs([cam, Variant(sweep.file, 5, "x")], "auto", _cluster_of([4, 4], gpus=2))
    assert [j.asks for j in jobs] == [
        {"num_cpus": 3.0, "num_gpus": 1.0, "resources": {}},  # world + renderer + node; cameras: a GPU
        {"num_cpus": 1.0, "num_gpus": 0.0, "resources": {}},
    ]
    assert notes == [] and jobs[1].values == {"seed": "2", "timeline[0].data.linear.x": "0.2"}
    jobs, notes = plan_jobs([cam], "auto", _cluster_of([2, 1]))  # no GPU here; 2 CPUs at most a node
    assert (
        jobs[0].asks == {"num_cpus": 2.0, "num_gpus": 0.0, "resources": {}} and "each run asks 2" in notes[0]
    )
    jobs, notes = plan_jobs([cam, cam], "auto", _cluster_of([2]))
    assert len(notes) == 1  # said once for the file
    assert plan_jobs([cam], "0", _cluster_of([4], gpus=1))[0][0].asks["num_gpus"] == 0.0
    assert plan_jobs([cam], "0.5", _cluster_of([4], gpus=1))[0][0].asks["num_gpus"] == 0.5
    with pytest.raises(RunError, match=r"1 GPU\(s\) asked for a run with cameras; the cluster has 0"):
        plan_jobs([cam], "1", _cluster_of([4]))
    jobs, _ = plan_jobs([own], "auto", _cluster_of([4], gpus=1, lidar_box=2))
    assert jobs[0].asks == {"num_cpus": 0.5, "num_gpus": 0.25, "resources": {"lidar_box": 1.0}}
    with pytest.raises(RunError, match=r"resources\.custom: no node of the cluster has lidar_box"):
        plan_jobs([own], "auto", _cluster_of([4], gpus=1))
    big = _folder(
        tmp_path / "big", {"big.yaml": CAMERA_BOT.format(name="big", resources="resources: {num_cpus: 8}")}
    )
    with pytest.raises(RunError, match=r"resources\.num_cpus 8: no node of the cluster has that many CPUs"):
        plan_jobs([Variant(big / "big.yaml", None, "")], "auto", _cluster_of([4, 4]))


@pytest.mark.parametrize(
    ("args", "address", "paths"),
    [
        (["--ray", "scenarios"], "", ["scenarios"]),  # a path after --ray is a path
        (["scenarios", "--ray"], "", ["scenarios"]),
        (["--ray", "127.0.0.1:6379", "scenarios"], "127.0.0.1:6379", ["scenarios"]),
        (["--ray", "ray://head:10001", "a.yaml", "b.yaml"], "ray://head:10001", ["a.yaml", "b.yaml"]),
        (["--ray", "auto", "-j", "2", "scenarios"], "auto", ["scenarios"]),
        (["--ray", "-j", "2", "scenarios"], "", ["scenarios"]),
        (["scenarios"], None, ["scenarios"]),
    ],
)
def test_ray_takes_an_address_or_none(args: list[str], address: str | None, paths: list[str]) -> None:
    from typer.main import get_command

    from runner.cli import app
    from tests.conftest import REPO

    cwd = os.getcwd()
    os.chdir(REPO)  # (`scenarios` is a folder here: never taken for an address)
    try:
        ctx = get_command(app).commands["test"].make_context("test", args)  # type: ignore[attr-defined]
    finally:
        os.chdir(cwd)
    assert ctx.params["ray"] == address and ctx.params["paths"] == [Path(p) for p in paths]
