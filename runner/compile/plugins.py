"""A robot's plugins: the description's `<plugin>`s and the scenario's, merged by name (or type); the
`robot_state_publisher` the runner adds for Foxglove's scene; each one's parameters checked and built,
its mistakes pointed at the scenario's line or the description's."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from pydantic import ValidationError

from runner.compile.gazebo import DescribedPlugin
from runner.compile.urdf import RobotModel
from runner.errors import RATE_CAPPED, Location, Notices, Problem, Problems, ScenarioError
from runner.plan import PluginPlan, ServicePlan, TopicPlan
from runner.plugin import BuildContext, PluginConfigError, Service, Topic
from runner.plugin.registry import PluginLookupError, drive_frames, load
from runner.scenario.loader import Document, PathKey, non_finite
from runner.scenario.schema import Robot, Scenario
from runner.scenario.validate import validate_model
from runner.wire import interfaces
from runner.wire.transport import topic_key


@dataclass
class _Entry:
    """One plugin to build: from the scenario, from the description, or both merged."""

    type: str
    name: str
    params: dict[str, Any]
    scenario_index: int | None = None  # index in robots[i].plugins, when the scenario names it
    scenario_keys: frozenset[str] = frozenset()  # params the scenario set (the rest came from the file)
    source: DescribedPlugin | None = None
    added: str | None = None  # why the runner adds it, when neither the scenario nor the description has it


def _plugin_entries(robot: Robot, model: RobotModel) -> list[_Entry]:
    """The description's plugins, with the scenario's added, or merged in by name (or by type when the
    description has exactly one of that type): the scenario's params win."""
    entries: list[_Entry] = []
    if robot.plugins_from_description:
        entries = [_Entry(d.type, d.name, dict(d.params), source=d) for d in model.gazebo.plugins]
    for k, p in enumerate(robot.plugins):
        target = None
        if p.name is not None:
            target = next((e for e in entries if e.source and e.name == p.name), None)
        else:
            same = [e for e in entries if e.source and e.type == p.type and e.scenario_index is None]
            target = same[0] if len(same) == 1 else None
        if target is not None and target.type == p.type:
            target.params.update(p.params)
            target.scenario_index = k
            target.scenario_keys = frozenset(p.params)
        else:
            entries.append(_Entry(p.type, p.name or p.type, dict(p.params), k, frozenset(p.params)))
    return entries


STATE_PUBLISHER = "robot_state_publisher"


def _state_publisher(sc: Scenario, entries: list[_Entry]) -> list[_Entry]:
    """With `foxglove.scene` (the default), a robot whose scenario and description have no `tf` plugin gets
    one, as a launch file starts robot_state_publisher beside a Gazebo robot: every link's transform on
    the robot's `tf` (moving) and `tf_static` (fixed, sent again every `1/foxglove.rate` s: the transport
    does not latch, and a viewer seeking into a recording needs them near where it lands). A robot whose
    drive says where it is (odom -> base) is joined to it; any other from `world`. `entries`: the robot's
    own plugins (`_plugin_entries`)."""
    if not sc.foxglove.scene or any(e.type == "tf" for e in entries):
        return []
    driven = any(drive_frames(e.type, e.params) for e in entries)
    taken = {e.name for e in entries}
    name = next(n for n in (STATE_PUBLISHER, f"_{STATE_PUBLISHER}", "_tf") if n not in taken)
    params = {
        "rate": sc.foxglove.tf_rate,
        "static_period": 1.0 / sc.foxglove.rate,
        "include_root": not driven,
    }
    return [_Entry("tf", name, params, added="foxglove.scene")]


def build_plugins(
    sc: Scenario,
    robot: Robot,
    i: int,
    model: RobotModel,
    doc: Document,
    problems: Problems,
    notices: Notices | None = None,
) -> list[PluginPlan]:
    """The robot's plugins, built; each one's mistakes go to `problems` and it is left out. A rate above
    the physics step's is capped to it, and said to `notices` (`_cap_rate`)."""
    plans: list[PluginPlan] = []
    ctx = BuildContext(
        spec=model.spec,
        robot=robot.name,
        namespace=robot.ns,
        root=model.root,
        world_link=model.world is not None,
    )
    names: set[str] = set()
    entries = _plugin_entries(robot, model)
    for entry in entries + _state_publisher(sc, entries):
        here: PathKey = ("robots", i, "plugins", entry.scenario_index or 0)
        src = entry.source
        with problems.each():

            def fail(
                message: str, param: str | None, hint: str | None, entry: _Entry = entry
            ) -> ScenarioError:
                return _plugin_error(entry, here, doc, robot, i, message, param, hint)  # noqa: B023

            if entry.name in names:
                raise fail(f"two plugins named {entry.name!r}", None, "give one of them another `name:`")
            names.add(entry.name)
            try:
                cls = load(entry.type)
            except PluginLookupError as e:
                if entry.scenario_index is not None and entry.source is None:
                    where = (*here, "type")
                    raise ScenarioError(Problem(str(e), doc.locate(where), where, hint=e.hint)) from None
                raise fail(str(e), None, e.hint) from None
            _check_finite(entry, doc, here, fail)
            if src is None or entry.scenario_keys >= set(entry.params):
                params = validate_model(cls.Params, entry.params, doc, (*here, "params"))
            else:
                try:
                    params = cls.Params.model_validate(entry.params)
                except ValidationError as e:
                    err = e.errors(include_url=False)[0]
                    param = ".".join(str(x) for x in err["loc"]) or None
                    hint = f"give `{param}` a value the {entry.type} plugin takes" if param else None
                    raise fail(f"{err['msg']} (found {err.get('input')!r})", param, hint) from None
            params = _cap_rate(sc, cls, params, entry, doc, here, notices)
            try:
                topics = cls.build(params, ctx, entry.name)
            except PluginConfigError as e:
                raise fail(str(e), e.param, e.hint) from None
            declared = list(topics)
            bad = _check_services(declared)
            if bad is not None:
                raise fail(f"the plugin offers a service of an unknown type: {bad}", None, None)
            plans.append(
                PluginPlan(
                    type=entry.type,
                    name=entry.name,
                    params=params.model_dump(mode="json"),
                    rate=cls.rate_of(params),
                    control_rate=cls.control_rate_of(params),
                    source_file=str(src.file) if src is not None and src.file else None,
                    source_line=src.line if src is not None else None,
                    added=entry.added,
                    **_endpoints(declared, sc.name, robot.ns, f"{robot.ns}/{entry.name}"),
                )
            )
    return plans


def _cap_rate(
    sc: Scenario,
    cls: Any,
    params: Any,
    entry: _Entry,
    doc: Document,
    here: PathKey,
    notices: Notices | None,
) -> Any:
    """A plugin runs at most once per physics step, in Gazebo as here: a sensor's next update is due by sim
    time, which moves a whole step at a time (Gazebo Classic's Sensor::NeedsUpdate, gz-sensors'
    Sensor::NextDataUpdateTime), and a model plugin's update is a world-update callback, once a step: a
    contact sensor at 1000 Hz with a 2 ms step publishes at 500 Hz. The
    plan's rate says what runs: `rate` above 1/timestep becomes 1/timestep, said at the tag (the
    description's line, or the scenario's `rate:` when the scenario set it)."""
    rate = cls.rate_of(params)
    step = sc.world.physics.timestep
    top = 1.0 / step
    if not rate or rate <= top * (1 + 1e-9) or not hasattr(params, "rate"):
        return params
    if notices is not None:
        src = entry.source
        if src is not None and "rate" not in entry.scenario_keys:
            file, line = src.file, src.line
        else:
            loc = doc.locate((*here, "params", "rate"))
            file, line = loc.file, loc.line
        notices.add(
            f"{entry.type} {entry.name!r}: its rate {rate:g} Hz is above the physics step's {top:g} Hz "
            f"(timestep {step:g} s); Gazebo updates a sensor or plugin at most once a step, so it runs at "
            f"{top:g} Hz (here too)",
            file,
            line,
            hint="lower the rate to what runs, or shorten the world's physics timestep",
            kind=RATE_CAPPED,
            about=entry.name,
        )
    return params.model_copy(update={"rate": top})


def _endpoints(declared: list[Any], run: str, ns: str, owner: str) -> dict[str, Any]:
    """A plugin's topics and services, as its plan holds them (an action's topics among the topics)."""
    services = [
        ServicePlan(key=topic_key(run, ns, s.name), type=s.type, kind=s.kind, owner=owner)
        for s in declared
        if isinstance(s, Service)
    ]
    topics = [
        TopicPlan(
            key=topic_key(run, ns, t.name), type=t.type, rate=t.rate, direction=t.direction, owner=owner
        )
        for t in declared
        if isinstance(t, Topic)
    ]
    return {"topics": topics + action_topics(services), "services": services}


def action_topics(services: list[ServicePlan]) -> list[TopicPlan]:
    """The topics of each action server (rcl_action's `_action/feedback` and `_action/status`)."""
    out = []
    for s in services:
        if s.kind == "action":
            for suffix, type_name in interfaces.action_parts(s.type)[1]:
                out.append(TopicPlan(key=f"{s.key}/{suffix}", type=type_name, direction="pub", owner=s.owner))
    return out


def _check_services(declared: list[Any]) -> str | None:
    """What is wrong with the services a plugin's `build` declared (a type nobody knows), or None."""
    for s in declared:
        if isinstance(s, Service):
            try:
                (interfaces.action_type if s.kind == "action" else interfaces.service_type)(s.type)
            except KeyError as e:
                return f"{s.name}: {e.args[0]}"
    return None


def _check_finite(entry: _Entry, doc: Document, here: PathKey, fail: Any) -> None:
    """NaN and infinity are no parameter's meaning (a plugin's model may let them through): an error at
    the scenario's line when the scenario set it, else at the description's."""
    found = non_finite(entry.params)
    if found is None:
        return
    path, value = found
    if entry.scenario_index is not None and path[0] in entry.scenario_keys:
        where: PathKey = (*here, "params", *path)
        raise ScenarioError(
            Problem(
                "not a finite number",
                doc.locate(where),
                where,
                expected="a finite number",
                found=repr(value),
                hint="YAML reads .nan, .inf and numbers beyond 1.8e308 as these",
            )
        )
    shown = ".".join(str(p) for p in path)
    raise fail(f"{shown} is {value!r}, not a finite number", None, "give a plain, finite number")


def _plugin_error(
    entry: _Entry,
    here: PathKey,
    doc: Document,
    robot: Robot,
    i: int,
    message: str,
    param: str | None,
    hint: str | None,
) -> ScenarioError:
    """Point at the scenario when it set the parameter, else at the description's line."""
    hint = hint or "see the plugin's parameters in docs/plugins.md"
    src = entry.source
    if src is None or (entry.scenario_index is not None and (param is None or param in entry.scenario_keys)):
        where: PathKey = (*here, "params", param) if param else here
        return ScenarioError(Problem(message, doc.locate(where), where, hint=hint))
    what = f"{entry.type} plugin {entry.name!r} from the description"
    return ScenarioError(
        [
            Problem(
                f"{what}: " + (f"{param}: " if param else "") + message,
                Location(src.file, src.line),
                hint=hint,
            ),
            Problem(f"while loading robot {robot.name!r}", doc.locate(("robots", i)), ("robots", i)),
        ]
    )
