"""`events:` checked and resolved for the world: every name an event uses (bodies, regions, actors, topics,
plugins and their parameters, joints, assertions, other events) is looked up here, each mistake located
at its place in the file with what there is instead; then the events are put in the order the world looks
at them within a step (one that another one sets off in the same step comes after it), and a ring of
events that set each other off in the same step is refused.

What the world gets (`EventPlan.when` and `.do`) is plain data with every name resolved: MuJoCo body and
joint names, full Zenoh keys, indices of actors, plugins and assertions (runner.sim.events plays them)."""

from __future__ import annotations

import heapq
from dataclasses import dataclass, field
from typing import Any

import mujoco

from runner.compile.nodes import declared_topics
from runner.compile.timeline import message_of, service_of, service_types
from runner.errors import Problem, Problems, ScenarioError, closest, did_you_mean
from runner.geometry import rpy_to_quat
from runner.plan import ActorPlan, EventPlan, RobotPlan, ServicePlan
from runner.plugin.registry import load
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import Action, Event, Scenario
from runner.wire import interfaces, msgs


def _choices(names: list[str] | set[str], what: str) -> str:
    names = sorted(names)
    return f"one of: {', '.join(names)}" if names else f"no {what} in this scenario"


@dataclass
class _World:
    """What the events of one world may name."""

    sc: Scenario
    doc: Document
    model: mujoco.MjModel
    robots: list[RobotPlan]
    actors: list[ActorPlan]
    published: dict[str, str]  # key -> type of what the world publishes (plugins, timeline, events)
    taken: dict[str, str]  # key -> type of what the world's plugins subscribe (from nodes...)
    heard: dict[str, str]  # key -> type of what nodes say they publish (`publishes:`): message triggers
    assertions: list[str] = field(default_factory=list)
    services: dict[str, str] = field(default_factory=dict)  # key -> type of the services a `call` may name

    def key(self, topic: str) -> str:
        return f"{self.sc.name}/{topic.strip('/')}"

    def bodies(self) -> list[str]:
        robots = [r.name for r in self.robots]
        return robots + [a.name for a in self.actors] + [m.name for m in self.sc.world.models]

    def ref(self, name: str, where: PathKey, *, moving: bool = False) -> dict[str, Any]:
        """A body by the scenario's name: a robot (its root body), an actor, a world model (body or, for a
        static one, geom), or a body of the world file by its MuJoCo name."""
        m = self.model
        for r in self.robots:
            if r.name == name:
                body = f"{r.prefix}{r.root}"
                if moving and r.fixed:
                    raise self.problem(
                        f"robot {name!r} is fixed to the world: it cannot be moved",
                        where,
                        hint="move a robot without `fixed: true` (and whose description has no root link "
                        "`world`), or a model that is not static",
                    )
                return {"name": name, "body": body, "free": not r.fixed}
        for a in self.actors:
            if a.name == name:
                return {"name": name, "body": name, "actor": self.actors.index(a)}
        bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
        if bid > 0:
            free = int(m.body_jntnum[bid]) == 1 and int(m.jnt_type[m.body_jntadr[bid]]) == 0
            if moving and not free:
                raise self.problem(
                    f"{name!r} is not free to move (it has no free joint)",
                    where,
                    hint="move a robot, or a world-file model that is not static (a free body)",
                )
            return {"name": name, "body": name, "free": free}
        gid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, name)
        if gid >= 0 and not moving:
            return {"name": name, "geom": name}
        if gid >= 0:
            raise self.problem(
                f"{name!r} is a static model: it cannot be moved",
                where,
                hint="set `static: false` on the model to make it free, or move a robot",
            )
        raise self.problem(
            f"no robot, actor or model named {name!r}",
            where,
            expected=_choices(self.bodies(), "robots, actors or models"),
            found=name,
            hint=(f"did you mean {near!r}? " if (near := closest(name, self.bodies())) else "")
            + "a name of `robots:`, `world.actors` or `world.models` (or a body of the world file)",
        )

    def problem(self, message: str, where: PathKey, **kw: Any) -> ScenarioError:
        return ScenarioError(Problem(message, self.doc.locate(where), where, **kw))

    def region(self, value: Any, where: PathKey) -> dict[str, Any]:
        if isinstance(value, str):
            if value not in self.sc.regions:
                raise self.problem(
                    f"no region named {value!r}",
                    where,
                    expected=_choices(set(self.sc.regions), "regions (`regions:`)"),
                    hint=(f"did you mean {near!r}? " if (near := closest(value, self.sc.regions)) else "")
                    + "name it under `regions:` or give it here: {min: [x, y], max: [x, y]}",
                )
            value = self.sc.regions[value]
        return value.model_dump(exclude_none=True)  # type: ignore[no-any-return]

    def topic_type(self, topic: str, where: PathKey, *, published: bool) -> tuple[str, str]:
        """(key, type) of a topic the world publishes (or, unless `published`, also takes in)."""
        key = self.key(topic)
        known = dict(self.published) if published else {**self.heard, **self.taken, **self.published}
        if key in known:
            return key, known[key]
        what = "the world publishes" if published else "the world or a node publishes, or the world takes in"
        names = sorted(k.split("/", 1)[1] for k in known)
        hint = (
            "faults and message triggers work on the topics of the world's plugins (sensors, odometry), "
            "its timeline and events, and those its plugins take in (cmd_vel); message triggers also on "
            "those a node declares (`publishes:`)"
        )
        if published and key in self.heard:
            hint = "a node publishes it: the world can put a fault only on what it publishes itself"
        elif (near := closest(topic.strip("/"), names)) is not None:
            hint = f"did you mean {near!r}?"
        raise self.problem(
            f"no topic {topic!r} that {what}",
            where,
            expected=", ".join(names[:12]) + (" ..." if len(names) > 12 else ""),
            found=topic,
            hint=hint,
        )


def compile_events(
    sc: Scenario,
    doc: Document,
    mjcf: str,
    robots: list[RobotPlan],
    actors: list[ActorPlan],
    problems: Problems,
    world_services: list[ServicePlan] | None = None,
) -> list[EventPlan]:
    """Every event checked (each on its own: its mistakes to `problems`), in the order a step plays them.
    A `call` names one of `world_services` or a plugin's service."""
    if not sc.events or not mjcf:
        return []
    model = mujoco.MjModel.from_xml_string(mjcf)
    published = {t.key: t.type for r in robots for p in r.plugins for t in p.topics if t.direction == "pub"}
    published.update(
        {
            f"{sc.name}/{e.topic.strip('/')}": msgs.normalize_type(e.type)
            for e in sc.timeline
            if e.topic is not None and e.type is not None
        }
    )
    for ev in sc.events:
        for act in ev.do:
            if act.publish is not None:
                published[f"{sc.name}/{act.publish.topic.strip('/')}"] = msgs.normalize_type(act.publish.type)
    taken = {t.key: t.type for r in robots for p in r.plugins for t in p.topics if t.direction == "sub"}
    heard = {k: t for k, t in declared_topics(sc).items() if t is not None}
    w = _World(sc, doc, model, robots, actors, published, taken, heard, [a.name for a in sc.assertions])
    w.services = service_types(world_services or [], robots)
    names = [e.name for e in sc.events]
    out: list[EventPlan | None] = []
    for i, ev in enumerate(sc.events):
        here: PathKey = ("events", i)
        if names.index(ev.name) != i:
            problems.add(
                Problem(
                    f"two events named {ev.name!r}",
                    doc.locate((*here, "name")),
                    (*here, "name"),
                    hint="give each a `name:` of its own (`after:` and the report name events by it)",
                )
            )
        plan: EventPlan | None = None
        with problems.each():
            plan = _event(w, ev, here, names)
        out.append(plan)
    if problems:
        return []
    ready = [p for p in out if p is not None]
    return _ordered(ready, sc, doc)


def _event(w: _World, ev: Event, here: PathKey, names: list[str]) -> EventPlan:
    """One event resolved; a mistake in its trigger and ones in its actions are reported together."""
    found: list[Problem] = []
    when: dict[str, Any] = {}
    do: list[dict[str, Any]] = []
    try:
        when = _when(w, ev, here, names)
    except ScenarioError as e:
        found += e.problems
    try:
        do = _actions(w, ev, here)
    except ScenarioError as e:
        found += e.problems
    if found:
        raise ScenarioError(found)
    return EventPlan(name=ev.name, when=when, do=do, repeat=ev.repeat)


def _when(w: _World, ev: Event, here: PathKey, names: list[str]) -> dict[str, Any]:
    when = ev.when
    at: PathKey = (*here, "when", when.kind)
    if when.at is not None:
        return {"kind": "at", "t_ns": round(when.at * 1e9)}
    if when.enter is not None or when.leave is not None:
        place = when.enter or when.leave
        assert place is not None
        problems: list[Problem] = []
        body = region = None
        try:
            body = w.ref(place.body, (*at, "body"))
        except ScenarioError as e:
            problems += e.problems
        try:
            region = w.region(place.region, (*at, "region"))
        except ScenarioError as e:
            problems += e.problems
        if problems:
            raise ScenarioError(problems)
        label = place.region if isinstance(place.region, str) else "the region"
        return {"kind": when.kind, "body": body, "region": region, "label": label}
    if when.near is not None:
        near = when.near
        body = w.ref(near.body, (*at, "body"))
        to: Any = list(near.to[:2]) if isinstance(near.to, list) else w.ref(near.to, (*at, "to"))
        return {"kind": "near", "body": body, "to": to, "within": near.within}
    if when.message is not None:
        return _on_message(w, ev, at)
    if when.after is not None:
        if when.after.event not in names:
            raise w.problem(
                f"no event named {when.after.event!r}",
                (*at, "event"),
                expected=_choices([n for n in names if n != ev.name], "other events"),
                hint=did_you_mean(when.after.event, [n for n in names if n != ev.name], "other events"),
            )
        if when.after.event == ev.name:
            raise w.problem("an event cannot follow itself", (*at, "event"), hint="use `repeat: true`")
        return {"kind": "after", "event": when.after.event, "delay_ns": round(when.after.delay * 1e9)}
    assert when.assertion is not None
    name = when.assertion.assertion
    if name not in w.assertions:
        raise w.problem(
            f"no assertion named {name!r}",
            (*at, "assertion"),
            expected=_choices(w.assertions, "assertions"),
            hint=did_you_mean(name, w.assertions, "assertions"),
        )
    return {
        "kind": "assertion",
        "index": w.assertions.index(name),
        "name": name,
        "becomes": when.assertion.becomes,
    }


def _on_message(w: _World, ev: Event, at: PathKey) -> dict[str, Any]:
    from runner.checks import _expr_problem
    from runner.checks.expr import ExprError, check_fields, compile_expr

    m = ev.when.message
    assert m is not None
    key, type_name = w.topic_type(m.topic, (*at, "topic"), published=False)
    try:
        check_fields(compile_expr(m.expr), type_name)
    except ExprError as e:
        raise ScenarioError(_expr_problem(m.expr, e, w.doc, (*at, "expr"))) from None
    return {"kind": "message", "key": key, "type": type_name, "expr": m.expr, "topic": m.topic}


def _actions(w: _World, ev: Event, here: PathKey) -> list[dict[str, Any]]:
    out, problems = [], []
    for j, act in enumerate(ev.do):
        try:
            out.append(_action(w, act, (*here, "do", j, act.kind)))
        except ScenarioError as e:
            problems += e.problems
    if problems:
        raise ScenarioError(problems)
    return out


def _action(w: _World, act: Action, at: PathKey) -> dict[str, Any]:
    kind = act.kind
    if act.publish is not None:
        return _publish(w, act, at)
    if act.start is not None or act.stop is not None:
        name = act.start or act.stop
        names = [a.name for a in w.actors]
        if name not in names:
            raise w.problem(
                f"no actor named {name!r}",
                at,
                expected=_choices(names, "actors (`world.actors`)"),
                hint=did_you_mean(name, names, "actors (`world.actors`)"),
            )
        return {"kind": kind, "actor": names.index(name), "name": name}
    if act.teleport is not None:
        target = w.ref(act.teleport.body, (*at, "body"), moving=True)
        pose = act.teleport.pose
        return {"kind": kind, "target": target, "pos": list(pose.xyz), "quat": list(rpy_to_quat(pose.rpy))}
    if act.push is not None or act.impulse is not None:
        body = (act.push or act.impulse).body  # type: ignore[union-attr]
        target = w.ref(body, (*at, "body"), moving=True)
        if "actor" in target:
            raise w.problem(
                f"{body!r} is an actor: it goes where its path says, forces do not move it",
                (*at, "body"),
                hint="`teleport` or `stop` an actor; push a robot or a free model",
            )
        if act.push is not None:
            p = act.push
            return {
                "kind": kind,
                "target": target,
                "force": list(p.force),
                "torque": list(p.torque),
                "duration_ns": round(p.duration * 1e9),
            }
        return {"kind": kind, "target": target, "linear": list(act.impulse.linear)}  # type: ignore[union-attr]
    if act.set is not None:
        return _set_param(w, act, at)
    if act.fault is not None:
        f = act.fault
        key, type_name = w.topic_type(f.topic, (*at, "topic"), published=True)
        if f.fields is not None:
            _check_noise_fields(w, f.fields, type_name, (*at, "fields"))
        drop = 1.0 if f.drop is True else f.drop
        return {
            "kind": kind,
            "key": key,
            "type": type_name,
            "topic": f.topic,
            "drop": drop,
            "delay_ns": round(f.delay * 1e9) if f.delay else 0,
            "freeze": f.freeze,
            "noise": f.noise,
            "fields": f.fields,
            "duration_ns": round(f.duration * 1e9) if f.duration else None,
        }
    if act.block is not None or act.cut is not None:
        return _joint(w, act, at)
    if act.call is not None:
        key, srv = service_of(w.sc, w.doc, act.call.service, w.services, (*at, "service"))
        message_of(interfaces.service_type(srv).request, act.call.data, w.doc, at)
        return {"kind": "call", "key": key, "type": srv, "data": act.call.data, "service": act.call.service}
    assert act.end is not None
    return {"kind": "end", "result": act.end.result, "message": act.end.message}


def _publish(w: _World, act: Action, at: PathKey) -> dict[str, Any]:
    p = act.publish
    assert p is not None
    type_name = message_of(p.type, p.data, w.doc, at)
    key = w.key(p.topic)
    wanted = w.taken.get(key)
    if wanted is not None and msgs.normalize_type(wanted) != type_name:
        raise w.problem(
            f"{p.topic} is taken by the world as {wanted}",
            (*at, "type"),
            expected=wanted,
            found=type_name,
            hint=f"publish a {wanted} there",
        )
    return {"kind": "publish", "key": key, "type": type_name, "data": p.data}


def _set_param(w: _World, act: Action, at: PathKey) -> dict[str, Any]:
    s = act.set
    assert s is not None
    robots = [r.name for r in w.robots]
    if s.robot not in robots:
        raise w.problem(
            f"no robot named {s.robot!r}",
            (*at, "robot"),
            expected=_choices(robots, "robots"),
            hint=did_you_mean(s.robot, robots, "robots"),
        )
    index = sum(len(r.plugins) for r in w.robots[: robots.index(s.robot)])
    robot = w.robots[robots.index(s.robot)]
    plugins = [p.name for p in robot.plugins]
    if s.plugin not in plugins:
        raise w.problem(
            f"robot {s.robot!r} has no plugin named {s.plugin!r}",
            (*at, "plugin"),
            expected=_choices(plugins, "plugins"),
            hint=did_you_mean(s.plugin, plugins, f"plugins of {s.robot!r}"),
        )
    pp = robot.plugins[plugins.index(s.plugin)]
    cls = load(pp.type)
    live = sorted({"rate", *cls.live}) if pp.rate else sorted(cls.live)
    if s.param not in live:
        raise w.problem(
            f"{s.param!r} of the {pp.type} plugin cannot change while it runs",
            (*at, "param"),
            expected=_choices(live, "live parameters"),
            found=s.param,
            hint="a parameter that shapes the model (a link, a size) is fixed once compiled",
        )
    from pydantic import ValidationError

    try:
        cls.Params.model_validate({**pp.params, s.param: s.value})
    except ValidationError as e:
        first = e.errors()[0]
        raise w.problem(
            f"{s.param}: {first['msg']}",
            (*at, "value"),
            found=repr(s.value),
            hint=f"give a value the {pp.type} plugin's `{s.param}` takes, as in its `params:`",
        ) from None
    return {
        "kind": "set",
        "plugin": index + plugins.index(s.plugin),
        "param": s.param,
        "value": s.value,
        "label": f"{s.robot}/{s.plugin}.{s.param}",
    }


def _check_noise_fields(w: _World, fields: list[str], type_name: str, where: PathKey) -> None:
    from runner.checks.expr import ExprError, check_fields, compile_expr

    for k, name in enumerate(fields):
        try:
            check_fields(compile_expr(f"{name} == {name}"), type_name)
        except ExprError as e:
            raise w.problem(
                f"{type_name} has no field {name!r}: {getattr(e, 'message', e)}",
                (*where, k),
                hint=e.hint or "a field path of the message, such as pose.pose.position.x",
            ) from None


def _joint(w: _World, act: Action, at: PathKey) -> dict[str, Any]:
    ref = act.block or act.cut
    assert ref is not None
    robots = {r.name: r for r in w.robots}
    robot = robots.get(ref.robot)
    if robot is None:
        raise w.problem(
            f"no robot named {ref.robot!r}",
            (*at, "robot"),
            expected=_choices(set(robots), "robots"),
            hint=did_you_mean(ref.robot, robots, "robots"),
        )
    if ref.joint not in robot.joints:
        raise w.problem(
            f"robot {ref.robot!r} has no joint {ref.joint!r}",
            (*at, "joint"),
            expected=_choices(robot.joints, "joints"),
            hint=did_you_mean(ref.joint, robot.joints, f"joints of {ref.robot!r}"),
        )
    name = f"{robot.prefix}{ref.joint}"
    jid = mujoco.mj_name2id(w.model, mujoco.mjtObj.mjOBJ_JOINT, name)
    if jid < 0 or int(w.model.jnt_type[jid]) not in (2, 3):  # slide, hinge
        raise w.problem(
            f"{ref.joint!r} is not a moving joint of the simulated robot",
            (*at, "joint"),
            hint="name a revolute, continuous or prismatic joint (fixed joints are merged away)",
        )
    if act.cut is not None:
        m = w.model
        driven = [
            a for a in range(m.nu) if int(m.actuator_trntype[a]) == 0 and int(m.actuator_trnid[a, 0]) == jid
        ]
        if not driven:
            raise w.problem(
                f"no motor drives joint {ref.joint!r} of robot {ref.robot!r}",
                (*at, "joint"),
                hint="`cut` acts on a joint a drive or controller plugin moves; `block` jams any joint",
            )
    return {"kind": act.kind, "joint": name, "label": f"{ref.robot}/{ref.joint}"}


def _ordered(events: list[EventPlan], sc: Scenario, doc: Document) -> list[EventPlan]:
    """Events in the order a step looks at them: file order, except that one set off in the same step by
    another (`after` without delay, or a message trigger on a topic the other publishes) comes after it.
    A ring of such events would set itself off forever in one step: refused."""
    n = len(events)
    index = {e.name: i for i, e in enumerate(events)}
    publishes = [{a["key"] for a in e.do if a["kind"] == "publish"} for e in events]
    edges: list[set[int]] = [set() for _ in range(n)]
    for j, e in enumerate(events):
        when = e.when
        if when["kind"] == "after" and when["delay_ns"] == 0:
            edges[index[when["event"]]].add(j)
        if when["kind"] == "message":
            for i in range(n):
                if when["key"] in publishes[i]:
                    edges[i].add(j)
    indeg = [0] * n
    for i in range(n):
        for j in edges[i]:
            indeg[j] += 1
    ready = [i for i in range(n) if indeg[i] == 0]
    heapq.heapify(ready)
    order: list[int] = []
    while ready:
        i = heapq.heappop(ready)
        order.append(i)
        for j in sorted(edges[i]):
            indeg[j] -= 1
            if indeg[j] == 0:
                heapq.heappush(ready, j)
    if len(order) < n:
        ring = _ring(edges, [i for i in range(n) if i not in order])
        names = [events[i].name for i in ring]
        where: PathKey = ("events", [e.name for e in sc.events].index(names[0]), "when")
        raise ScenarioError(
            Problem(
                "events that set each other off in the same step: " + " -> ".join([*names, names[0]]),
                doc.locate(where),
                where,
                hint="give one of them a `delay:` (`after: {event: ..., delay: 0.1}`), or drop one link",
            )
        )
    return [events[i] for i in order]


def _ring(edges: list[set[int]], left: list[int]) -> list[int]:
    """One cycle among the events `left` (those a topological sort could not place: each is set off by
    another of them, so walking back from one always finds one, and comes round)."""
    inside = set(left)
    back = {j: min(i for i in inside if j in edges[i]) for j in inside}
    path, seen = [left[0]], {left[0]: 0}
    while True:
        prev = back[path[-1]]
        if prev in seen:
            return path[seen[prev] :][::-1]
        seen[prev] = len(path)
        path.append(prev)
