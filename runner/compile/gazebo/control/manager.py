"""The controller manager node of a control plugin, as our `controller_manager` plugin
(plugins/controller_manager.py): the controllers each control plugin runs (their names, types as their
files give them, the plugins that run them, update rates) and those its launch does not spawn, so that its
services (`<manager>/list_controllers`, `switch_controller`, ...) answer for them at run time."""

from __future__ import annotations

from typing import Any

from runner.compile.gazebo.control import ControlContext, ControllerSpec
from runner.compile.gazebo.info import DescribedPlugin, Where

UPDATE_RATE = 100.0  # controller_manager_parameters.yaml: update_rate's default


def entry(spec: ControllerSpec, added: list[DescribedPlugin]) -> dict[str, Any]:
    """A controller the handler ran, with the plugins it added for it."""
    rates = [p.params.get("update_rate") for p in added]
    rate = next((r for r in rates if isinstance(r, (int, float))), None) or spec.update_rate or UPDATE_RATE
    return {"name": spec.name, "type": spec.type, "plugins": [p.name for p in added], "update_rate": rate}


def add_manager(
    ctx: ControlContext,
    where: Where,
    manager: str,
    loaded: list[dict[str, Any]],
    not_spawned: list[str],
    taken: set[str],
) -> None:
    """The `controller_manager` plugin of one control plugin; a second manager of the same name in the
    robot (two control plugins) would answer on the same services: said, not added."""
    if manager in taken:
        ctx.g.notices.add(
            f"a second control plugin's controller manager {manager!r}: its services are not offered (the "
            "first one's have those names)",
            *where,
            hint="give each control plugin its own <controller_manager_name>",
        )
        return
    taken.add(manager)
    params = {"manager": manager, "controllers": loaded, "not_spawned": not_spawned or None}
    clean = {k: v for k, v in params.items() if v is not None}
    ctx.g.info.plugins.append(DescribedPlugin("controller_manager", ctx.g.unique(manager), clean, *where))
