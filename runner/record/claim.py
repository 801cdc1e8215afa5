"""Who records where: a recording's claim is a lock on a hidden `.<name>.lock` beside it, held by the
run recording it (and then by its guard, `runner.record.finisher`) until the file is complete.

The lock is a `flock`, which the kernel drops when its holders are gone, however they ended; the file it
is on stays behind when the run and its guard were both killed. Such stale lock files are removed by the
run's keeper (runner.launch.keeper) or, failing that, by the next run that records in the same folder,
together with a recording beside one that holds nothing (a run that could not write its first bytes: a
full disk). A lock file is only ever removed by whoever holds its lock, and `claim` checks, once it holds
one, that the name is still its file, so a claim never rests on a removed file.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

# a recording shorter than the MCAP magic and one record's head holds nothing (runner.launch.keeper too)
EMPTY_BELOW = 8 + 9
MAGIC = b"\x89MCAP0\r\n"  # (runner.record.finisher's; not imported: the keeper script has the same checks)
# what a lock file of ours says: `clear_stale` removes no other (a folder a scenario records into may be
# anyone's: it removed a user's `.notes.lock` and the 5-byte `notes` beside it)
LOCK_MARK = b"scenario-runner recording lock\n"


def ours(lock: Path) -> bool:
    """Whether `lock` is a recording's lock file: it says so, or it is the empty `.<name>.mcap.lock` of a
    run from before locks said so."""
    try:
        with open(lock, "rb") as f:
            head = f.read(len(LOCK_MARK))
    except OSError:
        return False
    return head == LOCK_MARK or (head == b"" and lock.name.endswith(".mcap.lock"))


def holds_nothing(recording: Path) -> bool:
    """Whether `recording` is a recording that never got past its first bytes: shorter than a record, and
    what it has is the start of an MCAP file (a user's short file beside a lock is not ours to remove)."""
    try:
        with open(recording, "rb") as f:
            head = f.read(EMPTY_BELOW)
    except OSError:
        return False
    return len(head) < EMPTY_BELOW and head[: len(MAGIC)] == MAGIC[: len(head)]


def refuse_foreign(path: Path) -> None:
    """Raise `FileExistsError` when `path` is something a recording must not overwrite: anything but a
    regular file, or a file that is neither empty nor an MCAP recording. A scenario names its `record.path`,
    and one from elsewhere named `../../.bashrc`; a device (`/dev/sda`) would have been written over too."""
    try:
        st = path.stat()
    except FileNotFoundError:
        return
    import errno
    import stat

    if not stat.S_ISREG(st.st_mode):
        raise FileExistsError(errno.EEXIST, f"{path} exists and is not a regular file: it is not written to")
    if st.st_size:
        with open(path, "rb") as f:
            head = f.read(len(MAGIC))
        if head != MAGIC[: len(head)]:
            raise FileExistsError(
                errno.EEXIST, f"{path} exists and is not an MCAP recording: it is not overwritten"
            )


def lock_of(path: Path) -> Path:
    """The lock file of the recording `path`."""
    return path.with_name(f".{path.name}.lock")


def recording_live(path: Path) -> bool:
    """Whether a live run (or its guard) holds the claim on the recording `path` (see `claim`)."""
    import fcntl

    try:
        fd = os.open(lock_of(path), os.O_RDONLY)
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
    is recording to is not touched: the next free `<stem>-2.mcap`, `-3`... is taken instead. Stale lock
    files in the folder (their runs gone) are removed first (see `clear_stale`)."""
    import fcntl

    clear_stale(path.parent)
    n = 1
    while n < 1000:
        candidate = path if n == 1 else path.with_name(f"{path.stem}-{n}{path.suffix}")
        lock = lock_of(candidate)
        fd = os.open(lock, os.O_WRONLY | os.O_CREAT, 0o600)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            n += 1
            continue
        if not _still_named(lock, fd):  # removed (stale) between our open and our lock: open it again
            os.close(fd)
            continue
        if os.fstat(fd).st_size == 0:
            with contextlib.suppress(OSError):  # (a full disk: an empty `.<name>.mcap.lock` is ours too)
                os.write(fd, LOCK_MARK)
        return candidate, fd
    raise OSError(f"a thousand runs are recording beside {path}")


def clear_stale(folder: Path) -> list[Path]:
    """Remove the lock files in `folder` nobody holds (their runs and guards gone), and the recording
    beside each if it holds nothing; what was removed."""
    import fcntl

    removed: list[Path] = []
    try:
        locks = [
            p for p in folder.iterdir() if p.name.startswith(".") and p.name.endswith(".lock") and ours(p)
        ]
    except OSError:  # (no folder yet: nothing stale in it)
        return removed
    for lock in locks:
        try:
            fd = os.open(lock, os.O_RDONLY)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            if not _still_named(lock, fd):
                continue
            recording = lock.with_name(lock.name[1 : -len(".lock")])
            with contextlib.suppress(OSError):
                if holds_nothing(recording):
                    recording.unlink()
                    removed.append(recording)
            lock.unlink()
            removed.append(lock)
        except OSError:  # held: a live run's (or gone meanwhile)
            continue
        finally:
            os.close(fd)
    return removed


def _still_named(lock: Path, fd: int) -> bool:
    try:
        return os.stat(lock).st_ino == os.fstat(fd).st_ino
    except OSError:
        return False
