"""The size bound of a description file (URDF, xacro and each file it includes, SDF), checked before the
file is read or parsed: a xacro file with a 50 MB attribute took 109 s before it was refused (a 5 MB one,
2 s); XML parsers and xacro's passes over attribute text are not linear in it.

Real descriptions are far below the bound: a description holds no mesh data (URDF and SDF name mesh
files), and the large ones we know (humanoid URDFs of a few hundred links, generated ones listing every
mesh, Gazebo worlds of a few thousand models) are a few hundred KB to a few MB.
"""

from __future__ import annotations

from pathlib import Path

MAX_DESCRIPTION_BYTES = 16 * 1024 * 1024

HINT = (
    "a description file may be 16 MiB (runner/compile/filesize.py); a description names its meshes "
    "(<mesh filename=...>), it does not hold their data: keep meshes in mesh files, and split a generated "
    "file into xacro includes or SDF <include>s"
)


def too_large(path: Path) -> str | None:
    """What to say if `path` is larger than a description file may be; None if it is not (or cannot be
    read: the reader says why)."""
    try:
        size = path.stat().st_size
    except OSError:
        return None
    if size <= MAX_DESCRIPTION_BYTES:
        return None
    return f"{path.name} is {size:,} bytes, more than the 16 MiB a description file may be"
