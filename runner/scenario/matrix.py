"""`matrix:` parameter variants: one scenario file, several runs.

```yaml
matrix:
  seed: [1, 2]
  robots[0].pose.xyz: [[0, 0, 0.06], [1, 0, 0.06]]
  timeline[0].data.linear.x: [0.2, 0.4]
```
expands into the cartesian product (here 8 variants); each key is a path into the scenario, each value
replaces what is there (missing mappings on the way are created). Every variant is validated, run and judged
on its own, and reported as `<name>[seed=1,robots[0].pose.xyz=[0, 0, 0.06],...]`.

`samples: N` (a key of its own, not a path) runs each combination N times, sample i drawing the file's random
values (`runner.scenario.draws`) from `[seed, i]`: `<name>[sample=2,robots[0].pose=[1.23, -0.5, 0.06, yaw
1.2]]`. A file with draws and no matrix is one run, drawn as sample 0.
"""

from __future__ import annotations

import copy
import itertools
import math
import re
from typing import Any

from runner.errors import Problem, ScenarioError
from runner.scenario.draws import DrawnDocument, draw, has_draws
from runner.scenario.loader import Document

_PART = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(-?\d+)\]")


MAX_VARIANTS = 1000  # each one is a run: beyond this, a matrix is a mistake, not a test plan
SAMPLES = "samples"  # the matrix key that is not a path: how many seeded draws of each combination


def parse_path(text: str) -> tuple[str | int, ...] | None:
    """`robots[0].pose.xyz` -> ("robots", 0, "pose", "xyz"); None if it is not such a path."""
    out: list[str | int] = []
    for chunk in text.split("."):
        parts = list(_PART.finditer(chunk))
        if not chunk or "".join(m.group(0) for m in parts) != chunk or parts[0].group(1) is None:
            return None
        out += [m.group(1) if m.group(1) is not None else int(m.group(2)) for m in parts]
    return tuple(out) if out else None


def _set(data: Any, path: tuple[str | int, ...], value: Any) -> bool:
    cur = data
    for i, el in enumerate(path):
        last = i == len(path) - 1
        if isinstance(el, int):
            if not isinstance(cur, list) or not -len(cur) <= el < len(cur):
                return False
            if last:
                cur[el] = value
                return True
            cur = cur[el]
        else:
            if not isinstance(cur, dict):
                return False
            if last:
                cur[el] = value
                return True
            if el not in cur or cur[el] is None:
                cur[el] = {}
            cur = cur[el]
    return False


def _label(value: Any) -> str:
    text = str(value).replace("'", "")
    return text if len(text) <= 40 else text[:37] + "..."


def variants(doc: Document) -> list[tuple[str, Document]]:
    """[(label, document)] for every combination (and sample); [("", doc)] without a matrix. A variant whose
    file draws values is a `DrawnDocument` holding them."""
    data = doc.data
    if not isinstance(data, dict) or not data.get("matrix"):
        if isinstance(data, dict) and has_draws(data):
            drawn = copy.deepcopy(data)
            return [("", DrawnDocument(drawn, doc.file, doc.positions, draw(doc, drawn)))]
        return [("", doc)]
    paths, samples = _matrix(doc)
    matrix = data["matrix"]
    out: list[tuple[str, Document]] = []
    for combo in itertools.product(*[matrix[k] for k, _ in paths]):
        variant = copy.deepcopy(data)
        del variant["matrix"]
        for (key, path), value in zip(paths, combo, strict=True):
            if not _set(variant, path, copy.deepcopy(value)):
                where = ("matrix", key)
                raise ScenarioError(
                    Problem(
                        f"{key!r} does not lead to a value in this scenario",
                        doc.locate(where),
                        where,
                        hint="list indices must exist (robots[0] needs a first robot)",
                    )
                )
        prefix = [f"{key}={_label(v)}" for (key, _), v in zip(paths, combo, strict=True)]
        if samples is None and not has_draws(variant):
            out.append((",".join(prefix), Document(variant, doc.file, doc.positions)))
            continue
        for i in range(samples or 1):
            one = copy.deepcopy(variant) if samples else variant
            draws = draw(doc, one, i, [*prefix, *([f"sample={i}"] if samples else [])])
            out.append((draws.label(), DrawnDocument(one, doc.file, doc.positions, draws)))
    return out


def variant_values(doc: Document) -> list[dict[str, str]]:
    """Each variant's matrix values, as its label writes them ({key: value}, and `sample` with `samples:`),
    in the order of `variants` ([{}] without a matrix): what a suite's pass rate is broken down by."""
    data = doc.data
    if not isinstance(data, dict) or not data.get("matrix"):
        return [{}]
    paths, samples = _matrix(doc)
    out: list[dict[str, str]] = []
    for combo in itertools.product(*[data["matrix"][k] for k, _ in paths]):
        values = {key: _label(v) for (key, _), v in zip(paths, combo, strict=True)}
        out += [{**values, **({"sample": str(i)} if samples else {})} for i in range(samples or 1)]
    return out


def _matrix(doc: Document) -> tuple[list[tuple[str, tuple[str | int, ...]]], int | None]:
    """The matrix's paths (key, parsed) and `samples` (None without), every mistake in it at once."""
    matrix = doc.data["matrix"]
    problems: list[Problem] = []
    if not isinstance(matrix, dict):
        raise ScenarioError(
            Problem(
                "`matrix` must map paths to lists of values",
                doc.locate(("matrix",)),
                ("matrix",),
                hint="e.g. `matrix: {seed: [1, 2]}`",
            )
        )
    paths: list[tuple[str, tuple[str | int, ...]]] = []
    samples: int | None = None
    for key, values in matrix.items():
        where = ("matrix", key)
        path = parse_path(str(key))
        if key == SAMPLES:
            if isinstance(values, int) and not isinstance(values, bool) and values >= 1:
                samples = values
            else:
                problems.append(
                    Problem(
                        "`samples` is how many seeded draws of the scenario to run",
                        doc.locate(where),
                        where,
                        expected="a whole number, 1 or more",
                        found=repr(values),
                        hint="e.g. `matrix: {samples: 10}`",
                    )
                )
        elif path is None or path[0] in ("matrix", "name"):
            problems.append(
                Problem(
                    f"{key!r} is not a path into the scenario",
                    doc.locate(where),
                    where,
                    hint="paths look like `seed`, `robots[0].pose.xyz`, `timeline[1].data.linear.x`; "
                    "`samples: N` runs N seeded draws",
                )
            )
        elif not isinstance(values, list) or not values:
            problems.append(
                Problem(
                    "expected a non-empty list of values",
                    doc.locate(where),
                    where,
                    found=repr(values),
                    hint="give the values to try as a list: `robots[0].pose.xyz: [[0, 0, 0], [1, 0, 0]]`",
                )
            )
        else:
            paths.append((str(key), path))
    if problems:
        raise ScenarioError(problems)
    total = math.prod(len(matrix[k]) for k, _ in paths) * (samples or 1)
    if total > MAX_VARIANTS:
        counts = [str(len(matrix[k])) for k, _ in paths] + ([f"{samples} samples"] if samples else [])
        raise ScenarioError(
            Problem(
                f"the matrix makes {total} variants, more than {MAX_VARIANTS}",
                doc.locate(("matrix",)),
                ("matrix",),
                expected=f"at most {MAX_VARIANTS} combinations",
                found=" x ".join(counts),
                hint="split it into several scenario files, or run chosen variants with --variant",
            )
        )
    return paths, samples
