"""One run of a suite (`scenario test`): a scenario file's variant, run exactly as `scenario run` runs it,
in a process of its own (its own Zenoh router on a free loopback port, its own run id), and its suite
(verdicts, summary) read back from `--results-json`. The local pool (`-j N`) and the Ray tasks (`--ray`,
`runner.tools.fanout`) both run a variant with `run_variant`: there is no second implementation."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from runner.errors import ScenarioError
from runner.launch import keeper
from runner.tools.report import Suite

STOP_S = 15.0  # a run told to stop (SIGTERM) finishes its recording in ~2 s; then it is killed
WAIT_S = 0.25  # a run is waited for in slices this long (see `_wait`)


@dataclass(frozen=True)
class Variant:
    """A scenario file's run: the file, its variant's index (None without a matrix) and label."""

    file: Path
    index: int | None
    label: str

    @property
    def name(self) -> str:
        """`two_robots[seed=1]`, or the file's stem without a matrix (the table's and JUnit's name)."""
        return f"{self.file.stem}[{self.label}]" if self.label else self.file.stem

    @property
    def stem(self) -> str:
        """The name of its recording and artifacts: `two_robots-3`, or `two_robots` without a matrix."""
        return self.file.stem if self.index is None else f"{self.file.stem}-{self.index}"


def scenario_files(paths: list[Path]) -> list[Path]:
    """The scenario files of `paths`: a folder's *.yaml, sorted, and files as given."""
    files: list[Path] = []
    for p in paths:
        files += sorted(p.glob("*.yaml")) if p.is_dir() else [p]
    return files


def variants_of(files: list[Path]) -> list[Variant]:
    """Every run of the files: one per file, or one per variant of a file's matrix (and sample)."""
    from runner.scenario.loader import load_file
    from runner.scenario.matrix import variants

    out: list[Variant] = []
    for f in files:
        try:
            labels = [label for label, _ in variants(load_file(f))]
        except ScenarioError:
            labels = [""]  # the run itself reports the error
        out += [Variant(f, i if len(labels) > 1 else None, label) for i, label in enumerate(labels)]
    return out


def run_variant(
    variant: Variant,
    record: Path | None,
    *,
    allow_undecided: bool = False,
    timeout_s: float | None = None,
    cwd: Path | None = None,
    die_with_parent: bool = False,
    cancelled: Callable[[], bool] | None = None,
) -> Suite:
    """`scenario run FILE [--variant N]` in a process of its own, recording to `record` (None: no
    recording), and its suite. Over `timeout_s` of wall time the run is stopped as Ctrl-C stops it (its
    recording finished) and its suite is an error. Interrupted here (Ctrl-C, a Ray task cancelled), the run
    is stopped the same way before the interruption goes on, and so it is (then KeyboardInterrupt) when
    `cancelled()` says so (a Ray task cancelled). `die_with_parent`: the run is told to stop if the process
    that started it dies (a Ray worker killed under it)."""
    with tempfile.TemporaryDirectory(prefix="scenario-variant-") as tmp:
        res = Path(tmp) / "results.json"
        cmd = [sys.executable, "-m", "runner.cli", "run", str(variant.file), "-q", "--results-json", str(res)]
        cmd += ["--no-record"] if record is None else ["--record", str(record)]
        if variant.index is not None:
            cmd += ["--variant", str(variant.index)]
        if allow_undecided:
            cmd += ["--allow-undecided"]
        proc = subprocess.Popen(
            cmd,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=cwd,
            # (a run never outlives the Ray worker or `scenario test` that started it)
            preexec_fn=keeper.dies_with_runner(signal.SIGTERM) if die_with_parent else None,
        )
        try:
            out = _wait(proc, timeout_s, cancelled)
        except BaseException:
            _stop(proc)
            raise
        timed_out = out is None
        stdout, stderr = _stop(proc) if out is None else out
        suite = _suite_of(variant, res, proc.returncode, stdout, stderr)
    if timed_out:
        suite.error = f"timed out: still running after {timeout_s:g} s of wall time (--timeout), stopped" + (
            f"\n{suite.error}" if suite.error else ""
        )
    return suite


def _wait(
    proc: subprocess.Popen[str], timeout_s: float | None, cancelled: Callable[[], bool] | None
) -> tuple[str, str] | None:
    """What the run printed once it ended, or None when it is still going after `timeout_s`. It is waited
    for in slices, and `cancelled()` asked between them (KeyboardInterrupt when it says so)."""
    deadline = None if timeout_s is None else time.monotonic() + timeout_s
    while True:
        if cancelled is not None and cancelled():
            raise KeyboardInterrupt
        left = None if deadline is None else deadline - time.monotonic()
        if left is not None and left <= 0:
            return None
        try:
            return proc.communicate(timeout=WAIT_S if left is None else min(WAIT_S, left))
        except subprocess.TimeoutExpired:
            continue


def _suite_of(variant: Variant, res: Path, code: int | None, stdout: str, stderr: str) -> Suite:
    """The run's suite, read back from --results-json (or the process's last words as the suite's
    error)."""
    if res.is_file():
        suite = Suite.from_json(json.loads(res.read_text()))
        # the run's own label: a pose drawn in collision was drawn again there
        suite.name = f"{variant.file.stem}[{suite.label}]" if suite.label else variant.name
        return suite
    why = (stderr.strip() or stdout.strip() or f"exit {code}").splitlines()
    return Suite(variant.name, error="\n".join(why[-12:]))


def _stop(proc: subprocess.Popen[str]) -> tuple[str, str]:
    """Stop a run as Ctrl-C does (SIGTERM: in order, its recording finished), killing it if it is still
    there after STOP_S: what it printed."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
    try:
        return proc.communicate(timeout=STOP_S)
    except subprocess.TimeoutExpired:
        proc.kill()
        return proc.communicate()
