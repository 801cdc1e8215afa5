"""The world a scenario runs in (`world:`, or several under `worlds:`): physics settings, the ground plane,
an SDF/Gazebo world file and primitive models (walls, obstacles, boxes to push)."""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import Field, PositiveFloat, field_validator

from runner.scenario.schema.base import IDENT_RE, Namespace, Pose, Rgba, Strict, Vec3
from runner.scenario.schema.events import Actor


class Physics(Strict):
    timestep: PositiveFloat = Field(0.002, le=0.1, description="Physics step in seconds.")
    gravity: Vec3 = Field((0.0, 0.0, -9.81), description="Gravity in m/s².")
    integrator: Literal["euler", "implicitfast", "implicit", "rk4"] = Field(
        "implicitfast", description="MuJoCo integrator; implicitfast is stable with velocity actuators."
    )
    friction_cone: Literal["elliptic", "pyramidal"] = Field(
        "elliptic",
        description="MuJoCo friction cone. Elliptic is exact; MuJoCo's default pyramidal cone makes high "
        "friction (Gazebo descriptions use mu up to 100) soften contacts until wheels carry no load.",
    )


class Ground(Strict):
    enabled: bool = Field(True, description="Add an infinite ground plane at z = 0.")
    friction: PositiveFloat = Field(1.0, description="Sliding friction coefficient of the ground.")
    rgba: Rgba = Field((0.55, 0.57, 0.6, 1.0), description="Colour of the ground.")


class WorldModel(Strict):
    """A primitive shape in the world: a wall, an obstacle, a box to push."""

    name: Namespace = Field(description="Unique name of the model (its body is named after it).")
    shape: Literal["box", "cylinder", "sphere"] = Field(description="Primitive shape.")
    size: list[PositiveFloat] = Field(
        description="box: [x, y, z] full lengths; cylinder: [radius, length]; sphere: [radius] (metres).",
    )
    pose: Pose = Field(default_factory=Pose, description="Pose of the shape's centre in the world.")
    rgba: Rgba = Field((0.7, 0.7, 0.7, 1.0), description="Colour.")
    static: bool = Field(True, description="A static model never moves; otherwise it is free and has `mass`.")
    mass: PositiveFloat | None = Field(None, description="Mass in kg of a non-static model (default 1).")
    friction: PositiveFloat = Field(1.0, description="Sliding friction coefficient.")

    @field_validator("size")
    @classmethod
    def _size_len(cls, v: list[float], info: Any) -> list[float]:
        need = {"box": 3, "cylinder": 2, "sphere": 1}.get(info.data.get("shape", ""))
        if need is not None and len(v) != need:
            shape = info.data["shape"]
            form = {"box": "[x, y, z]", "cylinder": "[radius, length]", "sphere": "[radius]"}[shape]
            raise ValueError(f"a {shape} needs {need} number(s) {form}, found {len(v)}: write size: {form}")
        return v


class World(Strict):
    sdf: str | None = Field(
        None,
        description="An SDF (1.4-1.9) or Gazebo .world file to load, relative to the scenario's folder; "
        "`models` are added to it.",
    )
    physics: Physics = Field(default_factory=Physics, description="Physics settings.")
    ground: Ground = Field(default_factory=Ground, description="The ground plane.")
    models: list[WorldModel] = Field(default_factory=list, description="Primitive models in the world.")
    actors: list[Actor] = Field(
        default_factory=list,
        description="Models that move on their own (people walking a path, a door that opens), "
        "kinematically: they push robots and are seen by their sensors.",
    )
    clock_rate: PositiveFloat = Field(
        100.0, description="How often sim time is published on `<run>/clock`, in sim Hz."
    )
    host: str | None = Field(None, description="With `hosts:`, the host simulating it (default: the first).")


class NamedWorld(World):
    """One of several worlds: simulated by a process of its own, in a key space of its own."""

    name: Annotated[str, Field(pattern=IDENT_RE.pattern)] = Field(
        description="World name (letters, digits, '_'): the second chunk of its keys (`run/arena/r1/scan`)."
    )
