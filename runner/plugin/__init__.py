"""The plugin API: what a built-in or third-party plugin implements.

A plugin is a class with a `Params` pydantic model and fixed-name hooks:

- `build(params, ctx)` (classmethod, compile time): add what the plugin needs to the robot's MuJoCo
  model (actuators, sites, sensors) and declare the topics it publishes and subscribes;
- `setup()`, `before_step(now_ns)`, `after_step(now_ns)`, `close()` (run time, in the world process).
  `after_step` is called at the plugin's `rate` (sim Hz; every physics step if it has none),
  `before_step` at its `control_rate_of` (by default the same rate). Hooks that a class does not override
  are never called.

Plugins never touch Zenoh: they publish and subscribe through `ctx.publisher(...)`/`ctx.subscribe(...)`.
Built-ins are registered in the `scenario.plugins` entry-point group, as a third-party package would be.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import mujoco
import numpy as np
from pydantic import BaseModel, ConfigDict, Field, PositiveFloat

from runner.errors import closest
from runner.plugin.handle import RobotHandle

if TYPE_CHECKING:
    from runner.plugin.actions import ActionServer, GoalHandle
    from runner.wire.cdr import Layout

# `reply(response)`: what a service handler calls, once, with the response message
Reply = Callable[[Any], None]


# The most bytes a message from another process may have on a key a plugin takes, checked before it is
# decoded or queued: a valid 96 MB JointState (12 M names) cost the world 16.6 s and 400 MB to decode. The
# built-in plugins take commands of bytes to kilobytes (a Twist is 48 bytes of data; a JointState or
# Float64MultiArray for 100 joints, a few KB). A plugin that takes larger ones (a map, a trajectory of
# 100,000 points) says so in its subscription: `ctx.subscribe(..., max_bytes=...)`.
MAX_INBOUND_BYTES = 8 * 1024 * 1024


def _size_text(n: int) -> str:
    return f"{n // (1024 * 1024)} MiB" if n % (1024 * 1024) == 0 else f"{n:,} bytes"


def too_large(limit: int) -> str:
    """The reason a message over `limit` bytes is dropped, as the end table and metadata count it (one kind
    whatever the sizes: a stray publisher's sizes are its own to vary; the first one's is said on stderr)."""
    return f"more than the {_size_text(limit)} limit for a message a plugin takes"


# MuJoCo geom groups with a meaning across the run (compile puts geoms there, sensors read them):
RAY_GROUP = 4  # a world mesh as drawn: no contacts, hit by rays
PIECES_GROUP = 5  # its convex pieces: contacts, not hit by rays, never drawn


class PluginParams(BaseModel):
    """Base of every plugin's `Params`: unknown keys are errors."""

    model_config = ConfigDict(extra="forbid")


class RatedParams(PluginParams):
    rate: PositiveFloat = Field(10.0, description="How often the plugin runs and publishes, in sim Hz.")


class PluginConfigError(Exception):
    """A plugin's parameters do not fit the robot (e.g. a `link` that the URDF does not have).
    `param` names the parameter, so the error can point at its line in the scenario."""

    def __init__(self, message: str, param: str | None = None, hint: str | None = None):
        super().__init__(message)
        self.param = param
        self.hint = hint


@dataclass(frozen=True)
class Topic:
    """A topic a plugin uses. `name` is relative to the robot's namespace unless it starts with '/'."""

    name: str
    type: str
    direction: Literal["pub", "sub"] = "pub"
    rate: float | None = None


@dataclass(frozen=True)
class Service:
    """A service (`kind="service"`, `type` pkg/srv/Name) or action server (`kind="action"`, `type`
    pkg/action/Name) a plugin offers, returned by `build` beside its topics. `name` is relative to the
    robot's namespace unless it starts with '/'. An action's `_action/feedback` and `_action/status` topics
    are added to the plan by the compiler: the plugin declares the action only."""

    name: str
    type: str
    kind: Literal["service", "action"] = "service"


@dataclass
class BuildContext:
    """What `Plugin.build` sees: the robot's own MjSpec (names as in its URDF) before it is placed."""

    spec: mujoco.MjSpec
    robot: str
    namespace: str
    root: str
    # the description's root link is `world` (MuJoCo's world body): `root` and its siblings hang from it
    world_link: bool = False

    @property
    def links(self) -> list[str]:
        return [b.name for b in self.spec.bodies if b.name and b.name != "world"]

    @property
    def joints(self) -> list[str]:
        return [j.name for j in self.spec.joints if j.name]

    def body(self, name: str, param: str = "link") -> Any:
        body = self.spec.body(name) if name else None
        if body is None:
            raise PluginConfigError(
                f"robot {self.robot!r} has no link {name!r}",
                param,
                hint=_names_hint(name, self.links, "links"),
            )
        return body

    def joint(self, name: str, param: str) -> Any:
        joint = self.spec.joint(name) if name else None
        if joint is None:
            movable = [j.name for j in self.spec.joints if j.name and j.type != mujoco.mjtJoint.mjJNT_FREE]
            raise PluginConfigError(
                f"robot {self.robot!r} has no joint {name!r}",
                param,
                hint=_names_hint(name, movable, "joints"),
            )
        return joint


def _names_hint(name: str, names: list[str], what: str) -> str:
    """The one of `names` closest to `name` ("did you mean"), then all of them: what a plugin may name."""
    near = closest(name, names) if name else None
    return (f"did you mean {near!r}? " if near else "") + f"{what}: " + ", ".join(names)


class Publisher:
    """Publishes one topic. Made by `RuntimeContext.publisher`.

    `publish(msg, stamp)` takes a rosbags message object and encodes it. On hot paths, encode once into a
    fixed layout and send bytes: `layout = pub.layout(template, fields)`, then
    `pub.publish_cdr(layout.encode(stamp, ...), stamp)` (see `runner.wire.cdr`): a few microseconds a message.
    """

    def __init__(
        self,
        key: str,
        type_name: str,
        send: Callable[[Any, int], None],
        send_cdr: Callable[[bytes | bytearray, int], None] | None = None,
    ):
        self.key = key
        self.type = type_name
        # the sender's own functions, bound as attributes: no extra call per message
        self.publish: Callable[[Any, int], None] = send
        if send_cdr is not None:
            self.publish_cdr: Callable[[bytes | bytearray, int], None] = send_cdr

    def publish(self, msg: Any, stamp_ns: int) -> None:  # type: ignore[no-redef]  # replaced in __init__
        """Publish a rosbags message object of this topic's type."""
        raise NotImplementedError

    def publish_cdr(self, payload: bytes | bytearray, stamp_ns: int) -> None:  # type: ignore[no-redef]
        """Publish bytes that are already the CDR encoding of a message of this topic's type. A `bytearray`
        is borrowed (`Layout.fill`): sent at once, copied only where it is kept, free to reuse after."""
        from runner.wire import msgs

        self.publish(msgs.decode(payload, self.type), stamp_ns)

    def layout(self, template: Any, fields: Sequence[str] = ()) -> Layout:
        """A fixed-layout encoder for this topic's type (see `runner.wire.cdr.Layout`)."""
        from runner.wire.cdr import Layout

        return Layout(self.type, template, fields)


@dataclass
class RuntimeContext:
    """What a plugin sees at run time."""

    model: mujoco.MjModel
    data: mujoco.MjData
    robot: RobotHandle
    rng: np.random.Generator
    run: str
    _make_publisher: Callable[[str, str], Publisher] = field(repr=False)
    _subscribe: Callable[..., None] = field(repr=False)
    _serve: Callable[..., None] | None = field(default=None, repr=False)
    _plugins: Callable[[], list[Plugin]] | None = field(default=None, repr=False)

    def publisher(self, topic: str, type_name: str) -> Publisher:
        return self._make_publisher(topic, type_name)

    def subscribe(
        self, topic: str, type_name: str, callback: Callable[[Any, int], None], max_bytes: int | None = None
    ) -> None:
        """`callback(msg, stamp_ns)` is called in the sim loop, between physics steps. A message from
        another process holding a NaN or Inf, or larger than `max_bytes` (by default
        MAX_INBOUND_BYTES, 8 MiB), is dropped and counted before it reaches the callback."""
        self._subscribe(topic, type_name, callback, max_bytes=max_bytes)

    def plugins(self) -> list[Plugin]:
        """The plugins of this robot, in plan order (all made; `setup` runs in that order): a controller
        manager finds the controllers it switches."""
        return [] if self._plugins is None else self._plugins()

    def service(self, name: str, type_name: str, handler: Callable[[Any, Reply], None]) -> None:
        """Offer the service `name` (declared by `build` as a `Service`): `handler(request, reply)` is
        called in the sim loop, between physics steps, with the decoded `pkg/srv/Name_Request`; it calls
        `reply(response)` once, at once or at a later step (an action's result). A request that does not
        decode, or holds a NaN or Inf, is answered with an error before it reaches the handler."""
        if self._serve is None:
            raise RuntimeError("this world offers no services")
        self._serve(name, type_name, handler)

    def action_server(
        self,
        name: str,
        type_name: str,
        on_goal: Callable[[GoalHandle], bool],
        on_cancel: Callable[[GoalHandle], bool] | None = None,
    ) -> ActionServer:
        """Offer the action `name` of type `type_name` (pkg/action/Name), as rclcpp_action's server does
        (runner.plugin.actions): `on_goal(handle)` accepts (True) or rejects a goal; `on_cancel(handle)`
        accepts a cancel request (the plugin then ends the goal with `handle.canceled(result)`)."""
        from runner.plugin.actions import ActionServer

        return ActionServer(self, name, type_name, on_goal, on_cancel)


class Plugin:
    """Base class of every plugin. Subclasses set `Params` and override the hooks they need."""

    Params: ClassVar[type[PluginParams]] = PluginParams
    type_name: ClassVar[str] = ""
    renders: ClassVar[bool] = False  # needs OpenGL: the runner picks a working backend for its process
    # `after_step` reads values of MuJoCo's acceleration stage (contact and constraint forces, force/torque/
    # touch sensors): the world then runs `mj_forward` before it. Otherwise the hook sees positions,
    # velocities, contacts and position/velocity sensors of the current instant, and acceleration-stage
    # sensor values (accelerometer) of the step that led to it, at no extra cost.
    needs_forward: ClassVar[bool] = False
    # Parameters an event may change while the plugin runs (`set:`): ones its hooks read from `self.params`
    # every time (the world swaps in a new, validated `params`). `rate` is the world's to change, always.
    live: ClassVar[frozenset[str]] = frozenset()

    def __init__(self, params: PluginParams, ctx: RuntimeContext, name: str):
        self.params = params
        self.ctx = ctx
        self.name = name

    @classmethod
    def build(cls, params: Any, ctx: BuildContext, name: str) -> list[Topic]:
        """Compile time: change the robot's model, return the topics used (and, as `Service`s, the
        services and actions offered)."""
        return []

    @classmethod
    def rate_of(cls, params: PluginParams) -> float | None:
        rate = getattr(params, "rate", None)
        return float(rate) if rate else None

    @classmethod
    def control_rate_of(cls, params: PluginParams) -> float | None:
        """How often `before_step` runs (sim Hz; None: at `rate_of`). A plugin that both controls and
        publishes (a drive) controls at a high rate whatever it publishes at, as Gazebo's do."""
        return cls.rate_of(params)

    def setup(self) -> None:
        """Run time, once, before the first step."""

    def before_step(self, now_ns: int) -> None:
        """Act on the model before physics advances (controllers, commands)."""

    def after_step(self, now_ns: int) -> None:
        """Read the model after physics reached `now_ns` (sensors) and publish."""

    def rebind(self) -> None:
        """The world's model grew (a robot was spawned, runner.sim.grow): `self.ctx.model` and
        `self.ctx.data` are new objects. Every MuJoCo id and address this plugin holds is still valid (what
        was there keeps its ids; the new robot's things come after), but anything made from the old model or
        data must be made again here: numpy views into `data` (`data.sensordata[a:b]`), renderers and
        OpenGL contexts, tables sized by the model's counts. The world checks after this call that the
        plugin holds no view of the old data and no old model or data object, and says so if it does."""

    def close(self) -> None:
        """Run time, once, at the end (and when its robot is deleted)."""


def overrides(obj: Plugin, hook: str) -> bool:
    return getattr(type(obj), hook) is not getattr(Plugin, hook)
