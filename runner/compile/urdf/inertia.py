"""Masses and inertias that Gazebo (ODE) takes and MuJoCo refuses, repaired as a careful user would, with
one warning per link saying what was changed (`repair_inertias`)."""

from __future__ import annotations

from typing import Any

from lxml import etree

from runner.compile.urdf.checks import number
from runner.errors import Notices
from runner.plan import ParityLine

# Mass given to a moving link whose mass is zero, negative or next to nothing (MuJoCo refuses those).
MIN_MASS = 1e-3
_NEAR_ZERO_MASS = 1e-5
# MJCF text keeps 6 significant digits: a repaired A + B exceeds C by more than their rounding
_TEXT_ROUNDING = 2e-5
# A principal moment this far below the largest (or not positive) is raised to a thousandth of it.
_MIN_MOMENT_RATIO = 1e-3


def repair_inertias(root: Any, where: Any, notices: Notices, adjusted: list[ParityLine]) -> None:
    """Masses and inertias Gazebo (ODE) takes and MuJoCo refuses, repaired as a careful user would, with
    one warning per link saying what was changed:

    - a moving link (a revolute, continuous or prismatic joint's child) with a zero, negative or near-zero
      mass gets `MIN_MASS`;
    - an inertia that is not positive definite (a zero or negative principal moment) has those moments
      raised to a thousandth of the largest (a solid 10 cm sphere's when all are zero);
    - principal moments that break the triangle inequality (A + B >= C: no rigid body has them, e.g.
      ixx = iyy = 0.01, izz = 0.5) have the two smaller ones scaled up until A + B = C.

    The orientation of the principal axes is kept: the repaired tensor is written back in the link's frame.
    """
    moving = {
        j.find("child").get("link")
        for j in root.findall("joint")
        if j.get("type") in ("revolute", "continuous", "prismatic") and j.find("child") is not None
    }
    for link in root.findall("link"):
        name = link.get("name")
        inertial = link.find("inertial")
        if inertial is None:
            continue
        changes: list[str] = []
        mass_el = inertial.find("mass")
        mass = (
            number(mass_el.get("value", "0") or "0", "mass", where, mass_el) if mass_el is not None else 0.0
        )
        if name in moving and mass < _NEAR_ZERO_MASS:
            changes.append(f"mass {mass:g} kg -> {MIN_MASS:g} kg")
            mass = MIN_MASS
            if mass_el is None:
                mass_el = etree.SubElement(inertial, "mass")
            mass_el.set("value", repr(mass))
        el = inertial.find("inertia")
        if el is not None:
            fixed = _repaired_inertia(el, mass, name in moving)
            if fixed is not None:
                tensor, before, after, nudged_only = fixed
                for key, value in zip(("ixx", "iyy", "izz", "ixy", "ixz", "iyz"), tensor, strict=True):
                    el.set(key, repr(value))
                if not nudged_only:
                    changes.append(f"principal moments {before} -> {after} kg·m²")
        if not changes:
            continue
        at = where(el if el is not None else inertial)
        message = f"link {name!r}: its inertia is not one MuJoCo accepts (Gazebo does): " + "; ".join(changes)
        notices.add(
            message,
            *at,
            hint="a rigid body needs a positive mass and principal moments with A + B >= C; fix the "
            "<inertial> to silence this",
        )
        file, line = at
        adjusted.append(ParityLine(kind="changed", text=message, file=str(file) if file else None, line=line))


def _repaired_inertia(el: Any, mass: float, moving: bool) -> tuple[tuple[float, ...], str, str, bool] | None:
    """(ixx, iyy, izz, ixy, ixz, iyz) repaired, the principal moments before and after, and whether it was
    only nudged by the MJCF text's rounding (not worth a warning); None if fine."""
    import numpy as np

    def num(key: str) -> float:
        try:
            return float(el.get(key, "0") or 0)
        except ValueError:
            return 0.0

    ixx, iyy, izz, ixy, ixz, iyz = (num(k) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz"))
    tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    moments, axes = np.linalg.eigh(tensor)
    new = moments.copy()
    largest = float(moments.max())
    if largest <= 0.0:
        if not moving and mass <= 0.0:
            return None  # a massless fixed link: MuJoCo asks nothing of it
        new[:] = 0.4 * max(mass, MIN_MASS) * 0.05**2
    else:
        floor = largest * _MIN_MOMENT_RATIO
        if moving or moments.min() < 0.0:
            new = np.maximum(new, np.where(new <= largest * 1e-9, floor, new))
    raised = not np.array_equal(new, moments)
    order = np.argsort(new)
    a, b, c = (float(new[i]) for i in order)
    margin = 1.0 + _TEXT_ROUNDING
    nudged_only = False
    if a + b < c * margin:
        # A + B = C exactly (a thin plate, or an xacro formula such as m/12 (y² + z²)) holds in floating
        # point but not once the MJCF text keeps 6 digits: such a tensor is nudged by that rounding, silently
        nudged_only = not raised and a + b >= c * (1.0 - 1e-9)
        scale = c * margin / (a + b) if a + b > 0 else None
        a, b = (a * scale, b * scale) if scale else (c / 2.0 * margin, c / 2.0 * margin)
        new[order[0]], new[order[1]] = a, b
    if np.array_equal(new, moments):
        return None
    fixed = axes @ np.diag(new) @ axes.T
    values = (fixed[0, 0], fixed[1, 1], fixed[2, 2], fixed[0, 1], fixed[0, 2], fixed[1, 2])

    def shown(v: Any) -> str:
        return "(" + ", ".join(f"{x:.4g}" for x in sorted(v)) + ")"

    return tuple(float(v) for v in values), shown(moments), shown(new), nudged_only


def weigh_massless_links(root: Any, where: Any, notices: Notices, adjusted: list[ParityLine]) -> None:
    """A moving link with no `<inertial>` and nothing to weigh (no `<collision>`, on itself or on the links
    fixed joints weld to it: a gripper finger with only a visual mesh) is refused by MuJoCo ("mass and
    inertia of moving bodies must be larger than mjMINVAL"). Gazebo's URDF import leaves such a link out,
    with its joint and what hangs from it ("link[...] has no <inertial> block defined ... is not modeled in
    sdf": sdformat `parser_urdf.cc` `CreateSDF`). It is kept here, as every link without `<inertial>` is
    (MuJoCo weighs those by their collisions), with `MIN_MASS` and a small solid sphere's inertia, so that
    its joint exists for the controllers that name it; a warning at the link's line says so. Runs after the
    shapes that cannot load are left out (a visual-only Collada finger is the case seen)."""
    moving = {
        j.find("child").get("link")
        for j in root.findall("joint")
        if j.get("type") in ("revolute", "continuous", "prismatic", "floating", "planar")
    }
    welded: dict[str, list[str]] = {}  # link -> the links fixed joints hang from it
    for j in root.findall("joint"):
        if j.get("type") == "fixed":
            welded.setdefault(j.find("parent").get("link"), []).append(j.find("child").get("link"))
    links = {el.get("name"): el for el in root.findall("link")}

    def weighs(name: str) -> bool:
        el = links.get(name)
        if el is None:
            return False
        inertial = el.find("inertial")
        if el.find("collision") is not None or inertial is not None:
            return True  # (a given <inertial>'s mass has been repaired by repair_inertias)
        return any(weighs(child) for child in welded.get(name, []))

    for name in sorted(moving, key=list(links).index):
        if weighs(name):
            continue
        link = links[name]
        inertial = etree.SubElement(link, "inertial")
        etree.SubElement(inertial, "mass", value=repr(MIN_MASS))
        moment = repr(0.4 * MIN_MASS * 0.01**2)  # a solid sphere of 1 cm radius
        etree.SubElement(inertial, "inertia", ixx=moment, iyy=moment, izz=moment, ixy="0", ixz="0", iyz="0")
        at = where(link)
        message = (
            f"link {name!r} moves but has no <inertial> and no <collision> to weigh: given {MIN_MASS:g} kg "
            "(Gazebo's URDF import leaves such a link and its joint out of the model; here its joint stays, "
            "for the controllers that name it)"
        )
        notices.add(message, *at, hint="give the link an <inertial> with its real mass to silence this")
        file, line = at
        adjusted.append(ParityLine(kind="changed", text=message, file=str(file) if file else None, line=line))
