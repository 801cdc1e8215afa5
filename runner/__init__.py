"""scenario-runner: declarative YAML robot-simulation scenarios (URDF/xacro, MuJoCo, Zenoh, MCAP)."""

import os

# We never open a window: render offscreen through EGL unless the user chose a backend (osmesa, glfw).
# MuJoCo reads this once, when it is first imported, so it is set before any of our modules import it.
os.environ.setdefault("MUJOCO_GL", "egl")
