"""Honest limits, measured (issue 35): large legitimate inputs against the limits that refuse the rest.

- a 20,000-entry timeline (1.4 MB of plain YAML, no anchor): `scenario validate`'s path (read, schema,
  compile with each entry's message data checked), against the 5 s target;
- URDF chains of 500, 1,000, 2,000 and 10,000 hinged links and 3,000 links on fixed joints (a star and a
  chain): `scenario validate` in its own process, wall time and peak resident memory, against 60 s and 2 GB
  (MuJoCo compiles no tree deeper than 1023 bodies: the deeper ones are refused, at once, at their line);
- a 5 M-triangle binary STL (a smooth sphere and random triangles) as a robot's collision mesh: simplified
  to the budget within 60 s and 2 GB; the same as OBJ is refused before it is parsed.

Each figure is measured in the same run; the targets are the issue's. The generators are used by
tests/test_limits.py too."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DIFFBOT = REPO / "scenarios" / "robots" / "diffbot.urdf.xacro"
_STL = np.dtype([("normal", "<f4", (3,)), ("v", "<f4", (3, 3)), ("attr", "<u2")])


def timeline_scenario(entries: int) -> str:
    """A scenario with one diff-drive robot and `entries` timeline entries, written out (no anchors)."""
    rows = [
        "name: long_timeline",
        f"duration: {max(30.0, entries * 0.001 + 1):.1f}",
        "robots:",
        "  - name: r1",
        f"    description: {{file: {DIFFBOT}}}",
        "    pose: {xyz: [0, 0, 0.06]}",
        "    plugins:",
        "      - {type: diff_drive, params: {rate: 50}}",
        "timeline:",
    ]
    rows += [
        f"  - {{t: {i * 0.001:.3f}, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, "
        f"data: {{linear: {{x: {0.1 + (i % 7) * 0.01:.2f}}}, angular: {{z: {(i % 5) * 0.1:.1f}}}}}}}"
        for i in range(entries)
    ]
    return "\n".join(rows) + "\n"


def chain_urdf(links: int, joint: str = "revolute", star: bool = False, mesh: str | None = None) -> str:
    """`links` boxes (or the `mesh` file for the first link's collision), each on a joint to the one
    before it (or, `star`, all to the first)."""
    rows = ['<?xml version="1.0"?>', '<robot name="chain">']
    for i in range(links):
        shape = f'<mesh filename="{mesh}"/>' if mesh and i == 0 else '<box size="0.05 0.05 0.05"/>'
        rows.append(
            f'<link name="l{i}"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" '
            f'ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>{shape}</geometry></collision></link>'
        )
        if i:
            limit = "" if joint == "fixed" else '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
            rows.append(
                f'<joint name="j{i}" type="{joint}"><parent link="l{0 if star else i - 1}"/>'
                f'<child link="l{i}"/><origin xyz="0 0 0.06"/>{limit}</joint>'
            )
    return "\n".join([*rows, "</robot>"]) + "\n"


def sphere_triangles(n: int, radius: float = 0.1) -> np.ndarray:
    """About `n` triangles of a UV sphere, as (n, 3, 3) corners."""
    k = max(int(np.sqrt(n / 2)), 3)
    theta = np.linspace(0, np.pi, k + 1)
    phi = np.linspace(0, 2 * np.pi, k + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    v = radius * np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)
    a, b, c, d = v[:-1, :-1], v[1:, :-1], v[1:, 1:], v[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, c], axis=-2), np.stack([a, c, d], axis=-2)]).reshape(-1, 3, 3)
    return tris


def random_triangles(n: int, size: float = 0.2, seed: int = 1) -> np.ndarray:
    """`n` triangles with random corners in a cube: no structure a simplifier could use."""
    return np.random.default_rng(seed).uniform(-size / 2, size / 2, (n, 3, 3))


def write_stl(path: Path, tris: np.ndarray) -> Path:
    rec = np.zeros(len(tris), _STL)
    rec["v"] = tris
    with path.open("wb") as f:
        f.write(b"\0" * 80 + len(tris).to_bytes(4, "little"))
        f.write(rec.tobytes())
    return path


def write_obj(path: Path, tris: np.ndarray) -> Path:
    with path.open("w") as f:
        np.savetxt(f, tris.reshape(-1, 3), fmt="v %.5f %.5f %.5f")
        np.savetxt(f, np.arange(1, 3 * len(tris) + 1).reshape(-1, 3), fmt="f %d %d %d")
    return path


_MEASURED = """
import os, sys, time
t0 = time.perf_counter()
from runner.cli import main
sys.argv = ["scenario", "validate", sys.argv[1]]
code = 0
try:
    main()
except SystemExit as e:
    code = e.code or 0
# VmHWM: this process's own peak (getrusage's ru_maxrss keeps the parent's from before the exec)
peak = next(int(x.split()[1]) for x in open("/proc/self/status") if x.startswith("VmHWM"))
cpu = sum(os.times()[:2])
print("MEASURED", time.perf_counter() - t0, peak, code, cpu, file=sys.stderr)
"""


def validate_measured(
    scenario: Path, timeout: float = 300.0, env: dict[str, str] | None = None
) -> dict[str, Any]:
    """`scenario validate` in its own process: wall s, peak resident MB, exit code, last lines."""
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(
            [sys.executable, "-c", _MEASURED, str(scenario)],
            capture_output=True,
            text=True,
            timeout=timeout,
            cwd=scenario.parent,
            env={**os.environ, "PYTHONPATH": str(REPO), **(env or {})},
        )
    except subprocess.TimeoutExpired:
        return {
            "wall_s": time.perf_counter() - t0,
            "cpu_s": None,
            "peak_mb": None,
            "code": "timeout",
            "out": "",
        }
    out = proc.stdout + proc.stderr
    line = next((x for x in out.splitlines() if x.startswith("MEASURED")), None)
    if line is None:
        return {
            "wall_s": time.perf_counter() - t0,
            "peak_mb": None,
            "code": proc.returncode,
            "out": out[-2000:],
        }
    _, wall, kb, code, cpu = line.split()
    kept = ("error", "warning", "/", "Traceback")  # what validate says, and whatever escaped it
    text = "\n".join(x for x in out.splitlines() if x.startswith(kept) or "hint" in x)
    return {
        "wall_s": float(wall),
        "cpu_s": float(cpu),
        "peak_mb": int(kb) / 1024,
        "code": int(code),
        "out": text[-1500:],
    }


def _robot_scenario(folder: Path, urdf: str) -> Path:
    (folder / "robot.urdf").write_text(urdf)
    path = folder / "s.yaml"
    path.write_text(
        "name: big\nduration: 1.0\nrobots:\n  - name: r1\n    description: {file: robot.urdf}\n"
        "    pose: {xyz: [0, 0, 0.5]}\n"
    )
    return path


def run(quick: bool = False) -> tuple[dict[str, Any], str]:
    from bench.common import table
    from runner.compile import load_plan
    from runner.scenario.loader import load_file

    rows: list[list[Any]] = []
    doc: dict[str, Any] = {"timeline": {}, "urdf": [], "mesh": []}
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        # --- a 20,000-entry timeline, in this process (imports done), best of 3
        path = tmp / "timeline.yaml"
        path.write_text(timeline_scenario(20_000))
        best = {"read": 1e9, "validate": 1e9, "validate_cpu": 1e9}
        for _ in range(1 if quick else 3):
            t0, c0 = time.perf_counter(), time.process_time()
            d = load_file(path)
            t1 = time.perf_counter()
            load_plan(d)
            t2, c2 = time.perf_counter(), time.process_time()
            best = {
                "read": min(best["read"], t1 - t0),
                "validate": min(best["validate"], t2 - t0),
                "validate_cpu": min(best["validate_cpu"], c2 - c0),
            }
        whole = validate_measured(path)
        doc["timeline"] = {
            "entries": 20_000,
            "bytes": path.stat().st_size,
            **best,
            "cli_wall_s": whole["wall_s"],
            "cli_cpu_s": whole["cpu_s"],
            "cli_peak_mb": whole["peak_mb"],
        }
        rows.append(["timeline, 20,000 entries: read", _s(best["read"]), "", "", "", _of(best["read"], 5)])
        rows.append(
            [
                "  read + schema + compile",
                _s(best["validate"]),
                _s(best["validate_cpu"]),
                "",
                "",
                _of(best["validate"], 5),
            ]
        )
        rows.append(
            [
                "  `scenario validate` (its own process, imports included)",
                _s(whole["wall_s"]),
                _s(whole["cpu_s"]),
                _mb(whole),
                _verdict(whole),
                _of(whole["wall_s"], 5),
            ]
        )
        # --- URDFs
        cases = [
            ("500 hinged links, a chain", chain_urdf(500)),
            ("1,000 hinged links, a chain", chain_urdf(1000)),
            ("2,000 hinged links, a chain", chain_urdf(2000)),
            ("10,000 hinged links, a chain", chain_urdf(10_000)),
            ("3,000 links on fixed joints, a star", chain_urdf(3000, "fixed", star=True)),
            ("3,000 links on fixed joints, a chain", chain_urdf(3000, "fixed")),
        ]
        for name, urdf in cases[:: 2 if quick else 1]:
            folder = tmp / f"urdf{len(doc['urdf'])}"
            folder.mkdir()
            got = validate_measured(_robot_scenario(folder, urdf))
            doc["urdf"].append({"case": name, **got})
            rows.append(
                [name, _s(got["wall_s"]), _s(got["cpu_s"]), _mb(got), _verdict(got), _of(got["wall_s"], 60)]
            )
        # --- a 5 M-triangle mesh
        n = 1_000_000 if quick else 5_000_000
        cache = tmp / "cache"
        for label, tris in (("sphere", sphere_triangles(n)), ("random triangles", random_triangles(n))):
            folder = tmp / f"mesh_{label[:6]}"
            folder.mkdir()
            write_stl(folder / "big.stl", tris)
            scenario = _robot_scenario(folder, chain_urdf(1, mesh="big.stl"))
            got = validate_measured(scenario, env={"XDG_CACHE_HOME": str(cache / label[:6])})
            doc["mesh"].append({"case": f"{len(tris)} triangles, {label}, binary STL", **got})
            name = f"{len(tris) / 1e6:.1f} M triangles ({label}), binary STL"
            rows.append(
                [name, _s(got["wall_s"]), _s(got["cpu_s"]), _mb(got), _verdict(got), _of(got["wall_s"], 60)]
            )
        tris = sphere_triangles(n)
        folder = tmp / "mesh_obj"
        folder.mkdir()
        write_obj(folder / "big.obj", tris)
        got = validate_measured(_robot_scenario(folder, chain_urdf(1, mesh="big.obj")))
        doc["mesh"].append({"case": f"{len(tris)} triangles, sphere, OBJ", **got})
        label = f"{len(tris) / 1e6:.1f} M triangles (sphere), OBJ"
        rows.append(
            [label, _s(got["wall_s"]), _s(got["cpu_s"]), _mb(got), _verdict(got), _of(got["wall_s"], 60)]
        )
    doc["targets"] = {
        "a 20,000-entry timeline validates in < 5 s": best["validate"] < 5.0,
        "every URDF case and mesh ends (validated or a located error) in < 60 s and < 2 GB": all(
            r["code"] in (0, 1)
            and r["wall_s"] < 60
            and (r["peak_mb"] or 1e9) < 2048
            and "Traceback" not in r["out"]
            for r in (*doc["urdf"], *doc["mesh"])
        ),
    }
    doc["peak_mb_of_this_process"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    for r in (*doc["urdf"], *doc["mesh"]):  # no path of this machine in the results
        r["out"] = r["out"].replace(tmp_name, "<tmp>")
    text = table(
        "Limits: large legitimate inputs (targets: timeline 5 s; URDF and mesh 60 s and 2 GB)",
        ["input", "wall s", "CPU s", "peak MB", "result", "of the target"],
        rows,
    )
    return doc, text


def _s(seconds: float | None) -> str:
    return f"{seconds:.2f}" if seconds is not None else "?"


def _of(seconds: float, target: float) -> str:
    return f"{seconds / target:.2f}"


def _mb(got: dict[str, Any]) -> str:
    return f"{got['peak_mb']:.0f}" if got["peak_mb"] is not None else "?"


def _verdict(got: dict[str, Any]) -> str:
    if got["code"] == 0:
        return "validates" + (" (warned)" if "warning" in got["out"] else "")
    if got["code"] == 1 and "Traceback" not in got["out"]:
        return "refused, located"
    return f"FAILED ({got['code']})"
