"""The ROS 2 typestore every part of the runner shares: rosbags' ROS 2 Jazzy store, with the message types
it lacks that plugins publish (`EXTRA_TYPES`). `runner.wire.msgs` (messages) and `runner.wire.interfaces`
(services and actions) add to it and read it; this module imports neither."""

from __future__ import annotations

from typing import Any

from rosbags.typesys import Stores, get_types_from_msg, get_typestore

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)

# Types that ROS 2 Jazzy's store lacks but plugins publish: name -> `.msg` text (as in their ROS packages).
EXTRA_TYPES = {
    # gazebo_msgs (gazebo_ros_pkgs, ROS 2): what gazebo_ros_bumper publishes
    "gazebo_msgs/msg/ContactState": """\
string info
string collision1_name
string collision2_name
geometry_msgs/Wrench[] wrenches
geometry_msgs/Wrench total_wrench
geometry_msgs/Vector3[] contact_positions
geometry_msgs/Vector3[] contact_normals
float64[] depths
""",
    "gazebo_msgs/msg/ContactsState": """\
std_msgs/Header header
gazebo_msgs/ContactState[] states
""",
    # control_msgs (ros2_control's controllers, Jazzy branch 5.8): what the controllers publish and take
    "control_msgs/msg/InterfaceValue": """\
string[] interface_names
float64[] values
""",
    "control_msgs/msg/DynamicJointState": """\
std_msgs/Header header
string[] joint_names
InterfaceValue[] interface_values
""",
    "control_msgs/msg/JointTrajectoryControllerState": """\
std_msgs/Header header
string[] joint_names
trajectory_msgs/JointTrajectoryPoint reference
trajectory_msgs/JointTrajectoryPoint feedback
trajectory_msgs/JointTrajectoryPoint error
trajectory_msgs/JointTrajectoryPoint output
string[] multi_dof_joint_names
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_reference
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_feedback
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_error
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_output
float64 speed_scaling_factor
""",
    # ros_gz_interfaces (ros_gz, Jazzy): what ros_gz_bridge makes of gz.msgs.Altimeter
    "ros_gz_interfaces/msg/Altimeter": """\
std_msgs/Header header
float64 vertical_position
float64 vertical_velocity
float64 vertical_reference
""",
    "control_msgs/msg/GripperCommand": """\
float64 position
float64 max_effort
""",
    "control_msgs/msg/JointControllerState": """\
std_msgs/Header header
float64 set_point
float64 process_value
float64 process_value_dot
float64 error
float64 time_step
float64 command
float64 p
float64 i
float64 d
float64 i_clamp
bool antiwindup
""",
    "control_msgs/msg/MecanumDriveControllerState": """\
std_msgs/Header header
float64 front_left_wheel_velocity
float64 back_left_wheel_velocity
float64 back_right_wheel_velocity
float64 front_right_wheel_velocity
geometry_msgs/Twist reference_velocity
""",
    "control_msgs/msg/SteeringControllerStatus": """\
std_msgs/Header header
float64[] traction_wheels_position
float64[] traction_wheels_velocity
float64[] steer_positions
float64[] linear_velocity_command
float64[] steering_angle_command
""",
}


def _register_extra_types() -> None:
    """Add `EXTRA_TYPES` to the typestore, so CDR encoding/decoding and `msgdef()` work as for built-ins."""
    types: dict[str, Any] = {}
    for name, text in EXTRA_TYPES.items():
        types.update(get_types_from_msg(text, name))
    TYPESTORE.register(types)


_register_extra_types()
