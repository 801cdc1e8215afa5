"""The file as a whole: a `<world>` (its `<physics>`, `<gravity>`, `<state>` with saved poses, scales,
insertions and deletions) or a bare `<model>`, and each top-level model placed and built."""

from __future__ import annotations

import math
from pathlib import Path

from lxml import etree

from runner.compile.sdf.parts import Collected, ModelState, SdfWorld, Src
from runner.compile.sdf.pose import IDENTITY, Pose
from runner.compile.sdf.reader import Reader, SdfError, combine_errors, xml_bool


class WorldReader(Reader):
    """Reads the file: its world (or bare models), physics and saved state."""

    def load(self, path: Path) -> SdfWorld:
        """Reads the file; files it refers to that are missing are all listed in one error at the end."""
        try:
            result = self.read(path)
        except SdfError as e:
            if self.missing:
                raise combine_errors([*self.missing, e]) from None
            raise
        if self.missing:
            raise combine_errors(self.missing)
        return result

    def read(self, path: Path) -> SdfWorld:
        self.packages.add_package_of(path)  # its package's gazebo_model_path / gazebo_media_path exports
        root, src = self.parse(path)
        self.result = result = SdfWorld(file=src.path)
        self.stack.append(src.path)
        worlds = root.findall("world")
        if worlds:
            if len(worlds) > 1:
                self.note("the file holds several <world>s; only the first is loaded", src, worlds[1])
            self.check(root, src, {"world"})
            self.world(worlds[0], src, result)
        else:
            models = root.findall("model")
            if not models:
                raise self.error(
                    "the file has neither a <world> nor a <model>",
                    src,
                    root,
                    hint="write <sdf version='1.6'><world name='default'>...</world></sdf>",
                )
            self.check(root, src, {"model", "light"})
            for el in root:
                if el.tag == "model":
                    self.top_model(el, src, IDENTITY, name=None, pose=None, static=None)
                elif el.tag == "light":
                    self.light(el, src, self.spec.worldbody, IDENTITY, "")
        self.stack.pop()
        result.has_ground = self.ground_owner is not None
        return result

    def world(self, w: etree._Element, src: Src, result: SdfWorld) -> None:
        result.name = w.get("name")
        self.check(w, src, {"model", "include", "light", "physics", "gravity", "state"})
        states = w.findall("state")
        for extra in states[1:]:
            self.note("only the first <state> is applied", src, extra)
        insertions: list[etree._Element] = []
        if states:
            insertions = self.read_state(states[0], src)
        physics = w.findall("physics")
        if physics:
            chosen = next((p for p in physics if xml_bool(p.get("default"))), physics[0])
            for p in physics:
                if p is not chosen:
                    self.note("only one <physics> is used (the default one, else the first)", src, p)
            self.physics(chosen, src, result)
        g = w.find("gravity")
        if g is not None:
            result.gravity = self.floats(g, src, 3)  # type: ignore[assignment]
        for el in w:
            if el.tag == "model":
                self.top_model(el, src, IDENTITY, name=None, pose=None, static=None)
            elif el.tag == "include":
                self.include(el, src, IDENTITY, [], False, None, top=True)
            elif el.tag == "light":
                self.light(el, src, self.spec.worldbody, IDENTITY, "")
        for el in insertions:
            self.top_model(el, src, IDENTITY, name=None, pose=None, static=None)
        unused = [n for n in self.state if n not in result.models]
        if unused:
            self.note(
                f"<state> names model(s) the world does not have: {', '.join(unused[:5])}"
                + (" ..." if len(unused) > 5 else ""),
                src,
                self.state[unused[0]].el,
            )

    def read_state(self, st: etree._Element, src: Src) -> list[etree._Element]:
        """Reads a world's `<state>` (its models' and links' world poses, model scales, deletions) into
        `self.state`; returns the models its `<insertions>` add. Times, velocities, accelerations, wrenches
        and joint angles are not applied (the world starts at rest, as Gazebo's reset does)."""
        for el in st:
            if el.tag == "model" and el.get("name"):
                self.state[el.get("name")] = self.model_state(el, src, "")
            elif el.tag == "deletions":
                self.deleted |= {(n.text or "").strip() for n in el.findall("name")}
        ins = st.find("insertions")
        return ins.findall("model") if ins is not None else []

    def model_state(self, el: etree._Element, src: Src, scope: str) -> ModelState:
        pose_el = el.find("pose")
        scale_el = el.find("scale")
        scale = self.floats(scale_el, src, 3) if scale_el is not None else None
        out = ModelState(
            pose=self.pose(pose_el, src) if pose_el is not None else None,
            scale=scale,  # type: ignore[arg-type]
            links={},
            el=el,
        )
        for ch in el:
            name = ch.get("name")
            if not name:
                continue
            if ch.tag == "link" and ch.find("pose") is not None:
                out.links[scope + name] = self.pose(ch.find("pose"), src)
            elif ch.tag == "model":  # a nested model's links, scoped as the model's links are
                out.links.update(self.model_state(ch, src, f"{scope}{name}::").links)
        return out

    def physics(self, p: etree._Element, src: Src, result: SdfWorld) -> None:
        self.check(p, src, {"max_step_size", "real_time_factor", "gravity"})
        for tag in ("max_step_size", "real_time_factor"):
            el = p.find(tag)
            if el is not None:
                value = self.floats(el, src, 1)[0]
                if value <= 0:
                    raise self.error(
                        f"<{tag}> must be positive, found {value}",
                        src,
                        el,
                        hint="e.g. 0.001 (seconds) or 1.0",
                    )
                if tag == "max_step_size":
                    result.timestep = self.timestep = value
                else:
                    result.real_time_factor = value
        g = p.find("gravity")
        if g is not None:
            result.gravity = self.floats(g, src, 3)  # type: ignore[assignment]

    def top_model(
        self,
        el: etree._Element,
        src: Src,
        parent: Pose,
        *,
        name: str | None,
        pose: Pose | None,
        static: bool | None,
    ) -> None:
        assert self.result is not None
        model_name = name or el.get("name")
        if not model_name:
            raise self.error("a <model> has no name", src, el, hint="write <model name='...'>")
        if model_name in self.result.models or any(
            b.startswith(model_name + "/") for b in self.names["body"]
        ):
            raise self.error(
                f"the model name {model_name!r} is used twice",
                src,
                el,
                hint="model names must be unique in the world (and differ from robot namespaces); "
                "give each <include> its own <name>",
            )
        if model_name in self.deleted:
            self.note(f"model {model_name!r} is removed by the world's <state> <deletions>", src, el)
            return
        state = self.state.get(model_name)
        if pose is None:
            local, rel, pel = self.pose_of(el, src)
            if rel not in (None, "world", "__model__"):
                self.note(
                    f"pose relative_to {rel!r} of model {model_name!r} is taken relative to the world",
                    src,
                    pel,
                )
            pose = local
        if state is not None and state.pose is not None:
            parent, pose = IDENTITY, state.pose  # the saved pose is in the world frame
        collected = self.model(el, src, parent @ pose, [model_name], False, static, model_name)
        if state is not None:
            self.apply_state(state, collected, model_name, src)
        self.build(collected)
        self.result.models.append(model_name)

    def apply_state(self, state: ModelState, c: Collected, model: str, src: Src) -> None:
        """Links where the world's <state> saved them (as Gazebo sets each link's world pose), and the
        model's saved scale. A model with joints keeps its links where its joints hold them (its saved
        joint angles are not applied), with a notice when the saved poses differ."""
        moved = []
        for link in c.links:
            if state.scale is not None:
                link.scale = state.scale
            saved = state.links.get(link.key)
            if saved is None:
                continue
            off = math.dist(saved.p, link.world.p) + 2 * math.acos(
                min(1.0, abs(sum(a * b for a, b in zip(saved.q, link.world.q, strict=True))))
            )
            if off < 1e-6:
                continue
            if c.joints:
                moved.append(link.key)
            else:
                link.world = saved
        if moved:
            self.note(
                f"model {model!r} has joints: the poses <state> saved for its links ({', '.join(moved[:3])}) "
                "are not applied; its links are placed from the model's saved pose",
                src,
                state.el,
            )
