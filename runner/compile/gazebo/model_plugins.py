"""Model plugins (`<plugin>` in a `<gazebo>` block) -> our plugins: gazebo_ros's diff drive, skid steer,
planar move, joint state publisher, imu, gz-sim's diff drive, joint
state publisher and odometry publisher, ros_control (runner.compile.gazebo.controllers), hector's
(runner.compile.gazebo.thirdparty) and the force-based drives, p3d and world-odometry plugins
(runner.compile.gazebo.drives3p). Each handler reads its plugin's parameters as the real plugin does,
defaults included; gz-sim systems our world always runs are no-ops, any other plugin is said."""

from __future__ import annotations

import re
from typing import Any

from runner.compile.gazebo import catalogue, drives3p, field_sensors, gz_mecanum, thirdparty
from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.control.drives import by_wheels
from runner.compile.gazebo.controllers import ros_control
from runner.compile.gazebo.tables import IGNORED_REASONS, NOOP_PLUGINS
from runner.compile.gazebo.tags import TagReader, floats, plugin_base, ros_topic
from runner.errors import PLUGIN_UNSUPPORTED


def read_model_plugin(g: ReaderBase, p: Any, link: str | None) -> None:
    """A `<plugin>` of a `<gazebo>` block -> our plugin, by the handler of its file name."""
    filename = p.get("filename", "")
    name = p.get("name") or plugin_base(filename)
    base = plugin_base(filename)
    r = TagReader(p)
    context = f"<plugin filename={filename!r}>"
    handler = _MODEL_PLUGINS.get(base)
    if handler is None and _CONTROL_FORK.search(base):
        # a vendor's fork of the control plugin (franka's `franka_ign_ros2_control-system`...) loads the
        # controller manager as its parent does: read as the parent, said
        handler = ros_control
        g.note(p, f"plugin {filename!r} is read as the ros2_control / ros_control plugin it forks")
    if handler is None:
        if base in NOOP_PLUGINS:
            return
        # the catalogue says why, and what serves instead, where it knows the plugin
        why = catalogue.unsupported_reason(base)
        why = f": {why}" if why else ""
        g.note(
            p,
            f"plugin {filename!r} is not supported and is ignored{why}",
            hint="model plugins we map: " + ", ".join(sorted(_MODEL_PLUGINS)) + ". Add a plugin of ours "
            "under the robot's `plugins:` in the scenario instead.",
            kind=PLUGIN_UNSUPPORTED,
        )
        return
    ros = g.ros_block(r)
    r.mark("alwaysOn", "always_on", "robotNamespace")
    result = handler(g, r, ros["remap"])
    if result is not None:
        type_name, params = result
        g.add(p, type_name, name, params)
    doc = catalogue.entry(base)
    if doc is not None:  # its parameters, from the catalogue: the rest are typos or leftovers
        known, ignored = doc.names(), doc.ignored()
        for el in r.leftovers():
            if el.tag in ignored:
                r.mark(el.tag)
                g.note(el, f"<{el.tag}> in {context} is ignored ({ignored[el.tag]})")
            elif el.tag not in known and el.tag not in IGNORED_REASONS:
                r.mark(el.tag)
                g.note(el, f"<{el.tag}> is not a parameter of {filename!r}: Gazebo ignores it too")
    g.ignored(r, context)


# What gazebo_plugins put in the odometry's covariance: x, y and yaw given (or their defaults), z, roll and
# pitch 1e12 ("unknown")
_UNKNOWN = 1e12


def _covariance(r: TagReader, defaults: tuple[float, float, float]) -> list[float]:
    """`[cov_x, cov_y, 1e12, 1e12, 1e12, cov_yaw]` from `<covariance_x/y/yaw>` (ros2 branch:
    gazebo_ros_diff_drive.cpp:404-406 and 651-664, gazebo_ros_planar_move.cpp:193-210; noetic:
    gazebo_ros_skid_steer_drive.cpp:208-229 and 460-486)."""
    x = r.float("covariance_x")
    y = r.float("covariance_y")
    yaw = r.float("covariance_yaw")
    cx, cy, cyaw = (v if v is not None else d for v, d in zip((x, y, yaw), defaults, strict=True))
    return [cx, cy, _UNKNOWN, _UNKNOWN, _UNKNOWN, cyaw]


def _odom_source(text: str | None) -> str | None:
    if text is None:
        return None
    return "encoders" if text.strip().lower() in ("0", "encoder", "encoders") else "world"


def _diff_drive_classic(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
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
        "cmd_topic": ros_topic(r.text("commandTopic")) or remap.get("cmd_vel"),
        "odom_topic": ros_topic(r.text("odometryTopic")) or remap.get("odom"),
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
    r.mark("publishOdomTF")
    if r.el.find("leftJoint") is not None or r.el.find("rightJoint") is not None:
        # ROS 1 (noetic gazebo_ros_diff_drive.cpp:461-467): the pose's covariance fixed, the twist's zero;
        # <covariance_*> are not read there (said as not its parameters)
        params["pose_covariance_diagonal"] = [1e-5, 1e-5, _UNKNOWN, _UNKNOWN, _UNKNOWN, 1e-3]
    else:
        params["pose_covariance_diagonal"] = params["twist_covariance_diagonal"] = _covariance(
            r, (1e-5, 1e-5, 1e-3)
        )
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


def _diff_drive_gz(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    lefts = [e.text.strip() for e in r.children("left_joint") if e.text]
    rights = [e.text.strip() for e in r.children("right_joint") if e.text]
    model = f"model/{g.model}"  # gz-sim's defaults: /model/<model>/cmd_vel, .../odometry, .../tf
    params: dict[str, Any] = {
        "wheel_separation": r.float("wheel_separation"),
        "wheel_radius": r.float("wheel_radius"),
        # odom_publish_frequency is how often it publishes (default 50 Hz); it controls at every step
        "rate": r.float("odom_publish_frequency") or None,
        "cmd_topic": ros_topic(r.text("topic")) or f"{model}/cmd_vel",
        "odom_topic": ros_topic(r.text("odom_topic")) or f"{model}/odometry",
        "tf_topic": ros_topic(r.text("tf_topic")) or f"{model}/tf",
        "odom_frame": r.text("frame_id"),
        "base_frame": g.frame(r.text("child_frame_id")),
    }
    accel = r.float("max_linear_acceleration")
    radius = params["wheel_radius"]
    if accel and radius:
        params["max_wheel_acceleration"] = accel / radius
    return by_wheels(params, lefts, rights)


def _skid_steer(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
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
        "cmd_topic": ros_topic(r.text("commandTopic")) or remap.get("cmd_vel"),
        "odom_topic": ros_topic(r.text("odometryTopic")) or remap.get("odom"),
        "odom_frame": r.text("odometryFrame", "odometry_frame"),
        "base_frame": g.frame(r.text("robotBaseFrame", "robot_base_frame")),
    }
    tf = r.bool("broadcastTF", "publish_odom_tf")
    if tf is not None:
        params["publish_tf"] = tf
    params["pose_covariance_diagonal"] = params["twist_covariance_diagonal"] = _covariance(
        r, (1e-4, 1e-4, 1e-2)
    )
    return "skid_steer", params


def _planar_move(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    params: dict[str, Any] = {
        "rate": r.float("odometryRate", "publish_rate", "update_rate") or None,
        "cmd_topic": ros_topic(r.text("commandTopic")) or remap.get("cmd_vel"),
        "odom_topic": ros_topic(r.text("odometryTopic")) or remap.get("odom"),
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
    ros1 = ("commandTopic", "odometryTopic", "odometryFrame", "odometryRate", "robotBaseFrame")
    if any(r.el.find(t) is not None for t in ros1):
        # ROS 1 (noetic gazebo_ros_planar_move.cpp:292-297): the pose's covariance fixed, the twist's zero
        params["pose_covariance_diagonal"] = [1e-5, 1e-5, _UNKNOWN, _UNKNOWN, _UNKNOWN, 1e-3]
    else:
        params["pose_covariance_diagonal"] = params["twist_covariance_diagonal"] = _covariance(
            r, (1e-5, 1e-5, 1e-3)
        )
    return "planar_move", params


def _joint_states(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    joints: list[str] = []
    for el in r.children("jointName", "joint_name"):
        joints += [j.strip() for j in (el.text or "").split(",") if j.strip()]
    topic = ros_topic(r.text("topic")) or remap.get("joint_states")
    if topic is None and r.el.get("filename", "").startswith(("gz-sim", "ignition-gazebo", "libgz-sim")):
        topic = f"world/default/model/{g.model}/joint_state"  # gz-sim's default (the world is "default")
    params: dict[str, Any] = {
        "joints": joints or None,
        "rate": r.float("updateRate", "update_rate") or None,
        "topic": topic,
    }
    return "joint_states", params


def _imu_model(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    """ROS 1 gazebo_ros_imu (a model plugin): N(0, <gaussianNoise>) on every rate and acceleration, and
    nothing else; it reads no `<imu>` block (TurtleBot3's is not used by Gazebo either)."""
    noise = r.float("gaussianNoise")
    params: dict[str, Any] = {
        "link": r.text("bodyName", "body_name"),
        "topic": ros_topic(r.text("topicName", "topic_name")) or remap.get("imu") or "imu",
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
        if el is not None and (floats(el.text, 3) is None or any(floats(el.text, 3) or [])):
            g.note(el, f"<{tag}> in {r.el.get('filename')!r} is ignored")
    return "imu", params


def _odometry_publisher(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> tuple[str, dict[str, Any]]:
    """gz-sim's OdometryPublisher (src/systems/odometry_publisher/OdometryPublisher.cc at 93bbf3ed): the
    model's world pose composed with `<xyz_offset>`/`<rpy_offset>` (:386 `rawPose * offset`), frames
    `<odom_frame>` (default `<model>/odom`, :158) and `<robot_base_frame>` (`<model>/base_footprint`, :188),
    `<dimensions>` 2 (default: x, y, yaw rate only) or 3, twist in the body frame with `<gaussian_noise>`
    on each component (the pose is not noised), at `<odom_publish_frequency>` (50), and the pose again on
    `<tf_topic>` (`/model/<model>/pose`). Its twist is the mean of the last 10 publishes' pose differences
    (:128); ours is the body's velocity at the publish (the same at steady motion)."""
    dims = r.float("dimensions")
    params: dict[str, Any] = {
        "topic": ros_topic(r.text("odom_topic")) or f"model/{g.model}/odometry",
        "frame_id": g.frame(r.text("odom_frame") or "odom"),
        "child_frame_id": g.frame(r.text("robot_base_frame") or "base_footprint"),
        "rate": r.float("odom_publish_frequency") or 50.0,
        "planar": dims != 3,
        "offset_frame": "body",
        "linear_velocity_frame": "body",
        "angular_velocity_frame": "body",
        "publish_tf": True,
        "tf_topic": ros_topic(r.text("tf_topic")) or f"model/{g.model}/pose",
    }
    if dims is not None and dims not in (2, 3):
        g.note(
            r.child("dimensions"),
            f"<dimensions> {dims:g}: gz-sim accepts 2 or 3 (it then does not start); 2 is used",
        )
    for key, tag in (("xyz_offset", "xyz_offset"), ("rpy_offset", "rpy_offset")):
        values = floats(r.text(tag), 3)
        if values is not None:
            params[key] = tuple(values)
    noise = r.float("gaussian_noise")
    if noise:
        params["twist_noise"] = noise
    cov = r.child("odom_covariance_topic")
    if cov is not None:
        g.note(
            cov,
            "<odom_covariance_topic> is not published: gz-sim's OdometryWithCovariance carries the same pose "
            "and twist as the odometry topic, with the noise's variance",
        )
    return "ground_truth", params


_MODEL_PLUGINS = {
    "gazebo_ros_diff_drive": _diff_drive_classic,
    "gz-sim-diff-drive-system": _diff_drive_gz,
    "gz-sim-diffdrive-system": _diff_drive_gz,
    "gazebo_ros_skid_steer_drive": _skid_steer,
    "gazebo_ros_planar_move": _planar_move,
    "gazebo_ros_joint_state_publisher": _joint_states,
    "gz-sim-joint-state-publisher-system": _joint_states,
    "gazebo_ros_imu": _imu_model,
    "gz-sim-odometry-publisher-system": _odometry_publisher,
    "gazebo_ros_control": ros_control,
    "gazebo_ros2_control": ros_control,
    "gz_ros2_control-system": ros_control,
    "ign_ros2_control-system": ros_control,
}
_MODEL_PLUGINS.update(thirdparty.MODEL_PLUGINS)  # hector_gazebo_plugins (.thirdparty)
_MODEL_PLUGINS.update(drives3p.MODEL_PLUGINS)  # force-based drives, p3d, world odometry (.drives3p)
_MODEL_PLUGINS.update(field_sensors.MODEL_PLUGINS)  # gazebo_ros_ft_sensor (.field_sensors)
_MODEL_PLUGINS.update(gz_mecanum.MODEL_PLUGINS)  # gz-sim's MecanumDrive (.gz_mecanum)
# forks of gz_ros2_control / ign_ros2_control / gazebo_ros2_control / gazebo_ros_control keep the name's tail
_CONTROL_FORK = re.compile(r"(^|[_-])(gz|ign|gazebo)_ros2?_control(-system|_plugin)?$")
