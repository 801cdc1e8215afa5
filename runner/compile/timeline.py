"""The `timeline:`: each entry's message type and data checked against the message definitions, and its
type against the one its topic's subscriber takes."""

from __future__ import annotations

import difflib
from typing import Any

from runner.errors import Problem, Problems, ScenarioError
from runner.plan import RobotPlan, ServicePlan, TimelinePlan
from runner.scenario.loader import Document, PathKey, non_finite
from runner.scenario.schema import Scenario
from runner.wire import interfaces, msgs


def compile_timeline(
    sc: Scenario,
    doc: Document,
    robots: list[RobotPlan],
    problems: Problems,
    world_services: list[ServicePlan] | None = None,
) -> list[TimelinePlan]:
    """The timeline's entries checked (each on its own: its mistakes to `problems`), in time order. A
    `call` must name one of the world's services (`world_services`, the plugins' of `robots`)."""
    services = service_types(world_services or [], robots)
    ordered: list[tuple[int, TimelinePlan]] = []
    for i in range(len(sc.timeline)):
        with problems.each():
            entry = sc.timeline[i]
            plan = timeline_entry(sc, i, doc) if entry.call is None else call_entry(sc, i, doc, services)
            ordered.append((i, plan))
    with problems.each():
        check_timeline_types(ordered, robots, sc, doc)
    return sorted((ev for _, ev in ordered), key=lambda ev: ev.t_ns)


def message_type(type_text: str, doc: Document, where: PathKey) -> str:
    """A ROS 2 message type as written (`geometry_msgs/Twist`), normalized; unknown: a located error."""
    type_name = msgs.normalize_type(type_text)
    if not msgs.is_known(type_name):
        close = msgs.similar_types(type_text)
        raise ScenarioError(
            Problem(
                f"unknown message type {type_text!r}",
                doc.locate(where),
                where,
                expected="a ROS 2 message type such as geometry_msgs/msg/Twist",
                hint=f"did you mean {close[0]!r}?" if close else "write it as <package>/msg/<Name>",
            )
        )
    return type_name


def message_of(type_text: str, data: dict[str, Any], doc: Document, here: PathKey) -> str:
    """The type of a message given as `type` and `data` under `here` (a timeline entry, an event's
    `publish`), its data checked against the type's fields: each mistake located."""
    type_name = message_type(type_text, doc, (*here, "type"))
    try:
        msgs.check_data(type_name, data)
    except msgs.MessageDataError as e:
        where: PathKey = (*here, "data", *e.path)
        raise ScenarioError(
            Problem(str(e), doc.locate(where), where, hint=e.hint or _data_hint(str(e)))
        ) from None
    bad = non_finite(data)
    if bad is not None:
        # (YAML's .nan, .inf, -.inf: the plan's JSON would carry them as null, a silent 0.0 in the world,
        # and the world drops such a message from any other publisher)
        where = (*here, "data", *bad[0])
        raise ScenarioError(
            Problem(
                "a message field must be a finite number",
                doc.locate(where),
                where,
                expected="a finite number (within its type's range)",
                found=str(bad[1]),
                hint="a command of NaN or Inf cannot be obeyed: write the number meant (a large speed is "
                "limited by the robot's drive anyway)",
            )
        )
    return type_name


# What to write instead, by how msgs.from_data's message starts (its errors say what was found, not the fix).
_DATA_HINTS = {
    "expected a number": "write a plain number (SI units), without quotes",
    "expected an integer": "write a whole number, without quotes",
    "expected true or false": "write true or false, without quotes",
    "expected a string": "quote it: '...'",
    "expected a list": "write a list: [a, b, c]",
    "expected a mapping": "give the fields as a mapping: {x: 1.0, y: 0.0}",
}


def _data_hint(message: str) -> str:
    """A hint for a message-data error that has none of its own."""
    for start, hint in _DATA_HINTS.items():
        if message.startswith(start):
            return hint
    if "out of range" in message:
        return "give a value within the range"
    if "items, found" in message:
        return "give exactly as many items as the field holds"
    if "has no field" in message:
        return "remove it, or write one of the fields listed"
    return "each field takes the type of its message definition (`ros2 interface show <type>`)"


def timeline_entry(sc: Scenario, i: int, doc: Document) -> TimelinePlan:
    ev = sc.timeline[i]
    assert ev.topic is not None and ev.type is not None  # (TimelineEntry: a topic has a type)
    type_name = message_of(ev.type, ev.data, doc, ("timeline", i))
    topic = ev.topic
    key = f"{sc.name}/{topic.lstrip('/')}"
    return TimelinePlan(t_ns=round(ev.t * 1e9), key=key, type=type_name, data=ev.data)


def service_types(world_services: list[ServicePlan], robots: list[RobotPlan]) -> dict[str, str]:
    """Key -> type of every service a `call` may name: the world's own and its plugins' (not actions)."""
    plugins = [s for r in robots for p in r.plugins for s in p.services]
    return {s.key: s.type for s in [*world_services, *plugins] if s.kind == "service"}


def service_of(
    sc: Scenario, doc: Document, name: str, services: dict[str, str], where: PathKey
) -> tuple[str, str]:
    """(key, type) of the service `name` (`/reset_simulation`) of the world; else a located error."""
    key = f"{sc.name}/{name.lstrip('/')}"
    srv = services.get(key)
    if srv is None:
        names = sorted("/" + k.removeprefix(sc.name + "/") for k in services)
        close = difflib.get_close_matches("/" + name.lstrip("/"), names, n=1)
        raise ScenarioError(
            Problem(
                f"the world has no service {name!r}",
                doc.locate(where),
                where,
                expected="one of: " + ", ".join(names),
                hint=f"did you mean {close[0]!r}?" if close else "`scenario validate` lists the services",
            )
        )
    return key, srv


def call_entry(sc: Scenario, i: int, doc: Document, services: dict[str, str]) -> TimelinePlan:
    """A `call:` entry: the service (one of the world's), its request's fields checked."""
    ev = sc.timeline[i]
    assert ev.call is not None
    key, srv = service_of(sc, doc, ev.call, services, ("timeline", i, "call"))
    if ev.type is not None and interfaces.service_type(ev.type).name != srv:
        where: PathKey = ("timeline", i, "type")
        raise ScenarioError(
            Problem(
                f"{ev.call} is a {srv}",
                doc.locate(where),
                where,
                expected=srv,
                found=ev.type,
                hint="leave `type:` out: a call takes its service's type",
            )
        )
    message_of(interfaces.service_type(srv).request, ev.data, doc, ("timeline", i))
    return TimelinePlan(t_ns=round(ev.t * 1e9), key=key, type=srv, data=ev.data, call=True)


def check_timeline_types(
    timeline: list[tuple[int, TimelinePlan]], robots: list[RobotPlan], sc: Scenario, doc: Document
) -> None:
    """A timeline entry must carry the type its topic's subscriber takes: a `std_msgs/msg/String` on a
    drive's `cmd_vel` would reach the world (and a ROS client) as garbage."""
    takes = {
        t.key: (t.type, f"{p.type} {p.name!r} of robot {r.name!r}")
        for r in robots
        for p in r.plugins
        for t in p.topics
        if t.direction == "sub"
    }
    problems = []
    for i, ev in timeline:  # (the index in the scenario, the entry)
        wanted = takes.get(ev.key) if not ev.call else None
        if wanted is not None and msgs.normalize_type(wanted[0]) != ev.type:
            where: PathKey = ("timeline", i, "type")
            problems.append(
                Problem(
                    f"{sc.timeline[i].topic} is taken by {wanted[1]} as {wanted[0]}",
                    doc.locate(where),
                    where,
                    expected=wanted[0],
                    found=ev.type,
                    hint=f"write `type: {wanted[0]}` (and its fields under `data:`)",
                )
            )
    if problems:
        raise ScenarioError(problems)
