"""ROS 2 service and action types: their definitions, registered in the message typestore as ROS 2 generates
them, and their REP-2016 type hashes.

ROS 2 (rosidl) turns a service `pkg/srv/Name` into messages `Name_Request`, `Name_Response` and (Iron and
later) `Name_Event` (`service_msgs/ServiceEventInfo info`, `Name_Request[<=1] request`,
`Name_Response[<=1] response`); the service's type hash is the hash of a type with the three fields
`request_message`, `response_message`, `event_message` (rosidl_generator_type_description). An action
`pkg/action/Name` becomes `Name_Goal`, `Name_Result`, `Name_Feedback`, the services `Name_SendGoal`
(`unique_identifier_msgs/UUID goal_id`, `Name_Goal goal` -> `bool accepted`,
`builtin_interfaces/Time stamp`) and `Name_GetResult` (`goal_id` -> `int8 status`, `Name_Result result`),
and the message `Name_FeedbackMessage` (`goal_id`, `Name_Feedback feedback`) (rosidl_parser's action
conventions, rcl_action's topic and service names).

The definitions below are those of ROS 2 Jazzy's packages (std_srvs, action_msgs, control_msgs 5.x,
controller_manager_msgs, gazebo_msgs of gazebo_ros_pkgs' ros2 branch, ros_gz_interfaces), comments left
out. Hashes checked against ones published by ROS 2 Jazzy systems (tests/test_services.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

from rosbags.typesys import get_types_from_msg
from rosbags.typesys.base import Nodetype

from runner.wire.typestore import TYPESTORE

# messages the services and actions below refer to that the Jazzy store lacks
_MESSAGES = {
    "control_msgs/msg/JointTolerance": """\
string name
float64 position
float64 velocity
float64 acceleration
""",
    "control_msgs/msg/JointComponentTolerance": """\
uint16 X_AXIS=1
uint16 Y_AXIS=2
uint16 Z_AXIS=3
uint16 TRANSLATION=4
uint16 ROTATION=5
string joint_name
uint16 component
float64 position
float64 velocity
float64 acceleration
""",
    "controller_manager_msgs/msg/ChainConnection": """\
string name
string[] reference_interfaces
""",
    "controller_manager_msgs/msg/ControllerState": """\
string name
string state
string type
bool is_async
uint16 update_rate
string[] claimed_interfaces
string[] required_command_interfaces
string[] required_state_interfaces
bool is_chainable
bool is_chained
string[] exported_state_interfaces
string[] reference_interfaces
controller_manager_msgs/ChainConnection[] chain_connections
""",
    "controller_manager_msgs/msg/HardwareInterface": """\
string name
string data_type
bool is_available
bool is_claimed
""",
    "gazebo_msgs/msg/EntityState": """\
string name
geometry_msgs/Pose pose
geometry_msgs/Twist twist
string reference_frame
""",
    "ros_gz_interfaces/msg/Entity": """\
uint8 NONE=0
uint8 LIGHT=1
uint8 MODEL=2
uint8 LINK=3
uint8 VISUAL=4
uint8 COLLISION=5
uint8 SENSOR=6
uint8 JOINT=7
uint64 id
string name
uint8 type
""",
    "ros_gz_interfaces/msg/EntityFactory": """\
string name
bool allow_renaming
string sdf
string sdf_filename
string clone_name
geometry_msgs/Pose pose
string relative_to
""",
    "ros_gz_interfaces/msg/WorldReset": """\
bool all
bool time_only
bool model_only
""",
    "ros_gz_interfaces/msg/WorldControl": """\
bool pause
bool step
uint32 multi_step
ros_gz_interfaces/WorldReset reset
uint32 seed
builtin_interfaces/Time run_to_sim_time
""",
}

# name -> (request text, response text)
SERVICES: dict[str, tuple[str, str]] = {
    "std_srvs/srv/Empty": ("", ""),
    "std_srvs/srv/Trigger": ("", "bool success\nstring message\n"),
    "std_srvs/srv/SetBool": ("bool data\n", "bool success\nstring message\n"),
    "action_msgs/srv/CancelGoal": (
        "action_msgs/GoalInfo goal_info\n",
        """\
int8 ERROR_NONE=0
int8 ERROR_REJECTED=1
int8 ERROR_UNKNOWN_GOAL_ID=2
int8 ERROR_GOAL_TERMINATED=3
int8 return_code
action_msgs/GoalInfo[] goals_canceling
""",
    ),
    "controller_manager_msgs/srv/ListControllers": (
        "",
        "controller_manager_msgs/ControllerState[] controller\n",
    ),
    "controller_manager_msgs/srv/ListHardwareInterfaces": (
        "",
        "controller_manager_msgs/HardwareInterface[] command_interfaces\n"
        "controller_manager_msgs/HardwareInterface[] state_interfaces\n",
    ),
    "controller_manager_msgs/srv/SwitchController": (
        """\
int32 BEST_EFFORT=1
int32 STRICT=2
int32 AUTO=3
int32 FORCE_AUTO=4
string[] activate_controllers
string[] deactivate_controllers
int32 strictness
bool activate_asap
builtin_interfaces/Duration timeout
""",
        "bool ok\nstring message\n",
    ),
    "controller_manager_msgs/srv/LoadController": ("string name\n", "bool ok\n"),
    "controller_manager_msgs/srv/ConfigureController": ("string name\n", "bool ok\n"),
    "controller_manager_msgs/srv/UnloadController": ("string name\n", "bool ok\n"),
    "gazebo_msgs/srv/SpawnEntity": (
        """\
string name
string xml
string robot_namespace
geometry_msgs/Pose initial_pose
string reference_frame
""",
        "bool success\nstring status_message\n",
    ),
    "gazebo_msgs/srv/DeleteEntity": ("string name\n", "bool success\nstring status_message\n"),
    "gazebo_msgs/srv/GetEntityState": (
        "string name\nstring reference_frame\n",
        "std_msgs/Header header\ngazebo_msgs/EntityState state\nbool success\n",
    ),
    "gazebo_msgs/srv/SetEntityState": ("gazebo_msgs/EntityState state\n", "bool success\n"),
    "ros_gz_interfaces/srv/ControlWorld": (
        "ros_gz_interfaces/WorldControl world_control\n",
        "bool success\n",
    ),
    "ros_gz_interfaces/srv/SpawnEntity": (
        "ros_gz_interfaces/EntityFactory entity_factory\n",
        "bool success\n",
    ),
    "ros_gz_interfaces/srv/DeleteEntity": ("ros_gz_interfaces/Entity entity\n", "bool success\n"),
    "ros_gz_interfaces/srv/SetEntityPose": (
        "ros_gz_interfaces/Entity entity\ngeometry_msgs/Pose pose\n",
        "bool success\n",
    ),
}

# name -> (goal, result, feedback)
ACTIONS: dict[str, tuple[str, str, str]] = {
    "control_msgs/action/FollowJointTrajectory": (
        """\
trajectory_msgs/JointTrajectory trajectory
trajectory_msgs/MultiDOFJointTrajectory multi_dof_trajectory
control_msgs/JointTolerance[] path_tolerance
control_msgs/JointComponentTolerance[] component_path_tolerance
control_msgs/JointTolerance[] goal_tolerance
control_msgs/JointComponentTolerance[] component_goal_tolerance
builtin_interfaces/Duration goal_time_tolerance
""",
        """\
int32 SUCCESSFUL=0
int32 INVALID_GOAL=-1
int32 INVALID_JOINTS=-2
int32 OLD_HEADER_TIMESTAMP=-3
int32 PATH_TOLERANCE_VIOLATED=-4
int32 GOAL_TOLERANCE_VIOLATED=-5
int32 error_code
string error_string
""",
        """\
std_msgs/Header header
string[] joint_names
trajectory_msgs/JointTrajectoryPoint desired
trajectory_msgs/JointTrajectoryPoint actual
trajectory_msgs/JointTrajectoryPoint error
string[] multi_dof_joint_names
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_desired
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_actual
trajectory_msgs/MultiDOFJointTrajectoryPoint multi_dof_error
""",
    ),
    "control_msgs/action/GripperCommand": (
        "control_msgs/GripperCommand command\n",
        "float64 position\nfloat64 effort\nbool stalled\nbool reached_goal\n",
        "float64 position\nfloat64 effort\nbool stalled\nbool reached_goal\n",
    ),
    "control_msgs/action/ParallelGripperCommand": (
        "sensor_msgs/JointState command\n",
        "sensor_msgs/JointState state\nbool stalled\nbool reached_goal\n",
        "sensor_msgs/JointState state\n",
    ),
}


@dataclass(frozen=True)
class ServiceType:
    """A service type as the wire needs it: its request and response message types."""

    name: str  # pkg/srv/Name (or pkg/action/Name_SendGoal for an action's services)
    request: str
    response: str


def _char_as_uint8() -> None:
    """rosidl reads a `.msg` file's `char` as `uint8` (rosidl_adapter's MSG_TYPE_TO_IDL), so type hashes
    are taken with uint8; rosbags keeps `char`, which changes the hash of every service (through
    `service_msgs/ServiceEventInfo`'s `char[16] client_gid`). Same size on the wire: only the hash sees it."""
    name = "service_msgs/msg/ServiceEventInfo"
    consts, fields = TYPESTORE.fielddefs[name]
    fixed = []
    for fname, (kind, detail) in fields:
        if kind == Nodetype.ARRAY and detail[0][0] == Nodetype.BASE and detail[0][1][0] == "char":
            detail = ((Nodetype.BASE, ("uint8", 0)), detail[1])
        fixed.append((fname, (kind, detail)))
    TYPESTORE.fielddefs[name] = (consts, fixed)


def _register() -> None:
    _char_as_uint8()
    types: dict = {}
    for name, text in _MESSAGES.items():
        types.update(get_types_from_msg(text, name))
    TYPESTORE.register(types)
    types = {}
    for name, (request, response) in SERVICES.items():
        types.update(_service_types(name, request, response))
    for name, (goal, result, feedback) in ACTIONS.items():
        types.update(get_types_from_msg(goal, f"{name}_Goal"))
        types.update(get_types_from_msg(result, f"{name}_Result"))
        types.update(get_types_from_msg(feedback, f"{name}_Feedback"))
        short = name.rsplit("/", 1)[1]
        types.update(
            _service_types(
                f"{name}_SendGoal",
                f"unique_identifier_msgs/UUID goal_id\n{short}_Goal goal\n",
                "bool accepted\nbuiltin_interfaces/Time stamp\n",
            )
        )
        types.update(
            _service_types(
                f"{name}_GetResult",
                "unique_identifier_msgs/UUID goal_id\n",
                f"int8 status\n{short}_Result result\n",
            )
        )
        types.update(
            get_types_from_msg(
                f"unique_identifier_msgs/UUID goal_id\n{short}_Feedback feedback\n", f"{name}_FeedbackMessage"
            )
        )
    TYPESTORE.register(types)


def _service_types(name: str, request: str, response: str) -> dict:
    """The messages rosidl generates for one service, and the three-field type its hash is taken of."""
    short = name.rsplit("/", 1)[1]
    types: dict = {}
    types.update(get_types_from_msg(request, f"{name}_Request"))
    types.update(get_types_from_msg(response, f"{name}_Response"))
    event = (
        f"service_msgs/ServiceEventInfo info\n{short}_Request[<=1] request\n{short}_Response[<=1] response\n"
    )
    types.update(get_types_from_msg(event, f"{name}_Event"))
    whole = (
        f"{short}_Request request_message\n{short}_Response response_message\n{short}_Event event_message\n"
    )
    types.update(get_types_from_msg(whole, name))
    return _srv_names(types)


def _srv_names(value: Any) -> Any:
    """rosbags reads every interface as a message and spells `pkg/srv/Name` as `pkg/srv/msg/Name`; the
    names ROS 2 hashes and sends are `pkg/srv/Name`."""
    if isinstance(value, str):
        return value.replace("/srv/msg/", "/srv/")
    if isinstance(value, dict):
        return {_srv_names(k): _srv_names(v) for k, v in value.items()}
    if isinstance(value, tuple | list):
        return type(value)(_srv_names(v) for v in value)
    return value


_register()


def service_type(name: str) -> ServiceType:
    """`std_srvs/srv/Empty` (or `std_srvs/Empty`, or an action's `pkg/action/Name_SendGoal`) as a
    ServiceType; KeyError for a service this module does not know."""
    full = name.replace("/", "/srv/", 1) if name.count("/") == 1 else name
    if f"{full}_Request" not in TYPESTORE.fielddefs or full not in TYPESTORE.fielddefs:
        known = ", ".join(sorted(SERVICES))
        raise KeyError(f"unknown service type {name!r} (known: {known})")
    return ServiceType(full, f"{full}_Request", f"{full}_Response")


def known_service(name: str) -> bool:
    try:
        service_type(name)
    except KeyError:
        return False
    return True


def action_type(name: str) -> str:
    """`control_msgs/action/FollowJointTrajectory` (or `control_msgs/FollowJointTrajectory`) in full;
    KeyError for an action this module does not know."""
    full = name if name.count("/") == 2 else name.replace("/", "/action/", 1)
    if full not in ACTIONS:
        raise KeyError(f"unknown action type {name!r} (known: {', '.join(sorted(ACTIONS))})")
    return full


@cache
def service_hash(name: str) -> str:
    """The REP-2016 type hash of a service (`RIHS01_...`): the hash of its three-field type."""
    return str(TYPESTORE.hash_rihs01(service_type(name).name))


# An action's parts as rcl_action names them: (suffix after the action's name, kind, type suffix)
ACTION_SERVICES = (
    ("_action/send_goal", "_SendGoal"),
    ("_action/cancel_goal", None),  # action_msgs/srv/CancelGoal
    ("_action/get_result", "_GetResult"),
)
ACTION_TOPICS = (
    ("_action/feedback", "_FeedbackMessage"),
    ("_action/status", None),  # action_msgs/msg/GoalStatusArray
)


def action_parts(action: str) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """The services and topics an action server of type `action` is made of: ([(suffix, service type)],
    [(suffix, message type)])."""
    full = action_type(action)
    services = [(s, f"{full}{t}" if t else "action_msgs/srv/CancelGoal") for s, t in ACTION_SERVICES]
    topics = [(s, f"{full}{t}" if t else "action_msgs/msg/GoalStatusArray") for s, t in ACTION_TOPICS]
    return services, topics
