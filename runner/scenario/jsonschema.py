"""The JSON Schema of the scenario format, generated from the pydantic models (never edited by hand).

What pydantic writes is adjusted where it would disagree with the runner or with validators in their
strict modes (ajv, check-jsonschema): draft 2020-12 named; OpenAPI's `discriminator` keyword (unknown to
JSON Schema, refused by ajv's default strict mode) left out, its `oneOf` kept; forms a field's `before`
validator accepts written out (`bridges: {file: ...}`); bounds the field validators check, stated.

A plugin entry's `params` is checked against the `Params` model of the plugin its `type` names, for every
plugin installed when the schema is built (built-in and third-party, through the registry), one
`if type is X then params is XParams` rule each. A type the schema does not know keeps its `params` open:
it may be a plugin installed later. The rules refuse no params the runner takes (see `_ParamsSchema`):
no key is required (a robot's description may give it, the scenario's params being merged over the
description's), a field whose own validator sees the raw value takes anything, every name a field is
accepted under is listed.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

from pydantic import BaseModel, PydanticUserError
from pydantic.json_schema import GenerateJsonSchema, JsonSchemaValue, models_json_schema
from pydantic_core import CoreSchema, core_schema

from runner.scenario.schema import PluginEntry, Scenario

DRAFT = "https://json-schema.org/draft/2020-12/schema"
REF = "#/$defs/{model}"


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
    props["matrix"]["properties"] = {"samples": SAMPLES}
    props["matrix"]["additionalProperties"] = {"type": "array"}
    _check_plugin_params(schema)
    schema = _with_draws(schema)
    schema["$defs"].update(DRAW_DEFS)
    schema["$defs"] = dict(sorted(schema["$defs"].items()))
    return {"$schema": DRAFT, **schema}


# ------------------------------------------------------------------------------------------------- draws
# Values drawn at random (runner.scenario.draws) are resolved before the models see the file: in the JSON
# Schema, every number (and vector of numbers) also takes a draw, and every pose the `within` form.
SAMPLES = {
    "type": "integer",
    "minimum": 1,
    "description": "How many seeded draws of the scenario's random values to run (each combination of the "
    "other keys N times, sample i drawing from [seed, i]).",
}
_TWO = {
    "type": "array",
    "prefixItems": [{"type": "number"}, {"type": "number"}],
    "minItems": 2,
    "maxItems": 2,
}


def _one_key(key: str, value: dict[str, Any], description: str) -> dict[str, Any]:
    return {
        "type": "object",
        "properties": {key: value},
        "required": [key],
        "additionalProperties": False,
        "description": description,
    }


DRAW_DEFS: dict[str, Any] = {
    "Draw": {
        "title": "Draw",
        "description": "A value drawn at random from the scenario's seed (and the sample's index).",
        "oneOf": [
            _one_key("uniform", _TWO, "`[lo, hi]`: a float in [lo, hi)."),
            _one_key("normal", _TWO, "`[mean, stddev]`: a float from a normal distribution."),
            _one_key("choice", {"type": "array", "minItems": 1}, "One of the items."),
        ],
    },
    "DrawnPose": {
        "title": "DrawnPose",
        "description": "A pose drawn uniformly within a region of the ground, free of collisions at the "
        "start: `{xyz: [x, y, z], rpy: [0, 0, yaw]}`.",
        "type": "object",
        "properties": {
            "within": {"$ref": "#/$defs/Region"},
            "z": {"type": "number", "description": "Height in metres (default 0)."},
            "yaw": {
                "anyOf": [{"type": "number"}, _TWO],
                "description": "Yaw in radians: a number, or [lo, hi] drawn uniformly (default 0).",
            },
        },
        "required": ["within"],
        "additionalProperties": False,
    },
}
_VALUES = ("default", "examples", "const", "enum")  # keywords whose value is data, not a schema


def _with_draws(node: Any) -> Any:
    """`node` with every number and number vector also taking a `Draw`, every `Pose` a `DrawnPose`."""
    if isinstance(node, list):
        return [_with_draws(v) for v in node]
    if not isinstance(node, dict):
        return node
    out = {k: (v if k in _VALUES else _with_draws(v)) for k, v in node.items()}
    if node.get("$ref") == "#/$defs/Pose":
        rest = {k: v for k, v in out.items() if k != "$ref"}
        return {"anyOf": [{"$ref": "#/$defs/Pose"}, {"$ref": "#/$defs/DrawnPose"}], **rest}
    items = node.get("prefixItems")
    vector = node.get("type") == "array" and isinstance(items, list) and items
    if node.get("type") == "number" or (vector and all(i.get("type") == "number" for i in items)):
        kept = {k: v for k, v in out.items() if k in ("title", "description", "default")}
        inner = {k: v for k, v in out.items() if k not in kept}
        return {"anyOf": [inner, {"$ref": "#/$defs/Draw"}], **kept}
    return out


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


# ------------------------------------------------------------------------------------------ plugin params
def installed_params() -> list[tuple[str, type[BaseModel]]]:
    """(type, Params model) of every plugin the registry finds, by type name. A plugin that fails to load
    (a broken import, a name registered twice) is left out: the runner refuses it where a scenario uses it,
    and the schema leaves its params open."""
    from runner.plugin import registry

    found: list[tuple[str, type[BaseModel]]] = []
    for name in registry.available():
        try:
            params = registry.load(name).Params
        except registry.PluginLookupError:
            continue
        if isinstance(params, type) and issubclass(params, BaseModel):
            found.append((name, params))
    return found


def _check_plugin_params(schema: dict[str, Any]) -> None:
    """Add the installed plugins' Params models to `schema` and, to its plugin entry, the rules that check
    an entry's `params` against the model of the plugin its `type` names."""
    plugins = [(name, model) for name, model in installed_params() if _has_schema(model)]
    if not plugins:
        return
    models = list(dict.fromkeys(model for _, model in plugins))
    refs, top = models_json_schema(
        [(m, "validation") for m in models], ref_template=REF, schema_generator=_ParamsSchema
    )
    defs: dict[str, Any] = top.get("$defs", {})
    for node in _subschemas(defs):
        _settle(node)
    for model in models:
        root = _target(refs[(model, "validation")], defs)
        if root is not None:
            # a key the scenario leaves out may come from the robot's description: none is required here
            root.pop("required", None)
    renamed = _merge(schema.setdefault("$defs", {}), defs)
    schema["$defs"] = dict(sorted(schema["$defs"].items()))
    entry = schema["$defs"][PluginEntry.__name__]
    entry["allOf"] = [
        {
            "if": {"properties": {"type": {"const": name}}, "required": ["type"]},
            "then": {"properties": {"params": _renamed(refs[(model, "validation")], renamed)}},
        }
        for name, model in plugins
    ]


def _has_schema(model: type[BaseModel]) -> bool:
    """Whether pydantic can write `model`'s schema at all (a third-party model might not be)."""
    try:
        model.model_json_schema(ref_template=REF, schema_generator=_ParamsSchema)
    except PydanticUserError:  # e.g. a model not fully defined
        return False
    return True


def _target(ref: dict[str, Any], defs: dict[str, Any]) -> dict[str, Any] | None:
    name = ref.get("$ref", "").removeprefix("#/$defs/")
    return defs.get(name)


def _merge(into: dict[str, Any], defs: dict[str, Any]) -> dict[str, str]:
    """Put `defs` into `into`; a name `into` already has for another schema gets a number. Returns the
    names changed, old -> new, after rewriting the references in `defs` that use them."""
    renamed: dict[str, str] = {}
    for name in defs:
        if name in into and into[name] != defs[name]:
            n = 2
            while f"{name}{n}" in into or f"{name}{n}" in defs:
                n += 1
            renamed[name] = f"{name}{n}"
    for name, node in defs.items():
        into[renamed.get(name, name)] = _renamed(node, renamed)
    return renamed


def _renamed(node: Any, renamed: dict[str, str]) -> Any:
    """`node` with its `$ref`s to renamed definitions following them."""
    if isinstance(node, dict):
        out = {k: _renamed(v, renamed) for k, v in node.items()}
        ref = node.get("$ref")
        if isinstance(ref, str) and ref.startswith("#/$defs/"):
            out["$ref"] = "#/$defs/" + renamed.get(ref.removeprefix("#/$defs/"), ref.removeprefix("#/$defs/"))
        return out
    if isinstance(node, list):
        return [_renamed(v, renamed) for v in node]
    return node


# keywords whose value is a schema, a map of schemas, a list of schemas (JSON Schema 2020-12)
_ONE = ("additionalProperties", "items", "contains", "not", "if", "then", "else", "propertyNames",
        "unevaluatedItems", "unevaluatedProperties")  # fmt: skip
_MAP = ("properties", "patternProperties", "$defs", "dependentSchemas")
_LIST = ("allOf", "anyOf", "oneOf", "prefixItems")


def _subschemas(defs: dict[str, Any]) -> Iterator[dict[str, Any]]:
    """Every schema in `defs`, each one before those inside it (so that one can be replaced whole)."""
    stack = [d for d in reversed(defs.values()) if isinstance(d, dict)]
    while stack:
        node = stack.pop()
        yield node
        inner: list[Any] = [node.get(k) for k in _ONE]
        inner += [s for k in _MAP for s in (node.get(k) or {}).values()]
        inner += [s for k in _LIST for s in (node.get(k) or [])]
        stack.extend(s for s in reversed(inner) if isinstance(s, dict))


_LOOSE = "x-runner-loose"  # what _ParamsSchema marks; never in the output
_ANNOTATIONS = ("title", "description", "default", "examples", "deprecated")


def _settle(node: dict[str, Any]) -> None:
    """A schema as validators take it: where a validator of the model sees the raw value, anything goes
    (the annotations stay); `format` is left out (ajv's strict mode knows no format; pydantic's own, such
    as `path`, are not JSON Schema's); `discriminator` too (as for the scenario's own models)."""
    if node.pop(_LOOSE, False):
        for key in [k for k in node if k not in _ANNOTATIONS]:
            del node[key]
    node.pop("format", None)
    node.pop("discriminator", None)


class _ParamsSchema(GenerateJsonSchema):
    """pydantic's schema of a Params model, changed so as to refuse nothing the model takes:

    - a `before`, `wrap` or `plain` validator (of a field or of a model) sees the raw value and may take
      forms its type does not say (a number for a list, Gazebo's names...): its schema is marked, then made
      open (`_settle`), unless the validator states its input (`json_schema_input_type`);
    - a part pydantic cannot write (an arbitrary type) is open, not an error;
    - a field is listed under every key it is accepted by: each of its `AliasChoices`, and its own name as
      well as its alias where the model validates by name (`populate_by_name`); a field with several keys
      is not required.
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._configs: list[core_schema.CoreConfig] = []

    def function_before_schema(self, schema: core_schema.BeforeValidatorFunctionSchema) -> JsonSchemaValue:
        return self._loose(schema) or super().function_before_schema(schema)

    def function_wrap_schema(self, schema: core_schema.WrapValidatorFunctionSchema) -> JsonSchemaValue:
        return self._loose(schema) or super().function_wrap_schema(schema)

    def function_plain_schema(self, schema: core_schema.PlainValidatorFunctionSchema) -> JsonSchemaValue:
        return self._loose(schema) or super().function_plain_schema(schema)

    def handle_invalid_for_json_schema(self, schema: CoreSchema, error_info: str) -> JsonSchemaValue:
        return {_LOOSE: True}

    def _loose(self, schema: Any) -> JsonSchemaValue | None:
        if self.mode == "validation" and not schema.get("json_schema_input_schema"):
            return {_LOOSE: True}
        return None

    def model_schema(self, schema: core_schema.ModelSchema) -> JsonSchemaValue:
        self._configs.append(schema.get("config") or {})
        try:
            return super().model_schema(schema)
        finally:
            self._configs.pop()

    def model_fields_schema(self, schema: core_schema.ModelFieldsSchema) -> JsonSchemaValue:
        out = super().model_fields_schema(schema)
        props = out.get("properties")
        if not isinstance(props, dict):
            return out
        config = self._configs[-1] if self._configs else {}
        required: list[str] = out.get("required", [])
        for name, field in schema["fields"].items():
            keys = _field_keys(name, field, config)
            shown = next((k for k in keys if k in props), name if name in props else None)
            if shown is None:
                continue
            for key, deep in keys.items():
                if key not in props:
                    props[key] = {} if deep else props[shown]
            if len(keys) > 1 and shown in required:
                required.remove(shown)
        if "required" in out and not required:
            del out["required"]
        return out


def _field_keys(name: str, field: Any, config: core_schema.CoreConfig) -> dict[str, bool]:
    """The keys a model field is taken from: key -> whether its value is only a path into (`AliasPath`)."""
    alias = field.get("validation_alias")
    keys: dict[str, bool] = {}
    if alias is not None and config.get("validate_by_alias", True):
        if isinstance(alias, str):
            keys[alias] = False
        else:
            for path in alias:
                if path and isinstance(path[0], str):
                    keys.setdefault(path[0], len(path) > 1)
    if alias is None or config.get("validate_by_name", False):
        keys.setdefault(name, False)
    return keys
