"""Ctrl-C and SIGTERM at any moment of a run (runner.launch.supervisor): importing, compiling, starting,
running, stopping, draining. Whenever it comes, `scenario run` ends within 2 s with 130 (SIGINT) or 143
(SIGTERM), without a traceback, and a recording that had begun is complete and readable, noting how the
run ended. The moments are told by the supervisor itself (`SCENARIO_TRACE=states` prints each state as the
run enters it), not guessed from timing, except the earliest two (before the supervisor exists)."""

from __future__ import annotations

import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import pytest

from tests.conftest import REPO, SCENARIOS, scenario_cmd

STOP_S = 2.0  # the most a stop may take, from the signal to the command's exit


def _start(mcap: Path, duration: float) -> tuple[subprocess.Popen[str], list[str], threading.Event]:
    proc = subprocess.Popen(
        scenario_cmd(
            "run",
            str(SCENARIOS / "two_robots.yaml"),
            "--rate=realtime",
            f"--duration={duration}",
            f"--record={mcap}",
        ),
        cwd=REPO,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1", SCENARIO_TRACE="states"),
    )
    lines: list[str] = []
    changed = threading.Event()

    def read() -> None:
        assert proc.stderr is not None
        for line in proc.stderr:
            lines.append(line.rstrip())
            changed.set()

    threading.Thread(target=read, daemon=True).start()
    return proc, lines, changed


def _wait_for_state(
    proc: subprocess.Popen[str], lines: list[str], changed: threading.Event, state: str
) -> None:
    deadline = time.monotonic() + 90  # a loaded machine starts slowly
    while f"[supervisor] {state}" not in lines:
        assert proc.poll() is None, f"the run ended before {state}:\n" + "\n".join(lines)
        assert time.monotonic() < deadline, f"never {state}:\n" + "\n".join(lines)
        changed.wait(0.05)
        changed.clear()


def _ended_note(mcap: Path) -> str:
    """The recording read through by the mcap library: its summary, every message, the run's note."""
    from mcap.reader import make_reader

    with open(mcap, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None, "no summary: the file was not finished"
        count = sum(1 for _ in reader.iter_messages())
        assert summary.statistics is not None and count == summary.statistics.message_count
        notes = {m.name: m.metadata for m in reader.iter_metadata()}
    return notes["scenario"]["ended"]


CASES = [
    # (signal, when: seconds after launch or a state the supervisor enters, the run's duration)
    ("SIGINT", 0.1, 30.0),  # importing
    ("SIGTERM", 0.5, 30.0),  # importing or compiling
    ("SIGINT", "starting", 30.0),
    ("SIGTERM", "running", 30.0),
    ("SIGINT", "stopping", 1.0),  # the end of time came: the worlds are stopping
    ("SIGTERM", "draining", 1.0),
    ("SIGINT", "running,stopping", 30.0),  # twice: the second hurries the stop
]


@pytest.mark.timeout(150)
@pytest.mark.parametrize(("sig", "when", "duration"), CASES, ids=[f"{s}-{w}" for s, w, _ in CASES])
def test_a_signal_at_any_moment_stops_in_order(tmp_path: Path, sig: str, when: str | float, duration: float):
    mcap = tmp_path / "run.mcap"
    signum = getattr(signal, sig)
    proc, lines, changed = _start(mcap, duration)
    try:
        if isinstance(when, float):
            time.sleep(when)
        else:
            moments = when.split(",")
            for moment in moments[:-1]:
                _wait_for_state(proc, lines, changed, moment)
                proc.send_signal(signum)
            _wait_for_state(proc, lines, changed, moments[-1])
        sent = time.monotonic()
        proc.send_signal(signum)
        proc.wait(timeout=30)
        took = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    time.sleep(0.2)  # the reader thread takes the last lines
    err = "\n".join(lines)
    assert proc.returncode == (130 if signum == signal.SIGINT else 143), err
    assert took < STOP_S, f"{took:.2f} s from the signal to the exit\n{err}"
    assert "Traceback" not in err, err
    began = "[supervisor] starting" in lines
    if isinstance(when, str):
        assert began
    if mcap.exists():  # a recording begun (or being created) is whole
        expected = {"interrupted" if signum == signal.SIGINT else "terminated"}
        if when in ("stopping", "draining"):  # the run had reached its end of time: the signal may come
            expected.add("completed")  # after the note was written (the states pass in milliseconds)
        assert _ended_note(mcap) in expected, err
