"""Where a suite's recordings, reports and plots go (`scenario test --ray --artifacts URL`), one folder per
variant (`two_robots-3/two_robots-3.mcap`, `.html`, `.trajectory.png`) and the summary page at the top.

A plain path is a folder on the machine that runs `scenario test`: the cluster's workers send the files back
with their results. Anything with a scheme (`s3://bucket/runs`, `gs://...`, `file:///mnt/shared/runs`) is
an fsspec URL that each worker writes to itself; fsspec needs that filesystem's own package (s3fs,
gcsfs...) where the files are written."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from runner.errors import RunError

_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")


def is_url(where: str) -> bool:
    """Whether `--artifacts` names an fsspec URL (the workers write there) rather than a local folder."""
    return bool(_SCHEME.match(where))


def filesystem(url: str) -> tuple[Any, str]:
    """(the fsspec filesystem, the path in it) of an artifacts URL; a clear error when fsspec or the
    filesystem's package is not installed, or the scheme is unknown."""
    try:
        import fsspec
    except ImportError:
        raise RunError(
            f"--artifacts {url}: writing to a URL needs fsspec: pip install 'scenario-runner[ray]'"
        ) from None
    try:
        return fsspec.core.url_to_fs(url)
    except ImportError as e:
        raise RunError(f"--artifacts {url}: {e}") from None
    except ValueError as e:  # an unknown protocol
        raise RunError(
            f"--artifacts {url}: {e}\n  hint:     a local folder, file://, s3://, gs://..."
        ) from None


def check_url(url: str) -> None:
    """Fail early, on the driver, when the URL cannot be written (no package, unknown scheme, refused)."""
    fs, root = filesystem(url)
    try:
        fs.makedirs(root, exist_ok=True)
    except Exception as e:
        raise RunError(f"--artifacts {url}: cannot write there: {type(e).__name__}: {e}") from None


def upload(url: str, folder: str, files: list[Path]) -> dict[str, str]:
    """Copy `files` to `<url>/<folder>/`: {file name: its URL}."""
    fs, root = filesystem(url)
    base = f"{root.rstrip('/')}/{folder}"
    fs.makedirs(base, exist_ok=True)
    out: dict[str, str] = {}
    for f in files:
        fs.put_file(str(f), f"{base}/{f.name}")
        out[f.name] = f"{url.rstrip('/')}/{folder}/{f.name}"
    return out


def save(root: Path, folder: str, blobs: dict[str, bytes]) -> dict[str, str]:
    """Write files sent back by a worker into `<root>/<folder>/`: {file name: its path}."""
    base = root / folder
    base.mkdir(parents=True, exist_ok=True)
    out: dict[str, str] = {}
    for name, data in blobs.items():
        path = base / Path(name).name  # (a name, never a path out of the folder)
        path.write_bytes(data)
        out[name] = str(path)
    return out


def write_text(where: str, name: str, text: str) -> str:
    """Write `text` as `<where>/<name>` (a folder or a URL): where it went."""
    if not is_url(where):
        path = Path(where) / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
        return str(path)
    fs, root = filesystem(where)
    with fs.open(f"{root.rstrip('/')}/{name}", "w", encoding="utf-8") as f:
        f.write(text)
    return f"{where.rstrip('/')}/{name}"
