"""Who records where: a recording's claim is a lock on a hidden `.<name>.lock` beside it, held by the
run recording it (and then by its guard, `runner.record.finisher`) until the file is complete.
"""

from __future__ import annotations

import os
from pathlib import Path


def recording_live(path: Path) -> bool:
    """Whether a live run (or its guard) holds the claim on the recording `path` (see `claim`)."""
    import fcntl

    try:
        fd = os.open(path.with_name(f".{path.name}.lock"), os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError:
        return True
    finally:
        os.close(fd)
    return False


def claim(path: Path) -> tuple[Path, int]:
    """The recording path this run may write, and the descriptor that holds it: a lock on a hidden
    `.<name>.lock` beside it (released when the process ends, however it ends). A path another live run
    is recording to is not touched: the next free `<stem>-2.mcap`, `-3`... is taken instead."""
    import fcntl

    for n in range(1, 1000):
        candidate = path if n == 1 else path.with_name(f"{path.stem}-{n}{path.suffix}")
        lock = candidate.with_name(f".{candidate.name}.lock")
        fd = os.open(lock, os.O_WRONLY | os.O_CREAT, 0o600)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        return candidate, fd
    raise OSError(f"a thousand runs are recording beside {path}")
