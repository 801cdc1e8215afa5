"""The catalogue of Gazebo plugins and sensors people put in robot descriptions: for each, where it comes from
(its package and source file), what it becomes here, and each of its parameters: as in Gazebo (`same`),
approximated (`approx`, with how), or said and ignored (`ignored`, with what Gazebo does with it).

The readers (runner.compile.gazebo.model_plugins, .sensor_plugins, .thirdparty) take the parameter names a
plugin has from here: a tag in a plugin's block that is not one of them is reported as a typo or a leftover
Gazebo ignores too, and an `ignored` one is reported with its reason. docs/plugin_catalogue.md is generated
from this table (tests/test_catalogue.py keeps it in step; `python -c "from runner.compile.gazebo.catalogue
import render; print(render(), end='')" > docs/plugin_catalogue.md` writes it).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

Status = Literal["same", "approx", "ignored"]


@dataclass(frozen=True)
class Param:
    names: tuple[str, ...]  # every spelling the plugin reads (ROS 1 camelCase, ROS 2 snake_case)
    status: Status
    how: str = ""  # approx: how; ignored: what Gazebo does with it and why we do not


@dataclass(frozen=True)
class PluginDoc:
    bases: tuple[
        str, ...
    ]  # `plugin_base()` of its filenames (`gazebo_ros_diff_drive`, `gz-sim-diff-drive-system`)
    kind: Literal["model", "sensor"]
    origin: str  # the package and distribution, and the source file it is read from
    becomes: str  # what it is here (our plugin type, or why nothing)
    params: tuple[Param, ...] = field(default_factory=tuple)

    def names(self) -> set[str]:
        return {n for p in self.params for n in p.names}

    def ignored(self) -> dict[str, str]:
        return {n: p.how for p in self.params if p.status == "ignored" for n in p.names}


def _p(names: str, status: Status = "same", how: str = "") -> Param:
    return Param(tuple(names.split()), status, how)


_COMMON = (
    _p("alwaysOn always_on", "ignored", "sensors and plugins are always on"),
    _p("robotNamespace", "approx", "the robot's namespace is the scenario's (said when it differs)"),
    _p("ros", "approx", "`<remapping>` kept; `<namespace>` replaced by the robot's (said)"),
    _p("rosDebugLevel", "ignored", "ROS debug level"),
)

CATALOGUE: tuple[PluginDoc, ...] = (
    PluginDoc(
        ("gazebo_ros_diff_drive",),
        "model",
        "gazebo_plugins (ROS 1 Noetic, ROS 2 Humble/Jazzy): src/gazebo_ros_diff_drive.cpp",
        "diff_drive (skid_steer with num_wheel_pairs > 1)",
        (
            *_COMMON,
            _p("updateRate update_rate"),
            _p("leftJoint rightJoint left_joint right_joint"),
            _p("wheelSeparation wheel_separation wheelDiameter wheel_diameter"),
            _p("num_wheel_pairs"),
            _p("wheelAcceleration max_wheel_acceleration"),
            _p("wheelTorque max_wheel_torque", "approx", "a force limit on a velocity servo (bench/)"),
            _p("commandTopic odometryTopic odometryFrame robotBaseFrame odometry_frame robot_base_frame"),
            _p("publishWheelTF publishOdomTF publishWheelJointState publishTf publish_odom publish_odom_tf"),
            _p("publish_wheel_tf"),
            _p("odometrySource odometry_source"),
            _p("covariance_x covariance_y covariance_yaw"),
            _p("legacyMode", "ignored", "wheel order is taken from the joint names"),
        ),
    ),
    PluginDoc(
        ("gz-sim-diff-drive-system", "gz-sim-diffdrive-system"),
        "model",
        "gz-sim (Harmonic): src/systems/diff_drive/DiffDrive.cc",
        "diff_drive",
        (
            _p("left_joint right_joint wheel_separation wheel_radius"),
            _p("odom_publish_frequency"),
            _p("max_linear_acceleration min_linear_acceleration max_angular_acceleration"),
            _p("min_angular_acceleration max_linear_velocity min_linear_velocity max_angular_velocity"),
            _p("min_angular_velocity max_velocity max_acceleration max_jerk min_jerk"),
            _p("topic odom_topic tf_topic frame_id child_frame_id"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_skid_steer_drive",),
        "model",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_skid_steer_drive.cpp",
        "skid_steer",
        (
            *_COMMON,
            _p("updateRate update_rate"),
            _p("leftFrontJoint rightFrontJoint leftRearJoint rightRearJoint"),
            _p("left_front_joint right_front_joint left_rear_joint right_rear_joint"),
            _p("wheelSeparation wheelDiameter"),
            _p("torque", "approx", "a force limit on a velocity servo"),
            _p("commandTopic odometryTopic odometryFrame robotBaseFrame broadcastTF"),
            _p("covariance_x covariance_y covariance_yaw"),
        ),
    ),
)


def entry(base: str) -> PluginDoc | None:
    """The catalogue's entry of a plugin (by `plugin_base()` of its filename)."""
    return _BY_BASE.get(base)


_BY_BASE = {b: e for e in CATALOGUE for b in e.bases}


def render() -> str:
    """docs/plugin_catalogue.md."""
    out = [
        "# Plugin catalogue",
        "",
        "Generated from `runner/compile/gazebo/catalogue.py` (tests/test_catalogue.py keeps it in step):",
        "the Gazebo plugins and sensors a robot description may name, what each becomes here, and each",
        "parameter: **same** as in Gazebo, **approx**imated (how), or **ignored** and said (what Gazebo does",
        "with it). A parameter not listed is said as a typo or a leftover that Gazebo ignores too. How each",
        "plugin behaves, measured: [gazebo_parity.md](gazebo_parity.md).",
        "",
    ]
    for e in sorted(CATALOGUE, key=lambda e: (e.kind, e.bases[0])):
        out += [f"## `{'`, `'.join(e.bases)}` ({e.kind})", "", f"{e.origin}. Becomes: {e.becomes}.", ""]
        if e.params:
            out += ["| parameter | here | how |", "|---|---|---|"]
            for p in e.params:
                names = ", ".join(f"`{n}`" for n in p.names)
                out.append(f"| {names} | {p.status} | {p.how} |")
            out.append("")
    return "\n".join(out)
