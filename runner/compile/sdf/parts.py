"""What the SDF reader passes around: its result (`SdfWorld`, what the caller applies), where an element
came from (`Src`: file, SDF version, the files that included it), the links and joints collected from a
model before its bodies are built, and a model as the world's `<state>` saved it."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from runner.compile.sdf.pose import Pose


@dataclass
class SdfWorld:
    """What the caller must apply after `load_sdf_world` (values are None when the file does not set them)."""

    file: Path
    name: str | None = None  # <world name="...">; None for a bare <model> file
    timestep: float | None = None  # <physics><max_step_size>
    real_time_factor: float | None = None  # <physics><real_time_factor>
    gravity: tuple[float, float, float] | None = None  # <world><gravity> or (1.4) <physics><gravity>
    models: list[str] = field(default_factory=list)  # top-level models added: bodies are `<model>/...`
    free_bodies: list[str] = field(default_factory=list)  # bodies that were given a free joint
    ground: bool = False  # this file added the ground plane (geom `ground`)
    ground_model: str | None = None  # the file's own ground plane (its link) that became the ground geom
    has_ground: bool = False  # the file has a ground plane (model://ground_plane or a plane at z=0)


@dataclass
class Src:
    path: Path
    version: tuple[int, int] | None
    chain: tuple[Path, ...] = ()  # the files that included this one, outermost first


@dataclass
class Link:
    key: str  # scoped name in the top-level model: `link` or `sub::link`
    body: str  # `<model>/<sub>/<link>`
    world: Pose
    el: etree._Element
    src: Src
    static: bool
    model_world: Pose  # pose of the model that holds the link (axes expressed in the model frame)
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)  # the model's scale in the world's <state>


@dataclass
class Joint:
    name: str
    type: str
    parent: Link | None  # None: the world
    child: Link
    world: Pose
    el: etree._Element
    src: Src
    model_world: Pose


@dataclass
class ModelState:
    """A model in a world's `<state>` (Gazebo classic applies it when it loads the world; worlds saved
    from the GUI keep their true poses there): world poses of the model and its links, its scale."""

    pose: Pose | None
    scale: tuple[float, float, float] | None
    links: dict[str, Pose]  # scoped link key (`link`, `sub::link`) -> world pose
    el: etree._Element


@dataclass
class Collected:
    links: list[Link] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
