"""Where ROS packages live, without ROS: `$(find pkg)`, `package://pkg/...`, `model://...`.

Lookup order: packages given explicitly, then any folder holding a `package.xml` whose `<name>` matches
(or a Gazebo model folder, holding a `model.config` or a `model.sdf`, by its folder name), under the
scenario's folder and the folders in SCENARIO_PACKAGE_PATH, ROS_PACKAGE_PATH, GZ_SIM_RESOURCE_PATH (and
Gazebo classic's GAZEBO_MODEL_PATH, GAZEBO_RESOURCE_PATH). A package's `<export><gazebo_ros
gazebo_model_path="${prefix}/models" gazebo_media_path="${prefix}"/>` adds its model folders and the folders
relative `file://` paths are looked up in, as gazebo_ros does when it starts Gazebo.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from runner.errors import Problem

if TYPE_CHECKING:
    from runner.errors import Problems
    from runner.scenario.loader import Document
    from runner.scenario.schema import Scenario

ENV_VARS = (
    "SCENARIO_PACKAGE_PATH",
    "ROS_PACKAGE_PATH",
    "GZ_SIM_RESOURCE_PATH",
    "IGN_GAZEBO_RESOURCE_PATH",
    "GAZEBO_MODEL_PATH",
    "GAZEBO_RESOURCE_PATH",
)
_SKIP_DIRS = {".git", ".venv", "venv", "node_modules", "__pycache__", "build", "install", "log", "runs"}


@dataclass
class PackageMap:
    explicit: dict[str, Path] = field(default_factory=dict)
    roots: list[Path] = field(default_factory=list)
    allowed: list[Path] = field(default_factory=list)  # more folders xacro may read (`allow_paths:`)
    media: list[Path] = field(default_factory=list)  # gazebo_media_path exports: relative file:// paths
    _found: dict[str, Path] | None = None
    _exported: set[Path] = field(default_factory=set)

    def readable(self, path: Path, description: Path) -> bool:
        """Whether xacro, expanding `description`, may read `path`: a file of the scenario's folder or of a
        package root (and below), of the description's own folder, or of an `allow_paths:` folder."""
        target = path.resolve()
        folders = [*self.roots, *self.explicit.values(), description.resolve().parent, *self.allowed]
        return any(target.is_relative_to(f.resolve()) for f in folders)

    @classmethod
    def for_scenario(cls, base_dir: Path, explicit: dict[str, Path] | None = None) -> PackageMap:
        roots = [base_dir]
        for var in ENV_VARS:
            roots += [Path(p) for p in os.environ.get(var, "").split(os.pathsep) if p]
        return cls(dict(explicit or {}), roots)

    def searched(self) -> list[str]:
        return [str(r) for r in self.roots]

    def _scan(self) -> dict[str, Path]:
        if self._found is None:
            found: dict[str, Path] = {}
            for root in self.roots:
                if not root.is_dir():
                    continue
                for dirpath, dirnames, filenames in os.walk(root):
                    dirnames[:] = [d for d in dirnames if d not in _SKIP_DIRS and not d.startswith(".")]
                    if "package.xml" in filenames:
                        name = _package_name(Path(dirpath) / "package.xml")
                        if name and name not in found:
                            found[name] = Path(dirpath)
                        self._exports(Path(dirpath), found)
                        dirnames[:] = []  # a package does not nest packages
                    elif "model.config" in filenames or "model.sdf" in filenames:
                        # A Gazebo model folder (model://<folder name>): Gazebo takes a folder that holds a
                        # model.sdf without a model.config too.
                        found.setdefault(Path(dirpath).name, Path(dirpath))
            self._found = found
        return self._found

    def find(self, name: str) -> Path | None:
        if name in self.explicit:
            return self.explicit[name]
        return self._scan().get(name)

    def add_package_of(self, file: Path) -> None:
        """The exports of the package a file (a world) belongs to, wherever it is: Gazebo started by
        gazebo_ros knows every package's model and media paths, not only those under our roots."""
        package = enclosing_package(file)
        if package is not None:
            self._exports(package, self._scan())

    def _exports(self, package: Path, found: dict[str, Path]) -> None:
        package = package.resolve()
        if package in self._exported:
            return
        self._exported.add(package)
        models, media = gazebo_exports(package)
        for folder in media:
            if folder.is_dir() and folder not in self.media:
                self.media.append(folder)
        for folder in models:
            if not folder.is_dir():
                continue
            for child in sorted(folder.iterdir()):
                if child.is_dir() and ((child / "model.config").is_file() or (child / "model.sdf").is_file()):
                    found.setdefault(child.name, child)


def enclosing_package(file: Path, levels: int = 8) -> Path | None:
    """The nearest folder at or above `file` that holds a package.xml."""
    folder = file.resolve().parent
    for _ in range(levels):
        if (folder / "package.xml").is_file():
            return folder
        if folder.parent == folder:
            return None
        folder = folder.parent
    return None


def gazebo_exports(package: Path) -> tuple[list[Path], list[Path]]:
    """A package's `<export><gazebo_ros gazebo_model_path=... gazebo_media_path=...>` folders (`${prefix}`
    is the package's folder; several paths may be joined by `:`)."""
    try:
        root = ET.parse(package / "package.xml").getroot()
    except (ET.ParseError, OSError):
        return [], []
    models: list[Path] = []
    media: list[Path] = []
    for el in root.iter("gazebo_ros"):
        for attr, out in (("gazebo_model_path", models), ("gazebo_media_path", media)):
            for part in (el.get(attr) or "").split(":"):
                part = part.strip().replace("${prefix}", str(package))
                if part:
                    out.append(Path(part))
    return models, media


def _package_name(package_xml: Path) -> str | None:
    try:
        root = ET.parse(package_xml).getroot()
    except (ET.ParseError, OSError):
        return None
    el = root.find("name")
    return el.text.strip() if el is not None and el.text else None


URI_RE = re.compile(r"^(package|model)://([^/]+)/(.*)$")


def resolve_uri(uri: str, packages: PackageMap, base_dir: Path) -> Path | None:
    """`package://pkg/meshes/a.stl`, `model://m/a.dae`, `file:///abs`, or a path relative to base_dir."""
    m = URI_RE.match(uri)
    if m:
        root = packages.find(m.group(2))
        return (root / m.group(3)) if root else None
    if uri.startswith("file://"):
        return Path(uri[len("file://") :])
    p = Path(uri)
    return p if p.is_absolute() else base_dir / p


def scenario_packages(sc: Scenario, doc: Document, problems: Problems) -> PackageMap:
    """Where `package://` and `model://` names are found: the scenario's `packages:` (each folder must
    exist), its folder, SCENARIO_PACKAGE_PATH...; `allow_paths:` let files outside them be read."""
    base = doc.base_dir
    packages = PackageMap.for_scenario(base, {k: (base / v) for k, v in sc.packages.items()})
    packages.allowed = [base / p for p in sc.allow_paths]
    for name, folder in packages.explicit.items():
        if not folder.is_dir():
            problems.add(
                Problem(
                    f"package folder {str(folder)!r} does not exist",
                    doc.locate(("packages", name)),
                    ("packages", name),
                    hint="paths are relative to the scenario's folder",
                )
            )
    return packages
