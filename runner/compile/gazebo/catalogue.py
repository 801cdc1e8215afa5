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

from runner.compile.gazebo import catalogue_3p, catalogue_gz, catalogue_ros, catalogue_sdf
from runner.compile.gazebo.plugin_doc import COMMON as _COMMON
from runner.compile.gazebo.plugin_doc import Param, PluginDoc, Status
from runner.compile.gazebo.plugin_doc import p as _p

__all__ = [
    "CATALOGUE",
    "UNSUPPORTED",
    "Param",
    "PluginDoc",
    "Status",
    "entry",
    "render",
    "unsupported_reason",
]

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
    *catalogue_ros.ENTRIES,  # gazebo_plugins (ROS 1, ROS 2), ros_control
    *catalogue_gz.ENTRIES,  # gz-sim systems
    *catalogue_sdf.ENTRIES,  # SDF 1.10 sensor types no reader maps
    *catalogue_3p.ENTRIES,  # hector, velodyne, PAL, realsense
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
