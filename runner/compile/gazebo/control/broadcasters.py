"""Broadcasters: joint_state_broadcaster (ROS 2) and joint_state_controller (ROS 1) -> `joint_states`;
imu_sensor_broadcaster -> `imu`; force_torque_sensor_broadcaster -> `force_torque`. Each publishes at the
controller manager's update_rate (its own `update_rate` if lower), as the controller manager updates it."""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec, Handler
from runner.compile.gazebo.control.params import TABLES, check, line_of, read

_STANDARD = ("position", "velocity", "effort")


def _hardware_joints(ctx: ControlContext) -> list[tuple[str, list[str]]]:
    """The joints the hardware gives state interfaces, in the description's order, with the standard ones
    each declares: ROS 2 `<ros2_control><joint><state_interface>`; ROS 1 every joint of a `<transmission>`
    (gazebo_ros_control exposes position, velocity and effort for each). Empty: no such block."""
    root = ctx.g.root
    out: list[tuple[str, list[str]]] = []
    seen: set[str] = set()
    for rc in root.findall("ros2_control"):
        for j in rc.findall("joint"):
            name = j.get("name")
            if not name or name in seen or name not in ctx.g.joint_names:
                continue
            seen.add(name)
            states = [s.get("name") for s in j.findall("state_interface")]
            out.append((name, [s for s in _STANDARD if s in states]))
    if out:
        return out
    for t in root.findall("transmission"):
        for j in t.findall("joint"):
            name = j.get("name")
            if name and name not in seen and name in ctx.g.joint_names:
                seen.add(name)
                out.append((name, list(_STANDARD)))
    return out


def _moving(ctx: ControlContext) -> list[str]:
    """A description with no `<ros2_control>` or `<transmission>`: its revolute, continuous and prismatic
    joints, by name (gz_ros2_control would give the broadcaster none; here it publishes them all)."""
    kinds = ("revolute", "continuous", "prismatic")
    return sorted(str(j.get("name")) for j in ctx.g.root.findall("joint") if j.get("type") in kinds)


def _joint_state_controller(ctx: ControlContext, spec: ControllerSpec, p: dict[str, Any]) -> bool:
    """ROS 1 joint_state_controller (ros_controllers, Noetic): every joint, at `publish_rate`."""
    rate = p.get("publish_rate")
    if not isinstance(rate, (int, float)) or isinstance(rate, bool) or rate <= 0:
        # joint_state_controller.cpp:64 (Noetic) refuses to start without it
        ctx.say(
            spec,
            f"joint_state_controller {spec.name!r} has no positive `publish_rate`: ros_controllers does "
            "not start it; here it publishes at 50 Hz",
            hint="publish_rate: 50",
        )
        rate = 50.0
    # hardware_interface's resource map hands the joints over sorted by name
    hardware = sorted(_hardware_joints(ctx)) or [(j, []) for j in _moving(ctx)]
    ctx.add(
        spec,
        "joint_states",
        {
            "topic": ctx.topic("joint_states"),
            "joints": [j for j, _ in hardware] or None,
            "extra_joints": [str(j) for j in p.get("extra_joints") or []] or None,
            "rate": float(rate),
        },
    )
    return True


def _say_mapped(ctx: ControlContext, spec: ControllerSpec, p: dict[str, Any]) -> None:
    """`map_interface_to_joint_state` naming another interface than the standard one: said."""
    for field in _STANDARD:
        mapped = p[f"map_interface_to_joint_state.{field}"]
        if mapped != field:
            ctx.g.notices.add(
                f"joint_state_broadcaster {spec.name!r}: map_interface_to_joint_state.{field} {mapped!r} "
                f"is not used: the joints here have only the standard interfaces; `{field}` fills {field}",
                spec.file,
                line_of(spec.params, f"map_interface_to_joint_state.{field}") or spec.line,
            )


def joint_state_broadcaster(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """joint_state_broadcaster (ros2_controllers, Humble and Jazzy) as joint_state_broadcaster.cpp runs it:
    every state interface the hardware has, unless `joints` AND `interfaces` are both given (then those);
    `joint_states` (sensor_msgs/JointState: position, velocity, effort, NaN where a joint lacks one) and
    `dynamic_joint_states` (every interface by name), `~/` with `use_local_topics`; `extra_joints` with
    state 0; `frame_id` in the header. ROS 1 joint_state_controller: every joint, at `publish_rate`."""
    if spec.ros1:
        check(ctx, spec)
        return _joint_state_controller(ctx, spec, read(spec))
    # ROS 2 Foxy's joint_state_controller/JointStateController in a ROS 2 file (`ros__parameters`) is the
    # broadcaster before its rename (ros2_controllers foxy): read with the broadcaster's parameters
    table = TABLES["joint_state_broadcaster/JointStateBroadcaster"]
    check(ctx, spec, table)
    p = read(spec, table)
    hardware = _hardware_joints(ctx)
    joints = [str(j) for j in p["joints"] or []]
    interfaces = [str(i) for i in p["interfaces"] or []]
    if bool(joints) != bool(interfaces):
        given = "joints" if joints else "interfaces"
        ctx.g.notices.add(
            f"joint_state_broadcaster {spec.name!r}: `{given}` without `"
            f"{'interfaces' if joints else 'joints'}` is not used: it publishes every state interface, as "
            "the broadcaster does",
            spec.file,
            line_of(spec.params, given) or spec.line,
            hint="give both `joints` and `interfaces` to publish only some",
        )
    selected: list[tuple[str, list[str]]]
    if joints and interfaces:
        have = dict(hardware)
        selected = [
            (j, [i for i in _STANDARD if i in interfaces and i in have.get(j, _STANDARD)]) for j in joints
        ]
        other = [i for i in interfaces if i not in _STANDARD]
        if other:
            ctx.g.notices.add(
                f"joint_state_broadcaster {spec.name!r}: interface(s) {other} are not published: the joints "
                "here have only position, velocity and effort state interfaces",
                spec.file,
                line_of(spec.params, "interfaces") or spec.line,
            )
    else:
        # every state interface, in the order the hardware exports them (the description's: the resource
        # manager's available_state_interfaces); on Jazzy `use_urdf_to_filter` (default true) then orders the
        # joints as urdf::Model's joint map does, by name (joint_state_broadcaster.cpp:280); Humble has not
        # that filter and keeps the description's order, as `use_urdf_to_filter: false` does
        by_name = p["use_urdf_to_filter"] is not False
        selected = (sorted(hardware) if by_name else hardware) or [(j, list(_STANDARD)) for j in _moving(ctx)]
    # a joint with none of position, velocity and effort is not in joint_states (joint_state_broadcaster.cpp
    # names a joint there only for a standard interface, :263 on Jazzy)
    selected = [(j, i) for j, i in selected if i]
    _say_mapped(ctx, spec, p)
    local = p["use_local_topics"] is True
    prefix = "~/" if local else ""
    params: dict[str, Any] = {
        "topic": ctx.topic(prefix + "joint_states"),
        "joints": [j for j, _ in selected] or None,
        "interfaces": {j: i for j, i in selected} or None,
        "extra_joints": [str(j) for j in p["extra_joints"] or []] or None,
        "frame_id": ctx.frame(str(p["frame_id"])) if p["frame_id"] else None,
        "rate": spec.update_rate,
        "dynamic_topic": ctx.topic(prefix + "dynamic_joint_states")
        if p["publish_dynamic_joint_states"] is not False
        else None,
    }
    ctx.add(spec, "joint_states", params)
    return True


def _sensor_link(ctx: ControlContext, sensor: str) -> str | None:
    """The link of the Gazebo sensor named `sensor` (gz_ros2_control reads an IMU or force-torque sensor's
    values from the Gazebo sensor of the `<ros2_control><sensor>`'s name), else the `<ros2_control>`
    sensor's `frame_id` parameter."""
    for gz in ctx.g.root.findall("gazebo"):
        for s in gz.iter("sensor"):
            if s.get("name") == sensor and gz.get("reference"):
                return str(gz.get("reference"))
    for rc in ctx.g.root.findall("ros2_control"):
        for s in rc.findall("sensor"):
            if s.get("name") == sensor:
                for prm in s.findall("param"):
                    if prm.get("name") == "frame_id" and (prm.text or "").strip():
                        return (prm.text or "").strip()
    return None


def imu_sensor_broadcaster(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """imu_sensor_broadcaster: `~/imu` (sensor_msgs/Imu) from the IMU the `<ros2_control>` sensor
    `sensor_name` reads, `frame_id` in the header, the static covariances as given."""
    check(ctx, spec)
    p = read(spec)
    sensor = str(p["sensor_name"] or "")
    link = _sensor_link(ctx, sensor) if sensor else None
    if link is None:
        link = str(p["frame_id"]) if p["frame_id"] in ctx.g.link_names else None
    if link is None:
        ctx.say(
            spec,
            f"imu_sensor_broadcaster {spec.name!r}: no IMU named {sensor!r} (a Gazebo <sensor> or a "
            "<ros2_control> <sensor>) and no link named by its frame_id: it is not run",
            hint="sensor_name names the <ros2_control> <sensor> (and the Gazebo imu sensor) it reads",
        )
        return False
    ctx.add(
        spec,
        "imu",
        {
            "link": link,
            "topic": ctx.topic("~/imu"),
            "frame_id": ctx.frame(str(p["frame_id"])) if p["frame_id"] else ctx.frame(link),
            "rate": spec.update_rate,
        },
    )
    covariance = [
        p[f"static_covariance_{k}"] for k in ("orientation", "angular_velocity", "linear_acceleration")
    ]
    if any(isinstance(c, list) and any(c) for c in covariance):
        ctx.say(
            spec,
            f"imu_sensor_broadcaster {spec.name!r}: static covariances are published as zero (our imu "
            "plugin fills them from its noise)",
        )
    return True


def force_torque_sensor_broadcaster(ctx: ControlContext, spec: ControllerSpec) -> bool:
    """force_torque_sensor_broadcaster: `~/wrench` (geometry_msgs/WrenchStamped) from a force/torque
    sensor at the joint `sensor_name` names (gz_ros2_control reads the Gazebo force_torque sensor of that
    name, which sits at a joint), `frame_id` in the header."""
    check(ctx, spec)
    p = read(spec)
    sensor = str(p["sensor_name"] or "")
    joint = None
    block = None  # the Gazebo sensor's <force_torque> (its frame and direction: read and said there)
    for gz in ctx.g.root.findall("gazebo"):
        for s in gz.iter("sensor"):
            if s.get("name") == sensor and gz.get("reference") in ctx.g.joint_names | ctx.g.fixed_joints:
                joint = gz.get("reference")
                block = s.find("force_torque")
    if joint is None and sensor:
        for j in ctx.g.root.findall("joint"):
            if j.get("name") == sensor:
                joint = sensor
    link = None
    for j in ctx.g.root.findall("joint"):
        if joint is not None and j.get("name") == joint and j.find("child") is not None:
            link = j.find("child").get("link")
    if link is None:
        ctx.say(
            spec,
            f"force_torque_sensor_broadcaster {spec.name!r}: no force/torque sensor {sensor!r} at a joint: "
            "it is not run"
            + (" (`interface_names.*` of single interfaces are not read)" if not sensor else ""),
            hint="sensor_name names the <ros2_control> <sensor> and the Gazebo force_torque sensor of a "
            "joint",
        )
        return False
    # gazebo_ros2_control hands the broadcaster the sensor's own Force()/Torque(): in the sensor's
    # <frame> and <measure_direction> (gz-sensors' defaults: child, child_to_parent)
    direction = (
        (block.findtext("measure_direction") if block is not None else None) or "child_to_parent"
    ).strip()
    frame = ((block.findtext("frame") if block is not None else None) or "child").strip()
    ctx.add(
        spec,
        "force_torque",
        {
            "link": link,
            "topic": ctx.topic("~/wrench"),
            "frame_id": ctx.frame(str(p["frame_id"])) if p["frame_id"] else None,
            "rate": spec.update_rate,
            "measure_direction": direction if direction in ("child_to_parent", "parent_to_child") else None,
            "measure_frame": frame if frame in ("child", "parent", "sensor") else None,
        },
    )
    return True


HANDLERS: dict[str, Handler] = {
    "joint_state_broadcaster/JointStateBroadcaster": joint_state_broadcaster,
    "joint_state_controller/JointStateController": joint_state_broadcaster,
    "imu_sensor_broadcaster/IMUSensorBroadcaster": imu_sensor_broadcaster,
    "force_torque_sensor_broadcaster/ForceTorqueSensorBroadcaster": force_torque_sensor_broadcaster,
}
