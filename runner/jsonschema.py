"""The JSON Schema of the scenario format, generated from the pydantic models (never edited by hand).

What pydantic writes is adjusted where it would disagree with the runner or with validators in their
strict modes (ajv, check-jsonschema): draft 2020-12 named; OpenAPI's `discriminator` keyword (unknown to
JSON Schema, refused by ajv's default strict mode) left out, its `oneOf` kept; forms a field's `before`
validator accepts written out (`bridges: {file: ...}`); bounds the field validators check, stated.
"""

from __future__ import annotations

import json
from typing import Any

from runner.schema import Scenario

DRAFT = "https://json-schema.org/draft/2020-12/schema"


def build() -> dict[str, Any]:
    schema = Scenario.model_json_schema()
    _drop(schema, "discriminator")
    props = schema["properties"]
    # `bridges: {file: bridge.yaml}`: one entry, as the runner takes it
    bridges = props["bridges"]
    one = bridges.pop("items")
    bridges.pop("type", None)
    bridges["anyOf"] = [{"type": "array", "items": one}, one]
    props["seed"]["minimum"] = 0  # (Scenario._seed)
    return {"$schema": DRAFT, **schema}


def _drop(node: Any, keyword: str) -> None:
    if isinstance(node, dict):
        node.pop(keyword, None)
        for value in node.values():
            _drop(value, keyword)
    elif isinstance(node, list):
        for value in node:
            _drop(value, keyword)


def render() -> str:
    return json.dumps(build(), indent=2, sort_keys=False) + "\n"
