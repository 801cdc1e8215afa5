"""A robot's ros2_control / ros_control hardware into MuJoCo, before its plugins are built
(plugins/_actuators.py is the contract): one actuator per (joint, command interface), named
`<joint>/<interface>`, with the joint's URDF effort limit as its force range (none: unlimited, as Gazebo) and
gear 1; mimic joints get a joint equality and no actuator; the start state (`initial_value`s), the gains and
the velocity limits go to the plan (`HardwareJoint`), which the world applies before any plugin's setup
(runner.sim.hardware).

How Gazebo commands a joint, and what stands for it here:
- gz_ros2_control / ign_ros2_control (gz_system.cpp write()): velocity -> a DART servo (a velocity constraint
  whose impulse is bounded by the effort limit); position -> the same servo with the setpoint
  `position_proportional_gain * update_rate * error`; effort -> a joint force. Here: a velocity servo, and a
  position servo `kp = loop_gain * kv` (the same velocity loop on the position error), with a damping `kv`
  so high against the joint's inertia that it acts as the constraint does (runner.sim.hardware);
- gazebo_ros2_control and ROS 1's DefaultRobotHWSim: position -> SetPosition (the joint is placed at the
  command), or a PID on the effort when PID gains are given; velocity -> SetVelocity / a joint motor with the
  effort limit; effort -> SetForce. Here: the stiffest stable servo, or the given P and D.
"""

from __future__ import annotations

import mujoco

from runner.compile.urdf import RobotModel
from runner.compile.urdf.transmissions import Transmission
from runner.errors import Notices
from runner.plan import HardwareJoint, ParityLine

# placeholder servo gains: the world replaces them at start from the inertia each joint moves, unless a
# controller's build set its own (runner.sim.hardware)
PLACEHOLDER = 1e-9


def add_hardware(
    model: RobotModel, notices: Notices, timestep: float = 0.002
) -> tuple[list[HardwareJoint], float]:
    """The hardware's actuators and equalities added to the robot's spec; the joints' plan and the
    controller manager's update rate."""
    spec = model.spec
    out: list[HardwareJoint] = []
    rate = next((tr.update_rate for tr in model.transmissions), 100.0)
    for tr in model.transmissions:
        joint = spec.joint(tr.joint)
        if joint is None:
            # gz_system.cpp: "Skipping joint in the URDF named ... which is not in the gazebo model"
            notices.add(
                f"ros2_control / transmission names joint {tr.joint!r}, which the robot does not have; "
                "skipped",
                tr.file,
                tr.line,
            )
            continue
        hj = HardwareJoint(joint=tr.joint, velocity_limit=model.velocity_limits.get(tr.joint))
        hj.initial_position, hj.initial_velocity = _initial(tr, joint, notices)
        hj.initial_effort = tr.initial.get("effort")
        hj.state_interfaces = list(tr.states)
        if tr.mimic is not None and tr.mimic.joint and _mimic(spec, tr, notices):
            out.append(hj)  # its start state still counts; no actuator of its own
            continue
        if any(a.target == tr.joint for a in spec.actuators):
            continue  # a plugin of the description already drives it
        hj.loop_gain = tr.loop_gain
        if hj.loop_gain is not None and hj.loop_gain * timestep > 1.0:
            notices.add(
                f"joint {tr.joint!r}: position_proportional_gain {tr.position_gain:g} at "
                f"{tr.update_rate:g} Hz "
                f"asks the joint to close its error {hj.loop_gain * timestep:.2g} times per physics step; "
                "1 is used (more is unstable)",
                tr.file,
                tr.line,
            )
            hj.loop_gain = 1.0 / timestep
        hj.pid = tr.pid
        for mode in tr.interfaces:
            act = spec.add_actuator(
                name=f"{tr.joint}/{mode}", target=tr.joint, trntype=mujoco.mjtTrn.mjTRN_JOINT
            )
            if mode == "position":
                act.set_to_position(kp=PLACEHOLDER, kv=PLACEHOLDER)
            elif mode == "velocity":
                act.set_to_velocity(kv=PLACEHOLDER)
            else:
                act.set_to_motor()
            # ROS 1's mechanicalReduction is not applied in Gazebo (transmissions.py): joint units
            act.gear = [1.0, 0, 0, 0, 0, 0]
            frc = list(joint.actfrcrange)
            if _kinematic(tr, mode):
                # Gazebo classic sets the joint's position / velocity itself, whatever force it takes: no
                # effort limit (the joint's own range would clamp this actuator too: lifted, and any other
                # interface's actuator keeps the limit as its own)
                joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_FALSE
            elif frc[1] > frc[0]:  # URDF <limit effort>; none: unlimited, as Gazebo
                act.forcelimited = True
                act.forcerange = frc
            lo, hi = tr.limits.get(mode, (None, None))
            if mode == "velocity" and hj.velocity_limit is not None:
                # DART clips a servo's velocity command to the joint's velocity limits
                lo = max(lo if lo is not None else -hj.velocity_limit, -hj.velocity_limit)
                hi = min(hi if hi is not None else hj.velocity_limit, hj.velocity_limit)
            if lo is not None or hi is not None:
                act.ctrllimited = True
                act.ctrlrange = [lo if lo is not None else -1e30, hi if hi is not None else 1e30]
            if mode == "velocity" and "position" in tr.interfaces:
                act.gear = [0.0] * 6  # two servos would fight: the position one holds until one is claimed
            hj.actuators[mode] = f"{tr.joint}/{mode}"
        out.append(hj)
    return out, rate


def _initial(tr: Transmission, joint: mujoco.MjsJoint, notices: Notices) -> tuple[float | None, float | None]:
    """The start position and velocity; a position outside the joint's limits is put at the nearest limit
    (Gazebo resets the joint there and DART's limit constraint then holds it inside: it is not thrown back
    through the joint, as a stiff MuJoCo limit would)."""
    pos, vel = tr.initial.get("position"), tr.initial.get("velocity")
    if pos is not None and joint.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
        lo, hi = joint.range
        limited = joint.limited == mujoco.mjtLimited.mjLIMITED_TRUE or (
            joint.limited == mujoco.mjtLimited.mjLIMITED_AUTO and lo < hi
        )
        if limited and not lo <= pos <= hi:
            clamped = min(max(pos, lo), hi)
            notices.add(
                f"joint {tr.joint!r}: initial_value {pos:g} is outside its limits [{lo:g}, {hi:g}]; "
                f"it starts "
                f"at {clamped:g}",
                tr.file,
                tr.line,
                hint="Gazebo puts it there and its limit then holds it: fix the value in the description",
            )
            pos = clamped
    return pos, vel


def _mimic(spec: mujoco.MjSpec, tr: Transmission, notices: Notices) -> bool:
    """A mimic joint follows its joint through an equality (MuJoCo's URDF import makes one for `<mimic>`),
    as gz_system.cpp's write() drives it to `multiplier * position` every update. False when the joint it
    names is not there."""
    mimic = tr.mimic
    assert mimic is not None
    if spec.joint(mimic.joint) is None:
        # ign_system.cpp throws "Mimicked joint ... not found": Gazebo does not load the robot's hardware
        notices.add(
            f"joint {tr.joint!r} mimics {mimic.joint!r}, which the robot does not have (Gazebo's system "
            "refuses the hardware); it is driven by its own command interfaces",
            tr.file,
            tr.line,
        )
        return False
    for eq in spec.equalities:
        if eq.type == mujoco.mjtEq.mjEQ_JOINT and eq.name1 == tr.joint:
            return True
    data = [0.0] * mujoco.mjNEQDATA
    data[0], data[1] = mimic.offset, mimic.multiplier  # q1 = offset + multiplier * q2
    spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=tr.joint, name2=mimic.joint, data=data)
    return True


def _kinematic(tr: Transmission, mode: str) -> bool:
    """Whether Gazebo sets the joint's state for this command kinematically, with no effort limit:
    gazebo_ros2_control (classic, ROS 2) writes position commands with Joint::SetPosition and velocity
    commands with Joint::SetVelocity (gazebo_system.cpp write(), humble :855-858), which Gazebo classic
    implements as SetVelocityMaximal, "without applying forces" and not respecting force limits; ROS 1's
    DefaultRobotHWSim sets a position without PID gains with SetPosition (its velocity goes through ODE's
    "vel"/"fmax", the effort limit: limited). A public base's 6 N·m wheels stalled at 0.88 rad/s of their
    command where Gazebo classic drives them at it."""
    if tr.family == "classic":
        return mode in ("position", "velocity")
    return tr.family == "ros1" and mode == "position" and tr.pid is None


def release_hardware(spec: mujoco.MjSpec, hardware: list[HardwareJoint]) -> None:
    """A joint a description's plugin drives with an actuator of its own (a gazebo_ros_diff_drive's
    wheels, beside their ROS 1 transmissions) is the plugin's, as before there was a hardware layer: the
    hardware's actuators on it are taken out. Then the links the hardware's servos hold get their weight
    routed through them (`_gravity`)."""
    ours = {name for hj in hardware for name in hj.actuators.values()}
    for hj in hardware:
        acts = [a for a in spec.actuators if a.trntype == mujoco.mjtTrn.mjTRN_JOINT and a.target == hj.joint]
        if any(a.name not in ours and a.gear[0] != 0 for a in acts):
            for a in acts:
                if a.name in ours:
                    spec.delete(a)
            hj.actuators = {}
    # a PID without an integral term sags in Gazebo as it does here: its links carry their own weight
    _gravity(spec, {hj.joint for hj in hardware if hj.pid is None or hj.pid.get("i", 0.0) > 0})


def _gravity(spec: mujoco.MjSpec, hardware: set[str]) -> None:
    """A link whose every joint up to the world is a hardware joint held by a servo carries its weight
    through those servos, within their effort limits (MuJoCo's gravity compensation routed through the
    actuators, `actuatorgravcomp`, clamped by the joint's force range), as DART's servo constraint holds it
    with no sag; the servo then answers only for motion and outside loads. A link below a free joint (a
    mobile base), an effort-driven or a passive joint is not compensated: in Gazebo nothing holds it."""
    held = {
        a.target
        for a in spec.actuators
        if a.trntype == mujoco.mjtTrn.mjTRN_JOINT
        and a.target in hardware
        and a.gear[0] != 0
        and a.biastype == mujoco.mjtBias.mjBIAS_AFFINE
    }
    # a mimic joint (a joint equality on a held leader) is held by its leader's servo through the equality,
    # as Gazebo's mimic constraint holds it: a gripper's twin finger must not load the wrist it hangs from
    # (its 50 g sagged a light wrist 0.023 rad, the servo alone being soft against loads; see _servo)
    followers = [
        (e.name1, e.name2)
        for e in spec.equalities
        if e.type == mujoco.mjtEq.mjEQ_JOINT and e.name1 and e.name2
    ]
    grew = True
    while grew:
        grew = False
        for follower, leader in followers:
            if leader in held and follower not in held:
                held.add(follower)
                grew = True
    for body in spec.bodies:
        path, ok, b = [], True, body
        while b is not None and b.name != "world" and ok:
            for j in b.joints:
                ok = (
                    ok
                    and j.name in held
                    and j.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
                )
                path.append(j)
            b = b.parent
        if ok and path:
            body.gravcomp = 1.0
            for j in path:
                j.actgravcomp = True


_FAMILIES = {"gz": "gz_ros2_control", "classic": "gazebo_ros2_control", "ros1": "gazebo_ros_control"}


def summary(model: RobotModel, hardware: list[HardwareJoint]) -> list[ParityLine]:
    """The robot's hardware in its "as in Gazebo" summary: which system runs which joints, and how."""
    if not hardware:
        return []
    by = {tr.joint: tr for tr in model.transmissions}
    first = by.get(hardware[0].joint)
    family = _FAMILIES.get(first.family, "") if first else ""
    kinds = []
    for hj in hardware:
        tr = by.get(hj.joint)
        how = "/".join(hj.actuators) or ("mimics " + tr.mimic.joint if tr and tr.mimic else "state only")
        kinds.append(f"{hj.joint} ({how})")
    starts = sum(hj.initial_position is not None for hj in hardware)
    text = f"{family}: {', '.join(kinds)}"
    if starts:
        text += f"; {starts} start at their initial_value"
    gains = {hj.loop_gain for hj in hardware if hj.loop_gain is not None}
    if gains:
        text += f"; position loop {', '.join(f'{g:g}' for g in sorted(gains))}/s"
    where = (str(first.file) if first and first.file else None, first.line if first else None)
    return [ParityLine(kind="hardware", text=text, file=where[0], line=where[1])]
