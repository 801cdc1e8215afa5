"""Third-party Gazebo plugins as public robots declare them: hector_gazebo_plugins' IMU and GPS,
velodyne_simulator's lidar (ROS 1 and ROS 2), Gazebo's GPS sensor with gazebo_ros. Inline URDFs, real
compile, the world stepped in-process (real MuJoCo): topics, types, rates, frames, and the numbers against
physics (a wall at a known distance, a known displacement from the GPS reference, noise statistics)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from plugins.gps import earth_radii
from runner.plan import RunPlan
from tests.helpers import compile_with_notices, declared, messages, robot_scenario, simulate

ROBOT = """<?xml version="1.0"?>
<robot name="t">
  <link name="base_link">
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
    <inertial><mass value="2.0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <link name="imu_link">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
  </link>
  <joint name="imu_joint" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>
  <link name="gps_link">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
  </link>
  <joint name="gps_joint" type="fixed"><parent link="base_link"/><child link="gps_link"/>
    <origin xyz="0 0 0.2"/></joint>
  <link name="velodyne">
    <collision><geometry><cylinder radius="0.05" length="0.07"/></geometry></collision>
    <inertial><mass value="0.8"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial>
  </link>
  <joint name="velodyne_joint" type="fixed"><parent link="base_link"/><child link="velodyne"/>
    <origin xyz="0 0 0.95"/></joint>
  EXTRA
</robot>
"""

HECTOR_IMU = """
  <gazebo>
    <plugin name="imu_controller" filename="libhector_gazebo_ros_imu.so">
      <robotNamespace>/</robotNamespace>
      <updateRate>100.0</updateRate>
      <bodyName>imu_link</bodyName>
      <topicName>imu/data</topicName>
      <frameId>imu_link</frameId>
      <serviceName>imu/calibrate</serviceName>
      <accelOffset>0.1 -0.2 0.05</accelOffset>
      <accelDrift>0.0 0.0 0.0</accelDrift>
      <accelGaussianNoise>0.05 0.05 0.05</accelGaussianNoise>
      <rateOffset>0.01 0.02 -0.03</rateOffset>
      <rateDrift>0.0 0.0 0.0</rateDrift>
      <rateGaussianNoise>0.01 0.01 0.01</rateGaussianNoise>
      <yawOffset>0.1</yawOffset>
      <yawDrift>0.0</yawDrift>
      <yawGaussianNoise>0.0</yawGaussianNoise>
    </plugin>
  </gazebo>"""

DRIFTING_IMU = """
  <gazebo>
    <plugin name="imu_plugin" filename="libhector_gazebo_ros_imu.so">
      <updateRate>200</updateRate>
      <bodyName>imu_link</bodyName>
      <rateDrift>0.5 0.5 0.5</rateDrift>
      <rateDriftFrequency>20 20 20</rateDriftFrequency>
    </plugin>
  </gazebo>"""


def _velodyne(sensor_type: str, plugin: str) -> str:
    """A VLP-16 as velodyne_description declares it: 16 rings over ±15°, the plugin inside the sensor."""
    return f"""
  <gazebo reference="velodyne">
    <sensor type="{sensor_type}" name="velodyne-VLP16">
      <pose>0 0 0 0 0 0</pose>
      <visualize>false</visualize>
      <update_rate>10</update_rate>
      <ray>
        <scan>
          <horizontal><samples>360</samples><resolution>1</resolution>
            <min_angle>-3.14159265</min_angle><max_angle>3.14159265</max_angle></horizontal>
          <vertical><samples>16</samples><resolution>1</resolution>
            <min_angle>-0.261799388</min_angle><max_angle>0.261799388</max_angle></vertical>
        </scan>
        <range><min>0.3</min><max>131</max><resolution>0.001</resolution></range>
        <noise><type>gaussian</type><mean>0.0</mean><stddev>0.0</stddev></noise>
      </ray>
      {plugin}
    </sensor>
  </gazebo>"""


VELODYNE_ROS1 = _velodyne(
    "ray",
    """<plugin name="gazebo_ros_laser_controller" filename="libgazebo_ros_velodyne_laser.so">
        <topicName>/velodyne_points</topicName>
        <frameName>velodyne</frameName>
        <organize_cloud>false</organize_cloud>
        <min_range>0.9</min_range>
        <max_range>130.0</max_range>
        <gaussianNoise>0.0</gaussianNoise>
      </plugin>""",
)
VELODYNE_ROS2 = _velodyne(
    "gpu_ray",
    """<plugin name="gazebo_ros_laser_controller" filename="libgazebo_ros_velodyne_gpu_laser.so">
        <ros><namespace>/velodyne</namespace><remapping>~/out:=velodyne_points</remapping></ros>
        <frame_name>velodyne</frame_name>
        <organize_cloud>true</organize_cloud>
        <min_range>0.9</min_range>
        <max_range>130.0</max_range>
        <gaussian_noise>0.02</gaussian_noise>
      </plugin>""",
)

HECTOR_GPS = """
  <gazebo>
    <plugin name="gps_controller" filename="libhector_gazebo_ros_gps.so">
      <updateRate>40</updateRate>
      <bodyName>base_link</bodyName>
      <topicName>gps/fix</topicName>
      <velocityTopicName>gps/fix_velocity</velocityTopicName>
      <drift>0 0 0</drift>
      <gaussianNoise>GPS_NOISE</gaussianNoise>
      <velocityDrift>0 0 0</velocityDrift>
      <velocityGaussianNoise>0 0 0</velocityGaussianNoise>
      REFERENCE
    </plugin>
  </gazebo>"""

GPS_SENSOR = """
  <gazebo reference="gps_link">
    <sensor name="gps_sensor" type="gps">
      <always_on>true</always_on>
      <update_rate>20</update_rate>
      <gps>
        <position_sensing>
          <horizontal><noise type="gaussian"><mean>0.0</mean><stddev>0.3</stddev></noise></horizontal>
          <vertical><noise type="gaussian"><mean>0.0</mean><stddev>0.6</stddev></noise></vertical>
        </position_sensing>
      </gps>
      <plugin name="gps_plugin" filename="libgazebo_ros_gps_sensor.so">
        <ros><remapping>~/out:=gps/fix</remapping></ros>
        <frame_name>gps_link</frame_name>
      </plugin>
    </sensor>
  </gazebo>"""


def _write(
    tmp_path: Path,
    extra: str,
    duration: float = 1.0,
    seed: int = 1,
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.05),
    plugins: str = "[]",
    models: str = "",
    timeline: str = "",
    name: str = "t",
) -> Path:
    return robot_scenario(
        tmp_path,
        ROBOT.replace("EXTRA", extra),
        name=name,
        seed=seed,
        duration=duration,
        world=f"  models:\n{models}" if models else "",
        xyz=xyz,
        plugins=plugins,
        timeline=timeline,
    )


def _topics(plan: RunPlan) -> dict[str, str]:
    """The robot's topics from its declared plugins (not robot_state_publisher's `tf`, `tf_static`)."""
    return {
        t.key.removeprefix("g/bot/"): t.type
        for plugin in declared(plan.robots[0])
        for t in plugin.topics
        if t.key.startswith("g/bot/")
    }


def _vec(v: object) -> list[float]:
    return [v.x, v.y, v.z]  # type: ignore[attr-defined]


def _euler(q: object) -> tuple[float, float, float]:
    """roll, pitch, yaw (ZYX) of a geometry_msgs/Quaternion."""
    x, y, z, w = q.x, q.y, q.z, q.w  # type: ignore[attr-defined]
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


# ------------------------------------------------------------------------------------------ hector IMU
def test_hector_imu_publishes_with_its_error_model(tmp_path: Path):
    path = _write(tmp_path, HECTOR_IMU, duration=3.0)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    assert "<serviceName>" in notices  # reported at its line, not dropped silently
    topics = _topics(plan)
    assert topics["imu/data"] == topics["imu/data/bias"] == "sensor_msgs/msg/Imu"
    (imu,) = [p for p in plan.robots[0].plugins if p.type == "imu"]
    assert imu.rate == 100
    _, bus = simulate(path)
    msgs = messages(bus, "bot/imu/data")
    assert abs(len(msgs) - 300) <= 1  # <updateRate> 100 Hz for 3 s
    assert {m.header.frame_id for _, m in msgs} == {"bot/imu_link"}
    settled = [m for t, m in msgs if t >= 500_000_000]  # resting on the ground
    acc = np.array([_vec(m.linear_acceleration) for m in settled])
    gyro = np.array([_vec(m.angular_velocity) for m in settled])
    # offsets are constant biases; the gaussian noise is white with the given stddev
    assert np.allclose(acc.mean(axis=0), [0.1, -0.2, 9.81 + 0.05], atol=0.02)
    assert np.allclose(acc.std(axis=0), 0.05, rtol=0.15)
    assert np.allclose(gyro.mean(axis=0), [0.01, 0.02, -0.03], atol=0.003)
    assert np.allclose(gyro.std(axis=0), 0.01, rtol=0.15)
    assert msgs[-1][1].angular_velocity_covariance[0] == 0.01**2
    # the orientation: heading turned by yawOffset, tilted as the biased accelerometer levels it
    roll, pitch, yaw = _euler(settled[-1].orientation)
    assert abs(yaw - 0.1) < 1e-3
    assert abs(roll - (-0.2 / 9.81)) < 1e-3 and abs(pitch - (-0.1 / 9.81)) < 1e-3
    bias = messages(bus, "bot/imu/data/bias")
    assert len(bias) == len(msgs) and bias[-1][1].header.frame_id == "bot/imu_link"
    assert np.allclose(_vec(bias[-1][1].linear_acceleration), [0.1, -0.2, 0.05])
    assert np.allclose(_vec(bias[-1][1].angular_velocity), [0.01, 0.02, -0.03])


def test_hector_imu_drift_is_its_gauss_markov_process(tmp_path: Path):
    """rateDrift 0.5 rad/s at 20 Hz, read at 200 Hz: b' = b·exp(-20/200) + (1/200)·N(0, sqrt(40)·0.5)."""
    path = _write(tmp_path, DRIFTING_IMU, duration=6.0, seed=3)
    plan, _ = compile_with_notices(path)
    assert _topics(plan)["imu/bias"] == "sensor_msgs/msg/Imu"  # default topic `imu`, bias beside it
    _, bus = simulate(path)
    bias = np.array([_vec(m.angular_velocity) for _, m in messages(bus, "bot/imu/bias")])
    assert len(bias) >= 1199
    dt, f, sigma = 1 / 200, 20.0, 0.5
    prev, nxt = bias[:-1].ravel(), bias[1:].ravel()
    slope = float(np.dot(prev, nxt) / np.dot(prev, prev))
    assert abs(slope - math.exp(-f * dt)) < 0.02
    step = nxt - math.exp(-f * dt) * prev
    assert abs(step.std() / (dt * math.sqrt(2 * f) * sigma) - 1) < 0.08
    assert abs(step.mean()) < 0.002
    # the published rates carry that bias (the robot rests: true rate ~0)
    rates = np.array([_vec(m.angular_velocity) for _, m in messages(bus, "bot/imu")])
    assert np.allclose(rates[200:], bias[200:], atol=2e-3)


# ------------------------------------------------------------------------------------------ velodyne
WALL = "    - {name: wall, shape: box, size: [0.2, 4.0, 6.0], pose: {xyz: [3.1, 0, 1.0]}}\n"


def _wall_hits(n_samples: int = 360, distance: float = 3.0, half_width: float = 2.0) -> int:
    """Azimuths of a 360-sample scan (both ends at ±π) that reach the wall face x = distance, |y| < 2."""
    az = np.linspace(-math.pi, math.pi, n_samples)
    return int(np.sum((np.cos(az) > 0) & (np.abs(distance * np.tan(az)) < half_width)))


def _cloud(msg: object) -> np.ndarray:
    dtype = np.dtype(
        {
            "names": ["x", "y", "z", "intensity", "ring", "time"],
            "formats": ["<f4", "<f4", "<f4", "<f4", "<u2", "<f4"],
            "offsets": [0, 4, 8, 12, 16, 18],
            "itemsize": 22,
        }
    )
    return np.frombuffer(bytes(msg.data), dtype=dtype)  # type: ignore[attr-defined]


def test_velodyne_ros1_publishes_only_its_point_cloud(tmp_path: Path):
    path = _write(tmp_path, VELODYNE_ROS1, duration=1.0, models=WALL)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    topics = _topics(plan)
    assert topics == {"velodyne_points": "sensor_msgs/msg/PointCloud2"}  # no LaserScan
    _, bus = simulate(path)
    clouds = messages(bus, "bot/velodyne_points")
    assert len(clouds) in (10, 11)  # the sensor's <update_rate>
    msg = clouds[-1][1]
    assert msg.header.frame_id == "bot/velodyne"
    fields = [(f.name, f.offset, f.datatype, f.count) for f in msg.fields]
    assert fields == [
        ("x", 0, 7, 1),
        ("y", 4, 7, 1),
        ("z", 8, 7, 1),
        ("intensity", 12, 7, 1),
        ("ring", 16, 4, 1),
        ("time", 18, 7, 1),
    ]
    assert msg.point_step == 22 and msg.height == 1 and msg.is_dense
    assert msg.row_step == 22 * msg.width == len(msg.data)
    pts = _cloud(msg)
    # the sensor sits 1.0 m above the ground (0.05 + 0.95) at x = 0: every return is on the wall's face
    # (x = 3.0) or on the ground (z = -1.0), none nearer than min_range
    on_ground = np.abs(pts["z"] + 1.0) < 0.02
    on_wall = (np.abs(pts["x"] - 3.0) < 0.01) & ~on_ground
    assert np.all(on_wall | on_ground)
    assert on_wall.sum() == 16 * _wall_hits()  # every ring of every azimuth facing the wall
    assert np.all(np.abs(pts["y"][on_wall]) < 2.0)
    r = np.sqrt(pts["x"] ** 2 + pts["y"] ** 2 + pts["z"] ** 2)
    assert r.min() > 0.9
    # ring = beam index from the lowest (-15°), 2° apart
    elevation = np.degrees(np.arctan2(pts["z"], np.hypot(pts["x"], pts["y"])))
    assert np.allclose(elevation[on_wall], -15 + 2 * pts["ring"][on_wall].astype(float), atol=0.05)
    assert np.all(pts["intensity"] == 0) and np.all(pts["time"] == 0)
    # the rings of one azimuth, then the next azimuth (as the plugin and the velodyne driver order them)
    wall_rings = pts["ring"][on_wall]
    assert list(wall_rings[:16]) == list(range(16))


def test_velodyne_ros2_organized_cloud_with_noise(tmp_path: Path):
    path = _write(tmp_path, VELODYNE_ROS2, duration=1.0, models=WALL)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    assert "ROS namespace 'velodyne' is replaced" in notices
    assert _topics(plan) == {"velodyne_points": "sensor_msgs/msg/PointCloud2"}  # ~/out, remapped
    _, bus = simulate(path)
    clouds = messages(bus, "bot/velodyne_points")
    assert len(clouds) in (10, 11)
    msg = clouds[-1][1]
    # organized: one row per azimuth, one column per ring, NaN where there is no return
    assert (msg.height, msg.width) == (360, 16) and not msg.is_dense
    assert msg.header.frame_id == "bot/velodyne"
    pts = np.concatenate([_cloud(m) for _, m in clouds]).reshape(-1, 360, 16)
    assert np.array_equal(pts["ring"][0], np.tile(np.arange(16), (360, 1)))
    x = pts["x"]
    wall = np.isfinite(x) & (np.abs(x - 3.0) < 0.2) & (np.abs(pts["z"] + 1.0) > 0.2)
    assert np.isnan(pts["intensity"][~np.isfinite(x)]).all()
    # <gaussian_noise> 0.02 m along each beam: the distance to the wall face, beam by beam
    direction = np.stack([x, pts["y"], pts["z"]])[:, wall]
    r = np.linalg.norm(direction, axis=0)
    true = 3.0 * r / direction[0]
    assert wall.sum() > 5000
    assert abs(np.std(r - true) / 0.02 - 1) < 0.08
    assert abs(np.mean(r - true)) < 0.002


# ------------------------------------------------------------------------------------------ sonar
def _sonar(name: str, yaw: float, noise: float) -> str:
    """A sonar as hector_sensors_description declares one: a 3x3 ray cone, the plugin inside; 0.55 m
    above the ground, which its lowest rays (-0.1 rad) meet 5.5 m away, beyond its 3 m."""
    return f"""
  <link name="{name}_link">
    <inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" iyz="0" izz="1e-6"/></inertial>
  </link>
  <joint name="{name}_joint" type="fixed"><parent link="base_link"/><child link="{name}_link"/>
    <origin xyz="{0.15 * math.cos(yaw):.6f} {0.15 * math.sin(yaw):.6f} 0.5" rpy="0 0 {yaw}"/></joint>
  <gazebo reference="{name}_link">
    <sensor type="ray" name="{name}">
      <always_on>true</always_on>
      <update_rate>50</update_rate>
      <ray>
        <scan>
          <horizontal><samples>3</samples><resolution>1</resolution>
            <min_angle>-0.1</min_angle><max_angle>0.1</max_angle></horizontal>
          <vertical><samples>3</samples><resolution>1</resolution>
            <min_angle>-0.1</min_angle><max_angle>0.1</max_angle></vertical>
        </scan>
        <range><min>0.03</min><max>3.0</max><resolution>0.01</resolution></range>
      </ray>
      <plugin name="gazebo_ros_{name}_controller" filename="libhector_gazebo_ros_sonar.so">
        <updateRate>20</updateRate>
        <gaussianNoise>{noise}</gaussianNoise>
        <topicName>{name}</topicName>
        <frameId>{name}_link</frameId>
      </plugin>
    </sensor>
  </gazebo>"""


def test_hector_sonar_publishes_the_nearest_range(tmp_path: Path):
    extra = _sonar("sonar_front", 0.0, 0.01) + _sonar("sonar_back", math.pi, 0.01)
    path = _write(tmp_path, extra, duration=5.0, models=WALL)
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    assert _topics(plan) == {"sonar_front": "sensor_msgs/msg/Range", "sonar_back": "sensor_msgs/msg/Range"}
    _, bus = simulate(path)
    front = messages(bus, "bot/sonar_front")
    assert abs(len(front) - 100) <= 1  # the plugin's <updateRate>, not the sensor's
    msg = front[-1][1]
    assert msg.header.frame_id == "bot/sonar_front_link"
    assert msg.radiation_type == 0 and abs(msg.field_of_view - 0.2) < 1e-6
    assert abs(msg.min_range - 0.03) < 1e-6 and abs(msg.max_range - 3.0) < 1e-6
    ranges = np.array([m.range for _, m in front])
    # the wall's face is 2.85 m ahead of the sonar: the nearest (central) ray, with the plugin's noise
    assert abs(ranges.mean() - 2.85) < 0.004 and abs(ranges.std() / 0.01 - 1) < 0.2
    # nothing behind within 3 m: max_range, without noise (as hector)
    assert {m.range for _, m in messages(bus, "bot/sonar_back")} == {np.float32(3.0)}


# ------------------------------------------------------------------------------------------ GPS
def test_hector_gps_latitude_longitude_around_its_reference(tmp_path: Path):
    """100 m along x, 30 m along y: hector's defaults (heading 0) have x north and y west."""
    extra = HECTOR_GPS.replace("GPS_NOISE", "0 0 0").replace("REFERENCE", "")
    path = _write(tmp_path, extra, duration=1.0, xyz=(100.0, 30.0, 0.05))
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    topics = _topics(plan)
    assert topics["gps/fix"] == "sensor_msgs/msg/NavSatFix"
    assert topics["gps/fix_velocity"] == "geometry_msgs/msg/Vector3Stamped"
    _, bus = simulate(path)
    fixes = messages(bus, "bot/gps/fix")
    assert abs(len(fixes) - 40) <= 1
    fix = fixes[-1][1]
    r_north, r_east = earth_radii(49.9)
    assert abs(math.degrees(100.0 / r_north) - 0.000899) < 1e-6  # ~0.000899° a hundred metres north
    assert abs(fix.latitude - (49.9 + math.degrees(100.0 / r_north))) < 1e-8
    assert abs(fix.longitude - (8.9 - math.degrees(30.0 / r_east))) < 1e-8  # +y is west
    assert abs(fix.altitude - 0.05) < 0.01  # the link origin: resting, its box half-height above ground
    assert fix.header.frame_id == "world" and fix.status.status == 0 and fix.status.service == 0
    assert fix.position_covariance_type == 2


def test_hector_gps_heading_noise_and_velocity(tmp_path: Path):
    """referenceHeading 90 (x east, y north), driven east at 1 m/s; hector's velocity is north-west-up."""
    reference = (
        "<referenceLatitude>-33.5</referenceLatitude><referenceLongitude>151.2</referenceLongitude>"
        "<referenceHeading>90</referenceHeading><referenceAltitude>100</referenceAltitude>"
    )
    extra = HECTOR_GPS.replace("GPS_NOISE", "0.5 0.5 0.5").replace("REFERENCE", reference)
    timeline = "  - {t: 0.0, topic: bot/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: 1.0}}}\n"
    path = _write(
        tmp_path,
        extra,
        duration=8.0,
        plugins="[{type: planar_move}, {type: ground_truth, params: {rate: 40}}]",
        timeline=timeline,
    )
    _, bus = simulate(path)
    fixes = messages(bus, "bot/gps/fix")
    truth = messages(bus, "bot/ground_truth")
    assert len(fixes) == len(truth)
    r_north, r_east = earth_radii(-33.5)
    east = np.array([math.radians(m.longitude - 151.2) * r_east for _, m in fixes])
    north = np.array([math.radians(m.latitude + 33.5) * r_north for _, m in fixes])
    up = np.array([m.altitude - 100 for _, m in fixes])
    x = np.array([m.pose.pose.position.x for _, m in truth])
    y = np.array([m.pose.pose.position.y for _, m in truth])
    z = np.array([m.pose.pose.position.z for _, m in truth])
    for err in (east - x, north - y, up - z):  # <gaussianNoise> 0.5 m per axis, white
        assert abs(err.std() / 0.5 - 1) < 0.1 and abs(err.mean()) < 0.08
    assert fixes[-1][1].position_covariance[0] == 0.25
    vel = messages(bus, "bot/gps/fix_velocity")
    v = np.array([_vec(m.vector) for t, m in vel if t > 2e9])
    assert np.allclose(v.mean(axis=0), [0.0, -1.0, 0.0], atol=0.05)  # east is -west


def test_a_navsat_sensor_is_the_gps_sensor_under_sdfs_newer_name(tmp_path: Path):
    """sdf/1.10/navsat.sdf: `<sensor type="navsat">` with a `<navsat>` block is the GPS sensor (gz-sensors'
    NavSat); it was said as not supported and left out."""
    navsat = GPS_SENSOR.replace('type="gps"', 'type="navsat"').replace("<gps>", "<navsat>")
    navsat = navsat.replace("</gps>", "</navsat>")
    path = _write(tmp_path, navsat, duration=1.0, xyz=(50.0, 200.0, 0.05))
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices and "left out" not in notices, notices
    assert _topics(plan)["gps/fix"] == "sensor_msgs/msg/NavSatFix"
    _, bus = simulate(path)
    fixes = messages(bus, "bot/gps/fix")
    r_north, _r_east = earth_radii(0.0)
    north = np.array([math.radians(m.latitude) * r_north for _, m in fixes])
    assert len(fixes) >= 19 and abs(north.mean() - 200) < 0.3
    # without a ROS plugin: gz-sensors' one topic, no separate velocity topic
    bare = navsat.split("<plugin")[0] + "</sensor>\n  </gazebo>"
    plan, _said = compile_with_notices(_write(tmp_path, bare, duration=1.0))
    assert [t for t in _topics(plan) if "vel" in t] == [], _topics(plan)


def test_gazebo_gps_sensor_with_the_ros2_plugin(tmp_path: Path):
    """Gazebo's reference (0°, 0°, 0 m), x east and y north; the robot 50 m east and 200 m north."""
    path = _write(tmp_path, GPS_SENSOR, duration=5.0, xyz=(50.0, 200.0, 0.05))
    plan, notices = compile_with_notices(path)
    assert "not supported" not in notices
    topics = _topics(plan)
    assert topics["gps/fix"] == "sensor_msgs/msg/NavSatFix"  # ~/out:=gps/fix
    assert topics["gps_plugin/vel"] == "geometry_msgs/msg/Vector3Stamped"  # ~/vel, not remapped
    _, bus = simulate(path)
    fixes = messages(bus, "bot/gps/fix")
    assert abs(len(fixes) - 100) <= 1
    assert fixes[0][1].header.frame_id == "bot/gps_link"
    assert fixes[0][1].status.service == 1  # SERVICE_GPS
    r_north, r_east = earth_radii(0.0)
    north = np.array([math.radians(m.latitude) * r_north for _, m in fixes])
    east = np.array([math.radians(m.longitude) * r_east for _, m in fixes])
    up = np.array([m.altitude for _, m in fixes])
    assert abs(north.mean() - 200) < 0.1 and abs(east.mean() - 50) < 0.1
    assert abs(up.mean() - 0.25) < 0.15  # gps_link: 0.2 m above the resting base link
    assert abs(north.std() / 0.3 - 1) < 0.2 and abs(up.std() / 0.6 - 1) < 0.2
    assert np.allclose(fixes[0][1].position_covariance[[0, 4, 8]], [0.09, 0.09, 0.36])
