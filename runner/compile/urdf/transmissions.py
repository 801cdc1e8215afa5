"""The robot's hardware as Gazebo's ros_control plugins build it: `<ros2_control>` (ROS 2: gz_ros2_control,
ign_ros2_control, gazebo_ros2_control and their vendors' forks) and `<transmission>` (ROS 1:
gazebo_ros_control's DefaultRobotHWSim). One `Transmission` per joint: its command interfaces (one actuator
each, runner.compile.hardware), state interfaces and `initial_value`s, command `min`/`max`, mimic, and the
gains of the Gazebo plugin that runs it (position_proportional_gain, controller manager update rate, ROS 1
`gazebo_ros_control/pid_gains`). Everything else in those blocks is said at its line with what Gazebo does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from runner.errors import Notices

Mode = Literal["position", "velocity", "effort"]
Family = Literal["gz", "classic", "ros1"]

# gz_ros2_control's default position_proportional_gain (gz_ros2_control_plugin.cpp:318 on jazzy,
# ign_system.cpp:183 on humble) and the controller manager's default update rate (ros2_control's
# controller_manager declares update_rate 100)
POSITION_GAIN = 0.1
UPDATE_RATE = 100.0

# <hardware><plugin> -> the Gazebo system plugin family that runs it
_PLUGINS: dict[str, Family] = {
    "gz_ros2_control/GazeboSimSystem": "gz",
    "ign_ros2_control/IgnitionSystem": "gz",
    "gazebo_ros2_control/GazeboSystem": "classic",
}
# a vendor's fork (franka_ign_ros2_control/IgnitionSystem, <vendor>_gz_ros2_control/...) subclasses its
# parent's system: the package part names the parent
_FORKS: tuple[tuple[str, Family], ...] = (
    ("gz_ros2_control", "gz"),
    ("ign_ros2_control", "gz"),
    ("gazebo_ros2_control", "classic"),
)


@dataclass
class Mimic:
    joint: str  # the joint it follows
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass
class Transmission:
    """One joint of the robot's hardware."""

    joint: str
    interface: Mode  # its first command interface (the one that holds the joint before a controller claims)
    reduction: float = 1.0  # ROS 1 mechanicalReduction: read, not applied (as DefaultRobotHWSim)
    interfaces: list[Mode] = field(default_factory=list)  # every command interface, in order
    states: list[str] = field(default_factory=list)
    initial: dict[str, float] = field(default_factory=dict)  # state interface -> initial_value
    limits: dict[str, tuple[float | None, float | None]] = field(default_factory=dict)  # <param min/max>
    mimic: Mimic | None = None
    family: Family = "gz"
    position_gain: float = POSITION_GAIN  # gz: the velocity setpoint is gain * update_rate * error
    update_rate: float = UPDATE_RATE
    pid: dict[str, float] | None = None  # ROS 1 pid_gains / gazebo_ros2_control's position_pid gains
    hold: bool = True  # gz hold_joints: an unclaimed joint is held where it is
    file: Path | None = None
    line: int | None = None

    @property
    def loop_gain(self) -> float | None:
        """1/s from position error to the velocity setpoint (gz_system.cpp write(): -gain * error *
        update_rate); None where Gazebo sets the position itself (classic and ROS 1 without PID gains)."""
        if self.family == "gz":
            return self.position_gain * self.update_rate
        return None


def _interface(text: str | None) -> Mode | None:
    if not text:
        return None
    t = text.strip().split("/")[-1].lower()
    for key in ("position", "velocity", "effort"):
        if t.startswith(key):
            return key  # type: ignore[return-value]
    return None


def _number(text: str | None) -> float | None:
    try:
        value = float((text or "").strip())
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def family_of(plugin: str) -> tuple[Family | None, bool]:
    """(family, is a fork) of a `<hardware><plugin>` name."""
    plugin = plugin.strip()
    if plugin in _PLUGINS:
        return _PLUGINS[plugin], False
    package = plugin.split("/")[0].split("::")[0]
    for parent, fam in _FORKS:
        if parent in package:
            return fam, True
    return None, False


@dataclass
class _Settings:
    """What the control plugin and the controllers files say about the hardware."""

    position_gain: float = POSITION_GAIN
    update_rate: float = UPDATE_RATE
    hold: bool = True
    # controller_manager's enforce_command_limits: false on Humble (none) and Jazzy, true from Kilted
    # (controller_manager_parameters.yaml): only then are a command interface's min/max applied
    enforce_limits: bool = False
    pid: dict[str, dict[str, float]] = field(default_factory=dict)  # ROS 1: joint -> {p, i, d, ...}
    where_hold: tuple[Path | None, int | None] = (None, None)


def _walk(doc: Any, out: _Settings, path: tuple[str, ...] = ()) -> None:
    if not isinstance(doc, dict):
        return
    for key, value in doc.items():
        k = str(key)
        if k == "update_rate" and "controller_manager" in path and _number(str(value)) is not None:
            out.update_rate = float(value)
        elif k == "position_proportional_gain" and _number(str(value)) is not None:
            out.position_gain = float(value)
        elif k == "hold_joints" and value is False:
            out.hold = False
        elif k == "enforce_command_limits" and "controller_manager" in path and isinstance(value, bool):
            out.enforce_limits = value
        elif k == "pid_gains" and path and path[-1] == "gazebo_ros_control" and isinstance(value, dict):
            for joint, gains in value.items():
                if isinstance(gains, dict):
                    nums = {g: float(v) for g, v in gains.items() if _number(str(v)) is not None}
                    out.pid[str(joint)] = nums
        elif isinstance(value, dict):
            _walk(value, out, (*path, k))


def _settings(root: Any, where: Any, controllers: list[Path], notices: Notices) -> _Settings:
    """The gz_ros2_control plugin's `<position_proportional_gain>`/`<hold_joints>` and its `<parameters>`
    files, with the scenario's controllers files: their gains and the controller manager's update rate."""
    import yaml

    out = _Settings()
    files = list(controllers)
    for plugin in root.iter("plugin"):
        if plugin.getparent() is None or plugin.getparent().tag != "gazebo":
            continue
        name = (plugin.get("filename") or "") + (plugin.get("name") or "")
        if "ros2_control" not in name and "ros_control" not in name:
            continue
        gain = plugin.find("position_proportional_gain")
        if gain is not None and _number(gain.text) is not None:
            out.position_gain = float(gain.text)
        sim_type = plugin.find("robotSimType")
        if sim_type is not None and (sim_type.text or "").strip() not in (
            "",
            "gazebo_ros_control/DefaultRobotHWSim",
        ):
            # a vendor's RobotHWSim (ROS 1) is its own code: the default one's semantics stand in for it
            notices.add(
                f"robotSimType {(sim_type.text or '').strip()!r} is run as "
                "gazebo_ros_control/DefaultRobotHWSim",
                *where(sim_type),
            )
        hold = plugin.find("hold_joints")
        if hold is not None and (hold.text or "").strip().lower() in ("false", "0"):
            out.hold = False
            out.where_hold = where(hold)
        for p in plugin.findall("parameters"):
            text = (p.text or "").strip()
            if text.endswith((".yaml", ".yml")):
                path = Path(text)
                if not path.is_absolute():
                    base = where(p)[0]
                    path = (base.parent if base else Path.cwd()) / path
                files.append(path)
    for path in files:
        try:
            doc = yaml.safe_load(path.read_text())
        except (OSError, yaml.YAMLError):
            continue  # the controller manager says what is wrong with the file
        _walk(doc, out)
    return out


def read_transmissions(
    root: Any, where: Any, notices: Notices, controllers: list[Path] | None = None
) -> list[Transmission]:
    """The hardware's joints, from `<ros2_control>` blocks, else ROS 1 `<transmission>`s."""
    settings = _settings(root, where, list(controllers or []), notices)
    if not settings.hold:
        notices.add(
            "hold_joints false: Gazebo leaves a joint no controller has claimed free; here the hardware "
            "holds it until a controller commands it (which interfaces a controller claims is known only to "
            "it)",
            *settings.where_hold,
        )
    out: list[Transmission] = []
    seen: set[str] = set()
    for rc in root.findall("ros2_control"):
        for tr in _ros2_control(rc, where, notices, settings):
            if tr.joint in seen:
                notices.add(
                    f"joint {tr.joint!r} is in two <ros2_control> blocks; the first is used", tr.file, tr.line
                )
                continue
            seen.add(tr.joint)
            out.append(tr)
    for tr in _ros1(root, where, notices, settings):
        if tr.joint in seen:  # gz_ros2_control / gazebo_ros2_control read <ros2_control> only
            notices.add(
                f"transmission of joint {tr.joint!r}: a <ros2_control> block has the joint, which Gazebo's "
                "ROS 2 plugin uses; the ROS 1 transmission is ignored",
                tr.file,
                tr.line,
            )
            continue
        seen.add(tr.joint)
        out.append(tr)
    mimicked = {j.get("name"): j.find("mimic") for j in root.findall("joint") if j.find("mimic") is not None}
    for tr in out:
        m = mimicked.get(tr.joint)
        if m is not None and (tr.mimic is None or not tr.mimic.joint):
            mult = _number(m.get("multiplier"))
            tr.mimic = Mimic(
                m.get("joint") or "", 1.0 if mult is None else mult, _number(m.get("offset")) or 0.0
            )
    return out


def _ros2_control(rc: Any, where: Any, notices: Notices, s: _Settings) -> list[Transmission]:
    name = rc.get("name") or "?"
    hw = rc.find("hardware")
    plugin_el = hw.find("plugin") if hw is not None else None
    plugin = (plugin_el.text or "").strip() if plugin_el is not None else ""
    family, fork = family_of(plugin)
    here = where(plugin_el if plugin_el is not None else rc)
    if family is None:
        notices.add(
            f"<ros2_control name={name!r}>: hardware plugin {plugin or '(none)'!r} is not a Gazebo one: "
            "gz_ros2_control cannot load it, so its joints get no hardware (no actuators, no initial values)",
            *here,
            hint="launch files pick the simulation hardware with a xacro argument (use_sim:=true, "
            "sim_gazebo:=true, use_fake_hardware:=false...): give it under `args:`",
        )
        return []
    if fork:
        parent = {"gz": "gz_ros2_control/GazeboSimSystem", "classic": "gazebo_ros2_control/GazeboSystem"}[
            family
        ]
        notices.add(f"hardware plugin {plugin!r} is run as {parent} (a fork of it)", *here)
    if rc.get("type", "system") != "system":
        notices.add(
            f"<ros2_control name={name!r}> is of type {rc.get('type')!r}: Gazebo's plugin runs it as a "
            "system",
            *where(rc),
        )
    if hw is not None:
        for p in hw.findall("param"):
            notices.add(
                f"hardware <param name={p.get('name')!r}> of {name!r} is not read by {plugin} "
                "(said, ignored)",
                *where(p),
            )
    for el in rc.findall("sensor"):
        states = [st.get("name") for st in el.findall("state_interface")]
        notices.add(
            f"ros2_control sensor {el.get('name')!r} ({', '.join(s for s in states if s)}): Gazebo's system "
            "fills it from the Gazebo <sensor> of the same name (IMU and force-torque only); a broadcaster "
            "reads it",
            *where(el),
        )
    for el in rc.findall("gpio"):
        notices.add(
            f"ros2_control gpio {el.get('name')!r}: Gazebo's system has no GPIO interfaces; ignored",
            *where(el),
        )
    for el in rc.findall("transmission"):
        notices.add(
            "a <transmission> inside <ros2_control> is not used by Gazebo's system; ignored", *where(el)
        )
    out = []
    for joint in rc.findall("joint"):
        tr = _joint(joint, family, where, notices, s)
        if tr is not None:
            out.append(tr)
    return out


def _joint(joint: Any, family: Family, where: Any, notices: Notices, s: _Settings) -> Transmission | None:
    """One `<ros2_control>` `<joint>`: command and state interfaces, `initial_value`s, min/max, mimic."""
    jname = joint.get("name")
    if not jname:
        notices.add("a <ros2_control> <joint> without a name is ignored", *where(joint))
        return None
    tr = Transmission(jname, "position", family=family, file=where(joint)[0], line=where(joint)[1])
    tr.position_gain, tr.update_rate, tr.hold = s.position_gain, s.update_rate, s.hold
    params = {p.get("name"): (p.text or "").strip() for p in joint.findall("param")}
    for ci in joint.findall("command_interface"):
        mode = _interface(ci.get("name"))
        raw = (ci.get("name") or "").strip()
        if mode is None or raw not in ("position", "velocity", "effort", "position_pid", "velocity_pid"):
            notices.add(
                f"joint {jname!r}: command interface {raw!r} is not one Gazebo's system has "
                "(position, velocity, effort); ignored",
                *where(ci),
            )
            continue
        if mode in tr.interfaces:
            continue
        tr.interfaces.append(mode)
        cparams = {p.get("name"): p for p in ci.findall("param")}
        for key in ("min", "max"):
            if key in cparams and _number(cparams[key].text) is None:
                notices.add(
                    f"joint {jname!r}: {raw} <param name={key!r}> {cparams[key].text!r} is not a number; "
                    "ignored",
                    *where(cparams[key]),
                )
        lo = _number(cparams["min"].text) if "min" in cparams else None
        hi = _number(cparams["max"].text) if "max" in cparams else None
        if (lo is not None or hi is not None) and s.enforce_limits:
            tr.limits[mode] = (lo, hi)
        elif lo is not None or hi is not None:
            # Gazebo's systems never read them (gz_system.cpp, gazebo_system.cpp); ros2_control clamps to them
            # only with the manager's enforce_command_limits (default false on Humble and Jazzy): a public
            # base's wheels, max 1 rad/s here, would crawl at 0.09 m/s where Gazebo drives them at 3 rad/s
            notices.add(
                f"joint {jname!r}: {raw} command min/max are not applied, as in Gazebo: ros2_control "
                "enforces them only with the controller manager's enforce_command_limits (default false on "
                "Humble and Jazzy, true from Kilted)",
                *where(ci),
                hint="set `enforce_command_limits: true` in controller_manager's ros__parameters",
            )
    for si in joint.findall("state_interface"):
        sname = (si.get("name") or "").strip()
        tr.states.append(sname)
        init = si.find("param[@name='initial_value']")
        if init is not None:
            value = _number(init.text)
            if value is None:
                # gz_system.cpp throws "Failed converting initial_value string": the robot is not loaded
                notices.add(
                    f"joint {jname!r}: initial_value {init.text!r} of {sname!r} is not a number; ignored",
                    *where(init),
                )
            elif sname in ("position", "velocity", "effort"):
                tr.initial[sname] = value
    if "mimic" in params:  # ign_system.cpp: <param name="mimic">, <param name="multiplier">
        tr.mimic = Mimic(params["mimic"], _number(params.get("multiplier")) or 1.0, 0.0)
    if family == "classic":
        gains = {g: _number(params.get(f"pos_{g}")) for g in ("kp", "ki", "kd")}
        if any(v is not None for v in gains.values()):
            tr.pid = {"p": gains["kp"] or 0.0, "i": gains["ki"] or 0.0, "d": gains["kd"] or 0.0}
    if not tr.interfaces:
        if tr.mimic is None and joint.get("mimic") != "true":
            notices.add(
                f"joint {jname!r} has no command interface: Gazebo reads its state only", *where(joint)
            )
        if joint.get("mimic") == "true" and tr.mimic is None:
            tr.mimic = Mimic("", 1.0, 0.0)  # filled from the URDF's <mimic>
        tr.interfaces = []
    else:
        tr.interface = tr.interfaces[0]
    return tr


def _ros1(root: Any, where: Any, notices: Notices, s: _Settings) -> list[Transmission]:
    out: list[Transmission] = []
    for tr in root.findall("transmission"):
        joint = tr.find("joint")
        if joint is None or not joint.get("name"):
            notices.add("a <transmission> without a <joint name=...> is ignored", *where(tr))
            continue
        kinds = [_interface(e.text) for e in tr.iter("hardwareInterface")]
        kind = next((k for k in kinds if k), None)
        if kind is None:
            notices.add(
                f"transmission of joint {joint.get('name')!r} has no velocity/position/effort "
                "interface; ignored",
                *where(tr),
            )
            continue
        reduction = 1.0
        red = tr.find("actuator/mechanicalReduction")
        if red is not None and red.text:
            value = _number(red.text)
            if value is None:
                notices.add(f"mechanicalReduction {red.text!r} is not a number; 1 is used", *where(red))
            elif value != 1.0:
                reduction = value
                # default_robot_hw_sim.cpp reads the joint and its interface only: commands are joint values
                notices.add(
                    f"transmission of joint {joint.get('name')!r}: mechanicalReduction {value:g} is not "
                    "applied "
                    "(gazebo_ros_control commands the joint itself); the actuator has gear 1",
                    *where(red),
                )
        name = joint.get("name")
        t = Transmission(name, kind, reduction, [kind], family="ros1", file=where(tr)[0], line=where(tr)[1])
        t.pid = s.pid.get(name)
        out.append(t)
    return out


def velocity_limits(root: Any) -> dict[str, float]:
    """Joint -> its URDF `<limit velocity>` (> 0): MuJoCo's URDF import drops it; Gazebo's URDF->SDF
    conversion carries it into `<axis><limit><velocity>`, which DART enforces (and clips a servo's command
    to: dart/constraint/JointConstraint.cpp, "The desired velocity shouldn't be out of the velocity
    limits")."""
    out: dict[str, float] = {}
    for j in root.findall("joint"):
        lim = j.find("limit")
        v = _number(lim.get("velocity")) if lim is not None else None
        if j.get("name") and v is not None and v > 0:
            out[j.get("name")] = v
    return out
