"""`scenario render RUN.mcap -o run.mp4|gif|png`: the motion of a recorded run, rendered again.

A recording carries the compiled model (`<run>/_model`, MJCF) and the state (`<run>/_state`: qpos and
mocap poses, at `foxglove.tf_rate`). Each frame poses the model at the last state at or before its time,
and MuJoCo's offscreen renderer draws it (EGL or OSMesa: on the CPU where there is no GPU), from above the
whole scene (`overview`) or following a robot (`chase:r1`), with each robot's path so far drawn as a line.
`.mp4` is written by ffmpeg (imageio-ffmpeg), `.gif` and `.png` (the last frame) by Pillow.
"""

from __future__ import annotations

import bisect
import itertools
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from runner.errors import RunError

PATH_COLORS = [(0.85, 0.2, 0.2), (0.2, 0.35, 0.9), (0.1, 0.6, 0.2), (0.9, 0.6, 0.1), (0.5, 0.2, 0.7)]


@dataclass
class Recording:
    run: str  # the world's name (its keys' prefix)
    mjcf: str
    times: list[int]  # sim ns of each state
    states: list[np.ndarray]
    robots: set[str] | None = None  # the scenario's robot names (from its recorded plan), when known


def load(mcap: Path, world: str | None = None) -> Recording:
    from mcap.reader import make_reader

    from runner import msgs

    mjcf: dict[str, str] = {}
    states: dict[str, list[tuple[int, np.ndarray]]] = {}
    robots: set[str] | None = None
    try:
        with open(mcap, "rb") as f:
            for _schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
                topic = channel.topic
                if topic.endswith("/_model"):
                    text = msgs.decode(message.data, "std_msgs/msg/String").data
                    mjcf.setdefault(topic[: -len("/_model")], text)
                elif topic.endswith("/_plan") and robots is None:
                    robots = _robot_names(msgs.decode(message.data, "std_msgs/msg/String").data)
                elif topic.endswith("/_state"):
                    values = msgs.decode(message.data, "std_msgs/msg/Float64MultiArray").data
                    states.setdefault(topic[: -len("/_state")], []).append(
                        (message.log_time, np.asarray(values, dtype=float))
                    )
    except Exception as e:
        if not mjcf or not states:
            raise RunError(f"{mcap}: cannot read it as a recording: {e}") from None
    runs = [r for r in mjcf if r in states and (world is None or r.endswith(world))]
    if not runs:
        raise RunError(
            f"{mcap}: no model and state to replay (recorded with `foxglove: {{scene: false}}`, or an older "
            "recording?)"
        )
    run = runs[0]
    pairs = states[run]
    return Recording(run, mjcf[run], [t for t, _ in pairs], [s for _, s in pairs], robots)


def _robot_names(plan_json: str) -> set[str] | None:
    from runner.plan import RunPlan

    try:
        plan = RunPlan.model_validate_json(plan_json)
    except ValueError:
        return None
    return {r.name for p in plan.parts() for r in p.robots}


def _robots(m: mujoco.MjModel, names: set[str] | None = None) -> list[tuple[str, int]]:
    """(robot name, root body) of each robot: the world's top bodies named `<robot>/...`; with the
    scenario's robot names known, only theirs (an SDF world's models are named `<model>/...` too)."""
    out = []
    for b in range(1, m.nbody):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) or ""
        if int(m.body_parentid[b]) == 0 and "/" in name:
            robot = name.split("/", 1)[0]
            if names is None or robot in names:
                out.append((robot, b))
    return out


# What the overview frames: everything within this many metres of what moves (robots and the bodies that
# move), or within this many times what moves spans, whichever is larger; farther geoms are left out.
_FRAME_REACH_M = 100.0
_FRAME_REACH_SPANS = 20.0


def _framing(m: mujoco.MjModel, d: mujoco.MjData, rec: Recording) -> tuple[np.ndarray, float, list[str]]:
    """Centre and size of what is worth seeing: every geom but the (infinite) ground planes, at the start,
    and where the bodies go over the run; and the models left out because they lie far beyond the robots
    (a world model posed hundreds of kilometres away, a model without collision falling forever would
    shrink the rest to nothing)."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)

    def box(g: int) -> list[np.ndarray]:
        center, half = m.geom_aabb[g][:3], m.geom_aabb[g][3:]
        return list(d.geom_xpos[g] + (center + corners * half) @ d.geom_xmat[g].reshape(3, 3).T)

    def model_of(g: int) -> str:
        root = int(m.body_rootid[int(m.geom_bodyid[g])])
        # a scenario's world model is a geom of the world body; an SDF model or a robot, bodies `<name>/...`
        return (m.body(root).name if root else m.geom(g).name or "a world geom").split("/")[0]

    solid = [g for g in range(m.ngeom) if int(m.geom_type[g]) != int(mujoco.mjtGeom.mjGEOM_PLANE)]
    robots = {b for _, b in _robots(m, rec.robots)}
    # geoms of bodies that can move (their root body has joints), seen whole wherever they go: a box
    # pushed to the edge stays in the picture
    moving = [g for g in solid if int(m.body_jntnum[int(m.body_rootid[int(m.geom_bodyid[g])])]) > 0]
    boxes: dict[int, list[np.ndarray]] = {}
    mujoco.mj_kinematics(m, d)
    for g in solid:
        if g not in moving:
            boxes[g] = box(g)
    subject: list[np.ndarray] = []  # what the picture is about: the robots' paths, else all that moves
    for state in [*rec.states[:: max(1, len(rec.states) // 50)], rec.states[-1]]:
        d.qpos[:] = state[: m.nq]
        mujoco.mj_kinematics(m, d)
        for g in moving:
            pts = box(g)
            boxes.setdefault(g, []).extend(pts)
            if not robots or int(m.body_rootid[int(m.geom_bodyid[g])]) in robots:
                subject += pts
    if not subject:
        subject = [p for pts in boxes.values() for p in pts]
    left_out: list[str] = []
    points: list[np.ndarray] = []
    if subject:
        ref = np.array(subject)
        lo, hi = ref.min(axis=0), ref.max(axis=0)
        centre, reach = (lo + hi) / 2, max(_FRAME_REACH_M, _FRAME_REACH_SPANS * float(np.max(hi - lo)))
        for g, pts in boxes.items():
            far = np.max(np.linalg.norm(np.array(pts) - centre, axis=1)) > reach
            if far and int(m.body_rootid[int(m.geom_bodyid[g])]) not in robots:
                if model_of(g) not in left_out:
                    left_out.append(model_of(g))
                continue
            points += pts
    if not points:
        return np.array(m.stat.center), 2.0 * float(m.stat.extent), left_out
    pts = np.array(points)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return (lo + hi) / 2, float(max(hi[0] - lo[0], hi[1] - lo[1], 1.0)), left_out


def frames(
    rec: Recording,
    *,
    camera: str = "overview",
    width: int = 640,
    height: int = 480,
    fps: float = 15.0,
    last_only: bool = False,
    notes: list[str] | None = None,
) -> Iterator[np.ndarray]:
    """RGB frames of the recording, one every 1/fps sim seconds (or only the last, paths complete);
    `notes` receives what the viewer should know (models left out of the overview)."""
    m = mujoco.MjModel.from_xml_string(rec.mjcf)
    d = mujoco.MjData(m)
    m.vis.global_.offwidth = max(int(m.vis.global_.offwidth), width)
    m.vis.global_.offheight = max(int(m.vis.global_.offheight), height)
    robots = _robots(m, rec.robots)
    cam = mujoco.MjvCamera()
    if camera == "overview":
        center, span, left_out = _framing(m, d, rec)
        if left_out:
            # MuJoCo scales its clipping planes and lights with the model's extent: the far model's would
            # put the near plane kilometres away
            m.stat.extent, m.stat.center = max(span, 1.0), center
        if left_out and notes is not None:
            notes.append(
                f"the overview leaves out {', '.join(left_out[:5])}{' ...' if len(left_out) > 5 else ''}: "
                f"farther than {_FRAME_REACH_M:g} m (or {_FRAME_REACH_SPANS:g} times their spread) from "
                "the robots at some time of the run"
            )
        # the shadow map must cover what is framed, or its edge speckles the floor (shadow acne)
        extent = max(float(m.stat.extent), 1e-6)
        m.vis.map.shadowclip = max(float(m.vis.map.shadowclip), max(25.0, 3.0 * span) / extent)
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        cam.lookat[:] = center
        cam.distance = 1.3 * span / (2 * np.tan(np.radians(float(m.vis.global_.fovy)) / 2))
        cam.azimuth, cam.elevation = 135.0, -60.0
    elif camera.startswith("chase:"):
        name = camera.split(":", 1)[1]
        body = next((b for r, b in robots if r == name), None)
        if body is None:
            raise RunError(f"no robot {name!r} in the recording; robots: {', '.join(r for r, _ in robots)}")
        cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
        cam.trackbodyid = body
        cam.distance, cam.azimuth, cam.elevation = 3.0, 200.0, -30.0
    else:
        cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        cam.fixedcamid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        if cam.fixedcamid < 0:
            raise RunError(f"camera {camera!r}: use overview, chase:<robot>, or a camera of the model")
    nq, nm = m.nq, m.nmocap
    trails: list[list[np.ndarray]] = [[] for _ in robots]
    end = rec.times[-1]
    step = round(1e9 / fps)
    with mujoco.Renderer(m, height, width) as renderer:
        for t in range(0, end + 1, step):
            i = max(0, bisect.bisect_right(rec.times, t) - 1)
            state = rec.states[i]
            d.qpos[:] = state[:nq]
            if nm:
                d.mocap_pos[:] = state[nq : nq + 3 * nm].reshape(nm, 3)
                d.mocap_quat[:] = state[nq + 3 * nm : nq + 7 * nm].reshape(nm, 4)
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)  # subtree centres of mass: what a tracking (chase) camera looks at
            for k, (_name, body) in enumerate(robots):
                trails[k].append(np.array(d.xpos[body]))
            if last_only and t + step <= end:
                continue
            mujoco.mj_camlight(m, d)
            renderer.update_scene(d, camera=cam)
            for k in range(len(robots)):
                _draw_path(renderer.scene, trails[k], PATH_COLORS[k % len(PATH_COLORS)])
            yield renderer.render().copy()


def _draw_path(scene: Any, points: list[np.ndarray], rgb: tuple[float, float, float]) -> None:
    rgba = np.array([*rgb, 1.0], dtype=np.float32)
    for a, b in itertools.pairwise(points):
        if scene.ngeom >= scene.maxgeom or np.allclose(a, b):
            continue
        g = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(
            g, mujoco.mjtGeom.mjGEOM_CAPSULE, np.zeros(3), np.zeros(3), np.eye(3).ravel(), rgba
        )
        lift = np.array([0.0, 0.0, 0.02])
        mujoco.mjv_connector(g, mujoco.mjtGeom.mjGEOM_CAPSULE, 0.02, a + lift, b + lift)
        scene.ngeom += 1


def write(
    rec: Recording,
    out: Path,
    *,
    camera: str = "overview",
    width: int = 640,
    height: int = 480,
    fps: float = 15.0,
    progress: Callable[[int, int], None] | None = None,
    notes: list[str] | None = None,
) -> int:
    """Render `rec` into `out` (.mp4, .gif, .png); returns the number of frames (`notes`: see `frames`)."""
    suffix = out.suffix.lower()
    if suffix not in (".mp4", ".gif", ".png"):
        raise RunError(f"{out}: write .mp4, .gif or .png")
    total = 1 if suffix == ".png" else len(range(0, rec.times[-1] + 1, round(1e9 / fps)))
    out.parent.mkdir(parents=True, exist_ok=True)
    images = frames(
        rec, camera=camera, width=width, height=height, fps=fps, last_only=suffix == ".png", notes=notes
    )
    count = 0
    if suffix == ".mp4":
        import imageio_ffmpeg

        writer = imageio_ffmpeg.write_frames(
            str(out), (width, height), fps=fps, macro_block_size=1, quality=7
        )
        writer.send(None)
        try:
            for img in images:
                writer.send(np.ascontiguousarray(img).tobytes())
                count += 1
                if progress:
                    progress(count, total)
        finally:
            writer.close()
        return count
    from PIL import Image

    kept: list[Any] = []
    for img in images:
        count += 1
        if suffix == ".gif":
            kept.append(Image.fromarray(img).convert("P", palette=Image.Palette.ADAPTIVE))
        else:
            kept = [Image.fromarray(img)]  # a picture: the last frame, with the whole paths
        if progress:
            progress(count, total)
    if suffix == ".gif":
        kept[0].save(out, save_all=True, append_images=kept[1:], duration=round(1000 / fps), loop=0)
    else:
        kept[0].save(out)
    return count
