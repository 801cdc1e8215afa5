"""The mapping tables of the Gazebo reader: which tags are ignored on purpose (and why), which plugins
are read, which are no-ops here, the image formats, and the parameter names each real plugin reads (classic
ROS 1, ROS 2 and gz-sim spellings), so that anything else in a plugin's block is reported as Gazebo
itself would ignore it."""

from __future__ import annotations

# Tags whose meaning is GUI-only or debugging, ignored on purpose; listed with this reason.
IGNORED_REASONS = {
    "visualize": "GUI only",
    "always_on": "sensors are always on",
    "alwaysOn": "sensors are always on",
    "rosDebugLevel": "ROS debug level",
    "legacyMode": "wheel order is taken from the joint names",
    "hackBaseline": "stereo baseline (mono camera)",
    "enable_metrics": "diagnostics",
    "gaussianNoise": "use the sensor's <noise>",
    "minDepth": "ODE contact parameter; MuJoCo contacts are soft (solref/solimp)",
    "maxVel": "ODE contact parameter; MuJoCo contacts are soft (solref/solimp)",
    "serviceName": "no ROS services",
    "maxContacts": "MuJoCo finds contacts itself",
    "provideFeedback": "no joint wrench feedback",
    "implicitSpringDamper": "MuJoCo integrates joint damping implicitly",
    "disableFixedJointLumping": "fixed joints are never lumped",
    "preserveFixedJoint": "fixed joints are never lumped",
    "static": "only a whole model can be static, in Gazebo too",
}


# Plugin parameters that name joints of the robot (one, or a list).
JOINT_PARAMS = {"left_joint", "right_joint"}
JOINT_LIST_PARAMS = {"left_joints", "right_joints", "joints"}


FORMATS = {
    "R8G8B8": "rgb8",
    "RGB_INT8": "rgb8",
    "B8G8R8": "bgr8",
    "BGR_INT8": "bgr8",
    "L8": "mono8",
    "L_INT8": "mono8",
}
DISTORTION = (
    "distortionK1",
    "distortionK2",
    "distortionK3",
    "distortionT1",
    "distortionT2",
    "distortion_k1",
    "distortion_k2",
    "distortion_k3",
    "distortion_t1",
    "distortion_t2",
)
# Camera plugin parameters, ROS 1 (gazebo_ros_camera_utils, depth_camera, openni_kinect) and ROS 2
# (gazebo_ros_camera); the distortion ones and <updateRate> are handled on their own.
ROS1_CAMERA_PARAMS = {
    "cameraName",
    "imageTopicName",
    "cameraInfoTopicName",
    "depthImageTopicName",
    "depthImageCameraInfoTopicName",
    "pointCloudTopicName",
    "triggerTopicName",
    "frameName",
    "pointCloudCutoff",
    "pointCloudCutoffMax",
    "Cx",
    "Cy",
    "CxPrime",
    "focalLength",
    "hackBaseline",
    "borderCrop",
    "autoDistortion",
}
ROS2_CAMERA_PARAMS = {
    "ros",
    "camera_name",
    "frame_name",
    "hack_baseline",
    "cx",
    "cy",
    "focal_length",
    "min_depth",
    "max_depth",
    "border_crop",
    "triggered",
}
ROS2_CAMERA_DECISIVE = ("ros", "camera_name", "frame_name")
ROS1_CAMERA_EVIDENCE = (
    "cameraName",
    "imageTopicName",
    "cameraInfoTopicName",
    "depthImageTopicName",
    "depthImageCameraInfoTopicName",
    "pointCloudTopicName",
    "robotNamespace",
    "frameName",
    "updateRate",
)
CAMERA_KNOWN = (
    ROS1_CAMERA_PARAMS
    | ROS2_CAMERA_PARAMS
    | set(DISTORTION)
    | {"updateRate", "update_rate", "updateRateHZ", "robotNamespace", "alwaysOn", "always_on"}
)
# Read by one ROS version and not the other, but with no effect on what is published.
HARMLESS = {"hackBaseline", "hack_baseline", "borderCrop", "border_crop", "autoDistortion"}
NOISE_TAGS = {"type", "mean", "stddev", "bias_mean", "bias_stddev"}
IMU_TAGS = {"angular_velocity", "linear_acceleration", "noise"}
CAMERA_PLUGINS = {
    "gazebo_ros_camera",
    "gazebo_ros_depth_camera",
    "gazebo_ros_openni_kinect",
    "gazebo_ros_multicamera",
}
# gazebo_ros sensor plugins (the third-party ones: thirdparty.SENSOR_PLUGINS)
ROS_SENSOR_PLUGINS = CAMERA_PLUGINS | {
    "gazebo_ros_laser",
    "gazebo_ros_gpu_laser",
    "gazebo_ros_ray_sensor",
    "gazebo_ros_block_laser",
    "gazebo_ros_imu_sensor",
    "gazebo_ros_imu",
    "gazebo_ros_bumper",
}
# gz-sim systems that only switch on what our world always does (physics, sensors, broadcasting).
NOOP_PLUGINS = {
    "gz-sim-sensors-system",
    "gz-sim-imu-system",
    "gz-sim-physics-system",
    "gz-sim-user-commands-system",
    "gz-sim-scene-broadcaster-system",
    "gz-sim-contact-system",
    "gz-sim-forcetorque-system",
}


# The parameters the real Gazebo plugins read (classic ROS 1 and ROS 2 spellings, gz-sim systems): anything
# else in their block is a typo or a leftover that Gazebo itself ignores, and is reported as such.
DIFF_DRIVE_PARAMS = {
    "alwaysOn",
    "updateRate",
    "leftJoint",
    "rightJoint",
    "wheelSeparation",
    "wheelDiameter",
    "wheelAcceleration",
    "wheelTorque",
    "commandTopic",
    "odometryTopic",
    "odometryFrame",
    "robotBaseFrame",
    "publishWheelTF",
    "publishOdomTF",
    "publishWheelJointState",
    "publishTf",
    "legacyMode",
    "rosDebugLevel",
    "odometrySource",
    "robotNamespace",
    "ros",
    "update_rate",
    "left_joint",
    "right_joint",
    "wheel_separation",
    "wheel_diameter",
    "max_wheel_torque",
    "max_wheel_acceleration",
    "publish_odom",
    "publish_odom_tf",
    "publish_wheel_tf",
    "odometry_frame",
    "robot_base_frame",
    "odometry_source",
    "covariance_x",
    "covariance_y",
    "covariance_yaw",
    "num_wheel_pairs",
}
GZ_DIFF_DRIVE_PARAMS = {
    "left_joint",
    "right_joint",
    "wheel_separation",
    "wheel_radius",
    "odom_publish_frequency",
    "max_linear_acceleration",
    "min_linear_acceleration",
    "max_angular_acceleration",
    "min_angular_acceleration",
    "max_linear_velocity",
    "min_linear_velocity",
    "max_angular_velocity",
    "min_angular_velocity",
    "max_velocity",
    "max_acceleration",
    "max_jerk",
    "min_jerk",
    "topic",
    "odom_topic",
    "tf_topic",
    "frame_id",
    "child_frame_id",
}
SKID_STEER_PARAMS = {
    "alwaysOn",
    "updateRate",
    "leftFrontJoint",
    "rightFrontJoint",
    "leftRearJoint",
    "rightRearJoint",
    "wheelSeparation",
    "wheelDiameter",
    "robotBaseFrame",
    "torque",
    "commandTopic",
    "odometryTopic",
    "odometryFrame",
    "broadcastTF",
    "covariance_x",
    "covariance_y",
    "covariance_yaw",
    "robotNamespace",
    "ros",
    "update_rate",
    "left_front_joint",
    "right_front_joint",
    "left_rear_joint",
    "right_rear_joint",
}
PLUGIN_PARAMS = {
    "gazebo_ros_diff_drive": DIFF_DRIVE_PARAMS,
    "gz-sim-diff-drive-system": GZ_DIFF_DRIVE_PARAMS,
    "gz-sim-diffdrive-system": GZ_DIFF_DRIVE_PARAMS,
    "gazebo_ros_skid_steer_drive": SKID_STEER_PARAMS,
}
