"""Shared test helpers: inline scenarios, the real CLI in a subprocess, MCAP reading."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path
from typing import Any

import pytest

import runner  # noqa: F401  (headless GL backend chosen before any test module imports mujoco)

REPO = Path(__file__).resolve().parents[1]
SCENARIOS = REPO / "scenarios"
DIFFBOT = SCENARIOS / "robots" / "diffbot.urdf.xacro"


@pytest.fixture(scope="session", autouse=True)
def _own_folders(tmp_path_factory: pytest.TempPathFactory):
    """The session's own cache folder (converted meshes, decomposed meshes) and its own folder where runs
    announce themselves, inherited by every process the tests start: the user's cache is neither read nor
    written, and the tools never see a run another suite or the user started beside this one."""
    saved = {k: os.environ.get(k) for k in ("XDG_CACHE_HOME", "SCENARIO_RUNS_DIR")}
    os.environ["XDG_CACHE_HOME"] = str(tmp_path_factory.mktemp("cache"))
    os.environ["SCENARIO_RUNS_DIR"] = str(tmp_path_factory.mktemp("runs"))
    yield
    for key, value in saved.items():
        if value is None:
            os.environ.pop(key, None)
        else:
            os.environ[key] = value


@pytest.fixture
def write_scenario(tmp_path: Path):
    """Write an inline scenario (dedented); `{diffbot}` is replaced by the project's robot file."""

    def write(text: str, name: str = "scenario.yaml") -> Path:
        path = tmp_path / name
        path.write_text(textwrap.dedent(text).replace("{diffbot}", str(DIFFBOT)).lstrip())
        return path

    return write


def wait_recorded(mcap: Path, topic: str, at_least: int, deadline: float, every_s: float = 0.2) -> bool:
    """Wait (until `deadline`, a time.monotonic() value) for a recording being written to hold `at_least`
    messages on `topic`, read from its whole chunks: a run's progress, however long its start took."""
    from runner.record import read_summary

    while time.monotonic() < deadline:
        counts = {t["topic"]: t["count"] for t in read_summary(mcap)["topics"]} if mcap.exists() else {}
        if counts.get(topic, 0) >= at_least:
            return True
        time.sleep(every_s)
    return False


def processes_of(root: int, pattern: str, *, direct: bool = False) -> list[int]:
    """The processes whose command line matches `pattern` (pgrep -f) that `root` started: its children
    (`direct`), else any descendant. Another suite running beside this one has processes of the same
    names; a process forking a helper has, until the helper execs, a copy of its command line."""
    out = subprocess.run(["pgrep", "-f", pattern], capture_output=True, text=True).stdout
    found = []
    for pid in (int(p) for p in out.split()):
        try:
            parents = []
            p = pid
            while p > 1 and len(parents) < 64:
                status = Path(f"/proc/{p}/status").read_text()
                p = int(next(ln.split()[1] for ln in status.splitlines() if ln.startswith("PPid:")))
                parents.append(p)
        except (OSError, StopIteration, ValueError):
            continue
        if (parents[:1] == [root]) if direct else (root in parents):
            found.append(pid)
    return found


def scenario_cmd(*args: str) -> list[str]:
    return [sys.executable, "-m", "runner.cli", *args]


def start_cli(*args: str) -> subprocess.Popen[str]:
    """`scenario ARGS` started in the background, its output unbuffered (read it line by line as it
    comes); the caller waits with a timeout and kills it if it is still there."""
    return subprocess.Popen(
        scenario_cmd(*args),
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )


def run_cli(*args: str, timeout: float = 60, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    return subprocess.run(
        scenario_cmd(*args), capture_output=True, text=True, timeout=timeout, cwd=cwd or REPO, env=env
    )


def _decoder(factories: list[Any], encoding: str, schema: Any) -> Any:
    from runner.wire import msgs

    for factory in factories:
        try:
            decoder = factory.decoder_for(encoding, schema)
        except Exception:
            if "_" not in schema.name.rsplit("/", 1)[-1]:
                raise
            return lambda data, name=schema.name: msgs.decode(data, name)
        if decoder is not None:
            return decoder
    raise AssertionError(f"no decoder for {schema.name} ({encoding})")


def read_mcap(path: Path) -> list[tuple[str, str, int, Any]]:
    """(topic, type, log_time, decoded message) for every message, decoded by mcap_ros2 (an independent
    decoder of the ros2msg/CDR format, not ours) or, for the Foxglove scene, mcap_protobuf. A service's or
    action's messages (`pkg/srv/Name_Event`, `pkg/action/Name_FeedbackMessage`), whose names mcap_ros2's
    rosidl parser refuses (`^[A-Z][A-Za-z0-9]*$`, as it refuses those of rosbag2's own recordings), are
    decoded by rosbags from the same bytes."""
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory as ProtobufDecoders
    from mcap_ros2.decoder import DecoderFactory

    out = []
    factories = [DecoderFactory(), ProtobufDecoders()]
    decoders: dict[int, Any] = {}
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            assert schema is not None
            if schema.id not in decoders:
                decoders[schema.id] = _decoder(factories, channel.message_encoding, schema)
            decoded = decoders[schema.id](message.data)
            out.append((channel.topic, schema.name, message.log_time, decoded))
    return out
