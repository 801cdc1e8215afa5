"""What a URDF's `<gazebo>` tags change on the MuJoCo model once it is loaded: each link's colour,
friction, contact stiffness and gravity (`apply_link_props`), and Gazebo's self-collision rule as MuJoCo
contact exclusions (`self_collision`)."""

from __future__ import annotations

import math
from typing import Any

import mujoco

from runner.compile.gazebo import GazeboInfo


def apply_link_props(spec: mujoco.MjSpec, gazebo: GazeboInfo, timestep: float) -> None:
    for link, props in gazebo.links.items():
        body = spec.body(link)
        if body is None:
            continue
        if props.gravity_off:
            body.gravcomp = 1.0
        for geom in body.geoms:
            if props.rgba is not None:
                geom.rgba = list(props.rgba)
            if not (geom.contype or geom.conaffinity):
                continue
            if props.friction is not None:
                # MuJoCo takes the larger friction of two touching geoms, Gazebo the smaller: give the
                # geom priority so that its own value is used (a caster's mu1=0 must stay 0).
                geom.friction = [props.friction, geom.friction[1], geom.friction[2]]
                geom.priority = 1
                if props.friction == 0.0:
                    # Frictionless as MuJoCo means it: a normal-only contact. A zero-friction cone
                    # (condim 3) lets a loaded caster jitter until the robot is thrown.
                    geom.condim = 1
            if props.kp:
                # ODE's kp (N/m) as a MuJoCo contact time constant for the link's own mass, never
                # below 2 steps (MuJoCo's stability limit). MuJoCo's direct (-stiffness, -damping) form is
                # per unit mass, not N/m: fed Gazebo's numbers, wheels lose traction.
                mass = max(float(body.mass), 1e-3)
                geom.solref = [max(2.0 * timestep, 2.0 * math.pi * math.sqrt(mass / props.kp)), 1.0]


def self_collision(root: Any, spec: mujoco.MjSpec, gazebo: GazeboInfo) -> list[str]:
    """Gazebo's rule: links of one model collide with each other only if one of the two has self_collide
    (the link's `<selfCollide>`, else the model's `<self_collide>`, off by default), and never when a joint
    connects them. Gazebo lumps links joined by fixed joints into one link: those never collide with each
    other either, and a joint between two such groups connects all their links. MuJoCo only leaves out
    parent-child pairs, so every other pair that Gazebo would not collide is excluded here. Returns the
    links that self-collide."""
    parent: dict[str, str] = {}
    group = {el.get("name"): el.get("name") for el in root.findall("link")}

    def find(x: str) -> str:
        while group[x] != x:
            group[x] = group[group[x]]
            x = group[x]
        return x

    moving: list[tuple[str, str]] = []
    for j in root.findall("joint"):
        p, c = j.find("parent").get("link"), j.find("child").get("link")
        parent[c] = p
        if j.get("type") == "fixed":
            group[find(c)] = find(p)
        else:
            moving.append((p, c))
    jointed = {frozenset((find(p), find(c))) for p, c in moving}

    def collides(name: str) -> bool:
        props = gazebo.links.get(name)
        if props is not None and props.self_collide is not None:
            return props.self_collide
        return gazebo.self_collide

    bodies = [
        b.name for b in spec.bodies if b.name in group and any(g.contype or g.conaffinity for g in b.geoms)
    ]
    on = [name for name in bodies if collides(name)]
    for i, a in enumerate(bodies):
        for b in bodies[i + 1 :]:
            ga, gb = find(a), find(b)
            if parent.get(a) == b or parent.get(b) == a:
                continue  # MuJoCo leaves parent and child out by itself
            if (collides(a) or collides(b)) and ga != gb and frozenset((ga, gb)) not in jointed:
                continue
            spec.add_exclude(bodyname1=a, bodyname2=b)
    return on
