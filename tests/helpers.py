"""In-process helpers: compile an inline scenario and step its world on a MemoryBus (real MuJoCo)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from runner.compile import compile_plan
from runner.errors import Notices
from runner.plan import RunPlan
from runner.scenario.loader import load_file
from runner.scenario.validate import validate_scenario
from runner.sim.world import World
from runner.wire import msgs
from runner.wire.transport import MemoryBus, unpack_attachment


def plan_of(path: Path) -> RunPlan:
    doc = load_file(path)
    return compile_plan(validate_scenario(doc), doc)


def compile_with_notices(path: Path) -> tuple[RunPlan, str]:
    """The plan of a scenario file and its warnings, rendered as `scenario validate` prints them."""
    doc = load_file(path)
    notices = Notices()
    plan = compile_plan(validate_scenario(doc), doc, notices=notices)
    return plan, "\n".join(n.render() for n in notices)


def simulate(path: Path) -> tuple[World, MemoryBus]:
    bus = MemoryBus()
    world = World(plan_of(path), bus)
    world.run()
    return world, bus


def messages(bus: MemoryBus, key_suffix: str) -> list[tuple[int, Any]]:
    """(sim time ns, decoded message) of everything published on keys ending with `key_suffix`."""
    out = []
    for key, type_name, payload, att in bus.sent:
        if key.endswith(key_suffix):
            parsed = unpack_attachment(att)
            assert parsed is not None
            out.append((parsed[1], msgs.decode(payload, type_name)))
    return out


def robot_scenario(
    tmp_path: Path,
    urdf: str,
    *,
    name: str = "t",
    seed: int = 1,
    duration: float = 0.5,
    world: str = "",
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.05),
    plugins: str = "[]",
    timeline: str = "",
) -> Path:
    """`urdf` as <name>.urdf, and a scenario `g` that runs it as robot `bot` (its path, <name><seed>.yaml):
    `world` is YAML for the scenario's `world:` (without the key), `timeline` its entries."""
    (tmp_path / f"{name}.urdf").write_text(urdf)
    path = tmp_path / f"{name}{seed}.yaml"
    path.write_text(
        f"name: g\nduration: {duration}\nrate: max\nseed: {seed}"
        + (f"\nworld:\n{world}" if world else "")
        + f"\nrobots:\n  - name: bot\n    description: {name}.urdf\n    pose: {{xyz: {list(xyz)}}}\n"
        f"    plugins: {plugins}\n" + (f"timeline:\n{timeline}" if timeline else "")
    )
    return path


def declared(robot: Any) -> list[Any]:
    """A robot plan's plugins that its scenario or description declares (not the runner's own additions,
    such as the `robot_state_publisher` that `foxglove.scene` adds)."""
    return [p for p in robot.plugins if p.added is None]
