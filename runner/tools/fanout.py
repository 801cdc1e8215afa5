"""`scenario test --ray`: a suite fanned out on a Ray cluster, one Ray task per variant.

Each task runs its variant with `runner.tools.suite.run_variant`, the very code `scenario test -j N` runs
locally: `scenario run` in a process of its own on the worker's node (its own Zenoh router on a free
loopback port there, its own run id), judged there; the task returns the suite, and the recording, report
and plot (sent back, or written by the worker to an fsspec URL: `runner.tools.artifacts`).

- The scenario files' folder (robots, meshes, worlds, node scripts) is the job's `runtime_env`
  `working_dir`: Ray ships it to each node, and the runs start there (`shipped`). The project itself
  comes from the cluster's environment (an image with it installed, or `pip` in the job's runtime_env:
  docs/ray.md).
- Each task asks a CPU per process of its run (worlds, renderers, nodes, the bridge), a GPU for a run with
  cameras (`--gpus`), or what the scenario's `resources:` says; tasks are spread over the nodes.
- A worker that dies mid-run: Ray runs the task again (`max_retries`), and the suite says so (the
  `ray.attempts` property). A run over `--timeout` is stopped and is an error. Ctrl-C on the driver cancels
  every task (their runs stop in order) and returns what finished.
- A small actor (`_Ledger`) hears each attempt start and end: the progress bar's running count, the
  attempts, the node each run is on.

Ray is an optional extra (`pip install "scenario-runner[ray]"`); nothing here imports it at module level.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import shutil
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from runner.errors import RunError, ScenarioError
from runner.tools import artifacts
from runner.tools.report import Suite
from runner.tools.suite import Variant, run_variant

RETRIES = 2  # a task whose worker died is run again, this many times at most
CANCEL_WAIT_S = 30.0  # after Ctrl-C: how long cancelled runs get to stop in order
CAMERAS = ("camera", "depth_camera")
EXCLUDES = ["__pycache__/", ".git/", "*.mcap"]  # never shipped with a scenario's folder
CANCELLED = "cancelled: Ctrl-C on the driver"
INSTALL_HINT = 'pip install "scenario-runner[ray]" (in a checkout: pip install -e ".[ray]")'
_LOOPBACK = re.compile(r"^(?:ray://)?(?:127\.\d+\.\d+\.\d+|localhost|\[::1\])(?::\d+)?$")


def import_ray() -> Any:
    """The `ray` module, or a one-line error saying how to install it."""
    try:
        import ray
    except ImportError:
        raise RunError(f"--ray needs Ray, an optional extra: {INSTALL_HINT}") from None
    return ray


def shipped(files: list[Path], where: str) -> tuple[Path, dict[str, Any]]:
    """(the folder every worker gets, the job's runtime_env that ships it): the scenario files' common
    folder, as Ray's `working_dir` (robots, meshes, worlds and node scripts with it; recordings and the
    artifacts folder left out). Under a Ray job that ships a working_dir of its own (`ray job submit
    --working-dir`, a RayJob's runtimeEnvYAML), the scenarios come with it: they must lie in it."""
    folders = [f.resolve().parent for f in files]
    job_env = _job_runtime_env()
    if job_env.get("working_dir"):
        root = Path.cwd().resolve()
        outside = [str(f) for f, d in zip(files, folders, strict=True) if not d.is_relative_to(root)]
        if outside:
            raise RunError(
                f"{outside[0]}: not in the Ray job's working_dir ({root}), which is what the workers get"
            )
        return root, {}
    root = Path(os.path.commonpath(folders))
    excludes = list(EXCLUDES)
    if not artifacts.is_url(where) and Path(where).resolve().is_relative_to(root):
        excludes.append("/" + Path(where).resolve().relative_to(root).as_posix() + "/")
    return root, {"working_dir": str(root), "excludes": excludes}


def _job_runtime_env() -> dict[str, Any]:
    """The runtime_env of the Ray job this driver runs as (none outside a job)."""
    import json

    text = os.environ.get("RAY_JOB_CONFIG_JSON_ENV_VAR", "")
    try:
        return dict(json.loads(text).get("runtime_env") or {}) if text else {}
    except (ValueError, AttributeError):
        return {}


def connect(address: str, runtime_env: dict[str, Any]) -> Any:
    """`ray.init` for `--ray [ADDRESS]` ("": Ray's own rules: RAY_ADDRESS, else a cluster started on this
    machine, else a new one here), with the job's runtime_env: the ray module, connected.

    A cluster on this machine's loopback (an address on 127.0.0.1, or a new local one) is kept on it: Ray
    2.60 replaces 127.0.0.1 by the machine's outward address (and listens there) unless
    RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0 says the cluster is one machine's (docs/ray.md)."""
    target = address or os.environ.get("RAY_ADDRESS", "")
    if not target or _LOOPBACK.match(target):
        os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")  # (read when ray is imported)
    ray = import_ray()
    options: dict[str, Any] = {"log_to_driver": False, "logging_level": logging.WARNING}
    if not target:
        options.update(include_dashboard=False, _node_ip_address="127.0.0.1")
    try:
        ray.init(address=address or None, runtime_env=runtime_env or None, **options)
    except (ConnectionError, ValueError, RuntimeError, OSError) as e:
        where = address or os.environ.get("RAY_ADDRESS") or "a new local cluster"
        token = (
            "\n  hint:     a cluster with Ray's token authentication (a head started where "
            "~/.ray/auth_token exists) also needs RAY_AUTH_MODE=token here, and its token"
            if isinstance(e, ConnectionError) and not os.environ.get("RAY_AUTH_MODE")
            else ""
        )
        first = str(e).strip().splitlines()[0] if str(e).strip() else ""
        raise RunError(
            f"--ray {address}: cannot start the suite on {where}: {type(e).__name__}: {first}\n"
            "  hint:     the head's address as `ray start --head` printed it (host:port), or none for a "
            "cluster on this machine; a scenario folder small enough to ship (recordings are left out)"
            + token
        ) from None
    return ray


@dataclass
class Job:
    """A variant as the cluster runs it: its folder (the task's working_dir), what it asks of the
    cluster, and its matrix values (for the summary page)."""

    variant: Variant
    asks: dict[str, Any]
    values: dict[str, str] = field(default_factory=dict)
    key: str = ""  # its artifacts' folder and name: the variant's stem, made unique in the suite


@dataclass
class Outcome:
    """A job's end: its suite (verdicts, summary), the node it ran on, the attempts it took, and where
    its recording, report and plot are ({file name: path or URL})."""

    job: Job
    suite: Suite
    node: str = ""
    attempts: int = 0
    files: dict[str, str] = field(default_factory=dict)
    wall_s: float = 0.0  # the run's process from start to end, on the worker (its start included)


def cluster_info(ray: Any) -> dict[str, Any]:
    """What the cluster has: its alive nodes ({node id: (address, resources)}) and their resources in all."""
    nodes = {n["NodeID"]: (n["NodeManagerAddress"], n["Resources"]) for n in ray.nodes() if n.get("Alive")}
    return {"nodes": nodes, "total": ray.cluster_resources()}


def plan_jobs(variants: list[Variant], gpus: str, cluster: dict[str, Any]) -> tuple[list[Job], list[str]]:
    """Each variant compiled here (as its run will compile it there) for what it asks of the cluster:
    (the jobs, notes to print). A variant that does not compile asks one CPU: its run says what is wrong,
    as it does locally. What no node of the cluster has is an error here, before anything is sent."""
    from runner.compile.placement import load_drawn_plan
    from runner.scenario.loader import load_file
    from runner.scenario.matrix import variant_values
    from runner.scenario.matrix import variants as expand

    docs: dict[Path, tuple[list[Any], list[dict[str, str]]]] = {}
    jobs: list[Job] = []
    notes: list[str] = []
    taken: set[str] = set()
    for v in variants:
        if v.file not in docs:
            try:
                doc = load_file(v.file)
                docs[v.file] = (expand(doc), variant_values(doc))
            except ScenarioError:
                docs[v.file] = ([], [])
        found, values = docs[v.file]
        i = v.index or 0
        plan = None
        if i < len(found):
            try:
                plan = load_drawn_plan(found[i][1])
            except ScenarioError:
                plan = None
        key = v.stem if v.stem not in taken else f"{v.stem}-{len(taken)}"  # (x.yaml of two folders)
        taken.add(key)
        jobs.append(Job(v, _asks(v, plan, gpus, cluster, notes), values[i] if i < len(values) else {}, key))
    return jobs, notes


def _asks(v: Variant, plan: Any, gpus: str, cluster: dict[str, Any], notes: list[str]) -> dict[str, Any]:
    """What one run of `plan` asks of the cluster: {num_cpus, num_gpus, resources}."""
    own = (plan.resources if plan is not None else None) or {}
    procs, cameras = _processes(plan) if plan is not None else (1.0, False)
    biggest = max((r.get("CPU", 0.0) for _a, r in cluster["nodes"].values()), default=0.0)
    total = cluster["total"]
    cpus = own.get("num_cpus")
    if cpus is None:
        cpus = procs
        if biggest and cpus > biggest:
            note = (
                f"{v.file.name}: a CPU for each of a run's {procs:g} processes would be more than any node "
                f"has: each run asks {biggest:g} (`resources: {{num_cpus: N}}` says otherwise)"
            )
            notes += [] if note in notes else [note]  # (once for a file's variants)
            cpus = biggest
    elif cpus > biggest:
        raise RunError(
            f"{v.file}: resources.num_cpus {cpus:g}: no node of the cluster has that many CPUs "
            f"(the largest has {biggest:g})"
        )
    n_gpus = own.get("num_gpus")
    if n_gpus is None:
        n_gpus = 0.0 if not cameras else (min(1.0, total.get("GPU", 0.0)) if gpus == "auto" else float(gpus))
    if n_gpus > total.get("GPU", 0.0):
        raise RunError(
            f"{v.file}: {n_gpus:g} GPU(s) asked for a run with cameras; the cluster has "
            f"{total.get('GPU', 0.0):g}\n  hint:     --gpus 0 (cameras render on the CPU), or a cluster "
            "with GPUs"
        )
    custom = dict(own.get("custom") or {})
    missing = [name for name in custom if name not in total]
    if missing:
        raise RunError(
            f"{v.file}: resources.custom: no node of the cluster has {', '.join(missing)} "
            f"(it has: {', '.join(sorted(total))})"
        )
    return {"num_cpus": cpus, "num_gpus": n_gpus, "resources": custom}


def _processes(plan: Any) -> tuple[float, bool]:
    """(how many processes a run of `plan` has besides its runner: worlds, renderers, nodes, the bridge;
    whether it has cameras)."""
    parts = plan.worlds or [plan]
    cameras = any(p.type in CAMERAS for part in parts for r in part.robots for p in r.plugins)
    renderers = len(parts) if cameras and plan.renderers != "world" else 0
    bridge = 1 if plan.bridges or getattr(plan, "ros2", None) else 0
    return float(len(parts) + renderers + len(plan.nodes) + bridge), cameras


@dataclass
class Settings:
    """How each run goes: recorded or not, `--allow-undecided`, `--timeout`, and where its files go."""

    record: bool
    allow_undecided: bool
    timeout_s: float | None
    where: str  # a local folder, or an fsspec URL the workers write to
    root: Path  # the folder the workers get (`shipped`): scenario files are named relative to it


Progress = Callable[[int, int, int], None]  # (done, running, failed)


def run_jobs(
    ray: Any, jobs: list[Job], settings: Settings, on_progress: Progress, on_done: Callable[[Outcome], None]
) -> tuple[list[Outcome], bool]:
    """Every job as a Ray task, until each has ended: (their outcomes in the jobs' order, whether Ctrl-C
    cut the suite short: then every task still going was cancelled, its run stopped in order)."""
    ledger = ray.remote(num_cpus=0)(_Ledger).remote()
    task = ray.remote(_task)
    pending: dict[Any, Job] = {}
    try:
        for job in jobs:
            pending[_submit(task, job, settings, ledger)] = job
    except Exception as e:  # refused by the cluster
        for ref in pending:
            ray.cancel(ref)
        raise RunError(f"cannot send the suite to the cluster: {type(e).__name__}: {e}") from None
    ended: dict[str, Outcome] = {}
    interrupted = False
    try:
        _wait(ray, pending, ledger, settings, ended, on_progress, on_done)
    except KeyboardInterrupt:
        interrupted = True
        _cancel(ray, pending, settings, ended, on_done)
    seen = ray.get(ledger.seen.remote(), timeout=30)
    nodes = cluster_info(ray)["nodes"]
    for outcome in ended.values():
        node, outcome.attempts = seen.get(outcome.job.key, ("", 0))
        outcome.node = node
        address = nodes.get(node, ("",))[0]
        outcome.suite.properties.update(
            {"ray.node": node, "ray.node_address": address, "ray.attempts": str(outcome.attempts)}
        )
    ray.kill(ledger)
    return [ended[j.key] for j in jobs if j.key in ended], interrupted


def _submit(task: Any, job: Job, settings: Settings, ledger: Any) -> Any:
    v = job.variant
    spec = {
        "key": job.key,
        "file": v.file.resolve().relative_to(settings.root).as_posix(),
        "index": v.index,
        "label": v.label,
        "record": settings.record,
        "allow_undecided": settings.allow_undecided,
        "timeout_s": settings.timeout_s,
        "url": settings.where if artifacts.is_url(settings.where) else "",
    }
    return task.options(
        num_cpus=job.asks["num_cpus"],
        num_gpus=job.asks["num_gpus"],
        resources=job.asks["resources"],
        max_retries=RETRIES,
        retry_exceptions=False,
        scheduling_strategy="SPREAD",
        name=f"scenario {v.name}"[:200],
    ).remote(spec, ledger)


def _wait(
    ray: Any,
    pending: dict[Any, Job],
    ledger: Any,
    settings: Settings,
    ended: dict[str, Outcome],
    on_progress: Progress,
    on_done: Callable[[Outcome], None],
) -> None:
    failed = 0
    while pending:
        ready, _ = ray.wait(list(pending), num_returns=1, timeout=0.5)
        for ref in ready:
            outcome = _outcome(ray, ref, pending.pop(ref), settings)
            ended[outcome.job.key] = outcome
            failed += not outcome.suite.passed
            on_done(outcome)
        running = ray.get(ledger.running.remote(), timeout=30)
        on_progress(len(ended), len(set(running) - set(ended)), failed)


def _cancel(
    ray: Any,
    pending: dict[Any, Job],
    settings: Settings,
    ended: dict[str, Outcome],
    on_done: Callable[[Outcome], None],
) -> None:
    """Ctrl-C: cancel every task still going (a running one stops its run in order, its recording kept),
    give them CANCEL_WAIT_S to end, and count each as cancelled unless it finished meanwhile."""
    for ref in pending:
        ray.cancel(ref)
    deadline = time.monotonic() + CANCEL_WAIT_S
    with contextlib.suppress(KeyboardInterrupt):  # a second Ctrl-C: wait no more
        while pending and time.monotonic() < deadline:
            ready, _ = ray.wait(list(pending), num_returns=1, timeout=0.5)
            for ref in ready:
                outcome = _outcome(ray, ref, pending.pop(ref), settings)
                ended[outcome.job.key] = outcome
                on_done(outcome)
    for ref, job in pending.items():  # still there: its worker is ended (its run told to stop)
        ray.cancel(ref, force=True)
        outcome = Outcome(job, Suite(job.variant.name, error=CANCELLED))
        ended[job.key] = outcome
        on_done(outcome)


def _outcome(ray: Any, ref: Any, job: Job, settings: Settings) -> Outcome:
    """A task's end: the run's suite and its files (written here, or where the worker wrote them), or
    the error that ended the task."""
    name = job.variant.name
    try:
        got = ray.get(ref)
    except ray.exceptions.TaskCancelledError:
        return Outcome(job, Suite(name, error=CANCELLED))
    except (ray.exceptions.WorkerCrashedError, ray.exceptions.NodeDiedError) as e:
        why = f"{type(e).__name__}: the worker running it died {RETRIES + 1} times"
        return Outcome(job, Suite(name, error=why))
    except ray.exceptions.RayError as e:
        lines = [line for line in str(e).strip().splitlines() if line.strip()]
        return Outcome(job, Suite(name, error=f"{type(e).__name__}: {lines[-1] if lines else ''}"))
    suite = Suite.from_json(got["suite"])
    if "links" in got:
        files = dict(got["links"])
    else:
        files = artifacts.save(Path(settings.where), job.key, got["files"])
    suite.mcap = files.get(f"{job.key}.mcap")
    return Outcome(job, suite, files=files, wall_s=float(got.get("wall_s", 0.0)))


class _Ledger:
    """An actor that hears each attempt of each task start (on which node) and end."""

    def __init__(self) -> None:
        self._seen: dict[str, tuple[str, int]] = {}
        self._running: set[str] = set()

    def started(self, key: str, node: str) -> int:
        attempt = self._seen.get(key, ("", 0))[1] + 1
        self._seen[key] = (node, attempt)
        self._running.add(key)
        return attempt

    def finished(self, key: str) -> None:
        self._running.discard(key)

    def running(self) -> list[str]:
        return sorted(self._running)

    def seen(self) -> dict[str, tuple[str, int]]:
        return dict(self._seen)


def _task(spec: dict[str, Any], ledger: Any) -> dict[str, Any]:
    """One variant, on a worker: run and judged by `run_variant` in the task's working_dir (the scenario's
    folder, shipped by Ray), its report written beside its recording, and the files sent back or written
    to the artifacts URL."""
    import ray

    context = ray.get_runtime_context()
    ray.get(ledger.started.remote(spec["key"], context.get_node_id()))
    here = Path.cwd()
    variant = Variant(here / spec["file"], spec["index"], spec["label"])
    scratch_root = Path(context.get_temp_dir()) / "scenario-runs"
    scratch_root.mkdir(parents=True, exist_ok=True)
    scratch = Path(tempfile.mkdtemp(prefix=f"{spec['key']}-", dir=scratch_root))
    try:
        record = scratch / f"{spec['key']}.mcap" if spec["record"] else None
        started = time.perf_counter()
        try:
            suite = run_variant(
                variant,
                record,
                allow_undecided=spec["allow_undecided"],
                timeout_s=spec["timeout_s"],
                cwd=here,
                die_with_parent=True,
                cancelled=context.is_canceled,  # (ray.cancel: the run stopped in order, its recording kept)
            )
        except KeyboardInterrupt:
            suite = Suite(variant.name, error=CANCELLED)
        wall_s = time.perf_counter() - started
        if record is not None and record.is_file():
            _report(record)
        files = sorted(p for p in scratch.iterdir() if p.is_file())
        if spec["url"]:
            links = artifacts.upload(spec["url"], spec["key"], files)
            return {"suite": suite.to_json(), "wall_s": wall_s, "links": links}
        return {"suite": suite.to_json(), "wall_s": wall_s, "files": {p.name: p.read_bytes() for p in files}}
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
        ledger.finished.remote(spec["key"])


def _report(mcap: Path) -> None:
    """The run's HTML page beside its recording (a convenience: never a failed run)."""
    from runner.tools.html import write_report

    with contextlib.suppress(Exception):
        write_report(mcap, mcap.with_suffix(".html"))
