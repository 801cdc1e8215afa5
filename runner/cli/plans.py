"""A scenario file as the commands get it: its matrix variants compiled to plans (`load_variants`) and
`--strict`, which makes the scenario's own warnings errors (runner.cli.notices prints the warnings)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from runner.cli.console import err


def load_variants(file: Path, record: str | None, variant: int | None) -> list[tuple[str, Any]]:
    """[(label, plan)] of the scenario's matrix variants (one, unlabelled, without a matrix). Values drawn at
    random are in the plans (`plan.drawn`), their poses placed free of collisions, and in the labels."""
    from runner.compile.placement import load_drawn_plan
    from runner.scenario.loader import load_file
    from runner.scenario.matrix import variants

    found = variants(load_file(file))
    if variant is not None:
        if not 0 <= variant < len(found):
            raise typer.BadParameter(f"the scenario has {len(found)} variant(s): 0..{len(found) - 1}")
        found = [found[variant]]
    out = []
    for label, doc in found:
        plan = load_drawn_plan(doc, record_path=record)
        out.append((plan.variant or label, plan))
    return out


def drawn_line(plan: Any) -> str:
    """`drawn: path=value,...` for a run that drew values without a matrix ("" otherwise: a variant's label
    shows them)."""
    if not plan.drawn or plan.variant:
        return ""
    from runner.scenario.draws import shown

    return "drawn: " + shown(plan.drawn)


def strict_failure(plan: Any) -> None:
    """With --strict: the scenario's own warnings are errors (exit 1)."""
    if plan.scenario_warnings:
        for text in plan.scenario_warnings:
            err.print("error: " + text, markup=False, style="red")
        err.print(
            f"--strict: {len(plan.scenario_warnings)} warning(s) about the scenario are errors",
            markup=False,
            style="red",
        )
        raise typer.Exit(1)
