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

from runner.compile.gazebo import field_sensors, sensor_reasons, thirdparty
from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.noise import NoiseSpec, classic_noise_spec, noise_spec, noise_stddev
from runner.compile.gazebo.sensor_plugins import read_sensor_plugins
from runner.compile.gazebo.tables import FORMATS
from runner.compile.gazebo.tags import SdfReader, TagReader, floats, join_topic, ros_topic, sibling_topic
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
    r = SdfReader(el)
    context = f"<sensor name={name!r} type={kind!r}>"
    rate = r.float("update_rate", "updateRate")
    pose = floats(r.text("pose"), 6)
    pose_el = r.child("pose")
    relative_to = (pose_el.get("relative_to") or "").strip() if pose_el is not None else ""
    if relative_to and relative_to != link:
        g.note(
            pose_el,
            f"<pose relative_to={relative_to!r}> in {context} is taken relative to the sensor's link "
            f"{link!r} (SDF: relative to the frame {relative_to!r})",
        )
    base_topic = ros_topic(r.text("topic"))
    frame = g.frame(r.text("gz_frame_id", "ignition_frame_id", "frame_id", "frameName"))
    plugins = r.children("plugin")
    common: dict[str, Any] = {"link": link}
    if rate:
        common["rate"] = rate
    if pose and kind in _NO_POSE:  # our plugin takes none: said where it would change something
        if any(pose):
            g.note(r.child("pose"), f"<pose> in {context} is not applied: {_NO_POSE[kind]}")
    elif pose:
        common["pose"] = {"xyz": pose[:3], "rpy": pose[3:]}
    s = _Sensor(el, r, link, name, kind, context, rate, base_topic, frame, plugins, common)
    read = _KINDS.get(kind)
    if read is not None:
        if not read(g, s):
            return
    elif kind in thirdparty.SENSOR_KINDS:  # gps: runner/compile/gazebo/thirdparty.py
        thirdparty.sensor(g, r, el, common, plugins, name, kind, context, base_topic, frame)
    else:
        gazebo = sensor_reasons.UNSUPPORTED.get(kind)
        g.note(
            el,
            f"sensor type {kind!r} is not supported yet; {context} is ignored, with all it holds"
            + (f" ({gazebo})" if gazebo else ""),
            hint="supported: ray, gpu_ray, lidar, gpu_lidar, camera, depth, depth_camera, rgbd_camera, "
            "imu, contact, gps, magnetometer, air_pressure, altimeter, force_torque",
            kind=PLUGIN_UNSUPPORTED,
        )
        return
    g.ignored(r, context)


# Sensor types whose plugin here has no pose -> what the sensor's <pose> would change in Gazebo
_NO_POSE = {
    "contact": "the sensor reports every contact of its link, wherever it sits (in Gazebo too)",
    "gps": "the fix is the link origin's (Gazebo's is at the sensor's pose)",
    "navsat": "the fix is the link origin's (Gazebo's is at the sensor's pose)",
}


def _lidar_sensor(g: ReaderBase, s: _Sensor) -> bool:
    params = {**s.common, **_lidar(g, s.r, s.el, s.context)}
    ros = read_sensor_plugins(g, s.plugins, s.context, ("out", "scan"), s.name, s.kind)
    if ros.get("nothing"):  # its plugin publishes nothing, as said (gazebo_ros_range, ray_sensor)
        g.ignored(s.r, s.context)
        return False
    if "rate" not in (ros.get("params") or {}):
        _plugin_rate(params, s.rate, ros)  # gazebo_ros_range's <updateRate> throttles the sensor
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
    cam, info_topic = _camera(g, s.r, s.el, s.context)
    params = {**s.common, **cam}
    ros = read_sensor_plugins(g, s.plugins, s.context, ("image_raw", "image"), s.name, s.kind)
    # gz-sensors: <topic> carries the image, CameraInfo goes to <camera_info_topic> or a sibling
    image = ros.get("topic") or s.base_topic or "camera/image_raw"
    if g.harmonic and not (ros or s.base_topic):
        image = _gz_sensor_topic(g, s.link, s.name, "image")
    params["image_topic"] = image
    params["info_topic"] = (
        ros.get("info") or (info_topic if not ros else None) or sibling_topic(image, "camera_info")
    )
    params["frame_id"] = ros.get("frame") or s.frame
    _plugin_rate(params, s.rate, ros)
    g.add(s.el, "camera", s.name, params, implicit=not (ros or s.base_topic or g.harmonic))
    return True


def _depth_sensor(g: ReaderBase, s: _Sensor) -> bool:
    cam, info_topic = _camera(g, s.r, s.el, s.context)  # <camera_info_topic>: gz-sensors'; no ROS plugin's
    params = {**s.common, **cam}
    ros = read_sensor_plugins(g, s.plugins, s.context, ("image_raw", "image"), s.name, s.kind)
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
    params.update(ros.get("params") or {})  # the plugin's depth limits (sensor_plugins._depth_clip)
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
    block = s.r.child("contact")
    if block is not None:
        cr = SdfReader(block)
        # <collision> names the link's collision that senses (a URDF link's become <link>_collision,
        # <link>_collision_1, ...): we report every contact of the link, of any of its collisions
        cr.children("collision")
        gz_topic = (cr.text("topic") or "__default_topic__").strip()
        if gz_topic != "__default_topic__":
            g.note(
                cr.child("topic"),
                f"<contact><topic> {gz_topic!r} in {s.context} is a Gazebo transport topic: not used (the "
                "ROS topic is the plugin's, or the sensor's <topic>)",
            )
        g.ignored(cr, f"{s.context} <contact>")
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
    # runner/compile/gazebo/field_sensors.py
    "magnetometer": field_sensors.magnetometer,
    "air_pressure": field_sensors.air_pressure,
    "altimeter": field_sensors.altimeter,
    "force_torque": field_sensors.force_torque,
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
    where = f"{context} <{ray.tag}>"
    rr = SdfReader(ray)
    scan = rr.child("scan")
    if scan is not None:
        sr = SdfReader(scan)
        h = sr.child("horizontal")
        if h is not None:
            hr = SdfReader(h)
            samples = hr.float("samples")
            resolution = hr.float("resolution")
            n = int(samples) if samples is not None else 640
            if resolution and resolution not in (0.0, 1.0):
                n = max(1, round(n * resolution))  # Gazebo: beams = samples * resolution
            out["samples"] = n
            for tag in ("min_angle", "max_angle"):
                value = hr.float(tag)
                if value is not None:
                    out[tag] = value
            g.ignored(hr, f"{where} <horizontal>")
        v = sr.child("vertical")
        if v is not None:
            _vertical(g, SdfReader(v), out, where)
        g.ignored(sr, f"{where} <scan>")
    rng = rr.child("range")
    if rng is not None:
        nr = SdfReader(rng)
        for tag, key in (("min", "range_min"), ("max", "range_max"), ("resolution", "resolution")):
            value = nr.float(tag)
            if value is not None:
                out[key] = value
        g.ignored(nr, f"{where} <range>")
    noise = noise_stddev(g, rr, "a lidar", where)
    if noise:
        out["noise_stddev"] = noise
    _visibility(g, rr, where, sensor_reasons.LIDAR["visibility_mask"])
    g.ignored(rr, where, sensor_reasons.LIDAR)
    return out


def _vertical(g: ReaderBase, vr: TagReader, out: dict[str, Any], where: str) -> None:
    """`<scan><vertical>`: more than one sample makes a 3D lidar; one sample is the level scan plane."""
    samples = vr.float("samples")
    angles = {tag: vr.float(tag) for tag in ("min_angle", "max_angle")}
    resolution = vr.float("resolution")
    if samples and int(samples) > 1:
        out["vertical_samples"] = int(samples)
        for tag, value in angles.items():
            if value is not None:
                out[f"vertical_{tag}"] = value
        if resolution and resolution != 1.0:
            g.note(
                vr.child("resolution"),
                f"vertical <resolution> {resolution:g} in {where} is not applied: the lidar has <samples> "
                "rows (Gazebo has samples * resolution)",
            )
    elif any(angles.values()):
        g.note(
            vr.el,
            f"{where} has one vertical sample: its <min_angle>/<max_angle> are not applied, the scan is the "
            "sensor's level plane",
        )
    g.ignored(vr, f"{where} <vertical>")


def _camera(g: ReaderBase, r: TagReader, el: Any, context: str) -> tuple[dict[str, Any], str | None]:
    """The camera's params and its `<camera_info_topic>` (gz-sensors' CameraInfo topic; no ROS plugin
    reads it)."""
    cam = r.child("camera")
    out: dict[str, Any] = {}
    if cam is None:
        return out, None
    where = f"{context} <camera>"
    cr = SdfReader(cam)
    fov = cr.float("horizontal_fov")
    if fov is not None:
        out["fov"] = fov
    image = cr.child("image")
    if image is not None:
        ir = SdfReader(image)
        w, h = ir.float("width"), ir.float("height")
        if w is not None:
            out["width"] = int(w)
        if h is not None:
            out["height"] = int(h)
        fmt = (ir.text("format") or "").strip()
        if fmt:
            mapped = FORMATS.get(fmt.upper())
            if mapped:
                out["format"] = mapped
            else:
                g.note(cam, f"image format {fmt!r} is published as rgb8")
        g.ignored(ir, f"{where} <image>", sensor_reasons.IMAGE)
    clip = cr.child("clip")
    if clip is not None:
        clr = SdfReader(clip)
        for tag in ("near", "far"):
            value = clr.float(tag)
            if value is not None:
                out[tag] = value
        g.ignored(clr, f"{where} <clip>")
    noise = noise_stddev(g, cr, "a camera", where)
    if noise:
        out["noise_stddev"] = noise
    info_topic = ros_topic(cr.text("camera_info_topic"))
    if cr.bool("triggered"):
        g.note(
            cr.child("triggered"),
            f"<triggered> in {where} is ignored: the camera publishes at its rate (gz-sensors renders a "
            "frame per message on <trigger_topic>)",
        )
    cr.child("trigger_topic")  # read only when <triggered>, said above
    depth = cr.child("depth_camera")
    if depth is not None:
        dr = SdfReader(depth)
        output = (dr.text("output") or "depths").strip()
        if output != "depths":
            g.note(
                dr.child("output"),
                f"<depth_camera><output> {output!r} in {where} is not applied: depth cameras publish depths "
                "(and points as their plugin or gz-sensors does)",
            )
        g.ignored(dr, f"{where} <depth_camera>", sensor_reasons.DEPTH_CAMERA)
    _visibility(g, cr, where, sensor_reasons.CAMERA["visibility_mask"])
    g.ignored(cr, where, sensor_reasons.CAMERA)
    return out, info_topic


def _visibility(g: ReaderBase, r: TagReader, where: str, reason: str) -> None:
    """`<visibility_mask>`: every bit set (SDF's default) is what we do, every visual is seen; any other
    mask is said with `reason`."""
    text = r.text("visibility_mask")
    if text is None:
        return
    try:
        every = int(text, 0) & 0xFFFFFFFF == 0xFFFFFFFF
    except ValueError:
        every = False
    if not every:
        g.note(r.child("visibility_mask"), f"<visibility_mask> {text} in {where} is ignored ({reason})")


def _imu(g: ReaderBase, r: TagReader, el: Any, context: str) -> dict[str, Any]:
    """SDF imu noise, per axis: white noise (its stddev; the largest of the axes, as our imu takes one),
    a constant <mean>, and a bias drawn once per run from N(bias_mean, bias_stddev) with a random sign."""
    imu = r.child("imu")
    out: dict[str, Any] = {}
    if imu is None:
        return out
    where = f"{context} <imu>"
    ir = SdfReader(imu)
    for key in ("angular_velocity", "linear_acceleration"):
        block = ir.child(key)
        if block is None:
            continue
        br = SdfReader(block)
        specs = []
        for axis in ("x", "y", "z"):
            axis_el = br.child(axis)
            ar = SdfReader(axis_el) if axis_el is not None else None
            specs.append(noise_spec(g, ar, f"{where} <{key}><{axis}>"))
            if ar is not None:
                g.ignored(ar, f"{where} <{key}><{axis}>")
        _imu_noise(out, key, specs)
        g.ignored(br, f"{where} <{key}>")
    # classic (SDF 1.4) style: <imu><noise><type/><rate>..</rate><accel>..</accel></noise>, for all axes
    n = ir.child("noise")
    if n is not None:
        nr = SdfReader(n)
        for block_name, key in (("rate", "angular_velocity"), ("accel", "linear_acceleration")):
            spec = classic_noise_spec(g, nr, block_name, where)
            if spec is not None:
                _imu_noise(out, key, [spec] * 3)
        g.ignored(nr, f"{where} <noise>")
    frame = ir.child("orientation_reference_frame")
    if frame is not None:
        fr = SdfReader(frame)
        localization = (fr.text("localization") or "").strip()
        if localization.upper() not in ("", "ENU"):
            g.note(
                fr.child("localization"),
                f"<localization> {localization!r} in {where} is not applied: the orientation is in the world "
                "frame, ENU (REP 145), as gazebo_ros reports it (gz-sensors turns it into NED/NWU/CUSTOM)",
            )
        g.ignored(fr, f"{where} <orientation_reference_frame>", sensor_reasons.IMU_FRAME)
    if ir.bool("enable_orientation") is False:
        g.note(
            ir.child("enable_orientation"),
            f"<enable_orientation> false in {where} is not applied: the orientation is still reported "
            "(gz-sensors leaves it out)",
        )
    g.ignored(ir, where)
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
