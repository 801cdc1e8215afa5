"""A go-to-goal controller node: drives its robot to a point of its odometry frame and holds there.

    python nodes/go_to_goal.py --x 2.0 --y 1.5        (started by a scenario's `nodes:` entry)

Reads `odom` (nav_msgs/Odometry), publishes `cmd_vel` (geometry_msgs/Twist) at 10 Hz of sim time.
"""

import argparse
import math

from runner.node import Node

ap = argparse.ArgumentParser()
ap.add_argument("--x", type=float, required=True)
ap.add_argument("--y", type=float, required=True)
ap.add_argument("--speed", type=float, default=0.4, help="top speed, m/s")
ap.add_argument("--tolerance", type=float, default=0.05, help="distance counted as arrived, m")
args = ap.parse_args()

pose = {"x": 0.0, "y": 0.0, "yaw": 0.0}


def on_odom(odom) -> None:
    p, q = odom.pose.pose.position, odom.pose.pose.orientation
    pose.update(x=p.x, y=p.y, yaw=math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z)))


with Node() as node:
    cmd = node.publisher("cmd_vel", "geometry_msgs/msg/Twist")
    node.subscribe("odom", "nav_msgs/msg/Odometry", on_odom)
    arrived = False
    while node.ok():
        dx, dy = args.x - pose["x"], args.y - pose["y"]
        distance = math.hypot(dx, dy)
        turn = math.atan2(dy, dx) - pose["yaw"]
        heading = math.atan2(math.sin(turn), math.cos(turn))  # wrapped to [-pi, pi]
        if distance < args.tolerance:
            v = w = 0.0
            if not arrived:
                print(f"arrived at ({pose['x']:.2f}, {pose['y']:.2f}) at t = {node.now:.1f} s", flush=True)
                arrived = True
        else:
            w = max(-1.5, min(1.5, 2.0 * heading))
            v = min(args.speed, 0.8 * distance) * max(0.0, math.cos(heading))
        cmd.publish({"linear": {"x": v}, "angular": {"z": w}})
        node.sleep(0.1)
