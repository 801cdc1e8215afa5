"""What lights and carries the world besides models: the ground plane (`model://ground_plane`, or the
file's own plane at z=0 taking over the scenario's ground geom; a second one left out), the sun and
`<light>`s."""

from __future__ import annotations

import math

import mujoco
from lxml import etree

from runner.compile.sdf.parts import Link, Src
from runner.compile.sdf.pose import Pose, rotate, unit, vec_add
from runner.compile.sdf.reader import PLANE, Reader
from runner.scenario.schema import Ground

_GROUND_RGBA = (0.55, 0.57, 0.6, 1.0)


class SceneBuilder(Reader):
    """Adds the ground plane, the sun and lights."""

    def ground(self, pose: Pose, src: Src, el: etree._Element) -> None:
        """`model://ground_plane`: the world's ground as it is (the scenario's), or a plain one."""
        assert self.result is not None
        if self.ground_owner is not None:
            self.duplicate_ground(src, el)
            return
        self.ground_owner = ("model://ground_plane", src.path, el.sourceline)
        if self.ground_geom is not None:
            return
        self.ground_geom = self.spec.worldbody.add_geom(
            name=self.unique("geom", "ground"),
            type=PLANE,
            size=[0, 0, 0.05],
            pos=list(pose.p),
            quat=list(pose.q),
            rgba=list(_GROUND_RGBA),
            friction=[1.0, 0.005, 0.0001],
        )
        self.result.ground = True

    def duplicate_ground(self, src: Src, el: etree._Element) -> None:
        assert self.ground_owner is not None
        label, file, line = self.ground_owner
        where = f"line {line}" if file == src.path else f"{file}:{line}"
        self.note(
            f"the world file already has a ground plane ({label}, {where}); this plane at z=0 is left out",
            src,
            el,
        )

    def ground_role(self, link: Link, src: Src, el: etree._Element) -> str:
        """What a static horizontal plane at z=0 of `link` is: `ground` (the world's ground: its settings go
        onto the ground geom, no second plane is added), `add` (the scenario has no ground: the plane is
        added as it is) or `drop` (the file has a ground already: a notice, the plane is left out). The
        first such link in the file is the ground."""
        if self.ground_owner is None:
            assert self.result is not None
            self.ground_owner = (f"model {link.body.split('/')[0]!r}", src.path, link.el.sourceline)
            self.ground_link = self.result.ground_model = link.body
        elif self.ground_link != link.body:
            self.duplicate_ground(src, el)
            return "drop"
        return "add" if self.ground_geom is None else "ground"

    def take_ground(self, kw: dict[str, object], visual: bool, src: Src, el: etree._Element) -> None:
        """The world file's own ground plane is the ground: its surface (friction, collide bitmask) and its
        colour go onto the ground geom, unless the scenario's `world.ground` sets them."""
        assert self.ground_geom is not None
        ground = self.ground_geom
        default = Ground()
        if visual:
            if all(abs(a - b) < 1e-6 for a, b in zip(ground.rgba, default.rgba, strict=True)):
                ground.rgba = list(kw["rgba"])  # type: ignore[call-overload]
            return
        friction = kw.get("friction")
        if isinstance(friction, list):
            mu = float(friction[0])
            if abs(ground.friction[0] - default.friction) > 1e-9:
                self.note(
                    f"the ground plane's friction {mu:g} is not used: the scenario's "
                    f"`world.ground.friction` ({ground.friction[0]:g}) is",
                    src,
                    el,
                )
            else:
                # Gazebo takes the smaller mu of two surfaces, MuJoCo the larger unless one geom has
                # priority. A slippery ground (mu under 1, the default of every surface in both) gets the
                # top priority: its mu is what everything on it gets, as Gazebo's smaller-of-two would
                # give anything grippier. A grippy one (Gazebo's ground_plane says mu 100) leaves every
                # other surface its own friction, as the smaller-of-two does: 1 here, no priority, so
                # geoms that state theirs (robot wheels, a caster's 0: priority 1) keep it.
                ground.friction = [min(mu, 1.0), ground.friction[1], ground.friction[2]]
                ground.priority = 2 if mu < 1.0 else 0
        for k in ("contype", "conaffinity"):  # a collide bitmask
            if k in kw:
                setattr(ground, k, kw[k])

    def sun(self, pose: Pose) -> None:
        direction = unit(rotate(pose.q, (-0.5, 0.1, -0.9)))
        existing = self.spec.light("sun")
        if existing is not None:
            return  # the world has its sun already
        self.names["light"].add("sun")
        self.spec.worldbody.add_light(
            name="sun",
            type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
            pos=list(vec_add(pose.p, (0.0, 0.0, 10.0))),
            dir=list(direction or (0.0, 0.0, -1.0)),
            diffuse=[0.8, 0.8, 0.8],
            specular=[0.2, 0.2, 0.2],
            castshadow=True,
        )

    def light(self, el: etree._Element, src: Src, body: mujoco.MjsBody, parent: Pose, prefix: str) -> None:
        self.check(
            el,
            src,
            {"pose", "diffuse", "specular", "attenuation", "direction", "spot", "cast_shadows", "intensity"},
        )
        ltype = (el.get("type") or "point").strip()
        types = {
            "directional": mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
            "point": mujoco.mjtLightType.mjLIGHT_POINT,
            "spot": mujoco.mjtLightType.mjLIGHT_SPOT,
        }
        if ltype not in types:
            self.note(f"light type {ltype!r} is not known; the light is left out", src, el)
            return
        pose = parent @ self.pose_of(el, src)[0]
        d_el = el.find("direction")
        direction = unit(self.floats(d_el, src, 3)) if d_el is not None else (0.0, 0.0, -1.0)
        direction = rotate(pose.q, direction or (0.0, 0.0, -1.0))
        kw: dict[str, object] = {
            "type": types[ltype],
            "pos": list(pose.p),
            "dir": list(direction),
            "castshadow": bool(self.child_bool(el, "cast_shadows", src)),
        }
        for tag in ("diffuse", "specular"):
            c = el.find(tag)
            if c is not None:
                kw[tag] = list(self.floats(c, src, (3, 4))[:3])
        att = el.find("attenuation")
        if att is not None:
            self.check(att, src, {"range", "constant", "linear", "quadratic"})
            kw["attenuation"] = [
                self.child_float(att, "constant", src, 1.0),
                self.child_float(att, "linear", src, 0.0),
                self.child_float(att, "quadratic", src, 0.0),
            ]
            if att.find("range") is not None:
                kw["range"] = self.child_float(att, "range", src)
        spot = el.find("spot")
        if spot is not None and ltype == "spot":
            self.check(spot, src, {"inner_angle", "outer_angle", "falloff"})
            kw["cutoff"] = math.degrees(self.child_float(spot, "outer_angle", src, math.radians(90))) / 2
            kw["exponent"] = self.child_float(spot, "falloff", src, 1.0)
        name = prefix + (el.get("name") or "light")
        existing = self.spec.light(name) if not prefix else None
        if existing is not None and ltype == "directional" and existing.type == types[ltype]:
            for k, v in kw.items():  # the world's own sun: the file's settings win, no second sun
                setattr(existing, k, v)
            return
        body.add_light(name=self.unique("light", name), **kw)
