from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
import yaml
from pydantic import ValidationError

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
    key, a pattern, a bound), not a rule of its field validators (`value_error`); and JSON can hold it
    (`.inf` and keys that are not text it cannot)."""
    try:
        if json.loads(json.dumps(data, allow_nan=False)) != data:
            return False  # a key that is not text (`1:`) becomes text in JSON
    except (ValueError, TypeError):
        return False
    try:
        Scenario.model_validate(data)
    except ValidationError as e:
        return any(err["type"] not in ("value_error", "assertion_error") for err in e.errors())
    return False


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
    good = sorted(p for p in (REPO / "scenarios").rglob("*.yaml") if _is_scenario(p))
    bad = sorted(
        p for p in (REPO / "tests" / "bad_inputs").glob("*.yaml")
        if _loads(p) is not None and _expressible(_loads(p))
    )  # fmt: skip
    assert len(good) >= 8 and len(bad) >= 20, (len(good), len(bad))
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
