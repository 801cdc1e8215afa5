"""Values drawn at random where a number or a pose is written: randomized scenarios.

```yaml
seed: 3
robots:
  - name: r1
    pose: {within: {min: [-2, -2], max: [2, 2]}, z: 0.06, yaw: [-3.14, 3.14]}
world:
  models:
    - {name: box, shape: box, size: [{uniform: [0.2, 0.5]}, 0.3, 0.3], pose: {xyz: [1, 0, 0.15]}}
timeline:
  - {t: 0.5, topic: r1/cmd_vel, type: geometry_msgs/msg/Twist, data: {linear: {x: {normal: [0.3, 0.05]}}}}
```

A mapping whose one key is `uniform: [lo, hi]` (a float in [lo, hi)), `normal: [mean, stddev]` (a float) or
`choice: [a, b, ...]` (one of the items, any YAML value) is replaced by what it draws, anywhere in the file
but `matrix:`; a `pose:` written `{within: REGION, z: Z, yaw: YAW}` becomes `{xyz: [x, y, Z], rpy: [0, 0,
yaw]}` with (x, y) uniform over the region's area (REGION as the assertions write it: `{center: [x, y],
radius: r}` or `{min: [x, y], max: [x, y]}`; `z` 0 by default; `yaw` a number, or `[lo, hi]` drawn
uniformly, 0 by default). This happens on the raw data, before the schema sees it, so that every field that
takes a number takes a draw, plugin `params:` included.

The draws of one run come from `numpy.random.default_rng([seed, sample])` (the scenario's `seed:` as the
variant has it, and the index of `matrix: {samples: N}`, 0 without), in the order the file writes them:
the same file and seed give the same values on every machine. Drawn floats are rounded to 6 decimals.
Whether a drawn pose is free (no robot starting inside a wall) needs the compiled model: the compile layer
checks it (`runner.compile.placement`) and redraws from the same generator (`Draws.redraw`).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from runner.errors import Problem, ScenarioError, format_path
from runner.scenario.loader import Document, PathKey

DRAWS = ("uniform", "normal", "choice")
POSE_KEYS = ("within", "z", "yaw")
DECIMALS = 6  # drawn floats are rounded: readable labels, values that read back the same from YAML
REGION_HINT = "a region is `{center: [x, y], radius: r}` or `{min: [x, y], max: [x, y]}`"


@dataclass
class Drawn:
    """One value drawn, at `path` in the document. A pose drawn `within` a region keeps what it was drawn
    from (`region`, `z`, `yaw`), so that the compile layer can draw it again if it starts in collision."""

    path: PathKey
    value: Any
    # ("circle", (cx, cy, r)) or ("box", (x0, y0, x1, y1))
    region: tuple[str, tuple[float, ...]] | None = None
    z: float = 0.0
    yaw: tuple[float, float] = (0.0, 0.0)

    def shown(self) -> str:
        """`path=value`, short (`text`)."""
        return f"{format_path(self.path)}={text(self.value)}"


@dataclass
class Draws:
    """The values drawn for one run, in the file's order, and the generator they came from (its state
    after the last one: a redraw goes on from there, so redraws are as repeatable as the first draws)."""

    items: list[Drawn]
    rng: np.random.Generator
    prefix: list[str] | None = None  # the variant's label before its drawn values; None: an unlabelled run
    seed: int = 0
    sample: int = 0

    def label(self) -> str:
        """The variant's label: its matrix values, `sample=i`, then its drawn values ("" unlabelled)."""
        if self.prefix is None:
            return ""
        return ",".join([*self.prefix, *(d.shown() for d in self.items)])

    def values(self) -> dict[str, Any]:
        """{path: value} of every draw (the plan keeps them: the report shows them)."""
        return {format_path(d.path): copy.deepcopy(d.value) for d in self.items}

    def poses(self) -> list[Drawn]:
        """The poses drawn within a region, in the file's order."""
        return [d for d in self.items if d.region is not None]

    def redraw(self, item: Drawn) -> dict[str, Any]:
        """Another pose for `item`, drawn from the same generator (not yet accepted: `accept`)."""
        assert item.region is not None
        return _pose(self.rng, item.region, item.z, item.yaw)

    def accept(self, data: Any, item: Drawn, pose: dict[str, Any]) -> None:
        """`pose` becomes `item`'s value, in the record and in the document's data."""
        item.value = pose
        node = data
        for key in item.path[:-1]:
            node = node[key]
        node[item.path[-1]] = copy.deepcopy(pose)


@dataclass
class DrawnDocument(Document):
    """A document whose draws were made (a variant of `runner.scenario.matrix.variants`): the data holds
    the drawn values, `draws` says which and where."""

    draws: Draws | None = field(default=None)


def has_draws(data: Any, path: PathKey = ()) -> bool:
    """Whether `data` (a scenario's, `matrix:` aside) writes any draw."""
    return _has_draws(data, path[-1] if path else None, top=not path)


def _has_draws(data: Any, key: Any, top: bool) -> bool:
    # (the parent's key, not the whole path: building a path per value of a long timeline cost seconds)
    if isinstance(data, dict):
        if _draw_key(data) is not None or (key == "pose" and "within" in data):
            return True
        return any(_has_draws(v, k, False) for k, v in data.items() if not (top and k == "matrix"))
    if isinstance(data, list):
        return any(_has_draws(v, None, False) for v in data)
    return False


def seed_of(data: Any) -> int:
    """The scenario's `seed:` (0 when missing; a wrong one is the schema's to report)."""
    seed = data.get("seed", 0) if isinstance(data, dict) else 0
    return seed if isinstance(seed, int) and not isinstance(seed, bool) and seed >= 0 else 0


def draw(doc: Document, data: Any, sample: int = 0, prefix: list[str] | None = None) -> Draws:
    """Replace every draw in `data` (in place) by a value drawn for `sample` from the seed `data` holds;
    every mistake in the draws at once as a ScenarioError (located in `doc`)."""
    seed = seed_of(data)
    walk = _Walk(doc, np.random.default_rng([seed, sample]))
    if isinstance(data, dict):
        for key in list(data):
            if key != "matrix":
                data[key] = walk.value(data[key], (key,))
    if walk.problems:
        raise ScenarioError(walk.problems)
    return Draws(walk.items, walk.rng, prefix, seed, sample)


class _Walk:
    """One pass over the data in the file's order, drawing as it goes."""

    def __init__(self, doc: Document, rng: np.random.Generator) -> None:
        self.doc = doc
        self.rng = rng
        self.items: list[Drawn] = []
        self.problems: list[Problem] = []

    def value(self, node: Any, path: PathKey) -> Any:
        if isinstance(node, list):
            return [self.value(v, (*path, i)) for i, v in enumerate(node)]
        if not isinstance(node, dict):
            return node
        if path[-1:] == ("pose",) and "within" in node:
            return self.pose(node, path)
        key = _draw_key(node)
        if key is None:
            return {k: self.value(v, (*path, k)) for k, v in node.items()}
        others = [k for k in node if k != key]
        if others:
            self.problem(
                "a draw is a mapping of one key",
                path,
                expected=f"`{{{key}: ...}}` alone",
                found=f"also {', '.join(map(repr, others))}",
                hint="write the other keys beside the draw, not in it",
            )
            return node
        got = getattr(self, key)(node[key], (*path, key))
        if got is _BAD:
            return node
        if key == "choice":  # a chosen item may itself draw: its value is the choice's, recorded once
            n = len(self.items)
            got = self.value(got, path)
            self.items[n:] = [d for d in self.items[n:] if d.path != path]
        self.items.append(Drawn(path, got))
        return got

    def problem(self, message: str, path: PathKey, **kw: Any) -> None:
        self.problems.append(Problem(message, self.doc.locate(path), path, **kw))

    def uniform(self, spec: Any, path: PathKey) -> Any:
        lo_hi = self.bounds(spec, path, "uniform", "[lo, hi]", "e.g. `{uniform: [0.2, 0.5]}`")
        if lo_hi is None:
            return _BAD
        lo, hi = lo_hi
        if lo > hi:
            self.problem(
                "the lower bound is above the upper one",
                path,
                expected="[lo, hi] with lo <= hi",
                found=repr(spec),
                hint=f"write `[{_num(hi)}, {_num(lo)}]`",
            )
            return _BAD
        return _round(float(self.rng.uniform(lo, hi)))

    def normal(self, spec: Any, path: PathKey) -> Any:
        pair = self.bounds(spec, path, "normal", "[mean, stddev]", "e.g. `{normal: [0.3, 0.05]}`")
        if pair is None:
            return _BAD
        mean, stddev = pair
        if stddev < 0:
            self.problem(
                "a standard deviation is 0 or more",
                path,
                expected="[mean, stddev] with stddev >= 0",
                found=repr(spec),
            )
            return _BAD
        return _round(float(self.rng.normal(mean, stddev)))

    def choice(self, spec: Any, path: PathKey) -> Any:
        if not isinstance(spec, list) or not spec:
            self.problem(
                "`choice` picks one item of a list",
                path,
                expected="a non-empty list of values",
                found=repr(spec),
                hint="e.g. `{choice: [0.2, 0.4, 0.6]}` or `{choice: [[0, 0, 0.06], [1, 1, 0.06]]}`",
            )
            return _BAD
        return copy.deepcopy(spec[int(self.rng.integers(len(spec)))])

    def bounds(self, spec: Any, path: PathKey, key: str, shape: str, hint: str) -> tuple[float, float] | None:
        if isinstance(spec, list) and len(spec) == 2 and all(_is_number(v) for v in spec):
            return float(spec[0]), float(spec[1])
        self.problem(f"`{key}` takes two numbers", path, expected=shape, found=repr(spec), hint=hint)
        return None

    def pose(self, node: dict[str, Any], path: PathKey) -> Any:
        """`{within: REGION, z: Z, yaw: YAW}` -> `{xyz: [...], rpy: [0, 0, yaw]}`, or the node as it was
        (its mistakes recorded)."""
        before = len(self.problems)
        unknown = [k for k in node if k not in POSE_KEYS]
        if unknown:
            self.problem(
                f"unknown key(s) in a pose drawn within a region: {', '.join(map(repr, unknown))}",
                path,
                expected="`within:`, and optionally `z:` and `yaw:`",
                found=repr(sorted(map(str, node))),
                hint="a drawn pose is `{within: REGION, z: 0.05, yaw: [-3.14, 3.14]}`; "
                "for a fixed pose write `xyz:` and `rpy:` without `within`",
            )
        region = self.region(node["within"], (*path, "within"))
        z = node.get("z", 0.0)
        if not _is_number(z):
            self.problem("`z` is a height in metres", (*path, "z"), expected="a number", found=repr(z))
        yaw = self.yaw(node.get("yaw", 0.0), (*path, "yaw"))
        if len(self.problems) > before or region is None or yaw is None:
            return node
        pose = _pose(self.rng, region, float(z), yaw)
        self.items.append(Drawn(path, pose, region, float(z), yaw))
        return pose

    def yaw(self, spec: Any, path: PathKey) -> tuple[float, float] | None:
        if _is_number(spec):
            return float(spec), float(spec)
        pair = self.bounds(spec, path, "yaw", "a number, or [lo, hi] radians", "e.g. `yaw: [-3.14, 3.14]`")
        if pair is not None and pair[0] > pair[1]:
            self.problem("the lower bound is above the upper one", path, expected="[lo, hi] with lo <= hi")
            return None
        return pair

    def region(self, spec: Any, path: PathKey) -> tuple[str, tuple[float, ...]] | None:
        if not isinstance(spec, dict):
            self.problem("`within` takes a region", path, expected=REGION_HINT, found=repr(spec))
            return None
        keys = set(spec)
        if keys == {"center", "radius"}:
            c, r = spec["center"], spec["radius"]
            if _pair(c) and _is_number(r) and r > 0:
                return "circle", (float(c[0]), float(c[1]), float(r))
        elif keys == {"min", "max"}:
            lo, hi = spec["min"], spec["max"]
            if _pair(lo) and _pair(hi) and lo[0] < hi[0] and lo[1] < hi[1]:
                return "box", (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
            if _pair(lo) and _pair(hi):
                self.problem(
                    "the region's max must exceed its min on both axes",
                    path,
                    expected="min [x0, y0] below max [x1, y1]",
                    found=f"min {lo}, max {hi}",
                )
                return None
        self.problem(
            "not a region",
            path,
            expected=REGION_HINT + " (a radius above 0)",
            found=repr(spec),
        )
        return None


_BAD = object()  # what a draw with a mistake gives (the mistake is recorded)


def _pose(
    rng: np.random.Generator, region: tuple[str, tuple[float, ...]], z: float, yaw: tuple[float, float]
) -> dict[str, Any]:
    """A pose uniform over the region's area (a circle: the radius as r*sqrt(u)), at height `z`, its yaw
    uniform in `yaw` (a fixed one when both ends are equal: nothing is drawn for it)."""
    kind, v = region
    if kind == "circle":
        cx, cy, r = v
        rho, phi = r * math.sqrt(float(rng.uniform())), float(rng.uniform(0.0, 2 * math.pi))
        x, y = cx + rho * math.cos(phi), cy + rho * math.sin(phi)
    else:
        x, y = float(rng.uniform(v[0], v[2])), float(rng.uniform(v[1], v[3]))
    heading = yaw[0] if yaw[0] == yaw[1] else float(rng.uniform(*yaw))
    return {"xyz": [_round(x), _round(y), z], "rpy": [0.0, 0.0, _round(heading)]}


def _draw_key(node: dict[Any, Any]) -> str | None:
    """The draw a mapping writes, if it is one: a key of DRAWS whose value is not a mapping (message data
    may have a field named `normal` holding a vector: that is no draw)."""
    return next((k for k in DRAWS if k in node and not isinstance(node[k], dict)), None)


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _pair(v: Any) -> bool:
    return isinstance(v, list) and len(v) == 2 and all(_is_number(x) for x in v)


def _round(v: float) -> float:
    return round(v, DECIMALS) + 0.0  # (+ 0.0: no -0.0)


def _num(v: Any) -> str:
    return f"{round(v, 3) + 0.0:g}" if isinstance(v, float) else str(v)


def shown(values: dict[str, Any]) -> str:
    """{path: value} (a plan's `drawn`) as `path=value,...`, each value short (`text`)."""
    return ",".join(f"{path}={text(v)}" for path, v in values.items())


def text(value: Any) -> str:
    """A drawn value, short: floats to 3 decimals, a pose as `[x, y, z, yaw Y]`, at most 40 characters (as a
    matrix's labels)."""
    if isinstance(value, dict) and set(value) == {"xyz", "rpy"}:
        x, y, z = value["xyz"]
        out = f"[{_num(x)}, {_num(y)}, {_num(z)}, yaw {_num(value['rpy'][2])}]"
    else:
        out = _short(value)
    return out if len(out) <= 40 else out[:37] + "..."


def _short(value: Any) -> str:
    if isinstance(value, float):
        return _num(value)
    if isinstance(value, list):
        return "[" + ", ".join(_short(v) for v in value) + "]"
    return str(value).replace("'", "")
