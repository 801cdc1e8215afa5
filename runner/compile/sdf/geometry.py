"""A `<collision>` or `<visual>` as the arguments of a MuJoCo geom: its shape (box, cylinder, cone as a
convex mesh, sphere, capsule, ellipsoid, plane, mesh; scaled by the model's saved scale), its colour
(`<material>` rgba or the classic `Gazebo/...` names, transparency) and its `<surface>` (friction, collide
bitmasks, contact stiffness)."""

from __future__ import annotations

import math

import mujoco
from lxml import etree

from runner.compile.materials import gazebo_material
from runner.compile.sdf.parts import Link, Src
from runner.compile.sdf.pose import Pose, qmul, quat_z_to, rotate, unit
from runner.compile.sdf.reader import PLANE, Reader, is_custom
from runner.compile.urdf import COLLISION_GROUP

GREY = (0.7, 0.7, 0.7, 1.0)  # what has no colour of its own
_GEOM_KEYS = {"box", "cylinder", "cone", "sphere", "capsule", "ellipsoid", "plane", "mesh", "empty"}
_CONE_SEGMENTS = 48
_GEOM_SKIPPED = {"heightmap", "polyline", "image"}


class GeometryReader(Reader):
    """Reads collisions and visuals into geom arguments."""

    def geom(
        self,
        link: Link,
        el: etree._Element,
        *,
        visual: bool,
        rgba: tuple[float, ...] | None,
        mass: float,
    ) -> dict[str, object] | None:
        """The `add_geom` arguments of a <collision> or <visual> (None: left out); `name` is the SDF name."""
        src = link.src
        kind = "visual" if visual else "collision"
        handled = {"pose", "geometry"} | ({"material", "transparency"} if visual else {"surface"})
        self.check(el, src, handled)
        local, rel, pel = self.pose_of(el, src)
        if rel and rel != link.key.split("::")[-1]:
            self.note(f"{kind} pose relative_to {rel!r} is taken relative to its link", src, pel)
        g = el.find("geometry")
        if g is None:
            raise self.error(
                f"a <{kind}> of link {link.body!r} has no <geometry>",
                src,
                el,
                hint="e.g. <geometry><box><size>1 1 1</size></box></geometry>",
            )
        what = f"{kind} {el.get('name') or kind!r} of {link.body!r}"
        self.last_pieces = None
        kw = self.shape(g, src, link, local, visual, what)
        if kw is None:
            return None
        if self.last_pieces and not visual:
            kw["_pieces"] = self.last_pieces
        kw["name"] = el.get("name") or kind
        if visual:
            kw.update(contype=0, conaffinity=0, group=1, rgba=list(self.colour(el, src)))
        else:
            kw.update(group=COLLISION_GROUP, rgba=list(rgba or GREY))
            self.surface(el.find("surface"), src, kw, link, mass)
        if kw.pop("_ground", False):
            self.take_ground(kw, visual, src, el)
            return None
        kw["pos"] = list(kw.pop("_pose").p)  # type: ignore[attr-defined]
        return kw

    def shape(
        self, g: etree._Element, src: Src, link: Link, local: Pose, visual: bool, what: str
    ) -> dict[str, object] | None:
        """The geom arguments of a `<geometry>`'s shape (its `quat` and, as `_pose`, its pose in the link),
        None when it is left out; `local`: the geom's `<pose>`."""
        shapes = [c for c in g if isinstance(c.tag, str) and not is_custom(c)]
        known = [c for c in shapes if c.tag in _GEOM_KEYS]
        for c in shapes:
            if c.tag not in _GEOM_KEYS:
                self.skip(c, src)
        if not known:
            if any(c.tag in _GEOM_SKIPPED for c in shapes):
                return None
            raise self.error(
                "a <geometry> has no shape",
                src,
                g,
                hint="one of: box, cylinder, cone, sphere, capsule, ellipsoid, plane, mesh",
            )
        s = known[0]
        if s.tag == "empty":
            return None
        pose = local
        if s.tag == "plane":
            found = self.plane(s, src, link, local)
            if found is None:
                return None
            kw, pose = found
        elif s.tag == "mesh":
            mesh = self.mesh(
                s, src, visual=visual, what=what, convex_check=link.static and not visual, scaled=link.scale
            )
            if mesh is None:
                return None
            kw = {"type": mujoco.mjtGeom.mjGEOM_MESH, "meshname": mesh}
        else:
            kw = self.solid(s, src, link)
        self.check(s, src, {"size", "radius", "length", "radii", "normal", "uri", "scale", "submesh"})
        kw["quat"] = list(pose.q)
        kw["_pose"] = pose
        return kw

    def solid(self, s: etree._Element, src: Src, link: Link) -> dict[str, object]:
        """The type and size of a box, cylinder, capsule, cone (a mesh), sphere or ellipsoid, scaled by the
        model's saved scale (Gazebo scales each shape: box sizes one by one, a cylinder's radius by the
        larger of x and y and its length by z, a sphere's radius by the largest)."""
        G = mujoco.mjtGeom
        sx, sy, sz = link.scale
        sr = max(sx, sy)
        if s.tag == "box":
            x, y, z = self.floats(self.need(s, "size", src), src, 3)
            return {"type": G.mjGEOM_BOX, "size": [x * sx / 2, y * sy / 2, z * sz / 2]}
        if s.tag in ("cylinder", "capsule"):
            r = self.child_float(s, "radius", src) * sr
            length = self.child_float(s, "length", src) * sz
            kind = G.mjGEOM_CYLINDER if s.tag == "cylinder" else G.mjGEOM_CAPSULE
            return {"type": kind, "size": [r, length / 2, 0]}
        if s.tag == "cone":
            r = self.child_float(s, "radius", src) * sr
            length = self.child_float(s, "length", src) * sz
            if r <= 0 or length <= 0:
                raise self.error(
                    f"a <cone> needs a positive radius and length, found {r} and {length}",
                    src,
                    s,
                    hint="give <radius> and <length> in metres, both above 0",
                )
            return {"type": G.mjGEOM_MESH, "meshname": self.cone_mesh(r, length)}
        if s.tag == "sphere":
            radius = self.child_float(s, "radius", src) * max(link.scale)
            return {"type": G.mjGEOM_SPHERE, "size": [radius, 0, 0]}
        assert s.tag == "ellipsoid"
        radii = self.floats(self.need(s, "radii", src), src, 3)
        return {"type": G.mjGEOM_ELLIPSOID, "size": [a * b for a, b in zip(radii, link.scale, strict=True)]}

    def plane(
        self, s: etree._Element, src: Src, link: Link, local: Pose
    ) -> tuple[dict[str, object], Pose] | None:
        """A `<plane>`'s geom arguments and its pose (turned to its normal); None when it is left out (a
        second ground). A static plane at z=0 may be the world's ground (`ground_role`: `_ground` set); on
        a moving link it is a thin box."""
        n_el = s.find("normal")
        normal = unit(self.floats(n_el, src, 3)) if n_el is not None else (0.0, 0.0, 1.0)
        if normal is None:
            raise self.error(
                "the <normal> of a plane is zero", src, n_el, hint="e.g. <normal>0 0 1</normal> for a floor"
            )
        size_el = s.find("size")
        sx, sy = self.floats(size_el, src, 2) if size_el is not None else (1.0, 1.0)
        sx, sy = sx * link.scale[0], sy * link.scale[1]
        pose = Pose(local.p, qmul(local.q, quat_z_to(normal)))
        world = link.world @ pose
        up = rotate(world.q, (0.0, 0.0, 1.0))
        kw: dict[str, object] = {}
        if not link.static:
            self.note("a plane on a moving link is a thin box (MuJoCo planes are static)", src, s)
            kw.update(type=mujoco.mjtGeom.mjGEOM_BOX, size=[sx / 2, sy / 2, 0.005])
            return kw, pose
        if up[2] < 1 - 1e-9:
            self.note("this plane is not horizontal; MuJoCo planes are infinite", src, s)
        elif abs(world.p[2]) < 1e-6:
            role = self.ground_role(link, src, s)
            if role == "drop":
                return None
            kw["_ground"] = role == "ground"
        kw.update(type=PLANE, size=[sx / 2, sy / 2, 0.05])
        return kw, pose

    def cone_mesh(self, radius: float, length: float) -> str:
        """A cone as SDF (and gz-sim) draws it: axis +Z, base at -length/2, apex at +length/2. MuJoCo has no
        cone; the mesh is convex, so colliding with its hull is exact."""
        key = ("<cone>", (radius, length))
        if key in self.meshes:
            return self.meshes[key]
        n = _CONE_SEGMENTS
        angles = [2 * math.pi * i / n for i in range(n)]
        verts = [(radius * math.cos(a), radius * math.sin(a), -length / 2) for a in angles]
        verts += [(0.0, 0.0, length / 2), (0.0, 0.0, -length / 2)]  # apex n, base centre n + 1
        faces: list[int] = []
        for i in range(n):
            j = (i + 1) % n
            faces += [i, j, n, j, i, n + 1]  # side (outward, counter-clockwise), base (facing -Z)
        name = self.unique("mesh", f"sdf/cone_{radius:g}x{length:g}")
        self.spec.add_mesh(name=name, uservert=[c for v in verts for c in v], userface=faces)
        self.meshes[key] = name
        return name

    def colour(self, v: etree._Element, src: Src) -> tuple[float, ...]:
        rgba: tuple[float, ...] = GREY
        mat = v.find("material")
        if mat is not None:
            self.check(mat, src, {"diffuse", "ambient", "script", "pbr"})
            for tag in ("diffuse", "ambient"):
                c = mat.find(tag)
                if c is not None:
                    vals = self.floats(c, src, (3, 4))
                    rgba = (*vals, 1.0) if len(vals) == 3 else vals
                    break
            else:
                script = mat.find("script")
                if script is not None:
                    self.check(script, src, {"name", "uri"})
                    name = (script.findtext("name") or "").strip()
                    found = gazebo_material(name)
                    if found is None:
                        self.note(f"material {name!r} is not known; grey is used", src, script)
                    else:
                        rgba = found
        t = v.find("transparency")
        if t is not None:
            alpha = 1.0 - min(max(self.floats(t, src, 1)[0], 0.0), 1.0)
            rgba = (*rgba[:3], rgba[3] * alpha)
        return tuple(min(max(c, 0.0), 1.0) for c in rgba)

    def surface(
        self, s: etree._Element | None, src: Src, kw: dict[str, object], link: Link, mass: float
    ) -> None:
        if s is None:
            return
        self.check(s, src, {"friction", "contact", "bounce"})
        bounce = s.find("bounce")
        if bounce is not None:
            self.check(bounce, src, {"restitution_coefficient", "threshold"})
            if self.child_float(bounce, "restitution_coefficient", src, 0.0) > 0:
                self.skip(bounce, src)  # "restitution is not simulated": only when some is asked for
        fr = s.find("friction")
        if fr is not None:
            self.check(fr, src, {"ode"})
            ode = fr.find("ode")
            if ode is not None:
                self.check(ode, src, {"mu", "mu2"})
                mus = [self.child_float(ode, t, src) for t in ("mu", "mu2") if ode.find(t) is not None]
                if mus:
                    # Gazebo takes the smaller of two surfaces' mu, MuJoCo the larger unless one geom has
                    # priority. As for the ground (`take_ground`): a slippery surface (mu under 1, every
                    # surface's default in both) gets the top priority, so what touches it gets its mu, as the
                    # smaller-of-two would give anything grippier; a grippy one (mu 100 is common) keeps 1 and
                    # no priority, so a robot's wheels and casters keep the mu they state (a caster's 0)
                    # instead of dragging at 100.
                    mu = max(min(mus), 0.0)
                    kw["friction"] = [min(mu, 1.0), 0.005, 0.0001]
                    kw["priority"] = 2 if mu < 1.0 else 0
        ct = s.find("contact")
        if ct is None:
            return
        self.check(ct, src, {"ode", "collide_bitmask", "collide_without_contact", "category_bitmask"})
        if self.child_bool(ct, "collide_without_contact", src):
            kw.update(contype=0, conaffinity=0)
        mask_el = ct.find("collide_bitmask")
        if mask_el is not None:
            try:
                mask = int((mask_el.text or "").strip(), 0)
            except ValueError:
                raise self.error(
                    "<collide_bitmask> must be an integer such as 0x01",
                    src,
                    mask_el,
                    hint="write it in decimal (3) or hexadecimal (0x03)",
                ) from None
            kw.update(contype=mask & 0xFFFFFFFF, conaffinity=mask & 0xFFFFFFFF)
        ode = ct.find("ode")
        if ode is None:
            return
        self.check(ode, src, {"kp", "kd"})
        kp_el = ode.find("kp")
        if kp_el is None:
            return
        kp = self.floats(kp_el, src, 1)[0]
        kd = self.child_float(ode, "kd", src, 1.0)
        if link.static or mass <= 0:
            self.note(
                "contact <kp>/<kd> on a static model is not used (its stiffness needs a mass)", src, kp_el
            )
            return
        if kp <= 0:
            return
        # A mass-spring-damper m x'' + kd x' + kp x = 0 has w = sqrt(kp/m) and zeta = kd / (2 sqrt(kp m));
        # MuJoCo's solref (timeconst, dampratio) gives w = 1/(timeconst dampratio), zeta = dampratio.
        w = math.sqrt(kp / mass)
        if w * 2 * self.timestep >= 1:
            return  # stiffer than a step can resolve: MuJoCo's rigid default is the same thing
        zeta = min(max(kd / (2 * math.sqrt(kp * mass)), 0.01), 10.0)
        kw["solref"] = [1.0 / (w * zeta), zeta]
        kw["priority"] = 1
