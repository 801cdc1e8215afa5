"""scenario-runner: declarative YAML robot-simulation scenarios (URDF/xacro, MuJoCo, Zenoh, MCAP)."""

from runner.gl import ensure_gl_backend

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
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        libc.mallopt(-8, 2)  # M_ARENA_MAX
        # a fixed mmap threshold: big buffers (chunks, frames) always go back to the system when freed,
        # instead of glibc raising the threshold and carving them out of (and fragmenting) the heap
        libc.mallopt(-3, 128 * 1024)  # M_MMAP_THRESHOLD
    except (OSError, AttributeError):
        pass


_few_malloc_arenas()
