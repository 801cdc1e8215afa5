"""What a URDF's `<gazebo>` tags change on the MuJoCo model once it is loaded: each link's colour,
friction, contact stiffness and gravity (`apply_link_props`), and Gazebo's self-collision rule as MuJoCo
contact exclusions (`self_collision`)."""

from __future__ import annotations

import math
from typing import Any

import mujoco

from runner.compile.gazebo import GazeboInfo
from runner.compile.urdf.checks import DescriptionError


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


# Contact exclusions made for one robot at most: Gazebo's no-self-collision rule over n moving links is
# n²/2 MuJoCo exclusions (a chain as deep as MuJoCo allows, 1023 hinged links, needs 522k: ~5 s to compile).
MAX_EXCLUDES = 600_000


def self_collision(
    root: Any, spec: mujoco.MjSpec, gazebo: GazeboInfo, *, root_welded: bool = False, where: Any = None
) -> list[str]:
    """Gazebo's rule: links of one model collide with each other only if one of the two has self_collide
    (the link's `<selfCollide>`, else the model's `<self_collide>`, off by default), and never when a joint
    connects them. Gazebo lumps links joined by fixed joints into one link: those never collide with each
    other either, and a joint between two such groups connects all their links. Returns the links that
    self-collide.

    MuJoCo leaves out by itself the pairs of bodies welded together (no joint between them: one fixed
    group) and those whose welded groups are parent and child (engine_collision_driver.c, the parent
    filter, unless a group is welded to the world): every other pair that Gazebo would not collide is
    excluded here. (Excluding every pair, as this did, made 3,000 links on fixed joints 4.5 M exclusions.)
    The pairs are counted first: past MAX_EXCLUDES, a located error says why."""
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
    members: dict[str, list[str]] = {}  # group -> its bodies
    for name in bodies:
        members.setdefault(find(name), []).append(name)
    roots = [name for name in group if name not in parent]
    base = find(roots[0]) if roots else None  # the root link's group (welded to the world if fixed)
    pairs: list[tuple[str, str]] = []
    # a joint between two groups where one is welded to the world: MuJoCo's parent filter does not apply
    for g1, g2 in (tuple(pair) for pair in jointed if root_welded and base in pair):
        pairs += [(a, b) for a in members.get(g1, []) for b in members.get(g2, [])]
    off = {g: [n for n in names if not collides(n)] for g, names in members.items()}
    off = {g: names for g, names in off.items() if names}
    sizes = {g: len(names) for g, names in off.items()}
    total = sum(sizes.values())
    count = (total * total - sum(n * n for n in sizes.values())) // 2 - sum(
        sizes.get(g1, 0) * sizes.get(g2, 0) for g1, g2 in (tuple(pair) for pair in jointed)
    )
    if count + len(pairs) > MAX_EXCLUDES:
        raise DescriptionError(
            f"{len(bodies)} links that must not collide with each other (Gazebo's default: no "
            f"<self_collide>) need {count + len(pairs)} MuJoCo contact exclusions; at most {MAX_EXCLUDES} "
            "are made",
            *(where(root) if where is not None else (None, None)),
            hint="join links that never move relative to each other with fixed joints (a fixed group "
            "costs nothing), or set <self_collide>true</self_collide> on the model if its links may touch",
        )
    groups = list(off)
    for i, g1 in enumerate(groups):
        for g2 in groups[i + 1 :]:
            if frozenset((g1, g2)) not in jointed:
                pairs += [(a, b) for a in off[g1] for b in off[g2]]
    for a, b in pairs:
        spec.add_exclude(bodyname1=a, bodyname2=b)
    return on
