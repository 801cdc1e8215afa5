"""Poses drawn within a region (`pose: {within: ...}`, runner.scenario.draws) that start free.

A robot or world model whose drawn pose puts it inside something (a wall, a box, another robot) would be
shoved out at the first step, somewhere no one chose. So, after the variant is compiled, each drawn pose is
tried on the compiled model, in the file's order: the body is put there and its collision geoms measured
against every other one (`mj_geomDistance`, whatever MuJoCo's contact filters say, so that a static model
is checked against the static walls too; the ground plane aside). One that sinks more than 1 mm into
something is drawn again from the same generator (the same file and seed redraw the same way), up to 100
draws in all, on the same compiled model; the accepted poses are written into the document and it is
compiled once more. None free in 100 draws: a located error at the pose.

Poses drawn within a region elsewhere than a robot's or a world model's `pose:` are not checked here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from runner.compile import load_plan
from runner.errors import Notices, Problem, ScenarioError
from runner.geometry import rpy_to_quat
from runner.plan import RunPlan
from runner.scenario.draws import Drawn, Draws
from runner.scenario.loader import Document

PENETRATION_M = 0.001  # deeper than this into something is a collision
DRAWS_PER_POSE = 100  # the first draw included


def load_drawn_plan(
    doc: Document, *, record_path: str | None = None, notices: Notices | None = None
) -> RunPlan:
    """`load_plan` for a variant that may draw values: its drawn poses placed free of collisions, and the
    plan carrying what was drawn (`drawn`) and the variant's label (`variant`)."""
    draws: Draws | None = getattr(doc, "draws", None)
    if draws is None:
        return load_plan(doc, record_path=record_path, notices=notices)
    first = Notices() if draws.poses() else notices
    plan = load_plan(doc, record_path=record_path, notices=first)
    if draws.poses():
        if place(plan, doc, draws):
            plan = load_plan(doc, record_path=record_path, notices=notices)
        elif notices is not None and first is not None:
            for n in first:
                notices.add(n.message, n.location.file, n.location.line, n.hint)
    plan.variant = draws.label()
    plan.drawn = draws.values()
    return plan


@dataclass
class _Subject:
    """A drawn pose's body in a compiled world: how to move it and which geoms are its own."""

    item: Drawn
    world: tuple[mujoco.MjModel, mujoco.MjData]
    geoms: list[int]
    qadr: int = -1  # a free joint's qpos address (a robot or a model that moves)
    body: int = -1  # a welded body (a fixed robot)
    geom: int = -1  # a static model (a geom of the world body)
    local: tuple[np.ndarray, np.ndarray] | None = None  # the body in the pose's frame


def place(plan: RunPlan, doc: Document, draws: Draws) -> bool:
    """Try each drawn pose on `plan`'s compiled model(s), redrawing those in collision; the accepted ones
    go into `doc.data`. Whether any pose changed; a ScenarioError for every pose with none free."""
    models: dict[int, tuple[mujoco.MjModel, mujoco.MjData]] = {}
    problems: list[Problem] = []
    moved = False
    for item in draws.poses():
        subject = _subject(plan, doc, item, models)
        if subject is None:
            continue
        pose, other = item.value, _overlap(subject, plan)
        tries = 1
        while other is not None and tries < DRAWS_PER_POSE:
            pose = draws.redraw(item)
            _put(subject, pose)
            other, tries = _overlap(subject, plan), tries + 1
        if other is not None:
            problems.append(
                Problem(
                    f"no collision-free pose in {DRAWS_PER_POSE} draws within the region; "
                    f"it overlaps {other}",
                    doc.locate(item.path),
                    item.path,
                    hint="a larger region, or fewer obstacles in it",
                )
            )
        elif pose is not item.value:
            draws.accept(doc.data, item, pose)
            moved = True
    if problems:
        raise ScenarioError(problems)
    return moved


def _subject(
    plan: RunPlan, doc: Document, item: Drawn, models: dict[int, tuple[mujoco.MjModel, mujoco.MjData]]
) -> _Subject | None:
    """The body `item` poses, in its world's compiled model; None for a pose of something else."""
    path, data = item.path, doc.data
    parts = plan.parts()
    if len(path) == 3 and path[0] == "robots":
        name = data["robots"][path[1]].get("name")
        found = [(k, r) for k, p in enumerate(parts) for r in p.robots if r.name == name]
        if not found:
            return None
        k, robot = found[0]
        m, d = _world(parts, k, models)
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, robot.prefix + robot.root)
        return _body_subject(item, (m, d), body) if body >= 0 else None
    if len(path) >= 4 and path[-3] == "models" and path[0] in ("world", "worlds"):
        k = 0 if path[0] == "world" else int(path[1])
        world = data["world"] if path[0] == "world" else data["worlds"][k]
        spec = world["models"][path[-2]]
        if k >= len(parts):
            return None
        m, d = _world(parts, k, models)
        if spec.get("static", True):
            geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, spec.get("name"))
            if geom < 0:
                return None
            m.geom_sameframe[geom] = 0  # (its own position is read again at each forward)
            return _Subject(item, (m, d), [geom] if _collides(m, geom) else [], geom=geom)
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, spec.get("name"))
        return _body_subject(item, (m, d), body) if body >= 0 else None
    return None


def _world(
    parts: list[RunPlan], k: int, models: dict[int, tuple[mujoco.MjModel, mujoco.MjData]]
) -> tuple[mujoco.MjModel, mujoco.MjData]:
    if k not in models:
        m = mujoco.MjModel.from_xml_string(parts[k].mjcf)
        models[k] = (m, mujoco.MjData(m))
    return models[k]


def _body_subject(item: Drawn, world: tuple[mujoco.MjModel, mujoco.MjData], body: int) -> _Subject:
    """A robot's root body or a moving model's body: moved by its free joint, or (welded) by its pose."""
    m, _ = world
    geoms = [g for g in range(m.ngeom) if m.body_rootid[m.geom_bodyid[g]] == body and _collides(m, g)]
    jnt = int(m.body_jntadr[body])
    free = jnt >= 0 and m.jnt_type[jnt] == mujoco.mjtJoint.mjJNT_FREE
    qadr = int(m.jnt_qposadr[jnt]) if free else -1
    if free:
        pos, quat = m.qpos0[qadr : qadr + 3], m.qpos0[qadr + 3 : qadr + 7]
    else:
        pos, quat = m.body_pos[body], m.body_quat[body]
    fpos, fquat = _frame(item.value)
    inv_pos, inv_quat = np.zeros(3), np.zeros(4)
    mujoco.mju_negPose(inv_pos, inv_quat, fpos, fquat)
    lpos, lquat = np.zeros(3), np.zeros(4)
    mujoco.mju_mulPose(lpos, lquat, inv_pos, inv_quat, np.array(pos, float), np.array(quat, float))
    return _Subject(item, world, geoms, qadr=qadr, body=-1 if free else body, local=(lpos, lquat))


def _frame(pose: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    return np.array(pose["xyz"], float), rpy_to_quat(pose["rpy"])


def _put(s: _Subject, pose: dict[str, Any]) -> None:
    """Move the subject's body to `pose` (the model for a welded body or a static geom, else qpos)."""
    m, d = s.world
    fpos, fquat = _frame(pose)
    if s.geom >= 0:
        m.geom_pos[s.geom], m.geom_quat[s.geom] = fpos, fquat
        return
    assert s.local is not None
    pos, quat = np.zeros(3), np.zeros(4)
    mujoco.mju_mulPose(pos, quat, fpos, fquat, *s.local)
    if s.qadr >= 0:
        d.qpos[s.qadr : s.qadr + 3], d.qpos[s.qadr + 3 : s.qadr + 7] = pos, quat
    else:
        m.body_pos[s.body], m.body_quat[s.body] = pos, quat


def _collides(m: mujoco.MjModel, g: int) -> bool:
    """Whether geom `g` takes part in collisions at all (a visual geom does not)."""
    return bool(m.geom_contype[g] or m.geom_conaffinity[g])


_NOT_OBSTACLES = (int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_HFIELD))


def _overlap(s: _Subject, plan: RunPlan) -> str | None:
    """What the subject, where it is now, sinks more than PENETRATION_M into (named), or None."""
    m, d = s.world
    mujoco.mj_kinematics(m, d)
    own = set(s.geoms)
    others = [
        g for g in range(m.ngeom)
        if g not in own and _collides(m, g) and int(m.geom_type[g]) not in _NOT_OBSTACLES
    ]  # fmt: skip
    for a in s.geoms:
        for b in others:
            if not (m.geom_contype[a] & m.geom_conaffinity[b] or m.geom_contype[b] & m.geom_conaffinity[a]):
                continue
            reach = m.geom_rbound[a] + m.geom_rbound[b] + PENETRATION_M
            if np.linalg.norm(d.geom_xpos[a] - d.geom_xpos[b]) > reach:
                continue
            if mujoco.mj_geomDistance(m, d, a, b, 0.01, None) < -PENETRATION_M:
                return _name(m, b, plan)
    return None


def _name(m: mujoco.MjModel, g: int, plan: RunPlan) -> str:
    """A geom as the scenario names it: its robot's name, or the model's (geom or body) name."""
    body = int(m.geom_bodyid[g])
    root = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.body_rootid[body])) or ""
    for part in plan.parts():
        for r in part.robots:
            if root.startswith(r.prefix):
                return f"robot {r.name!r}"
    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g)
    name = name or mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, body)
    return repr(name) if name else "a geom of the world"
