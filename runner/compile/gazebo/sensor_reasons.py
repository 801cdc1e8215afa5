"""Why an element of an SDF `<sensor>` (sdf/1.10 sensor.sdf and its blocks) is not used here, per block, as
`g.ignored(reader, context, reasons)` says it at the element's own line; and the sensor types we do not
have, with what Gazebo does with them. Everything else of the spec is read by runner.compile.gazebo.sensors,
.field_sensors, .noise and .thirdparty (tests/test_sensor_ledger.py walks the whole spec)."""

from __future__ import annotations

CAMERA = {
    "save": "Gazebo writes the frames to <path> on disk; not here",
    "segmentation_type": "read only by a segmentation camera, which we do not have",
    "box_type": "read only by a bounding-box camera, which we do not have",
    "distortion": "images are not distorted, the ideal pinhole of <horizontal_fov>; Gazebo applies the "
    "Brown-Conrady model to the rendered image",
    "lens": "the projection is the ideal pinhole of <horizontal_fov>; Gazebo applies the lens' type, "
    "intrinsics and projection to the image and CameraInfo",
    "visibility_mask": "every visual is visible to every camera: visibility flags are not modelled",
    "optical_frame_id": "the images' frame_id is the plugin's <frame_name> or the link; gz-sensors writes "
    "this one in CameraInfo's header",
}
IMAGE = {"anti_aliasing": "the renderer's own anti-aliasing is used; Gazebo's MSAA samples are not set"}
DEPTH_CAMERA = {
    "clip": "depths are clipped at the camera's <clip> and the plugin's limits; gz-sensors clips the depth "
    "image at this one",
}
LIDAR = {
    "visibility_mask": "every object is visible to the lidar: visibility flags are not modelled",
}
IMU_FRAME = {
    "custom_rpy": "read only with <localization> CUSTOM, which is not applied: the orientation is in the "
    "world frame, ENU",
    "grav_dir_x": "read only with <localization> CUSTOM, which is not applied: the orientation is in the "
    "world frame, ENU",
}
NOT_SDF = "not an SDF element; Gazebo's SDF parser warns of it and ignores it"

# Sensor types we do not have -> what Gazebo does with them (said at the <sensor>, which accounts for all
# of its block)
UNSUPPORTED = {
    "air_speed": "gz-sensors publishes the airspeed, gz.msgs.AirSpeed, from the wind and the link's velocity",
    "logical_camera": "Gazebo publishes the names and poses of the models in its frustum as "
    "gz.msgs.LogicalCameraImage",
    "rfid": "Gazebo Classic's RFID reader reports the tags within its range on Gazebo transport only",
    "rfidtag": "Gazebo Classic's RFID tag is only seen by an RFID reader",
    "sonar": "Gazebo Classic's sonar cone publishes the nearest range on Gazebo transport only; a ray "
    "sensor with libgazebo_ros_range.so, which is read, gives a sensor_msgs/Range",
    "wireless_transceiver": "Gazebo Classic's wireless transmitter/receiver model signal strengths on "
    "Gazebo transport only",
    "wireless_transmitter": "Gazebo Classic's wireless transmitter models signal strength on Gazebo "
    "transport only",
    "wireless_receiver": "Gazebo Classic's wireless receiver models signal strength on Gazebo transport only",
    "thermal_camera": "gz-sensors renders temperatures from the visuals' temperature properties",
    "segmentation_camera": "gz-sensors renders a label per visual",
    "boundingbox_camera": "gz-sensors publishes the boxes of the labelled visuals in view",
    "wide_angle_camera": "Gazebo renders a cube map through the <lens>",
    "multicamera": "Gazebo Classic renders several cameras in one sensor",
}
