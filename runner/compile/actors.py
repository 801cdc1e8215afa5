"""`world.actors`: each actor becomes a MuJoCo mocap body of its own name (kinematic: it goes where its path
says whatever is in the way, pushes what it meets, and is hit by rays and drawn by cameras as any geom), and
an `ActorPlan` with its path as times and points for the world to play (runner.sim.actors)."""

from __future__ import annotations

import itertools
import math
from typing import Any

import mujoco

from runner.compile.meshes import MeshError, prepare_mesh
from runner.errors import Problem, Problems, ScenarioError
from runner.geometry import rpy_to_quat
from runner.plan import ActorPlan
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import Actor
from runner.scenario.schema.events import PERSON_HEIGHT, PERSON_RADIUS

_GEOM = {
    "box": mujoco.mjtGeom.mjGEOM_BOX,
    "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
    "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "person": mujoco.mjtGeom.mjGEOM_CAPSULE,
    "mesh": mujoco.mjtGeom.mjGEOM_MESH,
}


def add_actors(
    spec: mujoco.MjSpec, actors: list[Actor], doc: Document, problems: Problems, at: PathKey = ("world",)
) -> list[ActorPlan]:
    """Every actor's body added to the world (each on its own: its mistakes to `problems`)."""
    out = []
    for i, a in enumerate(actors):
        with problems.each():
            out.append(_add(spec, a, doc, (*at, "actors", i)))
    return out


def _add(spec: mujoco.MjSpec, a: Actor, doc: Document, here: PathKey) -> ActorPlan:
    plan = actor_plan(a)
    body = spec.worldbody.add_body(name=a.name, mocap=True, pos=plan.pos, quat=plan.quat)
    kw: dict[str, Any] = {"name": a.name, "type": _GEOM[a.shape], "rgba": list(a.rgba)}
    if a.shape == "person":
        radius, height = a.size if a.size is not None else (PERSON_RADIUS, PERSON_HEIGHT)
        half = max(height / 2 - radius, 1e-3)  # the cylinder part, between the two half spheres
        kw.update(size=[radius, half, 0], pos=[0, 0, height / 2])  # standing on its origin (its feet)
    elif a.shape == "mesh":
        assert a.mesh is not None
        path = doc.base_dir / a.mesh
        try:
            mesh = prepare_mesh(path)
        except (MeshError, OSError) as e:
            where: PathKey = (*here, "mesh")
            raise ScenarioError(
                Problem(f"actor {a.name!r}: {e}", doc.locate(where), where, hint=getattr(e, "hint", None))
            ) from None
        spec.add_mesh(name=f"actor/{a.name}", file=str(mesh.file), scale=list(a.scale))
        kw["meshname"] = f"actor/{a.name}"
    else:
        assert a.size is not None
        size = list(a.size)
        if a.shape == "box":
            kw["size"] = [s / 2 for s in size]
        elif a.shape == "sphere":  # (one number: the others' sizes cannot be worked out from it)
            kw["size"] = [size[0], 0, 0]
        else:  # cylinder, capsule
            kw["size"] = [size[0], size[1] / 2, 0]
    body.add_geom(**kw)
    return plan


def actor_plan(a: Actor) -> ActorPlan:
    """The actor's path: its points (z from its pose where a waypoint gives [x, y]) and their times (given,
    or from `speed`; with `loop` the path closes back to its first point at the same pace)."""
    base = a.pose.xyz if a.pose is not None else None
    z0 = base[2] if base is not None else 0.0
    points = [[float(w.xyz[0]), float(w.xyz[1]), float(w.xyz[2]) if len(w.xyz) == 3 else z0] for w in a.path]
    if points and a.loop and points[-1] != points[0]:
        points.append(list(points[0]))
    times: list[float] = []
    if a.waypoints and a.path[0].t is not None:
        times = [float(w.t) for w in a.path if w.t is not None]
        if len(points) > len(times):  # the closing leg of a loop, at the path's mean pace
            length = sum(math.dist(p, q) for p, q in itertools.pairwise(points[:-1]))
            pace = length / times[-1] if times[-1] > 0 and length > 0 else a.speed
            times.append(times[-1] + max(math.dist(points[-2], points[-1]) / pace, 1e-3))
    elif points:
        times = [0.0]
        for p, q in itertools.pairwise(points):
            times.append(times[-1] + math.dist(p, q) / a.speed)
    rpy = a.pose.rpy if a.pose is not None else (0.0, 0.0, 0.0)
    pos = list(base) if base is not None else list(points[0])
    return ActorPlan(
        name=a.name,
        start_ns=None if a.start == "event" else round(float(a.start) * 1e9),
        pos=[float(x) for x in pos],
        quat=[float(x) for x in rpy_to_quat(rpy)],
        times=times,
        points=points,
        loop=a.loop,
        travel=a.heading == "travel",
        hinge=a.hinge.model_dump() if a.hinge is not None else None,
    )
