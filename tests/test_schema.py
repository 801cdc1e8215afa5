from __future__ import annotations

from runner.jsonschema import render
from runner.schema import Scenario
from tests.conftest import REPO


def test_committed_json_schema_is_current():
    committed = (REPO / "schemas" / "scenario.schema.json").read_text()
    assert committed == render(), "schemas/scenario.schema.json is stale: run `scenario schema`"


def test_every_field_is_described():
    missing = []

    def walk(model: type) -> None:
        for name, f in model.model_fields.items():
            if not f.description and name != "rate":
                missing.append(f"{model.__name__}.{name}")
            for sub in _models(f.annotation):
                walk(sub)

    walk(Scenario)
    assert not missing, missing


def _models(tp):  # type: ignore[no-untyped-def]
    from typing import get_args

    from pydantic import BaseModel

    if isinstance(tp, type) and issubclass(tp, BaseModel):
        yield tp
    for a in get_args(tp):
        yield from _models(a)


def test_rate_is_described_in_schema():
    schema = Scenario.model_json_schema()
    assert "real-time factor" in schema["properties"]["rate"]["description"]
