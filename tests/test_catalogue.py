"""The plugin catalogue (runner/compile/gazebo/catalogue.py): its page is generated from it, and the readers
take each plugin's parameters from it."""

from __future__ import annotations

from pathlib import Path

from runner.compile.gazebo.catalogue import CATALOGUE, render

DOC = Path(__file__).parents[1] / "docs" / "plugin_catalogue.md"
REGENERATE = (
    "python -c \"from runner.compile.gazebo.catalogue import render; print(render(), end='')\" "
    "> docs/plugin_catalogue.md"
)


def test_the_catalogue_page_is_generated_from_the_table() -> None:
    assert DOC.read_text() == render(), f"docs/plugin_catalogue.md is stale: {REGENERATE}"


def test_every_plugin_is_catalogued_once_with_its_parameters_spelled_once() -> None:
    bases = [b for e in CATALOGUE for b in e.bases]
    assert len(bases) == len(set(bases))
    for e in CATALOGUE:
        names = [n for p in e.params for n in p.names]
        assert len(names) == len(set(names)), e.bases
        assert all(p.how for p in e.params if p.status != "same"), f"{e.bases}: say how or why"
