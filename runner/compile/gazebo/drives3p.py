"""Third-party drive and world-odometry plugins -> our `force_based_move` and `ground_truth`, with the
topics, frames, rates, gains, offsets and noise their sources read (each handler cites the file:line):

- hector_gazebo_plugins' `libgazebo_ros_force_based_move.so` (ROS 1), its ROS 2 port in the
  gazebo_plugins namespace (same file name, snake_case parameters), Robotnik's
  `librobotnik_force_based_move.so` -> `force_based_move` (a force and a torque on the base tracking
  cmd_vel through P gains; see plugins/force_based_move.py);
- gazebo_plugins' `libgazebo_ros_p3d.so` (ROS 1 and ROS 2), PAL's `libgazebo_world_odometry.so` (ROS 1
  and ROS 2), Robotnik's `librobotnik_gazebo_ground_truth_odom.so` -> `ground_truth` (the true pose).

Handlers have the signature of runner.compile.gazebo.model_plugins' (the reader as `g`, the plugin's tag
reader, its ROS remappings) and return (our plugin type, its params) or None; MODEL_PLUGINS is merged into
model_plugins._MODEL_PLUGINS. The parameter names each plugin has (the rest said as typos) and the ones
said as ignored come from runner.compile.gazebo.catalogue.
"""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.tags import TagReader, floats, ros_topic

Result = tuple[str, dict[str, Any]] | None

# Gazebo Classic's default physics step is 1 ms: a plugin without a rate publishes at every step. We
# give the ground truth that rate: it runs at every physics step of ours (the step caps it).
_EVERY_STEP_HZ = 1000.0
_WORLD_FRAMES = {"world", "/world", "map", "/map"}  # p3d: these mean "the Gazebo world", not a link

_HECTOR = "hector_gazebo_plugins' gazebo_ros_force_based_move.cpp (melodic-devel)"
_ROS2_FORCE = {
    "odometry_frame",
    "robot_base_frame",
    "update_rate",
    "publish_rate",
    "publish_odom",
    "publish_odom_tf",
    "vel_p_gain",
    "vel_i_gain",
    "vel_i_lim",
    "force_lim",
    "omega_p_gain",
    "omega_i_gain",
    "omega_i_lim",
    "torque_lim",
}


# ------------------------------------------------------------------------------------ force-based drives
def _base_link(g: ReaderBase, r: TagReader, tag: str, name: str | None, filename: str) -> str:
    """The link the plugin pushes and names as the odometry's child (default `base_footprint`, :110 of
    hector's source): Gazebo's `GetLink` of it. We push the robot's root; a name that is no link of the
    robot is said (Gazebo would dereference a null link there)."""
    link = (name or "base_footprint").strip().strip("/")
    if g.link_names and link not in g.link_names and link not in g.lumped_into:
        el = r.child(tag)
        g.note(
            el if el is not None else r.el,
            f"{filename!r} pushes link {link!r}"
            + (" (its default)" if name is None else "")
            + ", which the robot does not have: Gazebo finds no link to push; here the base is pushed",
            hint=f"set <{tag}> to the robot's base link",
        )
    return link


def _force_based_move_ros1(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> Result:
    """hector's plugin (ROS 1; gazebo_ros_force_based_move.cpp of melodic-devel, kinetic-devel's two
    additions): `<commandTopic>` (cmd_vel, :56-66), `<odometryTopic>` (odom, :68-78), `<odometryFrame>`
    (odom, :80-90), `<x|y|yaw_velocity_p_gain>` (10000, 10000, 100, :93-104), `<robotBaseFrame>`
    (base_footprint, :110-124), `<odometryRate>` (20 Hz; 0 or less: no odometry, :126-136 and :243),
    `<publishOdometryTf>` (true, :138-144); kinetic-devel: `<allowLateralMotion>` (true),
    `<commandTimeoutDuration>` (0: none; the command zeroed after it)."""
    filename = r.el.get("filename", "")
    return "force_based_move", _hector_params(g, r, remap, filename)


def _hector_params(g: ReaderBase, r: TagReader, remap: dict[str, str], filename: str) -> dict[str, Any]:
    base = _base_link(g, r, "robotBaseFrame", r.text("robotBaseFrame"), filename)
    rate = r.float("odometryRate")
    params: dict[str, Any] = {
        "cmd_topic": ros_topic(r.text("commandTopic")) or remap.get("cmd_vel") or "cmd_vel",
        "odom_topic": ros_topic(r.text("odometryTopic")) or remap.get("odom") or "odom",
        "odom_frame": (r.text("odometryFrame") or "odom").strip("/"),
        "base_frame": g.frame(base),
        "p_gains": [
            _gain(r, "x_velocity_p_gain", 10000.0),
            _gain(r, "y_velocity_p_gain", 10000.0),
            _gain(r, "yaw_velocity_p_gain", 100.0),
        ],
        "odometry": "integrated",
    }
    if rate is not None and rate <= 0:
        g.note(
            r.child("odometryRate"),
            f"<odometryRate> {rate:g} in {filename!r}: the plugin publishes neither odometry nor TF (as in "
            "Gazebo)",
        )
        params["publish_odom"] = params["publish_tf"] = False
    else:
        params["rate"] = rate or 20.0
        tf = r.bool("publishOdometryTf")
        params["publish_tf"] = True if tf is None else tf
    lateral = r.bool("allowLateralMotion")
    if lateral is False:
        params["allow_lateral"] = False
    timeout = r.float("commandTimeoutDuration")
    if timeout and timeout > 0:
        params["cmd_timeout"] = timeout
    return params


def _gain(r: TagReader, tag: str, default: float) -> float:
    value = r.float(tag)
    return value if value is not None and value > 0 else default


def _force_based_move(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> Result:
    """`libgazebo_ros_force_based_move.so`: hector's ROS 1 plugin (camelCase parameters), or the ROS 2
    port (snake_case parameters, a `<ros>` block), told apart by the parameters the block has."""
    if _has(r, "ros", *_ROS2_FORCE):
        return _force_based_move_ros2(g, r, remap)
    return _force_based_move_ros1(g, r, remap)


def _force_based_move_ros2(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> Result:
    """The ROS 2 port (gazebo_plugins namespace; read from eduardoespino2002/dots_gazebo2's
    gazebo_plugins/src/gazebo_ros_force_based_move.cpp): topics `cmd_vel` and `odom` (remappable, :179,
    :190), `<odometry_frame>` (odom, :155), `<robot_base_frame>` (base_footprint, :156), `<update_rate>`
    (20; the force is applied at every step regardless, :162), `<publish_rate>` (20 Hz, :171),
    `<publish_odom>`, `<publish_odom_tf>` (true, :188, :199), PI gains and limits `<vel_p_gain>` 1000,
    `<vel_i_gain>` 0, `<vel_i_lim>` 1, `<force_lim>` 1 N, `<omega_p_gain>` 100, `<omega_i_gain>` 0,
    `<omega_i_lim>` 1, `<torque_lim>` 1 N·m (:210-217); odometry: the world pose (:382-394)."""
    filename = r.el.get("filename", "")
    base = _base_link(g, r, "robot_base_frame", r.text("robot_base_frame"), filename)
    vel_p, omega_p = _gain(r, "vel_p_gain", 1000.0), _gain(r, "omega_p_gain", 100.0)
    vel_i, omega_i = r.float("vel_i_gain") or 0.0, r.float("omega_i_gain") or 0.0
    params: dict[str, Any] = {
        "cmd_topic": remap.get("cmd_vel") or "cmd_vel",
        "odom_topic": remap.get("odom") or "odom",
        "odom_frame": (r.text("odometry_frame") or "odom").strip("/"),
        "base_frame": g.frame(base),
        "rate": r.float("publish_rate") or 20.0,
        "p_gains": [vel_p, vel_p, omega_p],
        "i_gains": [max(vel_i, 0.0), max(vel_i, 0.0), max(omega_i, 0.0)],
        "i_limits": [r.float("vel_i_lim") or 1.0, r.float("vel_i_lim") or 1.0, r.float("omega_i_lim") or 1.0],
        "max_force": r.float("force_lim") or 1.0,
        "max_torque": r.float("torque_lim") or 1.0,
        "odometry": "world",
    }
    for key, tag in (("publish_odom", "publish_odom"), ("publish_tf", "publish_odom_tf")):
        value = r.bool(tag)
        if value is not None:
            params[key] = value
    return "force_based_move", params


def _robotnik_force_based_move(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> Result:
    """Robotnik's fork (robotnik_gazebo_plugins: robotnik_force_based_move/src/robotnik_force_based_move.cpp
    of master): hector's parameters as its melodic-devel reads them (:56-157), and `<commandWatchdog>`
    (2 s, :68-79): once no command came for that long it stops pushing and puts the model back where it
    was, its velocity zeroed, at every step (:215-221, :278-299) -> `hold_on_timeout`."""
    filename = r.el.get("filename", "")
    params = _hector_params(g, r, remap, filename)
    watchdog = r.float("commandWatchdog")
    params["cmd_timeout"] = watchdog if watchdog is not None and watchdog > 0 else 2.0
    params["hold_on_timeout"] = True
    return "force_based_move", params


# --------------------------------------------------------------------------------------- world odometry
def _offsets(g: ReaderBase, r: TagReader, params: dict[str, Any], *tags: str) -> None:
    """`<xyzOffset>`-style then `<rpyOffset>`-style tags (pairs of spellings: the first read wins) ->
    xyz_offset, rpy_offset; a value that is not three numbers is said (Gazebo's Get<Vector3d> gives 0s)."""
    for key, names in (("xyz_offset", tags[: len(tags) // 2]), ("rpy_offset", tags[len(tags) // 2 :])):
        el = r.child(*names)
        if el is None:
            continue
        values = floats(el.text, 3)
        if values is None:
            g.note(el, f"<{el.tag}> {el.text!r} is not three numbers: it is not used (Gazebo reads 0 0 0)")
        elif any(values):
            params[key] = values


def _frame_or_link(g: ReaderBase, name: str | None) -> tuple[str, str | None]:
    """A frame parameter that names the world (`world`, `map`) or a link of the robot: (frame_id,
    reference link or None)."""
    name = (name or "world").strip()
    if name in _WORLD_FRAMES:
        return name.strip("/"), None
    return g.frame(name) or name, name.strip("/")


def _has(r: TagReader, *tags: str) -> bool:
    """Whether the block has one of `tags` (a look that reads nothing: which spelling, ROS 1 or 2)."""
    return any(r.el.find(t) is not None for t in tags)


def _every_step(rate: float | None) -> float:
    return rate if rate and rate > 0 else _EVERY_STEP_HZ


def _p3d(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> Result:
    """gazebo_plugins' p3d. ROS 1 (gazebo_ros_p3d.cpp of noetic-devel): `<bodyName>` and `<topicName>`
    required (:65-87: without them it does nothing), `<frameName>` (world; a link's name gives the pose
    relative to it, :89-95, :171-199, :278-297), `<xyzOffset>`, `<rpyOffset>` (:97-111, applied :299-304),
    `<gaussianNoise>` on the twist only (:113-119, :327-340), `<updateRate>` (0: every step, :121-128).
    ROS 2 (gazebo_ros_p3d.cpp of ros2): `<body_name>` required, topic `odom` (remappable), `<frame_name>`,
    `<xyz_offset>`/`<rpy_offset>` (or the deprecated plurals), `<gaussian_noise>`, `<update_rate>`."""
    filename = r.el.get("filename", "")
    link = r.text("bodyName", "body_name")
    ros2 = _has(r, "body_name", "topic_name", "frame_name", "update_rate", "ros")
    topic = ros_topic(r.text("topicName", "topic_name"))
    if ros2:
        topic = topic or remap.get("odom") or "odom"
    for what, value in (("<bodyName>", link), ("<topicName>", topic)):
        if not value:
            g.note(
                r.el,
                f"{filename!r} has no {what}: the plugin stops loading and publishes nothing (as in Gazebo)",
            )
            r.mark(*[c.tag for c in r.el if isinstance(c.tag, str)])
            return None
    frame_id, ref = _frame_or_link(g, r.text("frameName", "frame_name"))
    params: dict[str, Any] = {
        "link": link.strip() if link else None,
        "topic": topic,
        "frame_id": frame_id,
        "reference_link": ref,
        "rate": _every_step(r.float("updateRate", "update_rate")),
    }
    _offsets(g, r, params, "xyzOffset", "xyz_offset", "xyz_offsets", "rpyOffset", "rpy_offset", "rpy_offsets")
    noise = r.float("gaussianNoise", "gaussian_noise")
    if noise:
        params["twist_noise"] = abs(noise)
    return "ground_truth", params


def _pal_world_odometry(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> Result:
    """PAL's world odometry (pal_gazebo_plugins). ROS 1 (src/gazebo_world_odometry.cpp of melodic-devel):
    `<topicName>` (default `ft_data`, :36-39), `<frameName>` (the header's frame, world, :41-47),
    `<bodyName>` (default the frameName, :49-55), `<updateRate>` (1000 Hz, :67-73); the pose is the link's
    world pose, the twist's linear part in the world frame and its angular part in the link's (:151-174).
    Its offsets and noise are dynamic-reconfigure variables (0 at start, :74-79), not SDF parameters.
    ROS 2 (humble-devel): `<body_name>` required (:111-116), topic `<topic_name>` (odom, :63, :126-128),
    `<frame_name>` (world or a link, :174-192), `<xyz_offset>`/`<rpy_offset>` (or plurals, :137-163),
    `<gaussian_noise>` on the twist (:165-170, :270-275), `<update_rate>` (0: every step, :102-108); the
    twist in the link's frame (:242-243)."""
    filename = r.el.get("filename", "")
    if _has(r, "body_name", "topic_name", "frame_name", "update_rate", "ros"):
        link = r.text("body_name")
        if not link:
            g.note(r.el, f"{filename!r} has no <body_name>: the plugin stops loading and publishes nothing")
            r.mark(*[c.tag for c in r.el if isinstance(c.tag, str)])
            return None
        frame_id, ref = _frame_or_link(g, r.text("frame_name"))
        params: dict[str, Any] = {
            "link": link.strip(),
            "topic": ros_topic(r.text("topic_name")) or remap.get("odom") or "odom",
            "frame_id": frame_id,
            "reference_link": ref,
            "rate": _every_step(r.float("update_rate")),
            "linear_velocity_frame": "body",
            "angular_velocity_frame": "body",
        }
        _offsets(g, r, params, "xyz_offset", "xyz_offsets", "rpy_offset", "rpy_offsets")
        noise = r.float("gaussian_noise")
        if noise:
            params["twist_noise"] = abs(noise)
        return "ground_truth", params
    frame = (r.text("frameName") or "world").strip()
    link = (r.text("bodyName") or frame).strip()
    return "ground_truth", {
        "link": link,
        "topic": ros_topic(r.text("topicName")) or "ft_data",
        "frame_id": frame.strip("/") if frame in _WORLD_FRAMES else g.frame(frame),
        "child_frame_id": g.frame(link),
        "rate": _every_step(r.float("updateRate") or 1000.0),
        "linear_velocity_frame": "world",
        "angular_velocity_frame": "body",
    }


def _robotnik_ground_truth(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> Result:
    """Robotnik's ground truth (robotnik_gazebo_plugins: robotnik_gazebo_ground_truth_odom/src/
    robotnik_gazebo_ground_truth_odom.cpp of master): `<bodyName>` and `<topicName>` required (:63-85),
    `<worldBodyName>` (world, or a link the pose is taken relative to, :87-93, :196-207), `<frameName>`
    (the child frame, default the bodyName, :95-101), `<worldFrameName>` (the header's frame, default the
    worldBodyName, :103-109), `<broadcastTF>` (false, :111-117), `<xyzOffset>`, `<rpyOffset>`
    (:119-133), `<gaussianNoise>` on the twist (:135-141, :364-376), `<updateRate>` (0: every step,
    :143-150); the twist in the link's frame (:358-362)."""
    filename = r.el.get("filename", "")
    link, topic = r.text("bodyName"), ros_topic(r.text("topicName"))
    for what, value in (("<bodyName>", link), ("<topicName>", topic)):
        if not value:
            g.note(r.el, f"{filename!r} has no {what}: the plugin publishes nothing (as in Gazebo)")
            r.mark(*[c.tag for c in r.el if isinstance(c.tag, str)])
            return None
    assert link is not None
    world_body = (r.text("worldBodyName") or "world").strip()
    ref = None if world_body in _WORLD_FRAMES else world_body.strip("/")
    world_frame = (r.text("worldFrameName") or world_body).strip()
    params: dict[str, Any] = {
        "link": link.strip(),
        "topic": topic,
        "frame_id": world_frame.strip("/") if world_frame in _WORLD_FRAMES else g.frame(world_frame),
        "child_frame_id": g.frame(r.text("frameName") or link),
        "reference_link": ref,
        "rate": _every_step(r.float("updateRate")),
        "linear_velocity_frame": "body",
        "angular_velocity_frame": "body",
        "publish_tf": bool(r.bool("broadcastTF")),
    }
    _offsets(g, r, params, "xyzOffset", "rpyOffset")
    noise = r.float("gaussianNoise")
    if noise:
        params["twist_noise"] = abs(noise)
    return "ground_truth", params


MODEL_PLUGINS = {
    "gazebo_ros_force_based_move": _force_based_move,
    "robotnik_force_based_move": _robotnik_force_based_move,
    "gazebo_ros_p3d": _p3d,
    "gazebo_world_odometry": _pal_world_odometry,
    "robotnik_gazebo_ground_truth_odom": _robotnik_ground_truth,
}
