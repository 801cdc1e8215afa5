"""The run's messages: published at sim times (`timeline:`), delivered reliably or not (`qos:`), recorded
to MCAP (`record:`), with the Foxglove 3D view a recording carries (`foxglove:`)."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, NonNegativeFloat, PositiveFloat, model_validator

from runner.scenario.schema.base import TOPIC_RE, Strict


class TimelineEntry(Strict):
    """At sim time `t`, publish a message on a topic of the run (`topic`, `type`, `data`), or call a
    service of the world (`call`, `data` the request): `/reset_simulation`, `/world/<world>/control`..."""

    t: NonNegativeFloat = Field(description="Sim time in seconds.")
    topic: str | None = Field(
        None,
        pattern=TOPIC_RE.pattern,
        description="Topic inside the run's key space, e.g. `r1/cmd_vel` (-> `<run>/r1/cmd_vel`).",
    )
    call: str | None = Field(
        None,
        pattern=TOPIC_RE.pattern,
        description="Instead of `topic`: a service of the world to call, e.g. `/reset_simulation`, "
        "`/pause_physics`, `/world/<world>/control` (`scenario validate` lists them); `data` is the "
        "request, the type is the service's. Answered at that step, recorded as `<service>/_service_event`. "
        "Made once per run: a `/reset_simulation` replays the topics' entries, not the calls.",
    )
    type: str | None = Field(
        None,
        description="ROS 2 message type, e.g. `geometry_msgs/msg/Twist` (with `call`: the service's type, "
        "which may be left out).",
    )
    data: dict[str, Any] = Field(
        default_factory=dict, description="Message fields as YAML; omitted fields are zero."
    )

    @model_validator(mode="after")
    def _what(self) -> TimelineEntry:
        if (self.topic is None) == (self.call is None):
            raise ValueError(
                "an entry has a `topic` (a message to publish) or a `call` (a service), one of them"
            )
        if self.topic is not None and self.type is None:
            raise ValueError("a message on a topic needs its `type`, e.g. geometry_msgs/msg/Twist")
        return self

    @property
    def name(self) -> str:
        """The topic, or the service called."""
        return self.topic if self.topic is not None else str(self.call)


class Record(Strict):
    enabled: bool = Field(True, description="Record the run to MCAP.")
    path: str | None = Field(
        None,
        description="MCAP file to write, relative to the scenario's folder (default: `runs/<name>.mcap` "
        "in the current folder).",
    )
    include: list[str] = Field(
        default_factory=lambda: ["**"],
        description="Zenoh key expressions relative to the run (`*/scan`, `r1/**`) of topics to record.",
    )
    exclude: list[str] = Field(default_factory=list, description="Key expressions of topics not to record.")
    compression: Literal["zstd", "none"] = Field(
        "zstd",
        description="How the MCAP's chunks are compressed: `zstd` (as MCAP writers do by default; level "
        "1), or `none`, for cameras recorded on a machine short of CPU: an 800x800 frame with Gazebo noise "
        "costs ~5 ms of zstd and shrinks about 2x (a clean one 0.4 ms and 100x); uncompressed, the file is "
        "larger and the run faster where the recorder shares the cores with the rendering.",
    )


class QosRule(Strict):
    """How the publishers of some topics behave when a subscriber falls behind."""

    topics: str = Field(
        description="Key expression inside the run (`*/camera/**`, `r1/scan`): the topics this rule is for."
    )
    reliability: Literal["reliable", "best_effort"] = Field(
        description="`reliable` (the default for every topic): a publisher waits rather than drop a message, "
        "so nothing recorded is ever lost and a slow subscriber slows the simulation down; `best_effort`: "
        "it drops instead (cameras for a live viewer: the simulation never waits; the recorder counts "
        "what was lost)."
    )


class Foxglove(Strict):
    """What the world publishes so that a recording (or a live run) opens in Foxglove as a 3D view with no
    set-up: the world's and robots' geometry, every link's transform, each robot's URDF."""

    scene: bool = Field(
        True,
        description="Publish `scene` (foxglove.SceneUpdate: boxes, cylinders, spheres, meshes of every "
        "body), `tf_static`/`tf` (every link, from `world`: a `robot_state_publisher` `tf` plugin is added "
        "to each robot without a `tf` plugin) and `<ns>/robot_description` (URDF, links named "
        "`<ns>/<link>`).",
    )
    rate: PositiveFloat = Field(
        1.0, description="How often (per sim second) the scene, static transforms and URDFs are sent again."
    )
    tf_rate: PositiveFloat = Field(30.0, description="Transforms of moving links per sim second.")
