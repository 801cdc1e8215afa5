"""The SDF reader assembled from its parts (see the package's docstring), and its entry point."""

from __future__ import annotations

from pathlib import Path

import mujoco

from runner.compile.packages import PackageMap
from runner.compile.sdf.bodies import BodyBuilder
from runner.compile.sdf.geometry import GeometryReader
from runner.compile.sdf.includes import IncludeReader
from runner.compile.sdf.meshes import MeshReader
from runner.compile.sdf.models import ModelReader
from runner.compile.sdf.parts import SdfWorld
from runner.compile.sdf.scene import SceneBuilder
from runner.compile.sdf.world import WorldReader
from runner.errors import Notices


class Loader(WorldReader, ModelReader, IncludeReader, BodyBuilder, GeometryReader, MeshReader, SceneBuilder):
    """One SDF file (and the files it includes) read into one `MjSpec`."""


def load_sdf_world(spec: mujoco.MjSpec, path: Path, packages: PackageMap, notices: Notices) -> SdfWorld:
    """Add the world (or the bare model) of the SDF file at `path` to `spec`; see the package docstring."""
    loader = Loader(spec, packages, notices)
    try:
        return loader.load(Path(path))
    finally:
        loader.flush()
