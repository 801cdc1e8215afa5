"""In-process runs for the tests of events and actors: a scenario text compiled as `scenario run` compiles
it, its world stepped on a MemoryBus (real MuJoCo), and what it published and where its bodies were read
back. A probe, called at every clock message (100 Hz of sim time, after the step's events and actors),
samples the MuJoCo state as the step left it."""

from __future__ import annotations

import json
import math
import textwrap
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from runner.compile import load_plan
from runner.errors import Problem, ScenarioError
from runner.plan import RunPlan
from runner.scenario.loader import load_text
from runner.sim.world import World, WorldStats
from runner.wire import msgs
from runner.wire.transport import MemoryBus, unpack_attachment
from tests.conftest import DIFFBOT

# r1: the project's diffbot at the origin, facing +x, with a drive (true odometry) and a 10 Hz lidar
ROBOT = """\
robots:
  - name: r1
    description: {diffbot}
    pose: {{xyz: [0, 0, 0.06]}}
    plugins:
      - {{type: diff_drive, params: {{rate: 50, odometry_source: world}}}}
      - {{type: lidar, params: {{link: lidar_link, samples: 72, rate: 10, range_max: 8.0}}}}
"""


def scenario_text(*parts: str, duration: float = 2.0, robot: bool = True, seed: int = 1) -> str:
    """A scenario `ev` (r1 unless not `robot`) with the YAML `parts` (each dedented on its own) after."""
    head = f"name: ev\nduration: {duration}\nrate: max\nseed: {seed}\n"
    return (
        head + (ROBOT.format(diffbot=DIFFBOT) if robot else "") + "".join(textwrap.dedent(p) for p in parts)
    )


def compile_text(tmp_path: Path, text: str) -> RunPlan:
    """The plan of a scenario text (written to tmp_path, so that relative paths resolve)."""
    path = tmp_path / "scenario.yaml"
    path.write_text(text)
    return load_plan(load_text(text, path))


def plan_of(tmp_path: Path, *parts: str, **kw: Any) -> RunPlan:
    return compile_text(tmp_path, scenario_text(*parts, **kw))


def problems_of(tmp_path: Path, *parts: str, **kw: Any) -> list[Problem]:
    """The located problems compiling the scenario reports (it must report some)."""
    try:
        plan_of(tmp_path, *parts, **kw)
    except ScenarioError as e:
        return list(e.problems)
    raise AssertionError("the scenario compiled without a problem")


@dataclass
class Ran:
    world: World
    bus: MemoryBus
    stats: WorldStats
    samples: list[tuple[int, Any]] = field(default_factory=list)  # (sim ns, what the probe returned)

    def on(self, suffix: str) -> list[tuple[int, Any]]:
        """(publish time ns, decoded message) of each message on the key ending with `suffix`."""
        out = []
        for key, type_name, payload, att in self.bus.sent:
            if key.endswith(suffix):
                parsed = unpack_attachment(att)
                assert parsed is not None
                out.append((parsed[1], msgs.decode(payload, type_name)))
        return out

    def raw(self, suffix: str) -> list[tuple[int, bytes]]:
        return [
            (unpack_attachment(att)[1], payload)  # type: ignore[index]
            for key, _t, payload, att in self.bus.sent
            if key.endswith(suffix)
        ]

    def fired(self) -> list[dict[str, Any]]:
        """The `<run>/_events` records, in the order they were published, each with its publish time."""
        return [{**json.loads(m.data), "t_ns": t} for t, m in self.on("/_events")]

    def times(self, event: str) -> list[float]:
        return [f["t"] for f in self.fired() if f["event"] == event]

    def sample(self, t: float) -> Any:
        """What the probe returned at sim time `t` (seconds, a multiple of 10 ms)."""
        want = round(t * 1e9)
        return next(v for ns, v in self.samples if ns == want)


def run(plan: RunPlan, probe: Callable[[World], Any] | None = None) -> Ran:
    bus = MemoryBus()
    world = World(plan, bus)
    samples: list[tuple[int, Any]] = []
    if probe is not None:
        world.listen(
            plan.clock_key, "rosgraph_msgs/msg/Clock", lambda _m, t: samples.append((t, probe(world)))
        )
    stats = world.run()
    return Ran(world, bus, stats, samples)


def body_id(world: World, name: str) -> int:
    bid = mujoco.mj_name2id(world.model, mujoco.mjtObj.mjOBJ_BODY, name)
    assert bid >= 0, name
    return bid


def xy(world: World, body: str) -> tuple[float, float]:
    """Where a body is (its MuJoCo name; r1's root is `r1/base_link`... see `root`)."""
    p = world.data.xpos[body_id(world, body)]
    return float(p[0]), float(p[1])


def root(world: World, robot: str = "r1") -> str:
    r = next(r for r in world.plan.robots if r.name == robot)
    return f"{r.prefix}{r.root}"


def yaw_of(quat: Any) -> float:
    w, x, y, z = (float(v) for v in quat)
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def mocap(world: World, actor: str) -> tuple[np.ndarray, np.ndarray]:
    """An actor's pose as set (mocap position and quaternion), copies."""
    i = int(world.model.body_mocapid[body_id(world, actor)])
    return world.data.mocap_pos[i].copy(), world.data.mocap_quat[i].copy()
