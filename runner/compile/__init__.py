"""compile: Scenario -> RunPlan. The one place where files on disk become a model.

Everything that touches disk or other formats happens here, and fails early with the line in the
scenario that caused it: xacro, URDF, plugin parameters, message data in the timeline, record paths.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from runner.compile.network import check_exposure, check_expr, full_expr, zenoh_settings
from runner.compile.record import check_record_patterns
from runner.compile.sanity import check_vacuous, window_edge
from runner.compile.world import compile_world
from runner.compile.worlds import compile_worlds
from runner.errors import Notices, Problems
from runner.plan import FoxglovePlan, NoticePlan, RunPlan
from runner.scenario.loader import Document, MappedDocument, PathKey
from runner.scenario.schema import Scenario

__all__ = ["compile_plan", "load_plan", "window_edge"]


def load_plan(doc: Document, *, record_path: str | None = None, notices: Notices | None = None) -> RunPlan:
    """A document checked and compiled in one pass that reports every independent mistake at once, in the
    file's order: the schema's, the cross-field rules', and compile's (robots, plugins and their
    parameters, timeline data, expressions, bridges, nodes...). Where the schema refuses part of the
    file, that part is taken out (`runner.scenario.validate.prune`) and the rest is checked all the same; what
    follows from the part taken out (a reference to a robot that was taken out) is not reported."""
    from pydantic import ValidationError

    from runner.scenario.validate import check_document, problems_from_validation, prune

    check_document(doc)
    problems = Problems(doc.file)
    stopped: str | None = None  # why the checks stopped early, if they did
    try:
        sc = Scenario.model_validate(doc.data)
    except ValidationError as err:
        problems.add(problems_from_validation(err, doc.data, doc, Scenario))
        found = prune(Scenario, doc.data)
        if found is None:
            stopped = "the rest of the file is checked once these are fixed"
        else:
            rest, pruned = found
            view = _PrunedView(data=pruned.data, file=doc.file, positions=doc.positions, pruned=pruned)
            later = Problems(doc.file)
            _, stopped = _check_and_compile(rest, view, later, record_path, notices)  # type: ignore[arg-type]
            # a name in the messages' own quoting: 'r2', 'r2/odom', r2/odom, a/r2/b
            names = [re.compile(rf"(?:^|['/ ]){re.escape(n)}(?:$|['/])") for n in pruned.names]
            for group in later.groups:
                if any(n.search(p.message) for p in group for n in names):
                    continue  # about something taken out (a robot the schema refused)
                for p in group:
                    p.path = view.map_path(p.path)
                problems.add(group)
        plan = None
    else:
        plan, stopped = _check_and_compile(sc, doc, problems, record_path, notices)
    problems.raise_all(stopped)
    assert plan is not None  # (no problems: it compiled)
    return plan


@dataclass
class _PrunedView(MappedDocument):
    """The document as the second look at a file the schema refused sees it: the data with the refused
    parts taken out, located in the user's file."""

    pruned: Any = None

    def map_path(self, path: PathKey) -> PathKey:
        return self.pruned.original(path)  # type: ignore[no-any-return]


def _check_and_compile(
    sc: Scenario, doc: Document, problems: Problems, record_path: str | None, notices: Notices | None
) -> tuple[RunPlan | None, str | None]:
    """(the plan or None, why the checks stopped early or None); the problems found go to `problems`.
    Two robots or models of one name stop them before compile: compiling those would only add noise."""
    from runner.scenario.validate import consistency_problems

    rules = consistency_problems(sc, doc)
    problems.add(rules)
    if any(p.path[:1] in (("robots",), ("world",), ("worlds",)) for p in rules):
        return None, "robots, plugins, the timeline and the rest are checked once these are fixed"
    with problems.each():
        return compile_plan(sc, doc, record_path=record_path, notices=notices), None
    return None, None


def compile_plan(
    sc: Scenario, doc: Document, *, record_path: str | None = None, notices: Notices | None = None
) -> RunPlan:
    """The whole run: its world (or each of `worlds:`, compiled on its own), then what spans the run,
    once: the QoS, Foxglove and Zenoh settings every part carries, the bridges, and the checks over all
    of the run's topics and assertions."""
    notices = notices if notices is not None else Notices()
    problems = Problems(doc.file)
    unloaded: list[str] = []  # key prefixes of robots that did not load: their topics are not checked
    if sc.worlds:
        plan = compile_worlds(sc, doc, record_path, notices, problems, unloaded)
    else:
        plan = compile_world(sc, doc, record_path, notices, problems, unloaded)
    drop = None
    if sc.qos:
        drop = [full_expr(sc.name, q.topics) for q in sc.qos if q.reliability == "best_effort"]
        for i, q in enumerate(sc.qos):
            with problems.each():
                check_expr(full_expr(sc.name, q.topics), doc, ("qos", i, "topics"), q.topics)
    fox = FoxglovePlan(**sc.foxglove.model_dump())
    zenoh = None
    with problems.each():
        zenoh = zenoh_settings(sc, doc) if sc.zenoh is not None else None
    for part in plan.every_plan():
        if drop is not None:
            part.best_effort = drop
        part.foxglove = fox
        if sc.zenoh is not None:
            part.zenoh = zenoh
            part.listen = list(sc.zenoh.listen)
    if sc.bridges or sc.ros2 is not None:
        from runner.compile.bridges import attach_bridges

        with problems.each():
            attach_bridges(plan, sc, doc, unchecked=unloaded)
    problems.raise_all()  # every mistake found, in the order of the file
    check_record_patterns(plan, sc, doc, notices)
    check_exposure(sc, doc, notices)
    check_vacuous(plan, sc, doc, notices)
    plan.notices = [n.render() for n in notices]  # (with those of the checks over the whole run)
    plan.notice_items = [
        NoticePlan(
            message=n.message,
            file=str(n.location.file) if n.location.file is not None else None,
            line=n.location.line,
            hint=n.hint,
            kind=n.kind,
            about=n.about,
            text=n.render(),
        )
        for n in notices
    ]
    own = doc.file.resolve() if doc.file is not None else None
    plan.scenario_warnings = [
        n.render()
        for n in notices
        if own is not None and n.location.file is not None and Path(n.location.file).resolve() == own
    ]
    return plan
