"""`scenario teleop`: drive a robot of a running scenario from the keyboard, with the keys and speed steps
of ROS's teleop_twist_keyboard, publishing geometry_msgs/Twist on its command topic."""

from __future__ import annotations

import sys
from typing import Annotated

import typer

from runner.cli.console import fail
from runner.cli.live import tool_tokens
from runner.cli.options import ConnectOpt, RunOpt
from runner.errors import RunError

# teleop_twist_keyboard's layout: key -> (forward, turn) directions
_MOVES = {
    "i": (1, 0), "o": (1, -1), "j": (0, 1), "l": (0, -1), "u": (1, 1),
    ",": (-1, 0), ".": (-1, 1), "m": (-1, -1),
}  # fmt: skip
_SPEEDS = {
    "q": (1.1, 1.1),
    "z": (0.9, 0.9),
    "w": (1.1, 1.0),
    "x": (0.9, 1.0),
    "e": (1.0, 1.1),
    "c": (1.0, 0.9),
}
_TELEOP_HELP = """Moving around:        speeds:
   u    i    o         q/z  all up/down by 10%
   j    k    l         w/x  linear only
   m    ,    .         e/c  angular only
k (or any other key) stops; Ctrl-C quits (and stops the robot)."""


def teleop(
    robot: Annotated[str, typer.Argument(help="The robot's name (its namespace), e.g. r1.")],
    speed: Annotated[float, typer.Option(metavar="M/S", help="Linear speed, m/s.")] = 0.5,
    turn: Annotated[float, typer.Option(metavar="RAD/S", help="Angular speed, rad/s.")] = 1.0,
    topic: Annotated[str, typer.Option(help="Command topic inside the robot's namespace.")] = "cmd_vel",
    run_name: RunOpt = None,
    connect: ConnectOpt = None,
) -> None:
    """Drive a robot from the keyboard (the keys of teleop_twist_keyboard), publishing geometry_msgs/Twist.

    Example: scenario teleop r1 --speed 0.3
    """
    import os
    import select
    import termios
    import time
    import tty

    import zenoh

    from runner.launch.announce import find_run, joined, key_of
    from runner.wire import msgs
    from runner.wire.transport import encoding_for, pack_attachment

    try:
        name, endpoints = find_run(run_name, connect)
        key = key_of(name, f"{robot}/{topic}")
        fd = sys.stdin.fileno()
        if not os.isatty(fd):
            raise RunError("teleop reads keys from a terminal; stdin is not one")
        twist_type = "geometry_msgs/msg/Twist"
        with joined(endpoints) as session:
            tool = tool_tokens(session, name, "teleop")  # (kept: a dropped token is withdrawn)
            tool.publisher(key, twist_type)
            pub = session.declare_publisher(
                key, encoding=encoding_for(twist_type), congestion_control=zenoh.CongestionControl.BLOCK
            )
            seq = 0

            def send(v: float, w: float) -> None:
                nonlocal seq
                data = {"linear": {"x": v}, "angular": {"z": w}}
                pub.put(
                    msgs.encode(msgs.from_data(twist_type, data), twist_type),
                    attachment=pack_attachment(seq, 0),
                )
                seq += 1

            print(f"{_TELEOP_HELP}\npublishing on {key}", end="\r\n", flush=True)
            saved = termios.tcgetattr(fd)
            try:
                tty.setraw(fd)
                while True:
                    ready, _, _ = select.select([fd], [], [], 0.2)
                    if not ready:
                        continue
                    ch = os.read(fd, 1).decode(errors="replace")
                    if ch in ("\x03", "\x04", ""):  # Ctrl-C, Ctrl-D
                        break
                    if ch in _SPEEDS:
                        a, b = _SPEEDS[ch]
                        speed, turn = speed * a, turn * b
                        print(f"speed {speed:.2f} m/s, turn {turn:.2f} rad/s", end="\r\n", flush=True)
                        continue
                    forward, rotate = _MOVES.get(ch, (0, 0))
                    send(forward * speed, rotate * turn)
                    print(
                        f"linear.x {forward * speed:+.2f}  angular.z {rotate * turn:+.2f}",
                        end="\r\n",
                        flush=True,
                    )
            finally:
                termios.tcsetattr(fd, termios.TCSADRAIN, saved)
                send(0.0, 0.0)  # never leave a robot driving
                time.sleep(0.1)
                pub.undeclare()
    except RunError as e:
        raise fail(e) from None
