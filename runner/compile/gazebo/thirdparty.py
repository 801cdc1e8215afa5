"""Third-party Gazebo plugins common in public ROS robots -> our plugins, as they publish in Gazebo.

- hector_gazebo_plugins' IMU, `libhector_gazebo_ros_imu.so` (a model plugin, ROS 1 and its ROS 2 port):
  sensor_msgs/Imu on `<topicName>` (default `imu`) and the current biases on `<biasTopicName>` (default
  `<topicName>/bias`), at `<updateRate>`; its error model (offset, drifting bias, white noise per axis for
  the accelerometer and the gyro; heading offset and drift; the orientation tilted by the accelerometer bias)
  -> `imu`;
- hector's GPS, `libhector_gazebo_ros_gps.so` (a model plugin): sensor_msgs/NavSatFix on `<topicName>`
  (`fix`) and geometry_msgs/Vector3Stamped on `<velocityTopicName>` (`fix_velocity`, north-west-up) at 4 Hz
  or `<updateRate>`, latitude and longitude on a flat earth around `<referenceLatitude>`... -> `gps`;
- Gazebo's own GPS sensor with gazebo_ros's `libgazebo_ros_gps_sensor.so` (ROS 2): NavSatFix on `~/out`
  and an east-north-up velocity on `~/vel` -> `gps`;
- velodyne_simulator, `libgazebo_ros_velodyne_laser.so` / `libgazebo_ros_velodyne_gpu_laser.so` (a sensor
  plugin in a `ray`/`gpu_ray` sensor, ROS 1 and ROS 2): only a PointCloud2 (x y z intensity ring time) on
  `<topicName>` (ROS 1, default `/points`) or `~/out` (ROS 2) -> `lidar` with `publish_scan: false` and
  the velodyne point layout;
- hector's sonar, `libhector_gazebo_ros_sonar.so` (a sensor plugin in a `ray` sensor): only a
  sensor_msgs/Range on `<topicName>` (`sonar`) at `<updateRate>` (10 Hz) -> `lidar` with a `range_topic`.

Handlers have the signatures of those in runner.compile.gazebo.model_plugins and .sensor_plugins: they
are given the reader as its base (runner.compile.gazebo.base), which those modules and the reader import.
"""

from __future__ import annotations

import math
from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.noise import NoiseSpec, noise_spec
from runner.compile.gazebo.tags import (
    SdfReader,
    TagReader,
    floats,
    is_zero,
    join_topic,
    plugin_base,
    ros_topic,
)
from runner.errors import NO_PUBLISHER, PLUGIN_UNSUPPORTED

# hector's defaults (hector_gazebo_plugins/src/gazebo_ros_gps.cpp, sensor_model.h)
_HECTOR_REFERENCE = {"latitude": 49.9, "longitude": 8.9, "heading": 0.0, "altitude": 0.0}
_HECTOR_DRIFT_FREQUENCY = 1.0 / 3600.0
_VELODYNE = {"gazebo_ros_velodyne_laser", "gazebo_ros_velodyne_gpu_laser"}
_VELODYNE_ROS1 = ("topicName", "frameName", "gaussianNoise")
_VELODYNE_ROS2 = ("frame_name", "gaussian_noise", "tf_prefix")

# sensor plugins (in a <sensor>) and sensor types handled here
SENSOR_PLUGINS = {*_VELODYNE, "hector_gazebo_ros_sonar"}
SENSOR_KINDS = {"gps", "navsat"}  # (SDF 1.10: navsat is the gps sensor's preferred name)


def _root_link(g: ReaderBase) -> str | None:
    """The URDF's root link: hector's plugins without `<bodyName>` use the model's first (canonical) link."""
    children = {j.find("child").get("link") for j in g.root.findall("joint") if j.find("child") is not None}
    for link in g.root.findall("link"):
        if link.get("name") not in children:
            return link.get("name")
    return None


def _vector(g: ReaderBase, r: TagReader, tag: str) -> list[float] | None:
    """A vector parameter of hector's (`"0.1 0.1 0.1"`); one number stands for all three axes."""
    text = r.text(tag)
    if text is None:
        return None
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) == 1:
        g.note(r.el.find(tag), f"<{tag}> has one number, taken for x, y and z (hector reads three)")
        return values * 3
    if len(values) != 3:
        g.note(r.el.find(tag), f"<{tag}> {text!r} is not three numbers; it is ignored")
        return None
    return values


def _rate(g: ReaderBase, r: TagReader) -> float | None:
    """hector's UpdateTimer: `<updateRate>` (Hz) or `<updatePeriod>` (s); 0 or neither: every world step."""
    rate = r.float("updateRate")
    period = r.float("updatePeriod")
    if period and period > 0:
        rate = 1.0 / period
    offset = r.child("updateOffset")
    if offset is not None and not is_zero(offset.text):
        g.note(offset, "<updateOffset> is ignored: readings are taken at multiples of the period")
    return rate if rate and rate > 0 else None


def _hector_model(
    g: ReaderBase, r: TagReader, prefix: str, what: str, unit: str, per_axis: bool
) -> tuple[list[float], list[float], list[float], list[float]]:
    """hector's SensorModel parameters `<prefix>Offset`, `Drift`, `DriftFrequency`, `GaussianNoise` (or
    without a prefix: `offset`, `drift`...): offset, drift, drift frequency, white noise, per axis. A
    `ScaleError` other than 1 is reported (readings are not scaled), and so are axes that differ where our
    plugin takes one number for the three (`per_axis` false: the largest is used)."""

    def tag(name: str) -> str:
        return prefix + name if prefix else name[0].lower() + name[1:]

    zero = [0.0, 0.0, 0.0]
    offset = _vector(g, r, tag("Offset")) or zero
    drift = _vector(g, r, tag("Drift")) or zero
    frequency = _vector(g, r, tag("DriftFrequency")) or [_HECTOR_DRIFT_FREQUENCY] * 3
    noise = _vector(g, r, tag("GaussianNoise")) or zero
    scale = _vector(g, r, tag("ScaleError"))
    if scale is not None and any(s != 1.0 for s in scale):
        g.note(r.el.find(tag("ScaleError")), f"<{tag('ScaleError')}> is not applied: {what} are not scaled")
    for name, values in (("Drift", drift), ("GaussianNoise", noise), ("DriftFrequency", frequency)):
        if len(set(values)) > 1 and not per_axis:
            g.note(
                r.el.find(tag(name)),
                f"<{tag(name)}> differs between axes; the {what} take the largest, {max(values)} {unit}",
            )
    return offset, drift, frequency, noise


def hector_imu(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]] | None:
    """hector_gazebo_plugins' IMU (`libhector_gazebo_ros_imu.so`). Its parameters -> `imu`:

    | hector | ours |
    |---|---|
    | bodyName (default: the model's first link) | link |
    | topicName (default `imu`) | topic |
    | biasTopicName (default `<topicName>/bias`) | bias_topic |
    | frameId (default: the link's name) | frame_id |
    | updateRate / updatePeriod (default: every physics step) | rate |
    | accelOffset, rateOffset | linear_acceleration_bias, angular_velocity_bias |
    | accelDrift, rateDrift | *_bias_stddev (the drift starts at N(0, drift)) |
    | accelDriftFrequency, rateDriftFrequency (1/3600 Hz) | *_bias_drift_frequency |
    | accelGaussianNoise, rateGaussianNoise, gaussianNoise | *_stddev |
    | yawOffset, yawDrift, yawDriftFrequency | yaw_bias, yaw_bias_stddev, yaw_bias_drift_frequency |
    | (always) | orientation_tilt_from_bias: true |
    """
    filename = r.el.get("filename")
    topic_text = r.text("topicName")
    if topic_text is not None and not topic_text.strip():
        said = f"{filename!r} has an empty <topicName>: it publishes nothing (as in Gazebo)"
        g.note(r.el, said, kind=NO_PUBLISHER)
        r.mark(*[c.tag for c in r.el if isinstance(c.tag, str)])
        return None
    topic = ros_topic(topic_text) or "imu"
    topic = remap.get(topic) or topic  # the ROS 2 port's node remaps its topics
    bias_text = r.text("biasTopicName")
    bias_topic = (ros_topic(bias_text) if bias_text is not None else f"{topic}/bias") or None
    link = r.text("bodyName") or _root_link(g)
    params: dict[str, Any] = {
        "link": link,
        "topic": topic,
        "bias_topic": remap.get(bias_topic, bias_topic) if bias_topic else None,
        "frame_id": g.frame(r.text("frameId")),
        "rate": _rate(g, r),
        "orientation_tilt_from_bias": True,
    }
    if params["rate"] is None:
        g.note(
            r.el,
            f"{filename!r} has no <updateRate> (or 0): Gazebo publishes it at every physics step; here at "
            "the imu plugin's 100 Hz",
            hint="add <updateRate> (or set `rate` in the scenario's plugin params)",
        )
    _hector_imu_errors(g, r, params)
    _hector_imu_yaw(g, r, params)
    _hector_imu_unused(g, r, filename)
    return "imu", params


def _hector_imu_errors(g: ReaderBase, r: TagReader, params: dict[str, Any]) -> None:
    """The accelerometer's and the gyro's error models (offset, drifting bias, white noise) -> `params`."""
    legacy = r.float("gaussianNoise")
    for prefix, key, what, unit in (
        ("accel", "linear_acceleration", "accelerations", "m/s²"),
        ("rate", "angular_velocity", "rates", "rad/s"),
    ):
        offset, drift, frequency, noise = _hector_model(g, r, prefix, what, unit, per_axis=False)
        if legacy:  # the older gazebo_ros_imu parameter, for both
            noise = [legacy] * 3
        if any(offset):
            params[f"{key}_bias"] = offset
        noise, drift = [abs(v) for v in noise], [abs(v) for v in drift]  # scales of N(0, .)
        if max(noise):
            params[f"{key}_stddev"] = max(noise)
        if max(drift):
            params[f"{key}_bias_stddev"] = max(drift)
            params[f"{key}_bias_drift_frequency"] = max(frequency)


def _hector_imu_yaw(g: ReaderBase, r: TagReader, params: dict[str, Any]) -> None:
    """The heading's offset and drift -> `params`; its white noise only fills a covariance (said)."""
    # `heading*`: the same parameters in hector's releases before 0.3.6
    yaw_offset = r.float("yawOffset", "headingOffset") or 0.0
    yaw_drift = r.float("yawDrift", "headingDrift") or 0.0
    yaw_frequency = r.float("yawDriftFrequency", "headingDriftFrequency")
    if yaw_offset:
        params["yaw_bias"] = yaw_offset
    if yaw_drift:
        params["yaw_bias_stddev"] = abs(yaw_drift)
        params["yaw_bias_drift_frequency"] = (
            yaw_frequency if yaw_frequency is not None else _HECTOR_DRIFT_FREQUENCY
        )
    yaw_noise = r.child("yawGaussianNoise", "headingGaussianNoise")
    if yaw_noise is not None and not is_zero(yaw_noise.text):
        g.note(
            yaw_noise,
            f"<{yaw_noise.tag}> only fills hector's orientation covariance, which is not reproduced here "
            "(the orientation itself is the same)",
        )
    r.mark("yawScaleError", "headingScaleError")  # read by hector, used for nothing


def _hector_imu_unused(g: ReaderBase, r: TagReader, filename: str | None) -> None:
    """hector's IMU parameters that change nothing here: the mounting offsets and the random seed."""
    rpy = r.child("rpyOffset")
    if rpy is not None and any(floats(rpy.text, 3) or [1.0]):
        g.note(rpy, f"<rpyOffset> in {filename!r} is not applied (the IMU is mounted as its link)")
    xyz = r.child("xyzOffset")
    if xyz is not None and any(floats(xyz.text, 3) or [1.0]):
        g.note(xyz, f"<xyzOffset> is read and not applied by {filename!r}: Gazebo ignores it too")
    seed = r.child("randomEngineSeed")
    if seed is not None:
        g.note(seed, "<randomEngineSeed> is ignored: noise is drawn from the scenario's `seed`")


def hector_gps(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    """hector_gazebo_plugins' GPS (`libhector_gazebo_ros_gps.so`). Its parameters -> `gps`:

    | hector | ours |
    |---|---|
    | bodyName (default: the model's first link) | link |
    | topicName (`fix`), velocityTopicName (`fix_velocity`) | topic, velocity_topic |
    | frameId (`/world`) | frame_id (`world`) |
    | updateRate / updatePeriod (4 Hz) | rate |
    | referenceLatitude, referenceLongitude (49.9, 8.9 deg) | reference_latitude, reference_longitude |
    | referenceHeading (0 deg), referenceAltitude (0 m) | reference_heading, reference_altitude |
    | status (0), service (0) | status, service |
    | offset, drift, driftFrequency, gaussianNoise (m) | position_offset, position_drift, ... |
    | velocityOffset, velocityDrift, ... (m/s) | velocity_offset, velocity_drift, ... |
    | (velocity north, west, up) | velocity_axes: NWU |
    """
    topic = ros_topic(r.text("topicName")) or "fix"
    velocity = ros_topic(r.text("velocityTopicName")) or "fix_velocity"
    frame = r.text("frameId")
    params: dict[str, Any] = {
        "link": r.text("bodyName") or _root_link(g),
        "topic": remap.get(topic) or topic,
        "velocity_topic": remap.get(velocity) or velocity,
        "frame_id": g.frame(frame) if frame and frame.strip("/") != "world" else "world",
        "rate": _rate(g, r) or 4.0,
        "velocity_axes": "NWU",
        "service": 0,
    }
    for key, tag in (
        ("latitude", "referenceLatitude"),
        ("longitude", "referenceLongitude"),
        ("heading", "referenceHeading"),
        ("altitude", "referenceAltitude"),
    ):
        value = r.float(tag)
        params[f"reference_{key}"] = value if value is not None else _HECTOR_REFERENCE[key]
    use_world = r.child("useWorldSphericalCoordinates")
    if use_world is not None and r.bool("useWorldSphericalCoordinates"):
        g.note(
            use_world,
            "<useWorldSphericalCoordinates> is not applied: the world's <spherical_coordinates> are not "
            "read; the plugin's reference point is used",
            hint="give <referenceLatitude>, <referenceLongitude>, <referenceHeading> and <referenceAltitude>",
        )
    for key in ("status", "service"):
        value = r.float(key)
        if value is not None:
            params[key] = int(value)
    for prefix, key, what, unit in (
        ("", "position", "positions", "m"),
        ("velocity", "velocity", "velocities", "m/s"),
    ):
        offset, drift, frequency, noise = _hector_model(g, r, prefix, what, unit, per_axis=True)
        if any(offset):
            params[f"{key}_offset"] = offset
        if any(drift):
            params[f"{key}_drift"] = [abs(d) for d in drift]
            params[f"{key}_drift_frequency"] = frequency
        if any(noise):
            params[f"{key}_noise_stddev"] = [abs(n) for n in noise]
    return "gps", params


def hector_magnetic(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    """hector_gazebo_plugins' magnetometer (`libhector_gazebo_ros_magnetic.so`, gazebo_ros_magnetic.cpp).
    Its parameters -> `magnetometer`:

    | hector | ours |
    |---|---|
    | bodyName (default: the model's first link) | link |
    | topicName (`magnetic`) | topic |
    | frameId (default: the link's name) | frame_id |
    | updateRate / updatePeriod (default: every physics step) | rate |
    | magnitude (1), referenceHeading (0 deg), declination (0 deg), inclination (60 deg) | field (:121-130) |
    | useMagneticFieldMsgs (false: geometry_msgs/Vector3Stamped) | message |
    | offset, drift, driftFrequency, gaussianNoise | noise_mean, drift, drift_frequency, noise_stddev |

    Each of the error parameters is per axis. The field is in Gazebo's world frame, a compass heading
    turning it about z."""
    filename = r.el.get("filename")
    topic = ros_topic(r.text("topicName")) or "magnetic"
    link = r.text("bodyName") or _root_link(g)
    frame = r.text("frameId")

    def deg(tag: str, default: float) -> float:
        value = r.float(tag)
        return math.radians(default if value is None else value)

    magnitude = r.float("magnitude")
    magnitude = 1.0 if magnitude is None else magnitude
    heading, declination, inclination = (
        deg("referenceHeading", 0.0),
        deg("declination", 0.0),
        deg("inclination", 60.0),
    )
    field = [
        magnitude * math.cos(inclination) * math.cos(heading - declination),
        magnitude * math.cos(inclination) * math.sin(heading - declination),
        -magnitude * math.sin(inclination),
    ]
    params: dict[str, Any] = {
        "link": link,
        "topic": remap.get(topic) or topic,
        "frame_id": g.frame(frame or link),
        "rate": _rate(g, r),
        "field": field,
        "message": "sensor_msgs/msg/MagneticField"
        if r.bool("useMagneticFieldMsgs")
        else "geometry_msgs/msg/Vector3Stamped",
    }
    if params["rate"] is None:
        g.note(
            r.el,
            f"{filename!r} has no <updateRate> (or 0): Gazebo publishes it at every physics step; here at "
            "the magnetometer plugin's 50 Hz",
            hint="add <updateRate> (or set `rate` in the scenario's plugin params)",
        )
    offset, drift, frequency, noise = _hector_model(g, r, "", "fields", "", per_axis=True)
    if any(offset):
        params["noise_mean"] = offset
    if any(drift):
        params["drift"] = [abs(v) for v in drift]
        params["drift_frequency"] = frequency
    if any(noise):
        params["noise_stddev"] = [abs(v) for v in noise]
    return "magnetometer", params


MODEL_PLUGINS = {
    "hector_gazebo_ros_imu": hector_imu,
    "hector_gazebo_ros_gps": hector_gps,
    "hector_gazebo_ros_magnetic": hector_magnetic,
}


# ------------------------------------------------------------------------------------------ sensor plugins
def sensor_plugin(
    g: ReaderBase,
    r: TagReader,
    base: str,
    remap: dict[str, str],
    sensor: str,
    kind: str,
    context: str,
) -> tuple[dict[str, Any], tuple[str, ...]]:
    """A plugin of `SENSOR_PLUGINS` inside a sensor: what `sensor_plugins.read_sensor_plugins` finds (`topic`,
    `frame`, `noise`, and `params` for the sensor's plugin), and the rate tags the plugin reads."""
    if base in _VELODYNE:
        return _velodyne(g, r, remap, kind, context), ()
    return _hector_sonar(g, r, remap), ("updateRate",)


def _hector_sonar(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> dict[str, Any]:
    """hector_gazebo_plugins' sonar (`libhector_gazebo_ros_sonar.so`, in a `ray` sensor): only a
    sensor_msgs/Range, the nearest of the sensor's rays, with hector's error model:

    | hector | ours (lidar) |
    |---|---|
    | topicName (default `sonar`) | range_topic (no LaserScan) |
    | frameId (default `/sonar_link`) | frame_id |
    | updateRate / updatePeriod (default 10 Hz) | rate |
    | offset, drift, driftFrequency, gaussianNoise (m) | range_offset, range_drift, ... |
    | (ULTRASOUND; min of the sensor's angular spans) | radiation_type, range_field_of_view |
    """
    topic = ros_topic(r.text("topicName")) or "sonar"
    topic = remap.get(topic) or topic
    frame = r.text("frameId") or "sonar_link"
    params: dict[str, Any] = {
        "publish_scan": False,
        "publish_points": False,
        "range_topic": topic,
        "radiation_type": "ultrasound",
        "rate": _rate(g, r) or 10.0,
    }
    spans = []
    for axis in ("horizontal", "vertical"):
        lo = _number(r.el.getparent(), (f"ray/scan/{axis}/min_angle",)) or 0.0
        hi = _number(r.el.getparent(), (f"ray/scan/{axis}/max_angle",)) or 0.0
        spans.append(abs(hi - lo))
    params["range_field_of_view"] = min(spans)
    for key, tag in (
        ("range_offset", "offset"),
        ("range_drift", "drift"),
        ("range_drift_frequency", "driftFrequency"),
        ("range_noise_stddev", "gaussianNoise"),
    ):
        value = r.float(tag)
        if value is not None and (value or key == "range_drift_frequency"):
            params[key] = abs(value) if key != "range_offset" else value
    scale = r.child("scaleError")
    if scale is not None and r.float("scaleError") not in (None, 1.0):
        g.note(scale, "<scaleError> is not applied: ranges are not scaled")
    return {"topic": topic, "frame": g.frame(frame), "params": params}


def _velodyne(g: ReaderBase, r: TagReader, remap: dict[str, str], kind: str, context: str) -> dict[str, Any]:
    """velodyne_simulator's plugin (Dataspeed; 1.0.10+ point layout). It publishes only a PointCloud2:

    | velodyne_simulator | ours (lidar) |
    |---|---|
    | ROS 1 `<topicName>` (default `/points`); ROS 2 `~/out` (`<plugin name>/out`, remapped) | points_topic |
    | ROS 1 `<frameName>` (default `/world`); ROS 2 `<frame_name>` (default: the link) | frame_id |
    | `<min_range>`, `<max_range>` (with the sensor's `<range>`: the narrower) | range_min, range_max |
    | ROS 1 `<gaussianNoise>`, ROS 2 `<gaussian_noise>` (added to the sensor's `<noise>`) | noise_stddev |
    | `<organize_cloud>` (false) | organize_cloud |
    | (no LaserScan; x y z intensity ring time) | publish_scan: false, points_format: velodyne |

    The ROS 2 plugin is told by `<ros>`, `<frame_name>`, `<gaussian_noise>` or `<tf_prefix>`, or by the
    absence of the ROS 1 tags; each reads only its own spellings (the other's are reported)."""
    p = r.el
    filename = p.get("filename")
    ros2 = any(p.find(t) is not None for t in ("ros", *_VELODYNE_ROS2)) or not any(
        p.find(t) is not None for t in (*_VELODYNE_ROS1, "robotNamespace")
    )
    found: dict[str, Any] = {}
    if ros2:
        name = ros_topic(p.get("name")) or "gazebo_ros_velodyne_laser"
        topic = remap.get("out") or join_topic(name, "out")
        frame = r.text("frame_name")
        found["frame"] = g.frame(frame) if frame else None
        noise = r.float("gaussian_noise")
        prefix = r.child("tf_prefix")
        if prefix is not None and (prefix.text or "").strip():
            g.note(prefix, "<tf_prefix> is ignored: frames are under the robot's namespace")
        own, other = _VELODYNE_ROS2, _VELODYNE_ROS1
    else:
        topic = ros_topic(r.text("topicName")) or "points"
        frame = r.text("frameName")
        # tf::resolve leaves the default `/world` (absolute) alone
        found["frame"] = g.frame(frame) if frame and frame.strip("/") != "world" else "world"
        noise = r.float("gaussianNoise")
        own, other = _VELODYNE_ROS1, _VELODYNE_ROS2
    for tag in other:
        el = p.find(tag)
        if el is not None and tag not in own:
            r.mark(tag)
            g.note(
                el,
                f"<{tag}> is a ROS {'1' if ros2 else '2'} parameter; the ROS {'2' if ros2 else '1'} "
                f"{filename!r} does not read it (Gazebo ignores it too)",
            )
    found["topic"] = topic
    found["noise"] = noise or None
    params: dict[str, Any] = {
        "publish_scan": False,
        "publish_points": True,
        "points_topic": topic,
        "points_format": "velodyne",
        "organize_cloud": bool(r.bool("organize_cloud")),
    }
    sensor_el = p.getparent()
    lo = r.float("min_range")
    hi = r.float("max_range")
    sensor_lo = _number(sensor_el, ("ray/range/min", "lidar/range/min"))
    sensor_hi = _number(sensor_el, ("ray/range/max", "lidar/range/max"))
    if lo is not None and lo > (sensor_lo or 0.0):
        params["range_min"] = lo
    if hi is not None and math.isfinite(hi) and (sensor_hi is None or hi < sensor_hi):
        params["range_max"] = hi
    intensity = r.child("min_intensity")
    if intensity is not None and (r.float("min_intensity") or 0.0) > 0.0:
        g.note(
            intensity,
            "<min_intensity> is not applied: every return has intensity 0 here (no <laser_retro>), which "
            "it would all drop",
        )
    found["params"] = params
    return found


def _number(el: Any, paths: tuple[str, ...]) -> float | None:
    for path in paths:
        text = el.findtext(path) if el is not None else None
        if text and text.strip():
            return float(text)
    return None


# ------------------------------------------------------------------------------------------ sensors
def sensor(
    g: ReaderBase,
    r: TagReader,
    el: Any,
    common: dict[str, Any],
    plugins: list[Any],
    name: str,
    kind: str,
    context: str,
    base_topic: str | None,
    frame: str | None,
) -> None:
    """A `<sensor>` of `SENSOR_KINDS`: Gazebo's GPS sensor (with `libgazebo_ros_gps_sensor.so`) -> `gps`:

    | Gazebo / gazebo_ros | ours |
    |---|---|
    | `~/out` (`<plugin name>/out`, remapped) | topic |
    | `~/vel` (`<plugin name>/vel`, east-north-up) | velocity_topic, velocity_axes: ENU |
    | `<frame_name>` (default: the link) | frame_id |
    | `<update_rate>` | rate |
    | `<position_sensing><horizontal>`/`<vertical>` `<noise><stddev>` | position_noise_stddev (x y, z) |
    | `<velocity_sensing>` likewise | velocity_noise_stddev |
    | the world's spherical coordinates (Gazebo's default: 0 deg, 0 deg, 0 m; ENU) | reference_* |
    | status FIX, service GPS | status 0, service 1 |
    """
    params: dict[str, Any] = {**common, "reference_heading": 90.0, "velocity_axes": "ENU"}
    # `<navsat>`: the same block under the name sdformat prefers (sdf/1.10/navsat.sdf; gz-sensors' NavSat)
    gps = r.child("gps", "navsat")
    if gps is not None:
        gr = SdfReader(gps)
        for block, key in (("position_sensing", "position"), ("velocity_sensing", "velocity")):
            h, v = _gps_axes(g, gr, block, context)
            sd = [h.stddev if h else 0.0] * 2 + [v.stddev if v else 0.0]
            if any(sd):
                params[f"{key}_noise_stddev"] = sd
            offset = [h.mean if h else 0.0] * 2 + [v.mean if v else 0.0]
            if any(offset):
                params[f"{key}_offset"] = offset
            for spec in (h, v):
                if spec is not None and (spec.bias_mean or spec.bias_stddev):
                    g.note(spec.el, "a GPS noise bias (<bias_mean>, <bias_stddev>) is not modelled")
        g.ignored(gr, f"{context} <{gps.tag}>")
    found = False
    topic, velocity = base_topic or "fix", None
    for p in plugins:
        filename = p.get("filename", "")
        if plugin_base(filename) != "gazebo_ros_gps_sensor":
            g.note(
                p,
                f"plugin {filename!r} in {context} is not supported and is ignored",
                hint="GPS sensor plugins we read: libgazebo_ros_gps_sensor.so",
                kind=PLUGIN_UNSUPPORTED,
            )
            continue
        found = True
        pr = TagReader(p)
        remap = g.ros_block(pr)["remap"]
        plugin = ros_topic(p.get("name")) or "gazebo_ros_gps_sensor"
        topic = remap.get("out") or f"{plugin}/out"
        velocity = remap.get("vel") or f"{plugin}/vel"
        frame_name = pr.text("frame_name")
        if frame_name:
            frame = g.frame(frame_name)
        pr.mark("alwaysOn", "always_on", "robotNamespace")
        g.ignored(pr, f"<plugin filename={filename!r}>")
    if not found:
        # no ROS plugin: the sensor's own topic (gz-sensors' NavSat: the fix, its velocity in the same
        # message), not gazebo_ros_gps_sensor's `~/vel` ("" is none; a None would be the plugin's default)
        velocity = ""
    params.update(topic=topic, velocity_topic=velocity, frame_id=frame)
    g.add(el, "gps", name, params, implicit=not (found or base_topic))


def _gps_axes(g: ReaderBase, gps: TagReader, block: str, context: str) -> list[NoiseSpec | None]:
    """The `<noise>` of `<gps><block>`'s `<horizontal>` and `<vertical>` (None where there is none)."""
    el = gps.child(block)
    if el is None:
        return [None, None]
    br = SdfReader(el)
    out = []
    for axis in ("horizontal", "vertical"):
        axis_el = br.child(axis)
        ar = SdfReader(axis_el) if axis_el is not None else None
        where = f"{context} <gps><{block}><{axis}>"
        out.append(noise_spec(g, ar, where))
        if ar is not None:
            g.ignored(ar, where)
    g.ignored(br, f"{context} <gps><{block}>")
    return out
