"""One TF tree, as ROS users expect it: each robot's links on its `tf`/`tf_static` beside its drive's
odom -> base, the world's frames on the run's, `robot_description` naming its links as the transforms do,
and the ROS 2 side (`ros2:`) showing `/tf` and `/tf_static` with `/tf_static` and `robot_description`
TRANSIENT_LOCAL, checked with a third-party rmw_zenoh client (zenoh-ros2-sdk)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections import defaultdict
from pathlib import Path

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from runner.wire.transport import free_port
from tests.conftest import run_cli
from tests.test_bridges import start_run

CLIENT = Path(__file__).parent / "clients" / "ros2_sdk_client.py"

MIXED = """
name: frames
duration: 1
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive}
      - {type: lidar, params: {link: lidar_link, samples: 8}}
  - name: r2
    description: "{diffbot}"
    pose: {xyz: [1, 0, 0.06]}
  - name: r3
    description: "{diffbot}"
    pose: {xyz: [-1, 0, 0.06]}
    plugins:
      - {type: diff_drive}
      - {type: tf, params: {rate: 20}}
  - name: r4
    description: "{diffbot}"
    pose: {xyz: [-1, 1, 0.06]}
    plugins:
      - {type: tf}
world:
  models:
    - {name: crate, shape: box, size: [0.3, 0.3, 0.3], pose: {xyz: [0, 2, 0.15]}}
    - {name: ball, shape: sphere, size: [0.1], pose: {xyz: [0, -2, 0.1]}, static: false, mass: 0.5}
"""


ROBOTS = ("r1", "r2", "r3", "r4")


def _tf_and_descriptions(mcap: Path) -> tuple[dict[str, set[str]], dict[str, str], set[str]]:
    """From the MCAP alone: parent -> children of every recorded transform, each robot_description, and
    the topics transforms came on."""
    edges: dict[str, set[str]] = defaultdict(set)
    descriptions: dict[str, str] = {}
    tf_topics: set[str] = set()
    with mcap.open("rb") as f:
        summary = make_reader(f).get_summary()
        assert summary is not None
        cdr = [c.topic for c in summary.channels.values() if c.message_encoding == "cdr"]
        f.seek(0)
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, _msg, decoded in reader.iter_decoded_messages(topics=cdr):
            if schema is not None and schema.name == "tf2_msgs/msg/TFMessage":
                tf_topics.add(channel.topic)
                for t in decoded.transforms:
                    edges[t.header.frame_id].add(t.child_frame_id)
            elif channel.topic.endswith("/robot_description"):
                descriptions[channel.topic] = decoded.data
    return edges, descriptions, tf_topics


def _reachable(edges: dict[str, set[str]], root: str) -> set[str]:
    seen, todo = {root}, [root]
    while todo:
        for child in edges.get(todo.pop(), ()):
            if child not in seen:
                seen.add(child)
                todo.append(child)
    return seen


@pytest.mark.timeout(180)
def test_every_link_of_every_robot_description_is_reachable_from_world_in_the_recording(
    write_scenario, tmp_path: Path
) -> None:
    """A driven robot, one with no plugin at all, a driven one with its own `tf` plugin and an undriven one
    with its own `tf` plugin (which leaves the root out), beside a fixed and a
    moving world model: read back from the MCAP alone, every link named in each robot's
    `robot_description` is a frame that the recorded transforms join to `world`."""
    path = write_scenario(MIXED)
    mcap = tmp_path / "frames.mcap"
    proc = run_cli("run", str(path), "-q", "--record", str(mcap), "--rate", "max", timeout=150)
    assert proc.returncode == 0, proc.stderr
    edges, descriptions, tf_topics = _tf_and_descriptions(mcap)
    assert sorted(descriptions) == [f"frames/{r}/robot_description" for r in ROBOTS]
    reachable = _reachable(edges, "world")
    for topic, urdf in descriptions.items():
        ns = topic.split("/")[1]
        links = [el.get("name") or "" for el in ET.fromstring(urdf).iter("link")]
        assert len(links) >= 4, links
        # the URDF names its links as the transforms do (robot_state_publisher's frame_prefix)
        assert all(link.startswith(f"{ns}/") for link in links), links
        joints = ET.fromstring(urdf).iter("joint")
        assert all((j.find("parent").get("link") or "").startswith(f"{ns}/") for j in joints)  # type: ignore[union-attr]
        assert not [link for link in links if link not in reachable], (topic, sorted(reachable))
    assert "ball" in reachable  # a moving world model (a static one is part of the `world` body)
    # one tree, on the topics ROS users look at: nothing on `scene/tf` any more
    assert tf_topics == {
        "frames/tf",
        "frames/tf_static",
        *(f"frames/{r}/{t}" for r in ROBOTS for t in ("tf", "tf_static")),
    }
    assert "r1/odom" in edges["world"] and "r1/base_link" in edges["r1/odom"]  # the drive, joined
    assert "r2/base_link" in edges["world"]  # no drive: placed from the world
    assert "r3/base_link" in edges["r3/odom"]
    assert "r4/base_link" in edges["world"]  # its own `tf` leaves the root out: the world places it


@pytest.mark.timeout(60)
def test_validate_lists_the_added_robot_state_publisher_and_not_over_a_tf_plugin(write_scenario) -> None:
    path = write_scenario(MIXED)
    proc = run_cli("validate", str(path), timeout=50)
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "r1/tf_static" in out and "r2/tf" in out
    assert "r1/robot_state_publisher" in out and "r2/robot_state_publisher" in out, out
    assert "r3/robot_state_publisher" not in out and "r3/tf " in out, out  # r3 has its own `tf`


ROS = """
name: rostf
duration: 120
rate: realtime
robots:
  - name: r1
    description: "{diffbot}"
    pose: {xyz: [0, 0, 0.06]}
    plugins:
      - {type: diff_drive}
      - {type: lidar, params: {link: lidar_link, samples: 16, rate: 10}}
foxglove: {rate: 0.01}   # the static transforms and URDF go out once in the window: the cache must hold them
ros2: {domain: %d}
"""


@pytest.mark.timeout(240)
def test_a_third_party_rmw_zenoh_client_resolves_the_scan_frame_to_odom_as_a_late_subscriber(
    write_scenario, tmp_path: Path
) -> None:
    """zenoh-ros2-sdk (an independent rmw_zenoh client, installed by the test command) joins a running
    scenario: `/tf` and `/tf_static` are listed; a TRANSIENT_LOCAL subscriber to `/tf_static` that comes
    after the only time the static tree was published receives it from the publishers' caches; and the
    chain from the scan's `frame_id` (`r1/lidar_link`) to `r1/odom` resolves from what it received."""
    domain = 40 + os.getpid() % 150
    port = free_port()
    path = write_scenario(ROS % domain)
    run = start_run(path, "--no-record", "--listen", f"tcp/127.0.0.1:{port}")
    out = tmp_path / "sdk.json"
    try:
        client = subprocess.run(
            [sys.executable, str(CLIENT), str(port), str(domain), str(out)],
            capture_output=True,
            text=True,
            timeout=180,
        )
        assert client.returncode == 0 and out.exists(), client.stderr[-3000:]
    finally:
        run.send_signal(signal.SIGINT)
        run.communicate(timeout=60)
    got = json.loads(out.read_text())
    topics = dict((name, types) for name, types in got["topics"])
    assert topics.get("/tf") == ["tf2_msgs/msg/TFMessage"], sorted(topics)
    assert topics.get("/tf_static") == ["tf2_msgs/msg/TFMessage"], sorted(topics)
    assert topics.get("/r1/robot_description") == ["std_msgs/msg/String"], sorted(topics)
    assert got["clock_at_subscribe"] >= 2.0

    # late: the static tree was sent once, at t = 0; it came from the cache as the subscription was made
    at_subscribe = {(p, c) for msg in got["static_at_subscribe"] for p, c in msg}
    assert ("r1/base_link", "r1/lidar_link") in at_subscribe, at_subscribe
    assert ("world", "r1/odom") in at_subscribe, at_subscribe

    parent: dict[str, str] = {}
    for msg in [*got["static_at_subscribe"], *got["tf"]]:
        for p, c in msg:
            parent[c] = p
    assert got["scan_frames"] and set(got["scan_frames"]) == {"r1/lidar_link"}
    chain = [got["scan_frames"][0]]
    while chain[-1] in parent and chain[-1] != "r1/odom" and len(chain) < 20:
        chain.append(parent[chain[-1]])
    assert chain[-1] == "r1/odom", chain
