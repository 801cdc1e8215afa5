"""`scenario report`: one self-contained HTML page about a run, looked at in headless Chromium."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import SCENARIOS, run_cli, scenario_cmd


@pytest.mark.timeout(180)
def test_the_report_shows_the_verdict_the_plots_and_the_topics(tmp_path: Path) -> None:
    from PIL import Image

    mcap = tmp_path / "demo.mcap"
    r = subprocess.run(
        scenario_cmd("run", str(SCENARIOS / "two_robots.yaml"), "--record", str(mcap), "-q"),
        capture_output=True,
        text=True,
        timeout=90,
    )
    assert r.returncode == 0, r.stderr
    page = tmp_path / "report.html"
    # the scenario comes from the recording itself: no --scenario
    r = run_cli("report", str(mcap), "-o", str(page), timeout=60)
    assert r.returncode == 0, r.stderr
    assert "9/9 assertions pass, 5 signal plot(s)" in r.stdout  # speed, distance, tilt, 2 topic rates
    text = page.read_text()
    assert "9 of 9 assertions pass" in text
    for name in ("r1_reaches_its_corner", "lidar_at_10_hz", "r2_under_half_a_metre_per_second"):
        assert f"<td>{name}</td>" in text
    assert text.count("<svg") == 5 and 'src="data:image/png;base64,' in text
    assert "two_robots/r1/scan" in text and "_truth" not in text  # topics, helpers hidden
    assert not re.search(r'(src|href)="(https?:)?//', text)  # self-contained: nothing fetched

    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    assert chromium, "headless Chromium is needed (Debian: apt-get install chromium; .ci/run installs it)"
    shot = tmp_path / "shot.png"
    subprocess.run(
        [chromium, "--headless", "--no-sandbox", "--disable-gpu", f"--screenshot={shot}",
         "--window-size=1100,1800", page.as_uri()],
        capture_output=True, timeout=90, check=True,
    )  # fmt: skip
    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    r_, g_, b_ = img[..., 0], img[..., 1], img[..., 2]
    # the speed plot's lines (#d62728 red, #1f77b4 blue) and the verdict badge (#1a7f37 green) are drawn
    red = (abs(r_ - 0xD6) < 30) & (abs(g_ - 0x27) < 40) & (abs(b_ - 0x28) < 40)
    blue = (abs(r_ - 0x1F) < 30) & (abs(g_ - 0x77) < 40) & (abs(b_ - 0xB4) < 40)
    green = (abs(r_ - 0x1A) < 20) & (abs(g_ - 0x7F) < 20) & (abs(b_ - 0x37) < 20)
    assert red.sum() > 200 and blue.sum() > 200 and green.sum() > 200, (red.sum(), blue.sum(), green.sum())
