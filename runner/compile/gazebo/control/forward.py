"""Controllers of this family (see runner.compile.gazebo.control)."""

from __future__ import annotations

from runner.compile.gazebo.control import Handler

HANDLERS: dict[str, Handler] = {}
