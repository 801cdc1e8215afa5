"""The plugin catalogue's entries of SDF 1.10's sensor types no reader maps (gazebosim/sdformat at 2ace5362:
sdf/1.10/sensor.sdf and each type's file), as `sensor:<type>`. The reader says such a sensor once at its line
and leaves it out (runner.compile.gazebo.sensors); its entry says why and what serves instead."""

from __future__ import annotations

from runner.compile.gazebo.plugin_doc import PluginDoc, p

ENTRIES: tuple[PluginDoc, ...] = (
    PluginDoc(
        ("sensor:logical_camera",),
        "sensor",
        "sdformat: sdf/1.10/logical_camera.sdf",
        "not supported: no counterpart (the models in a frustum, by name and pose)",
        (
            p(
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
            p("sonar.geometry sonar.radius", "ignored", "a cone (default) or sphere, its base's radius"),
            p("sonar.min sonar.max", "ignored", "the range's limits"),
        ),
    ),
    PluginDoc(
        ("sensor:air_speed",),
        "sensor",
        "sdformat: sdf/1.10/air_speed.sdf; gz-sim: src/systems/air_speed",
        "not supported: no counterpart (no air here)",
        (p("air_speed.pressure", "ignored", "the differential pressure's `<noise>`"),),
    ),
    PluginDoc(
        ("sensor:thermal_camera", "sensor:thermal"),
        "sensor",
        "sdformat: sdf/1.10/sensor.sdf, camera.sdf; gz-sim: src/systems/thermal/ThermalSensor.cc:56-58 (the "
        "thermal-sensor system's `<resolution>`, `<min_temp>`, `<max_temp>`)",
        "not supported: no counterpart (no temperatures here)",
        (p("camera", "ignored", "the image's size and field of view; temperatures come from visuals"),),
    ),
    PluginDoc(
        ("sensor:segmentation_camera", "sensor:segmentation"),
        "sensor",
        "sdformat: sdf/1.10/camera.sdf:80 (`<segmentation_type>`)",
        "not supported: no counterpart (no segmentation images here)",
        (p("camera.segmentation_type", "ignored", "semantic (default) or panoptic labels per pixel"),),
    ),
    PluginDoc(
        ("sensor:boundingbox_camera", "sensor:boundingbox"),
        "sensor",
        "sdformat: sdf/1.10/camera.sdf:94 (`<box_type>`)",
        "not supported: no counterpart (no bounding boxes here)",
        (p("camera.box_type", "ignored", "2d (default), visible_2d or 3d boxes of labelled visuals"),),
    ),
    PluginDoc(
        ("sensor:wide_angle_camera",),
        "sensor",
        "sdformat: sdf/1.10/camera.sdf:142-179 (`<lens>`)",
        "not supported: no counterpart; a `camera` sensor (a pinhole of `<horizontal_fov>`) is read",
        (
            p(
                "camera.lens",
                "ignored",
                "the lens' projection (`<type>`, `<custom_function>` c1 c2 c3 f fun, `<scale_to_hfov>`, "
                "`<cutoff_angle>`, `<env_texture_size>`, `<intrinsics>`)",
            ),
        ),
    ),
)
