"""`ReaderBase`: what every part of the Gazebo reader works with, and what the handlers of sensors and
plugins (runner.compile.gazebo.sensors, .sensor_plugins, .model_plugins, .controllers, .thirdparty) are
given as `g`: the description's tree, the robot's namespace and model name, and the services they share:
notices at a tag's line, reporting what a block left unread, adding a plugin, frame names, a plugin's ROS
block. `GazeboReader` (runner.compile.gazebo.reader) is the one subclass; the handlers import this module,
not the reader, so that the reader can import them."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from runner.compile.gazebo.info import DescribedPlugin, GazeboInfo, Spawn, Where
from runner.compile.gazebo.tables import IGNORED_REASONS
from runner.compile.gazebo.tags import TagReader, ros_topic
from runner.compile.locate import Locator
from runner.errors import TAG_IGNORED, Notices
from runner.frames import frame_id

# gazebo_ros's <ros> block (gazebo_ros/src/node.cpp: namespace, remapping, argument, parameter, qos): what
# we do not apply, and why
_ROS_REASONS = {
    "parameter": "ROS parameters of the plugin's node are not set here: the plugin reads its own tags",
    "qos": "gazebo_ros' QoS overrides are not applied",
}


class ReaderBase:
    def __init__(
        self,
        root: Any,
        file: Path | None,
        sources: list[Path],
        expanded: bool,
        namespace: str,
        notices: Notices,
        model: str | None = None,
    ):
        self.root = root
        self.where = Locator(file, sources, expanded)
        self.namespace = namespace
        self.model = model or namespace  # the model's name in Gazebo: the robot's name in the scenario
        self.controller_files: list[Path] = []
        self.spawn = Spawn()  # what the launch's spawners start (the scenario's `spawn:`)
        self.control_plugins: list[Any] = []  # the ros_control plugins (runner.compile.gazebo.controllers)
        self.notices = notices
        self.info = GazeboInfo()
        self._names: set[str] = set()
        # what the reader learns of the robot before reading its <gazebo> blocks (GazeboReader.read)
        self.link_names: set[str] = set()
        self.joint_names: set[str] = set()  # the moving ones
        self.fixed_joints: set[str] = set()
        self.lumped_into: dict[str, str] = {}  # the Gazebo link each URDF link becomes
        self.harmonic = False  # a description for Gazebo Harmonic (gz-sim systems)

    def note(
        self,
        el: Any,
        message: str,
        hint: str | None = None,
        *,
        kind: str | None = None,
        about: str | None = None,
    ) -> None:
        """Say `message` at `el`'s own file:line; `kind` and `about` as in runner.errors.Notice (what
        `scenario validate` groups the notices by)."""
        file, line = self.where(el)
        self.notices.add(message, file, line, hint, kind=kind, about=about)

    def ignored(self, reader: TagReader, context: str, reasons: dict[str, str] | str | None = None) -> None:
        """Say what nothing read of `reader`'s element, each at its own line, with why it is ignored:
        `reasons` by tag for this block (a string: the reason for any tag), else tables.IGNORED_REASONS."""
        seen: set[int] = set()
        for el, text in reader.not_numbers:
            if el is None or id(el) in seen:
                continue
            seen.add(id(el))
            self.note(
                el,
                f"<{el.tag}> {text!r} in {context} is not a number: it is not used (Gazebo falls back to "
                "its default too)",
                hint=f"write a plain number, e.g. <{el.tag}>0.3</{el.tag}>",
            )
        for el in reader.leftovers():
            if el.tag in reader.single:
                self.note(
                    el,
                    f"a second <{el.tag}> in {context} is ignored: the plugin reads only the first",
                    hint="remove the repeated tag, or check which one you meant",
                )
                continue
            reason = reasons if isinstance(reasons, str) else (reasons or {}).get(el.tag)
            reason = reason or IGNORED_REASONS.get(el.tag)
            self.note(
                el,
                f"<{el.tag}> in {context} is ignored" + (f" ({reason})" if reason else ""),
                kind=TAG_IGNORED,
                about=f"<{el.tag}>",
            )

    def unique(self, name: str) -> str:
        base = re.sub(r"[^A-Za-z0-9_]+", "_", name).strip("_") or "plugin"
        out, i = base, 2
        while out in self._names:
            out, i = f"{base}_{i}", i + 1
        self._names.add(out)
        return out

    def add(self, el: Any, type_name: str, name: str, params: dict[str, Any], implicit: bool = False) -> None:
        file, line = self.where(el)
        clean = {k: v for k, v in params.items() if v is not None}
        self.info.plugins.append(DescribedPlugin(type_name, self.unique(name), clean, file, line, implicit))

    def frame(self, frame: str | None) -> str | None:
        if not frame:
            return None
        return frame_id(self.namespace, frame.strip("/"))

    def drop(self, where: Where, message: str, hint: str | None = None) -> None:
        """Leave a block, a plugin or part of one out, as Gazebo does, with a warning at its line."""
        self.notices.add(message, *where, hint)
        self.info.dropped.append((message, where))

    def ros_block(self, r: TagReader) -> dict[str, Any]:
        """ROS 2 `<ros><namespace>..</namespace><remapping>a:=b</remapping></ros>` and classic
        `<robotNamespace>`: the namespace is replaced by the robot's (the scenario decides where a robot's
        topics live), remappings are kept."""
        out: dict[str, Any] = {"remap": {}}
        ros = r.child("ros")
        if ros is not None:
            rr = TagReader(ros)
            for rm in rr.children("remapping", "argument"):
                text = (rm.text or "").strip()
                if ":=" in text:
                    src, dst = text.split(":=", 1)
                    src = re.sub(r"^(--ros-args\s+)?(-r\s+)?", "", src).strip()
                    out["remap"][ros_topic(src) or src] = ros_topic(dst)
            ns = ros_topic(rr.text("namespace"))
            if ns and ns != self.namespace:
                self.note(
                    ros, f"ROS namespace {ns!r} is replaced by the robot's namespace {self.namespace!r}"
                )
            self.ignored(rr, "<ros>", _ROS_REASONS)
        rn = r.text("robotNamespace")
        if rn and ros_topic(rn) and ros_topic(rn) != self.namespace:
            self.note(
                r.el.find("robotNamespace"),
                f"robotNamespace {rn!r} is replaced by the robot's namespace {self.namespace!r}",
            )
        return out
