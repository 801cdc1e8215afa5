"""`<collision>` blocks of a `<gazebo reference="link">`: the SDF `<surface>` a URDF link's collisions get.

sdformat's URDF parser (src/parser_urdf.cc, main 2ace536) keeps each child of such a `<collision>` as a blob
and copies it into **every** collision of the link (`ParseSDFExtension`, lines 1322-1363: "are treated as
blobs that gets inserted into all collisions and visuals for the link"; `InsertSDFExtensionCollision`,
1604-1900: a `<surface>` blob replaces the collision's surface (1695-1717), then the URDF keys
`mu1`/`mu2`/`fdir1`/`kp`/`kd` are written over it (1859-1882); the keys it knows: 1366-1480, no `mu`). The
block's own `name` attribute is not read there: the blob goes to all of the link's own collisions, whatever it
says.

What the engines then do with a `<surface>` (cited where it is used):
- `<friction><ode><mu>`, `<mu2>`: classic ODE (gazebo/physics/ode/ODEPhysics.cc, `ODEPhysics::Collide`)
  and gz-physics dartsim (dartsim/src/SDFFeatures.cc 925-960, `ConstructSdfCollision`: `setFrictionCoeff`,
  `setSecondaryFrictionCoeff`; DART's ContactSurface.cpp, `DefaultContactSurfaceHandler::createParams`)
  both combine two surfaces by the **smaller** value, per direction.
- `<fdir1>`: the first friction direction, in the collision's frame (both engines rotate it with the
  collision), or, in gz-sim, in the frame of the link named by `gz:expressed_in` (SDFFeatures.cc:
  `setFirstFrictionDirectionFrame`; an unknown link is warned about and the collision's frame kept).
- `<slip1>`/`<slip2>`: force-dependent slip (ODE's contact CFM in each friction direction; dartsim's
  slip compliance): not simulated here.
- `<torsional>`: classic ODE's spin friction (gz-physics dartsim does not read it).
- `<bullet>`: read by the Bullet engine only, which neither Gazebo's default (ODE, DART) is.
- `<contact><ode><kp>`: the contact stiffness, as the URDF key `<kp>` (runner.compile.urdf.link_props).
"""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.info import LinkProps
from runner.compile.gazebo.tags import TagReader, floats

_SLIP = (
    "force-dependent slip (ODE's contact softness along each friction direction, dartsim's slip "
    "compliance) is not simulated: the contact grips up to mu as with slip 0"
)
_TORSIONAL = (
    "torsional (spin) friction is not simulated: gz-sim's dartsim does not read it either; classic ODE "
    "applies it only with a <patch_radius> or <surface_radius> (both 0 by default)"
)
_BULLET = "Bullet's settings: neither of Gazebo's default engines (classic ODE, gz-sim's dartsim) reads them"
_REASONS = {
    # <friction><ode>
    "slip1": _SLIP,
    "slip2": _SLIP,
    # <friction>
    "torsional": _TORSIONAL,
    "bullet": _BULLET,
    # <contact><ode>
    "kd": "contacts are critically damped here; <kp> sets their stiffness",
    "max_vel": "ODE's contact correction speed cap; MuJoCo's soft contacts (solref) correct on their own",
    "min_depth": "ODE's allowed penetration; MuJoCo's soft contacts (solref/solimp) set their own depth",
    "soft_cfm": "ODE's contact softness; MuJoCo's solref/solimp set it",
    "soft_erp": "ODE's contact softness; MuJoCo's solref/solimp set it",
    # <contact>
    "collide_bitmask": "collision bitmasks of URDF links are not applied; the link collides as Gazebo's "
    "default mask does",
    "category_bitmask": "collision bitmasks of URDF links are not applied",
    "collide_without_contact": "contact-only (sensor) collisions of URDF links are not applied",
    "collide_without_contact_bitmask": "contact-only (sensor) collisions of URDF links are not applied",
    "poissons_ratio": "ODE's elastic-contact model; MuJoCo's contacts are soft constraints",
    "elastic_modulus": "ODE's elastic-contact model; MuJoCo's contacts are soft constraints",
    # <surface>
    "bounce": "restitution is not simulated",
    "soft_contact": "DART's soft-body contact is not simulated",
    # <collision>
    "max_contacts": "MuJoCo finds contacts itself",
    "laser_retro": "laser retro-reflectivity is not simulated",
}


def read_collision_block(g: Any, coll: Any, link: str, props: LinkProps) -> None:
    """A `<collision>` blob of `<gazebo reference="link">`: its surface's friction and stiffness into
    `props`; every other element said at its own line with what Gazebo does with it."""
    where = f'<gazebo reference="{link}"><collision>'
    c = TagReader(coll)
    surface = c.child("surface")
    if surface is not None:
        _surface(g, surface, f"{where}<surface>", link, props)
    _say_rest(g, c, where)


def _surface(g: Any, surface: Any, where: str, link: str, props: LinkProps) -> None:
    s = TagReader(surface)
    friction = s.child("friction")
    if friction is not None:
        f = TagReader(friction)
        ode = f.child("ode")
        if ode is not None:
            _friction_ode(g, ode, f"{where}<friction><ode>", link, props)
        _say_rest(g, f, f"{where}<friction>")
    contact = s.child("contact")
    if contact is not None:
        ct = TagReader(contact)
        ode = ct.child("ode")
        if ode is not None:
            o = TagReader(ode)
            kp = o.float("kp")
            if kp is not None:
                props.kp = kp  # as the URDF key <kp>: both become this <contact><ode><kp>
            _say_rest(g, o, f"{where}<contact><ode>")
        _say_rest(g, ct, f"{where}<contact>")
    _say_rest(g, s, where)


def _friction_ode(g: Any, ode: Any, where: str, link: str, props: LinkProps) -> None:
    o = TagReader(ode)
    mu, mu2 = o.float("mu"), o.float("mu2")
    if mu2 is not None and mu is None:
        mu = 1.0  # SDF's default, in both engines
    if mu is not None and mu2 is None:
        # dartsim: setFrictionCoeff(mu) sets both directions, then mu2 only if given (SDFFeatures.cc); classic
        # ODE takes SDF's default 1 for mu2 (said in docs/gazebo_parity.md §14)
        mu2 = mu
    if mu is not None:
        props.mu1 = mu
    if mu2 is not None:
        props.mu2 = mu2
    known = [v for v in (props.mu1, props.mu2) if v is not None]
    if known:
        props.friction = min(known)
    el = o.child("fdir1")
    if el is not None:
        fdir = floats(o.text("fdir1"), 3)
        if fdir is None:
            g.note(el, f"<fdir1> {el.text!r} in {where} is not three numbers: it is not used")
        elif not any(fdir):
            props.fdir1 = None  # SDF's default 0 0 0: no direction (Gazebo: the engine picks one)
        else:
            props.fdir1 = (fdir[0], fdir[1], fdir[2])
            props.fdir1_at = g.where(el)
            props.fdir1_frame = _expressed_in(g, el, link)
    _say_rest(g, o, where)


def _expressed_in(g: Any, el: Any, link: str) -> str | None:
    """The link named by `gz:expressed_in` (also `ignition:`, with or without its `xmlns` declared), or None
    for the collision's own frame (runner.compile.wheels finds whether that link turns with the wheel)."""
    for key, value in el.attrib.items():
        name = str(key).rsplit("}", 1)[-1].rsplit(":", 1)[-1]
        if name != "expressed_in":
            continue
        frame = str(value).strip()
        if frame in g.link_names:
            return frame
        g.note(
            el,
            f"<fdir1> in <gazebo reference={link!r}> is expressed in {frame!r}, which is not a link of the "
            "robot: it is taken in the collision's frame, as gz-sim does (it warns 'Failed to get body "
            "node')",
            hint="name a link of the robot, e.g. the base link the wheels turn on",
        )
    return None


def _number(el: Any, tag: str, default: float) -> float:
    text = el.findtext(tag)
    try:
        return float(text) if text is not None and text.strip() else default
    except ValueError:
        return float("nan")  # not a number: said


def _no_torsion(el: Any) -> bool:
    """Classic ODE's torsional friction acts on a patch: with use_patch_radius (the default) of radius
    <patch_radius>, else of <surface_radius> and the depth; both 0 by default: no torque at all."""
    use_patch = (el.findtext("use_patch_radius") or "true").strip().lower() in ("1", "true")
    return _number(el, "patch_radius" if use_patch else "surface_radius", 0.0) == 0.0


def _integer(text: str | None) -> int | None:
    try:
        return int((text or "").strip(), 0)
    except ValueError:
        return None


# Elements whose value is what we do anyway (SDF's defaults, mostly): used as they are, nothing to say
_SAME_IF = {
    "slip1": lambda el: _number(el, ".", 0.0) == 0.0,
    "slip2": lambda el: _number(el, ".", 0.0) == 0.0,
    "torsional": _no_torsion,
    "bounce": lambda el: _number(el, "restitution_coefficient", 0.0) == 0.0,
    "collide_without_contact": lambda el: (el.text or "").strip().lower() in ("0", "false"),
    "collide_bitmask": lambda el: _integer(el.text) == 0xFFFF,
    "category_bitmask": lambda el: _integer(el.text) == 0xFFFF,
}


def _say_rest(g: Any, reader: TagReader, where: str) -> None:
    """What nothing read in this element: said at each element's line, with what Gazebo does with it
    (unless its value is what we do anyway)."""
    for el in reader.leftovers():
        same = _SAME_IF.get(el.tag)
        if same is not None and el.tag not in reader.single and same(el):
            reader.mark(el.tag)
            continue
        reason = _REASONS.get(el.tag)
        if reason is not None and el.tag not in reader.single:
            reader.mark(el.tag)
            g.note(el, f"<{el.tag}> in {where} is ignored ({reason})")
    g.ignored(reader, where)


def grips_by_friction(g: Any, joints: list[str]) -> bool:
    """Every joint's child link has friction differing along and across an fdir1: the description's own
    model of mecanum rollers (mu2 0 across a diagonal), which runner.compile.wheels simulates."""
    child = {
        j.get("name"): j.find("child").get("link")
        for j in g.root.findall("joint")
        if j.find("child") is not None
    }
    links = [g.info.links.get(child.get(j, "")) for j in joints]
    return bool(links) and all(
        p is not None and p.fdir1 is not None and p.mu1 is not None and p.mu2 is not None and p.mu1 != p.mu2
        for p in links
    )
