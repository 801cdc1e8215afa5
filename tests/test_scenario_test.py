"""`scenario test` over every example, JUnit XML in the common shape; the pytest plugin."""

from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from tests.conftest import REPO, SCENARIOS, read_mcap, run_cli


@pytest.mark.timeout(400)
def test_all_examples_pass_their_assertions_with_junit(tmp_path: Path):
    """Every example (and each variant of a matrix) runs through the real CLI in processes, two at a time,
    records a file an independent decoder reads, and passes its assertions; the JUnit report says so."""
    junit, out = tmp_path / "out.xml", tmp_path / "rec"
    proc = run_cli("test", str(SCENARIOS), "-j", "2", "--out", str(out), "--junit", str(junit), timeout=380)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    recordings = sorted(out.rglob("*.mcap"))
    recorded = {p.stem.split("[")[0].split("-")[0] for p in recordings}
    assert {p.stem for p in SCENARIOS.glob("*.yaml")} <= recorded, (recorded, recordings)
    for path in recordings:
        assert read_mcap(path), path
    root = ET.parse(junit).getroot()
    assert root.tag == "testsuites"
    suites = root.findall("testsuite")
    # a matrix's variants are suites of their own: `random_start[sample=0,robots[0].pose=...]`
    assert {s.get("name").split("[")[0] for s in suites} == {p.stem for p in SCENARIOS.glob("*.yaml")}
    assert sum(s.get("name").startswith("random_start[sample=") for s in suites) == 4
    for s in suites:
        cases = s.findall("testcase")
        assert cases and int(s.get("tests", "0")) == len(cases)  # every example carries assertions
        assert all(c.get("classname") == s.get("name") and c.get("name") for c in cases)
        assert s.find("testcase/failure") is None and s.get("failures") == "0"


@pytest.mark.timeout(120)
def test_a_tightened_bound_fails_the_run_and_names_it(tmp_path: Path):
    text = (SCENARIOS / "two_robots.yaml").read_text().replace("min: 2.7, max: 3.3", "min: 2.7, max: 2.9")
    text = text.replace("robots/diffbot.urdf.xacro", str(SCENARIOS / "robots" / "diffbot.urdf.xacro"))
    path = tmp_path / "tightened.yaml"
    path.write_text(text)
    junit = tmp_path / "j.xml"
    proc = run_cli("test", str(path), "--no-record", "--junit", str(junit))
    assert proc.returncode == 1
    failure = ET.parse(junit).getroot().find(".//testcase[@name='r1_drives_about_3_m']/failure")
    assert failure is not None
    message = failure.get("message", "")
    # a path only grows: decided when it went past the bound (~13.5 s, of the 2.995 m it drives in 20 s)
    assert "r1_drives_about_3_m" in message and "path length out of bounds" in message, message
    at = float(message.split("failed at t=")[1].split(" s")[0])
    value = float(message.split("value ")[1].split(" m")[0])
    assert 10 < at < 20 and 2.9 < value < 2.95


@pytest.mark.timeout(120)
def test_pytest_collects_scenarios_with_assertions():
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(SCENARIOS / "two_robots.yaml")],
        capture_output=True,
        text=True,
        timeout=110,
        cwd=REPO,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "9 passed" in proc.stdout


@pytest.mark.timeout(120)
def test_scenario_test_writes_and_links_a_report_per_scenario(tmp_path: Path):
    out = tmp_path / "runs"
    proc = run_cli("test", str(SCENARIOS / "two_robots.yaml"), "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    page = out / "two_robots.html"
    assert page.is_file() and "9 of 9 assertions pass" in page.read_text()
    assert "two_robots.html" in proc.stdout  # the table's report column


@pytest.mark.timeout(120)
def test_a_run_over_its_timeout_is_stopped_and_reported_as_an_error(write_scenario, tmp_path: Path):
    """--timeout without --ray (the same code runs each variant on Ray): the run is stopped as Ctrl-C stops
    it, its recording finished, and its suite is an error; the other variant passes."""
    path = write_scenario(
        """
        name: slow
        duration: 1.0
        rate: realtime
        robots:
          - {name: r1, description: {file: "{diffbot}"}, pose: {xyz: [0, 0, 0.06]}, plugins: [{type: diff_drive}]}
        matrix:
          duration: [1.0, 600.0]
        assertions:
          - {name: stays_near, type: stay_within, robot: r1, region: {center: [0, 0], radius: 1}}
        """
    )
    junit, out = tmp_path / "j.xml", tmp_path / "runs"
    proc = run_cli(
        "test", str(path), "-j", "2", "--timeout", "10", "--out", str(out), "--junit", str(junit), timeout=100
    )
    assert proc.returncode == 1, proc.stdout + proc.stderr
    suites = {s.get("name"): s for s in ET.parse(junit).getroot().findall("testsuite")}
    short, long = suites[f"{path.stem}[duration=1.0]"], suites[f"{path.stem}[duration=600.0]"]
    assert short.get("errors") == "0" and short.get("failures") == "0"
    error = long.find("testcase[@name='run']/error")
    assert error is not None and "timed out: still running after 10 s of wall time (--timeout), stopped" in (
        error.text or ""
    )
    from runner.record import read_summary

    assert read_summary(out / f"{path.stem}-1.mcap")["topics"]  # finished, readable
