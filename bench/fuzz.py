"""A long fuzzing run of the scenario reader: `python -m bench.fuzz --examples N [--seed S]`.

The same strategies and property as tests/test_fuzz.py (tests/fuzzing.py): valid-shaped scenarios,
mutated ones and damaged YAML text are read, validated and (a share of them) compiled; anything but a
`ScenarioError` whose problems are all located is a failure. Unlike the test, a failure does not stop the
run: each distinct one (exception type and the innermost frame of this project) is kept with the smallest
input that caused it, written to `--out`, and printed at the end. Exit status 1 when any was found.
"""

from __future__ import annotations

import argparse
import sys
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))


@dataclass
class Failure:
    kind: str
    where: str
    message: str
    text: str
    trace: str
    count: int = 1


@dataclass
class Run:
    tried: int = 0
    failures: dict[tuple[str, str], Failure] = field(default_factory=dict)

    def record(self, e: BaseException, text: str) -> None:
        frames = traceback.extract_tb(e.__traceback__)
        ours = [f for f in frames if "/runner/" in f.filename or "/plugins/" in f.filename]
        last = ours[-1] if ours else (frames[-1] if frames else None)
        where = "?"
        if last is not None:
            name = last.filename.removeprefix(str(REPO) + "/")
            where = f"{name}:{last.lineno}"
        key = (type(e).__name__, where)
        trace = "".join(traceback.format_exception(e))
        old = self.failures.get(key)
        if old is None:
            self.failures[key] = Failure(type(e).__name__, where, str(e)[:500], text, trace)
        else:
            old.count += 1
            if len(text) < len(old.text):
                old.text, old.message, old.trace = text, str(e)[:500], trace


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench.fuzz", description=__doc__.split("\n")[0])
    parser.add_argument("--examples", type=int, default=3000, help="examples in all (split over the kinds)")
    parser.add_argument("--seed", type=int, default=None, help="random seed (default: a new one each run)")
    parser.add_argument(
        "--compile-share", type=float, default=0.25, help="share of examples compiled too (MuJoCo), 0..1"
    )
    parser.add_argument(
        "--kinds",
        default="valid,mutated,text,files",
        help="comma-separated: valid, mutated, text (scenarios), files (damaged URDF/xacro/SDF)",
    )
    parser.add_argument("--out", type=Path, default=Path("runs/fuzz"), help="where failing inputs go")
    args = parser.parse_args(argv)

    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as hypothesis_seed
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

    def as_text(doc_text: str, compile_it: bool, outcome: Outcome) -> None:
        check(doc_text, compile_it, outcome)

    def as_file(named: tuple[str, str], compile_it: bool, outcome: Outcome) -> None:
        check_description(*named, outcome)

    kinds: dict[str, tuple[Any, Callable[[Any, bool, Outcome], None]]] = {
        "valid": (scenarios().map(to_yaml), as_text),
        "mutated": (mutated().map(to_yaml), as_text),
        "text": (yaml_texts(), as_text),
        "files": (descriptions(), as_file),
    }
    chosen = [k.strip() for k in args.kinds.split(",") if k.strip()]
    unknown = [k for k in chosen if k not in kinds]
    if unknown or not chosen:
        parser.error(f"unknown kind(s): {', '.join(unknown)}; kinds: {', '.join(kinds)}")
    per_kind = max(1, args.examples // len(chosen))
    share = min(max(args.compile_share, 0.0), 1.0)
    seed = args.seed if args.seed is not None else int(time.time())
    run = Run()
    outcome = Outcome()
    started = time.perf_counter()

    def make(
        strategy: Any, runner: Callable[[Any, bool, Outcome], None], examples: int
    ) -> Callable[[], None]:
        @hypothesis_seed(seed)
        @settings(
            max_examples=examples,
            deadline=None,
            database=None,
            derandomize=False,
            suppress_health_check=list(HealthCheck),
            phases=[Phase.explicit, Phase.generate],  # no shrinking: a failure does not stop the run
        )
        @given(value=strategy, pick=st.floats(0, 1, exclude_max=True))
        def one(value: Any, pick: float) -> None:
            run.tried += 1
            try:
                runner(value, pick < share, outcome)
            except Exception as e:  # a bug: kept, and the run goes on
                run.record(e, value if isinstance(value, str) else "\n".join(value))

        return one

    for name in chosen:
        one = make(*kinds[name], per_kind)
        one()
        print(f"{name}: {per_kind} examples, {len(run.failures)} distinct failure(s) so far", flush=True)
    elapsed = time.perf_counter() - started

    print(
        f"examples tried: {run.tried} in {elapsed:.0f} s (seed {seed}): {outcome.ok} valid, {outcome.errors} "
        f"reported as ScenarioError, {outcome.compiled} compiled"
    )
    print(f"failures found: {len(run.failures)}")
    if run.failures:
        args.out.mkdir(parents=True, exist_ok=True)
    for i, f in enumerate(sorted(run.failures.values(), key=lambda f: -f.count)):
        path = args.out / f"failure_{i}.yaml"
        path.write_text(f.text, encoding="utf-8")
        path.with_suffix(".txt").write_text(f.trace, encoding="utf-8")
        print(f"\n[{i}] {f.kind} at {f.where} ({f.count}x): {f.message}")
        print(f"    smallest input: {path} ({len(f.text)} characters); traceback: {path.with_suffix('.txt')}")
    return 1 if run.failures else 0


if __name__ == "__main__":
    sys.exit(main())
