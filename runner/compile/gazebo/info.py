"""What reading a description's `<gazebo>` tags yields: the plugins it declares (`DescribedPlugin`), the
per-link properties (`LinkProps`: colour, friction, contact stiffness, gravity, self-collision), and the
whole (`GazeboInfo`), with the blocks that were left out and why."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


@dataclass
class DescribedPlugin:
    """A plugin the description declares, before the scenario's `plugins:` are merged in."""

    type: str
    name: str
    params: dict[str, Any]
    file: Path | None = None
    line: int | None = None
    implicit: bool = False  # a sensor with neither a ROS plugin nor a <topic>: its topic is our default


Where = tuple[Path | None, int | None]  # (file, line) of a tag in the user's files


@dataclass
class Spawn:
    """What a launch file's spawners start (the scenario's `spawn:` / `controller_types:`): the controllers
    by name (None: every controller of the files, as a launch spawning them all), and the types a spawner
    gives on its command line (`-t` / `--controller-type`), for files that have none."""

    names: list[str] | None = None
    types: dict[str, str] = field(default_factory=dict)
    where: dict[str, Where] = field(default_factory=dict)  # a name's place in the scenario, for notices


@dataclass
class LinkProps:
    rgba: tuple[float, float, float, float] | None = None
    friction: float | None = None
    kp: float | None = None
    kd: float | None = None
    gravity_off: bool = False
    mu1: float | None = None  # friction along fdir1 ...
    mu2: float | None = None  # ... and across it: a drive's wheels keep the two apart (runner.compile.wheels)
    fdir1: tuple[float, float, float] | None = None  # in the collision's frame, or in fdir1_frame's
    fdir1_frame: str | None = None  # `gz:expressed_in` (or `ignition:`): the link whose frame fdir1 is in
    fdir1_at: Where = (None, None)  # the <fdir1> tag, for what is said about it
    self_collide: bool | None = None  # <selfCollide> (or <self_collide>) of the link; None: the model's
    self_collide_at: Where = (None, None)


@dataclass
class GazeboInfo:
    plugins: list[DescribedPlugin] = field(default_factory=list)
    links: dict[str, LinkProps] = field(default_factory=dict)
    static: bool = False
    self_collide: bool = False  # model-level <self_collide>: Gazebo's default is off
    self_collide_at: Where = (None, None)
    dropped: list[tuple[str, Where]] = field(default_factory=list)  # the warnings of what was left out
