"""Hardware from `<ros2_control>` (issue 36), measured: a heavy 3-link arm (10, 8 and 5 kg links of 0.5 m,
held out horizontally from its `initial_value`s: ~200 N·m on the shoulder) under gz_ros2_control's position
interface with its default gains (position_proportional_gain 0.1, controller manager at 100 Hz), with
no controller: the hardware holds the start pose as Gazebo's servo does. Printed per world timestep: the
largest drift of any joint over 10 s against the issue's 0.005 rad, and the peak joint speed after a 2 rad
step command against the URDF velocity limit of π rad/s (DART clips the servo there).

Run: `python -m bench hardware` (or `python bench/hardware.py`). The arm generator is used by
tests/test_hardware.py too."""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DRIFT_LIMIT = 0.005  # rad over 10 s (issue 36's acceptance)
VELOCITY_LIMIT = float(np.pi)


def arm_urdf(
    *,
    masses: tuple[float, ...] = (10.0, 8.0, 5.0),
    length: float = 0.5,
    initial: tuple[float, ...] | None = (0.0, 0.0, 0.0),
    effort: float | None = 1000.0,
    velocity: float = VELOCITY_LIMIT,
    plugin: str = "gz_ros2_control/GazeboSimSystem",
    interface: str = "position",
    extra: str = "",
    hardware_params: str = "",
    gazebo: str = "",
) -> str:
    """An arm of len(masses) links hinged about y, each `length` long along x (horizontal at 0), on a base
    (the scenario fixes it to the world), with a `<ros2_control>` block (`interface` command, `initial`
    positions)."""
    rows = ['<?xml version="1.0"?>', '<robot name="arm">', '<link name="base">']
    rows.append(
        '<inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>'
        "</inertial>"
        '<collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>'
    )
    parent = "base"
    for i, m in enumerate(masses):
        ixx = m * length**2 / 12
        rows.append(
            f'<link name="l{i}"><inertial><origin xyz="{length / 2} 0 0"/><mass value="{m}"/>'
            f'<inertia ixx="0.001" iyy="{ixx}" izz="{ixx}" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        )
        off = 0.0 if i == 0 else length
        eff = f' effort="{effort}"' if effort is not None else ' effort="0"'
        rows.append(
            f'<joint name="j{i}" type="revolute"><parent link="{parent}"/><child link="l{i}"/>'
            f'<origin xyz="{off} 0 0"/><axis xyz="0 1 0"/>'
            f'<limit lower="-3" upper="3"{eff} velocity="{velocity}"/></joint>'
        )
        parent = f"l{i}"
    rows.append(extra)
    rows.append(
        f'<ros2_control name="arm_hw" type="system"><hardware><plugin>{plugin}</plugin>'
        f"{hardware_params}</hardware>"
    )
    for i in range(len(masses)):
        init = (
            f'<param name="initial_value">{initial[i]}</param>'
            if initial is not None and i < len(initial)
            else ""
        )
        rows.append(
            f'<joint name="j{i}"><command_interface name="{interface}"/>'
            f'<state_interface name="position">{init}</state_interface>'
            '<state_interface name="velocity"/></joint>'
        )
    rows.append("</ros2_control>")
    rows.append(gazebo)
    rows.append("</robot>")
    return "\n".join(rows)


def arm_scenario(
    folder: Path, urdf: str, *, duration: float, timestep: float = 0.001, timeline: str = ""
) -> Path:
    (folder / "arm.urdf").write_text(urdf)
    path = folder / "arm.yaml"
    path.write_text(
        f"name: arm\nduration: {duration}\nrate: max\nseed: 1\n"
        f"world:\n  physics: {{timestep: {timestep}}}\n"
        "robots:\n  - name: arm\n    description: arm.urdf\n    fixed: true\n    pose: {xyz: [0, 0, 1.5]}\n"
        + (f"timeline:\n{timeline}" if timeline else "")
    )
    return path


def main() -> int:
    from runner.sim.hardware import SERVO_STEPS

    print(
        f"heavy 3-link arm (10/8/5 kg, 0.5 m links), gz_ros2_control position, default gains; "
        f"kv = {SERVO_STEPS:g} x inertia / timestep"
    )
    ok = True
    with tempfile.TemporaryDirectory() as tmp:
        for dt in (0.001, 0.002, 0.004):
            path = arm_scenario(Path(tmp), arm_urdf(), duration=10.0, timestep=dt)
            t0 = time.perf_counter()
            drift = hold_drift(path, 10.0)
            wall = time.perf_counter() - t0
            ratio = drift / DRIFT_LIMIT
            ok &= ratio <= 1
            print(
                f"  dt {dt * 1000:g} ms: drift over 10 s {drift:.2e} rad = {ratio:.3f} x limit "
                f"({DRIFT_LIMIT} rad); {wall:.1f} s wall"
            )
        urdf = arm_urdf()
        path = arm_scenario(Path(tmp), urdf, duration=2.0, timestep=0.001)
        peak = step_peak_speed(path, 2.0)
        ratio = peak / VELOCITY_LIMIT
        ok &= ratio <= 1.01
        print(f"  2 rad step on j2: peak speed {peak:.3f} rad/s = {ratio:.3f} x the URDF limit (pi)")
    return 0 if ok else 1


def _world(path: Path):  # type: ignore[no-untyped-def]
    from runner.compile import compile_plan
    from runner.scenario.loader import load_file
    from runner.scenario.validate import validate_scenario
    from runner.sim.world import World
    from runner.wire.transport import MemoryBus

    doc = load_file(path)
    plan = compile_plan(validate_scenario(doc), doc)
    return World(plan, MemoryBus()), plan


def hold_drift(path: Path, seconds: float) -> float:
    """The largest |q - q_start| of any hinge joint of the scenario's world over `seconds`, sampled every
    step (the world's own loop, stepped here)."""
    import mujoco

    world, _plan = _world(path)
    m, d = world.model, world.data
    hinges = [int(m.jnt_qposadr[j]) for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    start = d.qpos[hinges].copy()
    worst = 0.0
    for _ in range(round(seconds / m.opt.timestep)):
        for h in world._before:
            h.fn(0)
        mujoco.mj_step(m, d)
        worst = max(worst, float(np.max(np.abs(d.qpos[hinges] - start))))
    return worst


def step_peak_speed(path: Path, seconds: float, joint: str = "j2", step: float = 2.0) -> float:
    """The peak speed of `joint` after its position actuator is told to go `step` rad from its start."""
    import mujoco

    world, plan = _world(path)
    m, d = world.model, world.data
    prefix = plan.robots[0].prefix
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{prefix}{joint}/position")
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, prefix + joint)
    d.ctrl[a] = d.qpos[m.jnt_qposadr[jid]] + step
    peak = 0.0
    for _ in range(round(seconds / m.opt.timestep)):
        for h in world._before:
            h.fn(0)
        mujoco.mj_step(m, d)
        peak = max(peak, abs(float(d.qvel[m.jnt_dofadr[jid]])))
    return peak


if __name__ == "__main__":
    sys.exit(main())
