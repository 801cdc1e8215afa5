"""Hypothesis strategies for scenario documents, and the property every input must keep.

Used by tests/test_fuzz.py (a bounded run in the test suite) and bench/fuzz.py (a long run). The property:
reading, validating and compiling a scenario either succeeds or raises `ScenarioError` (never another
exception), and every `Problem` it holds says where it is (file and line).

- `scenarios()`: valid-shaped documents: names, durations, rates, robots (the project's diffbot) with plugins
  from the registry and plausible parameters, timeline entries, assertions, nodes, hosts, bridges, matrix;
- `mutated()`: those documents with keys deleted or misspelt, values replaced by values of other types
  (None, lists, mappings, huge/negative/NaN/inf numbers, unicode, `*`, `/`, empty strings), items
  duplicated;
- `yaml_texts()`: the YAML text of either, cut, spliced and re-indented at random places.
"""

from __future__ import annotations

import math
import random
import re
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from hypothesis import strategies as st
from pydantic import BaseModel

from runner.errors import ScenarioError

REPO = Path(__file__).resolve().parents[1]
# Documents are read as if from this file (never written): robot paths are relative to scenarios/.
SCENARIO_FILE = REPO / "scenarios" / "_fuzz.yaml"
DIFFBOT = "robots/diffbot.urdf.xacro"
LINKS = ["base_link", "left_wheel", "right_wheel", "caster", "lidar_link", "imu_link"]
WHEELS = ["left_wheel_joint", "right_wheel_joint"]
TYPES = {
    "geometry_msgs/msg/Twist": lambda v: {"linear": {"x": v}, "angular": {"z": -v}},
    "std_msgs/msg/Float64": lambda v: {"data": v},
    "std_msgs/msg/String": lambda v: {"data": str(v)},
    "std_msgs/msg/Empty": lambda v: {},
}

ident = st.from_regex(r"[a-z][a-z0-9_]{0,6}", fullmatch=True)
finite = st.floats(min_value=-100, max_value=100, allow_nan=False, allow_infinity=False)
positive = st.floats(min_value=0.01, max_value=200, allow_nan=False)
vec3 = st.lists(finite, min_size=3, max_size=3)
topic_name = st.one_of(ident, st.builds(lambda a, b: f"{a}/{b}", ident, ident))


# ------------------------------------------------------------------------------------ valid-shaped
def _annotation_values(tp: Any, depth: int = 0) -> st.SearchStrategy[Any] | None:
    """Plausible values of a plugin parameter's type (None where we have no idea)."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin is typing.Literal:
        return st.sampled_from(args)
    if origin in (typing.Union, types.UnionType):
        options = [s for a in args if (s := _annotation_values(a, depth)) is not None]
        return st.one_of(options) if options else None
    if origin is typing.Annotated:
        return _annotation_values(args[0], depth)
    if origin is tuple and args and Ellipsis not in args:
        parts = [_annotation_values(a, depth) for a in args]
        return None if any(p is None for p in parts) else st.tuples(*parts).map(list)  # type: ignore[misc]
    if origin is list and args:
        inner = _annotation_values(args[0], depth)
        return None if inner is None else st.lists(inner, min_size=1, max_size=3)
    if tp is type(None):
        return st.none()
    if tp is bool:
        return st.booleans()
    if tp is int:
        return st.integers(1, 400)
    if tp is float:
        return st.floats(0.0, 5.0)
    if tp is str:
        return topic_name
    if isinstance(tp, type) and issubclass(tp, BaseModel) and depth < 2:
        return model_params(tp, depth + 1)
    return None


def model_params(model: type[BaseModel], depth: int = 0) -> st.SearchStrategy[dict[str, Any]]:
    """A mapping of some of `model`'s fields to plausible values (named fields get fitting ones)."""
    optional: dict[str, st.SearchStrategy[Any]] = {}
    required: dict[str, st.SearchStrategy[Any]] = {}
    for name, info in model.model_fields.items():
        if name == "link":
            values: st.SearchStrategy[Any] | None = st.sampled_from(LINKS)
        elif name in ("left_joint", "right_joint"):
            values = st.just(WHEELS[name.startswith("right")])
        elif name in ("left_joints", "right_joints"):
            values = st.just([WHEELS[name.startswith("right")]])
        elif name == "near":
            values = st.floats(0.01, 0.1)
        elif name == "far":
            values = st.floats(5, 100)
        elif name == "joints":
            values = st.lists(st.sampled_from(WHEELS), min_size=1, max_size=2, unique=True)
        elif name == "rate":
            values = positive
        elif name in ("width", "height"):
            values = st.integers(8, 320)
        elif name == "initial":
            values = st.none()
        else:
            values = _annotation_values(info.annotation, depth)
        if values is None:
            continue
        (required if info.is_required() else optional)[name] = values
    return st.fixed_dictionaries(required, optional=optional)


def plugin_entries() -> st.SearchStrategy[dict[str, Any]]:
    """`{type, params}` for every plugin in the registry (one that fails to load is a type name only)."""
    from runner.plugin.registry import PluginLookupError, available, load

    options = []
    for name in available():
        try:
            params: st.SearchStrategy[dict[str, Any]] = model_params(load(name).Params)
        except PluginLookupError:
            params = st.just({})
        options.append(st.fixed_dictionaries({"type": st.just(name)}, optional={"params": params}))
    return st.one_of(options)


def _region() -> st.SearchStrategy[dict[str, Any]]:
    circle = st.fixed_dictionaries(
        {"center": st.lists(finite, min_size=2, max_size=2), "radius": st.floats(0.1, 10)}
    )
    box = st.builds(
        lambda x, y, w, h: {"min": [x, y], "max": [x + w, y + h]},
        finite,
        finite,
        st.floats(0.1, 10),
        st.floats(0.1, 10),
    )
    return st.one_of(circle, box)


def _assertion(
    robots: list[str], models: list[str], prefix: dict[str, str]
) -> st.SearchStrategy[dict[str, Any]]:
    robot = st.sampled_from(robots) if robots else ident
    scan = robot.map(lambda r: f"{prefix.get(r, r)}/scan")
    point = st.lists(finite, min_size=2, max_size=2)
    kinds = [
        st.fixed_dictionaries(
            {"type": st.just("reach"), "robot": robot, "point": point},
            optional={"tolerance": st.floats(0.05, 2), "by": st.floats(0.1, 20)},
        ),
        st.fixed_dictionaries(
            {"type": st.just("stay_within"), "robot": robot, "region": _region()},
            optional={"inside": st.booleans(), "after": st.floats(0, 2)},
        ),
        st.fixed_dictionaries(
            {
                "type": st.just("no_collision"),
                "between": st.lists(st.sampled_from([*robots, *models, "ground"]), min_size=1, max_size=3),
            }
        ),
        st.fixed_dictionaries(
            {"type": st.just("topic_rate"), "topic": scan},
            optional={"min": st.floats(0, 5), "max": st.floats(5, 100)},
        ),
        st.fixed_dictionaries(
            {
                "type": st.just("message"),
                "topic": scan,
                "expr": st.sampled_from(["ranges.min() > 0.1", "len(ranges) > 0", "range_max >= 1"]),
            },
            optional={"mode": st.sampled_from(["always", "eventually", "never"])},
        ),
        st.fixed_dictionaries({"type": st.just("max_speed"), "robot": robot, "max": st.floats(0.1, 5)}),
        st.fixed_dictionaries({"type": st.just("max_tilt"), "robot": robot, "max": st.floats(0.1, 1.5)}),
        st.fixed_dictionaries(
            {"type": st.just("distance_traveled"), "robot": robot},
            optional={"min": st.floats(0, 1), "max": st.floats(1, 10)},
        ),
    ]
    return st.one_of(kinds)


@st.composite
def scenarios(draw: st.DrawFn) -> dict[str, Any]:
    """A scenario document that is meant to be valid (mistakes it makes by chance are fine)."""
    duration = draw(st.floats(0.5, 30))
    doc: dict[str, Any] = {"name": draw(ident), "duration": duration}
    if draw(st.booleans()):
        doc["rate"] = draw(st.one_of(st.sampled_from(["realtime", "max"]), st.floats(0.1, 50)))
    if draw(st.booleans()):
        doc["seed"] = draw(st.integers(0, 2**31))
    names = draw(st.lists(ident, max_size=3, unique=True))
    robots = names[:2]
    models = [f"m_{n}" for n in names[2:]]
    worlds = draw(st.sampled_from([[], [], [], ["arena"], ["arena", "yard"]]))
    world: dict[str, Any] = {}
    if draw(st.booleans()):
        world["physics"] = draw(
            st.fixed_dictionaries(
                {},
                optional={
                    "timestep": st.floats(0.0005, 0.01),
                    "gravity": vec3,
                    "integrator": st.sampled_from(["euler", "implicitfast", "implicit", "rk4"]),
                },
            )
        )
    if models:
        shape = draw(st.sampled_from(["box", "cylinder", "sphere"]))
        size = {"box": 3, "cylinder": 2, "sphere": 1}[shape]
        world["models"] = [
            {
                "name": m,
                "shape": shape,
                "size": draw(st.lists(st.floats(0.05, 3), min_size=size, max_size=size)),
                "pose": {"xyz": [draw(finite), draw(finite), 0.5]},
                "static": draw(st.booleans()),
            }
            for m in models
        ]
    if worlds:
        doc["worlds"] = [{"name": w, **world} for w in worlds]
    elif world:
        doc["world"] = world
    entries = plugin_entries()
    doc["robots"] = []
    for i, r in enumerate(robots):
        desc: Any = DIFFBOT
        if draw(st.booleans()):
            desc = {
                "file": DIFFBOT,
                "args": {"color": "0.2 0.4 0.8 1", "wheel_radius": draw(st.floats(0.03, 0.1))},
            }
        robot: dict[str, Any] = {"name": r, "description": desc, "pose": {"xyz": [2.0 * i, 0.0, 0.06]}}
        plugins = draw(st.lists(entries, max_size=3, unique_by=lambda p: p["type"]))
        if plugins:
            robot["plugins"] = plugins
        if draw(st.booleans()):
            robot["namespace"] = f"ns_{r}"
        if worlds:
            robot["world"] = worlds[i % len(worlds)]
        doc["robots"].append(robot)
    prefix = {
        r["name"]: (f"{r['world']}/" if worlds else "") + r.get("namespace", r["name"]) for r in doc["robots"]
    }
    if robots and draw(st.booleans()):
        doc["timeline"] = [
            {
                "t": draw(st.floats(0, duration)),
                "topic": f"{prefix[draw(st.sampled_from(robots))]}/cmd_vel",
                "type": (kind := draw(st.sampled_from(sorted(TYPES)))),
                "data": TYPES[kind](draw(finite)),
            }
            for _ in range(draw(st.integers(1, 3)))
        ]
    if draw(st.booleans()):
        found = draw(st.lists(_assertion(robots, models, prefix), max_size=3))
        doc["assertions"] = [{"name": f"check_{k}", **a} for k, a in enumerate(found)]
    if draw(st.booleans()):
        doc["record"] = draw(
            st.fixed_dictionaries(
                {},
                optional={
                    "include": st.lists(st.sampled_from(["**", "*/scan", "r1/**", "clock"]), max_size=3),
                    "exclude": st.lists(st.sampled_from(["*/camera/**", "*/tf"]), max_size=2),
                    "enabled": st.booleans(),
                },
            )
        )
    if draw(st.integers(0, 4)) == 0:
        doc["nodes"] = [{"name": "ctl", "cmd": "python -c pass", "required": draw(st.booleans())}]
        if draw(st.booleans()):
            doc["lockstep"] = ["ctl"]
    if draw(st.integers(0, 5)) == 0:
        doc["hosts"] = {
            "main": {"endpoint": "tcp/127.0.0.1:7447"},
            "other": {"endpoint": "tcp/10.0.0.2:7447"},
        }
        if "world" in doc:
            doc["world"]["host"] = draw(st.sampled_from(["main", "other"]))
    if robots and draw(st.integers(0, 5)) == 0:
        doc["bridges"] = [
            {
                "topic": f"{prefix[robots[0]]}/cmd_vel",
                "direction": "ZENOH_TO_SIM",
                "type": "geometry_msgs/msg/Twist",
            }
        ]
    if draw(st.integers(0, 5)) == 0:
        doc["matrix"] = {"seed": [1, 2]}
        if robots:
            doc["matrix"]["robots[0].pose.xyz"] = [[0, 0, 0.06], [1, 1, 0.06]]
    if draw(st.integers(0, 5)) == 0:
        doc["stop_on"] = draw(st.sampled_from(["never", "first_failure", "all_decided"]))
    return doc


def examples() -> st.SearchStrategy[dict[str, Any]]:
    """The project's example scenarios (SDF worlds, Gazebo-tagged robots, bridge files, packages, nodes)."""
    docs = []
    for path in sorted((REPO / "scenarios").glob("*.yaml")):
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
        if isinstance(data, dict) and not path.name.startswith("_"):
            docs.append(data)
    return st.sampled_from(docs)


# ------------------------------------------------------------------------------------------ mutated
ODD_NUMBERS = [
    0,
    -1,
    -0.0,
    10**30,
    -(10**30),
    2**63,
    2**64 + 1,
    1e308,
    -1e308,
    5e-324,
    math.nan,
    math.inf,
    -math.inf,
]
ODD_TEXT = [
    "",
    " ",
    "*",
    "**",
    "/",
    "//",
    "$",
    "$*",
    "a b",
    "☃",
    "ü/*",
    "r1/",
    "/r1",
    "../x",
    "\t",
    "?",
    "#",
    "-1",
]
odd_values: st.SearchStrategy[Any] = st.one_of(
    st.none(),
    st.booleans(),
    st.sampled_from(ODD_NUMBERS),
    st.integers(-(10**40), 10**40),
    st.floats(),
    st.sampled_from(ODD_TEXT),
    st.text(max_size=12),
    st.lists(st.one_of(st.none(), st.integers(), st.text(max_size=3)), max_size=4),
    st.dictionaries(
        st.text(max_size=4), st.one_of(st.none(), st.integers(), st.text(max_size=3)), max_size=3
    ),
)


def _paths(node: Any, here: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every path in a document (the root included)."""
    out = [here]
    if isinstance(node, dict):
        for k, v in node.items():
            out += _paths(v, (*here, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _paths(v, (*here, i))
    return out


def _typo(key: str, where: int) -> str:
    if len(key) < 2:
        return key + "x"
    i = where % (len(key) - 1)
    return key[:i] + key[i + 1] + key[i] + key[i + 2 :] if where % 2 else key[:i] + key[i + 1 :]


def _get(node: Any, path: tuple[Any, ...]) -> Any:
    for el in path:
        node = node[el]
    return node


@st.composite
def mutated(draw: st.DrawFn, base: st.SearchStrategy[dict[str, Any]] | None = None) -> Any:
    """A scenario document with one to four mistakes."""
    import copy

    doc: Any = copy.deepcopy(draw(base if base is not None else st.one_of(scenarios(), examples())))
    # Any path alike: hypothesis favours small numbers (sampled_from would favour the first paths), so the
    # places to damage come from a random generator it seeds.
    rnd = random.Random(draw(st.integers(0, 2**32 - 1)))
    for _ in range(draw(st.integers(1, 4))):
        paths = _paths(doc)
        path = () if len(paths) == 1 or rnd.random() < 0.01 else rnd.choice(paths[1:])
        op = draw(
            st.sampled_from(["replace", "replace", "delete", "rename", "insert", "duplicate", "wrap", "copy"])
        )
        if not path:
            if op == "replace":
                doc = draw(odd_values)
            continue
        parent = _get(doc, path[:-1])
        last = path[-1]
        if op == "replace":
            parent[last] = draw(odd_values)
        elif op == "delete":
            del parent[last]
        elif op == "rename" and isinstance(parent, dict):
            new = draw(
                st.one_of(st.just(_typo(str(last), draw(st.integers(0, 20)))), st.sampled_from(ODD_TEXT))
            )
            parent[new] = parent.pop(last)
        elif op == "insert" and isinstance(parent, dict):
            parent[draw(st.one_of(st.sampled_from(ODD_TEXT), ident))] = draw(odd_values)
        elif op == "duplicate" and isinstance(parent, list):
            parent.insert(last, copy.deepcopy(parent[last]))
        elif op == "wrap":
            parent[last] = [parent[last]]
        elif op == "copy":  # a value from elsewhere in the document: the right kind of thing, misplaced
            source = rnd.choice(paths[1:])
            if path[: len(source)] != source and source[: len(path)] != path:
                parent[last] = copy.deepcopy(_get(doc, source))
    return doc


def to_yaml(doc: Any) -> str:
    return yaml.safe_dump(doc, sort_keys=False, allow_unicode=True, default_flow_style=None)


CUTS = [
    "\t",
    ":",
    " ",
    "  ",
    "[",
    "]",
    "{",
    "}",
    '"',
    "'",
    "-",
    "- ",
    "\n",
    "#",
    "&a",
    "*a",
    "!!",
    "? ",
    "%",
    "@",
    ",",
]


@st.composite
def yaml_texts(draw: st.DrawFn) -> str:
    """The YAML text of a valid-shaped or mutated document, damaged at one to three places."""
    text = to_yaml(draw(st.one_of(scenarios(), mutated())))
    for _ in range(draw(st.integers(1, 3))):
        if not text:
            break
        at = draw(st.integers(0, len(text)))
        op = draw(st.sampled_from(["insert", "delete", "dup_line", "swap_lines", "indent", "dedent"]))
        lines = text.splitlines(keepends=True)
        row = min(text.count("\n", 0, at), len(lines) - 1) if lines else 0
        if op == "insert":
            text = text[:at] + draw(st.sampled_from(CUTS)) + text[at:]
        elif op == "delete":
            text = text[:at] + text[at + draw(st.integers(1, 12)) :]
        elif op == "dup_line" and lines:
            lines.insert(row, lines[row])
            text = "".join(lines)
        elif op == "swap_lines" and len(lines) > 1:
            other = draw(st.integers(0, len(lines) - 1))
            lines[row], lines[other] = lines[other], lines[row]
            text = "".join(lines)
        elif op == "indent" and lines:
            lines[row] = "  " + lines[row]
            text = "".join(lines)
        elif op == "dedent" and lines:
            lines[row] = lines[row][min(2, len(lines[row]) - len(lines[row].lstrip(" "))) :]
            text = "".join(lines)
    return text


# ------------------------------------------------------------------------------- description files
DESCRIPTIONS = [
    REPO / "scenarios" / "robots" / "diffbot.urdf.xacro",
    REPO / "tests" / "data" / "liftbot.urdf",
    REPO / "tests" / "data" / "skidbot.urdf",
    REPO / "tests" / "data" / "gazebo" / "classic_bot.urdf",
    REPO / "scenarios" / "worlds" / "nav_world.sdf",
]
ODD_XML = ["-1", "0", "nan", "inf", "-inf", "1e400", "abc", "", " ", "1 2", "${x}", "$(arg y)", "&", "<", '"']
_NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e-?\d+)?")
_ATTRIBUTE = re.compile(r'\s[\w:]+="[^"]*"')
_TAG = re.compile(r"<(/?)([\w:]+)")


@st.composite
def descriptions(draw: st.DrawFn) -> tuple[str, str]:
    """(file name, text) of a robot description or SDF world of the project, damaged at one to three
    places: a number replaced by odd text, an attribute or a line dropped, a line doubled, a tag renamed."""
    source = draw(st.sampled_from(DESCRIPTIONS))
    text = source.read_text(encoding="utf-8")
    rnd = random.Random(draw(st.integers(0, 2**32 - 1)))
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["number", "number", "attribute", "drop_line", "dup_line", "tag", "char"]))
        lines = text.splitlines(keepends=True)
        row = rnd.randrange(len(lines))
        if op == "number" and (found := list(_NUMBER.finditer(text))):
            m = rnd.choice(found)
            text = text[: m.start()] + draw(st.sampled_from(ODD_XML)) + text[m.end() :]
        elif op == "attribute" and (found := list(_ATTRIBUTE.finditer(text))):
            m = rnd.choice(found)
            text = text[: m.start()] + text[m.end() :]
        elif op == "drop_line":
            text = "".join(lines[:row] + lines[row + 1 :])
        elif op == "dup_line":
            text = "".join(lines[: row + 1] + lines[row:])
        elif op == "tag" and (found := list(_TAG.finditer(text))):
            m = rnd.choice(found)
            text = (
                text[: m.start(2)]
                + draw(st.sampled_from(["link", "joint", "mass", "sensor", "x"]))
                + text[m.end(2) :]
            )
        elif op == "char":
            at = rnd.randrange(len(text) + 1)
            text = text[:at] + draw(st.sampled_from(["<", ">", "&", '"', "/", "\n"])) + text[at:]
    return source.name, text


def check_description(name: str, text: str, outcome: Outcome | None = None) -> None:
    """A scenario using the damaged file (as its robot, or its world) is read, validated and compiled:
    success or a located `ScenarioError`, as for `check`."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="fuzz-") as tmp:
        folder = Path(tmp)
        (folder / name).write_text(text, encoding="utf-8")
        if name.endswith((".sdf", ".world")):
            scenario = f"name: fuzz\nworld: {{sdf: {name}}}\n"
        else:
            scenario = f"name: fuzz\nrobots:\n  - name: r1\n    description: {name}\n    plugins: [{{type: joint_states}}]\n"
        check(scenario, True, outcome, folder / "scenario.yaml")


# ------------------------------------------------------------------------------------------ property
@dataclass
class Outcome:
    ok: int = 0
    errors: int = 0
    compiled: int = 0
    messages: list[str] = field(default_factory=list)


def check(text: str, compile_it: bool, outcome: Outcome | None = None, file: Path = SCENARIO_FILE) -> None:
    """Read, validate (every matrix variant) and, if asked, compile `text` (as if read from `file`): it must
    succeed or raise a `ScenarioError` whose problems all say where they are. Anything else propagates."""
    from runner.compile import compile_plan
    from runner.scenario.loader import load_text
    from runner.scenario.matrix import variants
    from runner.scenario.validate import validate_scenario

    outcome = outcome if outcome is not None else Outcome()
    try:
        doc = load_text(text, file)
        for _, variant in variants(doc)[:2]:
            sc = validate_scenario(variant)
            if compile_it:
                compile_plan(sc, variant)
                outcome.compiled += 1
    except ScenarioError as e:
        outcome.errors += 1
        check_problems(e, file)
        outcome.messages.append(e.render())
        return
    outcome.ok += 1


def check_problems(e: ScenarioError, file: Path = SCENARIO_FILE) -> None:
    """Every problem renders, names its file, and has a line, or comes with a problem that has one in
    the scenario (a robot's xacro error, then `while loading robot 'r1'` at the scenario's line)."""
    assert e.problems, "a ScenarioError without problems"
    in_scenario = any(p.location.file == file and p.location.line is not None for p in e.problems)
    for p in e.problems:
        text = p.render()
        assert isinstance(p.message, str) and p.message, repr(p)
        assert p.location.file is not None, f"no file: {text}"
        assert p.location.line is not None or in_scenario, f"no line: {text}"
        assert text.startswith(str(p.location)), text
    e.render()
