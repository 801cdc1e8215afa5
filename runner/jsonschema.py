"""The JSON Schema of the scenario format, generated from the pydantic models (never edited by hand)."""

from __future__ import annotations

import json

from runner.schema import Scenario


def render() -> str:
    schema = Scenario.model_json_schema()
    return json.dumps(schema, indent=2, sort_keys=False) + "\n"
