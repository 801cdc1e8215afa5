"""gazebo_plugins' ray-sensor plugins that publish something else than a LaserScan, as Gazebo runs them:

- ROS 1 `libgazebo_ros_range.so` (noetic-devel, gazebo_plugins/src/gazebo_ros_range.cpp): only a
  sensor_msgs/Range on `<topicName>` (default `/range`, under `<robotNamespace>`), frame `<frameName>`
  (default `/world`), `<radiation>` ultrasound (the default, :93-100) or anything else infrared (:136-139),
  `<fov>` (default 0.05, :102-108) as the field of view, min/max range from the ray sensor's `<range>`
  (:142-143), the nearest noise-free ray plus N(0, `<gaussianNoise>`) capped at the max range (:302-316),
  `<updateRate>` (default 0: every sensor update) throttling the sensor (:117-131, :230);
- ROS 2 `libgazebo_ros_ray_sensor.so` (ros2 branch, gazebo_plugins/src/gazebo_ros_ray_sensor.cpp): one
  publisher on `~/out` (`<plugin name>/out`, remapped by `<ros><remapping>`) of `<output_type>`
  sensor_msgs/LaserScan, PointCloud, PointCloud2 (the default, :116-119) or Range (:132-134); for a Range,
  `<radiation_type>` infrared (the default, :144-147) or ultrasound, anything else an error after which it
  publishes nothing (:152-157); the Range's field of view is the wider of the horizontal and vertical spans,
  its range the nearest of the scan's (REP 117-masked) ranges (gazebo_ros/conversions/sensor_msgs.hpp:
  291-316); the frame is `<frame_name>`, default the sensor's link (gazebo_ros/src/utils.cpp:52-61).

Both become our `lidar` with `publish_scan`/`publish_points`/`range_topic` set to what the plugin publishes.
"""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.tags import TagReader, join_topic, ros_topic
from runner.errors import NO_PUBLISHER

RANGE_PLUGINS = {"gazebo_ros_range"}


def _spans(sensor_el: Any) -> tuple[float, float]:
    """The ray sensor's horizontal and vertical angular spans (max_angle - min_angle; 0 when unset)."""
    out = []
    for axis in ("horizontal", "vertical"):
        vals = []
        for end in ("min_angle", "max_angle"):
            text = sensor_el.findtext(f"ray/scan/{axis}/{end}") if sensor_el is not None else None
            try:
                vals.append(float(text) if text and text.strip() else 0.0)
            except ValueError:
                vals.append(0.0)
        out.append(vals[1] - vals[0])
    return out[0], out[1]


def ros1_range(g: ReaderBase, r: TagReader, kind: str, context: str) -> dict[str, Any]:
    """ROS 1 `libgazebo_ros_range.so` -> what `read_sensor_plugins` finds: topic, frame, the plugin's rate
    (`rate`, applied as a throttle of the sensor's) and the lidar's params. It needs a CPU `ray` sensor:
    on any other Gazebo refuses to load it (gazebo_ros_range.cpp:66-71)."""
    p = r.el
    if kind != "ray":
        g.note(
            p,
            f"{context}: libgazebo_ros_range.so needs a sensor of type 'ray' (Gazebo throws on a {kind!r} "
            "sensor): it publishes nothing, and the sensor is left out",
            hint='use <sensor type="ray">',
            kind=NO_PUBLISHER,
        )
        r.mark(*[c.tag for c in p if isinstance(c.tag, str)])
        return {"nothing": True}
    topic_text = r.text("topicName")
    topic = ros_topic(topic_text) if topic_text is not None else "range"
    frame = r.text("frameName")
    radiation = (r.text("radiation") or "ultrasound").strip()
    fov = r.float("fov")
    params: dict[str, Any] = {
        "publish_scan": False,
        "publish_points": False,
        "range_topic": topic,
        "radiation_type": "ultrasound" if radiation == "ultrasound" else "infrared",
        "range_field_of_view": 0.05 if fov is None else fov,
        "range_style": "gazebo_ros_range",
    }
    if radiation not in ("ultrasound", "infrared"):
        g.note(
            p.find("radiation"),
            f"<radiation> {radiation!r} in {context}: gazebo_ros_range reports anything but 'ultrasound' "
            "as INFRARED (here too)",
        )
    noise = r.float("gaussianNoise")
    if noise:
        params["range_noise_stddev"] = abs(noise)
    found: dict[str, Any] = {"params": params}
    if topic is None:  # an empty <topicName>: the plugin advertises nothing (gazebo_ros_range.cpp:171)
        said = f"{context}: an empty <topicName>: gazebo_ros_range publishes nothing (in Gazebo too)"
        g.note(p, said, kind=NO_PUBLISHER)
        found["nothing"] = True
    # tf::resolve leaves the default `/world` (absolute) alone
    found["frame"] = g.frame(frame) if frame and frame.strip("/") != "world" else "world"
    found["topic"] = topic
    return found


OUTPUT_TYPES = ("LaserScan", "PointCloud", "PointCloud2", "Range")


def ros2_ray_sensor(g: ReaderBase, r: TagReader, remap: dict[str, str], context: str) -> dict[str, Any]:
    """ROS 2 `libgazebo_ros_ray_sensor.so` -> what `read_sensor_plugins` finds: one topic, `~/out`, of the
    `<output_type>`'s message."""
    p = r.el
    name = ros_topic(p.get("name")) or "gazebo_ros_ray_sensor"
    topic = remap.get("out") or join_topic(name, "out")
    frame = r.text("frame_name")
    out_text = r.text("output_type")
    out_type = (out_text or "sensor_msgs/PointCloud2").strip()
    short = out_type.split("/")[-1]
    found: dict[str, Any] = {"topic": topic, "frame": g.frame(frame) if frame else None}
    if out_text is None:
        g.note(
            p,
            f"{context}: libgazebo_ros_ray_sensor.so has no <output_type>: Gazebo publishes a "
            f"sensor_msgs/PointCloud2 on {topic} (here too), not a LaserScan",
            hint="add <output_type>sensor_msgs/LaserScan</output_type> for a scan",
        )
    if short not in OUTPUT_TYPES or out_type.count("/") > 2 or not out_type.startswith("sensor_msgs/"):
        g.note(
            p.find("output_type"),
            f"<output_type> {out_type!r} in {context} is invalid: gazebo_ros_ray_sensor publishes nothing "
            "(here: nothing either)",
            hint="one of sensor_msgs/LaserScan, sensor_msgs/PointCloud2, sensor_msgs/PointCloud, "
            "sensor_msgs/Range",
            kind=NO_PUBLISHER,
        )
        found["nothing"] = True
        return found
    if short == "LaserScan":
        found["params"] = {"publish_scan": True, "publish_points": False}
    elif short in ("PointCloud2", "PointCloud"):
        if short == "PointCloud":
            g.note(
                p.find("output_type"),
                f"<output_type> sensor_msgs/PointCloud in {context} is published as a "
                "sensor_msgs/PointCloud2 (the same points; the older message is not produced)",
            )
        found["params"] = {
            "publish_scan": False,
            "publish_points": True,
            "points_topic": topic,
            "organize_cloud": False,  # conversions: only the rays within range, one row
        }
    else:
        params = _range_params(g, r, topic, context)
        if params is None:
            found["nothing"] = True
            return found
        found["params"] = params
    if short != "Range" and p.find("radiation_type") is not None:
        r.mark("radiation_type")
        g.note(
            p.find("radiation_type"),
            f"<radiation_type> in {context} is read only for a sensor_msgs/Range output (Gazebo ignores it "
            "too)",
        )
    intensity = r.float("min_intensity")
    if intensity and intensity > 0 and short != "Range":
        g.note(
            p.find("min_intensity"),
            "<min_intensity> is not applied: every return has intensity 0 here (no <laser_retro>)",
        )
    return found


def _range_params(g: ReaderBase, r: TagReader, topic: str, context: str) -> dict[str, Any] | None:
    p = r.el
    radiation = (r.text("radiation_type") or "infrared").strip()
    params: dict[str, Any] = {
        "publish_scan": False,
        "publish_points": False,
        "range_topic": topic,
        "radiation_type": radiation,
        "range_style": "gazebo_ros_ray_sensor",
    }
    if radiation not in ("ultrasound", "infrared"):
        g.note(
            p.find("radiation_type"),
            f"<radiation_type> {radiation!r} in {context} is invalid: gazebo_ros_ray_sensor publishes "
            "nothing (here: nothing either)",
            hint="ultrasound or infrared",
            kind=NO_PUBLISHER,
        )
        return None
    h, v = _spans(p.getparent())
    params["range_field_of_view"] = max(h, v)
    intensity = p.find("min_intensity")
    if intensity is not None:
        r.mark("min_intensity")  # read, and unused by the Range conversion (sensor_msgs.hpp:293)
    return params
