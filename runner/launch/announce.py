"""What `scenario echo`, `scenario pub` and `scenario topics` share: finding a running run, and joining it.

A run announces itself in a small file while it runs (`<tmp>/scenario-runs/<id>.json`, or under
`$SCENARIO_RUNS_DIR`: its id (`<name>-<pid>`, unique on the machine), its name, its endpoints, its recording
and the runner's pid), so the tools find the local run without being told; `--connect` joins any run by
endpoint (another host's, say) and `--run` picks one of several, by id or by name.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import zenoh

from runner.errors import RunError
from runner.wire.transport import make_config, use_run_settings, zenoh_reason


def runs_dir() -> Path:
    """Where runs announce themselves: `$SCENARIO_RUNS_DIR`, else `<tmp>/scenario-runs`."""
    return Path(os.environ.get("SCENARIO_RUNS_DIR") or Path(tempfile.gettempdir()) / "scenario-runs")


@dataclass
class RunInfo:
    name: str
    endpoints: list[str]
    pid: int
    zenoh: dict[str, Any] | None = None  # the run's Zenoh settings (scenario `zenoh:`)
    id: str = ""  # `<name>-<pid>`: unique among the machine's runs
    recording: str | None = None


def announce(
    name: str,
    endpoints: list[str],
    zenoh_settings: dict[str, Any] | None = None,
    recording: str | None = None,
) -> Path:
    """Write the run's discovery file (with the run's Zenoh settings: a tool joining a TLS run needs its
    certificates); the caller removes it at the end (`withdraw`). Readable by this user only."""
    folder = runs_dir()
    folder.mkdir(parents=True, exist_ok=True)
    run_id = f"{name}-{os.getpid()}"
    path = folder / f"{run_id}.json"
    info = {
        "id": run_id,
        "name": name,
        "endpoints": endpoints,
        "pid": os.getpid(),
        "zenoh": zenoh_settings,
        "recording": recording,
    }
    _write(path, info)
    return path


def update_announcement(path: Path | None, **changes: Any) -> None:
    if path is None:
        return
    with contextlib.suppress(OSError, ValueError):
        info = json.loads(path.read_text())
        info.update(changes)
        _write(path, info)


def _write(path: Path, info: dict[str, Any]) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(json.dumps(info))
    tmp.replace(path)  # readers never see half a file


def withdraw(path: Path | None) -> None:
    if path is not None:
        with contextlib.suppress(OSError):
            path.unlink()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def running_runs() -> list[RunInfo]:
    out = []
    folder = runs_dir()
    for path in sorted(folder.glob("*.json")) if folder.is_dir() else []:
        try:
            info = json.loads(path.read_text())
            run = RunInfo(
                str(info["name"]),
                list(info["endpoints"]),
                int(info["pid"]),
                info.get("zenoh"),
                str(info.get("id") or f"{info['name']}-{info['pid']}"),
                info.get("recording"),
            )
        except (OSError, ValueError, KeyError, TypeError):
            continue
        if _alive(run.pid):
            out.append(run)
    return out


def find_run(run: str | None, connect: list[str] | None) -> tuple[str, list[str]]:
    """(run name, endpoints): from `--connect` (then `--run` is needed unless one local run is known), else
    the local run named `run`, else the only local run."""
    runs = running_runs()
    if connect:
        if run is None:
            if len(runs) != 1:
                raise RunError("with --connect, say which run with --run NAME")
            run = runs[0].name
        known = next((r for r in runs if run in (r.id, r.name)), None)
        use_run_settings(known.zenoh if known else None)
        return (known.name if known else run), list(connect)
    chosen = [r for r in runs if run is None or run in (r.id, r.name)]
    if not chosen:
        what = f"no run named {run!r}" if run else "no scenario is running on this machine"
        raise RunError(
            f"{what}; start one with `scenario run FILE`, or join one with --connect ENDPOINT --run NAME"
        )
    if len(chosen) > 1:
        listed = ", ".join(
            f"{r.id} ({r.name}" + (f", recording {r.recording}" if r.recording else "") + ")" for r in chosen
        )
        raise RunError(f"several runs are going: {listed}; pick one with --run ID")
    use_run_settings(chosen[0].zenoh)  # a TLS run: its certificates, for this tool's session too
    return chosen[0].name, [e.replace("0.0.0.0", "127.0.0.1") for e in chosen[0].endpoints]


@contextlib.contextmanager
def joined(endpoints: list[str]) -> Iterator[Any]:
    """A client session on the run's network."""
    try:
        session = zenoh.open(make_config("client", connect=endpoints))
    except zenoh.ZError as e:
        raise RunError(f"cannot reach {', '.join(endpoints)}: {zenoh_reason(e)}") from None
    try:
        yield session
    finally:
        session.close()


def key_of(run: str, topic: str) -> str:
    """`r1/scan` -> `<run>/r1/scan` (a topic already starting with the run's name is kept)."""
    topic = topic.strip("/")
    return topic if topic == run or topic.startswith(run + "/") else f"{run}/{topic}"


def field_of(data: Any, path: str) -> Any:
    """`pose.pose.position.x` or `ranges[3]` inside plain message data."""
    value = data
    for part in path.replace("]", "").replace("[", ".").split("."):
        if not part:
            continue
        if isinstance(value, list):
            value = value[int(part)]
        elif isinstance(value, dict) and part in value:
            value = value[part]
        else:
            raise RunError(f"no field {part!r} in {path!r}")
    return value


def wait_matched(pub: Any, timeout_s: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while not pub.matching_status.matching:
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True
