"""What the benchmark sections share: machine info, scenarios built from text, worlds on a real Zenoh
session, the raw MuJoCo step rate, tables."""

from __future__ import annotations

import contextlib
import os
import platform
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
RESULTS = HERE / "results"
DIFFBOT = REPO / "scenarios" / "robots" / "diffbot.urdf.xacro"
TWO_ROBOTS = REPO / "scenarios" / "two_robots.yaml"

import mujoco  # noqa: E402
import zenoh  # noqa: E402

from runner.compile import compile_plan  # noqa: E402
from runner.plan import RunPlan  # noqa: E402
from runner.scenario.loader import load_file, load_text  # noqa: E402
from runner.scenario.validate import validate_scenario  # noqa: E402
from runner.sim.world import World, WorldStats  # noqa: E402
from runner.wire.transport import ATTACHMENT, ZenohBus, free_port, make_config  # noqa: E402


def machine() -> dict[str, Any]:
    cpu = platform.processor() or platform.machine()
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    return {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu": cpu,
        "cpus": os.cpu_count(),
        "mujoco": mujoco.__version__,
        "zenoh": getattr(zenoh, "__version__", "?"),
        "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
    }


def plan_from_file(path: Path, *, seconds: float | None = None, judge: bool = False) -> RunPlan:
    doc = load_file(path)
    scenario = validate_scenario(doc)
    if not judge:
        scenario = scenario.model_copy(update={"assertions": []})
    plan = compile_plan(scenario, doc)
    return _adjust(plan, seconds)


def plan_from_text(text: str, *, seconds: float | None = None) -> RunPlan:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "bench.yaml"
        path.write_text(text)
        doc = load_text(text, path)
        plan = compile_plan(validate_scenario(doc), doc)
    return _adjust(plan, seconds)


def _adjust(plan: RunPlan, seconds: float | None) -> RunPlan:
    plan.rate = "max"
    if seconds is not None:
        plan.duration_ns = round(seconds * 1e9)
    return plan


def raw_rate(plan: RunPlan, steps: int, *, batched: bool = True) -> float:
    """Physics steps per second of the compiled model, no plugins (their actuators and sensors are in
    the model), robots at rest: the limit."""
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=50)  # settle contacts
    t0 = time.perf_counter()
    if batched:
        mujoco.mj_step(model, data, nstep=steps)
    else:
        for _ in range(steps):
            mujoco.mj_step(model, data)
    return steps / (time.perf_counter() - t0)


def raw_driving_rate(plan: RunPlan) -> float:
    """Physics steps per second of the same model replaying the controls a run applied (the robots drive,
    turn and touch as in the run), no plugins: what the physics of the run costs by itself."""
    from runner.wire.transport import MemoryBus

    world = World(plan, MemoryBus())
    controls: list[tuple[int, Any]] = []
    boundary = world._boundary

    def recording_boundary() -> None:
        boundary()
        controls.append((world.now_ns // plan.step_ns, world.data.ctrl.copy()))

    world._boundary = recording_boundary  # type: ignore[method-assign]
    world.run()
    model = mujoco.MjModel.from_xml_string(plan.mjcf)
    data = mujoco.MjData(model)
    total = plan.duration_ns // plan.step_ns
    t0 = time.perf_counter()
    for (step, ctrl), nxt in zip(controls, [*[c[0] for c in controls[1:]], total], strict=True):
        if nxt > step:
            data.ctrl[:] = ctrl
            mujoco.mj_step(model, data, nstep=nxt - step)
    return total / (time.perf_counter() - t0)


@contextlib.contextmanager
def zenoh_session(mode: str = "peer") -> Iterator[Any]:
    """A real Zenoh session on loopback with nothing else on it."""
    with zenoh.open(make_config(mode, listen=[f"tcp/127.0.0.1:{free_port()}"])) as session:
        yield session


def world_on_zenoh(plan: RunPlan) -> WorldStats:
    """The world with every plugin publishing on a real Zenoh session, nothing subscribed."""
    with zenoh_session() as session:
        bus = ZenohBus(session)
        try:
            return World(plan, bus).run()
        finally:
            bus.undeclare_all()


def world_floor(plan: RunPlan) -> WorldStats:
    """The floor under `world_on_zenoh`: the same world, loop and boundaries, every hook at its rate, but a
    hook does only MuJoCo's own work for its sensor (a lidar's ray casts, a camera's render and read-back)
    and puts the messages it would publish, encoded beforehand (those of a call after its first, which may
    publish once-only messages: static transforms), numbered and stamped, on the same real Zenoh session;
    nothing else is computed (no noise, no odometry, no encoding). No implementation of the plugins, in any
    language, costs less than this: what lies above it is the plugins' own computing."""
    with zenoh_session() as session:
        bus = ZenohBus(session)
        try:
            return floor_of(World(plan, bus)).run()
        finally:
            bus.undeclare_all()


def floor_of(world: World) -> World:
    """`world` with every hook made its floor's (see `world_floor`), before it runs."""
    if world.remote_renders:
        raise ValueError("the floor is measured for worlds that render in their own process only")
    for hook in [*world._after, *world._before, world._clock_hook]:
        hook.fn = _floor_hook(world, hook.fn)
    return world


def _floor_hook(world: World, fn: Any) -> Any:
    sent: list[tuple[Any, Any, bytes]] = []
    outs = list(world._out.values())
    sends = [o.send for o in outs]
    for out, send in zip(outs, sends, strict=True):
        out.send = lambda payload, att, out=out, send=send: sent.append((out, send, bytes(payload)))
    try:
        fn(world.now_ns)
        sent.clear()  # (the first call's once-only messages)
        fn(world.now_ns)
    finally:
        for out, send in zip(outs, sends, strict=True):
            out.send = send
            out.seq = 0
    engine = _engine_work(world, getattr(fn, "__self__", None))
    pack = ATTACHMENT.pack

    def floor(now_ns: int) -> None:
        if engine is not None:
            engine()
        for out, send, payload in sent:
            send(payload, pack(out.seq, now_ns))
            out.seq += 1

    return floor


def _engine_work(world: World, plugin: Any) -> Any:
    """What MuJoCo itself computes for a plugin's sensor, as the plugin calls it, or None."""
    scan = getattr(plugin, "scan", None)
    if callable(scan):
        return scan  # a lidar: mj_multiRay over its beams
    renderer = getattr(plugin, "renderer", None)
    if renderer is None:
        return None
    data = world.data
    color = getattr(plugin.params, "publish_color", True)
    depth = type(plugin).__name__ == "DepthCamera"

    def render() -> None:  # mjv_updateScene, mjr_render and mjr_readPixels, as the camera calls them
        renderer.update(data)
        if not depth:
            renderer._render(depth_too=False)
        elif color and renderer._depth_same_in_color_render():
            renderer._render(depth_too=True)
        else:
            if color:
                renderer._render(depth_too=False)
            renderer._render_depth()

    return render


def gl_renderer() -> str:
    """The OpenGL renderer cameras render with (e.g. 'llvmpipe (LLVM 15.0.6, 256 bits)' on the CPU, the GPU's
    name on one), read from a context of the backend mujoco loaded; '' if unknown."""
    try:
        from OpenGL import GL

        model = mujoco.MjModel.from_xml_string("<mujoco/>")
        r = mujoco.Renderer(model, 8, 8)
        try:
            r._gl_context.make_current()
            name = GL.glGetString(GL.GL_RENDERER)
            return name.decode() if name else ""
        finally:
            r.close()
    except Exception:
        return ""


def best(values: Sequence[float]) -> float:
    return max(values)


def table(title: str, header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    """A plain text table (also valid Markdown) — printed, and pasted into the README."""
    cells = [[str(h) for h in header]] + [[_fmt(c) for c in row] for row in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    lines = [f"### {title}", ""]
    for n, row in enumerate(cells):
        lines.append(
            "| "
            + " | ".join(
                c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(row, widths, strict=True))
            )
            + " |"
        )
        if n == 0:
            lines.append("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    return "\n".join(lines)


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        if v == 0:
            return "0"
        if abs(v) >= 1000:
            return f"{v:,.0f}"
        if abs(v) >= 100:
            return f"{v:.0f}"
        if abs(v) >= 10:
            return f"{v:.1f}"
        return f"{v:.2f}"
    return str(v)


def say(text: str) -> None:
    print(text, flush=True)
    sys.stdout.flush()


def readme_tables(block: str) -> dict[str, str]:
    """The tables between the README's bench markers, by section: each section starts at a title
    `#### NAME: ...` (NAME a word, the section's) and holds every table up to the next section's."""
    import re

    tables: dict[str, str] = {}
    starts = [m for m in re.finditer(r"^#### (\w+):", block, re.M)]
    for m, nxt in zip(starts, [*starts[1:], None], strict=True):
        tables[m.group(1)] = block[m.start() : nxt.start() if nxt else len(block)].strip()
    return tables
