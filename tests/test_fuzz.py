"""Fuzzing the scenario reader: generated and damaged scenarios either validate or fail with our
`ScenarioError`, every problem located (tests/fuzzing.py has the strategies and the property).

A bounded, derandomized run here; `python -m bench.fuzz --examples N` runs longer and reports failures.
"""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzzing import (
    Outcome,
    check,
    check_description,
    descriptions,
    mutated,
    scenarios,
    to_yaml,
    yaml_texts,
)


def fuzz(examples: int) -> settings:
    return settings(
        max_examples=examples,
        deadline=None,
        derandomize=True,
        database=None,
        suppress_health_check=[
            HealthCheck.too_slow,
            HealthCheck.data_too_large,
            HealthCheck.large_base_example,
        ],
    )


@pytest.mark.timeout(120)
@fuzz(120)
@given(doc=scenarios(), compile_it=st.integers(0, 2).map(lambda k: k == 0))
def test_valid_shaped_scenarios_validate_or_explain(doc: dict, compile_it: bool) -> None:
    check(to_yaml(doc), compile_it)


@pytest.mark.timeout(120)
def test_valid_shaped_scenarios_are_mostly_valid() -> None:
    """The generator of valid-shaped scenarios makes valid ones (else the fuzzing above tests little):
    most of them validate and compile."""
    outcome = Outcome()

    @fuzz(50)
    @given(doc=scenarios())
    def run(doc: dict) -> None:
        check(to_yaml(doc), True, outcome)

    run()
    assert outcome.ok + outcome.errors == 50
    assert outcome.ok >= 25, outcome.messages[:5]  # at least half
    assert outcome.compiled >= outcome.ok  # every valid one compiled (a matrix compiles each variant)


@pytest.mark.timeout(120)
@fuzz(180)
@given(doc=mutated(), compile_it=st.integers(0, 4).map(lambda k: k == 0))
def test_mutated_scenarios_validate_or_explain(doc: object, compile_it: bool) -> None:
    check(to_yaml(doc), compile_it)


@pytest.mark.timeout(120)
@fuzz(220)
@given(text=yaml_texts(), compile_it=st.integers(0, 9).map(lambda k: k == 0))
def test_damaged_yaml_validates_or_explains(text: str, compile_it: bool) -> None:
    check(text, compile_it)


@pytest.mark.timeout(120)
@fuzz(80)
@given(named=descriptions())
def test_damaged_description_files_compile_or_explain(named: tuple[str, str]) -> None:
    check_description(*named)
