"""A corridor driver: cruises along +x, stops while anything is close ahead, goes on once it is clear, and
watches its inputs (a watchdog per input).

    python nodes/corridor_driver.py [--speed 0.5] [--stop 1.2] [--ignore-lidar]

Reads `scan` (sensor_msgs/LaserScan) and `odom` (nav_msgs/Odometry); publishes `cmd_vel`
(geometry_msgs/Twist) at 10 Hz of sim time, and on `status` (std_msgs/String) each change of what its
watchdogs see: `lidar stale` (no scan for 0.5 s: it stops until scans come back), `lidar ok`, `odom late`
(the odometry it gets is more than 0.1 s old: it slows down), `odom ok`.
"""

import argparse
import math

import numpy as np

from runner.node import Node

ap = argparse.ArgumentParser()
ap.add_argument("--speed", type=float, default=0.5, help="cruise speed, m/s")
ap.add_argument("--stop", type=float, default=1.2, help="stop while a return ahead is closer, m")
ap.add_argument("--sector", type=float, default=60.0, help="half-width of 'ahead', degrees")
ap.add_argument("--ignore-lidar", action="store_true", help="drive blind (to see a test fail)")
args = ap.parse_args()

seen = {"scan_t": None, "blocked": False, "odom_lag": 0.0}


def on_scan(scan) -> None:
    seen["scan_t"] = node.now
    angles = scan.angle_min + scan.angle_increment * np.arange(len(scan.ranges))
    ahead = np.abs(angles) <= math.radians(args.sector)
    seen["blocked"] = bool(np.any(scan.ranges[ahead] < args.stop))


def on_odom(odom) -> None:
    stamp = odom.header.stamp.sec + odom.header.stamp.nanosec * 1e-9
    seen["odom_lag"] = node.now - stamp


with Node() as node:
    cmd = node.publisher("cmd_vel", "geometry_msgs/msg/Twist")
    status = node.publisher("status", "std_msgs/msg/String")
    node.subscribe("scan", "sensor_msgs/msg/LaserScan", on_scan)
    node.subscribe("odom", "nav_msgs/msg/Odometry", on_odom)
    said = {"lidar": "lidar ok", "odom": "odom ok"}

    def say(what: str, text: str) -> None:
        if said[what] != text:
            said[what] = text
            status.publish({"data": text})
            print(f"t = {node.now:.2f} s: {text}", flush=True)

    while node.ok():
        stale = seen["scan_t"] is None or node.now - seen["scan_t"] > 0.5
        say("lidar", "lidar stale" if stale and node.now > 1.0 else "lidar ok")
        say("odom", "odom late" if seen["odom_lag"] > 0.1 else "odom ok")
        v = args.speed
        if not args.ignore_lidar and (seen["blocked"] or said["lidar"] == "lidar stale"):
            v = 0.0
        elif said["odom"] == "odom late":
            v = args.speed / 2
        cmd.publish({"linear": {"x": v}})
        node.sleep(0.1)
