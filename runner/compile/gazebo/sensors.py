"""`<sensor>` blocks -> our sensor plugins: ray/gpu_ray/lidar/gpu_lidar -> `lidar`; camera -> `camera`;
depth/depth_camera/rgbd_camera -> `depth_camera`; imu -> `imu`; contact -> `contact`; gps (a third-party
plugin's): runner.compile.gazebo.thirdparty. Each kind reads its SDF block (`<ray>`, `<camera>`, `<imu>`,
with their noise) and takes its topics from the ROS plugin inside it (runner.compile.gazebo.sensor_plugins),
else from Harmonic's `<topic>` or gz-sensors' scoped default, else from our default (an *implicit* sensor,
which classic Gazebo would not publish on ROS)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from runner.compile.gazebo import thirdparty
from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.noise import NoiseSpec, classic_noise_spec, noise_spec, noise_stddev
from runner.compile.gazebo.sensor_plugins import read_sensor_plugins
from runner.compile.gazebo.tables import FORMATS, IMU_TAGS
from runner.compile.gazebo.tags import TagReader, floats, join_topic, put_number, ros_topic, sibling_topic
from runner.errors import PLUGIN_UNSUPPORTED


@dataclass
class _Sensor:
    """One `<sensor>` and what every kind reads of it the same way."""

    el: Any
    r: TagReader
    link: str | None
    name: str
    kind: str
    context: str
    rate: float | None  # <update_rate>
    base_topic: str | None  # Harmonic's <topic>
    frame: str | None  # <gz_frame_id> and its older spellings
    plugins: list[Any]  # the ROS plugins inside it
    common: dict[str, Any]  # link, rate and pose: the params of every kind


def read_sensor(g: ReaderBase, el: Any, link: str | None) -> None:
    """A `<sensor>` of the link `link` (None: in a `<gazebo>` block without a reference) -> a plugin."""
    kind = (el.get("type") or "").strip()
    name = el.get("name") or kind or "sensor"
    r = TagReader(el)
    context = f"<sensor name={name!r} type={kind!r}>"
    rate = r.float("update_rate", "updateRate")
    pose = floats(r.text("pose"), 6)
    base_topic = ros_topic(r.text("topic"))
    frame = g.frame(r.text("gz_frame_id", "ignition_frame_id", "frame_id", "frameName"))
    plugins = r.children("plugin")
    common: dict[str, Any] = {"link": link}
    if rate:
        common["rate"] = rate
    if pose:
        common["pose"] = {"xyz": pose[:3], "rpy": pose[3:]}
    s = _Sensor(el, r, link, name, kind, context, rate, base_topic, frame, plugins, common)
    read = _KINDS.get(kind)
    if read is not None:
        if not read(g, s):
            return
    elif kind in thirdparty.SENSOR_KINDS:  # gps: runner/compile/gazebo/thirdparty.py
        thirdparty.sensor(g, r, el, common, plugins, name, kind, context, base_topic, frame)
    else:
        g.note(
            el,
            f"sensor type {kind!r} is not supported yet; {context} is ignored",
            hint="supported: ray, gpu_ray, lidar, gpu_lidar, camera, depth, depth_camera, rgbd_camera, "
            "imu, contact",
            kind=PLUGIN_UNSUPPORTED,
        )
        return
    g.ignored(r, context)


def _lidar_sensor(g: ReaderBase, s: _Sensor) -> bool:
    params = {**s.common, **_lidar(g, s.r, s.el, s.context)}
    ros = read_sensor_plugins(g, s.plugins, s.context, ("out", "scan"), s.name, s.kind)
    params["topic"] = ros.get("topic") or s.base_topic or "scan"
    params["frame_id"] = ros.get("frame") or s.frame
    if ros.get("noise"):  # gazebo_ros_block_laser adds its <gaussianNoise> to the sensor's noise
        params["noise_stddev"] = math.hypot(params.get("noise_stddev", 0.0), ros["noise"])
    params.update(ros.get("params") or {})  # what a third-party plugin changes (velodyne)
    if not ros and (g.harmonic or s.kind in ("lidar", "gpu_lidar")):
        if not s.base_topic and g.harmonic:
            params["topic"] = _gz_sensor_topic(g, s.link, s.name, "scan")
        # gz-sensors: a lidar publishes its scan on <topic> and its point cloud on <topic>/points
        params.setdefault("publish_points", True)
        params["points_topic"] = join_topic(params["topic"], "points")
    g.add(s.el, "lidar", s.name, params, implicit=not (ros or s.base_topic or g.harmonic))
    return True


def _camera_sensor(g: ReaderBase, s: _Sensor) -> bool:
    params = {**s.common, **_camera(g, s.r, s.el, s.context)}
    ros = read_sensor_plugins(g, s.plugins, s.context, ("image_raw", "image"), s.name, s.kind)
    # gz-sensors: <topic> carries the image, CameraInfo goes to <camera_info_topic> or a sibling
    image = ros.get("topic") or s.base_topic or "camera/image_raw"
    if g.harmonic and not (ros or s.base_topic):
        image = _gz_sensor_topic(g, s.link, s.name, "image")
    params["image_topic"] = image
    info_topic = ros_topic(s.el.findtext("camera/camera_info_topic"))
    params["info_topic"] = (
        ros.get("info") or (info_topic if not ros else None) or sibling_topic(image, "camera_info")
    )
    params["frame_id"] = ros.get("frame") or s.frame
    _plugin_rate(params, s.rate, ros)
    g.add(s.el, "camera", s.name, params, implicit=not (ros or s.base_topic or g.harmonic))
    return True


def _depth_sensor(g: ReaderBase, s: _Sensor) -> bool:
    params = {**s.common, **_camera(g, s.r, s.el, s.context)}
    ros = read_sensor_plugins(g, s.plugins, s.context, ("image_raw", "image"), s.name, s.kind)
    info_topic = ros_topic(s.el.findtext("camera/camera_info_topic"))  # gz-sensors; no ROS plugin reads it
    if not ros and s.kind in ("depth", "depth_camera"):
        # Harmonic depth camera: depth image on <topic>, points on <topic>/points, CameraInfo beside
        topic = s.base_topic or "depth_camera"
        params.update(
            depth_topic=topic,
            points_topic=join_topic(topic, "points"),
            info_topic=sibling_topic(topic, "camera_info"),
            depth_info_topic=info_topic or sibling_topic(topic, "camera_info"),
            publish_color=False,
        )
    elif not ros:
        # Harmonic rgbd: <topic>/image, <topic>/depth_image, <topic>/points, <topic>/camera_info
        topic = s.base_topic or "rgbd_camera"
        params.update(
            image_topic=join_topic(topic, "image"),
            depth_topic=join_topic(topic, "depth_image"),
            points_topic=join_topic(topic, "points"),
            info_topic=info_topic or join_topic(topic, "camera_info"),
        )
    else:
        params.update(
            image_topic=ros["topic"],
            info_topic=ros["info"],
            depth_topic=ros["depth"],
            depth_info_topic=ros["depth_info"],
            points_topic=ros["points"],
        )
    params["frame_id"] = ros.get("frame") or s.frame
    _plugin_rate(params, s.rate, ros)
    g.add(s.el, "depth_camera", s.name, params)
    return True


def _imu_sensor(g: ReaderBase, s: _Sensor) -> bool:
    params = {**s.common, **_imu(g, s.r, s.el, s.context)}
    ros = read_sensor_plugins(g, s.plugins, s.context, ("out", "imu"), s.name, s.kind)
    params["topic"] = ros.get("topic") or s.base_topic or "imu"
    if g.harmonic and not (ros or s.base_topic):
        params["topic"] = _gz_sensor_topic(g, s.link, s.name, "imu")
    params["frame_id"] = ros.get("frame") or s.frame
    noise = ros.get("noise")
    if noise:
        # ROS 1 gazebo_ros_imu_sensor adds N(0, gaussianNoise) to every rate, acceleration and
        # quaternion component, on top of the sensor's own noise
        for key in ("angular_velocity_stddev", "linear_acceleration_stddev"):
            params[key] = math.hypot(params.get(key, 0.0), noise)
        params["orientation_stddev"] = 2.0 * noise  # a quaternion component of s is an angle of 2s
    _plugin_rate(params, s.rate, ros)
    g.add(s.el, "imu", s.name, params, implicit=not (ros or s.base_topic or g.harmonic))
    return True


def _contact_sensor(g: ReaderBase, s: _Sensor) -> bool:
    """A bumper: every contact of its link. False (said) outside a link's `<gazebo reference>` block."""
    if s.link is None:
        g.note(s.el, f"{s.context} outside a <gazebo reference=...> block has no link; ignored")
        return False
    s.r.child("contact")  # <collision> names: we report every contact of the link
    ros = read_sensor_plugins(g, s.plugins, s.context, ("bumper_states", "bumper"), s.name, s.kind)
    params = {**s.common, "topic": ros.get("topic") or s.base_topic or "bumper"}
    params["frame_id"] = ros.get("frame") or s.frame
    g.add(s.el, "contact", s.name, params)
    return True


# Each sensor type we read -> its reader (False: the sensor is left out, as said)
_KINDS: dict[str, Callable[[ReaderBase, _Sensor], bool]] = {
    **dict.fromkeys(("ray", "gpu_ray", "lidar", "gpu_lidar"), _lidar_sensor),
    "camera": _camera_sensor,
    **dict.fromkeys(("depth", "depth_camera", "rgbd_camera", "rgbd"), _depth_sensor),
    "imu": _imu_sensor,
    "contact": _contact_sensor,
}


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


def _gz_sensor_topic(g: ReaderBase, link: str | None, sensor: str, leaf: str) -> str:
    """gz-sensors' default topic of a sensor without `<topic>`: scoped by world, model, (lumped) link and
    sensor name (the world is "default", as in our other gz-sim defaults)."""
    gz_link = g.lumped_into.get(link or "", link or "base_link")
    return f"world/default/model/{g.model}/link/{gz_link}/sensor/{sensor}/{leaf}"


def _lidar(g: ReaderBase, r: TagReader, el: Any, context: str) -> dict[str, Any]:
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
        put_number(out, "range_min", rng, "min")
        put_number(out, "range_max", rng, "max")
        put_number(out, "resolution", rng, "resolution")
    noise = noise_stddev(g, ray, "a lidar")
    if noise:
        out["noise_stddev"] = noise
    known = {"scan", "range", "noise", "visibility_mask"}
    for child in ray:
        if isinstance(child.tag, str) and child.tag not in known:
            g.note(child, f"<{child.tag}> in {context} <{ray.tag}> is ignored")
    return out


def _camera(g: ReaderBase, r: TagReader, el: Any, context: str) -> dict[str, Any]:
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
        mapped = FORMATS.get(fmt.upper())
        if mapped:
            out["format"] = mapped
        else:
            g.note(cam, f"image format {fmt!r} is published as rgb8")
    near, far = cam.findtext("clip/near"), cam.findtext("clip/far")
    if near:
        out["near"] = float(near)
    if far:
        out["far"] = float(far)
    noise = noise_stddev(g, cam, "a camera")
    if noise:
        out["noise_stddev"] = noise
    known = {"horizontal_fov", "image", "clip", "noise", "camera_info_topic", "depth_camera"}
    for child in cam:
        if isinstance(child.tag, str) and child.tag not in known:
            g.note(child, f"<{child.tag}> in {context} <camera> is ignored")
    return out


def _imu(g: ReaderBase, r: TagReader, el: Any, context: str) -> dict[str, Any]:
    """SDF imu noise, per axis: white noise (its stddev; the largest of the axes, as our imu takes one),
    a constant <mean>, and a bias drawn once per run from N(bias_mean, bias_stddev) with a random sign."""
    imu = r.child("imu")
    out: dict[str, Any] = {}
    if imu is None:
        return out
    for key in ("angular_velocity", "linear_acceleration"):
        specs = [noise_spec(g, imu.find(f"{key}/{axis}")) for axis in ("x", "y", "z")]
        _imu_noise(out, key, specs)
    # classic (SDF 1.4) style: <imu><noise><type/><rate>..</rate><accel>..</accel></noise>, for all axes
    n = imu.find("noise")
    if n is not None:
        for block, key in (("rate", "angular_velocity"), ("accel", "linear_acceleration")):
            spec = classic_noise_spec(n, block)
            if spec is not None:
                _imu_noise(out, key, [spec] * 3)
    for child in imu:
        if isinstance(child.tag, str) and child.tag not in IMU_TAGS:
            g.note(child, f"<{child.tag}> in {context} <imu> is ignored")
    return out


def _imu_noise(out: dict[str, Any], key: str, specs: list[NoiseSpec | None]) -> None:
    if not any(specs):
        return
    s = [spec or NoiseSpec() for spec in specs]
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
