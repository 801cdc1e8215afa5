"""URDF `<gazebo>` extension tags -> our plugins and MuJoCo properties (Gazebo classic and Harmonic).

- `<gazebo reference="link">`: materials (`Gazebo/Red`, or `<material><diffuse>`), `mu1`/`mu2` (friction),
  `kp`/`kd` (contact stiffness and damping), `turnGravityOff`/`gravity`, and `<sensor>`s; these keys as text
  or, as Gazebo's URDF parser also takes them, as a `value` attribute (`<mu1 value="0.5"/>`);
- `<gazebo>` (no reference): model plugins (`<plugin filename=...>`) and `<static>`;
- sensors: ray/gpu_ray/lidar/gpu_lidar -> `lidar`; camera -> `camera`; depth/depth_camera/rgbd_camera ->
  `depth_camera`; imu -> `imu` (SDF noise with its bias); with the topic names their ROS plugin gives
  (classic `topicName`, `cameraName`+`imageTopicName`..., ROS 2 `<camera_name>` or the sensor's name and
  `<ros><remapping>`) or Harmonic `<topic>`, placed under the robot's namespace, and the rate of the sensor
  as the plugin throttles it (classic `<updateRate>`).

What is not understood is listed as a notice (tag, file, line), never dropped silently and never fatal.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from runner.compile import thirdparty
from runner.compile.locate import Locator
from runner.compile.materials import gazebo_material
from runner.errors import Notices, SourceError
from runner.frames import frame_id

_NOT_FINITE = {"inf", "-inf", "+inf", "infinity", "-infinity", "nan"}

# Tags whose meaning is GUI-only or debugging, ignored on purpose; listed with this reason.
_IGNORED_REASONS = {
    "visualize": "GUI only",
    "always_on": "sensors are always on",
    "alwaysOn": "sensors are always on",
    "rosDebugLevel": "ROS debug level",
    "legacyMode": "wheel order is taken from the joint names",
    "hackBaseline": "stereo baseline (mono camera)",
    "enable_metrics": "diagnostics",
    "gaussianNoise": "use the sensor's <noise>",
    "minDepth": "ODE contact parameter; MuJoCo contacts are soft (solref/solimp)",
    "maxVel": "ODE contact parameter; MuJoCo contacts are soft (solref/solimp)",
    "serviceName": "no ROS services",
    "maxContacts": "MuJoCo finds contacts itself",
    "provideFeedback": "no joint wrench feedback",
    "implicitSpringDamper": "MuJoCo integrates joint damping implicitly",
    "disableFixedJointLumping": "fixed joints are never lumped",
    "preserveFixedJoint": "fixed joints are never lumped",
    "static": "only a whole model can be static, in Gazebo too",
}


@dataclass
class DescribedPlugin:
    """A plugin the description declares, before the scenario's `plugins:` are merged in."""

    type: str
    name: str
    params: dict[str, Any]
    file: Path | None = None
    line: int | None = None
    implicit: bool = False  # a sensor with neither a ROS plugin nor a <topic>: its topic is our default


Where = tuple[Path | None, int | None]  # (file, line) of a tag in the user's files


@dataclass
class LinkProps:
    rgba: tuple[float, float, float, float] | None = None
    friction: float | None = None
    kp: float | None = None
    kd: float | None = None
    gravity_off: bool = False
    mu1: float | None = None  # friction along fdir1 ...
    mu2: float | None = None  # ... and across it: a drive's wheels keep the two apart (runner.compile.wheels)
    fdir1: tuple[float, float, float] | None = None  # in the collision's frame
    self_collide: bool | None = None  # <selfCollide> (or <self_collide>) of the link; None: the model's
    self_collide_at: Where = (None, None)


@dataclass
class GazeboInfo:
    plugins: list[DescribedPlugin] = field(default_factory=list)
    links: dict[str, LinkProps] = field(default_factory=dict)
    static: bool = False
    self_collide: bool = False  # model-level <self_collide>: Gazebo's default is off
    self_collide_at: Where = (None, None)
    dropped: list[tuple[str, Where]] = field(default_factory=list)  # the warnings of what was left out


class _Reader:
    """Reads children of one element by any of several spellings and remembers which were used.

    `attr_values`: a child's `value` attribute stands for its text, as in the URDF extension keys of a
    `<gazebo>` block (`<mu1 value="0.5"/>` is `<mu1>0.5</mu1>` to Gazebo's URDF parser, the attribute
    winning when both are given). Plugin and sensor parameters are SDF and have no such form."""

    def __init__(self, el: Any, attr_values: bool = False):
        self.el = el
        self.attr_values = attr_values
        self.used: set[str] = set()  # tags read whole (every element of that name)
        self.single: set[str] = set()  # tags read as one value: a repeated one is reported, not dropped
        # elements read one by one, kept alive: lxml hands out the same proxy only while one is referenced
        self._taken: list[Any] = []
        self.not_numbers: list[tuple[Any, str | None]] = []  # (element, text) asked as a number, not one

    def child(self, *names: str) -> Any | None:
        for n in names:
            found = self.el.find(n)
            if found is not None:
                self.single.add(n)
                if not any(found is t for t in self._taken):
                    self._taken.append(found)
                return found
        return None

    def children(self, *names: str) -> list[Any]:
        out = []
        for n in names:
            found = self.el.findall(n)
            if found:
                self.used.add(n)
                out += found
        return out

    def text(self, *names: str) -> str | None:
        el = self.child(*names)
        if el is None:
            return None
        if self.attr_values and el.get("value") is not None:
            return str(el.get("value")).strip()
        return el.text.strip() if el.text is not None else None

    def float(self, *names: str) -> float | None:
        t = self.text(*names)
        try:
            return float(t) if t is not None else None
        except ValueError:
            # Gazebo logs that it cannot read it and uses its default: so do we, said at the tag
            self.not_numbers.append((self.child(*names), t))
            return None

    def bool(self, *names: str) -> bool | None:
        t = self.text(*names)
        if t is None:
            return None
        return t.lower() in ("1", "true", "yes", "on")

    def mark(self, *names: str) -> None:
        self.used.update(names)

    def leftovers(self) -> list[Any]:
        """Elements nothing read: unknown tags, and the second and later copies of a one-value tag."""
        return [
            c
            for c in self.el
            if isinstance(c.tag, str) and c.tag not in self.used and not any(c is t for t in self._taken)
        ]


def _floats(text: str | None, n: int) -> list[float] | None:
    if not text:
        return None
    try:
        vals = [float(v) for v in text.split()]
    except ValueError:
        return None
    return vals if len(vals) == n else None


def _topic(name: str | None) -> str | None:
    """A ROS topic from a plugin parameter, relative to the robot's namespace (leading '/' dropped:
    the scenario places every robot's topics under its namespace)."""
    if name is None:
        return None
    name = name.strip().strip("/")
    name = re.sub(r"^~/?", "", name)
    return name or None


def _join(*parts: str | None) -> str:
    return "/".join(p.strip("/") for p in parts if p and p.strip("/"))


class GazeboReader:
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
        self.notices = notices
        self.info = GazeboInfo()
        self._names: set[str] = set()

    # --------------------------------------------------------------------------------------- helpers
    def note(self, el: Any, message: str, hint: str | None = None) -> None:
        file, line = self.where(el)
        self.notices.add(message, file, line, hint)

    def ignored(self, reader: _Reader, context: str) -> None:
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
            reason = _IGNORED_REASONS.get(el.tag)
            self.note(el, f"<{el.tag}> in {context} is ignored" + (f" ({reason})" if reason else ""))

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

    # ------------------------------------------------------------------------------------------ read
    def read(self) -> GazeboInfo:
        self.link_names = {el.get("name") for el in self.root.findall("link")}
        # a description for Gazebo Harmonic (gz-sim systems): its sensors publish as gz-sensors does
        self.harmonic = any(
            _plugin_base(el.get("filename") or "").startswith("gz-sim")
            for gz in self.root.findall("gazebo")
            for el in gz.iter("plugin")
        )
        # the Gazebo link each URDF link becomes: links joined by fixed joints are lumped into the upper one
        upper = {
            j.find("child").get("link"): j.find("parent").get("link")
            for j in self.root.findall("joint")
            if j.get("type") == "fixed" and j.find("child") is not None and j.find("parent") is not None
        }
        self.lumped_into: dict[str, str] = {}
        for link in self.link_names:
            top, seen = link, {link}
            while top in upper and upper[top] not in seen:
                top = upper[top]
                seen.add(top)
            self.lumped_into[link] = top
        self.joint_names = {el.get("name") for el in self.root.findall("joint") if el.get("type") != "fixed"}
        self.fixed_joints = {el.get("name") for el in self.root.findall("joint") if el.get("type") == "fixed"}
        for gz in self.root.findall("gazebo"):
            ref = gz.get("reference")
            try:
                if ref:
                    if ref not in self.link_names | self.joint_names | self.fixed_joints:
                        self.drop(
                            self.where(gz),
                            f'<gazebo reference="{ref}"> names a link or joint the robot does not have: '
                            "it is left out",
                            "Gazebo drops such a block too; xacro arguments may have left the link out",
                        )
                        continue
                    self._reference(gz, ref)
                else:
                    self._model(gz)
            except (ValueError, OverflowError) as e:  # float("many"), int(float("inf")) in a tag's text
                raise self._not_a_number(gz, e) from None
        for path in self.controller_files:  # the scenario's `controllers:` (what a launch file would load)
            self.controllers(path, (path, None))
        self._drop_shadowed()
        self._drop_missing_targets()
        return self.info

    def controllers(self, path: Path, where: Where) -> int:
        """Run the diff drive and joint state controllers of a ros_control / ros2_control controllers file
        (as `<parameters>` names it, or the scenario's `controllers:`); returns how many. Other controllers
        are said, with their type."""
        import yaml

        try:
            text = path.read_text()
        except OSError as e:
            raise SourceError(
                f"controllers file {str(path)!r} cannot be read: {e.strerror or e}", path
            ) from None
        # `<rosparam subst_value="true">` substitutes launch arguments in such files: with none given here,
        # each `$(arg name)` is empty (the usual default of a `prefix`), and said
        args = sorted(set(_LAUNCH_ARG.findall(text)))
        if args:
            text = _LAUNCH_ARG.sub("", text)
            self.notices.add(
                f"controllers file: launch argument(s) {', '.join(args)} taken as empty",
                path,
                None,
                hint="write the values into a copy of the file if the robot is launched with others",
            )
        try:
            doc = yaml.safe_load(text)
        except yaml.YAMLError as e:
            mark = getattr(e, "problem_mark", None)
            raise SourceError(
                f"controllers file {str(path)!r} is not valid YAML: {getattr(e, 'problem', e)}",
                path,
                mark.line + 1 if mark else None,
            ) from None
        entries, update_rate = _controller_entries(doc)
        ros1 = not _ros_parameters(doc)
        count = 0
        for name, kind, params in entries:
            if kind.endswith("DiffDriveController"):
                type_name, drive = _diff_drive_controller(self, name, params, ros1, where)
                self.info.plugins.append(
                    DescribedPlugin(
                        type_name,
                        self.unique(name),
                        {k: v for k, v in drive.items() if v is not None},
                        *where,
                    )
                )
            elif kind.endswith(("JointStateBroadcaster", "JointStateController")):
                rate = params.get("publish_rate") if ros1 else update_rate
                js = {"topic": "joint_states", "joints": params.get("joints") or None, "rate": rate}
                self.info.plugins.append(
                    DescribedPlugin(
                        "joint_states", self.unique(name), {k: v for k, v in js.items() if v}, *where
                    )
                )
            else:
                self.notices.add(f"ros_control controller {name!r} ({kind}) is not run", *where)
                continue
            count += 1
        return count

    def drop(self, where: Where, message: str, hint: str | None = None) -> None:
        """Leave a block, a plugin or part of one out, as Gazebo does, with a warning at its line."""
        self.notices.add(message, *where, hint)
        self.info.dropped.append((message, where))

    def _drop_missing_targets(self) -> None:
        """A plugin naming a link or joint the expanded URDF lacks (an `enable_imu:=false` xacro argument
        took it out) does not load in Gazebo, which goes on without it: so do we. A joint list (a joint
        state publisher's) loses only the joints that are missing."""
        keep: list[DescribedPlugin] = []

        def named(joint: str) -> str:
            fixed = " (fixed: Gazebo lumps it into its parent link)" if joint in self.fixed_joints else ""
            return f"joint {joint!r}{fixed}"

        for p in self.info.plugins:
            missing: list[str] = []
            for key, value in p.params.items():
                if key == "link" and isinstance(value, str) and value not in self.link_names:
                    missing.append(f"link {value!r}")
                elif key in _JOINT_PARAMS and isinstance(value, str) and value not in self.joint_names:
                    missing.append(named(value))
                elif key in _JOINT_LIST_PARAMS and isinstance(value, list):
                    gone = [j for j in value if j not in self.joint_names]
                    if gone and key == "joints" and len(gone) < len(value):
                        p.params[key] = [j for j in value if j in self.joint_names]
                        gone_names = ", ".join(named(j) for j in gone)
                        self.drop(
                            (p.file, p.line),
                            f"{p.type} plugin {p.name!r} names joint(s) the robot does not have: "
                            f"{gone_names}: they are left out",
                        )
                    else:
                        missing += [named(j) for j in gone]
            if missing:
                self.drop(
                    (p.file, p.line),
                    f"{p.type} plugin {p.name!r} names {', '.join(missing)}, which the robot does not have: "
                    "it is left out",
                    "Gazebo does not load such a plugin either; xacro arguments may have left the link out",
                )
                continue
            keep.append(p)
        self.info.plugins = keep

    def _not_a_number(self, gz: Any, e: Exception) -> SourceError:
        """A tag whose text should be a number and is not: the error at that tag's line."""
        m = re.search(r": '(.*)'$", str(e))
        text = m.group(1) if m else None
        bad = next(
            (
                el
                for el in gz.iter()
                if isinstance(el.tag, str)
                and el.text is not None
                and (el.text.strip() == text or (text is None and el.text.strip().lower() in _NOT_FINITE))
            ),
            None,
        )
        el = bad if bad is not None else gz
        shown = repr(el.text.strip()) if bad is not None and el.text else "a value"
        return SourceError(
            f"<{el.tag}> {shown} is not a number that fits here ({e})",
            *self.where(el),
            hint="Gazebo tags take plain numbers (an integer for counts such as <samples>)",
        )

    def _drop_shadowed(self) -> None:
        """A classic sensor without a ROS plugin (e.g. TurtleBot3's imu sensor) publishes nothing in
        Gazebo; a model plugin (libgazebo_ros_imu) does it. Keep one publisher per topic."""
        topics: dict[tuple[str, str], DescribedPlugin] = {}
        keep: list[DescribedPlugin] = []
        for p in sorted(self.info.plugins, key=lambda p: p.implicit):
            key = (p.type, str(p.params.get("topic") or p.params.get("image_topic") or p.name))
            other = topics.get(key)
            if other is not None and p.implicit:
                self.notices.add(
                    f"{p.type} sensor {p.name!r} has no ROS plugin and publishes on the same topic as "
                    f"{other.name!r}: it is left out",
                    p.file,
                    p.line,
                )
                continue
            topics[key] = p
            keep.append(p)
        self.info.plugins = [p for p in self.info.plugins if p in keep]

    def _reference(self, gz: Any, link: str) -> None:
        r = _Reader(gz, attr_values=True)
        props = self.info.links.setdefault(link, LinkProps())
        mat = r.child("material")
        if mat is not None:
            props.rgba = self._material(mat) or props.rgba
        visual = r.child("visual")
        if visual is not None:
            vm = visual.find("material")
            if vm is not None:
                props.rgba = self._material(vm) or props.rgba
        mu1, mu2 = r.float("mu1"), r.float("mu2")
        mu = [v for v in (mu1, mu2, r.float("mu")) if v is not None]
        if mu:
            props.friction = min(mu)
        props.mu1, props.mu2 = mu1, mu2
        fdir = _floats(r.text("fdir1"), 3)
        if fdir is not None and any(fdir):
            props.fdir1 = (fdir[0], fdir[1], fdir[2])
        props.kp = r.float("kp")
        r.mark("kd")
        if r.float("kd") is not None:
            self.note(
                gz.find("kd"),
                f'<kd> in <gazebo reference="{link}"> is ignored (contacts are critically '
                "damped; <kp> sets their stiffness)",
            )
        if r.bool("turnGravityOff"):
            props.gravity_off = True
        self_collide = r.bool("selfCollide", "self_collide")
        if self_collide is not None:
            props.self_collide = self_collide
            props.self_collide_at = self.where(r.child("selfCollide", "self_collide"))
        gravity = r.bool("gravity")
        if gravity is False:
            props.gravity_off = True
        for sensor in r.children("sensor"):
            self._sensor(sensor, link)
        for plugin in r.children("plugin"):  # a model plugin written inside a reference block
            self._plugin(plugin, link)
        self.ignored(r, f'<gazebo reference="{link}">')

    def _material(self, el: Any) -> tuple[float, float, float, float] | None:
        name = el.get("value") or el.text  # <material value="Gazebo/Red"/> is <material>Gazebo/Red</material>
        if name and name.strip():
            rgba = gazebo_material(name)
            if rgba is None:
                self.note(el, f"unknown Gazebo material {name.strip()!r}; the URDF colour is kept")
            return rgba
        script = el.find("script/name")
        if script is not None and script.text:
            rgba = gazebo_material(script.text)
            if rgba is None:
                self.note(el, f"unknown Gazebo material {script.text.strip()!r}; the URDF colour is kept")
            return rgba
        for tag in ("diffuse", "ambient"):
            vals = _floats(el.findtext(tag), 4) or (_floats(el.findtext(tag), 3) or [])
            if len(vals) == 3:
                vals = [*vals, 1.0]
            if len(vals) == 4:
                return (vals[0], vals[1], vals[2], vals[3])
        return None

    def _model(self, gz: Any) -> None:
        r = _Reader(gz, attr_values=True)
        if r.bool("static"):
            self.info.static = True
        self_collide = r.bool("self_collide", "selfCollide")
        if self_collide is not None:
            self.info.self_collide = self_collide
            self.info.self_collide_at = self.where(r.child("self_collide", "selfCollide"))
        for plugin in r.children("plugin"):
            self._plugin(plugin, None)
        for sensor in r.children("sensor"):
            self._sensor(sensor, None)
        self.ignored(r, "<gazebo>")

    # --------------------------------------------------------------------------------------- sensors
    def _sensor(self, el: Any, link: str | None) -> None:
        kind = (el.get("type") or "").strip()
        name = el.get("name") or kind or "sensor"
        r = _Reader(el)
        context = f"<sensor name={name!r} type={kind!r}>"
        rate = r.float("update_rate", "updateRate")
        pose = _floats(r.text("pose"), 6)
        base_topic = _topic(r.text("topic"))
        frame = self.frame(r.text("gz_frame_id", "ignition_frame_id", "frame_id", "frameName"))
        plugins = r.children("plugin")
        common: dict[str, Any] = {"link": link}
        if rate:
            common["rate"] = rate
        if pose:
            common["pose"] = {"xyz": pose[:3], "rpy": pose[3:]}
        if kind in ("ray", "gpu_ray", "lidar", "gpu_lidar"):
            params = {**common, **self._lidar(r, el, context)}
            ros = self._sensor_plugins(plugins, context, ("out", "scan"), name, kind)
            params["topic"] = ros.get("topic") or base_topic or "scan"
            params["frame_id"] = ros.get("frame") or frame
            if ros.get("noise"):  # gazebo_ros_block_laser adds its <gaussianNoise> to the sensor's noise
                params["noise_stddev"] = math.hypot(params.get("noise_stddev", 0.0), ros["noise"])
            params.update(ros.get("params") or {})  # what a third-party plugin changes (velodyne)
            if not ros and (self.harmonic or kind in ("lidar", "gpu_lidar")):
                if not base_topic and self.harmonic:
                    params["topic"] = self._gz_sensor_topic(link, name, "scan")
                # gz-sensors: a lidar publishes its scan on <topic> and its point cloud on <topic>/points
                params.setdefault("publish_points", True)
                params["points_topic"] = _join(params["topic"], "points")
            self.add(el, "lidar", name, params, implicit=not (ros or base_topic or self.harmonic))
        elif kind == "camera":
            params = {**common, **self._camera(r, el, context)}
            ros = self._sensor_plugins(plugins, context, ("image_raw", "image"), name, kind)
            # gz-sensors: <topic> carries the image, CameraInfo goes to <camera_info_topic> or a sibling
            image = ros.get("topic") or base_topic or "camera/image_raw"
            if self.harmonic and not (ros or base_topic):
                image = self._gz_sensor_topic(link, name, "image")
            params["image_topic"] = image
            info_topic = _topic(el.findtext("camera/camera_info_topic"))
            params["info_topic"] = (
                ros.get("info") or (info_topic if not ros else None) or _sibling(image, "camera_info")
            )
            params["frame_id"] = ros.get("frame") or frame
            self._plugin_rate(params, rate, ros)
            self.add(el, "camera", name, params, implicit=not (ros or base_topic or self.harmonic))
        elif kind in ("depth", "depth_camera", "rgbd_camera", "rgbd"):
            params = {**common, **self._camera(r, el, context)}
            ros = self._sensor_plugins(plugins, context, ("image_raw", "image"), name, kind)
            info_topic = _topic(el.findtext("camera/camera_info_topic"))  # gz-sensors; no ROS plugin reads it
            if not ros and kind in ("depth", "depth_camera"):
                # Harmonic depth camera: depth image on <topic>, points on <topic>/points, CameraInfo beside
                topic = base_topic or "depth_camera"
                params.update(
                    depth_topic=topic,
                    points_topic=_join(topic, "points"),
                    info_topic=_sibling(topic, "camera_info"),
                    depth_info_topic=info_topic or _sibling(topic, "camera_info"),
                    publish_color=False,
                )
            elif not ros:
                # Harmonic rgbd: <topic>/image, <topic>/depth_image, <topic>/points, <topic>/camera_info
                topic = base_topic or "rgbd_camera"
                params.update(
                    image_topic=_join(topic, "image"),
                    depth_topic=_join(topic, "depth_image"),
                    points_topic=_join(topic, "points"),
                    info_topic=info_topic or _join(topic, "camera_info"),
                )
            else:
                params.update(
                    image_topic=ros["topic"],
                    info_topic=ros["info"],
                    depth_topic=ros["depth"],
                    depth_info_topic=ros["depth_info"],
                    points_topic=ros["points"],
                )
            params["frame_id"] = ros.get("frame") or frame
            self._plugin_rate(params, rate, ros)
            self.add(el, "depth_camera", name, params)
        elif kind == "imu":
            params = {**common, **self._imu(r, el, context)}
            ros = self._sensor_plugins(plugins, context, ("out", "imu"), name, kind)
            params["topic"] = ros.get("topic") or base_topic or "imu"
            if self.harmonic and not (ros or base_topic):
                params["topic"] = self._gz_sensor_topic(link, name, "imu")
            params["frame_id"] = ros.get("frame") or frame
            noise = ros.get("noise")
            if noise:
                # ROS 1 gazebo_ros_imu_sensor adds N(0, gaussianNoise) to every rate, acceleration and
                # quaternion component, on top of the sensor's own noise
                for key in ("angular_velocity_stddev", "linear_acceleration_stddev"):
                    params[key] = math.hypot(params.get(key, 0.0), noise)
                params["orientation_stddev"] = 2.0 * noise  # a quaternion component of s is an angle of 2s
            self._plugin_rate(params, rate, ros)
            self.add(el, "imu", name, params, implicit=not (ros or base_topic or self.harmonic))
        elif kind == "contact":
            if link is None:
                self.note(el, f"{context} outside a <gazebo reference=...> block has no link; ignored")
                return
            r.child("contact")  # <collision> names: we report every contact of the link
            ros = self._sensor_plugins(plugins, context, ("bumper_states", "bumper"), name, kind)
            params = {**common, "topic": ros.get("topic") or base_topic or "bumper"}
            params["frame_id"] = ros.get("frame") or frame
            self.add(el, "contact", name, params)
        elif kind in thirdparty.SENSOR_KINDS:  # gps: runner/compile/thirdparty.py
            thirdparty.sensor(self, r, el, common, plugins, name, kind, context, base_topic, frame)
        else:
            self.note(
                el,
                f"sensor type {kind!r} is not supported yet; {context} is ignored",
                hint="supported: ray, gpu_ray, lidar, gpu_lidar, camera, depth, depth_camera, rgbd_camera, "
                "imu, contact",
            )
            return
        self.ignored(r, context)

    @staticmethod
    def _plugin_rate(params: dict[str, Any], sensor_rate: float | None, ros: dict[str, Any]) -> None:
        """A ROS 1 plugin's own rate (camera `<updateRate>`, imu `<updateRateHZ>`) throttles the sensor: the
        plugin publishes a frame when at least 1/rate has passed since the last one it published. With a
        sensor `<update_rate>` as well, it publishes every ceil(sensor / plugin)-th frame (30 and 10 Hz: 10;
        10 and 30 Hz: 10; 30 and 20 Hz: 15); without one (Gazebo: as fast as possible), at its own rate."""
        plugin_rate = ros.get("rate")
        if not plugin_rate or plugin_rate <= 0:
            return
        if sensor_rate and sensor_rate > 0:
            params["rate"] = sensor_rate / max(1, math.ceil(sensor_rate / plugin_rate - 1e-9))
        else:
            params["rate"] = plugin_rate

    def _noise(self, parent: Any | None, what: str = "this sensor") -> float | None:
        """The stddev of a `<noise>` under `parent`; a mean or bias is not modelled here (reported)."""
        spec = self._noise_spec(parent)
        if spec is None:
            return None
        if spec.mean:
            self.note(
                spec.el, f"a non-zero noise <mean> is ignored for {what} (use a bias in the plugin params)"
            )
        if spec.bias_mean or spec.bias_stddev:
            self.note(spec.el, f"a noise bias (<bias_mean>, <bias_stddev>) is not modelled for {what}")
        return spec.stddev or None

    def _noise_spec(self, parent: Any | None) -> _NoiseSpec | None:
        """SDF `<noise>` (gaussian, with a bias drawn once per run from N(bias_mean, bias_stddev) with a
        random sign); what it has that we do not model (quantization, dynamic bias) is reported."""
        if parent is None:
            return None
        noise = parent.find("noise")
        if noise is None:
            return None
        kind = (noise.get("type") or noise.findtext("type") or "gaussian").strip()
        if kind.lower() == "none":
            return None
        if kind.lower() not in ("gaussian", "gaussian_quantized"):
            self.note(noise, f"noise type {kind!r} is treated as gaussian")

        for child in noise:
            if not isinstance(child.tag, str) or child.tag in _NOISE_TAGS:
                continue
            if child.tag == "precision" and (child.text or "").strip() and float(child.text) != 0.0:
                self.note(child, "noise <precision> is ignored (readings are not quantized)")
            elif child.tag != "precision" and not _zero(child.text):
                self.note(child, f"noise <{child.tag}> is ignored")
        return _NoiseSpec.of(noise)

    def _gz_sensor_topic(self, link: str | None, sensor: str, leaf: str) -> str:
        """gz-sensors' default topic of a sensor without `<topic>`: scoped by world, model, (lumped) link and
        sensor name (the world is "default", as in our other gz-sim defaults)."""
        gz_link = self.lumped_into.get(link or "", link or "base_link")
        return f"world/default/model/{self.model}/link/{gz_link}/sensor/{sensor}/{leaf}"

    def _lidar(self, r: _Reader, el: Any, context: str) -> dict[str, Any]:
        ray = r.child("ray", "lidar")
        out: dict[str, Any] = {}
        if ray is None:
            return out
        h = ray.find("scan/horizontal")
        if h is not None:
            samples = h.findtext("samples")
            resolution = h.findtext("resolution")
            n = int(float(samples)) if samples else 640
            if resolution and float(resolution) not in (0.0, 1.0):
                n = max(1, round(n * float(resolution)))  # Gazebo: beams = samples * resolution
            out["samples"] = n
            if h.findtext("min_angle"):
                out["min_angle"] = float(h.findtext("min_angle"))
            if h.findtext("max_angle"):
                out["max_angle"] = float(h.findtext("max_angle"))
        v = ray.find("scan/vertical")
        if v is not None and v.findtext("samples") and int(float(v.findtext("samples"))) > 1:
            out["vertical_samples"] = int(float(v.findtext("samples")))
            if v.findtext("min_angle"):
                out["vertical_min_angle"] = float(v.findtext("min_angle"))
            if v.findtext("max_angle"):
                out["vertical_max_angle"] = float(v.findtext("max_angle"))
        rng = ray.find("range")
        if rng is not None:
            _put(out, "range_min", rng, "min")
            _put(out, "range_max", rng, "max")
            _put(out, "resolution", rng, "resolution")
        noise = self._noise(ray, "a lidar")
        if noise:
            out["noise_stddev"] = noise
        known = {"scan", "range", "noise", "visibility_mask"}
        for child in ray:
            if isinstance(child.tag, str) and child.tag not in known:
                self.note(child, f"<{child.tag}> in {context} <{ray.tag}> is ignored")
        return out

    def _camera(self, r: _Reader, el: Any, context: str) -> dict[str, Any]:
        cam = r.child("camera")
        out: dict[str, Any] = {}
        if cam is None:
            return out
        fov = cam.findtext("horizontal_fov")
        if fov:
            out["fov"] = float(fov)
        w, h = cam.findtext("image/width"), cam.findtext("image/height")
        if w:
            out["width"] = int(float(w))
        if h:
            out["height"] = int(float(h))
        fmt = (cam.findtext("image/format") or "").strip()
        if fmt:
            mapped = _FORMATS.get(fmt.upper())
            if mapped:
                out["format"] = mapped
            else:
                self.note(cam, f"image format {fmt!r} is published as rgb8")
        near, far = cam.findtext("clip/near"), cam.findtext("clip/far")
        if near:
            out["near"] = float(near)
        if far:
            out["far"] = float(far)
        noise = self._noise(cam, "a camera")
        if noise:
            out["noise_stddev"] = noise
        known = {"horizontal_fov", "image", "clip", "noise", "camera_info_topic", "depth_camera"}
        for child in cam:
            if isinstance(child.tag, str) and child.tag not in known:
                self.note(child, f"<{child.tag}> in {context} <camera> is ignored")
        return out

    def _imu(self, r: _Reader, el: Any, context: str) -> dict[str, Any]:
        """SDF imu noise, per axis: white noise (its stddev; the largest of the axes, as our imu takes one),
        a constant <mean>, and a bias drawn once per run from N(bias_mean, bias_stddev) with a random sign."""
        imu = r.child("imu")
        out: dict[str, Any] = {}
        if imu is None:
            return out
        for key in ("angular_velocity", "linear_acceleration"):
            specs = [self._noise_spec(imu.find(f"{key}/{axis}")) for axis in ("x", "y", "z")]
            self._imu_noise(out, key, specs)
        # classic (SDF 1.4) style: <imu><noise><type/><rate>..</rate><accel>..</accel></noise>, for all axes
        n = imu.find("noise")
        if n is not None:
            for block, key in (("rate", "angular_velocity"), ("accel", "linear_acceleration")):
                spec = self._noise_spec_classic(n, block)
                if spec is not None:
                    self._imu_noise(out, key, [spec] * 3)
        for child in imu:
            if isinstance(child.tag, str) and child.tag not in _IMU_TAGS:
                self.note(child, f"<{child.tag}> in {context} <imu> is ignored")
        return out

    def _noise_spec_classic(self, noise: Any, block: str) -> _NoiseSpec | None:
        el = noise.find(block)
        if el is None:
            return None
        kind = (noise.findtext("type") or "gaussian").strip().lower()
        if kind == "none":
            return None

        return _NoiseSpec.of(el)

    @staticmethod
    def _imu_noise(out: dict[str, Any], key: str, specs: list[_NoiseSpec | None]) -> None:
        if not any(specs):
            return
        s = [spec or _NoiseSpec() for spec in specs]
        sd = max(x.stddev for x in s)
        if sd:
            out[f"{key}_stddev"] = sd
        if any(x.mean for x in s):  # Gazebo adds the white noise's mean to every reading: a constant bias
            out[f"{key}_bias"] = [x.mean for x in s]
        if any(x.bias_mean for x in s):
            out[f"{key}_bias_mean"] = [x.bias_mean for x in s]
        bias_sd = max(x.bias_stddev for x in s)
        if bias_sd:
            out[f"{key}_bias_stddev"] = bias_sd

    def _sensor_plugins(
        self, plugins: list[Any], context: str, out_names: tuple[str, ...], sensor: str, kind: str
    ) -> dict[str, Any]:
        """The ROS plugin inside a sensor: where it publishes (classic and ROS 2 spellings), its own rate."""
        found: dict[str, Any] = {}
        for p in plugins:
            filename = p.get("filename", "")
            base = _plugin_base(filename)
            r = _Reader(p)
            if base not in _SENSOR_PLUGINS:
                self.note(
                    p,
                    f"plugin {filename!r} in {context} is not supported and is ignored",
                    hint="sensor plugins we read: " + ", ".join(sorted(_SENSOR_PLUGINS)),
                )
                continue
            ros = self._ros_block(r)
            remap = ros["remap"]
            rates: tuple[str, ...] = ()
            if base in _CAMERA_PLUGINS:
                found.update(self._camera_plugin(r, filename, base, remap, sensor, kind, context))
                rates = () if found["ros2"] else ("updateRate",)
            elif base in thirdparty.SENSOR_PLUGINS:
                extra, rates = thirdparty.sensor_plugin(self, r, base, remap, sensor, kind, context)
                found.update(extra)
            else:
                frame = r.text("frameName", "frame_name")
                if frame:
                    found["frame"] = self.frame(frame)
                topic = _topic(r.text("topicName", "topic_name", "bumperTopicName"))
                for out in out_names:
                    if out in remap:
                        topic = topic or remap[out]
                if topic:
                    found["topic"] = topic
                ros2 = any(
                    p.find(t) is not None for t in ("ros", "frame_name", "initial_orientation_as_reference")
                )
                if base == "gazebo_ros_imu_sensor" and not ros2:
                    # ROS 1: <updateRateHZ> throttles, <gaussianNoise> adds to the sensor's noise
                    rates = ("updateRateHZ",)
                    found["noise"] = r.float("gaussianNoise")
                    offset = r.text("rpyOffset")
                    if offset is not None and (_floats(offset, 3) is None or any(_floats(offset, 3) or [])):
                        self.note(p.find("rpyOffset"), f"<rpyOffset> in {context} is ignored")
                    r.mark("xyzOffset")  # read and unused by the plugin itself
                elif base == "gazebo_ros_block_laser":
                    found["noise"] = r.float("gaussianNoise")
                if base == "gazebo_ros_imu_sensor" and r.bool("initial_orientation_as_reference"):
                    self.note(
                        p.find("initial_orientation_as_reference"),
                        "<initial_orientation_as_reference> true is ignored: the orientation is reported "
                        "in the world frame (REP 145), as with false",
                    )
                out_type = r.text("output_type")
                if out_type and out_type.split("/")[-1] != "LaserScan":
                    self.note(p.find("output_type"), f"<output_type> {out_type} is published as a LaserScan")
            for tag in rates:
                value = r.float(tag)
                if value and value > 0:
                    found["rate"] = value
            for tag in ("updateRate", "update_rate", "updateRateHZ"):
                el = p.find(tag)
                if el is None or tag in rates:
                    continue
                r.mark(tag)
                if not _zero(el.text):
                    self.note(
                        el,
                        f"<{tag}> is not read by {filename!r}"
                        + (" (ROS 2)" if found.get("ros2") else "")
                        + ": Gazebo ignores it too; the sensor's <update_rate> sets the rate",
                    )
            r.mark(
                "alwaysOn",
                "always_on",
                "robotNamespace",
                "bodyName",
                "output_type",
                "min_intensity",
                "hokuyoMinIntensity",
                "initial_orientation_as_reference",
                "radiation_type",
                "min_range",
                "max_range",
            )
            self.ignored(r, f"<plugin filename={filename!r}>")
        found.pop("ros2", None)
        return {k: v for k, v in found.items() if v is not None}

    def _camera_plugin(
        self,
        r: _Reader,
        filename: str,
        base: str,
        remap: dict[str, str],
        sensor: str,
        kind: str,
        context: str,
    ) -> dict[str, Any]:
        """Topics of the gazebo_ros camera plugins.

        ROS 2 (gazebo_ros_pkgs for ROS 2, `libgazebo_ros_camera.so`): `<camera_name>` (default: the sensor's
        name) + `/image_raw`, `/camera_info`, and for depth sensors `/depth/image_raw`, `/depth/camera_info`,
        `/points`; `<ros><remapping>` rules match those whole names, as ROS 2 remapping does
        (`mycam/image_raw:=mycam/image_demo`). The rate is the sensor's `<update_rate>`.

        ROS 1 (`libgazebo_ros_camera.so`, `libgazebo_ros_depth_camera.so`, `libgazebo_ros_openni_kinect.so`):
        `<cameraName>` (default: none) + `imageTopicName` (image_raw), `cameraInfoTopicName` (camera_info),
        `depthImageTopicName` (depth/image_raw), `depthImageCameraInfoTopicName` (depth/camera_info),
        `pointCloudTopicName` (points); a name with a leading '/' is not under `<cameraName>`.
        `<updateRate>` throttles the sensor (see `_plugin_rate`).

        The same file name is both: a `<ros>` block, `<camera_name>` or `<frame_name>` is ROS 2; otherwise
        ROS 1 naming tags or `<updateRate>` are ROS 1; a plugin with neither is taken as ROS 2."""
        p = r.el
        ros2 = base in ("gazebo_ros_camera", "gazebo_ros_multicamera") and (
            any(p.find(t) is not None for t in _ROS2_CAMERA_DECISIVE)
            or not any(p.find(t) is not None for t in _ROS1_CAMERA_EVIDENCE)
        )
        depth = kind != "camera"
        out: dict[str, Any] = {"ros2": ros2}
        frame = r.text("frame_name" if ros2 else "frameName")
        if frame:
            out["frame"] = self.frame(frame)
        for t in _DISTORTION:  # ROS 1 and early ROS 2 spellings: the images are ideal either way
            el = p.find(t)
            if el is not None:
                r.mark(t)
                if not _zero(el.text):
                    self.note(el, f"<{t}> in {context} is ignored (images are not distorted)")
        if ros2:
            cam = _topic(r.text("camera_name")) if p.find("camera_name") is not None else _topic(sensor)
            names = {
                "topic": _join(cam, "image_raw"),
                "info": _join(cam, "camera_info"),
                "depth": _join(cam, "depth/image_raw"),
                "depth_info": _join(cam, "depth/camera_info"),
                "points": _join(cam, "points"),
            }
            mine = set(names.values()) if depth else {names["topic"], names["info"]}
            for key, topic in names.items():
                out[key] = remap.get(topic) or topic
            for src, dst in remap.items():
                if src not in mine and not src.startswith("__") and src != _join(cam, "image_trigger"):
                    self.note(
                        p.find("ros"),
                        f"remapping {src}:={dst} matches none of this camera's topics ("
                        + ", ".join(sorted(mine))
                        + "): ROS 2 applies it to none either",
                        hint=f"name the whole topic, as {names['topic']}:=...",
                    )
            own, other = _ROS2_CAMERA_PARAMS, _ROS1_CAMERA_PARAMS
        else:
            raw_cam = r.text("cameraName")
            cam = _topic(raw_cam) if raw_cam else None

            def name(tag: str, default: str) -> str:
                text = r.text(tag)
                if text and text.startswith("/"):  # absolute: not under <cameraName>
                    return _topic(text) or default
                return _join(cam, _topic(text) or default)

            out.update(
                topic=name("imageTopicName", "image_raw"),
                info=name("cameraInfoTopicName", "camera_info"),
                depth=name("depthImageTopicName", "depth/image_raw"),
                depth_info=name("depthImageCameraInfoTopicName", "depth/camera_info"),
                points=name("pointCloudTopicName", "points"),
            )
            own, other = _ROS1_CAMERA_PARAMS, _ROS2_CAMERA_PARAMS
        r.mark(*(t for t in own if p.find(t) is not None))
        if ros2 and r.bool("triggered"):
            self.note(p.find("triggered"), "<triggered> is ignored: the camera publishes at its rate")
        for tag in other:
            el = p.find(tag)
            if el is None:
                continue
            r.mark(tag)
            if not _zero(el.text) and tag not in _HARMLESS and (el.text or "").strip().lower() != "true":
                self.note(
                    el,
                    f"<{tag}> is a ROS {'1' if ros2 else '2'} parameter; the ROS {'2' if ros2 else '1'} "
                    f"{filename!r} does not read it (Gazebo ignores it too)",
                )
        for tag in ("pointCloudCutoff", "pointCloudCutoffMax", "min_depth", "max_depth"):
            el = p.find(tag)
            if el is not None and tag in own and depth:
                self.note(
                    el, f"<{tag}> is not applied: depth and points span the clip planes (<near>..<far>)"
                )
        for tag in ("Cx", "Cy", "CxPrime", "focalLength", "cx", "cy", "focal_length"):
            el = p.find(tag)
            if el is not None and tag in own and not _zero(el.text):
                self.note(el, f"<{tag}> is not applied: CameraInfo is the ideal pinhole of <horizontal_fov>")
        for el in r.leftovers():
            if el.tag not in _CAMERA_KNOWN and el.tag not in _IGNORED_REASONS:
                r.mark(el.tag)
                self.note(el, f"<{el.tag}> is not a parameter of {filename!r}: Gazebo ignores it too")
        return out

    def _ros_block(self, r: _Reader) -> dict[str, Any]:
        """ROS 2 `<ros><namespace>..</namespace><remapping>a:=b</remapping></ros>` and classic
        `<robotNamespace>`: the namespace is replaced by the robot's (the scenario decides where a robot's
        topics live), remappings are kept."""
        out: dict[str, Any] = {"remap": {}}
        ros = r.child("ros")
        if ros is not None:
            for rm in ros.findall("remapping") + ros.findall("argument"):
                text = (rm.text or "").strip()
                if ":=" in text:
                    src, dst = text.split(":=", 1)
                    src = re.sub(r"^(--ros-args\s+)?(-r\s+)?", "", src).strip()
                    out["remap"][_topic(src) or src] = _topic(dst)
            ns = _topic(ros.findtext("namespace"))
            if ns and ns != self.namespace:
                self.note(
                    ros, f"ROS namespace {ns!r} is replaced by the robot's namespace {self.namespace!r}"
                )
        rn = r.text("robotNamespace")
        if rn and _topic(rn) and _topic(rn) != self.namespace:
            self.note(
                r.el.find("robotNamespace"),
                f"robotNamespace {rn!r} is replaced by the robot's namespace {self.namespace!r}",
            )
        return out

    # ---------------------------------------------------------------------------------- model plugins
    def _plugin(self, p: Any, link: str | None) -> None:
        filename = p.get("filename", "")
        name = p.get("name") or _plugin_base(filename)
        base = _plugin_base(filename)
        r = _Reader(p)
        context = f"<plugin filename={filename!r}>"
        handler = _MODEL_PLUGINS.get(base)
        if handler is None:
            if base in _NOOP_PLUGINS:
                return
            self.note(
                p,
                f"plugin {filename!r} is not supported and is ignored",
                hint="model plugins we map: " + ", ".join(sorted(_MODEL_PLUGINS)) + ". Add a plugin of ours "
                "under the robot's `plugins:` in the scenario instead.",
            )
            return
        ros = self._ros_block(r)
        r.mark("alwaysOn", "always_on", "robotNamespace")
        result = handler(self, r, ros["remap"])
        if result is not None:
            type_name, params = result
            self.add(p, type_name, name, params)
        known = _PLUGIN_PARAMS.get(base)
        if known is not None:
            for el in r.leftovers():
                if el.tag not in known and el.tag not in _IGNORED_REASONS:
                    r.mark(el.tag)
                    self.note(el, f"<{el.tag}> is not a parameter of {filename!r}: Gazebo ignores it too")
        self.ignored(r, context)


_LAUNCH_ARG = re.compile(r"\$\(arg\s+([^)\s]+)\s*\)")

# Plugin parameters that name joints of the robot (one, or a list).
_JOINT_PARAMS = {"left_joint", "right_joint"}
_JOINT_LIST_PARAMS = {"left_joints", "right_joints", "joints"}


def _put(out: dict[str, Any], key: str, el: Any, path: str) -> None:
    """out[key] = the number at `path` under `el`, when there is one."""
    text = el.findtext(path)
    if text and text.strip():
        out[key] = float(text)


def _plugin_base(filename: str) -> str:
    """`libgazebo_ros_diff_drive.so` -> `gazebo_ros_diff_drive`; `gz-sim-diff-drive-system` as is."""
    base = Path(filename).name
    base = re.sub(r"\.so(\.\d+)*$", "", base)
    base = re.sub(r"^lib", "", base)
    return re.sub(r"^(ignition-gazebo|gz-sim)\d*-", "gz-sim-", base)


def _zero(text: str | None) -> bool:
    """An unset, zero or false parameter value."""
    if text is None or not text.strip():
        return True
    try:
        return float(text) == 0.0
    except ValueError:
        return text.strip().lower() == "false"


@dataclass
class _NoiseSpec:
    """SDF `<noise>`: white noise N(mean, stddev) at every reading plus a bias drawn once per run."""

    stddev: float = 0.0
    mean: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0
    el: Any = None

    @classmethod
    def of(cls, el: Any) -> _NoiseSpec:
        """The numbers of a noise element (`<noise>`, or a classic `<rate>`/`<accel>` block); 0 if absent."""

        def num(tag: str) -> float:
            text = el.findtext(tag)
            return float(text) if text and text.strip() else 0.0

        return cls(num("stddev"), num("mean"), num("bias_mean"), num("bias_stddev"), el)


def _sibling(topic: str, name: str) -> str:
    head = topic.rsplit("/", 1)[0] if "/" in topic else ""
    return _join(head, name)


_FORMATS = {
    "R8G8B8": "rgb8",
    "RGB_INT8": "rgb8",
    "B8G8R8": "bgr8",
    "BGR_INT8": "bgr8",
    "L8": "mono8",
    "L_INT8": "mono8",
}
_DISTORTION = (
    "distortionK1",
    "distortionK2",
    "distortionK3",
    "distortionT1",
    "distortionT2",
    "distortion_k1",
    "distortion_k2",
    "distortion_k3",
    "distortion_t1",
    "distortion_t2",
)
# Camera plugin parameters, ROS 1 (gazebo_ros_camera_utils, depth_camera, openni_kinect) and ROS 2
# (gazebo_ros_camera); the distortion ones and <updateRate> are handled on their own.
_ROS1_CAMERA_PARAMS = {
    "cameraName",
    "imageTopicName",
    "cameraInfoTopicName",
    "depthImageTopicName",
    "depthImageCameraInfoTopicName",
    "pointCloudTopicName",
    "triggerTopicName",
    "frameName",
    "pointCloudCutoff",
    "pointCloudCutoffMax",
    "Cx",
    "Cy",
    "CxPrime",
    "focalLength",
    "hackBaseline",
    "borderCrop",
    "autoDistortion",
}
_ROS2_CAMERA_PARAMS = {
    "ros",
    "camera_name",
    "frame_name",
    "hack_baseline",
    "cx",
    "cy",
    "focal_length",
    "min_depth",
    "max_depth",
    "border_crop",
    "triggered",
}
_ROS2_CAMERA_DECISIVE = ("ros", "camera_name", "frame_name")
_ROS1_CAMERA_EVIDENCE = (
    "cameraName",
    "imageTopicName",
    "cameraInfoTopicName",
    "depthImageTopicName",
    "depthImageCameraInfoTopicName",
    "pointCloudTopicName",
    "robotNamespace",
    "frameName",
    "updateRate",
)
_CAMERA_KNOWN = (
    _ROS1_CAMERA_PARAMS
    | _ROS2_CAMERA_PARAMS
    | set(_DISTORTION)
    | {"updateRate", "update_rate", "updateRateHZ", "robotNamespace", "alwaysOn", "always_on"}
)
# Read by one ROS version and not the other, but with no effect on what is published.
_HARMLESS = {"hackBaseline", "hack_baseline", "borderCrop", "border_crop", "autoDistortion"}
_NOISE_TAGS = {"type", "mean", "stddev", "bias_mean", "bias_stddev"}
_IMU_TAGS = {"angular_velocity", "linear_acceleration", "noise"}
_CAMERA_PLUGINS = {
    "gazebo_ros_camera",
    "gazebo_ros_depth_camera",
    "gazebo_ros_openni_kinect",
    "gazebo_ros_multicamera",
}
_SENSOR_PLUGINS = _CAMERA_PLUGINS | {
    "gazebo_ros_laser",
    "gazebo_ros_gpu_laser",
    "gazebo_ros_ray_sensor",
    "gazebo_ros_block_laser",
    "gazebo_ros_imu_sensor",
    "gazebo_ros_imu",
    "gazebo_ros_bumper",
}
_SENSOR_PLUGINS |= thirdparty.SENSOR_PLUGINS  # velodyne_simulator: runner/compile/thirdparty.py
# gz-sim systems that only switch on what our world always does (physics, sensors, broadcasting).
_NOOP_PLUGINS = {
    "gz-sim-sensors-system",
    "gz-sim-imu-system",
    "gz-sim-physics-system",
    "gz-sim-user-commands-system",
    "gz-sim-scene-broadcaster-system",
    "gz-sim-contact-system",
    "gz-sim-forcetorque-system",
}


def _odom_source(text: str | None) -> str | None:
    if text is None:
        return None
    return "encoders" if text.strip().lower() in ("0", "encoder", "encoders") else "world"


def _diff_drive_classic(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    """gazebo_ros_diff_drive, ROS 1 (`leftJoint`...) and ROS 2 (`left_joint`...). The ROS 2 plugin drives
    `<num_wheel_pairs>` pairs: `left_joint`, `right_joint`, `wheel_separation` and `wheel_diameter` repeat,
    one per pair (a pair without its own separation or diameter keeps the plugin's default, 0.34 m and
    0.15 m); odometry comes from the first pair. Several pairs become our `skid_steer` with every wheel."""
    lefts = [e.text.strip() for e in r.children("leftJoint", "left_joint") if e.text and e.text.strip()]
    rights = [e.text.strip() for e in r.children("rightJoint", "right_joint") if e.text and e.text.strip()]
    seps = [float(e.text) for e in r.children("wheelSeparation", "wheel_separation") if e.text]
    diameters = [float(e.text) for e in r.children("wheelDiameter", "wheel_diameter") if e.text]
    pairs_el = r.child("num_wheel_pairs")
    pairs = int(float(pairs_el.text)) if pairs_el is not None and pairs_el.text else 1
    if pairs_el is not None and pairs != max(len(lefts), len(rights), 1):
        g.note(
            pairs_el,
            f"<num_wheel_pairs> is {pairs} but the plugin names {len(lefts)} left and {len(rights)} right "
            "joint(s): every named wheel is driven",
        )
    diameter = diameters[0] if diameters else None
    torque = r.float("wheelTorque", "max_wheel_torque")
    accel = r.float("wheelAcceleration", "max_wheel_acceleration")
    params: dict[str, Any] = {
        "wheel_separation": seps[0] if seps else None,
        "wheel_radius": diameter / 2 if diameter else None,
        "max_wheel_torque": torque if torque else None,
        # gazebo_ros_diff_drive limits the rim's linear acceleration (m/s²); ours is angular (rad/s²)
        "max_wheel_acceleration": accel / (diameter / 2) if accel and diameter else None,
        "rate": r.float("updateRate", "update_rate") or None,
        "cmd_topic": _topic(r.text("commandTopic")) or remap.get("cmd_vel"),
        "odom_topic": _topic(r.text("odometryTopic")) or remap.get("odom"),
        "odom_frame": r.text("odometryFrame", "odometry_frame"),
        "base_frame": g.frame(r.text("robotBaseFrame", "robot_base_frame")),
        # gazebo_ros_diff_drive reports the true pose unless told `encoder` (its default is world)
        "odometry_source": _odom_source(r.text("odometrySource", "odometry_source")) or "world",
    }
    tf = r.bool("publishTf", "publish_odom_tf", "broadcastTF")
    if tf is not None:
        params["publish_tf"] = tf
    odom = r.bool("publishOdom", "publish_odom")
    if odom is not None:
        params["publish_odom"] = odom
    wheel_tf = r.bool("publishWheelTF", "publish_wheel_tf")
    if wheel_tf:
        params["publish_wheel_tf"] = True
    if r.bool("publishWheelJointState", "publish_wheel_joint_state"):
        g.add(
            r.el,
            "joint_states",
            "wheel_joint_states",
            {"joints": lefts + rights, "rate": params["rate"]},
        )
    r.mark("covariance_x", "covariance_y", "covariance_yaw", "publishOdomTF")
    if len(lefts) > 1 or len(rights) > 1:
        params["left_joints"], params["right_joints"] = lefts, rights
        n = max(len(lefts), len(rights))
        for values, tag, default in ((seps, "wheel_separation", 0.34), (diameters, "wheel_diameter", 0.15)):
            if values and len(values) < n:
                g.note(
                    r.el,
                    f"{n} wheel pairs but {len(values)} <{tag}>: gazebo_ros_diff_drive gives the pairs "
                    f"without one its default, {default} m, and so do we",
                    hint=f"repeat <{tag}> once per pair",
                )
                values += [default] * (n - len(values))
        if seps or diameters:
            params["pair_separations"] = seps or None
            params["pair_radii"] = [d / 2 for d in diameters] or None
        return "skid_steer", params
    params["left_joint"] = lefts[0] if lefts else None
    params["right_joint"] = rights[0] if rights else None
    return "diff_drive", params


def _diff_drive_gz(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    lefts = [e.text.strip() for e in r.children("left_joint") if e.text]
    rights = [e.text.strip() for e in r.children("right_joint") if e.text]
    model = f"model/{g.model}"  # gz-sim's defaults: /model/<model>/cmd_vel, .../odometry, .../tf
    params: dict[str, Any] = {
        "wheel_separation": r.float("wheel_separation"),
        "wheel_radius": r.float("wheel_radius"),
        # odom_publish_frequency is how often it publishes (default 50 Hz); it controls at every step
        "rate": r.float("odom_publish_frequency") or None,
        "cmd_topic": _topic(r.text("topic")) or f"{model}/cmd_vel",
        "odom_topic": _topic(r.text("odom_topic")) or f"{model}/odometry",
        "tf_topic": _topic(r.text("tf_topic")) or f"{model}/tf",
        "odom_frame": r.text("frame_id"),
        "base_frame": g.frame(r.text("child_frame_id")),
    }
    accel = r.float("max_linear_acceleration")
    radius = params["wheel_radius"]
    if accel and radius:
        params["max_wheel_acceleration"] = accel / radius
    return _by_wheels(params, lefts, rights)


def _skid_steer(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    diameter = r.float("wheelDiameter", "wheel_diameter")
    left = [r.text("leftFrontJoint", "left_front_joint"), r.text("leftRearJoint", "left_rear_joint")]
    right = [r.text("rightFrontJoint", "right_front_joint"), r.text("rightRearJoint", "right_rear_joint")]
    params: dict[str, Any] = {
        "left_joints": [j for j in left if j] or None,
        "right_joints": [j for j in right if j] or None,
        "wheel_separation": r.float("wheelSeparation", "wheel_separation"),
        "wheel_radius": diameter / 2 if diameter else None,
        "max_wheel_torque": r.float("torque", "wheelTorque") or None,
        "rate": r.float("updateRate", "update_rate") or None,
        "cmd_topic": _topic(r.text("commandTopic")) or remap.get("cmd_vel"),
        "odom_topic": _topic(r.text("odometryTopic")) or remap.get("odom"),
        "odom_frame": r.text("odometryFrame", "odometry_frame"),
        "base_frame": g.frame(r.text("robotBaseFrame", "robot_base_frame")),
    }
    tf = r.bool("broadcastTF", "publish_odom_tf")
    if tf is not None:
        params["publish_tf"] = tf
    r.mark("covariance_x", "covariance_y", "covariance_yaw")
    return "skid_steer", params


def _planar_move(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    params: dict[str, Any] = {
        "rate": r.float("odometryRate", "publish_rate", "update_rate") or None,
        "cmd_topic": _topic(r.text("commandTopic")) or remap.get("cmd_vel"),
        "odom_topic": _topic(r.text("odometryTopic")) or remap.get("odom"),
        "odom_frame": r.text("odometryFrame", "odometry_frame"),
        "base_frame": g.frame(r.text("robotBaseFrame", "robot_base_frame")),
    }
    tf = r.bool("publish_odom_tf")
    if tf is not None:
        params["publish_tf"] = tf
    odom = r.bool("publish_odom")
    if odom is not None:
        params["publish_odom"] = odom
    timeout = r.float("cmdTimeout", "cmd_timeout")
    if timeout and timeout > 0:
        params["cmd_timeout"] = timeout
    r.mark("covariance_x", "covariance_y", "covariance_yaw")
    return "planar_move", params


def _joint_states(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    joints: list[str] = []
    for el in r.children("jointName", "joint_name"):
        joints += [j.strip() for j in (el.text or "").split(",") if j.strip()]
    topic = _topic(r.text("topic")) or remap.get("joint_states")
    if topic is None and r.el.get("filename", "").startswith(("gz-sim", "ignition-gazebo", "libgz-sim")):
        topic = f"world/default/model/{g.model}/joint_state"  # gz-sim's default (the world is "default")
    params: dict[str, Any] = {
        "joints": joints or None,
        "rate": r.float("updateRate", "update_rate") or None,
        "topic": topic,
    }
    return "joint_states", params


def _imu_model(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    """ROS 1 gazebo_ros_imu (a model plugin): N(0, <gaussianNoise>) on every rate and acceleration, and
    nothing else; it reads no `<imu>` block (TurtleBot3's is not used by Gazebo either)."""
    noise = r.float("gaussianNoise")
    params: dict[str, Any] = {
        "link": r.text("bodyName", "body_name"),
        "topic": _topic(r.text("topicName", "topic_name")) or remap.get("imu") or "imu",
        "frame_id": g.frame(r.text("frameName", "frame_name")),
        "rate": r.float("updateRate", "updateRateHZ", "update_rate") or None,
        "angular_velocity_stddev": noise or None,
        "linear_acceleration_stddev": noise or None,
    }
    imu = r.child("imu")
    if imu is not None:
        g.note(
            imu,
            f"<imu> is not a parameter of {r.el.get('filename')!r}: Gazebo ignores it too (the plugin adds "
            f"only <gaussianNoise>, here {noise or 0.0})",
            hint="give the noise in the scenario: plugins: [{type: imu, params: {angular_velocity_stddev: "
            "..., linear_acceleration_stddev: ..., angular_velocity_bias_mean: [...]}}]",
        )
    for tag in ("xyzOffset", "rpyOffset", "xyzOffsets", "rpyOffsets"):
        el = r.child(tag)
        if el is not None and (_floats(el.text, 3) is None or any(_floats(el.text, 3) or [])):
            g.note(el, f"<{tag}> in {r.el.get('filename')!r} is ignored")
    return "imu", params


def _p3d(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    params: dict[str, Any] = {
        "link": r.text("bodyName", "body_name"),
        "topic": _topic(r.text("topicName", "topic_name")) or remap.get("odom") or "ground_truth",
        "frame_id": r.text("frameName", "frame_name"),
        "rate": r.float("updateRate", "update_rate") or None,
    }
    r.mark("xyzOffsets", "rpyOffsets", "gaussianNoise", "xyz_offsets", "rpy_offsets", "gaussian_noise")
    return "ground_truth", params


def _odometry_publisher(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    params: dict[str, Any] = {
        "topic": _topic(r.text("odom_topic")) or f"model/{g.model}/odometry",
        "frame_id": g.frame(r.text("odom_frame") or "odom"),
        "rate": r.float("odom_publish_frequency") or None,
    }
    r.mark(
        "robot_base_frame",
        "dimensions",
        "tf_topic",
        "odom_covariance_topic",
        "gaussian_noise",
        "xyz_offset",
        "rpy_offset",
    )
    return "ground_truth", params


def _ros_control(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> None:
    """gazebo_ros_control (ROS 1): its controllers come from parameters a launch file loads, which the
    description does not name. gz_ros2_control / gazebo_ros2_control (ROS 2): `<parameters>` names the
    controllers file, whose diff drive and joint state broadcaster are run as Gazebo runs them."""
    r.mark(*[c.tag for c in r.el if isinstance(c.tag, str)])
    files = [e for e in r.children("parameters") if (e.text or "").strip().endswith((".yaml", ".yml"))]
    ran = sum(_ros2_controllers(g, r.el, e) for e in files)
    if ran or g.controller_files:  # the scenario's `controllers:` are run (read at the end)
        return None
    g.note(
        r.el,
        f"{r.el.get('filename')!r}: ros_control controllers are not run"
        + (" (no diff drive or joint state broadcaster in its <parameters>)" if files else "")
        + "; transmissions became MuJoCo actuators",
        hint="command joints with a `joint_controller` plugin in the scenario, or give the robot a "
        "`diff_drive` plugin with the controller's wheels and topics",
    )
    return None


def _by_wheels(params: dict[str, Any], lefts: list[str], rights: list[str]) -> tuple[str, dict[str, Any]]:
    """A drive with one wheel a side is a diff_drive; with several, a skid_steer driving them all."""
    if len(lefts) > 1 or len(rights) > 1:
        params["left_joints"], params["right_joints"] = lefts, rights
        return "skid_steer", params
    params["left_joint"] = lefts[0] if lefts else None
    params["right_joint"] = rights[0] if rights else None
    return "diff_drive", params


def _ros_parameters(doc: Any, path: tuple[str, ...] = ()) -> dict[str, dict[str, Any]]:
    """Node name -> its `ros__parameters` in a ROS 2 parameters file (under `/**`, namespaces, or plain)."""
    out: dict[str, dict[str, Any]] = {}
    if not isinstance(doc, dict):
        return out
    for key, value in doc.items():
        if key == "ros__parameters" and isinstance(value, dict) and path:
            out[path[-1].strip("/").split("/")[-1]] = value
        elif isinstance(value, dict):
            out.update(_ros_parameters(value, (*path, str(key))))
    return out


def _param(params: dict[str, Any], dotted: str) -> Any:
    """A parameter written `a.b.c: v` or nested (`a: {b: {c: v}}`)."""
    if dotted in params:
        return params[dotted]
    node: Any = params
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _ros2_controllers(g: GazeboReader, plugin: Any, el: Any) -> int:
    """The controllers of the ros2_control parameters file a `<parameters>` names; returns how many run."""
    path = Path((el.text or "").strip())
    if not path.is_absolute():
        base = g.where(el)[0]
        path = (base.parent if base else Path.cwd()) / path
    try:
        return g.controllers(path, g.where(plugin))
    except SourceError as e:
        g.note(el, f"{e}; its controllers are not run")
        return 0


def _controller_entries(doc: Any) -> tuple[list[tuple[str, str, dict[str, Any]]], Any]:
    """(name, type, parameters) of each controller in a controllers file, and the update rate: ROS 2's
    (`controller_manager: ros__parameters: <name>: {type}` and `<name>: ros__parameters: {...}`, under
    `/**` or namespaces) or ROS 1's (`<name>: {type: ..., ...}`, at the top or under namespaces)."""
    nodes = _ros_parameters(doc)
    if nodes:
        manager = nodes.get("controller_manager", {})
        found = [
            (name, str(spec["type"]), nodes.get(name, {}))
            for name, spec in manager.items()
            if isinstance(spec, dict) and "type" in spec
        ]
        return found, manager.get("update_rate")
    found = []

    def walk(node: Any) -> None:
        if not isinstance(node, dict):
            return
        for key, value in node.items():
            if isinstance(value, dict) and isinstance(value.get("type"), str):
                found.append((str(key), value["type"], value))
            elif isinstance(value, dict):
                walk(value)

    walk(doc)
    return found, None


def _diff_drive_controller(
    g: GazeboReader, name: str, p: dict[str, Any], ros1: bool, where: Where
) -> tuple[str, dict[str, Any]]:
    """diff_drive_controller/DiffDriveController as it runs in Gazebo. ROS 1: `left_wheel`/`right_wheel`
    (a joint or a list), `<name>/cmd_vel` (Twist); separation and radius from the URDF unless given. ROS 2
    (Humble to Jazzy): `left_wheel_names`/`right_wheel_names`, `<name>/cmd_vel` (TwistStamped) or, with
    `use_stamped_vel: false`, `<name>/cmd_vel_unstamped` (Twist). Both: `<name>/odom` at `publish_rate`,
    `/tf` when `enable_odom_tf`, stopping `cmd_vel_timeout` (0.5 s) after the last command, multipliers."""

    def names(*keys: str) -> list[str]:
        for key in keys:
            value = _param(p, key)
            if value:
                return [str(v) for v in value] if isinstance(value, list) else [str(value)]
        return []

    lefts, rights = names("left_wheel_names", "left_wheel"), names("right_wheel_names", "right_wheel")
    sep, radius = _param(p, "wheel_separation"), _param(p, "wheel_radius")
    stamped = False if ros1 else _param(p, "use_stamped_vel") is not False
    if stamped:
        g.notices.add(
            f"ros2_control diff drive {name!r} takes geometry_msgs/TwistStamped on {name}/cmd_vel; here it "
            "takes geometry_msgs/Twist there",
            *where,
            hint="set use_stamped_vel: false in the controllers file to have it as Gazebo then has it "
            f"({name}/cmd_vel_unstamped, Twist)",
        )
    params: dict[str, Any] = {
        "wheel_separation": float(sep) if sep else None,
        "wheel_radius": float(radius) if radius else None,
        "wheel_separation_multiplier": float(_param(p, "wheel_separation_multiplier") or 1.0),
        "wheel_radius_multiplier": float(
            _param(p, "wheel_radius_multiplier") or _param(p, "left_wheel_radius_multiplier") or 1.0
        ),
        "rate": float(_param(p, "publish_rate") or 50.0),
        "cmd_topic": f"{name}/cmd_vel_unstamped" if not ros1 and not stamped else f"{name}/cmd_vel",
        "odom_topic": f"{name}/odom",
        "tf_topic": "tf",
        "publish_tf": _param(p, "enable_odom_tf") is not False,
        "odom_frame": _param(p, "odom_frame_id") or "odom",
        "base_frame": g.frame(_param(p, "base_frame_id") or "base_link"),
        "cmd_timeout": float(_param(p, "cmd_vel_timeout") or 0.5),
    }
    accel = _param(p, "linear.x.max_acceleration")
    if accel and radius and _param(p, "linear.x.has_acceleration_limits"):
        params["max_wheel_acceleration"] = float(accel) / float(radius)
    return _by_wheels(params, lefts, rights)


# The parameters the real Gazebo plugins read (classic ROS 1 and ROS 2 spellings, gz-sim systems): anything
# else in their block is a typo or a leftover that Gazebo itself ignores, and is reported as such.
_DIFF_DRIVE_PARAMS = {
    "alwaysOn",
    "updateRate",
    "leftJoint",
    "rightJoint",
    "wheelSeparation",
    "wheelDiameter",
    "wheelAcceleration",
    "wheelTorque",
    "commandTopic",
    "odometryTopic",
    "odometryFrame",
    "robotBaseFrame",
    "publishWheelTF",
    "publishOdomTF",
    "publishWheelJointState",
    "publishTf",
    "legacyMode",
    "rosDebugLevel",
    "odometrySource",
    "robotNamespace",
    "ros",
    "update_rate",
    "left_joint",
    "right_joint",
    "wheel_separation",
    "wheel_diameter",
    "max_wheel_torque",
    "max_wheel_acceleration",
    "publish_odom",
    "publish_odom_tf",
    "publish_wheel_tf",
    "odometry_frame",
    "robot_base_frame",
    "odometry_source",
    "covariance_x",
    "covariance_y",
    "covariance_yaw",
    "num_wheel_pairs",
}
_GZ_DIFF_DRIVE_PARAMS = {
    "left_joint",
    "right_joint",
    "wheel_separation",
    "wheel_radius",
    "odom_publish_frequency",
    "max_linear_acceleration",
    "min_linear_acceleration",
    "max_angular_acceleration",
    "min_angular_acceleration",
    "max_linear_velocity",
    "min_linear_velocity",
    "max_angular_velocity",
    "min_angular_velocity",
    "max_velocity",
    "max_acceleration",
    "max_jerk",
    "min_jerk",
    "topic",
    "odom_topic",
    "tf_topic",
    "frame_id",
    "child_frame_id",
}
_SKID_STEER_PARAMS = {
    "alwaysOn",
    "updateRate",
    "leftFrontJoint",
    "rightFrontJoint",
    "leftRearJoint",
    "rightRearJoint",
    "wheelSeparation",
    "wheelDiameter",
    "robotBaseFrame",
    "torque",
    "commandTopic",
    "odometryTopic",
    "odometryFrame",
    "broadcastTF",
    "covariance_x",
    "covariance_y",
    "covariance_yaw",
    "robotNamespace",
    "ros",
    "update_rate",
    "left_front_joint",
    "right_front_joint",
    "left_rear_joint",
    "right_rear_joint",
}
_PLUGIN_PARAMS = {
    "gazebo_ros_diff_drive": _DIFF_DRIVE_PARAMS,
    "gz-sim-diff-drive-system": _GZ_DIFF_DRIVE_PARAMS,
    "gz-sim-diffdrive-system": _GZ_DIFF_DRIVE_PARAMS,
    "gazebo_ros_skid_steer_drive": _SKID_STEER_PARAMS,
}

_MODEL_PLUGINS = {
    "gazebo_ros_diff_drive": _diff_drive_classic,
    "gz-sim-diff-drive-system": _diff_drive_gz,
    "gz-sim-diffdrive-system": _diff_drive_gz,
    "gazebo_ros_skid_steer_drive": _skid_steer,
    "gazebo_ros_planar_move": _planar_move,
    "gazebo_ros_joint_state_publisher": _joint_states,
    "gz-sim-joint-state-publisher-system": _joint_states,
    "gazebo_ros_imu": _imu_model,
    "gazebo_ros_p3d": _p3d,
    "gz-sim-odometry-publisher-system": _odometry_publisher,
    "gazebo_ros_control": _ros_control,
    "gazebo_ros2_control": _ros_control,
    "gz_ros2_control-system": _ros_control,
    "ign_ros2_control-system": _ros_control,
}
_MODEL_PLUGINS.update(thirdparty.MODEL_PLUGINS)  # hector_gazebo_plugins: runner/compile/thirdparty.py


def read_gazebo(
    root: Any,
    file: Path | None,
    *,
    sources: list[Path] | None = None,
    expanded: bool = False,
    namespace: str,
    model: str | None = None,
    notices: Notices,
    controllers: list[Path] | None = None,
) -> GazeboInfo:
    reader = GazeboReader(root, file, sources or [], expanded, namespace, notices, model)
    reader.controller_files = list(controllers or [])
    return reader.read()


def parse(text: str) -> Any:
    parser = etree.XMLParser(remove_comments=True)
    return etree.fromstring(text.encode(), parser)
