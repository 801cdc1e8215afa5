"""SDF `<sensor>`s of type magnetometer, altimeter, air_pressure and force_torque -> our `magnetometer`,
`altimeter`, `air_pressure` (plugins/field_sensors.py) and `force_torque` (plugins/force_torque.py), as
gz-sensors computes them and ros_gz_bridge hands them to ROS (sensor_msgs/MagneticField,
ros_gz_interfaces/Altimeter, sensor_msgs/FluidPressure, geometry_msgs/WrenchStamped).

Topics: Harmonic's `<topic>`, else gz-sim's scoped default `.../sensor/<name>/<leaf>` (gz-sim systems
Magnetometer.cc:359-362 `magnetometer`, Altimeter.cc:186-190 `altimeter`, AirPressure.cc:186-189
`air_pressure`, ForceTorque.cc `forcetorque`). Gazebo Classic has these sensors too, but gazebo_ros has no
plugin that publishes the first three: there they are *implicit* (published on our default topic, which
classic Gazebo would not publish on ROS, as said).
"""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.noise import NoiseSpec, noise_spec
from runner.compile.gazebo.sensor_plugins import read_sensor_plugins
from runner.compile.gazebo.sensor_reasons import NOT_SDF
from runner.compile.gazebo.tags import SdfReader, TagReader, ros_topic
from runner.errors import NO_PUBLISHER, PLUGIN_UNSUPPORTED

# `s`: runner.compile.gazebo.sensors' `_Sensor` (one <sensor> as every kind reads it), which imports this
_Sensor = Any


def _noise(g: ReaderBase, block: TagReader, tag: str, what: str, context: str) -> NoiseSpec | None:
    """The `<noise>` of the axis `tag` of `block` (anything else in the axis is said); a bias (drawn once
    per run in gz-sensors) is said and left out."""
    el = block.child(tag)
    if el is None:
        return None
    r = SdfReader(el)
    where = f"{context} <{block.el.tag}><{tag}>"
    spec = noise_spec(g, r, where)
    g.ignored(r, where, NOT_SDF)
    if spec is not None and (spec.bias_mean or spec.bias_stddev):
        g.note(spec.el, f"a noise bias (<bias_mean>, <bias_stddev>) is not modelled for {what}")
    return spec


def _topic(g: ReaderBase, s: _Sensor, leaf: str, scope: str = "link") -> tuple[str, bool]:
    """The sensor's topic and whether it is implicit (see the module doc)."""
    if s.base_topic:
        return s.base_topic, False
    if g.harmonic:
        where = g.lumped_into.get(s.link or "", s.link or "base_link") if scope == "link" else s.link
        return f"world/default/model/{g.model}/{scope}/{where}/sensor/{s.name}/{leaf}", False
    return leaf, True


def _link_of(g: ReaderBase, s: _Sensor) -> str | None:
    """A link-mounted sensor's link: the reference's link (a joint's reference: its child link)."""
    if s.link in g.joint_names | g.fixed_joints:
        return _child_of(g, s.link)
    return s.link


def _child_of(g: ReaderBase, joint: str | None) -> str | None:
    for j in g.root.findall("joint"):
        if j.get("name") == joint and j.find("child") is not None:
            return j.find("child").get("link")
    return None


def _own_plugins(g: ReaderBase, s: _Sensor) -> None:
    """gazebo_ros has no sensor plugin for these: a plugin inside is said (read_sensor_plugins does)."""
    if s.plugins:
        read_sensor_plugins(g, s.plugins, s.context, (), s.name, s.kind)


def magnetometer(g: ReaderBase, s: _Sensor) -> bool:
    """`<magnetometer><x|y|z><noise>` -> `magnetometer` (MagnetometerSensor.cc:121-136, 162-198). The
    world's field is SDF's default `<magnetic_field>`: gz-sim (Harmonic) computes it from a table at the
    world's `<spherical_coordinates>` when the world sets them, which scenario worlds do not."""
    params: dict[str, Any] = {**s.common, "link": _link_of(g, s)}
    block = s.r.child("magnetometer")
    if block is not None:
        br = SdfReader(block)
        specs = [_noise(g, br, axis, "a magnetometer", s.context) for axis in ("x", "y", "z")]
        if any(specs):
            params["noise_stddev"] = [sp.stddev if sp else 0.0 for sp in specs]
            params["noise_mean"] = [sp.mean if sp else 0.0 for sp in specs]
        g.ignored(br, f"{s.context} <magnetometer>", NOT_SDF)
    _own_plugins(g, s)
    params["topic"], implicit = _topic(g, s, "magnetometer")
    params["frame_id"] = s.frame
    g.add(s.el, "magnetometer", s.name, params, implicit=implicit)
    return True


def air_pressure(g: ReaderBase, s: _Sensor) -> bool:
    """`<air_pressure><reference_altitude>` and `<pressure><noise>` -> `air_pressure`
    (AirPressureSensor.cc:130-133, 165-203; gz-sim AirPressure.cc sets the reference altitude)."""
    params: dict[str, Any] = {**s.common, "link": _link_of(g, s)}
    block = s.r.child("air_pressure")
    if block is not None:
        br = SdfReader(block)
        ref = br.float("reference_altitude")
        if ref is not None:
            params["reference_altitude"] = ref
        spec = _noise(g, br, "pressure", "an air pressure sensor", s.context)
        if spec is not None:
            params["noise_stddev"] = spec.stddev
            params["noise_mean"] = spec.mean
        g.ignored(br, f"{s.context} <air_pressure>", NOT_SDF)
    _own_plugins(g, s)
    params["topic"], implicit = _topic(g, s, "air_pressure")
    params["frame_id"] = s.frame
    g.add(s.el, "air_pressure", s.name, params, implicit=implicit)
    return True


def altimeter(g: ReaderBase, s: _Sensor) -> bool:
    """`<altimeter><vertical_position|vertical_velocity><noise>` -> `altimeter` (AltimeterSensor.cc:117-131;
    ros_gz_bridge maps gz.msgs.Altimeter to ros_gz_interfaces/msg/Altimeter)."""
    params: dict[str, Any] = {**s.common, "link": _link_of(g, s)}
    block = s.r.child("altimeter")
    if block is not None:
        br = SdfReader(block)
        for tag, key in (("vertical_position", "position"), ("vertical_velocity", "velocity")):
            spec = _noise(g, br, tag, "an altimeter", s.context)
            if spec is not None:
                params[f"{key}_noise_stddev"] = spec.stddev
                params[f"{key}_noise_mean"] = spec.mean
        g.ignored(br, f"{s.context} <altimeter>", NOT_SDF)
    _own_plugins(g, s)
    params["topic"], implicit = _topic(g, s, "altimeter")
    params["frame_id"] = s.frame
    g.add(s.el, "altimeter", s.name, params, implicit=implicit)
    return True


_FT_FRAMES = {"child": "child", "parent": "parent", "sensor": "sensor"}
_FT_DIRECTIONS = ("child_to_parent", "parent_to_child")


def force_torque(g: ReaderBase, s: _Sensor) -> bool:
    """`<force_torque>` in a joint's `<gazebo reference>` -> `force_torque` at the joint's child link: the
    wrench the joint transmits (gz-sim ForceTorque.cc:262-320), in `<frame>` child (default) / parent /
    sensor, `<measure_direction>` child_to_parent (default: the wrench the child applies on the parent)
    or parent_to_child (ForceTorqueSensor.cc:199-231); `<force>`/`<torque>` `<x|y|z><noise>` per axis.
    A force_torque sensor outside a joint's block is an error to Gazebo: said and left out."""
    joint = s.link if s.link in g.joint_names | g.fixed_joints else None
    if joint is None:
        g.note(
            s.el,
            f"{s.context} is not in a joint's <gazebo reference=...> block: Gazebo mounts a force_torque "
            "sensor on a joint only; it is left out",
            hint='write it in <gazebo reference="the joint">',
            kind=PLUGIN_UNSUPPORTED,
        )
        s.r.mark(*[c.tag for c in s.el if isinstance(c.tag, str)])
        return False
    params: dict[str, Any] = {**s.common, "link": _child_of(g, joint)}
    block = s.r.child("force_torque")
    if block is not None:
        br = SdfReader(block)
        frame = (br.text("frame") or "child").strip().lower()
        direction = (br.text("measure_direction") or "child_to_parent").strip().lower()
        if frame not in _FT_FRAMES:
            g.note(br.child("frame"), f"<frame> {frame!r} is not child, parent or sensor: child is used")
            frame = "child"
        if direction not in _FT_DIRECTIONS:
            g.note(
                br.child("measure_direction"),
                f"<measure_direction> {direction!r} is not child_to_parent or parent_to_child: "
                "child_to_parent is used",
            )
            direction = "child_to_parent"
        params["measure_frame"] = frame
        params["measure_direction"] = direction
        for part in ("force", "torque"):
            el = br.child(part)
            if el is None:
                continue
            pr = TagReader(el)
            specs = [_noise(g, pr, axis, "a force/torque sensor", s.context) for axis in ("x", "y", "z")]
            if any(specs):
                params[f"{part}_noise_stddev"] = [sp.stddev if sp else 0.0 for sp in specs]
                params[f"{part}_noise_mean"] = [sp.mean if sp else 0.0 for sp in specs]
            g.ignored(pr, f"{s.context} <force_torque><{part}>", NOT_SDF)
        g.ignored(br, f"{s.context} <force_torque>", NOT_SDF)
    else:
        params["measure_frame"] = "child"
        params["measure_direction"] = "child_to_parent"
    _own_plugins(g, s)
    params["topic"], implicit = _topic(g, s, "forcetorque", scope="joint")
    if s.base_topic is None and not g.harmonic:
        params["topic"] = f"{s.name}/forcetorque"
    params["frame_id"] = s.frame
    g.add(s.el, "force_torque", s.name, params, implicit=implicit)
    return True


def ft_sensor(g: ReaderBase, r: Any, remap: dict[str, str]) -> tuple[str, dict[str, Any]] | None:
    """gazebo_plugins' `libgazebo_ros_ft_sensor.so` (a model plugin) -> `force_torque`: the wrench a
    joint applies on its child link (`GetForceTorque(0).body2Force/body2Torque`), in the child link's
    frame, plus N(0, noise) on each of the six components.

    ROS 1 (noetic-devel gazebo_ros_ft_sensor.cpp:64-111, 185-216): `<jointName>` and `<topicName>` are
    required (without either it publishes nothing), `<gaussianNoise>`, `<updateRate>` (0: every step),
    frame the child link. ROS 2 (ros2 gazebo_ros_ft_sensor.cpp:100-157): `<joint_name>` or `<body_name>`,
    topic `wrench` (remapped), `<gaussian_noise>`, `<update_rate>`, `<frame_name>` only with a body.
    A `<body_name>` reports the forces other plugins applied to the link (`Link::WorldForce`), which here
    are none: said and left out."""
    p = r.el
    filename = p.get("filename")
    ros1 = p.find("jointName") is not None or p.find("topicName") is not None
    if p.find("body_name") is not None and p.find("joint_name") is None:
        g.note(
            p,
            f"{filename!r} with <body_name> reports the forces plugins apply to the link (Link::WorldForce), "
            "which here are none: it is left out",
            hint="measure at a joint: <joint_name>",
            kind=PLUGIN_UNSUPPORTED,
        )
        r.mark(*[c.tag for c in p if isinstance(c.tag, str)])
        return None
    joint = r.text("jointName" if ros1 else "joint_name")
    topic = ros_topic(r.text("topicName")) if ros1 else (remap.get("wrench") or "wrench")
    missing = "<jointName>" if ros1 and not joint else "<topicName>" if ros1 and not topic else None
    if not ros1 and not joint:
        missing = "<joint_name> or <body_name>"
    if missing is None and joint not in g.joint_names | g.fixed_joints:
        said = f"{filename!r}: joint {joint!r} does not exist: it publishes nothing (in Gazebo too)"
        g.note(p, said, kind=NO_PUBLISHER)
        r.mark(*[c.tag for c in p if isinstance(c.tag, str)])
        return None
    if missing is not None:
        g.note(p, f"{filename!r} has no {missing}: it publishes nothing (in Gazebo too)", kind=NO_PUBLISHER)
        r.mark(*[c.tag for c in p if isinstance(c.tag, str)])
        return None
    child = _child_of(g, joint)
    noise = r.float("gaussianNoise" if ros1 else "gaussian_noise")
    rate = r.float("updateRate" if ros1 else "update_rate")
    frame = p.find("frame_name")
    if frame is not None:
        r.mark("frame_name")
        g.note(
            frame, "<frame_name> is read only with <body_name>: the frame is the joint's child link (Gazebo)"
        )
    params: dict[str, Any] = {
        "link": child,
        "topic": topic,
        "frame_id": g.frame(child),
        "measure_frame": "child",
        "measure_direction": "parent_to_child",
    }
    if noise:
        params["force_noise_stddev"] = [abs(noise)] * 3
        params["torque_noise_stddev"] = [abs(noise)] * 3
    if rate and rate > 0:
        params["rate"] = rate
    else:
        g.note(
            p,
            f"{filename!r} has no update rate (or 0): Gazebo publishes it at every physics step; here at the "
            "force_torque plugin's 100 Hz",
            hint="add <updateRate> / <update_rate> (or set `rate` in the scenario's plugin params)",
        )
    return "force_torque", params


MODEL_PLUGINS = {"gazebo_ros_ft_sensor": ft_sensor}
