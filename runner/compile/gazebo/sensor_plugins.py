"""The ROS plugin inside a `<sensor>` (gazebo_ros's laser, imu, bumper and camera plugins, classic ROS 1
and ROS 2; the third-party ones in runner.compile.gazebo.thirdparty): where the sensor publishes (each
plugin's topic and frame spellings, `<ros><remapping>`), the plugin's own rate and noise, and what of its
parameters Gazebo would not read either."""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo import thirdparty
from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.tables import (
    CAMERA_KNOWN,
    CAMERA_PLUGINS,
    DISTORTION,
    HARMLESS,
    IGNORED_REASONS,
    ROS1_CAMERA_EVIDENCE,
    ROS1_CAMERA_PARAMS,
    ROS2_CAMERA_DECISIVE,
    ROS2_CAMERA_PARAMS,
    ROS_SENSOR_PLUGINS,
)
from runner.compile.gazebo.tags import TagReader, floats, is_zero, join_topic, plugin_base, ros_topic
from runner.errors import PLUGIN_UNSUPPORTED

_SENSOR_PLUGINS = ROS_SENSOR_PLUGINS | thirdparty.SENSOR_PLUGINS  # velodyne_simulator, hector's sonar


def read_sensor_plugins(
    g: ReaderBase, plugins: list[Any], context: str, out_names: tuple[str, ...], sensor: str, kind: str
) -> dict[str, Any]:
    """The ROS plugin inside a sensor: where it publishes (classic and ROS 2 spellings), its own rate."""
    found: dict[str, Any] = {}
    for p in plugins:
        filename = p.get("filename", "")
        base = plugin_base(filename)
        r = TagReader(p)
        if base not in _SENSOR_PLUGINS:
            g.note(
                p,
                f"plugin {filename!r} in {context} is not supported and is ignored",
                hint="sensor plugins we read: " + ", ".join(sorted(_SENSOR_PLUGINS)),
                kind=PLUGIN_UNSUPPORTED,
            )
            continue
        ros = g.ros_block(r)
        remap = ros["remap"]
        rates: tuple[str, ...] = ()
        if base in CAMERA_PLUGINS:
            found.update(_camera_plugin(g, r, filename, base, remap, sensor, kind, context))
            rates = () if found["ros2"] else ("updateRate",)
        elif base in thirdparty.SENSOR_PLUGINS:
            extra, rates = thirdparty.sensor_plugin(g, r, base, remap, sensor, kind, context)
            found.update(extra)
        else:
            rates = _ros_sensor_plugin(g, r, base, remap, out_names, context, found)
        _plugin_rates(g, r, rates, filename, found)
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
        g.ignored(r, f"<plugin filename={filename!r}>")
    found.pop("ros2", None)
    return {k: v for k, v in found.items() if v is not None}


def _ros_sensor_plugin(
    g: ReaderBase,
    r: TagReader,
    base: str,
    remap: dict[str, str],
    out_names: tuple[str, ...],
    context: str,
    found: dict[str, Any],
) -> tuple[str, ...]:
    """gazebo_ros's laser, imu and bumper plugins -> `found` (frame, topic, noise); returns the tags of
    the plugin's own rate (ROS 1 imu: `<updateRateHZ>`)."""
    p = r.el
    rates: tuple[str, ...] = ()
    frame = r.text("frameName", "frame_name")
    if frame:
        found["frame"] = g.frame(frame)
    topic = ros_topic(r.text("topicName", "topic_name", "bumperTopicName"))
    for out in out_names:
        if out in remap:
            topic = topic or remap[out]
    if topic:
        found["topic"] = topic
    ros2 = any(p.find(t) is not None for t in ("ros", "frame_name", "initial_orientation_as_reference"))
    if base == "gazebo_ros_imu_sensor" and not ros2:
        # ROS 1: <updateRateHZ> throttles, <gaussianNoise> adds to the sensor's noise
        rates = ("updateRateHZ",)
        found["noise"] = r.float("gaussianNoise")
        offset = r.text("rpyOffset")
        if offset is not None and (floats(offset, 3) is None or any(floats(offset, 3) or [])):
            g.note(p.find("rpyOffset"), f"<rpyOffset> in {context} is ignored")
        r.mark("xyzOffset")  # read and unused by the plugin itself
    elif base == "gazebo_ros_block_laser":
        found["noise"] = r.float("gaussianNoise")
    if base == "gazebo_ros_imu_sensor" and r.bool("initial_orientation_as_reference"):
        g.note(
            p.find("initial_orientation_as_reference"),
            "<initial_orientation_as_reference> true is ignored: the orientation is reported "
            "in the world frame (REP 145), as with false",
        )
    out_type = r.text("output_type")
    if out_type and out_type.split("/")[-1] != "LaserScan":
        g.note(p.find("output_type"), f"<output_type> {out_type} is published as a LaserScan")
    return rates


def _plugin_rates(
    g: ReaderBase, r: TagReader, rates: tuple[str, ...], filename: str, found: dict[str, Any]
) -> None:
    """The plugin's own rate (from the tags in `rates`) -> `found`; a rate tag it does not read is said."""
    p = r.el
    for tag in rates:
        value = r.float(tag)
        if value and value > 0:
            found["rate"] = value
    for tag in ("updateRate", "update_rate", "updateRateHZ"):
        el = p.find(tag)
        if el is None or tag in rates:
            continue
        r.mark(tag)
        if not is_zero(el.text):
            g.note(
                el,
                f"<{tag}> is not read by {filename!r}"
                + (" (ROS 2)" if found.get("ros2") else "")
                + ": Gazebo ignores it too; the sensor's <update_rate> sets the rate",
            )


def _camera_plugin(
    g: ReaderBase,
    r: TagReader,
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
    `<updateRate>` throttles the sensor (see `sensors._plugin_rate`).

    The same file name is both: a `<ros>` block, `<camera_name>` or `<frame_name>` is ROS 2; otherwise
    ROS 1 naming tags or `<updateRate>` are ROS 1; a plugin with neither is taken as ROS 2."""
    p = r.el
    ros2 = base in ("gazebo_ros_camera", "gazebo_ros_multicamera") and (
        any(p.find(t) is not None for t in ROS2_CAMERA_DECISIVE)
        or not any(p.find(t) is not None for t in ROS1_CAMERA_EVIDENCE)
    )
    depth = kind != "camera"
    out: dict[str, Any] = {"ros2": ros2}
    frame = r.text("frame_name" if ros2 else "frameName")
    if frame:
        out["frame"] = g.frame(frame)
    for t in DISTORTION:  # ROS 1 and early ROS 2 spellings: the images are ideal either way
        el = p.find(t)
        if el is not None:
            r.mark(t)
            if not is_zero(el.text):
                g.note(el, f"<{t}> in {context} is ignored (images are not distorted)")
    if ros2:
        out.update(_ros2_camera_topics(g, r, remap, sensor, depth))
        own, other = ROS2_CAMERA_PARAMS, ROS1_CAMERA_PARAMS
    else:
        out.update(_ros1_camera_topics(r))
        own, other = ROS1_CAMERA_PARAMS, ROS2_CAMERA_PARAMS
    r.mark(*(t for t in own if p.find(t) is not None))
    if ros2 and r.bool("triggered"):
        g.note(p.find("triggered"), "<triggered> is ignored: the camera publishes at its rate")
    _camera_params_unread(g, r, filename, ros2, own, other, depth)
    return out


def _ros2_camera_topics(
    g: ReaderBase, r: TagReader, remap: dict[str, str], sensor: str, depth: bool
) -> dict[str, Any]:
    """The ROS 2 camera's topics under `<camera_name>` (default: the sensor's name), remapped; a remapping
    that matches none of them is said (ROS 2 applies it to none either)."""
    p = r.el
    out: dict[str, Any] = {}
    cam = ros_topic(r.text("camera_name")) if p.find("camera_name") is not None else ros_topic(sensor)
    names = {
        "topic": join_topic(cam, "image_raw"),
        "info": join_topic(cam, "camera_info"),
        "depth": join_topic(cam, "depth/image_raw"),
        "depth_info": join_topic(cam, "depth/camera_info"),
        "points": join_topic(cam, "points"),
    }
    mine = set(names.values()) if depth else {names["topic"], names["info"]}
    for key, topic in names.items():
        out[key] = remap.get(topic) or topic
    for src, dst in remap.items():
        if src not in mine and not src.startswith("__") and src != join_topic(cam, "image_trigger"):
            g.note(
                p.find("ros"),
                f"remapping {src}:={dst} matches none of this camera's topics ("
                + ", ".join(sorted(mine))
                + "): ROS 2 applies it to none either",
                hint=f"name the whole topic, as {names['topic']}:=...",
            )
    return out


def _ros1_camera_topics(r: TagReader) -> dict[str, Any]:
    """The ROS 1 camera's topics: each `*TopicName` under `<cameraName>` (default: none) unless absolute."""
    raw_cam = r.text("cameraName")
    cam = ros_topic(raw_cam) if raw_cam else None

    def name(tag: str, default: str) -> str:
        text = r.text(tag)
        if text and text.startswith("/"):  # absolute: not under <cameraName>
            return ros_topic(text) or default
        return join_topic(cam, ros_topic(text) or default)

    return {
        "topic": name("imageTopicName", "image_raw"),
        "info": name("cameraInfoTopicName", "camera_info"),
        "depth": name("depthImageTopicName", "depth/image_raw"),
        "depth_info": name("depthImageCameraInfoTopicName", "depth/camera_info"),
        "points": name("pointCloudTopicName", "points"),
    }


def _camera_params_unread(
    g: ReaderBase,
    r: TagReader,
    filename: str,
    ros2: bool,
    own: set[str],
    other: set[str],
    depth: bool,
) -> None:
    """What the camera plugin's block has that changes nothing: the other ROS version's parameters, depth
    cut-offs and intrinsics (not applied here), and tags no version reads."""
    p = r.el
    for tag in other:
        el = p.find(tag)
        if el is None:
            continue
        r.mark(tag)
        if not is_zero(el.text) and tag not in HARMLESS and (el.text or "").strip().lower() != "true":
            g.note(
                el,
                f"<{tag}> is a ROS {'1' if ros2 else '2'} parameter; the ROS {'2' if ros2 else '1'} "
                f"{filename!r} does not read it (Gazebo ignores it too)",
            )
    for tag in ("pointCloudCutoff", "pointCloudCutoffMax", "min_depth", "max_depth"):
        el = p.find(tag)
        if el is not None and tag in own and depth:
            g.note(el, f"<{tag}> is not applied: depth and points span the clip planes (<near>..<far>)")
    for tag in ("Cx", "Cy", "CxPrime", "focalLength", "cx", "cy", "focal_length"):
        el = p.find(tag)
        if el is not None and tag in own and not is_zero(el.text):
            g.note(el, f"<{tag}> is not applied: CameraInfo is the ideal pinhole of <horizontal_fov>")
    for el in r.leftovers():
        if el.tag not in CAMERA_KNOWN and el.tag not in IGNORED_REASONS:
            r.mark(el.tag)
            g.note(el, f"<{el.tag}> is not a parameter of {filename!r}: Gazebo ignores it too")
