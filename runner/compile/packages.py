"""Where ROS packages live, without ROS: `$(find pkg)`, `package://pkg/...`, `model://...`.

Lookup order: packages given explicitly, then any folder holding a `package.xml` whose `<name>` matches
(or a Gazebo model folder, holding a `model.config` or a `model.sdf`, by its folder name), under the
scenario's folder and the folders in SCENARIO_PACKAGE_PATH, ROS_PACKAGE_PATH and GZ_SIM_RESOURCE_PATH.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

ENV_VARS = ("SCENARIO_PACKAGE_PATH", "ROS_PACKAGE_PATH", "GZ_SIM_RESOURCE_PATH")
_SKIP_DIRS = {".git", ".venv", "venv", "node_modules", "__pycache__", "build", "install", "log", "runs"}


@dataclass
class PackageMap:
    explicit: dict[str, Path] = field(default_factory=dict)
    roots: list[Path] = field(default_factory=list)
    allowed: list[Path] = field(default_factory=list)  # more folders xacro may read (`allow_paths:`)
    _found: dict[str, Path] | None = None

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
