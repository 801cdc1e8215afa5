"""`runner.tools.graph_draw`: the run's graph as DOT text, as a PNG drawn with Pillow, and as terminal lines.

Plain unit tests on graphs built by hand (no Zenoh session, no network)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageDraw

from runner.tools.graph_draw import (
    EDGE_BACK,
    process_id,
    render_png,
    short_type,
    summary_lines,
    to_dot,
    topic_id,
)
from runner.wire.graph import Endpoint, Graph

RUN = "demo"
TYPES = {
    "scan": "sensor_msgs/msg/LaserScan",
    "odom": "nav_msgs/msg/Odometry",
    "tf": "tf2_msgs/msg/TFMessage",
    "cmd_vel": "geometry_msgs/msg/Twist",
    "clock": "rosgraph_msgs/msg/Clock",
}


def two_robots(robots: tuple[str, ...] = ("r1", "r2"), extra_topics: int = 0) -> Graph:
    """What a two-robot run declares: the world publishes sensors and the clock and takes `cmd_vel`,
    the recorder takes everything, `scenario echo` listens to one scan, a controller drives r1."""
    g = Graph(RUN)
    g.processes.update({"world": "world", "recorder": "recorder", "echo-123": "tool", "controller": "node"})

    def ep(process: str, kind: str, rel: str, type_name: str | None) -> None:
        g.endpoints.add(Endpoint(process, kind, f"{RUN}/{rel}", type_name))

    ep("world", "pub", "clock", TYPES["clock"])
    for r in robots:
        for t in ("scan", "odom", "tf"):
            ep("world", "pub", f"{r}/{t}", TYPES[t])
        ep("world", "sub", f"{r}/cmd_vel", TYPES["cmd_vel"])
        for i in range(extra_topics):
            ep("world", "pub", f"{r}/extra_{i:02d}", "sensor_msgs/msg/Image")
    ep("recorder", "sub", "**", None)
    ep("echo-123", "sub", "r1/scan", TYPES["scan"])
    ep("controller", "pub", "r1/cmd_vel", TYPES["cmd_vel"])
    ep("controller", "sub", "r1/odom", TYPES["odom"])
    return g


ALL_TOPICS = ["clock"] + [f"{r}/{t}" for r in ("r1", "r2") for t in ("cmd_vel", "odom", "scan", "tf")]

# (from, to) by hand: "p:" a process, "t:" a topic inside the run
EXPECTED_EDGES = (
    {("p:world", f"t:{k}") for k in ALL_TOPICS if not k.endswith("cmd_vel")}
    | {("t:r1/cmd_vel", "p:world"), ("t:r2/cmd_vel", "p:world")}
    | {(f"t:{k}", "p:recorder") for k in ALL_TOPICS}  # through its `demo/**` wildcard
    | {("t:r1/scan", "p:echo-123"), ("p:controller", "t:r1/cmd_vel"), ("t:r1/odom", "p:controller")}
)


# ---------------------------------------------------------------------------------------------------------
# a small DOT reader, following Graphviz's scanner: in a quoted string `\"` is a quote and `\\` a pair


TOKEN = re.compile(r'\s*(?:(->|--|[{}\[\];,=])|"((?:[^"\\]|\\.)*)"|([A-Za-z0-9_.]+))', re.S)


def _tokens(text: str) -> list[tuple[str, str]]:
    out, pos = [], 0
    text = text.rstrip()
    while pos < len(text):
        m = TOKEN.match(text, pos)
        assert m, f"not DOT at {pos}: {text[pos : pos + 40]!r}"
        punct, quoted, bare = m.groups()
        if punct is not None:
            out.append(("p", punct))
        elif quoted is not None:
            out.append(("id", re.sub(r"\\([\\\"])", r"\1", quoted)))
        else:
            out.append(("id", bare))
        pos = m.end()
    return out


def parse_dot(text: str) -> tuple[dict[str, str], dict[str, dict[str, str]], list[tuple[str, str, dict]]]:
    """(graph attributes, nodes with their attributes, edges): fails on anything not DOT."""
    toks = _tokens(text)
    i = 0

    def take(kind: str, value: str | None = None) -> str:
        nonlocal i
        k, v = toks[i]
        assert k == kind and (value is None or v == value), (
            f"expected {value or kind}, got {v!r} at token {i}"
        )
        i += 1
        return v

    def attrs() -> dict[str, str]:
        nonlocal i
        out: dict[str, str] = {}
        if toks[i] != ("p", "["):
            return out
        take("p", "[")
        while toks[i] != ("p", "]"):
            key = take("id")
            take("p", "=")
            out[key] = take("id")
            if toks[i] == ("p", ","):
                take("p", ",")
        take("p", "]")
        return out

    take("id", "digraph")
    if toks[i][0] == "id":
        take("id")
    take("p", "{")
    graph_attrs: dict[str, str] = {}
    nodes: dict[str, dict[str, str]] = {}
    edges: list[tuple[str, str, dict]] = []
    while toks[i] != ("p", "}"):
        first = take("id")
        if first in ("graph", "node", "edge") and toks[i] == ("p", "["):
            a = attrs()
            if first == "graph":
                graph_attrs.update(a)
        elif toks[i] == ("p", "->"):
            take("p", "->")
            second = take("id")
            edges.append((first, second, attrs()))
        else:
            assert first not in nodes, f"node {first!r} declared twice"
            nodes[first] = attrs()
        if toks[i] == ("p", ";"):
            take("p", ";")
    take("p", "}")
    assert i == len(toks), "text after the graph"
    return graph_attrs, nodes, edges


def _short(dot_id: str) -> str:
    if dot_id.startswith("process:"):
        return "p:" + dot_id[len("process:") :]
    assert dot_id.startswith(f"topic:{RUN}/"), dot_id
    return "t:" + dot_id[len(f"topic:{RUN}/") :]


# ---------------------------------------------------------------------------------------------------------
# DOT


def test_dot_is_a_left_to_right_digraph_with_every_topic_and_process():
    graph_attrs, nodes, _ = parse_dot(to_dot(two_robots()))
    assert graph_attrs["rankdir"] == "LR"
    topics = {_short(n) for n, a in nodes.items() if a["shape"] == "box"}
    processes = {_short(n) for n, a in nodes.items() if a["shape"] == "ellipse"}
    assert topics == {f"t:{k}" for k in ALL_TOPICS}
    assert processes == {"p:world", "p:recorder", "p:echo-123", "p:controller"}
    assert len(nodes) == len(topics) + len(processes)


def test_dot_has_every_edge_wildcards_included_and_nothing_else():
    _, nodes, edges = parse_dot(to_dot(two_robots()))
    got = [(_short(a), _short(b)) for a, b, _ in edges]
    assert len(got) == len(set(got)), "an edge twice"
    assert set(got) == EXPECTED_EDGES
    for a, b, _ in edges:  # every edge joins declared nodes
        assert a in nodes and b in nodes
    wild = {(_short(a), _short(b)) for a, b, attrs in edges if attrs.get("style") == "dashed"}
    assert wild == {(f"t:{k}", "p:recorder") for k in ALL_TOPICS}


def test_dot_labels_topics_inside_the_run_with_short_types_and_colours_roles():
    _, nodes, _ = parse_dot(to_dot(two_robots()))
    assert nodes[topic_id(f"{RUN}/r1/scan")]["label"] == "r1/scan\\nsensor_msgs/LaserScan"
    assert nodes[topic_id(f"{RUN}/clock")]["label"] == "clock\\nrosgraph_msgs/Clock"
    fills = {n: nodes[process_id(n)]["fillcolor"] for n in ("world", "recorder", "echo-123", "controller")}
    assert len(set(fills.values())) == 4, fills


def test_dot_quotes_keys_and_names_with_odd_characters():
    g = Graph(RUN)
    odd_key = f'{RUN}/we"ird/%20 key\\'  # a quote, a percent, a space, a trailing backslash
    odd_proc = 'echo "q" \\ 1'
    g.processes[odd_proc] = "tool"
    g.endpoints.add(Endpoint("world", "pub", odd_key, 'pkg/msg/"T"'))
    g.endpoints.add(Endpoint(odd_proc, "sub", f"{RUN}/*/**", None))
    _, nodes, edges = parse_dot(to_dot(g))
    assert topic_id(odd_key) in nodes
    assert process_id(odd_proc) in nodes
    assert process_id("world") in nodes  # known only through its endpoint
    assert [(a, b) for a, b, _ in edges] == [
        (process_id("world"), topic_id(odd_key)),
        (topic_id(odd_key), process_id(odd_proc)),
    ]
    assert nodes[topic_id(odd_key)]["label"] == 'we"ird/%20 key\\\\npkg/"T"'


def test_dot_of_an_empty_graph():
    graph_attrs, nodes, edges = parse_dot(to_dot(Graph(RUN)))
    assert graph_attrs["rankdir"] == "LR"
    assert nodes == {} and edges == []


def test_short_type():
    assert short_type("sensor_msgs/msg/LaserScan") == "sensor_msgs/LaserScan"
    assert short_type("custom/Thing") == "custom/Thing"
    assert short_type(None) == ""


# ---------------------------------------------------------------------------------------------------------
# terminal lines


def test_summary_lines():
    lines = summary_lines(two_robots())
    assert len(lines) == len(ALL_TOPICS)
    by_key = {line.split()[0]: line for line in lines}
    assert set(by_key) == set(ALL_TOPICS)
    assert re.fullmatch(
        r"r1/scan +sensor_msgs/msg/LaserScan +pubs: world  subs: echo-123, recorder", by_key["r1/scan"]
    )
    assert by_key["r2/cmd_vel"].endswith("pubs: -  subs: recorder, world")
    assert by_key["r1/cmd_vel"].endswith("pubs: controller  subs: recorder, world")
    assert len({line.index("pubs:") for line in lines}) == 1  # columns line up
    assert summary_lines(Graph(RUN)) == []


# ---------------------------------------------------------------------------------------------------------
# PNG


@pytest.fixture
def drawn_texts(monkeypatch):
    """Every text the renderer draws: (text, bounding box in the drawing's pixels, drawing size)."""
    seen: list[tuple[str, tuple[float, float, float, float], tuple[int, int]]] = []
    original = ImageDraw.ImageDraw.text

    def text(self, xy, text, fill=None, font=None, anchor=None, *args, **kwargs):
        seen.append((text, self.textbbox(xy, text, font=font, anchor=anchor), self.im.size))
        return original(self, xy, text, fill, font, anchor, *args, **kwargs)

    monkeypatch.setattr(ImageDraw.ImageDraw, "text", text)
    return seen


def _render(graph: Graph, path: Path, **kwargs) -> Image.Image:
    render_png(graph, path, **kwargs)
    with Image.open(path) as im:
        im.verify()
    im = Image.open(path)
    assert im.format == "PNG"
    return im.convert("RGB")


def _ink(im: Image.Image) -> float:
    """Share of pixels that are not (near) white."""
    grey = im.convert("L")
    return sum(grey.histogram()[:240]) / (im.width * im.height)


def _pixels_near(im: Image.Image, rgb: tuple[int, int, int], tol: int = 30) -> int:
    diff = np.abs(np.asarray(im, dtype=np.int16) - np.array(rgb, dtype=np.int16))
    return int(np.count_nonzero((diff <= tol).all(axis=2)))


def _overlaps(boxes: list[tuple[str, tuple[float, float, float, float]]]) -> list[tuple[str, str]]:
    out = []
    for i, (ta, a) in enumerate(boxes):
        for tb, b in boxes[i + 1 :]:
            if a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]:
                out.append((ta, tb))
    return out


def test_png_is_a_sized_non_blank_image(tmp_path):
    im = _render(two_robots(), tmp_path / "g.png")
    assert 600 <= im.width <= 2000 and 400 <= im.height <= 2000
    assert 0.05 < _ink(im) < 0.6


def test_png_draws_every_label_inside_the_image_without_overlaps(tmp_path, drawn_texts):
    render_png(two_robots(), tmp_path / "g.png")
    texts = [t for t, _, _ in drawn_texts]
    for k in ALL_TOPICS:
        assert k in texts
    for name in ("world", "recorder", "echo-123", "controller", "sensor_msgs/LaserScan"):
        assert name in texts
    assert any(t.startswith("Run graph: demo") for t in texts)
    assert any("4 processes" in t and "9 topics" in t for t in texts)
    for t, (x0, y0, x1, y1), (w, h) in drawn_texts:
        assert x0 >= 0 and y0 >= 0 and x1 <= w and y1 <= h, f"{t!r} clipped"
    assert _overlaps([(t, b) for t, b, _ in drawn_texts]) == []


def test_png_puts_publishers_left_topics_middle_subscribers_right(tmp_path, drawn_texts):
    g = two_robots()
    g.endpoints.add(Endpoint("world", "pub", f"{RUN}/rosout", None))  # sorts after r2/... as a key
    render_png(g, tmp_path / "g.png")
    x: dict[str, float] = {}
    y: dict[str, float] = {}
    for t, b, _ in drawn_texts:  # the first of each: the boxes are drawn before the legend
        x.setdefault(t, (b[0] + b[2]) / 2)
        y.setdefault(t, (b[1] + b[3]) / 2)
    assert x["world"] < x["r1/scan"] < x["recorder"]
    assert x["r1/scan"] < x["echo-123"]
    assert x["r1/scan"] < x["controller"]  # one pub, one sub: a node goes right
    # the run's own topics together, then one group per robot
    assert y["clock"] < y["rosout"] < y["r1/cmd_vel"] < y["r1/tf"] < y["r2/cmd_vel"] < y["r2/tf"]


def test_png_shortens_very_long_names(tmp_path, drawn_texts):
    g = two_robots()
    long_key = "r1/" + "deeply_nested_namespace/" * 12 + "points"
    long_name = "a_process_with_a_name_far_too_long_to_fit_" * 4
    g.endpoints.add(Endpoint("world", "pub", f"{RUN}/{long_key}", "sensor_msgs/msg/PointCloud2"))
    g.endpoints.add(Endpoint(long_name, "sub", f"{RUN}/{long_key}", None))
    im = _render(g, tmp_path / "g.png")
    assert im.width < 1400
    texts = [t for t, _, _ in drawn_texts]
    assert long_key not in texts and long_name not in texts
    shortened = [t for t in texts if "..." in t]
    assert any(t.startswith("r1/deeply") and t.endswith("points") for t in shortened)
    assert any(t.startswith("a_process") for t in shortened)
    for t, (x0, y0, x1, y1), (w, h) in drawn_texts:
        assert x0 >= 0 and y0 >= 0 and x1 <= w and y1 <= h, f"{t!r} clipped"
    assert _overlaps([(t, b) for t, b, _ in drawn_texts]) == []


def test_png_draws_edges_against_the_flow_in_their_own_colour(tmp_path):
    with_feedback = _render(two_robots(), tmp_path / "a.png")
    assert _pixels_near(with_feedback, EDGE_BACK) > 200
    g = Graph(RUN, {"world": "world", "recorder": "recorder"})
    for k in ALL_TOPICS:
        g.endpoints.add(Endpoint("world", "pub", f"{RUN}/{k}", None))
    g.endpoints.add(Endpoint("recorder", "sub", f"{RUN}/**", None))
    assert _pixels_near(_render(g, tmp_path / "b.png"), EDGE_BACK) == 0


def test_png_changes_and_grows_with_a_topic(tmp_path):
    g = two_robots()
    a = _render(g, tmp_path / "a.png")
    g.endpoints.add(Endpoint("world", "pub", f"{RUN}/r2/imu", "sensor_msgs/msg/Imu"))
    b = _render(g, tmp_path / "b.png")
    assert (tmp_path / "a.png").read_bytes() != (tmp_path / "b.png").read_bytes()
    assert b.height > a.height


def test_png_is_deterministic(tmp_path):
    render_png(two_robots(), tmp_path / "a.png")
    g = two_robots()
    shuffled = Graph(
        RUN, dict(reversed(g.processes.items())), set(sorted(g.endpoints, key=repr, reverse=True))
    )
    render_png(shuffled, tmp_path / "b.png")
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()


def test_png_of_a_graph_without_endpoints_says_no_topics(tmp_path, drawn_texts):
    g = Graph(RUN, {"world": "world"})
    im = _render(g, tmp_path / "g.png")
    texts = [t for t, _, _ in drawn_texts]
    assert "no topics" in texts and "world" in texts
    assert im.width >= 300 and im.height >= 100 and _ink(im) > 0.01
    drawn_texts.clear()
    _render(Graph(RUN), tmp_path / "empty.png")
    assert "no topics" in [t for t, _, _ in drawn_texts]


def test_png_width_is_honoured(tmp_path):
    assert _render(two_robots(), tmp_path / "wide.png", width=1600).width == 1600
    assert _render(two_robots(), tmp_path / "narrow.png", width=500).width == 500


def test_png_stays_legible_with_forty_topics_and_twelve_processes(tmp_path, drawn_texts):
    g = two_robots(robots=("r1", "r2", "r3", "r4"), extra_topics=6)
    for i in range(8):
        name = f"node_{i}_with_a_rather_long_name" if i % 3 else f"n{i}"
        g.processes[name] = ("node", "bridge", "renderer", "tool")[i % 4]
        kind = "pub" if i % 2 else "sub"
        g.endpoints.add(Endpoint(name, kind, f"{RUN}/r{i % 4 + 1}/extra_{i:02d}", None))
    assert len(g.topics()) >= 40 and len(g.processes) == 12
    small = _render(two_robots(), tmp_path / "small.png")
    im = _render(g, tmp_path / "big.png")
    assert im.height > 2.5 * small.height  # one row per topic, not squeezed
    for t, (x0, y0, x1, y1), (w, h) in drawn_texts:
        assert x0 >= 0 and y0 >= 0 and x1 <= w and y1 <= h, f"{t!r} clipped"
    last = [(t, b) for t, b, size in drawn_texts if size == drawn_texts[-1][2]]
    assert _overlaps(last) == []
    assert {f"r{r}/extra_{i:02d}" for r in (1, 2, 3, 4) for i in range(6)} <= {t for t, _ in last}
