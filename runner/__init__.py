"""scenario-runner: declarative YAML robot-simulation scenarios (URDF/xacro, MuJoCo, Zenoh, MCAP)."""


def _quiet_early_signals() -> None:
    """Ctrl-C or SIGTERM while the `scenario` command (or one of its `python -m runner...` processes) is
    still importing: nothing has started and nothing is recorded yet, so it ends at once with 130 / 143,
    without a KeyboardInterrupt traceback. The command's `main` replaces these handlers once it runs.
    Left alone when runner is imported as a library (by tests, by a user's program)."""
    import os
    import signal
    import sys

    from runner.interrupts import exit_at_once

    first = os.path.basename(sys.argv[0]) if sys.argv else ""
    if first not in ("scenario", "-m") and not first.startswith("scenario"):
        return
    if signal.getsignal(signal.SIGINT) in (signal.SIG_DFL, signal.default_int_handler):
        exit_at_once()


_quiet_early_signals()

from runner.gl import ensure_gl_backend  # noqa: E402

# We never open a window: render offscreen (EGL, else OSMesa) unless the user chose a backend. MuJoCo reads
# MUJOCO_GL once, when it is first imported, so this runs before any of our modules imports it.
ensure_gl_backend()


def _few_malloc_arenas() -> None:
    """glibc gives each thread that allocates its own malloc arena (up to 8 per core); with Zenoh's threads
    and the recorder's handing payloads to one another, memory freed in one arena is not reused by the
    next, and a long run's resident memory creeps up (bench/soak.py: +25 % over 10 sim minutes). Two
    arenas keep it flat. Set before our threads start; a no-op off glibc."""
    import ctypes
    import ctypes.util
    import sys

    if not sys.platform.startswith("linux"):
        return
    try:
        try:  # glibc's name, without find_library's helper process (ldconfig), forked at every start
            libc = ctypes.CDLL("libc.so.6")
        except OSError:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.mallopt(-8, 2)  # M_ARENA_MAX
        # a fixed mmap threshold: big buffers (chunks, frames) always go back to the system when freed,
        # instead of glibc raising the threshold and carving them out of (and fragmenting) the heap
        libc.mallopt(-3, 128 * 1024)  # M_MMAP_THRESHOLD
    except (OSError, AttributeError):
        pass


_few_malloc_arenas()
