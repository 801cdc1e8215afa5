"""RunPlan: everything a world process needs, as plain serialisable data.

Made by `runner.compile.compile_plan`; handed to child processes (or other hosts) as JSON.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel


class TopicPlan(BaseModel):
    key: str  # full Zenoh key, e.g. two_robots/r1/scan
    type: str  # ROS 2 type, e.g. sensor_msgs/msg/LaserScan
    rate: float | None = None  # sim Hz, when known
    direction: Literal["pub", "sub"] = "pub"
    owner: str = ""  # e.g. r1/lidar


class ServicePlan(BaseModel):
    """A service (`kind="service"`, `type` pkg/srv/Name) or an action server (`kind="action"`, `type`
    pkg/action/Name) the world answers; an action's services and topics are under `<key>/_action/`."""

    key: str  # full Zenoh key, e.g. arm/arm_controller/follow_joint_trajectory
    type: str
    kind: Literal["service", "action"] = "service"
    owner: str = ""  # e.g. arm/arm_controller, or `world`


# The world's simulation control services (runner.sim.control answers them), under the names scripts use:
# gazebo_ros's (Gazebo Classic, ROS 2: gazebo_ros_init.cpp, gazebo_ros_factory.cpp, gazebo_ros_state.cpp
# with no <ros><namespace>) at the top of the run, and ros_gz's (Gazebo Sim through ros_gz_bridge, which
# keeps gz-transport's names: /world/<world>/control...) under `world/<world name>`. The world tells them
# apart by the last part of the key.
GAZEBO_ROS_SERVICES: tuple[tuple[str, str], ...] = (
    ("reset_simulation", "std_srvs/srv/Empty"),
    ("reset_world", "std_srvs/srv/Empty"),
    ("pause_physics", "std_srvs/srv/Empty"),
    ("unpause_physics", "std_srvs/srv/Empty"),
    ("get_entity_state", "gazebo_msgs/srv/GetEntityState"),
    ("set_entity_state", "gazebo_msgs/srv/SetEntityState"),
    ("spawn_entity", "gazebo_msgs/srv/SpawnEntity"),
    ("delete_entity", "gazebo_msgs/srv/DeleteEntity"),
)
ROS_GZ_SERVICES: tuple[tuple[str, str], ...] = (
    ("control", "ros_gz_interfaces/srv/ControlWorld"),
    ("set_pose", "ros_gz_interfaces/srv/SetEntityPose"),
    ("create", "ros_gz_interfaces/srv/SpawnEntity"),
    ("remove", "ros_gz_interfaces/srv/DeleteEntity"),
)


def control_services(run: str, world_name: str) -> list[ServicePlan]:
    """The world's own services of a world plan named `run` whose Gazebo world name is `world_name`."""
    out = [ServicePlan(key=f"{run}/{n}", type=t, owner="world") for n, t in GAZEBO_ROS_SERVICES]
    out += [
        ServicePlan(key=f"{run}/world/{world_name}/{n}", type=t, owner="world") for n, t in ROS_GZ_SERVICES
    ]
    return out


class PluginPlan(BaseModel):
    type: str
    name: str
    params: dict[str, Any]
    rate: float | None
    control_rate: float | None = None  # how often before_step runs, when not at `rate`
    topics: list[TopicPlan] = []
    services: list[ServicePlan] = []
    source_file: str | None = None  # where the description declares it (a Gazebo <plugin> or <sensor>)
    source_line: int | None = None
    added: str | None = None  # not declared, added by the runner, and why (`foxglove.scene`)


class ParityLine(BaseModel):
    """One line of a robot's "as in Gazebo" summary: a drive, a sensor, self-collision, or what was changed,
    dropped or ignored to load it, with where in the description it comes from."""

    kind: str
    text: str
    file: str | None = None
    line: int | None = None


class HardwareJoint(BaseModel):
    """A joint of the robot's ros2_control / ros_control hardware, as the world sets it up before any plugin:
    start state, servo gains from the inertia it moves, velocity limit (runner.sim.hardware)."""

    joint: str  # un-prefixed
    actuators: dict[str, str] = {}  # command interface -> actuator name (un-prefixed)
    loop_gain: float | None = None  # position: 1/s from error to velocity setpoint; None: Gazebo sets it
    pid: dict[str, float] | None = None  # position: {p, i, d} given by the description / controllers file
    velocity_limit: float | None = None  # rad/s or m/s (URDF <limit velocity>)
    initial_position: float | None = None
    initial_velocity: float | None = None
    initial_effort: float | None = None  # the effort command until a controller sends one
    state_interfaces: list[str] = []  # its <state_interface>s (the controller manager lists them)


class RobotPlan(BaseModel):
    name: str
    namespace: str
    prefix: str  # MuJoCo name prefix, e.g. "r1/"
    root: str  # root link name (un-prefixed)
    fixed: bool
    description_file: str
    links: list[str]
    joints: list[str]
    plugins: list[PluginPlan]
    urdf: str = ""  # the description as URDF (xacro expanded): published on <ns>/robot_description
    gazebo: list[ParityLine] = []  # the robot as in Gazebo (scenario validate prints it)
    # The description's root link is `world` (it welds the robot): `root` (its first child) in that link's
    # frame, x y z qw qx qy qz. The link is the TF frame `<ns>/world` at the robot's pose.
    world_origin: list[float] | None = None
    hardware: list[HardwareJoint] = []  # <ros2_control> / <transmission> joints
    hardware_rate: float = 100.0  # the controller manager's update rate (Hz)


class TimelinePlan(BaseModel):
    t_ns: int
    key: str
    type: str  # the message's, or with `call` the service's (pkg/srv/Name)
    data: dict[str, Any]  # the message, or the request
    call: bool = False  # a call of the world's service `key` (made once per run), not a message


class ActorPlan(BaseModel):
    """An actor (a mocap body named `name`): its path as times and points, or its hinge."""

    name: str
    start_ns: int | None  # None: started by an event
    pos: list[float]  # where it stands before it starts (world frame)
    quat: list[float]  # its orientation then (w, x, y, z)
    times: list[float] = []  # seconds after it starts, one per point
    points: list[list[float]] = []  # [x, y, z] of its origin
    loop: bool = False
    travel: bool = False  # its yaw follows the direction of travel (added to its pose's)
    hinge: dict[str, Any] | None = None  # {at, axis, angle, duration} in the model's frame


class EventPlan(BaseModel):
    """An event with every name resolved (MuJoCo bodies, Zenoh keys, actor and plugin indices):
    `when` and each of `do` are `{"kind": ..., fields...}` (runner.compile.events says which)."""

    name: str
    when: dict[str, Any]
    do: list[dict[str, Any]]
    repeat: bool = False


class NodePlan(BaseModel):
    """A process of the run, its command resolved (`argv[0]` an executable, `cwd` absolute)."""

    name: str
    argv: list[str]
    world: str | None = None  # with several worlds: the world whose key space it works in
    host: str | None = None  # with hosts: the host that runs it (None: the first)
    env: dict[str, str] = {}
    cwd: str
    namespace: str | None = None
    topics: list[TopicPlan] = []  # what it says it publishes (`publishes:`)
    respawn: Literal["never", "on-failure"] = "never"
    respawn_limit: int = 3
    required: bool = False


class Ros2Plan(BaseModel):
    domain: int = 0
    node: str  # the ROS 2 node the simulation appears as
    router: str | None = None  # a ROS 2 Zenoh router the bridge process joins as well
    topics: Literal["all", "bridged"] = "all"


class BridgePlan(BaseModel):
    """One mapping, resolved: the sim key and type, and the key on the other side."""

    where: str  # for messages: `bridges[0]`, `bridge.yaml:12`
    sim_key: str
    type: str
    direction: Literal["SIM_TO_ZENOH", "ZENOH_TO_SIM", "BIDIRECTIONAL"]
    key: str | None = None  # plain Zenoh key (None with ros2)
    ros_topic: str | None = None  # ROS 2 fully qualified name, with ros2
    ros2: Ros2Plan | None = None
    encoding: Literal["cdr", "json"] = "cdr"
    rate: float | None = None  # messages per sim second, at most
    lazy: bool = False
    best_effort: bool = False  # the sim topic is best effort (`qos:`): its copy drops rather than blocks


class ServiceBridgePlan(BaseModel):
    """A service the world answers, offered to ROS 2 as rmw_zenoh offers one (an action is three of these,
    and its two topics as ordinary `BridgePlan`s)."""

    where: str
    sim_key: str
    type: str  # the service type: pkg/srv/Name, or an action's pkg/action/Name_SendGoal ...
    ros_name: str  # fully qualified
    ros2: Ros2Plan


class FoxglovePlan(BaseModel):
    scene: bool = True  # geometry (foxglove.SceneUpdate), every link's tf, robot_description
    rate: float = 1.0  # scene, tf_static and robot_description are sent again this often (no latching)
    tf_rate: float = 30.0  # moving links' transforms


class RecordPlan(BaseModel):
    enabled: bool
    path: str
    include: list[str]  # full key expressions
    exclude: list[str]
    compression: Literal["zstd", "none"] = "zstd"  # the chunks' (recordings of older plans: zstd)


class NoticePlan(BaseModel):
    """One warning of compile, as data (`scenario validate --json`; the CLI groups them by kind): its
    message, where, its hint, its kind (runner.errors.kind_of) and what it is about (a topic, a tag)."""

    message: str
    file: str | None = None
    line: int | None = None
    hint: str | None = None
    kind: str = ""
    about: str | None = None
    text: str = ""  # as printed: "file:line: message" and the hint


class RunPlan(BaseModel):
    name: str
    scenario_file: str | None
    duration_ns: int
    rate: Literal["realtime", "max"] | float
    seed: int
    step_ns: int
    clock_rate: float
    mjcf: str
    robots: list[RobotPlan]
    timeline: list[TimelinePlan]
    record: RecordPlan
    actors: list[ActorPlan] = []
    events: list[EventPlan] = []  # in the order they are looked at in a step (one that follows another
    # in the same step after it)
    notices: list[str] = []  # warnings from compile: tags read but not acted on, and the scenario's own
    # warnings about the scenario file itself (a window past its end, a typo'd topic): errors with --strict
    scenario_warnings: list[str] = []
    notice_items: list[NoticePlan] = []  # `notices` as data, each with its kind: what validate groups
    assertions: list[dict[str, Any]] = []  # the scenario's assertion models, as plain data
    assertion_keys: list[str] = []  # the key each assertion reads
    # what of the scenario a robot spawned at run time is compiled against (runner.compile.spawn)
    spawn: dict[str, Any] | None = None
    contact_watch: list[str] = []  # robot/model names whose contacts the world publishes on <run>/_contacts
    stop_on: Literal["never", "first_failure", "all_decided"] = "never"
    renderers: Literal["auto", "world", "process"] = "auto"  # the launcher resolves auto
    nodes: list[NodePlan] = []
    lockstep: list[str] = []  # node names the world waits for at each step
    zenoh: dict[str, Any] | None = None  # {"file": absolute path | None, "settings": {path: value}}
    listen: list[str] = []  # the run's router endpoints (zenoh.listen), unless --listen says otherwise
    foxglove: FoxglovePlan = FoxglovePlan()  # what the world publishes for a 3D view
    best_effort: list[str] = []  # key expressions whose publishers drop rather than block (qos:)
    bridges: list[BridgePlan] = []  # run by the bridge process (a node of the run)
    service_bridges: list[ServiceBridgePlan] = []  # services offered to ROS 2 by the bridge process
    world_services: list[ServicePlan] = []  # the world's own (simulation control), beside the plugins'
    ros2: Ros2Plan | None = None  # the run's rmw_zenoh settings, when it appears to ROS 2 as a whole
    # Several worlds: each its own plan, named `<run>/<world>` (so its keys are `<run>/<world>/<ns>/...`),
    # run by a process of its own; this plan then holds the run-wide parts (record, nodes, stop_on).
    worlds: list[RunPlan] = []
    hosts: dict[str, str] = {}  # host name -> Zenoh endpoint; the first is the main host
    host: str | None = None  # with hosts: the host that simulates this world (None: the first)
    variant: str = ""  # the matrix variant's label ("" without a matrix): its values, sample, drawn values
    drawn: dict[str, Any] = {}  # values drawn at random (runner.scenario.draws): {path: value}
    # what one run asks of a cluster (`resources:`; `scenario test --ray`): {num_cpus, num_gpus, custom}
    resources: dict[str, Any] | None = None

    def parts(self) -> list[RunPlan]:
        """The world plans of the run: `worlds`, or this plan itself."""
        return self.worlds or [self]

    def every_plan(self) -> list[RunPlan]:
        """This plan and each of its worlds' (once each): for a setting every one of them carries."""
        return [self, *self.worlds]

    @property
    def main_host(self) -> str | None:
        return next(iter(self.hosts), None)

    def on_host(self, host: str | None, placed: str | None) -> bool:
        """Whether a part placed on `placed` (None: the main host) runs on `host` (None: the main host)."""
        if not self.hosts:
            return True  # everything here
        main = self.main_host
        return (placed or main) == (host or main)

    def renders(self) -> bool:
        """Whether any plugin of the run renders (cameras)."""
        from runner.plugin.registry import load

        return any(load(p.type).renders for r in self.robots for p in r.plugins)

    @property
    def clock_key(self) -> str:
        return f"{self.name}/clock"

    def services(self) -> list[ServicePlan]:
        """Every service and action server of this world: its own, then its plugins', in plan order."""
        return [*self.world_services, *(s for r in self.robots for p in r.plugins for s in p.services)]

    def topics(self) -> list[TopicPlan]:
        """Every topic of the run, once per key and direction; a key several plugins publish on (a
        robot's `tf`) lists them all and the sum of their rates."""
        out = [
            TopicPlan(key=self.clock_key, type="rosgraph_msgs/msg/Clock", rate=self.clock_rate, owner="world")
        ]
        seen: dict[tuple[str, str], TopicPlan] = {(self.clock_key, "pub"): out[0]}
        for r in self.robots:
            for p in r.plugins:
                for t in p.topics:
                    known = seen.get((t.key, t.direction))
                    if known is None:
                        seen[(t.key, t.direction)] = t.model_copy()
                        out.append(seen[(t.key, t.direction)])
                    else:
                        known.owner = f"{known.owner}, {t.owner}"
                        if known.rate is not None and t.rate is not None:
                            known.rate += t.rate
        for n in self.nodes:
            for t in n.topics:
                if (t.key, "pub") not in seen:
                    seen[(t.key, "pub")] = t
                    out.append(t)
        for ev in self.timeline:
            if not ev.call and (ev.key, "pub") not in seen:
                seen[(ev.key, "pub")] = TopicPlan(key=ev.key, type=ev.type, direction="pub", owner="timeline")
                out.append(seen[(ev.key, "pub")])
        return out
