"""MuJoCo bodies built from a model's collected links and joints: the kinematic tree (free bodies, loops
and second parents left out with a notice), joint axes, limits and dynamics, inertials, and each link's
geoms (a non-convex static mesh as its convex pieces) and lights."""

from __future__ import annotations

import math

import mujoco

from runner.compile.sdf.geometry import GREY
from runner.compile.sdf.parts import Collected, Joint, Link
from runner.compile.sdf.pose import IDENTITY, rotate, unit
from runner.compile.sdf.reader import Reader
from runner.errors import did_you_mean
from runner.plugin import PIECES_GROUP, RAY_GROUP

# The joint types of SDF (sdformat's joint.sdf), for a "did you mean" on a misspelt one.
_SDF_JOINTS = (
    "ball",
    "continuous",
    "fixed",
    "gearbox",
    "prismatic",
    "revolute",
    "revolute2",
    "screw",
    "universal",
)


class BodyBuilder(Reader):
    """Builds the bodies of a model's collected links and joints."""

    def build(self, c: Collected) -> None:
        assert self.result is not None
        parent_of: dict[int, Joint] = {}
        for j in c.joints:
            if j.type not in ("fixed", "revolute", "continuous", "prismatic", "ball"):
                self.note(
                    f"joint type {j.type!r} (joint {j.name!r}) is not supported; its links are held fixed",
                    j.src,
                    j.el,
                    hint=did_you_mean(j.type, _SDF_JOINTS, "SDF joint types")
                    if j.type not in _SDF_JOINTS
                    else "supported: fixed, revolute, continuous, prismatic, ball",
                )
                j.type = "fixed"
            if j.child.static:
                continue  # a static model's links never move: its joints do nothing
            if id(j.child) in parent_of:
                self.note(
                    f"link {j.child.key!r} is the child of two joints; {j.name!r} is ignored", j.src, j.el
                )
                continue
            parent_of[id(j.child)] = j
        made: dict[int, mujoco.MjsBody] = {}
        visiting: set[int] = set()

        def make(link: Link) -> mujoco.MjsBody:
            if id(link) in made:
                return made[id(link)]
            j = parent_of.get(id(link))
            if j is not None and id(link) in visiting:
                self.note(f"joint {j.name!r} closes a loop; it is ignored", j.src, j.el)
                parent_of.pop(id(link))
                j = None
            visiting.add(id(link))
            if j is None or j.parent is None:
                parent_body, parent_world = self.spec.worldbody, IDENTITY
            else:
                parent_body, parent_world = make(j.parent), j.parent.world
                if id(link) in made:  # made while resolving a loop
                    return made[id(link)]
            rel = parent_world.inv() @ link.world
            body = parent_body.add_body(
                name=self.unique("body", link.body), pos=list(rel.p), quat=list(rel.q)
            )
            made[id(link)] = body
            if not link.static:
                if j is None:
                    body.add_freejoint(name=self.unique("joint", f"{link.body}/root"))
                    self.result.free_bodies.append(body.name)  # type: ignore[union-attr]
                elif j.type != "fixed":
                    self.add_joint(body, j)
            self.link(body, link)
            return body

        for link in c.links:
            make(link)

    def add_joint(self, body: mujoco.MjsBody, j: Joint) -> None:
        el, src = j.el, j.src
        name = self.unique("joint", "/".join([*j.child.body.split("/")[:-1], j.name]))
        rel = j.child.world.inv() @ j.world
        if j.type == "ball":
            body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_BALL, pos=list(rel.p))
            return
        kind = {
            "revolute": mujoco.mjtJoint.mjJNT_HINGE,
            "continuous": mujoco.mjtJoint.mjJNT_HINGE,
            "prismatic": mujoco.mjtJoint.mjJNT_SLIDE,
        }[j.type]
        axis_el = el.find("axis")
        if axis_el is None:
            raise self.error(
                f"{j.type} joint {j.name!r} has no <axis>", src, el, hint="e.g. <axis><xyz>0 0 1</xyz></axis>"
            )
        self.check(axis_el, src, {"xyz", "limit", "dynamics", "use_parent_model_frame"})
        xyz_el = axis_el.find("xyz")
        if xyz_el is None:
            raise self.error(
                f"the <axis> of joint {j.name!r} has no <xyz>", src, axis_el, hint="e.g. <xyz>0 0 1</xyz>"
            )
        axis = unit(self.floats(xyz_el, src, 3))
        if axis is None:
            raise self.error(
                f"the axis of joint {j.name!r} is zero",
                src,
                xyz_el,
                hint="give the direction it turns or slides about, e.g. <xyz>0 0 1</xyz>",
            )
        # Which frame the axis is expressed in: 1.4 the model; 1.5/1.6 the joint unless
        # use_parent_model_frame; 1.7+ `expressed_in`.
        expressed = xyz_el.get("expressed_in")
        in_model = src.version is not None and src.version < (1, 5)
        if self.child_bool(axis_el, "use_parent_model_frame", src):
            in_model = True
        if expressed:
            in_model = expressed == "__model__"
            if expressed not in ("__model__", j.name):
                self.note(f"axis expressed_in {expressed!r} is taken as the joint frame", src, xyz_el)
        world_axis = rotate(j.model_world.q, axis) if in_model else rotate(j.world.q, axis)
        local_axis = rotate(j.child.world.inv().q, world_axis)
        joint = body.add_joint(name=name, type=kind, pos=list(rel.p), axis=list(local_axis))
        limit = axis_el.find("limit")
        if limit is not None and j.type != "continuous":
            self.check(limit, src, {"lower", "upper", "stiffness", "dissipation"})
            lo = self.child_float(limit, "lower", src, -math.inf)
            hi = self.child_float(limit, "upper", src, math.inf)
            if -1e15 < lo < hi < 1e15:
                if kind == mujoco.mjtJoint.mjJNT_HINGE and self.spec.compiler.degree:
                    lo, hi = math.degrees(lo), math.degrees(hi)
                joint.range = [lo, hi]
                joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        dyn = axis_el.find("dynamics")
        if dyn is not None:
            self.check(dyn, src, {"damping", "friction", "spring_reference", "spring_stiffness"})
            joint.damping = [self.child_float(dyn, "damping", src, 0.0), 0.0, 0.0]  # (linear, ...) terms
            joint.frictionloss = self.child_float(dyn, "friction", src, 0.0)
            stiffness = self.child_float(dyn, "spring_stiffness", src, 0.0)
            if stiffness:
                joint.stiffness = [stiffness, 0.0, 0.0]
                joint.springref = self.child_float(dyn, "spring_reference", src, 0.0)

    def link(self, body: mujoco.MjsBody, link: Link) -> None:
        el, src = link.el, link.src
        self.check(el, src, {"pose", "inertial", "collision", "visual", "light", "gravity"})
        mass = 0.0
        if not link.static:
            mass = self.inertial(body, link)
            if self.child_bool(el, "gravity", src) is False:
                body.gravcomp = 1.0
        visuals = [self.geom(link, v, visual=True, rgba=None, mass=mass) for v in el.findall("visual")]
        first_rgba = next((kw["rgba"] for kw in visuals if kw), None)
        collisions = [
            self.geom(link, c, visual=False, rgba=first_rgba or GREY, mass=mass)
            for c in el.findall("collision")
        ]
        for kw in collisions + visuals:  # collisions first: they keep their plain name if a visual shares it
            if kw is not None:
                kw["name"] = self.unique("geom", f"{link.body}/{kw['name']}")
                pieces = kw.pop("_pieces", None)
                if pieces:
                    # the mesh itself stays for rays (its real faces), touching nothing; its convex pieces
                    # collide, seen by no ray and no camera
                    for k, mesh in enumerate(pieces):
                        piece = {**kw, "meshname": mesh, "group": PIECES_GROUP}
                        piece["name"] = self.unique("geom", f"{kw['name']}/piece{k}")
                        body.add_geom(**piece)
                    kw.update(contype=0, conaffinity=0, group=RAY_GROUP)
                body.add_geom(**kw)
        for li in el.findall("light"):
            self.light(li, src, body, IDENTITY, link.body + "/")

    def inertial(self, body: mujoco.MjsBody, link: Link) -> float:
        el, src = link.el, link.src
        inertial = el.find("inertial")
        if inertial is None:
            self.no_inertial.append((link.body, src.path, el.sourceline))
            mass, full, ipose = 1.0, [1.0, 1.0, 1.0, 0.0, 0.0, 0.0], IDENTITY
        else:
            self.check(inertial, src, {"mass", "inertia", "pose"})
            mass = self.child_float(inertial, "mass", src, 1.0)
            if mass <= 0:
                raise self.error(
                    f"link {link.body!r} has mass {mass}; a moving link needs a positive mass",
                    src,
                    inertial.find("mass"),
                    hint="give it a <mass> or make the model <static>true</static>",
                )
            ipose = self.pose_of(inertial, src)[0]
            i = inertial.find("inertia")
            if i is None:
                full = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
            else:
                self.check(i, src, {"ixx", "iyy", "izz", "ixy", "ixz", "iyz"})
                full = [
                    self.child_float(i, t, src, d)
                    for t, d in (
                        ("ixx", 1.0),
                        ("iyy", 1.0),
                        ("izz", 1.0),
                        ("ixy", 0.0),
                        ("ixz", 0.0),
                        ("iyz", 0.0),
                    )
                ]
        body.mass = mass
        body.ipos = list(ipose.p)
        body.iquat = list(ipose.q)
        body.fullinertia = full
        body.explicitinertial = True
        return mass
