"""Assertions: compile-time checks and wiring (here), the judge (`judge.py`), safe expressions (`expr/`).
Their results as JUnit XML are written by `runner.tools.report`."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from runner.errors import Location, Problem, ScenarioError, did_you_mean
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import MessageCheck, NoCollision, Scenario, TopicRate

_OWN_NAME = "give each a `name:` of its own (results and events name assertions by it)"
POSE_KINDS = ("reach", "stay_within", "max_speed", "max_tilt", "distance_traveled")


def truth_robots(sc: Scenario) -> set[str]:
    """Robots whose true pose some assertion reads."""
    return {a.robot for a in sc.assertions if a.type in POSE_KINDS}  # type: ignore[union-attr]


def check_names(sc: Scenario, doc: Document, model_names: set[str], has_sdf: bool) -> None:
    robots = {r.name for r in sc.robots}
    problems: list[Problem] = []
    names: set[str] = set()
    for i, a in enumerate(sc.assertions):
        if a.name in names:
            where: PathKey = ("assertions", i, "name")
            problems.append(
                Problem(f"two assertions named {a.name!r}", doc.locate(where), where, hint=_OWN_NAME)
            )
        names.add(a.name)
        if a.type in POSE_KINDS and a.robot not in robots:  # type: ignore[union-attr]
            where = ("assertions", i, "robot")
            problems.append(
                Problem(
                    f"no robot named {a.robot!r}",  # type: ignore[union-attr]
                    doc.locate(where),
                    where,
                    expected="one of: " + ", ".join(sorted(robots)) if robots else "a robot of this scenario",
                    hint=did_you_mean(a.robot, robots, "robots"),  # type: ignore[union-attr]
                )
            )
        if isinstance(a, NoCollision) and not has_sdf:
            known = robots | model_names | {"ground"}
            for j, n in enumerate(a.between):
                if n not in known:
                    where = ("assertions", i, "between", j)
                    problems.append(
                        Problem(
                            f"no robot or model named {n!r}",
                            doc.locate(where),
                            where,
                            expected="one of: " + ", ".join(sorted(known)),
                            hint=did_you_mean(n, known, "robots and models"),
                        )
                    )
    if problems:
        raise ScenarioError(problems)


def assertion_keys(
    sc: Scenario, doc: Document, topics: dict[str, str], unchecked: Sequence[str] = ()
) -> list[str]:
    """The key each assertion reads; topics and expressions checked against the plan (`topics`: key ->
    type of every published topic). Topics under an `unchecked` prefix (a robot that failed to load, its
    mistakes already reported) are not said to be missing; their expressions are checked for syntax."""
    from runner.checks.expr import ExprError, check_fields, compile_expr
    from runner.checks.judge import contacts_key, truth_key

    ns = {r.name: r.ns for r in sc.robots}
    keys: list[str] = []
    problems: list[Problem] = []
    for i, a in enumerate(sc.assertions):
        if a.type in POSE_KINDS:
            # (a robot the scenario does not have is check_names' to report)
            keys.append(truth_key(sc.name, ns.get(a.robot, a.robot)))  # type: ignore[union-attr,arg-type]
            continue
        if isinstance(a, NoCollision):
            keys.append(contacts_key(sc.name))
            continue
        assert isinstance(a, TopicRate | MessageCheck)
        key = f"{sc.name}/{a.topic.strip('/')}"
        keys.append(key)
        if key not in topics and any(key.startswith(p) for p in unchecked):
            if isinstance(a, MessageCheck):
                try:
                    compile_expr(a.expr)
                except ExprError as e:
                    problems.append(_expr_problem(a.expr, e, doc, ("assertions", i, "expr")))
            continue
        if key not in topics:
            where: PathKey = ("assertions", i, "topic")
            problems.append(
                Problem(
                    f"no topic {a.topic!r} is published in this scenario",
                    doc.locate(where),
                    where,
                    hint=did_you_mean(a.topic.strip("/"), (k.split("/", 1)[1] for k in topics), "topics"),
                )
            )
            continue
        if isinstance(a, MessageCheck):
            where = ("assertions", i, "expr")
            try:
                check_fields(compile_expr(a.expr), topics[key])
            except ExprError as e:
                problems.append(_expr_problem(a.expr, e, doc, where))
    if problems:
        raise ScenarioError(problems)
    return keys


def _expr_problem(expr: str, e: Exception, doc: Document, where: PathKey) -> Problem:
    loc = doc.locate(where)
    column = getattr(e, "column", None)
    return Problem(
        f"in `{expr}`" + (f" (column {column})" if column else "") + f": {getattr(e, 'message', e)}",
        Location(loc.file, loc.line, loc.column),
        where,
        hint=getattr(e, "hint", None) or _EXPR_HINT,
    )


# The hint of an expression error that has none of its own: what the language is made of.
_EXPR_HINT = (
    "an expression is one condition on the message's fields: field paths, numbers, strings, True/False, "
    "+ - * / %, < <= > >= == !=, and/or/not, abs len min max, .min() .max() .mean() .sum() .std()"
)


def specs_from_plan(raw: list[dict[str, Any]]) -> list[Any]:
    """The assertion models back from a RunPlan's plain data."""
    from pydantic import TypeAdapter

    from runner.scenario.schema import Assertion

    adapter: TypeAdapter[Any] = TypeAdapter(Assertion)
    return [adapter.validate_python(a) for a in raw]
