"""URDF `<gazebo>` extension tags -> our plugins and MuJoCo properties (Gazebo classic and Harmonic).

- `<gazebo reference="link">`: materials (`Gazebo/Red`, or `<material><diffuse>`), `mu1`/`mu2` (friction),
  `kp`/`kd` (contact stiffness and damping), `turnGravityOff`/`gravity`, and `<sensor>`s;
- `<gazebo>` (no reference): model plugins (`<plugin filename=...>`) and `<static>`;
- sensors: ray/gpu_ray/lidar/gpu_lidar -> `lidar`; camera -> `camera`; depth/depth_camera/rgbd_camera ->
  `depth_camera`; imu -> `imu`; with the topic names their ROS plugin (classic `topicName`,
  `cameraName`+`imageTopicName`, ROS 2 `<ros><remapping>`) or Harmonic `<topic>` gives, placed under the
  robot's namespace.

What is not understood is listed as a notice (tag, file, line), never dropped silently and never fatal.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from runner.compile.locate import Locator
from runner.compile.materials import gazebo_material
from runner.errors import Notices, SourceError

_NOT_FINITE = {"inf", "-inf", "+inf", "infinity", "-infinity", "nan"}

# Tags whose meaning is GUI-only or debugging, ignored on purpose; listed with this reason.
_IGNORED_REASONS = {
    "visualize": "GUI only",
    "always_on": "sensors are always on",
    "alwaysOn": "sensors are always on",
    "rosDebugLevel": "ROS debug level",
    "legacyMode": "wheel order is taken from the joint names",
    "publishWheelTF": "wheel TF comes from joint_states",
    "publish_wheel_tf": "wheel TF comes from joint_states",
    "hackBaseline": "stereo baseline (mono camera)",
    "selfCollide": "MuJoCo excludes parent-child contacts",
    "self_collide": "MuJoCo excludes parent-child contacts",
    "enable_metrics": "diagnostics",
    "gaussianNoise": "use the sensor's <noise>",
    "minDepth": "ODE contact parameter; MuJoCo contacts are soft (solref/solimp)",
    "maxVel": "ODE contact parameter; MuJoCo contacts are soft (solref/solimp)",
    "fdir1": "anisotropic friction is not supported",
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


@dataclass
class LinkProps:
    rgba: tuple[float, float, float, float] | None = None
    friction: float | None = None
    kp: float | None = None
    kd: float | None = None
    gravity_off: bool = False


@dataclass
class GazeboInfo:
    plugins: list[DescribedPlugin] = field(default_factory=list)
    links: dict[str, LinkProps] = field(default_factory=dict)
    static: bool = False


class _Reader:
    """Reads children of one element by any of several spellings and remembers which were used."""

    def __init__(self, el: Any):
        self.el = el
        self.used: set[str] = set()

    def child(self, *names: str) -> Any | None:
        for n in names:
            found = self.el.find(n)
            if found is not None:
                self.used.add(n)
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
        if el is None or el.text is None:
            return None
        return el.text.strip()

    def float(self, *names: str) -> float | None:
        t = self.text(*names)
        try:
            return float(t) if t is not None else None
        except ValueError:
            return None

    def bool(self, *names: str) -> bool | None:
        t = self.text(*names)
        if t is None:
            return None
        return t.lower() in ("1", "true", "yes", "on")

    def mark(self, *names: str) -> None:
        self.used.update(names)

    def leftovers(self) -> list[Any]:
        return [c for c in self.el if isinstance(c.tag, str) and c.tag not in self.used]


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
    ):
        self.root = root
        self.where = Locator(file, sources, expanded)
        self.namespace = namespace
        self.notices = notices
        self.info = GazeboInfo()
        self._names: set[str] = set()

    # --------------------------------------------------------------------------------------- helpers
    def note(self, el: Any, message: str, hint: str | None = None) -> None:
        file, line = self.where(el)
        self.notices.add(message, file, line, hint)

    def ignored(self, reader: _Reader, context: str) -> None:
        for el in reader.leftovers():
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
        frame = frame.strip("/")
        ns = self.namespace
        return frame if frame.startswith(ns + "/") else f"{ns}/{frame}"

    # ------------------------------------------------------------------------------------------ read
    def read(self) -> GazeboInfo:
        for gz in self.root.findall("gazebo"):
            ref = gz.get("reference")
            try:
                if ref:
                    self._reference(gz, ref)
                else:
                    self._model(gz)
            except (ValueError, OverflowError) as e:  # float("many"), int(float("inf")) in a tag's text
                raise self._not_a_number(gz, e) from None
        self._drop_shadowed()
        return self.info

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
        r = _Reader(gz)
        props = self.info.links.setdefault(link, LinkProps())
        mat = r.child("material")
        if mat is not None:
            props.rgba = self._material(mat) or props.rgba
        visual = r.child("visual")
        if visual is not None:
            vm = visual.find("material")
            if vm is not None:
                props.rgba = self._material(vm) or props.rgba
        mu = [v for v in (r.float("mu1"), r.float("mu2"), r.float("mu")) if v is not None]
        if mu:
            props.friction = min(mu)
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
        gravity = r.bool("gravity")
        if gravity is False:
            props.gravity_off = True
        for sensor in r.children("sensor"):
            self._sensor(sensor, link)
        for plugin in r.children("plugin"):  # a model plugin written inside a reference block
            self._plugin(plugin, link)
        self.ignored(r, f'<gazebo reference="{link}">')

    def _material(self, el: Any) -> tuple[float, float, float, float] | None:
        if el.text and el.text.strip():
            rgba = gazebo_material(el.text)
            if rgba is None:
                self.note(el, f"unknown Gazebo material {el.text.strip()!r}; the URDF colour is kept")
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
        r = _Reader(gz)
        if r.bool("static"):
            self.info.static = True
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
        frame = self.frame(r.text("gz_frame_id", "frame_id", "frameName"))
        plugins = r.children("plugin")
        common: dict[str, Any] = {"link": link}
        if rate:
            common["rate"] = rate
        if pose:
            common["pose"] = {"xyz": pose[:3], "rpy": pose[3:]}
        if kind in ("ray", "gpu_ray", "lidar", "gpu_lidar"):
            params = {**common, **self._lidar(r, el, context)}
            ros = self._sensor_plugins(plugins, context, ("out", "scan"))
            params["topic"] = ros.get("topic") or base_topic or "scan"
            params["frame_id"] = ros.get("frame") or frame
            self.add(el, "lidar", name, params, implicit=not (ros or base_topic))
        elif kind == "camera":
            params = {**common, **self._camera(r, el, context)}
            ros = self._sensor_plugins(plugins, context, ("image_raw", "image"))
            image = ros.get("topic") or (_join(base_topic, "image") if base_topic else "camera/image_raw")
            params["image_topic"] = image
            params["info_topic"] = ros.get("info") or _sibling(image, "camera_info")
            params["frame_id"] = ros.get("frame") or frame
            self.add(el, "camera", name, params, implicit=not (ros or base_topic))
        elif kind in ("depth", "depth_camera", "rgbd_camera", "rgbd"):
            params = {**common, **self._camera(r, el, context)}
            ros = self._sensor_plugins(plugins, context, ("image_raw", "image"))
            if not ros and kind in ("depth", "depth_camera"):
                # Harmonic depth camera: depth image on <topic>, points on <topic>/points
                topic = base_topic or "depth_camera"
                params.update(
                    depth_topic=topic,
                    points_topic=_join(topic, "points"),
                    info_topic=_sibling(topic, "camera_info"),
                    publish_color=False,
                )
            elif not ros:
                # Harmonic rgbd: <topic>/image, <topic>/depth_image, <topic>/points, <topic>/camera_info
                topic = base_topic or "rgbd_camera"
                params.update(
                    image_topic=_join(topic, "image"),
                    depth_topic=_join(topic, "depth_image"),
                    points_topic=_join(topic, "points"),
                    info_topic=_join(topic, "camera_info"),
                )
            else:
                cam = ros.get("camera") or "camera"
                params.update(
                    image_topic=ros.get("topic") or _join(cam, "image_raw"),
                    depth_topic=ros.get("depth") or _join(cam, "depth/image_raw"),
                    points_topic=ros.get("points") or _join(cam, "points"),
                    info_topic=ros.get("info") or _join(cam, "camera_info"),
                )
            info_topic = _topic(el.findtext("camera/camera_info_topic"))
            if info_topic:
                params["info_topic"] = info_topic
            params["frame_id"] = ros.get("frame") or frame
            self.add(el, "depth_camera", name, params)
        elif kind == "imu":
            params = {**common, **self._imu(r, el)}
            ros = self._sensor_plugins(plugins, context, ("out", "imu"))
            params["topic"] = ros.get("topic") or base_topic or "imu"
            params["frame_id"] = ros.get("frame") or frame
            if ros.get("noise") and not params.get("angular_velocity_stddev"):
                params["angular_velocity_stddev"] = ros["noise"]
                params["linear_acceleration_stddev"] = ros["noise"]
            self.add(el, "imu", name, params, implicit=not (ros or base_topic))
        elif kind == "contact":
            if link is None:
                self.note(el, f"{context} outside a <gazebo reference=...> block has no link; ignored")
                return
            r.child("contact")  # <collision> names: we report every contact of the link
            ros = self._sensor_plugins(plugins, context, ("bumper_states", "bumper"))
            params = {**common, "topic": ros.get("topic") or base_topic or "bumper"}
            params["frame_id"] = ros.get("frame") or frame
            self.add(el, "contact", name, params)
        else:
            self.note(
                el,
                f"sensor type {kind!r} is not supported yet; {context} is ignored",
                hint="supported: ray, gpu_ray, lidar, gpu_lidar, camera, depth, depth_camera, rgbd_camera, "
                "imu, contact",
            )
            return
        self.ignored(r, context)

    def _noise(self, el: Any | None) -> float | None:
        if el is None:
            return None
        noise = el.find("noise")
        if noise is None:
            return None
        kind = (noise.get("type") or noise.findtext("type") or "gaussian").strip()
        if kind.lower() not in ("gaussian", "gaussian_quantized"):
            self.note(noise, f"noise type {kind!r} is treated as gaussian")
        mean = noise.findtext("mean")
        if mean and float(mean) != 0.0:
            self.note(noise, "a non-zero noise mean is ignored (use a bias in the plugin params)")
        sd = noise.findtext("stddev")
        return float(sd) if sd else None

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
        noise = self._noise(ray)
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
        noise = self._noise(cam)
        if noise:
            out["noise_stddev"] = noise
        known = {"horizontal_fov", "image", "clip", "noise", "camera_info_topic", "depth_camera"}
        for child in cam:
            if isinstance(child.tag, str) and child.tag not in known:
                self.note(child, f"<{child.tag}> in {context} <camera> is ignored")
        return out

    def _imu(self, r: _Reader, el: Any) -> dict[str, Any]:
        imu = r.child("imu")
        out: dict[str, Any] = {}
        if imu is None:
            return out
        for block, key in (
            ("angular_velocity", "angular_velocity_stddev"),
            ("linear_acceleration", "linear_acceleration_stddev"),
        ):
            sds = [self._noise(imu.find(f"{block}/{axis}")) for axis in ("x", "y", "z")]
            sds = [s for s in sds if s]
            if sds:
                out[key] = max(sds)
        # classic (SDF 1.4) style: <imu><noise><rate><stddev>, <accel><stddev>
        n = imu.find("noise")
        if n is not None:
            _put(out, "angular_velocity_stddev", n, "rate/stddev")
            _put(out, "linear_acceleration_stddev", n, "accel/stddev")
        return out

    def _sensor_plugins(self, plugins: list[Any], context: str, out_names: tuple[str, ...]) -> dict[str, Any]:
        """The ROS plugin inside a sensor: where it publishes (classic and ROS 2 spellings)."""
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
            cam = _topic(r.text("cameraName", "camera_name"))
            if cam:
                found["camera"] = cam
            prefix = cam if base in _CAMERA_PLUGINS else None
            topic = _topic(r.text("topicName", "topic_name", "bumperTopicName"))
            image = _topic(r.text("imageTopicName", "image_topic_name"))
            info = _topic(r.text("cameraInfoTopicName", "camera_info_topic_name"))
            depth = _topic(r.text("depthImageTopicName", "depth_image_topic_name"))
            points = _topic(r.text("pointCloudTopicName", "point_cloud_topic_name"))
            for out in out_names:
                if out in remap:
                    topic = topic or remap[out]
            if base in _CAMERA_PLUGINS:
                image = image or remap.get("image_raw") or "image_raw"
                info = info or remap.get("camera_info") or "camera_info"
                depth = depth or remap.get("depth/image_raw") or "depth/image_raw"
                points = points or remap.get("points") or "points"
                found["topic"] = _join(prefix, image)
                found["info"] = _join(prefix, info)
                found["depth"] = _join(prefix, depth)
                found["points"] = _join(prefix, points)
                found["color"] = True
            elif topic:
                found["topic"] = topic
            frame = r.text("frameName", "frame_name")
            if frame:
                found["frame"] = self.frame(frame)
            noise = r.float("gaussianNoise")
            if noise:
                found["noise"] = noise
            r.mark(
                "alwaysOn",
                "always_on",
                "updateRate",
                "update_rate",
                "robotNamespace",
                "bodyName",
                "output_type",
                "min_intensity",
                "pointCloudCutoff",
                "pointCloudCutoffMax",
                "Cx",
                "Cy",
                "CxPrime",
                "focalLength",
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
                "hack_baseline",
                "hackBaseline",
                "updateRateHZ",
                "min_range",
                "max_range",
                "initial_orientation_as_reference",
            )
            nonzero = [
                t
                for t in ("distortionK1", "distortionK2", "distortionK3", "distortionT1", "distortionT2")
                if (p.findtext(t) or "0").strip() not in ("0", "0.0", "0.00000000")
            ]
            for t in nonzero:
                self.note(p.find(t), f"<{t}> in {context} is ignored (images are not distorted)")
            self.ignored(r, f"<plugin filename={filename!r}>")
        return found

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
_DISTORTION = ("distortionK1", "distortionK2", "distortionK3", "distortionT1", "distortionT2")
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
    diameter = r.float("wheelDiameter", "wheel_diameter")
    torque = r.float("wheelTorque", "max_wheel_torque")
    accel = r.float("wheelAcceleration", "max_wheel_acceleration")
    params: dict[str, Any] = {
        "left_joint": r.text("leftJoint", "left_joint"),
        "right_joint": r.text("rightJoint", "right_joint"),
        "wheel_separation": r.float("wheelSeparation", "wheel_separation"),
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
    if r.bool("publishWheelJointState", "publish_wheel_joint_state"):
        g.add(
            r.el,
            "joint_states",
            "wheel_joint_states",
            {"joints": [params["left_joint"], params["right_joint"]], "rate": params["rate"]},
        )
    r.mark("covariance_x", "covariance_y", "covariance_yaw", "publishOdomTF", "num_wheel_pairs")
    return "diff_drive", params


def _diff_drive_gz(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    lefts = [e.text.strip() for e in r.children("left_joint") if e.text]
    rights = [e.text.strip() for e in r.children("right_joint") if e.text]
    params: dict[str, Any] = {
        "wheel_separation": r.float("wheel_separation"),
        "wheel_radius": r.float("wheel_radius"),
        "rate": r.float("odom_publish_frequency") or None,
        "cmd_topic": _topic(r.text("topic")),
        "odom_topic": _topic(r.text("odom_topic")),
        "tf_topic": _topic(r.text("tf_topic")),
        "odom_frame": r.text("frame_id"),
        "base_frame": g.frame(r.text("child_frame_id")),
    }
    accel = r.float("max_linear_acceleration")
    radius = params["wheel_radius"]
    if accel and radius:
        params["max_wheel_acceleration"] = accel / radius
    if len(lefts) > 1 or len(rights) > 1:
        params["left_joints"], params["right_joints"] = lefts, rights
        return "skid_steer", params
    params["left_joint"] = lefts[0] if lefts else None
    params["right_joint"] = rights[0] if rights else None
    return "diff_drive", params


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
    params: dict[str, Any] = {
        "joints": joints or None,
        "rate": r.float("updateRate", "update_rate") or None,
        "topic": _topic(r.text("topic")) or remap.get("joint_states"),
    }
    return "joint_states", params


def _imu_model(g: GazeboReader, r: _Reader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
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
        rate_sd, accel_sd = imu.findtext("noise/rate/stddev"), imu.findtext("noise/accel/stddev")
        if rate_sd:
            params["angular_velocity_stddev"] = float(rate_sd)
        if accel_sd:
            params["linear_acceleration_stddev"] = float(accel_sd)
    r.mark("xyzOffset", "rpyOffset", "xyzOffsets", "rpyOffsets")
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
        "topic": _topic(r.text("odom_topic")) or "odom",
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
    g.note(
        r.el,
        f"{r.el.get('filename')!r}: ros_control controllers are not run; transmissions became MuJoCo "
        "actuators",
        hint="command joints with a `joint_controller` plugin in the scenario",
    )
    r.mark(*[c.tag for c in r.el if isinstance(c.tag, str)])
    return None


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


def read_gazebo(
    root: Any,
    file: Path | None,
    *,
    sources: list[Path] | None = None,
    expanded: bool = False,
    namespace: str,
    notices: Notices,
) -> GazeboInfo:
    return GazeboReader(root, file, sources or [], expanded, namespace, notices).read()


def parse(text: str) -> Any:
    parser = etree.XMLParser(remove_comments=True)
    return etree.fromstring(text.encode(), parser)
