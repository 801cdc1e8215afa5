"""SDF `<noise>` of a sensor: white noise N(mean, stddev) at every reading plus a bias drawn once per run
(`NoiseSpec`), read from a `<noise>` block or the classic (SDF 1.4) imu `<rate>`/`<accel>` blocks; what it
has that our sensors do not model (quantization, dynamic bias, a mean where none is taken) is reported.
Every element is read through a `TagReader` (what none reads is said by `g.ignored`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.tags import SdfReader, TagReader

# What a `<noise>` has that we do not model, said when it is not zero (sdf/1.10/noise.sdf; gz-sensors'
# GaussianNoiseModel applies them, Gazebo Classic's only the first four)
_NOT_MODELLED = {
    "precision": "noise <precision> is ignored (readings are not quantized)",
    "dynamic_bias_stddev": "noise <dynamic_bias_stddev> is ignored (gz-sensors drifts the bias as a "
    "Gauss-Markov process; here the bias is drawn once per run)",
    "dynamic_bias_correlation_time": "noise <dynamic_bias_correlation_time> is ignored (the time constant "
    "of gz-sensors' drifting bias; here the bias does not drift)",
}
_NUMBERS = ("stddev", "mean", "bias_mean", "bias_stddev")


@dataclass
class NoiseSpec:
    """SDF `<noise>`: white noise N(mean, stddev) at every reading plus a bias drawn once per run."""

    stddev: float = 0.0
    mean: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0
    el: Any = None


def _numbers(r: TagReader) -> NoiseSpec:
    """The numbers of a noise element (`<noise>`, or a classic `<rate>`/`<accel>` block); 0 if absent."""
    vals = [r.float(tag) or 0.0 for tag in _NUMBERS]
    return NoiseSpec(*vals, el=r.el)


def noise_stddev(
    g: ReaderBase, parent: TagReader | None, what: str = "this sensor", context: str = ""
) -> float | None:
    """The stddev of a `<noise>` under `parent`; a mean or bias is not modelled here (reported)."""
    spec = noise_spec(g, parent, context or what)
    if spec is None:
        return None
    if spec.mean:
        g.note(spec.el, f"a non-zero noise <mean> is ignored for {what} (use a bias in the plugin params)")
    if spec.bias_mean or spec.bias_stddev:
        g.note(spec.el, f"a noise bias (<bias_mean>, <bias_stddev>) is not modelled for {what}")
    return spec.stddev or None


def noise_spec(g: ReaderBase, parent: TagReader | None, context: str = "a sensor") -> NoiseSpec | None:
    """SDF `<noise>` under `parent` (gaussian, with a bias drawn once per run from N(bias_mean,
    bias_stddev) with a random sign); what it has that we do not model (quantization, dynamic bias) is
    reported, and so is anything that is not an element of `<noise>`. None: no noise (none, or `type`
    none: gz-sensors' NoiseFactory makes no noise model then, whatever the numbers say)."""
    noise = parent.child("noise") if parent is not None else None
    if noise is None:
        return None
    r = SdfReader(noise)
    where = f"{context} <noise>"
    kind = (noise.get("type") or r.text("type") or "gaussian").strip()
    spec = _numbers(r)
    extra = {tag: r.float(tag) for tag in _NOT_MODELLED}
    if kind.lower() == "none":
        if spec.stddev or spec.mean or spec.bias_mean or spec.bias_stddev or any(extra.values()):
            g.note(noise, f"{where} has type 'none': its numbers are not used (in Gazebo neither)")
        g.ignored(r, where)
        return None
    if kind.lower() not in ("gaussian", "gaussian_quantized"):
        g.note(noise, f"noise type {kind!r} is treated as gaussian")
    for tag, value in extra.items():
        if value:
            g.note(r.child(tag), _NOT_MODELLED[tag])
    g.ignored(r, where)
    return spec


def classic_noise_spec(g: ReaderBase, noise: TagReader, block: str, context: str) -> NoiseSpec | None:
    """The classic imu `<noise>`'s `<rate>` or `<accel>` block, for all three axes."""
    el = noise.child(block)
    if el is None:
        return None
    r = SdfReader(el)
    spec = _numbers(r)
    g.ignored(r, f"{context} <noise><{block}>")
    kind = (noise.text("type") or "gaussian").strip().lower()
    if kind == "none":
        return None
    return spec
