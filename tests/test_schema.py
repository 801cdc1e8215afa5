from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml
from pydantic import ValidationError

from runner.scenario.jsonschema import installed_params, render
from runner.scenario.schema import Scenario
from tests.conftest import REPO


def test_committed_json_schema_is_current():
    committed = (REPO / "schemas" / "scenario.schema.json").read_text()
    plugins = ", ".join(name for name, _ in installed_params())
    assert committed == render(), (
        f"schemas/scenario.schema.json is stale: run `scenario schema` (plugins here: {plugins})"
    )


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


CLIENTS = Path(__file__).parent / "clients"


def _as_json(files: list[Path], out: Path) -> list[Path]:
    written = []
    for i, f in enumerate(files):
        target = out / f"{i:03d}_{f.stem}.json"
        target.write_text(json.dumps(yaml.safe_load(f.read_text(encoding="utf-8"))))
        written.append(target)
    return written


def _expressible(data: object) -> bool:
    """Whether the runner's own schema pass refuses `data` for a reason JSON Schema can state (a type, a
    key, a pattern, a bound), not a rule of its field validators (`value_error`), in the scenario or in a
    plugin's `params` (checked against the plugin's own model; a missing parameter is no such reason, as
    the robot's description may give it); and JSON can hold it (`.inf` and keys that are not text it
    cannot)."""
    try:
        if json.loads(json.dumps(data, allow_nan=False)) != data:
            return False  # a key that is not text (`1:`) becomes text in JSON
    except (ValueError, TypeError):
        return False
    try:
        Scenario.model_validate(data)
    except ValidationError as e:
        if any(err["type"] not in _RULES for err in e.errors()):
            return True
    params = dict(installed_params())
    for entry in _plugin_entries(data):
        model = params.get(entry["type"])
        try:
            if model is not None:
                model.model_validate(entry["params"])
        except ValidationError as e:
            if any(err["type"] not in (*_RULES, "missing") for err in e.errors()):
                return True
    return False


_RULES = ("value_error", "assertion_error")  # a validator's own rule: no schema states it


def _plugin_entries(data: object) -> list[dict[str, Any]]:
    """The plugin entries of a scenario's robots that have a text `type` and mapping `params`."""
    robots = data.get("robots") if isinstance(data, dict) else None
    return [
        p
        for r in (robots if isinstance(robots, list) else [])
        if isinstance(r, dict) and isinstance(r.get("plugins"), list)
        for p in r["plugins"]
        if isinstance(p, dict) and isinstance(p.get("type"), str) and isinstance(p.get("params"), dict)
    ]


def _corpus() -> tuple[list[Path], list[Path]]:
    """The scenarios of `scenarios/` (every validator must take them) and the files of tests/bad_inputs/
    that the runner refuses for a reason a schema can state (every validator must refuse them)."""
    good = sorted(p for p in (REPO / "scenarios").rglob("*.yaml") if _is_scenario(p))
    bad = sorted(
        p for p in (REPO / "tests" / "bad_inputs").glob("*.yaml")
        if _loads(p) is not None and _expressible(_loads(p))
    )  # fmt: skip
    assert len(good) >= 8 and len(bad) >= 20, (len(good), len(bad))
    assert {p.name for p in bad} >= PARAMS_REFUSED, "plugin params are no longer stated by the schema"
    return good, bad


# plugin params a schema refuses: a wrong type, an unknown key (as the runner does)
PARAMS_REFUSED = {"plugin_param_type.yaml", "plugin_unknown_param.yaml"}


@pytest.mark.timeout(120)
def test_ajv_in_strict_mode_takes_the_schema_and_agrees_with_the_runner(tmp_path: Path) -> None:
    """An editor's validator (ajv, draft 2020-12, default strict mode) compiles the committed schema,
    accepts every scenario of `scenarios/` (`bridges: {file: ...}` included), and refuses each file of
    tests/bad_inputs/ that the runner's schema pass refuses for a reason a schema can state."""
    import shutil

    node = shutil.which("node")
    assert node is not None and (CLIENTS / "node_modules" / "ajv").is_dir(), (
        "Node and the test clients are needed: run `.ci/setup --test`"
    )
    good, bad = _corpus()
    files = _as_json(good + bad, tmp_path)
    proc = subprocess.run(
        [
            node,
            str(CLIENTS / "ajv_check.mjs"),
            str(REPO / "schemas" / "scenario.schema.json"),
            *map(str, files),
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    got = json.loads(proc.stdout)
    assert got["compiled"], got.get("error")
    verdicts = [r["valid"] for r in got["results"]]
    wrong_good = [(f.name, r["errors"]) for f, r in zip(good, got["results"], strict=False) if not r["valid"]]
    assert not wrong_good, wrong_good
    accepted_bad = [f.name for f, ok in zip(bad, verdicts[len(good) :], strict=True) if ok]
    assert not accepted_bad, accepted_bad
    refused = {f.name for f, ok in zip(bad, verdicts[len(good) :], strict=True) if not ok}
    assert refused >= PARAMS_REFUSED


def _loads(path: Path) -> object:
    try:
        return yaml.safe_load(path.read_text(encoding="utf-8"))
    except (yaml.YAMLError, UnicodeDecodeError):
        return None


def _is_scenario(path: Path) -> bool:
    data = _loads(path)
    return (
        isinstance(data, dict)
        and "name" in data
        and ("robots" in data or "world" in data or "worlds" in data)
    )


# check-jsonschema run with the network refused: a schema it tried to download (the metaschema, a remote
# `$ref`) would fail the check instead of passing on a machine that happens to be online
_OFFLINE = """\
import socket, sys
def refuse(*args, **kwargs):
    raise OSError("check-jsonschema tried to use the network")
socket.socket.connect = refuse
socket.getaddrinfo = refuse
from check_jsonschema import main
sys.exit(main())
"""


def _check_jsonschema(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", _OFFLINE, *args], capture_output=True, text=True, timeout=60)


@pytest.mark.timeout(120)
def test_check_jsonschema_takes_the_schema_and_agrees_with_the_runner(tmp_path: Path) -> None:
    """The Python validator (check-jsonschema: jsonschema, draft 2020-12, ECMAScript regexes), offline:
    the committed schema is valid under its metaschema, every scenario of `scenarios/` passes, and each
    bad input the runner refuses for a reason a schema can state is refused, plugin params included."""
    schema = REPO / "schemas" / "scenario.schema.json"
    proc = _check_jsonschema("--check-metaschema", str(schema))
    assert proc.returncode == 0, proc.stdout + proc.stderr
    good, bad = _corpus()
    files = _as_json(good + bad, tmp_path)
    proc = _check_jsonschema("--output-format", "json", "--schemafile", str(schema), *map(str, files))
    assert "network" not in proc.stderr, proc.stderr
    got = json.loads(proc.stdout)
    assert not got["parse_errors"], got["parse_errors"]
    refused = {Path(e["filename"]).name for e in got["errors"]}
    wrong_good = [(f.name, j.name) for f, j in zip(good, files, strict=False) if j.name in refused]
    assert not wrong_good, (wrong_good, got["errors"])
    refused_bad = {f.name for f, j in zip(bad, files[len(good) :], strict=True) if j.name in refused}
    accepted_bad = [f.name for f in bad if f.name not in refused_bad]
    assert not accepted_bad, accepted_bad
    assert refused_bad >= PARAMS_REFUSED
    assert proc.returncode == 1  # (some files were refused)


def _then(schema: dict[str, Any], plugin: str) -> dict[str, Any]:
    """The params schema the plugin entry's rule for `plugin` applies."""
    for rule in schema["$defs"]["PluginEntry"]["allOf"]:
        if rule["if"]["properties"]["type"] == {"const": plugin}:
            ref = rule["then"]["properties"]["params"]["$ref"]
            return schema["$defs"][ref.removeprefix("#/$defs/")]
    raise AssertionError(f"no rule for {plugin!r}")


def test_every_installed_plugin_has_its_params_rule_and_its_defaults_pass() -> None:
    """One rule per installed plugin, in name order; what each model takes by default (its own dump, the
    required keys given) passes its rule; no key is required (the description may give it)."""
    from jsonschema import Draft202012Validator

    from runner.scenario.jsonschema import build

    schema = build()
    rules = schema["$defs"]["PluginEntry"]["allOf"]
    names = [r["if"]["properties"]["type"]["const"] for r in rules]
    assert names == sorted(name for name, _ in installed_params())
    assert {"lidar", "imu", "diff_drive", "camera", "joint_controller"} <= set(names)
    validator = Draft202012Validator(schema)
    samples = {
        "contact": {"link": "base_link"},
        "joint_controller": {"joints": ["lift"]},
        "joint_trajectory_controller": {"joints": ["shoulder"]},
        "gripper_action_controller": {"joint": "finger"},
    }
    for name, model in installed_params():
        params = model.model_validate(samples.get(name, {})).model_dump(mode="json")
        entry = {"type": name, "params": params}
        doc = {"name": "x", "robots": [{"name": "r", "description": "r.urdf", "plugins": [entry]}]}
        errors = [e.message for e in validator.iter_errors(doc)]
        assert not errors, (name, errors)
        assert "required" not in _then(schema, name), name
    lidar = _then(schema, "lidar")
    assert lidar["additionalProperties"] is False
    assert lidar["properties"]["samples"]["type"] == "integer"
    assert lidar["properties"]["samples"]["exclusiveMinimum"] == 0
    assert lidar["properties"]["points_format"]["enum"] == ["xyz", "velodyne"]
    assert _plain(lidar["properties"]["min_angle"])["minimum"] == -7.0


def _plain(prop: dict[str, Any]) -> dict[str, Any]:
    """A number's (or number vector's) own schema: every one of them also takes a draw (`{uniform: ...}`)."""
    own, draw = prop["anyOf"]
    assert draw == {"$ref": "#/$defs/Draw"}, prop
    return own  # type: ignore[no-any-return]


def test_params_rules_refuse_nothing_the_model_takes(monkeypatch: pytest.MonkeyPatch) -> None:
    """A third-party Params model may take more than its types say: other names (aliases, `AliasChoices`,
    its field names with `populate_by_name`), raw values its `before` validators turn into the type, a
    field pydantic cannot describe. Each form the model takes passes the schema; an unknown key and a
    wrong type of a plain field are still refused."""
    from typing import Annotated

    from jsonschema import Draft202012Validator
    from pydantic import (
        AliasChoices,
        BaseModel,
        BeforeValidator,
        ConfigDict,
        Field,
        field_validator,
        model_validator,
    )

    import runner.scenario.jsonschema as js

    class Inner(BaseModel):
        model_config = ConfigDict(extra="forbid")
        a: int = 0

    class Fancy(BaseModel):
        model_config = ConfigDict(extra="forbid", populate_by_name=True)
        update_rate: float = Field(10.0, gt=0, alias="updateRate")
        frame: str = Field("base", validation_alias=AliasChoices("frame", "frameName"))
        joints: list[str] = Field(default_factory=list)
        noise: Annotated[
            float, BeforeValidator(lambda v: float(v.split()[0]) if isinstance(v, str) else v)
        ] = 0
        inner: Inner = Field(default_factory=Inner)
        link: str = Field(description="Required: the description may give it.")

        @field_validator("joints", mode="before")
        @classmethod
        def _one(cls, v: Any) -> Any:
            return [v] if isinstance(v, str) else v

    class Gazebo(BaseModel):
        """Takes Gazebo's names too, renamed by a model validator that sees the raw mapping."""

        model_config = ConfigDict(extra="forbid")
        rate: float = 1.0

        @model_validator(mode="before")
        @classmethod
        def _names(cls, v: Any) -> Any:
            return {"rate" if k == "updateRate" else k: x for k, x in v.items()} if isinstance(v, dict) else v

    class Opaque:
        pass

    class Handles(BaseModel):
        model_config = ConfigDict(extra="forbid", arbitrary_types_allowed=True)
        handle: Opaque | None = None  # pydantic cannot describe it: any value passes the schema
        size: int = 1

    monkeypatch.setattr(
        js, "installed_params", lambda: [("fancy", Fancy), ("gazebo", Gazebo), ("handles", Handles)]
    )
    validator = Draft202012Validator(js.build())

    def valid(params: dict[str, Any], plugin: str = "fancy") -> bool:
        entry = {"type": plugin, "params": params}
        return validator.is_valid(
            {"name": "x", "robots": [{"name": "r", "description": "d", "plugins": [entry]}]}
        )

    taken = [
        {"updateRate": 5}, {"update_rate": 5}, {"frame": "a"}, {"frameName": "a"},
        {"joints": "j1"}, {"joints": ["j1", "j2"]}, {"noise": "0.1 0.1 0.1"}, {"noise": 0.1},
        {"inner": {"a": 1}}, {},
    ]  # fmt: skip
    for params in taken:
        Fancy.model_validate({"link": "l", **params})  # the model takes it...
        assert valid(params), params  # ... and so does the schema
    for params in ({"rat": 1}, {"updateRate": "fast"}, {"updateRate": 0}, {"inner": {"b": 1}}):
        with pytest.raises(ValidationError):
            Fancy.model_validate({"link": "l", **params})
        assert not valid(params), params
    assert valid({"anything": [1]}, "unknown_plugin")  # a plugin installed later: its params are open
    assert valid({"updateRate": 5}, "gazebo") and Gazebo.model_validate({"updateRate": 5}).rate == 5
    assert valid({"handle": "x"}, "handles") and not valid({"size": "big"}, "handles")


@pytest.mark.timeout(120)
def test_a_third_party_plugin_gets_its_params_rule(tmp_path: Path) -> None:
    """`scenario schema` run where a third-party plugin package is installed (tests/thirdparty_plugin, as
    pip would lay it out: its package and a .dist-info with its entry points) writes that plugin's params
    rule; its broken sibling (an import error) is left open, and the built-ins are all there."""
    import shutil
    import tomllib

    package = Path(__file__).parent / "thirdparty_plugin"
    project = tomllib.loads((package / "pyproject.toml").read_text())["project"]
    site = tmp_path / "site"
    shutil.copytree(package / "scenario_beacon", site / "scenario_beacon")
    dist = site / f"{project['name'].replace('-', '_')}-{project['version']}.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(
        f"Metadata-Version: 2.1\nName: {project['name']}\nVersion: {project['version']}\n"
    )
    eps = project["entry-points"]["scenario.plugins"]
    (dist / "entry_points.txt").write_text(
        "[scenario.plugins]\n" + "".join(f"{k} = {v}\n" for k, v in eps.items())
    )
    out = tmp_path / "scenario.schema.json"
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(site), str(REPO), os.environ.get("PYTHONPATH", "")])
    )
    proc = subprocess.run(
        [sys.executable, "-m", "runner.cli", "schema", "-o", str(out)],
        capture_output=True, text=True, timeout=90, env=env, cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    schema = json.loads(out.read_text())
    names = [r["if"]["properties"]["type"]["const"] for r in schema["$defs"]["PluginEntry"]["allOf"]]
    assert "beacon" in names and "beacon_broken" not in names
    assert names == sorted(names) and {name for name, _ in installed_params()} < set(names)
    beacon = _then(schema, "beacon")
    assert beacon["additionalProperties"] is False
    assert set(beacon["properties"]) == {"rate", "point", "link", "topic"}
    assert _plain(beacon["properties"]["rate"])["exclusiveMinimum"] == 0
    assert _plain(beacon["properties"]["point"])["maxItems"] == 3
    # the rest is the committed schema (built with the built-ins only), the beacon's rule and model added
    committed = json.loads((REPO / "schemas" / "scenario.schema.json").read_text())
    rules = schema["$defs"]["PluginEntry"].pop("allOf")
    assert [r for r in rules if r["if"]["properties"]["type"]["const"] != "beacon"] == committed["$defs"][
        "PluginEntry"
    ].pop("allOf")
    assert {k: v for k, v in schema["$defs"].items() if k != "BeaconParams"} == committed["$defs"]
