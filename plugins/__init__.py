"""Built-in plugins, one module each, registered through the `scenario.plugins` entry-point group."""

import runner  # noqa: F401  (chooses the headless GL backend before any plugin imports mujoco)
