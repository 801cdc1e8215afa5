"""The plugin catalogue's entries of gazebo_plugins (gazebo_ros_pkgs: ROS 1 Noetic at noetic-devel f9e1a460,
ROS 2 Humble/Jazzy at ros2 d52f7c47) and of the ros_control plugins, mapped or not, each read from its source
(file:lines in `origin`). An entry whose `becomes` starts "not supported" is one no reader maps: its
parameters are all ignored, and the reader says the plugin once with the reason
(catalogue.unsupported_reason).
"""

from __future__ import annotations

from runner.compile.gazebo.plugin_doc import COMMON, PluginDoc, p

ENTRIES: tuple[PluginDoc, ...] = (
    PluginDoc(
        ("gazebo_ros_planar_move",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_planar_move.cpp:47-126; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_planar_move.cpp:141-195)",
        "planar_move (the base's velocity set to the command, in its own frame)",
        (
            *COMMON,
            p("commandTopic odometryTopic odometryFrame robotBaseFrame odometry_frame robot_base_frame"),
            p(
                "odometryRate publish_rate update_rate",
                "approx",
                "the odometry's rate; ROS 2's `update_rate` (its control rate) stands in when `publish_rate` "
                "is absent; the velocity is set at every step",
            ),
            p("cmdTimeout cmd_timeout", "same", "ROS 1 Noetic: no command for that long stops the base"),
            p("publish_odom publish_odom_tf"),
            p(
                "covariance_x covariance_y covariance_yaw",
                "same",
                "ROS 2: the pose's and twist's diagonal (1e12 for z, roll, pitch); ROS 1: fixed pose values",
            ),
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
            *COMMON,
            p("jointName joint_name", "same", "ROS 1: one comma-separated list; ROS 2, gz-sim: repeated"),
            p("updateRate update_rate"),
            p("topic", "same", "gz-sim: default `world/<world>/model/<model>/joint_state`"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_imu",),
        "model",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_imu.cpp:70-136 (a model plugin; ROS 2 has only the "
        "sensor plugin gazebo_ros_imu_sensor)",
        "imu on `<bodyName>` (N(0, gaussianNoise) on every rate and acceleration)",
        (
            *COMMON,
            p("bodyName body_name topicName topic_name frameName frame_name"),
            p("updateRate update_rate updateRateHZ", "same", "0 (the default): every physics step"),
            p("gaussianNoise", "same", "white noise on every rate and acceleration"),
            p("xyzOffset rpyOffset", "ignored", "offsets of the reported pose (said)"),
            p("serviceName", "ignored", "a ROS service that calibrates; no ROS services here"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_control",),
        "model",
        "gazebo_ros_control (ROS 1 Noetic, gazebo_ros_pkgs): src/gazebo_ros_control_plugin.cpp:85-157",
        "the scenario's `controllers:` (the controller manager's parameters a launch file loads)",
        (
            p("robotNamespace", "approx", "the robot's namespace is the scenario's (said when it differs)"),
            p("robotParam", "same", "the description is the robot's"),
            p(
                "legacyModeNS",
                "ignored",
                "kinetic/melodic only (namespaced controllers); Noetic does not read it, nor do we",
            ),
            p("controlPeriod", "approx", "controllers act at every physics step (said)"),
            p("robotSimType", "approx", "DefaultRobotHWSim's interfaces; a custom one is said"),
            p("eStopTopic", "ignored", "Gazebo stops the controllers on it; not subscribed (said)"),
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
            p("parameters", "same", "the controllers files (relative to the description's file)"),
            p("ros", "approx", "`<remapping>` kept; `<namespace>` replaced by the robot's (said)"),
            p("controller_manager_name controller_manager_prefix_node_name"),
            p("robot_param robot_param_node", "same", "the description is the robot's"),
            p("hold_joints position_proportional_gain"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_laser", "gazebo_ros_gpu_laser"),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_laser.cpp:88-103, src/gazebo_ros_gpu_laser.cpp:91-105",
        "lidar (sensor_msgs/LaserScan on `<topicName>`)",
        (*COMMON, p("frameName topicName")),
    ),
    PluginDoc(
        ("gazebo_ros_block_laser",),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic): src/gazebo_ros_block_laser.cpp:106-149",
        "lidar (its points)",
        (
            *COMMON,
            p("frameName topicName updateRate"),
            p("gaussianNoise", "same", "added to the sensor's noise"),
            p(
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
        (*COMMON, p("bumperTopicName frameName frame_name")),
    ),
    PluginDoc(
        ("gazebo_ros_imu_sensor",),
        "sensor",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_imu_sensor.cpp:48-55, :175-252; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_imu_sensor.cpp:76-82, frame_name through gazebo_ros::SensorFrameID)",
        "imu (the sensor's `<imu>` noise)",
        (
            *COMMON,
            p("topicName frameName frame_name"),
            p("updateRateHZ", "same", "ROS 1: throttles the sensor's `<update_rate>`"),
            p("gaussianNoise", "same", "ROS 1: added to the sensor's noise"),
            p("xyzOffset", "ignored", "read and unused by the plugin itself"),
            p("rpyOffset", "ignored", "turns the reported orientation; said"),
            p(
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
            *COMMON,
            p("cameraName imageTopicName cameraInfoTopicName frameName updateRate"),
            p("hackBaseline", "ignored", "the stereo baseline in the right camera's CameraInfo"),
            p("Cx Cy CxPrime focalLength", "ignored", "CameraInfo is the ideal pinhole of <horizontal_fov>"),
            p("triggerTopicName borderCrop autoDistortion", "ignored", "triggering; rectification only"),
            p(
                "distortionK1 distortionK2 distortionK3 distortionT1 distortionT2",
                "ignored",
                "images are not distorted (said when not 0)",
            ),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_tricycle_drive",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_tricycle_drive.cpp:84-113; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_tricycle_drive.cpp:248-354)",
        "not supported: use the scenario's `steering_drive` plugin (a tricycle steering controller's "
        "kinematics)",
        (
            p(
                "steeringJoint actuatedWheelJoint encoderWheelLeftJoint encoderWheelRightJoint "
                "steering_joint actuated_wheel_joint encoder_wheel_left_joint encoder_wheel_right_joint",
                "ignored",
                "the steered and driven front wheel's joints; the rear wheels' joints for odometry",
            ),
            p(
                "actuatedWheelDiameter encoderWheelDiameter encoderWheelSeparation actuated_wheel_diameter "
                "encoder_wheel_diameter wheel_separation",
                "ignored",
                "the geometry of the command's inverse kinematics and of the odometry",
            ),
            p(
                "wheelTorque wheelAcceleration wheelDeceleration wheelSpeedTolerance steeringSpeed "
                "steeringAngleTolerance max_wheel_torque max_wheel_acceleration max_wheel_deceleration "
                "max_wheel_speed_tolerance max_steering_speed max_steering_angle_tolerance",
                "ignored",
                "limits of the wheel's velocity servo and of the steering's rate",
            ),
            p(
                "commandTopic odometryTopic odometryFrame robotBaseFrame odometry_frame robot_base_frame",
                "ignored",
                "the Twist it subscribes and the odometry it publishes",
            ),
            p(
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
            p(
                "front_left_joint front_right_joint rear_left_joint rear_right_joint left_steering_joint "
                "right_steering_joint steering_wheel_joint",
                "ignored",
                "the four wheels' and two steering joints; the steering wheel turned with them",
            ),
            p(
                "max_speed max_steer max_steering_angle",
                "ignored",
                "the command's limits; the steering wheel's angle at max_steer",
            ),
            p(
                "left_steering_pid_gain left_steering_i_range right_steering_pid_gain right_steering_i_range "
                "linear_velocity_pid_gain linear_velocity_i_range",
                "ignored",
                "PID gains (p i d) and integral ranges of the joint forces that track the command",
            ),
            p(
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
            p("robotNamespace", "ignored", "the namespace of its topic"),
            p("bodyName topicName frameName", "ignored", "the link; the WrenchStamped topic; its frame"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_force",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_force.cpp:72-96; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_force.cpp:68-88)",
        "not supported: no counterpart (a wrench from a topic is not applied to a link)",
        (
            p("robotNamespace ros", "ignored", "the namespace of its topic"),
            p("bodyName link_name", "ignored", "the link the wrench is applied to"),
            p("topicName", "ignored", "ROS 1: the geometry_msgs/Wrench topic it subscribes"),
            p("force_frame", "ignored", "ROS 2: world (default) or link, the frame of the wrench"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_hand_of_god",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_hand_of_god.cpp:83-99; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_hand_of_god.cpp:109-115)",
        "not supported: no counterpart (a link is not pulled along a TF frame)",
        (
            p("robotNamespace ros", "ignored", "the namespace of its TF"),
            p("frameId frame_id linkName link_name", "ignored", "the TF frame the link follows; the link"),
            p("kl ka", "ignored", "the linear and angular gains of the force and torque that pull it"),
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
            p("robotNamespace ros", "ignored", "the namespace of its topics and services"),
            p("bodyName link_name", "ignored", "the gripper's link"),
            p("topicName", "ignored", "ROS 1: the Bool topic saying whether it grasps"),
            p("max_distance", "ignored", "ROS 2: how far objects are pulled from"),
            p("fixed", "ignored", "ROS 2: models never pulled"),
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
            p("robotNamespace ros", "ignored", "the namespace of its topic"),
            p("serviceName topicName", "ignored", "ROS 1: the trajectory's service and topic"),
            p("updateRate update_rate", "ignored", "the rate at which it sets the joints' positions"),
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
            p("robotNamespace ros", "ignored", "the namespace of its parameters"),
            p("wheel link_name", "ignored", "a `<wheel link_name=...>` per wheel link"),
            p(
                "slip_compliance_lateral slip_compliance_longitudinal",
                "ignored",
                "ODE slip (velocity per force) scaled by the wheel's speed, per wheel",
            ),
            p("wheel_spin_tolerance publisher_update_rate", "ignored", "ROS 2: the slip it publishes"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_gps_sensor",),
        "sensor",
        "gazebo_plugins (ROS 2 Humble/Jazzy): src/gazebo_ros_gps_sensor.cpp:66-89 (NavSatFix on `~/out`, the "
        "velocity on `~/vel`; frame_name through gazebo_ros::SensorFrameID)",
        "gps (Gazebo's GPS sensor: its `<gps>` noise, velocity east-north-up)",
        (
            p(
                "ros",
                "approx",
                "`<remapping>` (`~/out`, `~/vel`) kept; `<namespace>` replaced by the robot's",
            ),
            p("frame_name", "same", "default: the sensor's link"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_projector",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_projector.cpp:93-110; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_projector.cpp:80-81)",
        "not supported: no counterpart (nothing is rendered from projectors here)",
        (
            p("robotNamespace ros", "ignored", "the namespace of its topics"),
            p(
                "projector projector_link projector_name",
                "ignored",
                "the `<projector>` of a link it switches",
            ),
            p(
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
            p("robotNamespace ros", "ignored", "the namespace of its topic"),
            p("topicName", "ignored", "ROS 1: the sensor_msgs/Image topic it shows"),
            p("height width name", "ignored", "the texture's size; the visual's name"),
        ),
    ),
    PluginDoc(
        ("gazebo_ros_elevator",),
        "model",
        "gazebo_plugins (ROS 1 Noetic: src/gazebo_ros_elevator.cpp:44-61; ROS 2 Humble/Jazzy: "
        "src/gazebo_ros_elevator.cpp:55-67; the lift itself is Gazebo's ElevatorPlugin)",
        "not supported: no counterpart (an elevator's lift and doors on a String command)",
        (
            p("robotNamespace ros", "ignored", "the namespace of its topic"),
            p("topic", "ignored", "ROS 1: the String topic with the floor to go to"),
            p("bottom_floor top_floor", "ignored", "ROS 2: the floors it accepts"),
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
            p("robotNamespace", "ignored", "the namespace of its topics"),
            p(
                "cameraName imageTopicName cameraInfoTopicName frameName updateRate triggerTopicName",
                "ignored",
                "the image and CameraInfo topics; the trigger topic that makes it publish one frame",
            ),
            p(
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
            p("robotNamespace ros", "ignored", "the namespace of its velocity and detach topics"),
            p("init_vel", "ignored", "ROS 2: the winch's initial velocity"),
        ),
    ),
)
