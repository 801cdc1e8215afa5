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
    # the systems of the field sensors read by runner.compile.gazebo.field_sensors (issue 38's catalogue)
    "gz-sim-magnetometer-system",
    "gz-sim-air-pressure-system",
    "gz-sim-altimeter-system",
    "gz-sim-navsat-system",  # (navsat sensors: read as gps, runner.compile.gazebo.thirdparty)
}
