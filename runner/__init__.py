"""scenario-runner: declarative YAML robot-simulation scenarios (URDF/xacro, MuJoCo, Zenoh, MCAP)."""

from runner.gl import ensure_gl_backend

# We never open a window: render offscreen (EGL, else OSMesa) unless the user chose a backend. MuJoCo reads
# MUJOCO_GL once, when it is first imported, so this runs before any of our modules imports it.
ensure_gl_backend()
