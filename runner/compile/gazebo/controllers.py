"""ros_control and ros2_control: the controller manager. It reads the controllers files as the controller
manager and its spawner read them, and hands each controller to the handler of its type
(runner.compile.gazebo.control); a type without one is said with its type at its own line.

Files: the ones the description's control plugin names (`<parameters>`, each one, in order) then the
scenario's `controllers:` (what a launch file's spawner would load), read together as the controller manager
reads the parameter files it is given (a later file's value wins). Layouts, ROS 2:
- `controller_manager: ros__parameters: {update_rate, <name>: {type: ...}}`, each controller's own
  parameters in `<name>: ros__parameters:`;
- the spawner's `--param-file` layout: `type:` inside the controller's own `ros__parameters` and no
  controller list (controller_manager_services.py, get_parameter_from_param_files, on Jazzy);
- any of these under `/**`, a namespace (`/robot/controller_manager`, nested maps), `/**/<name>`, or a
  wildcard node (`/**: ros__parameters:`, `<ns>/*`), whose parameters every node gets.
ROS 1: `<name>: {type: ..., ...}` at the top or under namespaces.

A key written twice in one mapping is a warning naming both lines; ROS 2 files are then merged as
rcl_yaml_param_parser merges them (parse.c on Humble: `find_node`, :1008, finds the node a repeated key
names again and adds to it; `find_parameter`, :964, finds a repeated parameter and its later value
replaces the earlier), ROS 1 files keep the later block (rosparam loads them with PyYAML, which does)."""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.control import ControlContext, ControllerSpec, Remap, fork_of, handler_for
from runner.compile.gazebo.control import manager as manager_node
from runner.compile.gazebo.control.params import Block
from runner.compile.gazebo.info import Where
from runner.compile.gazebo.tags import TagReader
from runner.errors import SourceError

_LAUNCH_ARG = re.compile(r"\$\(arg\s+([^)\s]+)\s*\)")
_WILDCARDS = ("*", "**")
MANAGER = "controller_manager"
UPDATE_RATE = 100.0  # controller_manager_parameters.yaml: update_rate's default (Humble and Jazzy)

# the controller manager's parameters (controller_manager_parameters.yaml, Jazzy) and why each is not used
# here: the controllers run inside the physics step, at the manager's update_rate, on simulated time
_MANAGER_SAID = {
    "enforce_command_limits": "command limits are the URDF's, as the hardware layer applies them",
    "handle_exceptions": "no controller throws here",
    "hardware_components_initial_state": "every hardware component starts active",
    "defaults": "controllers are activated at the start, as the spawner does",
    "diagnostics": "no diagnostics are published",
    "overruns": "the update loop runs inside the physics step and never overruns",
    "thread_priority": "no real-time thread",
    "cpu_affinity": "no real-time thread",
    "lock_memory": "no real-time thread",
    "use_sim_time": "",  # always simulated time here: nothing to say
    "robot_description": "the description is the robot's",
}


class _LineLoader(yaml.SafeLoader):
    """yaml.SafeLoader (the same tags and types) whose mappings are `Block`s knowing the line of each key,
    and which records a key written twice in one mapping (PyYAML keeps the later silently)."""

    merge = True  # a repeated key's two mappings are merged (ROS 2); else the later is kept (ROS 1)

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self.duplicates: list[tuple[Any, int, int]] = []  # (key, first line, repeated line)


def _merge(into: Block, more: Block) -> Block:
    """`more` over `into`, mappings merged key by key, the later value winning (rcl's parameter files)."""
    for key, value in more.items():
        old = into.get(key)
        if isinstance(old, Block) and isinstance(value, Block):
            _merge(old, value)
        else:
            into[key] = value
            into.lines[key] = more.lines.get(key, into.lines.get(key, 0))
    return into


def _construct_block(loader: _LineLoader, node: yaml.MappingNode) -> Any:
    data = Block()
    yield data
    explicit = sum(1 for k, _ in node.value if k.tag != "tag:yaml.org,2002:merge")
    loader.flatten_mapping(node)  # `<<:` merge keys first, as SafeConstructor does
    merged = len(node.value) - explicit
    written: set[Any] = set()  # keys written in this mapping itself (a merged-in key may be overridden)
    for i, (key_node, value_node) in enumerate(node.value):
        key = loader.construct_object(key_node, deep=True)
        try:
            hash(key)
        except TypeError:
            raise yaml.constructor.ConstructorError(
                "while constructing a mapping", node.start_mark, "found unhashable key", key_node.start_mark
            ) from None
        value = loader.construct_object(value_node, deep=True)
        line = key_node.start_mark.line + 1
        if i >= merged and key in written:
            loader.duplicates.append((key, data.lines.get(key, 0), line))
            old = data[key]
            if loader.merge and isinstance(old, Block) and isinstance(value, Block):
                _merge(old, value)
                continue
        data[key] = value
        data.lines[key] = line
        if i >= merged:
            written.add(key)


_LineLoader.add_constructor("tag:yaml.org,2002:map", _construct_block)  # type: ignore[arg-type]


@dataclass
class _File:
    path: Path
    doc: Any
    ros2: bool
    duplicates: list[tuple[Any, int, int]]


@dataclass
class _Node:
    """A node's parameters in a ROS 2 parameters file."""

    name: str  # the node's own name (the last part of its key path), `*`/`**` for a wildcard
    params: Block
    file: Path
    line: int | None  # the line of the key naming the node


@dataclass
class ControlPlugin:
    """The description's control plugin (gazebo_ros_control, gazebo_ros2_control, gz_ros2_control or a fork),
    read at its `<gazebo>` block; its controllers are read once every block is (`run_controller_files`)."""

    where: Where
    filename: str
    files: list[tuple[Path, Any]] = field(default_factory=list)  # (path, its <parameters> element)
    rules: list[Remap] = field(default_factory=list)
    remap: dict[str, str] = field(default_factory=dict)
    namespace: str = ""
    manager: str = MANAGER
    el: Any = None


def _load(g: ReaderBase, path: Path) -> _File:
    try:
        text = path.read_text()
    except OSError as e:
        hint = "check the path (`controllers:` in the scenario, or the description's <parameters>)"
        raise SourceError(
            f"controllers file {str(path)!r} cannot be read: {e.strerror or e}", path, hint=hint
        ) from None
    # `<rosparam subst_value="true">` substitutes launch arguments in such files: with none given here,
    # each `$(arg name)` is empty (the usual default of a `prefix`), and said
    args = sorted(set(_LAUNCH_ARG.findall(text)))
    if args:
        text = _LAUNCH_ARG.sub("", text)
        g.notices.add(
            f"controllers file: launch argument(s) {', '.join(args)} taken as empty",
            path,
            None,
            hint="write the values into a copy of the file if the robot is launched with others",
        )

    def parse(merge: bool) -> tuple[Any, list[tuple[Any, int, int]]]:
        loader = _LineLoader(text)
        loader.merge = merge
        try:
            return loader.get_single_data(), loader.duplicates
        except yaml.YAMLError as e:
            mark = getattr(e, "problem_mark", None)
            raise SourceError(
                f"controllers file {str(path)!r} is not valid YAML: {getattr(e, 'problem', e)}",
                path,
                mark.line + 1 if mark else None,
                hint="check the indentation and the `:` after each key at this line",
            ) from None
        finally:
            loader.dispose()

    doc, duplicates = parse(True)
    ros2 = _has_ros_parameters(doc)
    if duplicates and not ros2:
        doc, duplicates = parse(False)
    return _File(path, doc, ros2, duplicates)


def _has_ros_parameters(doc: Any) -> bool:
    if not isinstance(doc, dict):
        return False
    return any(k == "ros__parameters" or _has_ros_parameters(v) for k, v in doc.items())


def _nodes(f: _File) -> list[_Node]:
    """Every node's `ros__parameters` in a ROS 2 file, its name from its key path (`/**/controller_manager`,
    `/robot: {controller_manager: ...}`, `robot/*`: rcl reads nested maps as namespaces)."""
    out: list[_Node] = []

    def walk(node: Any, parts: list[str], line: int | None) -> None:
        if not isinstance(node, dict):
            return
        for key, value in node.items():
            if key == "ros__parameters" and isinstance(value, dict):
                name = parts[-1] if parts else "**"
                out.append(_Node(name, value if isinstance(value, Block) else Block(value), f.path, line))
            elif isinstance(value, dict):
                tokens = [t for t in str(key).split("/") if t]
                walk(value, parts + tokens, getattr(node, "lines", {}).get(key, line))

    walk(f.doc, [], None)
    return out


def _say_duplicates(g: ReaderBase, f: _File) -> None:
    for key, first, again in f.duplicates:
        how = (
            "ROS 2's parameter file parser (rcl_yaml_param_parser) merges the two blocks, a parameter in "
            "both taking the later value, and so do we"
            if f.ros2
            else "rosparam (PyYAML) keeps only the later one, and so do we"
        )
        g.notices.add(
            f"controllers file: key {key!r} at line {again} repeats the one at line {first}: {how}",
            f.path,
            again,
            hint="a YAML mapping should name each key once: merge the two blocks into one",
        )


def _ros2_specs(g: ReaderBase, files: list[_File], manager: str) -> tuple[list[ControllerSpec], set[Path]]:
    """The controllers of ROS 2 files read together, and the files that gave a controller or parameters
    of one."""
    nodes = [n for f in files if f.ros2 for n in _nodes(f)]
    shared = Block()  # a wildcard node's parameters: every node gets them (rcl matches `/**`, `*`)
    for n in nodes:
        if n.name in _WILDCARDS:
            _merge(shared, _copy(n.params))
    own: dict[str, Block] = {}
    first: dict[str, _Node] = {}
    for n in nodes:
        if n.name not in _WILDCARDS:
            _merge(own.setdefault(n.name, Block()), _copy(n.params))
            first.setdefault(n.name, n)
    cm = _merge(_copy(shared), own.get(manager, Block()))
    cm.inherited = {k for k in shared if k not in own.get(manager, Block())}
    cm_node = first.get(manager)
    rate = _manager_rate(g, cm, cm_node)
    listed = _manager_entries(g, cm, nodes, manager)
    used: set[Path] = set()
    specs: list[ControllerSpec] = []
    for name in first:
        if name == manager:
            continue
        kind = own[name].get("type")
        if isinstance(kind, str):  # the spawner's `--param-file` layout: the type in its own parameters
            if name in listed and listed[name][0] != kind:
                g.notices.add(
                    f"controller {name!r} is listed as {listed[name][0]} but its parameters say type {kind}: "
                    "the spawner sets the type from its parameters, and so do we",
                    *listed[name][1:],
                )
            typed = [m for m in nodes if m.name == name and "type" in m.params][-1]  # the last one wins
            listed[name] = (kind, typed.file, typed.params.lines.get("type", typed.line))
    for name, kind in g.spawn.types.items():  # a spawner's `-t <type>` (the scenario's controller_types:)
        if name in listed and listed[name][0] != kind:
            g.notices.add(
                f"controller {name!r}: controller_types gives {kind}, the file {listed[name][0]}: the "
                "spawner's -t wins",
                *g.spawn.where.get(name, (None, None)),
            )
        file, line = (first[name].file, first[name].line) if name in first else (None, None)
        listed[name] = (kind, file, line)
    for name, (kind, file, line) in listed.items():
        mine = own.get(name, Block())
        params = _merge(_copy(shared), mine)
        params.inherited = {k for k in shared if k not in mine}  # a wildcard block's: not checked per type
        own_rate = params.get("update_rate")
        spec_rate = rate
        if isinstance(own_rate, (int, float)) and 0 < own_rate < rate:
            # controller_manager.cpp:1669 (Jazzy): a controller may run slower than the manager, not faster
            # (:3433 runs one asking more at the manager's rate)
            spec_rate = float(own_rate)
        specs.append(ControllerSpec(name, kind, params, file, line, False, spec_rate))
        if file:
            used.add(file)
        if name in first:
            used.add(first[name].file)
    for name, n in first.items():
        if name != manager and name not in listed:
            g.notices.add(
                f"controllers file: parameters of {name!r}, which no controller list names and which have no "
                "`type`: no controller is loaded with them",
                n.file,
                n.line,
                hint=f"list it under {manager}: ros__parameters: {name}: {{type: ...}}, or give it a `type:`",
            )
    # a file is used when it gives the manager's parameters or a listed controller's
    used |= {n.file for n in nodes if n.name == manager or n.name in listed}
    for n in nodes:
        if n.name in _WILDCARDS and isinstance(n.params.get("type"), str):
            g.notices.add(
                f"controllers file: a wildcard block gives a controller type ({n.params['type']}) but no "
                "controller name (the spawner's command line names it): it is not run",
                n.file,
                n.params.lines.get("type", n.line),
                hint="name the controller: <name>: ros__parameters: {type: ...}",
            )
    return specs, used


def _manager_entries(
    g: ReaderBase, cm: Block, nodes: list[_Node], manager: str
) -> dict[str, tuple[str, Path | None, int | None]]:
    """The controllers the controller manager's parameters list (`<name>: {type}` or `<name>.type`), each
    with the file and line of its entry; its other parameters read (update_rate) or said."""
    listed: dict[str, tuple[str, Path | None, int | None]] = {}  # name -> (type, file, line)
    for key, value in cm.items():
        if isinstance(value, dict) and isinstance(value.get("type"), str):
            where = _where_of(nodes, manager, key)
            listed[str(key)] = (value["type"], *where)
        elif isinstance(key, str) and key.endswith(".type") and isinstance(value, str):
            listed[key[: -len(".type")]] = (value, *_where_of(nodes, manager, key))
        elif key in cm.inherited:  # a wildcard node's parameter: every node gets it, few read it
            pass
        elif key in _MANAGER_SAID:
            if _MANAGER_SAID[str(key)]:
                g.notices.add(
                    f"controller manager parameter {key!r} is not used ({_MANAGER_SAID[str(key)]})",
                    *_where_of(nodes, manager, key),
                )
        elif key == "update_rate":
            pass
        elif isinstance(value, dict):
            g.notices.add(
                f"controller manager entry {key!r} has no `type`: no controller is loaded from it",
                *_where_of(nodes, manager, key),
                hint=f"{key}: {{type: <package>/<Class>}}",
            )
        else:
            g.notices.add(
                f"controller manager parameter {key!r} is not one of its parameters: it is not used",
                *_where_of(nodes, manager, key),
            )
    return listed


def _copy(b: Block) -> Block:
    out = Block()
    for k, v in b.items():
        out[k] = _copy(v) if isinstance(v, Block) else v
    out.lines = dict(b.lines)
    return out


def _where_of(nodes: list[_Node], manager: str, key: Any) -> tuple[Path | None, int | None]:
    """The file and line where the controller manager's parameters give `key` (the last file that does)."""
    found: tuple[Path | None, int | None] = (None, None)
    for n in nodes:
        if n.name == manager and key in n.params:
            found = (n.file, n.params.lines.get(key))
    return found


def _manager_rate(g: ReaderBase, cm: Block, cm_node: _Node | None) -> float:
    value = cm.get("update_rate", UPDATE_RATE)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value <= 0:
        g.notices.add(
            f"controller manager update_rate {value!r} is not a positive number: {UPDATE_RATE:g} Hz is used",
            cm_node.file if cm_node else None,
            cm.lines.get("update_rate"),
        )
        return UPDATE_RATE
    return float(value)


def _ros1_specs(f: _File) -> list[ControllerSpec]:
    """ROS 1: `<name>: {type: ..., ...}` at the top or under namespaces."""
    found: list[ControllerSpec] = []

    def walk(node: Any) -> None:
        if not isinstance(node, dict):
            return
        lines = getattr(node, "lines", {})
        for key, value in node.items():
            if isinstance(value, dict) and isinstance(value.get("type"), str):
                found.append(ControllerSpec(str(key), value["type"], value, f.path, lines.get(key), True))
            elif isinstance(value, dict):
                walk(value)

    walk(f.doc)
    return found


def read_controllers(
    g: ReaderBase, paths: list[Path], manager: str = MANAGER, on_error: dict[Path, Any] | None = None
) -> list[ControllerSpec]:
    """The controllers of these files, read together as the controller manager reads them. A file that
    cannot be read raises SourceError, unless `on_error` has a callback `(error) -> None` for its path."""
    files: list[_File] = []
    for path in paths:
        try:
            files.append(_load(g, path))
        except SourceError as e:
            if on_error is None or path not in on_error:
                raise
            on_error[path](e)
    for f in files:
        _say_duplicates(g, f)
    specs, used = _ros2_specs(g, files, manager)
    for f in files:
        if not f.ros2:
            ros1 = _ros1_specs(f)
            specs += ros1
            if ros1:
                used.add(f.path)
    for f in files:
        if f.path not in used:
            g.notices.add(
                f"controllers file {str(f.path)!r} yields no controller: no `controller_manager: "
                "ros__parameters:` list, no controller block with a `type:` (ROS 2: `<name>: "
                "ros__parameters: {type: ...}`; ROS 1: `<name>: {type: ...}`)",
                f.path,
                None,
                hint="check the file is the controllers file the robot's launch loads",
            )
    return specs


def dispatch(ctx: ControlContext, specs: list[ControllerSpec], loaded: list[dict[str, Any]]) -> int:
    """Each controller to the handler of its type; returns how many run (each added to `loaded`, for the
    controller manager). With the scenario's `spawn:`, only the controllers it names (what the launch's
    spawners start); the others are loaded by no spawner."""
    count = 0
    spawn = ctx.g.spawn.names
    for spec in specs:
        if spawn is not None and spec.name not in spawn:
            ctx.g.notices.add(
                f"controller {spec.name!r} is not spawned (`spawn:` leaves it out): not run (nor loadable)",
                *spec.where,
            )
            continue
        handler = handler_for(spec.type)
        parent = fork_of(spec.type) if handler is None else None
        if parent is not None:
            ctx.g.notices.add(
                f"controller {spec.name!r}: {spec.type} is run as {parent}, the controller it is a fork of; "
                "parameters of the fork's own are said",
                *spec.where,
            )
            spec = dataclasses.replace(spec, type=parent)
            handler = handler_for(parent)
        if handler is None:
            ctx.g.notices.add(
                f"ros_control controller {spec.name!r} ({spec.type}) is not run",
                *spec.where,
                "controller types we run: " + ", ".join(sorted(_types())),
            )
            continue
        ctx.node = spec.name
        before = len(ctx.g.info.plugins)
        try:
            if handler(ctx, spec):
                count += 1
                loaded.append(manager_node.entry(spec, ctx.g.info.plugins[before:]))
        finally:
            ctx.node = None
    return count


def _types() -> list[str]:
    from runner.compile.gazebo.control import handlers

    return list(handlers())


def run_controller_files(g: ReaderBase) -> None:
    """Once every `<gazebo>` block is read: the controllers of each control plugin (its `<parameters>`
    files, then the scenario's `controllers:` for the first plugin), with the plugin's remappings and
    namespace. The scenario's files run with no plugin too (their launch file loads them)."""
    plugins: list[ControlPlugin] = list(g.control_plugins)
    scenario_files = list(g.controller_files)
    if not plugins and not scenario_files:
        return
    names: set[str] = set()
    managers: set[str] = set()
    if not plugins:
        plugins = [ControlPlugin((scenario_files[0], None), "")]
    for k, plugin in enumerate(plugins):

        def unreadable(el: Any) -> Any:
            return lambda e: g.note(el, f"{e}; its controllers are not run")

        paths = [p for p, _ in plugin.files] + (scenario_files if k == 0 else [])
        on_error = {path: unreadable(el) for path, el in plugin.files}
        specs = read_controllers(g, paths, plugin.manager, on_error)
        names |= {s.name for s in specs}
        # the rules as written (`~/` kept) replace the plugin's remap table, which has lost the `~/`
        ctx = ControlContext(g, plugin.where, {}, plugin.rules, plugin.namespace)
        loaded: list[dict[str, Any]] = []
        ran = dispatch(ctx, specs, loaded)
        if ran:
            spawn = g.spawn.names
            unspawned = [s.name for s in specs if spawn is not None and s.name not in spawn]
            manager_node.add_manager(ctx, plugin.where, plugin.manager, loaded, unspawned, managers)
        if ran or plugin.el is None:
            continue
        if g.spawn.names is not None and specs:
            why = " (the robot's `spawn:` starts none of its controllers)"
        else:
            why = " (its <parameters> files yield no controller we run)" if plugin.files else ""
        g.note(
            plugin.el,
            f"{plugin.filename!r}: ros_control controllers are not run{why}; the hardware holds its joints "
            "where they start, as Gazebo's system holds joints no controller claims",
            hint="name the controllers file the robot's launch loads in the scenario (`controllers:`), or "
            "command joints with a `joint_controller` plugin",
        )
    for name in g.spawn.names or []:
        if name not in names:
            g.notices.add(
                f"`spawn:` names controller {name!r}, which no controllers file has: nothing is spawned "
                "for it (the spawner would fail to load it)",
                *g.spawn.where.get(name, (None, None)),
                hint="controllers: " + ", ".join(sorted(names)) if names else None,
            )


def _ros_rules(r: TagReader) -> tuple[list[Remap], str]:
    """The plugin's `<ros><remapping>` (and `<argument>-r a:=b`) rules as written, and its namespace."""
    rules: list[Remap] = []
    ros = r.el.find("ros")
    if ros is None:
        return rules, ""
    for rm in ros.findall("remapping") + ros.findall("argument"):
        text = (rm.text or "").strip()
        text = re.sub(r"^(--ros-args\s+)?(-r\s+|--remap\s+)?", "", text).strip()
        if ":=" not in text:
            continue
        src, dst = (s.strip() for s in text.split(":=", 1))
        node = None
        if ":" in src and not src.startswith("~"):  # `node:from:=to`, a rule for one node
            node, src = src.split(":", 1)
        if src.startswith("__"):  # `__ns:=`, `__node:=`: the node's name, not a topic
            continue
        rules.append(Remap(src, dst, node))
    return rules, (ros.findtext("namespace") or "").strip()


def ros_control(g: ReaderBase, r: TagReader, remap: dict[str, str]) -> None:
    """gazebo_ros_control (ROS 1): its controllers come from parameters a launch file loads (the scenario's
    `controllers:`). gz_ros2_control / gazebo_ros2_control (ROS 2) and their forks: `<parameters>` names the
    controllers files. Read when every block is (`run_controller_files`), with the plugin's `<ros>`."""
    # read here: the files, the `<ros>` block, the manager's name; read by the hardware layer (gains, holding
    # joints, the description's parameter): marked; gazebo_ros_control's (ROS 1) said where they change
    # something; any other tag is said by the caller (`ignored`)
    r.mark("parameters", "ros", "controller_manager_name", "robot_param", "robot_param_node", "robotParam")
    r.mark("hold_joints", "position_proportional_gain", "controller_manager_prefix_node_name")
    r.mark("robotNamespace")  # (<legacyModeNS>: Noetic reads none; the catalogue's reason says so)
    period = r.child("controlPeriod")
    if period is not None:
        g.note(
            period,
            f"<controlPeriod> {(period.text or '').strip()!r} is not used: ROS 1 controllers act at every "
            "physics step here (a joint servo inside the step), joint_state_controller at its publish_rate",
        )
    sim_type = r.text("robotSimType")
    if sim_type and sim_type != "gazebo_ros_control/DefaultRobotHWSim":
        g.note(
            r.child("robotSimType"),
            f"<robotSimType> {sim_type!r}: a custom hardware interface is not loaded; the joints get the "
            "default one's (gazebo_ros_control/DefaultRobotHWSim) position, velocity and effort interfaces",
        )
    estop = r.child("eStopTopic")
    if estop is not None:
        g.note(
            estop,
            "<eStopTopic> is not subscribed: no emergency stop (gazebo_ros_control stops controllers on it)",
        )
    files = []
    for e in r.children("parameters"):
        text = (e.text or "").strip()
        if not text.endswith((".yaml", ".yml")):
            continue
        path = Path(text)
        if not path.is_absolute():
            base = g.where(e)[0]
            path = (base.parent if base else Path.cwd()) / path
        files.append((path, e))
    rules, namespace = _ros_rules(r)
    manager = (r.text("controller_manager_name") or MANAGER).strip().strip("/").split("/")[-1] or MANAGER
    plugin = ControlPlugin(
        g.where(r.el), r.el.get("filename") or "", files, rules, dict(remap), namespace, manager, r.el
    )
    g.control_plugins.append(plugin)
    return None
