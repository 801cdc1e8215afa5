"""A `<model>` read into links and joints with their world poses: `relative_to` frames (links, nested
models, `<frame>`s, joints), nested models and includes, joints' parent and child links."""

from __future__ import annotations

from collections.abc import Callable

from lxml import etree

from runner.compile.sdf.parts import Collected, Joint, Link, Src
from runner.compile.sdf.pose import IDENTITY, Pose
from runner.compile.sdf.reader import Reader
from runner.errors import closest


class _Frames:
    """The frames of one model that a `relative_to` may name (links, nested models, `<frame>`s, joints),
    each resolved once to its pose in the model frame; a name that is no frame of the model, or a loop,
    is a notice and taken relative to the model."""

    def __init__(self, reader: Reader, el: etree._Element, src: Src, model: str):
        self.reader, self.src, self.model = reader, src, model
        self.entries: dict[str, etree._Element] = {}
        for ch in el:
            if ch.tag in ("link", "model", "frame", "joint"):
                n = ch.get("name")
                if not n:
                    hint = f'give it one: <{ch.tag} name="...">'
                    raise reader.error(f"a <{ch.tag}> of model {model!r} has no name", src, ch, hint=hint)
                self.entries.setdefault(n, ch)
        self.resolved: dict[str, Pose] = {}
        self.busy: set[str] = set()

    def of(self, name: str) -> Pose | None:
        """The pose of the frame named `name`, None when the model has none of that name."""
        return self.pose(self.entries[name]) if name in self.entries else None

    def pose(self, ch: etree._Element, default: str | None = None) -> Pose:
        """The pose of element `ch` (with a `<pose>`) in the model frame; `default`: the frame its pose is
        relative to when it names none."""
        n = ch.get("name", "")
        if n in self.resolved and self.entries.get(n) is ch:
            return self.resolved[n]
        local, rel, pel = self.reader.pose_of(ch, self.src)
        if ch.tag == "frame" and rel is None:
            rel = ch.get("attached_to") or None
        elif ch.tag == "joint" and rel is None:
            rel = (ch.findtext("child") or "").strip() or None
        rel = rel or default
        base = IDENTITY
        if rel and rel != "__model__":
            target = self.entries.get(rel)
            if target is None or target is ch or rel in self.busy:
                self.reader.note(
                    f"pose relative_to {rel!r} in model {self.model!r} is not a frame of the model; "
                    "taken relative to the model",
                    self.src,
                    pel if pel is not None else ch,
                )
            else:
                self.busy.add(n)
                base = self.pose(target)
                self.busy.discard(n)
        pose = base @ local
        if self.entries.get(n) is ch:
            self.resolved[n] = pose
        return pose


class ModelReader(Reader):
    """Reads models into links and joints placed in the world."""

    def model(
        self,
        el: etree._Element,
        src: Src,
        world: Pose,
        path: list[str],
        static_parent: bool,
        static_override: bool | None,
        name: str,
    ) -> Collected:
        """Reads a model (the pose of its frame given) and its nested models: links and joints."""
        self.check(el, src, {"static", "pose", "link", "joint", "model", "include", "frame"})
        own_static = self.child_bool(el, "static", src)
        static = static_override if static_override is not None else bool(own_static) or static_parent
        out = Collected()

        frames = _Frames(self, el, src, name)
        links: dict[str, Link] = {}
        for ch in el:
            if ch.tag == "link":
                lname = ch.get("name")
                assert lname
                link = Link(
                    key=lname,
                    body="/".join([*path, lname]),
                    world=world @ frames.pose(ch),
                    el=ch,
                    src=src,
                    static=static,
                    model_world=world,
                )
                links[lname] = link
                out.links.append(link)
            elif ch.tag == "model":
                sub = ch.get("name")
                assert sub
                inner = self.model(ch, src, world @ frames.pose(ch), [*path, sub], static, None, sub)
                self.merge(out, inner, sub, links)
            elif ch.tag == "include":
                sub, inner = self.include(ch, src, world, path, static, frame_of=frames.of)
                if inner is not None:
                    self.merge(out, inner, sub, links)

        for ch in el.findall("joint"):
            joint = self.joint(ch, src, links, name, world, frames.pose)
            if joint is not None:
                out.joints.append(joint)
        return out

    @staticmethod
    def merge(out: Collected, inner: Collected, sub: str, links: dict[str, Link]) -> None:
        for link in inner.links:
            link.key = f"{sub}::{link.key}"
            links[link.key] = link
            out.links.append(link)
        out.joints.extend(inner.joints)

    def joint(
        self,
        el: etree._Element,
        src: Src,
        links: dict[str, Link],
        model: str,
        model_world: Pose,
        frame: Callable[..., Pose],
    ) -> Joint | None:
        jname = el.get("name", "")
        jtype = (el.get("type") or "").strip()
        self.check(el, src, {"parent", "child", "pose", "axis"})
        ends: list[Link | None] = []
        for tag in ("parent", "child"):
            c = el.find(tag)
            ref = (c.text or "").strip() if c is not None else ""
            if not ref:
                raise self.error(
                    f"joint {jname!r} has no <{tag}>",
                    src,
                    el,
                    hint=f"add <{tag}>link_name</{tag}> naming one of: " + ", ".join(links),
                )
            if ref == "world" and tag == "parent":
                ends.append(None)
                continue
            ref = ref.removeprefix(f"{model}::")
            if ref not in links:
                raise self.error(
                    f"joint {jname!r} names {tag} link {ref!r}, which is not in model {model!r}",
                    src,
                    c,
                    hint=(f"did you mean {near!r}? " if (near := closest(ref, links)) else "")
                    + "links of the model: "
                    + ", ".join(links),
                )
            ends.append(links[ref])
        parent, child = ends
        assert child is not None
        local, rel, _ = self.pose_of(el, src)
        world = model_world @ frame(el) if rel and rel != child.key else child.world @ local
        return Joint(jname, jtype, parent, child, world, el, src, model_world)
