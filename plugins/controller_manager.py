"""controller_manager: the services of ros2_control's controller manager node for the controllers a robot's
control plugin runs (the compiler adds one per control plugin: runner.compile.gazebo.control.manager).

Services, under `<manager>/` in the robot's namespace (`/<ns>/controller_manager/...`, as the node
names them; controller_manager.cpp at 9ffbf97 on jazzy):
- `list_controllers` (controller_manager_msgs/srv/ListControllers, list_controllers_srv_cb :2835): every
  loaded controller with its state (active / inactive / unconfigured), type, update rate, the command
  interfaces it claims while active, and the command / state interfaces it requires (active or inactive);
- `list_hardware_interfaces`: the hardware's command and state interfaces (`<joint>/<interface>`, double,
  available; a command interface is claimed while an active controller holds it);
- `switch_controller` (:1858 switch_controller_cb): the names checked as the manager checks them, with
  BEST_EFFORT (a controller that cannot be switched is left out) or STRICT (nothing is switched and `ok` is
  false); strictness 0 (the parameters' default, best_effort), AUTO and FORCE_AUTO are BEST_EFFORT, as the
  manager's defaults make them; a command interface another active controller claims refuses the
  activation (check_for_interfaces_availability_to_activate :4312). A deactivated controller stops
  commanding and its joints are held by the hardware (plugins._actuators.release);
- `load_controller` / `configure_controller` / `unload_controller`: the lifecycle of the controllers built
  for the run: unload (only when not active) takes a controller out of the list, load puts it back
  unconfigured, configure makes it inactive. A controller the controllers file has but the launch does not
  spawn is not built (its plugins would claim the joints): loading it answers ok=false, said on stderr.

Every controller plugin the control handlers add switches (plugins._actuators.Lifecycle); one that does not
(none yet) is refused as a controller that fails its transition is, said in the reply's message.
"""

from __future__ import annotations

import logging
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from plugins._actuators import Lifecycle
from runner.plugin import BuildContext, Plugin, PluginParams, Reply, Service
from runner.wire import msgs

log = logging.getLogger(__name__)

SRV = "controller_manager_msgs/srv/"
BEST_EFFORT, STRICT = 1, 2
State = Literal["active", "inactive", "unconfigured"]


# (service, controller_manager_msgs/srv type, handler)
_SERVICES = (
    ("list_controllers", "ListControllers", "_list_controllers"),
    ("list_hardware_interfaces", "ListHardwareInterfaces", "_list_hardware"),
    ("switch_controller", "SwitchController", "_switch"),
    ("load_controller", "LoadController", "_load"),
    ("configure_controller", "ConfigureController", "_configure"),
    ("unload_controller", "UnloadController", "_unload"),
)


class ControllerEntry(BaseModel):
    model_config = ConfigDict(extra="forbid")
    name: str = Field(description="The controller's name.")
    type: str = Field(description="Its type as its controllers file gives it (pkg/Class).")
    plugins: list[str] = Field(default_factory=list, description="The plugins that run it.")
    update_rate: float = Field(100.0, description="Hz.")


class ControllerManagerParams(PluginParams):
    manager: str = Field("controller_manager", description="The controller manager node's name.")
    controllers: list[ControllerEntry] = Field(default_factory=list, description="The controllers run.")
    not_spawned: list[str] = Field(
        default_factory=list, description="Controllers of the files that no spawner starts (not built)."
    )


class Controller:
    """A loaded controller at run time: its entry, its plugins, its state."""

    def __init__(self, entry: ControllerEntry, plugins: list[Plugin]):
        self.entry = entry
        self.plugins = plugins
        self.state: State = "active"
        self.loaded = True

    @property
    def switchable(self) -> bool:
        return bool(self.plugins) and all(isinstance(p, Lifecycle) for p in self.plugins)

    def interfaces(self) -> tuple[list[str], list[str] | None]:
        """(command, state) interfaces it requires; state None: all (joint_state_broadcaster's ALL)."""
        command: list[str] = []
        state: list[str] | None = []
        for p in self.plugins:
            c, s = interfaces_of(p)
            command += c
            state = None if s is None or state is None else state + s
        return command, state


class ControllerManager(Plugin):
    Params = ControllerManagerParams
    params: ControllerManagerParams

    @classmethod
    def build(cls, params: ControllerManagerParams, ctx: BuildContext, name: str) -> list[Service]:
        m = params.manager.strip("/")
        return [Service(f"{m}/{service}", f"{SRV}{kind}") for service, kind, _ in _SERVICES]

    def setup(self) -> None:
        mine = {p.name: p for p in self.ctx.plugins()}
        self.controllers = {
            e.name: Controller(e, [mine[n] for n in e.plugins if n in mine]) for e in self.params.controllers
        }
        m = self.params.manager.strip("/")
        for service, kind, handler in _SERVICES:
            self.ctx.service(f"{m}/{service}", f"{SRV}{kind}", getattr(self, handler))

    def _loaded(self, name: str) -> Controller | None:
        c = self.controllers.get(name)
        return c if c is not None and c.loaded else None

    # ------------------------------------------------------------------------------------------ lists
    def _list_controllers(self, _request: Any, reply: Reply) -> None:
        out = []
        for c in self.controllers.values():
            if not c.loaded:
                continue
            command, state = c.interfaces()
            data: dict[str, Any] = {
                "name": c.entry.name,
                "state": c.state,
                "type": c.entry.type,
                "update_rate": min(round(c.entry.update_rate), 65535),
                "claimed_interfaces": command if c.state == "active" else [],
            }
            if c.state != "unconfigured":
                data["required_command_interfaces"] = command
                data["required_state_interfaces"] = self._all_states() if state is None else state
            out.append(msgs.from_data("controller_manager_msgs/msg/ControllerState", data))
        reply(msgs.T[f"{SRV}ListControllers_Response"](controller=out))

    def _hardware(self) -> tuple[list[str], list[str]]:
        command: list[str] = []
        state: list[str] = []
        for hj in getattr(self.ctx.robot.plan, "hardware", []):
            command += [f"{hj.joint}/{mode}" for mode in hj.actuators]
            state += [f"{hj.joint}/{s}" for s in (hj.state_interfaces or ("position", "velocity", "effort"))]
        return command, state

    def _all_states(self) -> list[str]:
        return self._hardware()[1]

    def _claimed(self) -> set[str]:
        return {
            i
            for c in self.controllers.values()
            if c.loaded and c.state == "active"
            for i in c.interfaces()[0]
        }

    def _list_hardware(self, _request: Any, reply: Reply) -> None:
        command, state = self._hardware()
        claimed = self._claimed()

        def item(name: str, is_claimed: bool) -> Any:
            return msgs.T["controller_manager_msgs/msg/HardwareInterface"](
                name=name, data_type="double", is_available=True, is_claimed=is_claimed
            )

        reply(
            msgs.T[f"{SRV}ListHardwareInterfaces_Response"](
                command_interfaces=[item(n, n in claimed) for n in command],
                state_interfaces=[item(n, False) for n in state],
            )
        )

    # ---------------------------------------------------------------------------------------- switch
    def _switch(self, request: Any, reply: Reply) -> None:
        ok, message = self.switch(
            list(request.activate_controllers), list(request.deactivate_controllers), int(request.strictness)
        )
        reply(msgs.T[f"{SRV}SwitchController_Response"](ok=ok, message=message))

    def switch(self, activate: list[str], deactivate: list[str], strictness: int) -> tuple[bool, str]:
        """controller_manager.cpp switch_controller_cb (:1858): (ok, message)."""
        strict = strictness == STRICT  # 0 (the default parameter), AUTO, FORCE_AUTO: BEST_EFFORT
        message = ""
        requests: dict[str, list[str]] = {}
        for action, names in (("deactivate", deactivate), ("activate", activate)):
            request: list[str] = []
            ok = True
            for name in names:
                if self._loaded(name) is None:
                    error = (
                        f"Could not {action} controller with name '{name}' because no controller with this "
                        "name exists"
                    )
                    log.warning("%s: %s", self.name, error)
                    if strict:
                        return False, error
                    message += error + "\n"
                    ok = bool(request)  # the manager's `request_list.empty() ? ERROR : OK`
                else:
                    ok = True
                    request.append(name)
            if not ok:
                return False, message
            requests[action] = request
        off, on = requests["deactivate"], requests["activate"]
        ok, message = self._check(on, off, strict)
        if not ok:
            return False, message
        if not on and not off:
            return True, "After checking the controllers, no controllers need to be activated or deactivated."
        why = self._available(on, off)
        if why is not None:
            log.warning("%s: %s", self.name, why)
            return False, why
        for name in off:
            self._set_state(self.controllers[name], "inactive")
        for name in on:
            self._set_state(self.controllers[name], "active")
        return True, ""

    def _check(self, on: list[str], off: list[str], strict: bool) -> tuple[bool, str]:
        """The per-controller checks of switch_controller_cb: a failing one is dropped (BEST_EFFORT) or fails
        the whole switch (STRICT)."""
        for names, verdict in ((on, lambda c: self._can_activate(c, off)), (off, self._can_deactivate)):
            for name in list(names):
                why = verdict(self.controllers[name])
                if why is None:
                    continue
                log.warning("%s: %s", self.name, why)
                if strict:
                    return False, why
                names.remove(name)
        return True, ""

    def _can_activate(self, c: Controller, off: list[str]) -> str | None:
        name = c.entry.name
        if c.state == "unconfigured":
            return (
                f"Controller with name '{name}' is in 'unconfigured' state. The controller needs to be "
                "configured to be in 'inactive' state before it can be checked and activated."
            )
        if c.state == "active" and name not in off:
            return f"Controller with name '{name}' is already active."
        if not c.switchable:
            return f"Controller with name '{name}' ({c.entry.type}) can not be switched in this simulation."
        return None

    def _can_deactivate(self, c: Controller) -> str | None:
        name = c.entry.name
        if c.state != "active":
            return f"Controller with name '{name}' can not be deactivated since it is not active."
        if not c.switchable:
            return f"Controller with name '{name}' ({c.entry.type}) can not be switched in this simulation."
        return None

    def _available(self, on: list[str], off: list[str]) -> str | None:
        """check_for_interfaces_availability_to_activate (:4312)."""
        freed = {i for n in off for i in self.controllers[n].interfaces()[0]}
        claimed = self._claimed()
        hardware = set(self._hardware()[0])
        taken: set[str] = set()
        for name in on:
            if name in off:
                continue
            for itf in self.controllers[name].interfaces()[0]:
                if hardware and itf not in hardware:
                    return (
                        f"Unable to activate controller '{name}' since the command interface '{itf}' is not "
                        "available."
                    )
                if itf in claimed and itf not in freed:
                    return (
                        f"Unable to activate controller '{name}' since the command interface '{itf}' is "
                        "currently claimed by another controller."
                    )
                if itf in taken:
                    return (
                        f"Unable to activate controller '{name}' since the command interface '{itf}' will be "
                        "used by another controller that is being activated."
                    )
                taken.add(itf)
        return None

    def _set_state(self, c: Controller, state: State) -> None:
        was, c.state = c.state, state
        if was == "active" and state != "active":
            for p in c.plugins:
                p.deactivate()  # type: ignore[attr-defined]
        elif state == "active" and was != "active":
            for p in c.plugins:
                p.activate()  # type: ignore[attr-defined]

    # -------------------------------------------------------------------------------------- lifecycle
    def _load(self, request: Any, reply: Reply) -> None:
        name = request.name
        c = self.controllers.get(name)
        ok = c is not None and not c.loaded
        if c is not None and c.loaded:
            log.error(
                "%s: A controller named '%s' was already loaded inside the controller manager",
                self.name,
                name,
            )
        elif c is None:
            why = (
                "it is in the controllers file but no spawner starts it, so it is not built in this run"
                if name in self.params.not_spawned
                else "no controllers file of the robot has it"
            )
            log.error("%s: controller '%s' can not be loaded: %s", self.name, name, why)
        else:
            c.loaded, c.state = True, "unconfigured"
        reply(msgs.T[f"{SRV}LoadController_Response"](ok=ok))

    def _configure(self, request: Any, reply: Reply) -> None:
        c = self._loaded(request.name)
        ok = c is not None and c.state != "active"
        if c is None:
            log.error("%s: Controller '%s' is not loaded", self.name, request.name)
        elif c.state == "active":
            log.error(
                "%s: Controller '%s' can not be configured from 'active' state.", self.name, request.name
            )
        else:
            c.state = "inactive"  # its parameters are those it was built with
        reply(msgs.T[f"{SRV}ConfigureController_Response"](ok=ok))

    def _unload(self, request: Any, reply: Reply) -> None:
        c = self._loaded(request.name)
        ok = c is not None and c.state != "active"
        if c is None:
            log.error("%s: Controller '%s' is not loaded", self.name, request.name)
        elif c.state == "active":
            log.error(
                "%s: Could not unload controller with name '%s' because it is still active",
                self.name,
                request.name,
            )
        else:
            c.loaded = False
        reply(msgs.T[f"{SRV}UnloadController_Response"](ok=ok))


def interfaces_of(p: Plugin) -> tuple[list[str], list[str] | None]:
    """The command and state interfaces a controller plugin requires, as its ros2_controllers controller's
    command_ / state_interface_configuration names them (state None: ALL, the broadcaster's default)."""
    from plugins.diff_drive import WheelDrive
    from plugins.gripper_action_controller import GripperActionController
    from plugins.joint_controller import JointController
    from plugins.joint_states import JointStates
    from plugins.joint_trajectory_controller import JointTrajectoryController
    from plugins.mecanum_drive import MecanumDrive
    from plugins.mecanum_drive import _joints as mecanum_wheels
    from plugins.steering_drive import SteeringDrive

    q: Any = p.params
    if isinstance(p, JointTrajectoryController):
        command = [f"{j}/{i}" for i in q.command_interfaces for j in (q.command_joints or q.joints)]
        return command, [f"{j}/{i}" for i in q.state_interfaces for j in q.joints]
    if isinstance(p, JointController):
        return [f"{j}/{q.mode}" for j in q.joints], []
    if isinstance(p, GripperActionController):
        command = [f"{q.joint}/{'position' if q.parallel else q.command_interface}"]
        command += [i for i in (q.max_effort_interface, q.max_velocity_interface) if q.parallel and i]
        return command, [f"{q.joint}/position", f"{q.joint}/velocity"]
    if isinstance(p, JointStates):
        if q.joints is None:
            return [], None
        return [], [
            f"{j}/{i}"
            for j in q.joints
            for i in (q.interfaces or {}).get(j, ("position", "velocity", "effort"))
        ]
    if isinstance(p, WheelDrive):  # diff_drive_controller: position feedback, unless from velocities
        left, right = type(p).sides(q)
        wheels = [j for j, _ in left + right]
        state = "velocity" if q.odometry_source == "velocity" else "position"
        return [f"{j}/velocity" for j in wheels], [f"{j}/{state}" for j in wheels]
    if isinstance(p, MecanumDrive):
        wheels = mecanum_wheels(q)
        return [f"{j}/velocity" for j in wheels], [f"{j}/velocity" for j in wheels]
    if isinstance(p, SteeringDrive):
        traction, steering = q.traction_joints_names, q.steering_joints_names
        command = [f"{j}/velocity" for j in traction] + [f"{j}/position" for j in steering]
        # steering_controllers_library: traction velocity (position_feedback false, the default); steering
        return command, [f"{j}/velocity" for j in traction] + [f"{j}/position" for j in steering]
    return [], []  # the sensor broadcasters read sensors, not joints
