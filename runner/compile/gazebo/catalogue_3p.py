"""The plugin catalogue's entries of third-party plugins common in public robots: hector_gazebo_plugins
(ROS 1 melodic-devel), velodyne_simulator, PAL's pal_gazebo_plugins (humble-devel 6575bb12) and
realsense_gazebo_plugin (melodic-devel 49ab134f), each read from its source (file:lines in `origin`). An
entry whose `becomes` starts "not supported" is one no reader maps: its parameters are all ignored."""

from __future__ import annotations

from runner.compile.gazebo.plugin_doc import COMMON, PluginDoc, p

ENTRIES: tuple[PluginDoc, ...] = (
    PluginDoc(
        ("hector_gazebo_ros_imu",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/gazebo_ros_imu.cpp:75-153; include/"
        "hector_gazebo_plugins/sensor_model.h:106-115 (the error model's tags per prefix), "
        "update_timer.h:56-80",
        "imu (hector's error model: offset, drifting bias, white noise; the orientation tilted by the bias)",
        (
            *COMMON,
            p("bodyName frameId topicName biasTopicName"),
            p("updateRate updatePeriod", "same", "none or 0: every physics step"),
            p("updateOffset", "ignored", "readings are taken at multiples of the period"),
            p("accelOffset accelDrift accelDriftFrequency accelGaussianNoise"),
            p("rateOffset rateDrift rateDriftFrequency rateGaussianNoise"),
            p("yawOffset yawDrift yawDriftFrequency"),
            p(
                "headingOffset headingDrift headingDriftFrequency",
                "same",
                "the yaw model's spellings before hector 0.3.6",
            ),
            p("headingGaussianNoise", "ignored", "only fills hector's orientation covariance (said)"),
            p("yawGaussianNoise", "ignored", "only fills hector's orientation covariance (said)"),
            p("gaussianNoise", "same", "the older spelling of both white noises"),
            p(
                "accelScaleError rateScaleError yawScaleError headingScaleError",
                "ignored",
                "read by hector, used for nothing",
            ),
            p("xyzOffset", "ignored", "read and not applied by hector either (said when not 0)"),
            p("rpyOffset", "ignored", "the IMU is mounted as its link (said when not 0)"),
            p("serviceName", "ignored", "hector's calibrate service; no ROS services here"),
        ),
    ),
    PluginDoc(
        ("hector_gazebo_ros_gps",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/gazebo_ros_gps.cpp:70-157; sensor_model.h:106-115, "
        "update_timer.h:56-80",
        "gps (a flat earth around the reference point, hector's error model, velocity north-west-up)",
        (
            *COMMON,
            p("bodyName frameId topicName velocityTopicName status service"),
            p("referenceLatitude referenceLongitude referenceHeading referenceAltitude"),
            p("updateRate updatePeriod", "same", "default 4 Hz"),
            p("updateOffset", "ignored", "readings are taken at multiples of the period"),
            p("offset drift driftFrequency gaussianNoise"),
            p("velocityOffset velocityDrift velocityDriftFrequency velocityGaussianNoise"),
            p("scaleError velocityScaleError", "ignored", "read by hector, used for nothing"),
            p(
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
            *COMMON,
            p("frameId topicName"),
            p("updateRate updatePeriod", "same", "default 10 Hz"),
            p("offset drift driftFrequency gaussianNoise"),
            p("scaleError", "ignored", "read by hector, used for nothing"),
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
            *COMMON,
            p("topicName frameName frame_name", "same", "ROS 1 default `/points`, `/world`"),
            p("min_range max_range", "same", "with the sensor's `<range>`: the narrower"),
            p("gaussianNoise gaussian_noise", "same", "added to the sensor's noise"),
            p("organize_cloud", "same", "1.0.10+: an organised cloud"),
            p("min_intensity", "ignored", "drops dimmer returns; every return has intensity 0 here"),
            p("tf_prefix", "ignored", "ROS 2: prefixes the frame; the frame is the robot's"),
        ),
    ),
    PluginDoc(
        ("realsense_gazebo_plugin",),
        "model",
        "realsense_gazebo_plugin (PAL Robotics, ROS 1 melodic-devel 49ab134f): "
        "src/RealSensePlugin.cpp:52-120 (each tag by name; any other one throws), "
        "src/gazebo_ros_realsense.cpp",
        'not supported: give the robot\'s `<sensor type="depth">` and `<sensor type="camera">` with '
        "gazebo_ros_camera (or the scenario's `depth_camera` and `camera` plugins)",
        (
            p("prefix robotNamespace", "ignored", "the cameras' sensor name prefix; its namespace"),
            p(
                "depthUpdateRate colorUpdateRate infraredUpdateRate",
                "ignored",
                "the rates of the depth, colour and infrared cameras (sensors of its model)",
            ),
            p(
                "depthTopicName depthCameraInfoTopicName colorTopicName colorCameraInfoTopicName "
                "infrared1TopicName infrared1CameraInfoTopicName infrared2TopicName "
                "infrared2CameraInfoTopicName",
                "ignored",
                "the image and CameraInfo topics of each camera",
            ),
            p(
                "colorOpticalframeName depthOpticalframeName infrared1OpticalframeName "
                "infrared2OpticalframeName",
                "ignored",
                "each image's frame",
            ),
            p(
                "rangeMinDepth rangeMaxDepth pointCloud pointCloudTopicName pointCloudCutoff "
                "pointCloudCutoffMax",
                "ignored",
                "the depth's limits; the coloured PointCloud2 it publishes and its cut-offs",
            ),
        ),
    ),
    PluginDoc(
        ("diffdrive_plugin_multi_wheel",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/diffdrive_plugin_multi_wheel.cpp:120-230",
        "not supported: use the scenario's `skid_steer` plugin (every wheel of a side at one speed)",
        (
            p("robotNamespace", "ignored", "the namespace of its topics"),
            p("leftJoints rightJoints", "ignored", "each side's wheel joints, space-separated"),
            p("wheelSeparation wheelDiameter torque", "ignored", "the kinematics; the wheels' force limit"),
            p(
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
            p("robotNamespace topicName bodyName", "ignored", "the Twist topic; the base link"),
            p(
                "frontLeftJoint frontRightJoint midLeftJoint midRightJoint rearLeftJoint rearRightJoint",
                "ignored",
                "the six wheel joints",
            ),
            p("wheelSeparation wheelDiameter torque", "ignored", "the kinematics; the wheels' force limit"),
        ),
    ),
    PluginDoc(
        ("hector_servo_plugin",),
        "model",
        "hector_gazebo_plugins (ROS 1 melodic-devel): src/servo_plugin.cpp:93-120",
        "not supported: use the scenario's `joint_controller` plugin (mode position) on each joint",
        (
            p("robotNamespace topicName jointStateName", "ignored", "the command and joint-state topics"),
            p(
                "firstServoName firstServoAxis secondServoName secondServoAxis thirdServoName thirdServoAxis",
                "ignored",
                "up to three joints turned to a commanded orientation",
            ),
            p(
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
            p("namespace", "ignored", "its namespace"),
            p("actuatedJoint", "ignored", "the joint the hand's controller drives"),
            p(
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
        (p("updateRate", "ignored", "the rate at which it publishes the contacts"),),
    ),
    PluginDoc(
        ("roboticsgroup_upatras_gazebo_mimic_joint_plugin", "roboticsgroup_gazebo_mimic_joint_plugin"),
        "model",
        "roboticsgroup_upatras_gazebo_plugins (ROS 1 master 15187abc): src/mimic_joint_plugin.cpp:62-128; "
        "its origin roboticsgroup_gazebo_plugins (509a32ea): src/mimic_joint_plugin.cpp:63-129, the same",
        "not supported: declare the joint `<mimic joint=... multiplier=... offset=...>` in the URDF (held "
        "by an equality constraint here)",
        (
            p("robotNamespace", "ignored", "the namespace of its PID's parameters"),
            p("joint mimicJoint", "ignored", "the joint followed; the joint that follows it"),
            p("multiplier offset", "ignored", "mimic = multiplier × joint + offset (1, 0)"),
            p(
                "sensitiveness",
                "ignored",
                "below this difference the follower is not moved (0)",
            ),
            p(
                "hasPID maxEffort",
                "ignored",
                "a PID (gains from the parameter server) with maxEffort; without, the position is set with "
                "fmax maxEffort (default: the joint's effort limit)",
            ),
        ),
    ),
    PluginDoc(
        ("roboticsgroup_upatras_gazebo_disable_link_plugin", "roboticsgroup_gazebo_disable_link_plugin"),
        "model",
        "roboticsgroup_upatras_gazebo_plugins (ROS 1 master 15187abc): src/disable_link_plugin.cpp:42-52; "
        "roboticsgroup_gazebo_plugins (509a32ea), the same",
        "not supported: no counterpart (a link is not disabled; remove it from the description instead)",
        (p("link", "ignored", "the link switched off (Link::SetEnabled(false)): not simulated"),),
    ),
)
