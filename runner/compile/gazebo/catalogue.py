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
    # --- third-party force-based drives and world odometry (runner.compile.gazebo.drives3p) ---
    PluginDoc(
        ("gazebo_ros_force_based_move",),
        "model",
        "hector_gazebo_plugins (ROS 1; tu-darmstadt-ros-pkg/hector_gazebo melodic-devel, kinetic-devel): "
        "hector_gazebo_plugins/src/gazebo_ros_force_based_move.cpp:56-144 (parameters), :200-256 (force), "
        ":285-398 (odometry); its ROS 2 port in the gazebo_plugins namespace (e.g. "
        "eduardoespino2002/dots_gazebo2: gazebo_plugins/src/gazebo_ros_force_based_move.cpp:155-217, "
        ":270-333, :380-394), told apart by its snake_case parameters",
        "force_based_move (a force and a torque on the base tracking cmd_vel through P gains)",
        (
            *_COMMON,
            _p("commandTopic odometryTopic odometryFrame publishOdometryTf"),
            _p(
                "robotBaseFrame robot_base_frame",
                "approx",
                "the odometry's child frame; the force acts on the robot's root at its origin (Gazebo: on "
                "that link, at its centre of mass); a name the robot lacks is said",
            ),
            _p(
                "odometryRate",
                "approx",
                "Gazebo publishes once more than 1/rate has passed (a step late each period: 19.6 Hz for 20 "
                "at 1 ms); here at exactly the rate; 0 or less: nothing published, as in Gazebo",
            ),
            _p(
                "x_velocity_p_gain y_velocity_p_gain yaw_velocity_p_gain",
                "approx",
                "a MuJoCo velocity actuator of that gain, integrated implicitly: the same lag m/kp; where "
                "kp·dt/m nears 1 it settles in a step or two without the explicit step's overshoot",
            ),
            _p("allowLateralMotion commandTimeoutDuration"),
            _p("odometry_frame publish_rate publish_odom publish_odom_tf"),
            _p("vel_p_gain omega_p_gain force_lim torque_lim"),
            _p(
                "vel_i_gain omega_i_gain vel_i_lim omega_i_lim",
                "approx",
                "the integral is updated at the control rate (every physics step up to 1 kHz)",
            ),
            _p(
                "update_rate",
                "ignored",
                "the ROS 2 port computes a period from it but applies the force at every step; so do we",
            ),
            _p(
                "covariance_x covariance_y covariance_yaw",
                "ignored",
                "the ROS 2 port's fixed covariances; the odometry carries hector's (x, y 0.001, yaw 0.01 "
                "still / 100 turning)",
            ),
        ),
    ),
    PluginDoc(
        ("robotnik_force_based_move",),
        "model",
        "robotnik_gazebo_plugins (ROS 1; RobotnikAutomation/robotnik_gazebo_plugins master): "
        "robotnik_force_based_move/src/robotnik_force_based_move.cpp:56-157 (parameters), :215-299 "
        "(force, watchdog), :335-448 (odometry, hector's)",
        "force_based_move with hold_on_timeout",
        (
            *_COMMON,
            _p("commandTopic odometryTopic odometryFrame publishOdometryTf"),
            _p(
                "robotBaseFrame",
                "approx",
                "the odometry's child frame; the force acts on the robot's root at its origin",
            ),
            _p("odometryRate", "approx", "published at exactly the rate (Gazebo: a step late each period)"),
            _p(
                "x_velocity_p_gain y_velocity_p_gain yaw_velocity_p_gain",
                "approx",
                "a velocity actuator of that gain, integrated implicitly (the lag m/kp)",
            ),
            _p(
                "commandWatchdog",
                "approx",
                "after it (2 s) no force and the base put back where it was, at rest, before every step "
                "(Gazebo: after the step), so one step of gravity and contact shows in its velocity",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_p3d",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_p3d.cpp:65-128 parameters, :278-340 pose and twist; "
        "ROS 2 Humble/Jazzy: src/gazebo_ros_p3d.cpp:102-190)",
        "ground_truth (twist in the world frame)",
        (
            *_COMMON,
            _p("bodyName body_name topicName topic_name"),
            _p(
                "frameName frame_name",
                "same",
                "world/map: the world; a link's name: the pose relative to it, as the source computes it",
            ),
            _p("xyzOffset xyz_offset xyz_offsets rpyOffset rpy_offset rpy_offsets"),
            _p(
                "gaussianNoise gaussian_noise",
                "same",
                "white noise on the twist only; variance in covariance",
            ),
            _p(
                "updateRate update_rate",
                "approx",
                "0 (its default): every physics step, here too (asked as 1 kHz, capped by the step)",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_world_odometry",),
        "model",
        "pal_gazebo_plugins (ROS 1 melodic-devel: src/gazebo_world_odometry.cpp:36-73 parameters, :132-181 "
        "message; ROS 2 humble-devel: src/gazebo_world_odometry.cpp:102-192, :234-297)",
        "ground_truth (ROS 1: linear twist in the world frame, angular in the link's; ROS 2: both the "
        "link's)",
        (
            *_COMMON,
            _p("topicName frameName bodyName"),
            _p("updateRate", "approx", "default 1000 Hz: every physics step of ours (capped by the step)"),
            _p("body_name topic_name xyz_offset xyz_offsets rpy_offset rpy_offsets gaussian_noise"),
            _p(
                "frame_name",
                "approx",
                "a link's name gives the pose relative to it; the source leaves the twist as it is, here "
                "it is taken relative too (p3d's way)",
            ),
            _p("update_rate", "approx", "0 (its default): every physics step"),
        ),
    ),
    PluginDoc(
        ("robotnik_gazebo_ground_truth_odom",),
        "model",
        "robotnik_gazebo_plugins (ROS 1 master): robotnik_gazebo_ground_truth_odom/src/"
        "robotnik_gazebo_ground_truth_odom.cpp:58-150 parameters, :239-413 message",
        "ground_truth (twist in the link's frame, TF when broadcastTF)",
        (
            *_COMMON,
            _p("bodyName topicName frameName worldFrameName broadcastTF xyzOffset rpyOffset"),
            _p("worldBodyName", "same", "world/map: the world; a link: the pose relative to it"),
            _p("gaussianNoise", "same", "white noise on the twist only"),
            _p("updateRate", "approx", "0 (its default): every physics step"),
        ),
    ),
    # --- gz-sim's MecanumDrive (runner.compile.gazebo.gz_mecanum), its wheels' friction (.surface) ---
    PluginDoc(
        ("gz-sim-mecanum-drive-system",),
        "model",
        "gz-sim (Fortress to Harmonic): src/systems/mecanum_drive/MecanumDrive.cc (Configure: parameters; "
        "UpdateVelocity: the inverse kinematics; PostUpdate: MecanumDriveOdometry)",
        "mecanum_drive (its wheels' mecanum friction, or else rollers, said)",
        (
            _p(
                "front_left_joint front_right_joint back_left_joint back_right_joint",
                "approx",
                "the first joint of each corner is driven; further ones are said",
            ),
            _p("wheel_separation wheelbase wheel_radius"),
            _p("topic odom_topic tf_topic frame_id child_frame_id odom_publish_frequency"),
            _p("min_velocity max_velocity min_linear_velocity max_linear_velocity min_angular_velocity"),
            _p("max_angular_velocity min_acceleration max_acceleration min_linear_acceleration"),
            _p("max_linear_acceleration min_angular_acceleration max_angular_acceleration min_jerk"),
            _p("max_jerk min_linear_jerk max_linear_jerk min_angular_jerk max_angular_jerk"),
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
