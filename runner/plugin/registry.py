"""Plugins are found through the `scenario.plugins` entry-point group, loaded lazily, once.

A name registered twice is an error; a plugin that fails to import is reported only when a scenario
uses it.
"""

from __future__ import annotations

from functools import cache
from importlib.metadata import EntryPoint, entry_points
from typing import Any

from runner.errors import closest
from runner.plugin import Plugin

GROUP = "scenario.plugins"


class PluginLookupError(Exception):
    def __init__(self, message: str, hint: str | None = None):
        super().__init__(message)
        self.hint = hint


@cache
def _entry_points() -> dict[str, list[EntryPoint]]:
    found: dict[str, list[EntryPoint]] = {}
    for ep in entry_points(group=GROUP):
        found.setdefault(ep.name, []).append(ep)
    return found


def available() -> list[str]:
    return sorted(_entry_points())


@cache
def load(name: str) -> type[Plugin]:
    eps = _entry_points().get(name)
    if not eps:
        near = closest(name, available())
        hint = f"did you mean {near!r}? " if near else ""
        raise PluginLookupError(
            f"unknown plugin type {name!r}",
            hint=hint + "installed plugins: " + ", ".join(available()),
        )
    distinct = {ep.value for ep in eps}
    if len(distinct) > 1:
        raise PluginLookupError(
            f"plugin type {name!r} is registered more than once: " + ", ".join(sorted(distinct)),
            hint="uninstall one of the packages that provide it",
        )
    try:
        cls = eps[0].load()
    except Exception as e:  # a broken third-party plugin: report it, only now that it is used
        raise PluginLookupError(
            f"plugin {name!r} ({eps[0].value}) failed to import: {type(e).__name__}: {e}",
            hint="fix or reinstall the package that provides it",
        ) from None
    if not (isinstance(cls, type) and issubclass(cls, Plugin)):
        raise PluginLookupError(f"{eps[0].value} is not a runner.plugin.Plugin subclass")
    cls.type_name = name
    return cls


def drive_frames(plugin_type: str, params: dict[str, Any]) -> tuple[str, str | None] | None:
    """(odom frame, base frame or None for the root) of a base drive that publishes odom -> base."""
    try:
        p = load(plugin_type).Params.model_validate(params)
    except Exception:
        return None
    if "odom_frame" not in type(p).model_fields or not getattr(p, "publish_tf", False):
        return None
    return p.odom_frame, p.base_frame
