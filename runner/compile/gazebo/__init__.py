"""URDF `<gazebo>` extension tags -> our plugins and MuJoCo properties (Gazebo classic and Harmonic).

- `<gazebo reference="link">`: materials (`Gazebo/Red`, or `<material><diffuse>`), `mu1`/`mu2` (friction),
  `kp`/`kd` (contact stiffness and damping), `turnGravityOff`/`gravity`, and `<sensor>`s; these keys as text
  or, as Gazebo's URDF parser also takes them, as a `value` attribute (`<mu1 value="0.5"/>`);
- `<gazebo>` (no reference): model plugins (`<plugin filename=...>`) and `<static>`;
- sensors: ray/gpu_ray/lidar/gpu_lidar -> `lidar`; camera -> `camera`; depth/depth_camera/rgbd_camera ->
  `depth_camera`; imu -> `imu` (SDF noise with its bias); with the topic names their ROS plugin gives
  (classic `topicName`, `cameraName`+`imageTopicName`..., ROS 2 `<camera_name>` or the sensor's name and
  `<ros><remapping>`) or Harmonic `<topic>`, placed under the robot's namespace, and the rate of the sensor
  as the plugin throttles it (classic `<updateRate>`).

What is not understood is listed as a notice (tag, file, line), never dropped silently and never fatal.

Where things live: `reader` (the `<gazebo>` blocks, `read_gazebo`), `sensors` (the `<sensor>` kinds and
their SDF blocks), `noise` (SDF `<noise>`), `sensor_plugins` (the ROS plugin inside a sensor),
`model_plugins` (model plugins), `controllers` (ros_control / ros2_control), `thirdparty` (hector,
velodyne, GPS), `tables` (the tag and parameter tables), `tags` (`TagReader` and text helpers), `base`
(`ReaderBase`, what the handlers are given), `info` (the results).
"""

from runner.compile.gazebo.info import DescribedPlugin, GazeboInfo, LinkProps, Where
from runner.compile.gazebo.reader import GazeboReader, parse, read_gazebo

__all__ = ["DescribedPlugin", "GazeboInfo", "GazeboReader", "LinkProps", "Where", "parse", "read_gazebo"]
