"""Benchmark: the recorder's sustained rate (messages/s into MCAP) with nothing lost.

    python bench/recorder.py [--seconds 5] [--size BYTES] [--entry subscribe|callback ...]

The recorder's side is hosted as `scenario run` hosts it: a Zenoh router session in this process with a
`Recorder` on `<run>/**`. A separate publisher process connects to it as a client (TCP on loopback) and
publishes as fast as it can, round-robin on 8 keys with realistic CDR payloads (two Imu, two Odometry,
JointState, TFMessage, Clock and a 720-ray LaserScan of ~3 KB; `--size` puts one size on every key instead),
each sample with its (sequence number, sim time) attachment, with BLOCK congestion control and RELIABLE
reliability as the world publishes: if the recorder falls behind, the publisher is slowed down, so the
figure is the recorder's sustained rate. Then it says how many it sent per key, and the recorder's side
waits until it holds them all.

Reported, per recorder entry point (`subscribe`: the recorder's own FIFO subscriber drained by its thread;
`callback`: `on_sample` as a Zenoh callback):
- messages/s: messages recorded / (time the last one was recorded - time the first one was sent);
- MB/s: payload bytes recorded over the same window;
- lost: sequence gaps seen by the recorder + messages sent but not recorded;
- CPU µs/msg: CPU time per message of the recorder's process (all its threads, Zenoh's included) + that
  of the publisher's: where the 2 cores go;
- the MCAP read back: every message on its channel, sequence numbers 0..n-1 in order, log times = the
  sim times sent.
Results are printed and written to bench/results/recorder.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from importlib import metadata
from pathlib import Path
from typing import Any

# Run as a script, this folder comes first on sys.path, and bench/plugins.py would shadow the `plugins`
# package: put the repository first instead.
REPO = Path(__file__).resolve().parents[1]
if sys.path and Path(sys.path[0]).resolve() == REPO / "bench":
    sys.path[0] = str(REPO)

import zenoh  # noqa: E402

from runner.record import Recorder  # noqa: E402
from runner.wire.transport import ATTACHMENT, encoding_for, free_port, make_config  # noqa: E402

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results" / "recorder.json"
RUN = "bench"
ENTRIES = ("subscribe", "callback")
# Distinct payloads per key, cycled: a chunk (~400 messages) holds no repeat, as with real data.
VARIANTS = 128
STEP_NS = 1_000_000  # sim time between two rounds of the publisher
TARGET = 50_000  # messages/s, from the performance issue


# ------------------------------------------------------------------------------------------ publisher
def payload_mix(size: int | None = None) -> list[tuple[str, str, list[bytes]]]:
    """(key suffix, ROS type, payload variants) of the 8 keys the publisher publishes on."""
    import numpy as np

    from runner.wire import msgs

    rng = np.random.default_rng(1)

    def vec() -> dict[str, float]:
        x, y, z = rng.normal(size=3)
        return {"x": float(x), "y": float(y), "z": float(z)}

    def quat() -> dict[str, float]:
        yaw = rng.uniform(-np.pi, np.pi)
        return {"x": 0.0, "y": 0.0, "z": float(np.sin(yaw / 2)), "w": float(np.cos(yaw / 2))}

    def pose() -> dict[str, Any]:
        return {"position": vec(), "orientation": quat()}

    def header(frame: str) -> dict[str, Any]:
        return {"stamp": {"sec": 12, "nanosec": int(rng.integers(0, 10**9))}, "frame_id": frame}

    def cov(n: int) -> list[float]:  # constant, diagonal: as sensors publish them
        side = round(n**0.5)
        return [1e-4 if i % (side + 1) == 0 else 0.0 for i in range(n)]

    def values(n: int) -> list[float]:
        return [float(v) for v in rng.normal(size=n)]

    def scan() -> list[float]:  # a square room seen from a random spot, with 1 cm noise
        angles = np.linspace(-np.pi, np.pi, 720, endpoint=False)
        x, y = rng.uniform(-3, 3, size=2)
        c, s = np.cos(angles), np.sin(angles)
        with np.errstate(divide="ignore"):
            walls = np.minimum(
                np.where(c > 0, (5 - x) / c, (-5 - x) / c), np.where(s > 0, (5 - y) / s, (-5 - y) / s)
            )
        ranges = np.minimum(walls, 8.0) + rng.normal(scale=0.01, size=720)
        return [float(r) for r in ranges.astype(np.float32)]

    makers: list[tuple[str, str, Any]]
    if size is not None:
        blob = "sensor_msgs/msg/CompressedImage"
        n = max(0, size - len(msgs.encode(msgs.from_data(blob, {"format": "jpeg"}), blob)))
        makers = [
            (
                f"r{i}/blob",
                blob,
                lambda: {"format": "jpeg", "data": rng.integers(0, 256, size=n).tolist()},
            )
            for i in range(8)
        ]
    else:
        imu = lambda: {  # noqa: E731
            "header": header("imu_link"),
            "orientation": quat(),
            "orientation_covariance": cov(9),
            "angular_velocity": vec(),
            "angular_velocity_covariance": cov(9),
            "linear_acceleration": vec(),
            "linear_acceleration_covariance": cov(9),
        }
        odom = lambda: {  # noqa: E731
            "header": header("odom"),
            "child_frame_id": "base_link",
            "pose": {"pose": pose(), "covariance": cov(36)},
            "twist": {"twist": {"linear": vec(), "angular": vec()}, "covariance": cov(36)},
        }
        makers = [
            ("r1/imu", "sensor_msgs/msg/Imu", imu),
            ("r2/imu", "sensor_msgs/msg/Imu", imu),
            ("r1/odom", "nav_msgs/msg/Odometry", odom),
            ("r2/odom", "nav_msgs/msg/Odometry", odom),
            (
                "r1/joint_states",
                "sensor_msgs/msg/JointState",
                lambda: {
                    "header": header(""),
                    "name": ["left_wheel_joint", "right_wheel_joint"],
                    "position": values(2),
                    "velocity": values(2),
                    "effort": values(2),
                },
            ),
            (
                "r1/tf",
                "tf2_msgs/msg/TFMessage",
                lambda: {
                    "transforms": [
                        {
                            "header": header("odom"),
                            "child_frame_id": "base_link",
                            "transform": {"translation": vec(), "rotation": quat()},
                        }
                    ]
                },
            ),
            ("clock", "rosgraph_msgs/msg/Clock", lambda: {"clock": header("")["stamp"]}),
            (
                "r1/scan",
                "sensor_msgs/msg/LaserScan",
                lambda: {
                    "header": header("lidar_link"),
                    "angle_min": -3.14159,
                    "angle_max": 3.14159,
                    "angle_increment": 6.28318 / 720,
                    "range_min": 0.1,
                    "range_max": 8.0,
                    "ranges": scan(),
                },
            ),
        ]
    return [
        (suffix, t, [msgs.encode(msgs.from_data(t, make()), t) for _ in range(VARIANTS)])
        for suffix, t, make in makers
    ]


def publish(endpoint: str, run: str, seconds: float, size: int | None) -> None:
    """The publisher process: publish round-robin on every key for `seconds`, print what was sent (one
    JSON line), then wait for a line on stdin (the recorder's side is done) before closing the session,
    so that nothing still queued in this process is cut off."""
    mix = payload_mix(size)
    with zenoh.open(make_config("client", connect=[endpoint])) as session:
        pubs = [
            session.declare_publisher(
                f"{run}/{suffix}",
                encoding=encoding_for(type_name),
                congestion_control=zenoh.CongestionControl.BLOCK,
                reliability=zenoh.Reliability.RELIABLE,
            )
            for suffix, type_name, _ in mix
        ]
        deadline = time.monotonic() + 10.0
        while not all(p.matching_status.matching for p in pubs):  # the recorder's subscriber is known here
            if time.monotonic() > deadline:
                raise SystemExit("publisher: no subscriber matched within 10 s")
            time.sleep(0.005)
        puts = [p.put for p in pubs]
        variants = [payloads for _, _, payloads in mix]
        pairs = list(zip(puts, variants, strict=True))
        pack = ATTACHMENT.pack
        clock = time.monotonic
        rounds = 0
        cpu0 = time.process_time()
        t0 = clock()
        end = t0 + seconds
        while True:
            att = pack(rounds, rounds * STEP_NS)
            v = rounds % VARIANTS
            for put, payloads in pairs:
                put(payloads[v], attachment=att)
            rounds += 1
            if not rounds & 31 and clock() >= end:
                break
        t1 = clock()
        cpu = time.process_time() - cpu0
        full, part = divmod(rounds, VARIANTS)
        sent_bytes = sum(
            full * sum(map(len, payloads)) + sum(map(len, payloads[:part])) for payloads in variants
        )
        report = {
            "published": {f"{run}/{suffix}": rounds for suffix, _, _ in mix},
            "bytes": sent_bytes,
            "t0": t0,
            "t1": t1,
            "cpu_s": cpu,
        }
        print(json.dumps(report), flush=True)
        sys.stdin.readline()
        for p in pubs:
            p.undeclare()


# ------------------------------------------------------------------------------------------- recorder
def measure(
    seconds: float, size: int | None, entry: str, mcap_path: Path, drain_timeout: float = 30.0
) -> dict[str, Any]:
    """One measurement: a recorder fed through `entry`, a publisher process for `seconds`."""
    if entry not in ENTRIES:
        raise ValueError(f"unknown entry {entry!r} (one of {', '.join(ENTRIES)})")
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    recorder = Recorder(mcap_path, [f"{RUN}/**"])
    session = zenoh.open(make_config("router", listen=[endpoint]))
    sub = None
    child: subprocess.Popen[str] | None = None
    try:
        if entry == "subscribe":
            recorder.subscribe(session, f"{RUN}/**")
        else:
            sub = session.declare_subscriber(f"{RUN}/**", recorder.on_sample)
        cmd = [
            sys.executable,
            str(Path(__file__).resolve()),
            "--publisher",
            endpoint,
            "--seconds",
            str(seconds),
        ]
        if size is not None:
            cmd += ["--size", str(size)]
        cpu0 = time.process_time()  # this process is idle until the publisher starts
        child = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd=REPO)
        assert child.stdout is not None and child.stdin is not None
        line = child.stdout.readline()
        if not line:
            raise RuntimeError(f"the publisher process failed (exit code {child.wait()})")
        report = json.loads(line)
        published: dict[str, int] = report["published"]
        total = sum(published.values())
        deadline = time.monotonic() + drain_timeout
        while True:
            now = time.monotonic()
            got = recorder.counts()
            if sum(got.values()) >= total or now > deadline:
                break
            time.sleep(0.001)
        done = now
        cpu = time.process_time() - cpu0
        child.stdin.write("\n")
        child.stdin.flush()
        child.wait(timeout=30)
    finally:
        if child is not None:
            if child.poll() is None:
                child.kill()
                child.wait()
            for stream in (child.stdin, child.stdout):
                if stream is not None:
                    stream.close()
        if sub is not None:
            sub.undeclare()
        recorder.close()
        session.close()

    stats = {s.key: s for s in recorder.stats()}
    recorded = sum(s.count for s in stats.values())
    gaps = sum(s.lost for s in stats.values())
    missing = sum(max(0, n - (stats[k].count if k in stats else 0)) for k, n in published.items())
    window = done - report["t0"]
    readback = read_back(mcap_path, published)
    return {
        "entry": entry,
        "published": total,
        "recorded": recorded,
        "lost": gaps + missing,
        "sequence_gaps": gaps,
        "missing": missing,
        "window_s": window,
        "messages_per_s": recorded / window,
        "mb_per_s": report["bytes"] * (recorded / total) / window / 1e6,
        "publisher_messages_per_s": total / (report["t1"] - report["t0"]),
        "drain_s": max(0.0, done - report["t1"]),
        # CPU time (all threads, Zenoh's included) per message, on each side: what the 2 cores are spent on
        "recorder_cpu_us_per_msg": cpu / max(recorded, 1) * 1e6,
        "publisher_cpu_us_per_msg": report["cpu_s"] / total * 1e6,
        "mean_payload_bytes": report["bytes"] / total,
        "mcap_bytes": mcap_path.stat().st_size,
        "readback": readback,
        "per_key": {
            k: {"published": n, "recorded": stats[k].count if k in stats else 0} for k, n in published.items()
        },
    }


def read_back(path: Path, published: dict[str, int]) -> dict[str, Any]:
    """Read the MCAP back: messages per channel (summary and a full read), and whether each channel's
    sequence numbers are 0..n-1 in file order, with log times = the publisher's sim times (never going
    back)."""
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        topics = {cid: ch.topic for cid, ch in summary.channels.items()}
        summary_counts = {topics[c]: n for c, n in summary.statistics.channel_message_counts.items()}
        counts: dict[str, int] = {}
        next_seq: dict[int, int] = {}
        last_time: dict[int, int] = {}
        in_order = True
        for _, channel, message in reader.iter_messages(log_time_order=False):
            cid = channel.id
            in_order &= (
                message.sequence == next_seq.get(cid, 0)
                and message.log_time == message.sequence * STEP_NS  # the sim time the publisher sent
                and message.log_time >= last_time.get(cid, 0)
            )
            next_seq[cid] = message.sequence + 1
            last_time[cid] = message.log_time
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    return {
        "messages": sum(counts.values()),
        "per_channel_equals_published": counts == published and summary_counts == published,
        "sequences_and_log_times_in_order": in_order,
    }


def _read_back_ok(result: dict[str, Any]) -> bool:
    rb = result["readback"]
    return bool(rb["per_channel_equals_published"] and rb["sequences_and_log_times_in_order"])


def machine() -> dict[str, Any]:
    def version(dist: str) -> str | None:
        try:
            return metadata.version(dist)
        except metadata.PackageNotFoundError:
            return None

    return {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
        "mujoco": version("mujoco"),
        "zenoh": version("eclipse-zenoh"),
        "mcap": version("mcap"),
        "zstandard": version("zstandard"),
    }


def run(
    seconds: float = 5.0,
    size: int | None = None,
    entries: tuple[str, ...] = ENTRIES,
    out: Path | None = None,
    verbose: bool = True,
) -> dict[str, Any]:
    """Measure each entry point in turn (a fresh recorder, router and publisher process each); print a
    table (`verbose`) and write the results as JSON to `out` (the script: bench/results/recorder.json).
    The top-level `messages_per_s`, `mb_per_s` and `lost` are those of the first entry."""
    if not entries:
        raise ValueError("no entry point to measure")
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for entry in entries:
            results.append(measure(seconds, size, entry, Path(tmp) / f"{entry}.mcap"))
    first = results[0]
    met = all(r["messages_per_s"] >= TARGET and r["lost"] == 0 and _read_back_ok(r) for r in results)
    doc: dict[str, Any] = {
        "benchmark": "recorder",
        "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "machine": machine(),
        "seconds": seconds,
        "size": size,
        "keys": len(first["per_key"]),
        "mean_payload_bytes": first["mean_payload_bytes"],
        "messages_per_s": first["messages_per_s"],
        "mb_per_s": first["mb_per_s"],
        "lost": first["lost"],
        **{f"{r['entry']}_messages_per_s": r["messages_per_s"] for r in results},
        **{f"{r['entry']}_lost": r["lost"] for r in results},
        "targets": {
            f"recorder >= {TARGET:,} messages/s sustained with 0 lost ({', '.join(entries)})": {
                "met": met,
                "messages_per_s": {r["entry"]: r["messages_per_s"] for r in results},
                "lost": {r["entry"]: r["lost"] for r in results},
            }
        },
        "results": results,
    }
    if verbose:
        payload = f"{size} B on every key" if size else f"mixed, mean {first['mean_payload_bytes']:.0f} B"
        print(f"recorder: {doc['keys']} keys, payloads {payload}, {seconds:g} s, 1 publisher process")
        print(
            f"{'entry':10s} {'msgs/s':>9s} {'MB/s':>7s} {'lost':>5s} {'recorded':>9s} {'pub msgs/s':>10s} "
            f"{'CPU µs/msg rec+pub':>18s}  read back"
        )
        for r in results:
            ok = _read_back_ok(r)
            cpu = f"{r['recorder_cpu_us_per_msg']:.1f} + {r['publisher_cpu_us_per_msg']:.1f}"
            check = "ok" if ok else "MISMATCH"
            print(
                f"{r['entry']:10s} {r['messages_per_s']:9.0f} {r['mb_per_s']:7.1f} {r['lost']:5d} "
                f"{r['recorded']:9d} {r['publisher_messages_per_s']:10.0f} {cpu:>18s}  {check}"
            )
        print(f"target: >= {TARGET:,} msgs/s with 0 lost: {'met' if met else 'NOT met'}")
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(doc, indent=2) + "\n")
        if verbose:
            print(f"wrote {out.relative_to(REPO) if out.is_relative_to(REPO) else out}")
    return doc


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=5.0, help="publishing time per measurement")
    ap.add_argument("--size", type=int, default=None, help="one payload size (bytes) on every key")
    ap.add_argument(
        "--entry", action="append", choices=ENTRIES, help="entry point(s) to measure (default: both)"
    )
    ap.add_argument("--publisher", metavar="ENDPOINT", help=argparse.SUPPRESS)  # the publisher process
    args = ap.parse_args()
    if args.publisher:
        publish(args.publisher, RUN, args.seconds, args.size)
        return
    run(args.seconds, args.size, tuple(args.entry) if args.entry else ENTRIES, out=RESULTS)


if __name__ == "__main__":
    main()
