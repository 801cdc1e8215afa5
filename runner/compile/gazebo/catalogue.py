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
    # ---- sensors: Range, field sensors, force/torque, depth limits (issue 38, part A) ----
    PluginDoc(
        ("gazebo_ros_range",),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_range.cpp:52-158 parameters, :302-316 the range",
        "lidar with only a sensor_msgs/Range (range_style gazebo_ros_range: the nearest noise-free ray, "
        "max_range when none, its noise capped at max_range)",
        (
            _p("alwaysOn", "ignored", "sensors are always on"),
            _p("robotNamespace", "approx", "the robot's namespace is the scenario's (said when it differs)"),
            _p("topicName", "same", "default `/range`: `range` under the robot's namespace"),
            _p("frameName", "same", "default `/world`: `world`"),
            _p("radiation", "same", "`ultrasound` (the default) is ULTRASOUND, anything else INFRARED"),
            _p("fov", "same", "the Range's field_of_view, default 0.05 (not the ray fan's)"),
            _p("gaussianNoise", "same", "added to the nearest ray short of max_range, then capped at it"),
            _p("updateRate", "same", "throttles the sensor's `<update_rate>` (every ceil(sensor/plugin)-th)"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_ray_sensor",),
        "sensor",
        "gazebo_plugins (ROS 2 Humble/Jazzy): src/gazebo_ros_ray_sensor.cpp:101-237; gazebo_ros "
        "conversions/sensor_msgs.hpp:291-316 (Range)",
        "lidar publishing the one `<output_type>` on `~/out`: LaserScan, PointCloud2 (the default), or a "
        "Range "
        "(range_style gazebo_ros_ray_sensor: the nearest REP 117-masked ray, +inf when none)",
        (
            _p(
                "ros",
                "approx",
                "`<remapping>` kept (`~/out:=x`); `<namespace>` replaced by the robot's (said)",
            ),
            _p(
                "output_type",
                "approx",
                "sensor_msgs/PointCloud is published as a PointCloud2 (said); an "
                "invalid type publishes nothing, in Gazebo too (said)",
            ),
            _p(
                "radiation_type",
                "same",
                "infrared (the default) or ultrasound; anything else publishes nothing, in Gazebo too (said)",
            ),
            _p("frame_name", "same", "default: the sensor's link"),
            _p(
                "min_intensity",
                "ignored",
                "every return has intensity 0 here (no `<laser_retro>`); said "
                "above 0, where Gazebo would drop the rays of surfaces without retro-reflectivity",
            ),
        ),
    ),
    PluginDoc(
        ("sensor:magnetometer",),
        "sensor",
        "gz-sensors (Harmonic): src/MagnetometerSensor.cc:104-198; gz-sim src/systems/magnetometer/"
        "Magnetometer.cc:359-379 topic and field; ros_gz_bridge: sensor_msgs/MagneticField",
        "magnetometer (the world's field turned into the sensor frame)",
        (
            _p(
                "topic",
                "same",
                "default the scoped `.../sensor/<name>/magnetometer` (Harmonic); classic "
                "Gazebo has no ROS plugin for it: published on `magnetometer`, said as implicit",
            ),
            _p("update_rate", "same", "capped at the physics step's rate (said)"),
            _p("pose", "same"),
            _p("gz_frame_id", "approx", "under the robot's namespace"),
            _p("always_on visualize enable_metrics", "ignored", "sensors are always on; GUI; diagnostics"),
            _p(
                "magnetometer.x.noise magnetometer.y.noise magnetometer.z.noise",
                "approx",
                "mean and stddev per axis; a bias (bias_mean, bias_stddev) is said and left out",
            ),
            _p(
                "magnetic_field",
                "approx",
                "the world's: SDF's default field (5.5645e-6, 22.8758e-6, "
                "-42.3884e-6 T); gz-sim's table at the world's <spherical_coordinates> is not read",
            ),
        ),
    ),
    PluginDoc(
        ("sensor:air_pressure",),
        "sensor",
        "gz-sensors (Harmonic): src/AirPressureSensor.cc:41-52 the atmosphere, :113-203; gz-sim src/systems/"
        "air_pressure/AirPressure.cc:186-210; ros_gz_bridge: sensor_msgs/FluidPressure",
        "air_pressure (the RotorS standard atmosphere at reference_altitude + the sensor's world z)",
        (
            _p("topic", "same", "default `.../sensor/<name>/air_pressure` (Harmonic); classic: implicit"),
            _p("update_rate", "same", "capped at the physics step's rate (said)"),
            _p("pose", "same"),
            _p("gz_frame_id", "approx", "under the robot's namespace"),
            _p("always_on visualize enable_metrics", "ignored", "sensors are always on; GUI; diagnostics"),
            _p("air_pressure.reference_altitude", "same"),
            _p(
                "air_pressure.pressure.noise",
                "approx",
                "mean and stddev; the message's variance is "
                "sqrt(stddev), as gz-sensors writes it; a bias is said and left out",
            ),
        ),
    ),
    PluginDoc(
        ("sensor:altimeter",),
        "sensor",
        "gz-sensors (Harmonic): src/AltimeterSensor.cc:117-131 noise; gz-sim src/systems/altimeter/"
        "Altimeter.cc:186-212 topic and reference, :265-266; ros_gz_bridge: ros_gz_interfaces/msg/Altimeter",
        "altimeter (world z less the start z, world vertical velocity, the start z as the reference)",
        (
            _p("topic", "same", "default `.../sensor/<name>/altimeter` (Harmonic); classic: implicit"),
            _p("update_rate", "same", "capped at the physics step's rate (said)"),
            _p("pose", "same"),
            _p("gz_frame_id", "approx", "under the robot's namespace"),
            _p("always_on visualize enable_metrics", "ignored", "sensors are always on; GUI; diagnostics"),
            _p(
                "altimeter.vertical_position.noise altimeter.vertical_velocity.noise",
                "approx",
                "mean and stddev; a bias is said and left out",
            ),
        ),
    ),
    PluginDoc(
        ("sensor:force_torque",),
        "sensor",
        "gz-sensors (Harmonic): src/ForceTorqueSensor.cc:126-155, 199-257; gz-sim src/systems/force_torque/"
        "ForceTorque.cc:262-320 (the joint's transmitted wrench); ros_gz_bridge: geometry_msgs/WrenchStamped",
        "force_torque at the joint's child link (MuJoCo's force and torque sensors, turned and signed); in a "
        "link's block (Gazebo mounts it on joints only): said and left out",
        (
            _p(
                "topic",
                "same",
                "default `.../joint/<joint>/sensor/<name>/forcetorque` (Harmonic); classic: "
                "`<name>/forcetorque`, implicit",
            ),
            _p("update_rate", "same", "capped at the physics step's rate (said)"),
            _p("pose", "same", "the sensor frame and the point torques are about"),
            _p("gz_frame_id", "approx", "under the robot's namespace"),
            _p("always_on visualize enable_metrics", "ignored", "sensors are always on; GUI; diagnostics"),
            _p("force_torque.frame", "same", "child (default), parent, sensor"),
            _p("force_torque.measure_direction", "same", "child_to_parent (default), parent_to_child"),
            _p(
                "force_torque.force.noise force_torque.torque.noise",
                "approx",
                "mean and stddev per axis; a bias is said and left out",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_ft_sensor",),
        "model",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_ft_sensor.cpp:64-111, 185-216; (ROS 2 Humble/Jazzy): "
        "src/gazebo_ros_ft_sensor.cpp:100-215",
        "force_torque at the joint's child link: the joint's wrench on it (parent_to_child), in its frame",
        (
            *_COMMON,
            _p("jointName joint_name", "same", "required (ROS 1 also `<topicName>`): without, nothing"),
            _p("topicName", "same", "ROS 2: `wrench` under the namespace, remapped by `<ros>`"),
            _p("gaussianNoise gaussian_noise", "same", "N(0, noise) on each of the six components"),
            _p("updateRate update_rate", "approx", "0 (the default): every physics step; here 100 Hz (said)"),
            _p("body_name", "ignored", "Link::WorldForce is what other plugins apply, none here: left out"),
            _p("frame_name", "ignored", "read only with body_name (Gazebo warns too)"),
        ),
    ),
    PluginDoc(
        ("hector_gazebo_ros_magnetic",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel, its ROS 2 ports): src/gazebo_ros_magnetic.cpp:60-173; "
        "sensor_model.h (the error model), update_timer.h (the rate)",
        "magnetometer (field from magnitude/heading/declination/inclination, Vector3Stamped by default)",
        (
            *_COMMON,
            _p("bodyName topicName frameId"),
            _p("updateRate updatePeriod", "approx", "none or 0: every physics step; here 50 Hz (said)"),
            _p("updateOffset", "ignored", "readings are taken at multiples of the period (said)"),
            _p("magnitude referenceHeading declination inclination useMagneticFieldMsgs"),
            _p("offset drift driftFrequency gaussianNoise"),
            _p("scaleError", "ignored", "fields are not scaled (said when not 1)"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_depth_camera", "gazebo_ros_openni_kinect"),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_depth_camera.cpp:126-129, 675-766; "
        "src/gazebo_ros_openni_kinect.cpp:101-108, 361-465; src/gazebo_ros_camera_utils.cpp (names, rate)",
        "depth_camera (out_of_range nan: NaN in the image and the cloud outside the cut-offs)",
        (
            *_COMMON,
            _p("cameraName imageTopicName cameraInfoTopicName depthImageTopicName"),
            _p("depthImageCameraInfoTopicName pointCloudTopicName frameName"),
            _p("updateRate", "same", "throttles the sensor's `<update_rate>`"),
            _p("pointCloudCutoff", "same", "default 0.4 m: at or below, NaN"),
            _p(
                "pointCloudCutoffMax",
                "same",
                "openni_kinect only, default 5 m: at or beyond, NaN (said "
                "and unused in depth_camera, as there)",
            ),
            _p("triggerTopicName", "ignored", "the camera publishes at its rate"),
            _p("Cx Cy CxPrime focalLength", "ignored", "CameraInfo is the ideal pinhole of <horizontal_fov>"),
            _p("hackBaseline borderCrop autoDistortion", "ignored", "stereo/rectification only"),
            _p(
                "distortionK1 distortionK2 distortionK3 distortionT1 distortionT2",
                "ignored",
                "images are not distorted (said when not 0)",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_camera",),
        "sensor",
        "gazebo_plugins (ROS 2 Humble/Jazzy): src/gazebo_ros_camera.cpp:476-478 depth limits, :642-768; "
        "(ROS 1 Noetic, the same file name): src/gazebo_ros_camera_utils.cpp",
        "camera, or depth_camera on a depth sensor (out_of_range inf: -inf/+inf in the image and the cloud)",
        (
            *_COMMON,
            _p("camera_name frame_name", "same", "default: the sensor's name; the link"),
            _p("min_depth", "same", "default 0.4 m: at or below, -inf (x = y = z in the cloud)"),
            _p("max_depth", "same", "default +inf: at or beyond, +inf"),
            _p("triggered", "ignored", "the camera publishes at its rate (said)"),
            _p("cx cy focal_length", "ignored", "CameraInfo is the ideal pinhole of <horizontal_fov>"),
            _p("hack_baseline border_crop", "ignored", "stereo/rectification only"),
            _p(
                "distortion_k1 distortion_k2 distortion_k3 distortion_t1 distortion_t2",
                "ignored",
                "images are not distorted (said when not 0)",
            ),
            _p(
                "cameraName imageTopicName cameraInfoTopicName frameName updateRate",
                "same",
                "the ROS 1 plugin of the same file name (told apart by its tags)",
            ),
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
    # --- gz-sim's OdometryPublisher (runner.compile.gazebo.model_plugins._odometry_publisher) ---
    PluginDoc(
        ("gz-sim-odometry-publisher-system",),
        "model",
        "gz-sim (Fortress to Harmonic): src/systems/odometry_publisher/OdometryPublisher.cc at 93bbf3ed "
        "(Configure :150-290, UpdateOdometry :360-470)",
        "ground_truth (the model's world pose, body-frame twist)",
        (
            _p("odom_topic odom_frame robot_base_frame odom_publish_frequency tf_topic"),
            _p("xyz_offset rpy_offset", "same", "composed after the pose, `rawPose * offset` (:386)"),
            _p("dimensions", "same", "2: x, y and the yaw rate only; 3: everything"),
            _p("gaussian_noise", "same", "on each twist component; the pose is not noised, as there"),
            _p(
                "odom_covariance_topic",
                "ignored",
                "gz-sim publishes the same odometry with the noise's variance there (said)",
            ),
        ),
    ),
    # ---- issue 38, the catalogue of the plugins people use (mapped or not), each read from its source ----
    # gazebo_ros_pkgs at noetic-devel f9e1a460 (ROS 1) and ros2 d52f7c47 (Humble/Jazzy); gz-sim at 93bbf3ed
    # (Harmonic and later; Fortress's names are the same with `ignition-gazebo-`). An entry that says
    # "not supported" is one no reader maps: its parameters are ignored (the plugin is said once, with why).
    PluginDoc(
        ("gazebo_ros_planar_move",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_planar_move.cpp:47-126; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_planar_move.cpp:141-195)",
        "planar_move (the base's velocity set to the command, in its own frame)",
        (
            *_COMMON,
            _p("commandTopic odometryTopic odometryFrame robotBaseFrame odometry_frame robot_base_frame"),
            _p(
                "odometryRate publish_rate update_rate",
                "approx",
                "the odometry's rate; ROS 2's `update_rate` (its control rate) stands in when `publish_rate` "
                "is absent; the velocity is set at every step",
            ),
            _p("cmdTimeout cmd_timeout", "same", "ROS 1 Noetic: no command for that long stops the base"),
            _p("publish_odom publish_odom_tf"),
            _p("covariance_x covariance_y covariance_yaw", "ignored", "the odometry's fixed covariances"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_joint_state_publisher", "gz-sim-joint-state-publisher-system"),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_joint_state_publisher.cpp:51-75; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_joint_state_publisher.cpp:97-132); gz-sim: src/systems/joint_state_publisher/"
        "JointStatePublisher.cc:69-107",
        "joint_states (the named joints, or every joint where gz-sim names none)",
        (
            *_COMMON,
            _p("jointName joint_name", "same", "ROS 1: one comma-separated list; ROS 2, gz-sim: repeated"),
            _p("updateRate update_rate"),
            _p("topic", "same", "gz-sim: default `world/<world>/model/<model>/joint_state`"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_imu",),
        "model",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_imu.cpp:70-136 (a model plugin; ROS 2 has only the "
        "sensor plugin gazebo_ros_imu_sensor)",
        "imu on `<bodyName>` (N(0, gaussianNoise) on every rate and acceleration)",
        (
            *_COMMON,
            _p("bodyName body_name topicName topic_name frameName frame_name"),
            _p("updateRate update_rate updateRateHZ", "same", "0 (the default): every physics step"),
            _p("gaussianNoise", "same", "white noise on every rate and acceleration"),
            _p("xyzOffset rpyOffset", "ignored", "offsets of the reported pose (said)"),
            _p("serviceName", "ignored", "a ROS service that calibrates; no ROS services here"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_control",),
        "model",
        "gazebo_ros_control (ROS 1 Noetic, gazebo_ros_pkgs): src/gazebo_ros_control_plugin.cpp:85-157",
        "the scenario's `controllers:` (the controller manager's parameters a launch file loads)",
        (
            _p("robotNamespace", "approx", "the robot's namespace is the scenario's (said when it differs)"),
            _p("robotParam", "same", "the description is the robot's"),
            _p(
                "legacyModeNS",
                "ignored",
                "kinetic/melodic only (namespaced controllers); Noetic does not read it, nor do we",
            ),
            _p("controlPeriod", "approx", "controllers act at every physics step (said)"),
            _p("robotSimType", "approx", "DefaultRobotHWSim's interfaces; a custom one is said"),
            _p("eStopTopic", "ignored", "Gazebo stops the controllers on it; not subscribed (said)"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros2_control", "gz_ros2_control-system", "ign_ros2_control-system"),
        "model",
        "gazebo_ros2_control (humble: gazebo_ros2_control/src/gazebo_ros2_control_plugin.cpp:174-231; "
        "master: :252-287); gz_ros2_control (jazzy: gz_ros2_control/src/gz_ros2_control_plugin.cpp:281-338; "
        "humble: ign_ros2_control/src/ign_ros2_control_plugin.cpp)",
        "controller_manager with the controllers files of `<parameters>`",
        (
            _p("parameters", "same", "the controllers files (relative to the description's file)"),
            _p("ros", "approx", "`<remapping>` kept; `<namespace>` replaced by the robot's (said)"),
            _p("controller_manager_name controller_manager_prefix_node_name"),
            _p("robot_param robot_param_node", "same", "the description is the robot's"),
            _p("hold_joints position_proportional_gain"),
        ),
    ),
    PluginDoc(
        ("hector_gazebo_ros_imu",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/gazebo_ros_imu.cpp:75-153; include/"
        "hector_gazebo_plugins/sensor_model.h:106-115 (the error model's tags per prefix), "
        "update_timer.h:56-80",
        "imu (hector's error model: offset, drifting bias, white noise; the orientation tilted by the bias)",
        (
            *_COMMON,
            _p("bodyName frameId topicName biasTopicName"),
            _p("updateRate updatePeriod", "same", "none or 0: every physics step"),
            _p("updateOffset", "ignored", "readings are taken at multiples of the period"),
            _p("accelOffset accelDrift accelDriftFrequency accelGaussianNoise"),
            _p("rateOffset rateDrift rateDriftFrequency rateGaussianNoise"),
            _p("yawOffset yawDrift yawDriftFrequency"),
            _p("yawGaussianNoise", "ignored", "only fills hector's orientation covariance (said)"),
            _p("gaussianNoise", "same", "the older spelling of both white noises"),
            _p("accelScaleError rateScaleError yawScaleError", "ignored", "read by hector, used for nothing"),
            _p("xyzOffset", "ignored", "read and not applied by hector either (said when not 0)"),
            _p("rpyOffset", "ignored", "the IMU is mounted as its link (said when not 0)"),
            _p("serviceName", "ignored", "hector's calibrate service; no ROS services here"),
        ),
    ),
    PluginDoc(
        ("hector_gazebo_ros_gps",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/gazebo_ros_gps.cpp:70-157; sensor_model.h:106-115, "
        "update_timer.h:56-80",
        "gps (a flat earth around the reference point, hector's error model, velocity north-west-up)",
        (
            *_COMMON,
            _p("bodyName frameId topicName velocityTopicName status service"),
            _p("referenceLatitude referenceLongitude referenceHeading referenceAltitude"),
            _p("updateRate updatePeriod", "same", "default 4 Hz"),
            _p("updateOffset", "ignored", "readings are taken at multiples of the period"),
            _p("offset drift driftFrequency gaussianNoise"),
            _p("velocityOffset velocityDrift velocityDriftFrequency velocityGaussianNoise"),
            _p("scaleError velocityScaleError", "ignored", "read by hector, used for nothing"),
            _p(
                "useWorldSphericalCoordinates",
                "ignored",
                "Gazebo takes the world's <spherical_coordinates>; the plugin's reference is used (said)",
            ),
        ),
    ),
    PluginDoc(
        ("hector_gazebo_ros_sonar",),
        "sensor",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/gazebo_ros_sonar.cpp:82-96; sensor_model.h, "
        "update_timer.h",
        "lidar with only a sensor_msgs/Range (the nearest ray, ULTRASOUND, hector's error model)",
        (
            *_COMMON,
            _p("frameId topicName"),
            _p("updateRate updatePeriod", "same", "default 10 Hz"),
            _p("offset drift driftFrequency gaussianNoise"),
            _p("scaleError", "ignored", "read by hector, used for nothing"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_laser", "gazebo_ros_gpu_laser"),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_laser.cpp:88-103, src/gazebo_ros_gpu_laser.cpp:91-105",
        "lidar (sensor_msgs/LaserScan on `<topicName>`)",
        (*_COMMON, _p("frameName topicName")),
    ),
    PluginDoc(
        ("gazebo_ros_block_laser",),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_block_laser.cpp:106-149",
        "lidar (its points)",
        (
            *_COMMON,
            _p("frameName topicName updateRate"),
            _p("gaussianNoise", "same", "added to the sensor's noise"),
            _p(
                "hokuyoMinIntensity",
                "ignored",
                "a floor on the intensities; every return has intensity 0 here",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_bumper",),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_bumper.cpp:82-101; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_bumper.cpp:99)",
        "contact (gazebo_msgs/ContactsState on the bumper topic)",
        (*_COMMON, _p("bumperTopicName frameName frame_name")),
    ),
    PluginDoc(
        ("gazebo_ros_imu_sensor",),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_imu_sensor.cpp:48-55, :175-252; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_imu_sensor.cpp:76-82, frame_name through gazebo_ros::SensorFrameID)",
        "imu (the sensor's `<imu>` noise)",
        (
            *_COMMON,
            _p("topicName frameName frame_name"),
            _p("updateRateHZ", "same", "ROS 1: throttles the sensor's `<update_rate>`"),
            _p("gaussianNoise", "same", "ROS 1: added to the sensor's noise"),
            _p("xyzOffset", "ignored", "read and unused by the plugin itself"),
            _p("rpyOffset", "ignored", "turns the reported orientation; said"),
            _p(
                "initialOrientationAsReference initial_orientation_as_reference",
                "ignored",
                "true: the orientation relative to the start; here always the world's (said)",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_multicamera",),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_multicamera.cpp:92-93, src/gazebo_ros_camera_utils.cpp"
        ":125-254 (per camera); ROS 2 Humble/Jazzy: gazebo_ros_camera reads a multicamera sensor",
        "camera (one per camera of the sensor)",
        (
            *_COMMON,
            _p("cameraName imageTopicName cameraInfoTopicName frameName updateRate"),
            _p("hackBaseline", "ignored", "the stereo baseline in the right camera's CameraInfo"),
            _p("Cx Cy CxPrime focalLength", "ignored", "CameraInfo is the ideal pinhole of <horizontal_fov>"),
            _p("triggerTopicName borderCrop autoDistortion", "ignored", "triggering; rectification only"),
            _p(
                "distortionK1 distortionK2 distortionK3 distortionT1 distortionT2",
                "ignored",
                "images are not distorted (said when not 0)",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_velodyne_laser", "gazebo_ros_velodyne_gpu_laser"),
        "sensor",
        "velodyne_simulator (Dataspeed; ROS 1, as in lmark1/velodyne_simulator e08185a3): "
        "velodyne_gazebo_plugins/src/GazeboRosVelodyneLaser.cpp:115-158; its ROS 2 port reads `<ros>`, "
        "`frame_name`, `gaussian_noise`, `tf_prefix`",
        "lidar with only a PointCloud2 (x y z intensity ring time, the velodyne layout)",
        (
            *_COMMON,
            _p("topicName frameName frame_name", "same", "ROS 1 default `/points`, `/world`"),
            _p("min_range max_range", "same", "with the sensor's `<range>`: the narrower"),
            _p("gaussianNoise gaussian_noise", "same", "added to the sensor's noise"),
            _p("organize_cloud", "same", "1.0.10+: an organised cloud"),
            _p("min_intensity", "ignored", "drops dimmer returns; every return has intensity 0 here"),
            _p("tf_prefix", "ignored", "ROS 2: prefixes the frame; the frame is the robot's"),
        ),
    ),
    # gz-sim systems our world always runs: read as no-ops (tables.NOOP_PLUGINS), their options unread
    PluginDoc(
        ("gz-sim-physics-system",),
        "model",
        "gz-sim: src/systems/physics/Physics.cc:905-945",
        "nothing: our world always steps physics (MuJoCo)",
        (
            _p("engine", "ignored", "the physics engine's library (dartsim by default); MuJoCo here"),
            _p("contacts enforce_fixed_constraint", "ignored", "contact naming; fixed-joint enforcement"),
        ),
    ),
    PluginDoc(
        ("gz-sim-sensors-system",),
        "model",
        "gz-sim: src/systems/sensors/Sensors.cc:701-780",
        "nothing: our world always runs the sensors",
        (
            _p(
                "render_engine render_engine_api_backend background_color ambient_light",
                "ignored",
                "the rendering engine and scene; cameras here render with MuJoCo",
            ),
            _p(
                "global_illumination resolution octant_count bounce_count high_quality anisotropic",
                "ignored",
                "global illumination of the rendering engine",
            ),
            _p("thin_wall_counter conserve_memory debug_vis_mode", "ignored", "global illumination options"),
            _p("disable_on_drained_battery", "ignored", "no batteries here"),
        ),
    ),
    PluginDoc(
        ("gz-sim-scene-broadcaster-system",),
        "model",
        "gz-sim: src/systems/scene_broadcaster/SceneBroadcaster.cc:329-332",
        "nothing: the GUI's scene updates",
        (_p("dynamic_pose_hertz state_hertz", "ignored", "rates of the GUI's pose and state messages"),),
    ),
    PluginDoc(
        ("gz-sim-user-commands-system",),
        "model",
        "gz-sim: src/systems/user_commands/UserCommands.cc:564-636",
        "nothing: the services that create, move and remove entities",
        (_p("set_all_light_entities", "ignored", "light commands affect every light"),),
    ),
    PluginDoc(
        ("gz-sim-imu-system", "gz-sim-contact-system", "gz-sim-forcetorque-system"),
        "model",
        "gz-sim: src/systems/imu/Imu.cc, src/systems/contact/Contact.cc, src/systems/force_torque/"
        "ForceTorque.cc (no options of their own: each sensor's are in its `<sensor>`)",
        "nothing: our world always runs these sensors",
    ),
    PluginDoc(
        ("gz-sim-magnetometer-system", "gz-sim-air-pressure-system", "gz-sim-altimeter-system"),
        "model",
        "gz-sim: src/systems/magnetometer/Magnetometer.cc:252-271 (the air pressure and altimeter systems "
        "read no options: each sensor's are in its `<sensor>`)",
        "nothing: our world always runs these sensors (runner.compile.gazebo.field_sensors)",
        (
            _p(
                "use_units_gauss use_earth_frame_ned",
                "ignored",
                "the units and axes of gz-sim's field table at the world's <spherical_coordinates>, which is "
                "not read here (the field is SDF's default)",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-navsat-system",),
        "model",
        "gz-sim: src/systems/navsat/NavSat.cc (no options: the sensor's are in its `<sensor type='navsat'>`)",
        "not supported: a navsat sensor is not read here; use the scenario's `gps` plugin",
    ),
    # gazebo_plugins we do not map (ROS 1 Noetic, ROS 2 Humble/Jazzy)
    PluginDoc(
        ("gazebo_ros_tricycle_drive",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_tricycle_drive.cpp:84-113; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_tricycle_drive.cpp:248-354)",
        "not supported: use the scenario's `steering_drive` plugin (a tricycle steering controller's "
        "kinematics)",
        (
            _p(
                "steeringJoint actuatedWheelJoint encoderWheelLeftJoint encoderWheelRightJoint "
                "steering_joint actuated_wheel_joint encoder_wheel_left_joint encoder_wheel_right_joint",
                "ignored",
                "the steered and driven front wheel's joints; the rear wheels' joints for odometry",
            ),
            _p(
                "actuatedWheelDiameter encoderWheelDiameter encoderWheelSeparation actuated_wheel_diameter "
                "encoder_wheel_diameter wheel_separation",
                "ignored",
                "the geometry of the command's inverse kinematics and of the odometry",
            ),
            _p(
                "wheelTorque wheelAcceleration wheelDeceleration wheelSpeedTolerance steeringSpeed "
                "steeringAngleTolerance max_wheel_torque max_wheel_acceleration max_wheel_deceleration "
                "max_wheel_speed_tolerance max_steering_speed max_steering_angle_tolerance",
                "ignored",
                "limits of the wheel's velocity servo and of the steering's rate",
            ),
            _p(
                "commandTopic odometryTopic odometryFrame robotBaseFrame odometry_frame robot_base_frame",
                "ignored",
                "the Twist it subscribes and the odometry it publishes",
            ),
            _p(
                "updateRate update_rate odometrySource odometry_source publishWheelTF publishWheelJointState "
                "publish_wheel_tf publish_wheel_joint_state publish_odom",
                "ignored",
                "the control rate; odometry from the encoders or the world; what else it publishes",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_ackermann_drive",),
        "model",
        "gazebo_plugins (ROS 2 Humble/Jazzy): src/gazebo_ros_ackermann_drive.cpp:230-447",
        "not supported: use the scenario's `steering_drive` plugin (ackermann steering kinematics)",
        (
            _p(
                "front_left_joint front_right_joint rear_left_joint rear_right_joint left_steering_joint "
                "right_steering_joint steering_wheel_joint",
                "ignored",
                "the four wheels' and two steering joints; the steering wheel turned with them",
            ),
            _p(
                "max_speed max_steer max_steering_angle",
                "ignored",
                "the command's limits; the steering wheel's angle at max_steer",
            ),
            _p(
                "left_steering_pid_gain left_steering_i_range right_steering_pid_gain right_steering_i_range "
                "linear_velocity_pid_gain linear_velocity_i_range",
                "ignored",
                "PID gains (p i d) and integral ranges of the joint forces that track the command",
            ),
            _p(
                "update_rate odometry_frame robot_base_frame publish_odom publish_odom_tf publish_wheel_tf "
                "publish_distance publish_steerangle covariance_x covariance_y covariance_yaw",
                "ignored",
                "the control rate; the odometry, the distance and the steering angle it publishes",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_f3d",),
        "model",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_f3d.cpp:63-96",
        "not supported: no counterpart (the external force and torque on a link are not published)",
        (
            _p("robotNamespace", "ignored", "the namespace of its topic"),
            _p("bodyName topicName frameName", "ignored", "the link; the WrenchStamped topic; its frame"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_force",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_force.cpp:72-96; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_force.cpp:68-88)",
        "not supported: no counterpart (a wrench from a topic is not applied to a link)",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its topic"),
            _p("bodyName link_name", "ignored", "the link the wrench is applied to"),
            _p("topicName", "ignored", "ROS 1: the geometry_msgs/Wrench topic it subscribes"),
            _p("force_frame", "ignored", "ROS 2: world (default) or link, the frame of the wrench"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_hand_of_god",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_hand_of_god.cpp:83-99; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_hand_of_god.cpp:109-115)",
        "not supported: no counterpart (a link is not pulled along a TF frame)",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its TF"),
            _p("frameId frame_id linkName link_name", "ignored", "the TF frame the link follows; the link"),
            _p("kl ka", "ignored", "the linear and angular gains of the force and torque that pull it"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_vacuum_gripper",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_vacuum_gripper.cpp:74-105; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_vacuum_gripper.cpp:105-120)",
        "not supported: no counterpart (nothing is pulled to a link); for a gripper's fingers use the "
        "scenario's `gripper_action_controller`",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its topics and services"),
            _p("bodyName link_name", "ignored", "the gripper's link"),
            _p("topicName", "ignored", "ROS 1: the Bool topic saying whether it grasps"),
            _p("max_distance", "ignored", "ROS 2: how far objects are pulled from"),
            _p("fixed", "ignored", "ROS 2: models never pulled"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_joint_pose_trajectory",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_joint_pose_trajectory.cpp:77-103; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_joint_pose_trajectory.cpp:119)",
        "not supported: use the scenario's `joint_trajectory_controller` plugin (it drives the joints; this "
        "plugin sets their positions without dynamics)",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its topic"),
            _p("serviceName topicName", "ignored", "ROS 1: the trajectory's service and topic"),
            _p("updateRate update_rate", "ignored", "the rate at which it sets the joints' positions"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_wheel_slip",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_wheel_slip.cpp:74-76, the rest read by Gazebo's "
        "WheelSlipPlugin; ROS 2 Humble/Jazzy: src/gazebo_ros_wheel_slip.cpp:113-126, :337-351)",
        "not supported: slip compliance is not modelled (the wheels' `<collision><surface>` friction is "
        "read)",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its parameters"),
            _p("wheel link_name", "ignored", "a `<wheel link_name=...>` per wheel link"),
            _p(
                "slip_compliance_lateral slip_compliance_longitudinal",
                "ignored",
                "ODE slip (velocity per force) scaled by the wheel's speed, per wheel",
            ),
            _p("wheel_spin_tolerance publisher_update_rate", "ignored", "ROS 2: the slip it publishes"),
        ),
    ),
    # gz-sim systems found in robot descriptions that we do not map
    PluginDoc(
        ("gz-sim-joint-position-controller-system",),
        "model",
        "gz-sim: src/systems/joint_position_controller/JointPositionController.cc:241-394",
        "not supported: use the scenario's `joint_controller` plugin (mode position)",
        (
            _p("joint_name joint_index", "ignored", "the joint(s), and which axis of a multi-axis joint"),
            _p(
                "p_gain i_gain d_gain i_max i_min cmd_max cmd_min cmd_offset",
                "ignored",
                "the PID that turns the position error into a force (or a velocity)",
            ),
            _p("use_velocity_commands", "ignored", "command the joint's velocity instead of a force"),
            _p("initial_position", "ignored", "the target before any command"),
            _p(
                "topic sub_topic use_actuator_msg actuator_number",
                "ignored",
                "the Double (or Actuators) topic",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-joint-controller-system",),
        "model",
        "gz-sim: src/systems/joint_controller/JointController.cc:113-245",
        "not supported: use the scenario's `joint_controller` plugin (mode velocity)",
        (
            _p("joint_name", "ignored", "the joint(s)"),
            _p("initial_velocity", "ignored", "the target before any command"),
            _p(
                "use_force_commands p_gain i_gain d_gain i_max i_min cmd_max cmd_min cmd_offset",
                "ignored",
                "with use_force_commands, a PID on the velocity error; else the velocity is set directly",
            ),
            _p("disable_braking", "ignored", "no velocity command while the target is 0"),
            _p(
                "topic sub_topic use_actuator_msg actuator_number",
                "ignored",
                "the Double (or Actuators) topic",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-apply-joint-force-system",),
        "model",
        "gz-sim: src/systems/apply_joint_force/ApplyJointForce.cc:93",
        "not supported: use the scenario's `joint_controller` plugin (mode effort)",
        (
            _p(
                "joint_name",
                "ignored",
                "the joint a Double on `/model/<model>/joint/<joint>/cmd_force` drives",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-joint-trajectory-controller-system",),
        "model",
        "gz-sim: src/systems/joint_traj_control/JointTrajectoryController.cc:367-378, :537, :720-754",
        "not supported: use the scenario's `joint_trajectory_controller` plugin",
        (
            _p(
                "topic use_header_start_time",
                "ignored",
                "the JointTrajectory topic; when a trajectory starts",
            ),
            _p("joint_name initial_position", "ignored", "the joints (default: every one) and their start"),
            _p(
                "position_p_gain position_i_gain position_d_gain position_i_min position_i_max "
                "position_cmd_min position_cmd_max position_cmd_offset",
                "ignored",
                "the per-joint position PID (forces)",
            ),
            _p(
                "velocity_p_gain velocity_i_gain velocity_d_gain velocity_i_min velocity_i_max "
                "velocity_cmd_min velocity_cmd_max velocity_cmd_offset",
                "ignored",
                "the per-joint velocity PID (forces)",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-pose-publisher-system",),
        "model",
        "gz-sim: src/systems/pose_publisher/PosePublisher.cc:200-268",
        "not supported: use the scenario's `tf` plugin (the link tree) or `ground_truth` (a link's world "
        "pose)",
        (
            _p(
                "publish_link_pose publish_nested_model_pose publish_model_pose publish_visual_pose "
                "publish_collision_pose publish_sensor_pose",
                "ignored",
                "which poses it publishes (links by default) on `/model/<model>/pose`",
            ),
            _p(
                "update_frequency static_publisher static_update_frequency",
                "ignored",
                "its rate; the fixed poses on their own topic at their own rate",
            ),
            _p("use_pose_vector_msg topic", "ignored", "one Pose_V per update; the topic"),
        ),
    ),
    PluginDoc(
        ("gz-sim-ackermann-steering-system",),
        "model",
        "gz-sim: src/systems/ackermann_steering/AckermannSteering.cc:258-497",
        "not supported: use the scenario's `steering_drive` plugin (ackermann steering kinematics)",
        (
            _p(
                "left_joint right_joint left_steering_joint right_steering_joint",
                "ignored",
                "the driven wheels' and the steering joints",
            ),
            _p(
                "wheel_radius kingpin_width wheel_separation wheel_base steering_limit steer_p_gain",
                "ignored",
                "the geometry of the steering angles; the steering servo's gain",
            ),
            _p(
                "min_velocity max_velocity min_acceleration max_acceleration min_jerk max_jerk",
                "ignored",
                "the speed limiter on the command",
            ),
            _p(
                "steering_only use_actuator_msg actuator_number",
                "ignored",
                "steering only (the wheels driven by something else); an Actuators command",
            ),
            _p(
                "topic sub_topic odom_topic tf_topic frame_id child_frame_id odom_publish_frequency",
                "ignored",
                "the Twist it subscribes and the odometry it publishes",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-velocity-control-system",),
        "model",
        "gz-sim: src/systems/velocity_control/VelocityControl.cc:123-160",
        "not supported: use the scenario's `planar_move` plugin (the base's velocity set to a Twist)",
        (
            _p("initial_linear initial_angular", "ignored", "the velocity before any command"),
            _p("topic", "ignored", "the Twist topic (default `/model/<model>/cmd_vel`)"),
            _p("link_name", "ignored", "links whose velocity it sets instead, each on its own topic"),
        ),
    ),
    PluginDoc(
        ("gz-sim-wheel-slip-system",),
        "model",
        "gz-sim: src/systems/wheel_slip/WheelSlip.cc:183-220",
        "not supported: slip compliance is not modelled (the wheels' `<collision><surface>` friction is "
        "read)",
        (
            _p("wheel link_name", "ignored", "a `<wheel link_name=...>` per wheel link"),
            _p(
                "slip_compliance_lateral slip_compliance_longitudinal wheel_normal_force wheel_radius",
                "ignored",
                "ODE slip (velocity per force), scaled by the wheel's speed and its normal force",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-detachable-joint-system",),
        "model",
        "gz-sim: src/systems/detachable_joint/DetachableJoint.cc:56-209",
        "not supported: no counterpart (no joint is made or broken during a run)",
        (
            _p("parent_link child_model child_link", "ignored", "the fixed joint it makes between them"),
            _p(
                "topic detach_topic attach_topic output_topic",
                "ignored",
                "the Empty topics that detach and attach; the state it publishes",
            ),
            _p("suppress_child_warning", "ignored", "a warning when the child model is missing"),
        ),
    ),
    PluginDoc(
        ("gz-sim-touchplugin-system",),
        "model",
        "gz-sim: src/systems/touch_plugin/TouchPlugin.cc:140-300",
        "not supported: use the scenario's `contact` plugin (the contacts of a link)",
        (
            _p("target collision", "ignored", "the model it must touch; the collisions that do"),
            _p("time", "ignored", "how long the touch must last"),
            _p("namespace enabled", "ignored", "its topics' namespace; whether it starts enabled"),
        ),
    ),
    PluginDoc(
        ("gz-sim-triggered-publisher-system",),
        "model",
        "gz-sim: src/systems/triggered_publisher/TriggeredPublisher.cc:438-641",
        "not supported: no counterpart (use the scenario's timeline to publish)",
        (
            _p("input output", "ignored", "the message (type, topic) that triggers; what it publishes"),
            _p("match field logic_type tol", "ignored", "what the input must match"),
            _p("delay_ms", "ignored", "the delay between the trigger and the output"),
            _p("service", "ignored", "services it calls when triggered"),
        ),
    ),
    PluginDoc(
        ("gz-sim-label-system",),
        "model",
        "gz-sim: src/systems/label/Label.cc:49-71",
        "not supported: no counterpart (no segmentation cameras here)",
        (_p("label", "ignored", "the semantic label (0-255) segmentation cameras see on its visuals"),),
    ),
    PluginDoc(
        ("gz-sim-thruster-system",),
        "model",
        "gz-sim: src/systems/thruster/Thruster.cc:230-511",
        "not supported: no counterpart (no fluid dynamics here)",
        (
            _p("namespace joint_name topic", "ignored", "the propeller's joint; the command topic"),
            _p(
                "thrust_coefficient propeller_diameter fluid_density wake_fraction alpha_1 alpha_2",
                "ignored",
                "the thrust the propeller's speed gives",
            ),
            _p(
                "use_angvel_cmd velocity_control p_gain i_gain d_gain max_thrust_cmd min_thrust_cmd deadband",
                "ignored",
                "how the command drives the propeller; its limits",
            ),
            _p("power_load battery_name", "ignored", "the battery it drains"),
        ),
    ),
    PluginDoc(
        ("gz-sim-buoyancy-system",),
        "model",
        "gz-sim: src/systems/buoyancy/Buoyancy.cc:487-551 (a world system)",
        "not supported: no counterpart (no fluid here)",
        (
            _p("uniform_fluid_density", "ignored", "the fluid's density (1000 by default)"),
            _p("graded_buoyancy", "ignored", "densities by depth (`<density_change>` `<above_depth>`)"),
            _p("enable", "ignored", "the models it acts on"),
        ),
    ),
    PluginDoc(
        ("gz-sim-lift-drag-system",),
        "model",
        "gz-sim: src/systems/lift_drag/LiftDrag.cc:162-230",
        "not supported: no counterpart (no aerodynamics here)",
        (
            _p(
                "cla cda cma alpha_stall cla_stall cda_stall cma_stall a0 cm_delta",
                "ignored",
                "lift, drag and moment coefficients and the stall",
            ),
            _p(
                "air_density area cp forward upward radial_symmetry",
                "ignored",
                "the wing's geometry, the air",
            ),
            _p("link_name control_joint_name", "ignored", "the wing's link; a control surface's joint"),
        ),
    ),
    PluginDoc(
        ("gz-sim-multicopter-motor-model-system",),
        "model",
        "gz-sim: src/systems/multicopter_motor_model/MulticopterMotorModel.cc:250-366",
        "not supported: no counterpart (rotor thrust is not modelled)",
        (
            _p(
                "robotNamespace jointName linkName motorNumber actuator_number commandSubTopic",
                "ignored",
                "the rotor's joint and link; its index in the Actuators command",
            ),
            _p(
                "turningDirection motorType maxRotVelocity motorConstant momentConstant",
                "ignored",
                "the thrust and drag moment from the rotor's speed",
            ),
            _p(
                "rotorDragCoefficient rollingMomentCoefficient timeConstantUp timeConstantDown "
                "rotorVelocitySlowdownSim",
                "ignored",
                "the rotor's drag and rolling moment; the motor's lag",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-tracked-vehicle-system",),
        "model",
        "gz-sim: src/systems/tracked_vehicle/TrackedVehicle.cc:238-423",
        "not supported: tracks are not modelled; use the scenario's `skid_steer` plugin on wheels",
        (
            _p("body_link left_track right_track", "ignored", "the body and each side's track links"),
            _p("tracks_separation steering_efficiency", "ignored", "the skid-steer kinematics"),
            _p(
                "min_velocity max_velocity min_acceleration max_acceleration min_jerk max_jerk",
                "ignored",
                "the speed limiter on the command",
            ),
            _p(
                "topic odom_topic tf_topic frame_id child_frame_id odom_publish_frequency "
                "center_of_rotation_topic steering_efficiency_topic debug",
                "ignored",
                "the Twist it subscribes; the odometry; topics that change it while running",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-track-controller-system",),
        "model",
        "gz-sim: src/systems/track_controller/TrackController.cc:214-373",
        "not supported: tracks are not modelled (the surface motion of a track link)",
        (
            _p("link max_command_age debug", "ignored", "the track link; a command's lifetime"),
            _p(
                "min_velocity max_velocity min_acceleration max_acceleration min_jerk max_jerk",
                "ignored",
                "the speed limiter on the track's velocity",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-apply-link-wrench-system",),
        "model",
        "gz-sim: src/systems/apply_link_wrench/ApplyLinkWrench.cc:154-226",
        "not supported: no counterpart (a wrench from a topic is not applied to a link)",
        (
            _p(
                "persistent entity_name entity_type force torque", "ignored", "wrenches applied at every step"
            ),
            _p(
                "topic topic_persistent topic_clear verbose",
                "ignored",
                "the topics that apply and clear them",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-linearbatteryplugin-system",),
        "model",
        "gz-sim: src/systems/battery_plugin/LinearBatteryPlugin.cc:232-411",
        "not supported: no counterpart (no batteries here)",
        (
            _p(
                "battery_name voltage open_circuit_voltage_constant_coef open_circuit_voltage_linear_coef "
                "capacity initial_charge resistance smooth_current_tau",
                "ignored",
                "the battery's model",
            ),
            _p("power_load start_draining fix_issue_225 invert_current_sign", "ignored", "how it drains"),
            _p(
                "enable_recharge charging_time recharge_by_topic power_draining_topic "
                "stop_power_draining_topic",
                "ignored",
                "recharging; the topics that start and stop draining",
            ),
        ),
    ),
    # third-party
    PluginDoc(
        ("realsense_gazebo_plugin",),
        "model",
        "realsense_gazebo_plugin (PAL Robotics, ROS 1 melodic-devel 49ab134f): "
        "src/RealSensePlugin.cpp:52-120 (each tag by name; any other one throws), "
        "src/gazebo_ros_realsense.cpp",
        'not supported: give the robot\'s `<sensor type="depth">` and `<sensor type="camera">` with '
        "gazebo_ros_camera (or the scenario's `depth_camera` and `camera` plugins)",
        (
            _p("prefix robotNamespace", "ignored", "the cameras' sensor name prefix; its namespace"),
            _p(
                "depthUpdateRate colorUpdateRate infraredUpdateRate",
                "ignored",
                "the rates of the depth, colour and infrared cameras (sensors of its model)",
            ),
            _p(
                "depthTopicName depthCameraInfoTopicName colorTopicName colorCameraInfoTopicName "
                "infrared1TopicName infrared1CameraInfoTopicName infrared2TopicName "
                "infrared2CameraInfoTopicName",
                "ignored",
                "the image and CameraInfo topics of each camera",
            ),
            _p(
                "colorOpticalframeName depthOpticalframeName infrared1OpticalframeName "
                "infrared2OpticalframeName",
                "ignored",
                "each image's frame",
            ),
            _p(
                "rangeMinDepth rangeMaxDepth pointCloud pointCloudTopicName pointCloudCutoff "
                "pointCloudCutoffMax",
                "ignored",
                "the depth's limits; the coloured PointCloud2 it publishes and its cut-offs",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_gps_sensor",),
        "sensor",
        "gazebo_plugins (ROS 2 Humble/Jazzy): src/gazebo_ros_gps_sensor.cpp:66-89 (NavSatFix on `~/out`, the "
        "velocity on `~/vel`; frame_name through gazebo_ros::SensorFrameID)",
        "gps (Gazebo's GPS sensor: its `<gps>` noise, velocity east-north-up)",
        (
            _p(
                "ros",
                "approx",
                "`<remapping>` (`~/out`, `~/vel`) kept; `<namespace>` replaced by the robot's",
            ),
            _p("frame_name", "same", "default: the sensor's link"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_projector",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_projector.cpp:93-110; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_projector.cpp:80-81)",
        "not supported: no counterpart (nothing is rendered from projectors here)",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its topics"),
            _p(
                "projector projector_link projector_name",
                "ignored",
                "the `<projector>` of a link it switches",
            ),
            _p(
                "textureTopicName projectorTopicName",
                "ignored",
                "ROS 1: the topics that set the texture, switch",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_video",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_video.cpp:139-188; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_video.cpp:209-214, a visual plugin)",
        "not supported: no counterpart (images from a topic are not shown on a visual)",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its topic"),
            _p("topicName", "ignored", "ROS 1: the sensor_msgs/Image topic it shows"),
            _p("height width name", "ignored", "the texture's size; the visual's name"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_elevator",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_elevator.cpp:44-61; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_elevator.cpp:55-67; the lift itself is Gazebo's ElevatorPlugin)",
        "not supported: no counterpart (an elevator's lift and doors on a String command)",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its topic"),
            _p("topic", "ignored", "ROS 1: the String topic with the floor to go to"),
            _p("bottom_floor top_floor", "ignored", "ROS 2: the floors it accepts"),
        ),
    ),
    # hector_gazebo_plugins' drives (ROS 1 melodic-devel), PAL's, gz-sim's trajectory follower
    PluginDoc(
        ("diffdrive_plugin_multi_wheel",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/diffdrive_plugin_multi_wheel.cpp:120-230",
        "not supported: use the scenario's `skid_steer` plugin (every wheel of a side at one speed)",
        (
            _p("robotNamespace", "ignored", "the namespace of its topics"),
            _p("leftJoints rightJoints", "ignored", "each side's wheel joints, space-separated"),
            _p("wheelSeparation wheelDiameter torque", "ignored", "the kinematics; the wheels' force limit"),
            _p(
                "commandTopic odometryTopic odometryFrame robotBaseFrame updateRate publishOdometryTf "
                "publishOdometryMsg",
                "ignored",
                "the Twist it subscribes and the odometry (from the world pose) it publishes",
            ),
        ),
    ),
    PluginDoc(
        ("diffdrive_plugin_6w",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/diffdrive_plugin_6w.cpp:94-137",
        "not supported: use the scenario's `skid_steer` plugin (three wheels a side)",
        (
            _p("robotNamespace topicName bodyName", "ignored", "the Twist topic; the base link"),
            _p(
                "frontLeftJoint frontRightJoint midLeftJoint midRightJoint rearLeftJoint rearRightJoint",
                "ignored",
                "the six wheel joints",
            ),
            _p("wheelSeparation wheelDiameter torque", "ignored", "the kinematics; the wheels' force limit"),
        ),
    ),
    PluginDoc(
        ("hector_servo_plugin",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/servo_plugin.cpp:93-120",
        "not supported: use the scenario's `joint_controller` plugin (mode position) on each joint",
        (
            _p("robotNamespace topicName jointStateName", "ignored", "the command and joint-state topics"),
            _p(
                "firstServoName firstServoAxis secondServoName secondServoAxis thirdServoName thirdServoAxis",
                "ignored",
                "up to three joints turned to a commanded orientation",
            ),
            _p(
                "proportionalControllerGain derivativeControllerGain maxVelocity torque controlRate",
                "ignored",
                "the PD servo that drives them; its limits and rate",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_underactuated_finger",),
        "model",
        "pal_gazebo_plugins (ROS 2 humble-devel 6575bb12): src/gazebo_underactuated_finger.cpp:58-125",
        "not supported: declare the finger's joints `<mimic>` of the actuated one in the URDF (mimic joints "
        "are held by an equality constraint here)",
        (
            _p("namespace", "ignored", "its namespace"),
            _p("actuatedJoint", "ignored", "the joint the hand's controller drives"),
            _p(
                "virtualJoint",
                "ignored",
                "each joint that follows it: `<name>`, `<scale_factor>`, `<pid_gains>` (p i d i_max i_min)",
            ),
        ),
    ),
    PluginDoc(
        ("pal_gazebo_collisions",),
        "model",
        "pal_gazebo_plugins (ROS 2 humble-devel 6575bb12): src/pal_gazebo_collisions.cpp:35-40",
        "not supported: no counterpart (the model's self-collisions are not published)",
        (_p("updateRate", "ignored", "the rate at which it publishes the contacts"),),
    ),
    PluginDoc(
        ("gz-sim-trajectory-follower-system",),
        "model",
        "gz-sim: src/systems/trajectory_follower/TrajectoryFollower.cc:123-265",
        "not supported: no counterpart (use the scenario's timeline of velocity commands to a drive)",
        (
            _p("link_name", "ignored", "the link it pushes (default: the model's canonical link)"),
            _p(
                "waypoints waypoint circle radius line direction length loop",
                "ignored",
                "the path: waypoints, a circle or a line, once or in a loop",
            ),
            _p(
                "force torque range_tolerance bearing_tolerance zero_vel_on_bearing_reached",
                "ignored",
                "the force and torque it pushes with; when a waypoint or bearing counts as reached",
            ),
            _p("topic", "ignored", "the Boolean topic that pauses and resumes it"),
        ),
    ),
    # sensor types of SDF 1.10 (sdformat 2ace5362: sdf/1.10/sensor.sdf and each type's file) no reader maps
    PluginDoc(
        ("sensor:navsat",),
        "sensor",
        "sdformat: sdf/1.10/navsat.sdf (SDF: the same sensor as `gps`); gz-sim: src/systems/navsat/NavSat.cc",
        'not supported: the reader maps the legacy name `<sensor type="gps">` (Gazebo\'s GPS sensor), not '
        "`navsat`; rename the type or use the scenario's `gps` plugin",
        (
            _p(
                "navsat.position_sensing navsat.velocity_sensing",
                "ignored",
                "`<horizontal>`/`<vertical>` `<noise>` on the fix and the velocity (NavSat on `.../navsat`)",
            ),
        ),
    ),
    PluginDoc(
        ("sensor:logical_camera",),
        "sensor",
        "sdformat: sdf/1.10/logical_camera.sdf",
        "not supported: no counterpart (the models in a frustum, by name and pose)",
        (
            _p(
                "logical_camera.near logical_camera.far logical_camera.aspect_ratio "
                "logical_camera.horizontal_fov",
                "ignored",
                "the frustum in which models are reported",
            ),
        ),
    ),
    PluginDoc(
        ("sensor:sonar",),
        "sensor",
        "sdformat: sdf/1.10/sonar.sdf (Gazebo classic's SonarSensor)",
        "not supported: a `ray` sensor with gazebo_ros_range (ROS 1) or gazebo_ros_ray_sensor's "
        "sensor_msgs/Range (ROS 2) is read as a Range",
        (
            _p("sonar.geometry sonar.radius", "ignored", "a cone (default) or sphere, its base's radius"),
            _p("sonar.min sonar.max", "ignored", "the range's limits"),
        ),
    ),
    PluginDoc(
        ("sensor:air_speed",),
        "sensor",
        "sdformat: sdf/1.10/air_speed.sdf; gz-sim: src/systems/air_speed",
        "not supported: no counterpart (no air here)",
        (_p("air_speed.pressure", "ignored", "the differential pressure's `<noise>`"),),
    ),
    PluginDoc(
        ("sensor:thermal_camera", "sensor:thermal"),
        "sensor",
        "sdformat: sdf/1.10/sensor.sdf, camera.sdf; gz-sim: src/systems/thermal/ThermalSensor.cc:56-58 (the "
        "thermal-sensor system's `<resolution>`, `<min_temp>`, `<max_temp>`)",
        "not supported: no counterpart (no temperatures here)",
        (_p("camera", "ignored", "the image's size and field of view; temperatures come from visuals"),),
    ),
    PluginDoc(
        ("sensor:segmentation_camera", "sensor:segmentation"),
        "sensor",
        "sdformat: sdf/1.10/camera.sdf:80 (`<segmentation_type>`)",
        "not supported: no counterpart (no segmentation images here)",
        (_p("camera.segmentation_type", "ignored", "semantic (default) or panoptic labels per pixel"),),
    ),
    PluginDoc(
        ("sensor:boundingbox_camera", "sensor:boundingbox"),
        "sensor",
        "sdformat: sdf/1.10/camera.sdf:94 (`<box_type>`)",
        "not supported: no counterpart (no bounding boxes here)",
        (_p("camera.box_type", "ignored", "2d (default), visible_2d or 3d boxes of labelled visuals"),),
    ),
    PluginDoc(
        ("sensor:wide_angle_camera",),
        "sensor",
        "sdformat: sdf/1.10/camera.sdf:142-179 (`<lens>`)",
        "not supported: no counterpart; a `camera` sensor (a pinhole of `<horizontal_fov>`) is read",
        (
            _p(
                "camera.lens",
                "ignored",
                "the lens' projection (`<type>`, `<custom_function>` c1 c2 c3 f fun, `<scale_to_hfov>`, "
                "`<cutoff_angle>`, `<env_texture_size>`, `<intrinsics>`)",
            ),
        ),
    ),
    PluginDoc(
        ("gz-sim-thermal-system",),
        "model",
        "gz-sim: src/systems/thermal/Thermal.cc:58-105 (in a `<visual>` or a model)",
        "not supported: no counterpart (no thermal cameras here)",
        (
            _p("temperature heat_signature", "ignored", "a uniform temperature or a heat-signature texture"),
            _p("min_temp max_temp", "ignored", "the texture's temperature range"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_triggered_camera", "gazebo_ros_triggered_multicamera"),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_triggered_camera.cpp:50-82, "
        "src/gazebo_ros_triggered_multicamera.cpp:87-88, src/gazebo_ros_camera_utils.cpp:125-254",
        "not supported: use gazebo_ros_camera (or gazebo_ros_multicamera), which publish at the sensor's "
        "rate; a frame per message on the trigger topic is not reproduced",
        (
            _p("robotNamespace", "ignored", "the namespace of its topics"),
            _p(
                "cameraName imageTopicName cameraInfoTopicName frameName updateRate triggerTopicName",
                "ignored",
                "the image and CameraInfo topics; the trigger topic that makes it publish one frame",
            ),
            _p(
                "Cx Cy CxPrime focalLength hackBaseline borderCrop autoDistortion distortionK1 distortionK2 "
                "distortionK3 distortionT1 distortionT2",
                "ignored",
                "the CameraInfo's intrinsics and distortion",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_harness",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_harness.cpp:56-57; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_harness.cpp:77-89; the harness itself is Gazebo's HarnessPlugin)",
        "not supported: no counterpart (a model held by a winched joint until detached); start the robot "
        "where it should stand",
        (
            _p("robotNamespace ros", "ignored", "the namespace of its velocity and detach topics"),
            _p("init_vel", "ignored", "ROS 2: the winch's initial velocity"),
        ),
    ),
)


def entry(base: str) -> PluginDoc | None:
    """The catalogue's entry of a plugin (by `plugin_base()` of its filename)."""
    return _BY_BASE.get(base)


_BY_BASE = {b: e for e in CATALOGUE for b in e.bases}
UNSUPPORTED = (
    "not supported"  # how `becomes` starts for a plugin we do not map: "not supported: why; instead"
)


def unsupported_reason(base: str) -> str:
    """Why the plugin is not supported and what serves instead ('' when it is mapped or not catalogued)."""
    doc = _BY_BASE.get(base)
    if doc is None or not doc.becomes.startswith(UNSUPPORTED):
        return ""
    return doc.becomes.removeprefix(UNSUPPORTED).lstrip(":; ").strip()


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
