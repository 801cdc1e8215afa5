"""The `record:` section: where the recording goes, its include/exclude patterns made full key
expressions and checked, and a notice for a pattern that matches none of the run's topics."""

from __future__ import annotations

from pathlib import Path

from runner.checks.judge import contacts_key
from runner.compile.network import check_expr, full_expr
from runner.errors import Notices, Problem, ScenarioError
from runner.plan import RecordPlan, RunPlan
from runner.scenario.loader import Document, PathKey
from runner.scenario.schema import Record, Scenario
from runner.wire.transport import hidden_topic, topic_key


def record_plan(sc: Scenario, doc: Document, record_path: str | None) -> RecordPlan:
    rec = sc.record
    if record_path is not None:
        path = Path(record_path)
    elif rec.path is not None:
        path = doc.base_dir / rec.path
        if rec.path.endswith(("/", "\\")) or path.is_dir():  # a folder: the recording goes in it
            path = path / f"{sc.name}.mcap"
    else:
        path = Path("runs") / f"{sc.name}.mcap"
    if rec.enabled and rec.path is not None and record_path is None:
        _check_writable(path, doc)
    record = RecordPlan(
        enabled=rec.enabled,
        path=str(path),
        include=[full_expr(sc.name, e) for e in rec.include],
        exclude=[full_expr(sc.name, e) for e in rec.exclude],
        compression=rec.compression,
    )
    _check_key_exprs(record, doc, rec)
    return record


def _check_writable(path: Path, doc: Document) -> None:
    """The recording can be made where `record.path` says: the file, if it is there, can be written, and
    its folder can be made in the nearest folder that exists. Checked with `os.access` (nothing is
    written, `validate` leaves no trace), so that a path the run would refuse at its start is said at its
    line now."""
    import os

    where: PathKey = ("record", "path")
    problem = None
    if path.exists() and not path.is_file():
        problem = ("is not a file", "give a file name ending in .mcap, or a folder ending in '/'")
    elif path.is_file():
        if not os.access(path, os.W_OK):
            problem = ("cannot be written (no permission)", "choose another file, or change its permissions")
    else:
        ancestor = path.parent
        while not ancestor.exists() and ancestor != ancestor.parent:
            ancestor = ancestor.parent
        if not ancestor.is_dir():
            problem = (
                f"cannot be made: {str(ancestor)!r} is a file, not a folder",
                "choose a path whose folders are folders (or can be made)",
            )
        elif not os.access(ancestor, os.W_OK | os.X_OK):
            made = "" if ancestor == path.parent else f" (to make {str(path.parent)!r})"
            problem = (
                f"cannot be written: no permission to write in {str(ancestor)!r}{made}",
                "choose a folder you can write to, or record with `scenario run --record PATH`",
            )
    if problem is not None:
        what, hint = problem
        raise ScenarioError(
            Problem(
                f"the recording {str(path)!r} {what}", doc.locate(where), where, found=str(path), hint=hint
            )
        )


def _check_key_exprs(record: RecordPlan, doc: Document, given: Record | None = None) -> None:
    """Every include/exclude pattern is a key expression; errors show the pattern as the user wrote it
    (`given`), not with the run's name in front."""
    for field_name, exprs in (("include", record.include), ("exclude", record.exclude)):
        written = list(getattr(given, field_name)) if given is not None else exprs
        for j, e in enumerate(exprs):
            check_expr(e, doc, ("record", field_name, j), written[j])


def check_record_patterns(plan: RunPlan, sc: Scenario, doc: Document, notices: Notices) -> None:
    """A `record.exclude` (or `include`) pattern that matches none of the run's topics is most likely a
    typo, and a costly one (the camera images it was meant to leave out fill the disk): say so."""
    import zenoh

    rec = plan.record
    if not rec.enabled:
        return
    keys = set()
    for part in plan.every_plan():
        keys |= {t.key for t in part.topics()}  # plugins' (the judge's _truth too), timeline's, clock
        # what the world publishes besides (runner.sim.scene, the contacts judge, the launcher's plan)
        keys |= {f"{part.name}/{k}" for k in ("scene", "tf", "tf_static", "_model", "_state", "_plan")}
        keys |= {topic_key(part.name, r.namespace, "robot_description") for r in part.robots}
        keys.add(contacts_key(part.name))
    known = [zenoh.KeyExpr(k) for k in keys]
    nodes = " (or a node publishes it)" if plan.nodes else ""
    rels = (k[len(plan.name) + 1 :] for k in keys)
    sample = ", ".join(sorted(rel for rel in rels if not hidden_topic(rel))[:6])
    for field_name, written, full in (
        ("exclude", sc.record.exclude, rec.exclude),
        ("include", sc.record.include, rec.include),
    ):
        for i, (text, expr) in enumerate(zip(written, full, strict=True)):
            if any(zenoh.KeyExpr(expr).intersects(k) for k in known):
                continue
            where = doc.locate(("record", field_name, i))
            notices.add(
                f"record.{field_name}[{i}] {text!r} matches none of the run's topics{nodes}",
                where.file,
                where.line,
                hint=f"patterns are relative to the run, e.g. r1/camera/** or */camera/**; topics: {sample}",
            )
