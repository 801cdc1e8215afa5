"""`scenario render RUN.mcap -o run.mp4|gif|png`: the motion of a recorded run, rendered again.

A recording carries the compiled model (`<run>/_model`, MJCF) and the state (`<run>/_state`: qpos and
mocap poses, at `foxglove.tf_rate`). Each frame poses the model at the last state at or before its time,
and MuJoCo's offscreen renderer draws it (EGL or OSMesa: on the CPU where there is no GPU), from above the
whole scene (`overview`: every model and every robot wherever it goes, filling the picture) or following
a robot (`chase:r1`), with each robot's path so far drawn in the robot's colour (`runner.tools.pictures`: the
same as in the trajectory plot and the report).

A video has one frame every 1/fps sim seconds and plays for as long as the run took in sim time. `.mp4` is
written by ffmpeg (imageio-ffmpeg); `.gif` by Pillow, each frame's delay in whole hundredths of a second
(a GIF's unit) so that they add up to the run's time, and a frame that shows the same picture as the one
before merged into it (as Pillow would), so that the count said is the count written; `.png` is the run's
last moment.
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from runner.errors import RunError
from runner.tools.pictures import (
    FRAME_REACH_M,
    FRAME_REACH_SPANS,
    PALETTE,
    RGB,
    fit_camera,
    model_colours,
    model_of,
    reach,
    robot_bodies,
    run_colours,
)

DEFAULT_SIZE = (960, 720)
# A GIF says how long each frame shows in hundredths of a second, and viewers slow down delays under 2
GIF_MAX_FPS = 50.0


@dataclass
class Recording:
    run: str  # the world's name (its keys' prefix)
    mjcf: str
    times: list[int]  # sim ns of each state
    states: list[np.ndarray]
    robots: set[str] | None = None  # the scenario's robot names (from its recorded plan), when known
    plan: Any = None  # the recorded plan (RunPlan), when known: every robot's colour comes from it


def load(mcap: Path, world: str | None = None) -> Recording:
    from mcap.reader import make_reader

    from runner.wire import msgs

    mjcf: dict[str, str] = {}
    states: dict[str, list[tuple[int, np.ndarray]]] = {}
    plan: Any = None
    try:
        with open(mcap, "rb") as f:
            for _schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
                topic = channel.topic
                if topic.endswith("/_model"):
                    # the last one: a robot spawned mid-run is in it (its world grew, keeping what it had)
                    mjcf[topic[: -len("/_model")]] = msgs.decode(message.data, "std_msgs/msg/String").data
                elif topic.endswith("/_plan") and plan is None:
                    plan = _plan_of(msgs.decode(message.data, "std_msgs/msg/String").data)
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
    robots = None if plan is None else {r.name for p in plan.parts() for r in p.robots}
    grown = _grown_states([s for _, s in pairs], mjcf[run])
    return Recording(run, mjcf[run], [t for t, _ in pairs], grown, robots, plan)


def _grown_states(states: list[np.ndarray], mjcf: str) -> list[np.ndarray]:
    """States recorded before robots were spawned (shorter: fewer joints) made the size of the last model's:
    the joints they lack at the model's start values (a spawned robot shows where it was spawned)."""
    if len({len(s) for s in states}) <= 1:
        return states
    m = mujoco.MjModel.from_xml_string(mjcf)
    size, mocap = m.nq + 7 * m.nmocap, 7 * m.nmocap
    out = []
    for s in states:
        nq = len(s) - mocap
        if len(s) != size and 0 <= nq < m.nq:
            s = np.concatenate([s[:nq], m.qpos0[nq:], s[nq:]])
        out.append(s)
    return out


def _plan_of(plan_json: str) -> Any:
    from runner.plan import RunPlan

    try:
        return RunPlan.model_validate_json(plan_json)
    except ValueError:
        return None


def colours(m: mujoco.MjModel, rec: Recording) -> dict[str, RGB]:
    """Each robot's colour: the one it has in the trajectory plot and the report (`runner.tools.pictures`)."""
    if rec.plan is not None:
        return run_colours(rec.plan, {rec.run: m})
    return model_colours(m, rec.robots)


# The overview: from the south (x to the right, y away: as the trajectory plot draws it), tilted enough to
# see the walls' sides.
OVERVIEW_AZIMUTH = 90.0
OVERVIEW_ELEVATION = -60.0
OVERVIEW_MARGIN = 0.04  # of the half-frame, kept free around what is framed


def _framing(m: mujoco.MjModel, d: mujoco.MjData, rec: Recording) -> tuple[np.ndarray, list[str]]:
    """What is worth seeing (points, one a row: the corners of each geom's box) and the models left out.

    Every geom but the (infinite) ground planes, at the start, and where the bodies go over the run; but
    not the models far beyond the robots (a world model posed hundreds of kilometres away, a model without
    collision falling forever would shrink the rest to nothing)."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)

    def box(g: int) -> list[np.ndarray]:
        center, half = m.geom_aabb[g][:3], m.geom_aabb[g][3:]
        return list(d.geom_xpos[g] + (center + corners * half) @ d.geom_xmat[g].reshape(3, 3).T)

    solid = [g for g in range(m.ngeom) if int(m.geom_type[g]) != int(mujoco.mjtGeom.mjGEOM_PLANE)]
    robots = {b for _, b in robot_bodies(m, rec.robots)}
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
        centre, radius = reach(np.array(subject))
        for g, pts in boxes.items():
            far = np.max(np.linalg.norm(np.array(pts) - centre, axis=1)) > radius
            if far and int(m.body_rootid[int(m.geom_bodyid[g])]) not in robots:
                if model_of(m, g) not in left_out:
                    left_out.append(model_of(m, g))
                continue
            points += pts
    if not points:
        c, e = np.array(m.stat.center), float(m.stat.extent)
        return c + corners * e, left_out
    return np.array(points), left_out


def frame_times(end_ns: int, fps: float) -> list[int]:
    """The sim time of each frame of a video of `end_ns` sim ns at `fps`: one every 1/fps s from 0, as
    many as play for the run's length (the last one shows the run's last 1/fps s)."""
    n = max(1, math.ceil(end_ns * fps / 1e9 - 1e-6))
    return [round(i * 1e9 / fps) for i in range(n)]


def overview_camera(
    m: mujoco.MjModel,
    d: mujoco.MjData,
    rec: Recording,
    width: int,
    height: int,
    notes: list[str] | None = None,
) -> tuple[mujoco.MjvCamera, float]:
    """The overview's free camera, placed so that the whole world (every model, every robot wherever it
    goes in the run) fills a `width` x `height` picture, with a small margin; and the span (m) of what it
    frames. Sets the model's visual settings that depend on it (shadows, clipping)."""
    points, left_out = _framing(m, d, rec)
    lookat, distance = fit_camera(
        points,
        azimuth=OVERVIEW_AZIMUTH,
        elevation=OVERVIEW_ELEVATION,
        fovy=float(m.vis.global_.fovy),
        aspect=width / height,
        margin=OVERVIEW_MARGIN,
    )
    lo, hi = points.min(axis=0), points.max(axis=0)
    span = float(max(hi[0] - lo[0], hi[1] - lo[1], 1.0))
    if left_out:
        # MuJoCo scales its clipping planes and lights with the model's extent: the far model's would put
        # the near plane kilometres away
        m.stat.extent, m.stat.center = span, lookat
        if notes is not None:
            notes.append(
                f"the overview leaves out {', '.join(left_out[:5])}{' ...' if len(left_out) > 5 else ''}: "
                f"farther than {FRAME_REACH_M:g} m (or {FRAME_REACH_SPANS:g} times their spread) from "
                "the robots at some time of the run"
            )
    extent = max(float(m.stat.extent), 1e-6)
    # the shadow map must cover what is framed, or its edge speckles the floor (shadow acne)
    m.vis.map.shadowclip = max(float(m.vis.map.shadowclip), max(25.0, 3.0 * span) / extent)
    # and the far clipping plane must lie beyond what is framed
    m.vis.map.zfar = max(float(m.vis.map.zfar), 2.0 * (distance + span) / extent)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = lookat
    cam.distance = distance
    cam.azimuth, cam.elevation = OVERVIEW_AZIMUTH, OVERVIEW_ELEVATION
    return cam, span


def frames(
    rec: Recording,
    *,
    camera: str = "overview",
    width: int = DEFAULT_SIZE[0],
    height: int = DEFAULT_SIZE[1],
    fps: float = 15.0,
    last_only: bool = False,
    notes: list[str] | None = None,
) -> Iterator[np.ndarray]:
    """RGB frames of the recording at `frame_times` (or only the last, at the run's end, paths complete);
    `notes` receives what the viewer should know (models left out of the overview)."""
    m = mujoco.MjModel.from_xml_string(rec.mjcf)
    d = mujoco.MjData(m)
    m.vis.global_.offwidth = max(int(m.vis.global_.offwidth), width)
    m.vis.global_.offheight = max(int(m.vis.global_.offheight), height)
    robots = robot_bodies(m, rec.robots)
    colour = colours(m, rec)
    cam = mujoco.MjvCamera()
    path_radius = 0.02
    if camera == "overview":
        cam, span = overview_camera(m, d, rec, width, height, notes)
        path_radius = max(0.02, 0.003 * span)  # a path as wide as a few pixels, whatever the world's size
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
    times = [end] if last_only else frame_times(end, fps)
    # a path is a capsule from point to point: one every `step` metres of the way (each recorded state
    # would be thousands on a long run, more than the scene holds)
    step = max(0.02, path_radius)
    with mujoco.Renderer(m, height, width) as renderer:
        done = 0  # states already on the paths
        for t in times:
            upto = max(1, bisect.bisect_right(rec.times, t))
            for i in range(done, upto):
                _pose(m, d, rec.states[i], nq, nm)
                for k, (_name, body) in enumerate(robots):
                    here, trail = np.array(d.xpos[body]), trails[k]
                    if len(trail) < 2 or np.linalg.norm(trail[-2] - here) >= step:
                        trail.append(here)
                    else:  # (the last point follows the robot until the next is far enough)
                        trail[-1] = here
            done = max(done, upto)
            _pose(m, d, rec.states[upto - 1], nq, nm)
            mujoco.mj_comPos(m, d)  # subtree centres of mass: what a tracking (chase) camera looks at
            mujoco.mj_camlight(m, d)
            renderer.update_scene(d, camera=cam)
            for k, (name, _body) in enumerate(robots):
                rgb = colour.get(name, PALETTE[k % len(PALETTE)])
                _draw_path(renderer.scene, trails[k], rgb, path_radius)
            yield renderer.render().copy()


def _pose(m: mujoco.MjModel, d: mujoco.MjData, state: np.ndarray, nq: int, nm: int) -> None:
    d.qpos[:] = state[:nq]
    if nm:
        d.mocap_pos[:] = state[nq : nq + 3 * nm].reshape(nm, 3)
        d.mocap_quat[:] = state[nq + 3 * nm : nq + 7 * nm].reshape(nm, 4)
    mujoco.mj_kinematics(m, d)


def _draw_path(scene: Any, points: list[np.ndarray], rgb: RGB, radius: float) -> None:
    rgba = np.array([*rgb, 1.0], dtype=np.float32)
    lift = np.array([0.0, 0.0, max(0.02, radius)])
    for a, b in itertools.pairwise(points):
        if scene.ngeom >= scene.maxgeom:
            break
        if np.allclose(a, b):
            continue
        g = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(
            g, mujoco.mjtGeom.mjGEOM_CAPSULE, np.zeros(3), np.zeros(3), np.eye(3).ravel(), rgba
        )
        mujoco.mjv_connector(g, mujoco.mjtGeom.mjGEOM_CAPSULE, radius, a + lift, b + lift)
        scene.ngeom += 1


@dataclass
class Written:
    """What a video or picture holds, as a player reads it back."""

    frames: int
    seconds: float  # how long it plays (0 for a picture)
    fps: float  # frames per second it plays at (a GIF: on average)
    merged: int = 0  # frames that were the same picture as the one before (a GIF shows it on)


def gif_delays(n: int, fps: float) -> list[int]:
    """Each frame's delay in milliseconds, whole hundredths of a second (a GIF's unit), adding up to n/fps
    rounded to the hundredth: at 15 fps, 70, 70, 60, 70, 70, 60... (6.67 cs is not a GIF delay)."""
    edges = [round(100 * i / fps) for i in range(n + 1)]
    return [10 * (b - a) for a, b in itertools.pairwise(edges)]


def write(
    rec: Recording,
    out: Path,
    *,
    camera: str = "overview",
    width: int = DEFAULT_SIZE[0],
    height: int = DEFAULT_SIZE[1],
    fps: float = 15.0,
    progress: Callable[[int, int], None] | None = None,
    notes: list[str] | None = None,
) -> Written:
    """Render `rec` into `out` (.mp4, .gif, .png): one frame every 1/fps sim seconds, so that it plays for
    as long as the run took in sim time (`notes`: see `frames`). Returns what the file holds."""
    suffix = out.suffix.lower()
    if suffix not in (".mp4", ".gif", ".png"):
        raise RunError(f"{out}: write .mp4, .gif or .png")
    if suffix == ".gif" and fps > GIF_MAX_FPS:
        if notes is not None:
            notes.append(f"a GIF plays at {GIF_MAX_FPS:g} fps at most: --fps {fps:g} became {GIF_MAX_FPS:g}")
        fps = GIF_MAX_FPS
    total = 1 if suffix == ".png" else len(frame_times(rec.times[-1], fps))
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
        return Written(count, count / fps, fps)
    from PIL import Image

    if suffix == ".png":
        for img in images:  # one: the run's end, with the whole paths
            Image.fromarray(img).save(out)
            count += 1
        if progress:
            progress(count, total)
        return Written(count, 0.0, 0.0)
    delays = gif_delays(total, fps)
    kept: list[Any] = []
    shown: list[int] = []  # each kept frame's delay, ms
    last: bytes | None = None
    for img in images:
        frame = Image.fromarray(img).convert("P", palette=Image.Palette.ADAPTIVE)
        # the same picture as the one before (nothing moved): shown on for longer instead, as Pillow would
        # merge it anyway (and the count said would not be the count written)
        same = frame.convert("RGB").tobytes()
        if same == last:
            shown[-1] += delays[count]
        else:
            kept.append(frame)
            shown.append(delays[count])
        last = same
        count += 1
        if progress:
            progress(count, total)
    kept[0].save(out, save_all=True, append_images=kept[1:], duration=shown, loop=0)
    return Written(len(kept), sum(shown) / 1000, fps, merged=count - len(kept))
