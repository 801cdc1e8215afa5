"""SDF `<noise>` of a sensor: white noise N(mean, stddev) at every reading plus a bias drawn once per run
(`NoiseSpec`), read from a `<noise>` block or the classic (SDF 1.4) imu `<rate>`/`<accel>` blocks; what it
has that our sensors do not model (quantization, dynamic bias, a mean where none is taken) is reported."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from runner.compile.gazebo.base import ReaderBase
from runner.compile.gazebo.tables import NOISE_TAGS
from runner.compile.gazebo.tags import is_zero


@dataclass
class NoiseSpec:
    """SDF `<noise>`: white noise N(mean, stddev) at every reading plus a bias drawn once per run."""

    stddev: float = 0.0
    mean: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0
    el: Any = None

    @classmethod
    def of(cls, el: Any) -> NoiseSpec:
        """The numbers of a noise element (`<noise>`, or a classic `<rate>`/`<accel>` block); 0 if absent."""

        def num(tag: str) -> float:
            text = el.findtext(tag)
            return float(text) if text and text.strip() else 0.0

        return cls(num("stddev"), num("mean"), num("bias_mean"), num("bias_stddev"), el)


def noise_stddev(g: ReaderBase, parent: Any | None, what: str = "this sensor") -> float | None:
    """The stddev of a `<noise>` under `parent`; a mean or bias is not modelled here (reported)."""
    spec = noise_spec(g, parent)
    if spec is None:
        return None
    if spec.mean:
        g.note(spec.el, f"a non-zero noise <mean> is ignored for {what} (use a bias in the plugin params)")
    if spec.bias_mean or spec.bias_stddev:
        g.note(spec.el, f"a noise bias (<bias_mean>, <bias_stddev>) is not modelled for {what}")
    return spec.stddev or None


def noise_spec(g: ReaderBase, parent: Any | None) -> NoiseSpec | None:
    """SDF `<noise>` (gaussian, with a bias drawn once per run from N(bias_mean, bias_stddev) with a
    random sign); what it has that we do not model (quantization, dynamic bias) is reported."""
    if parent is None:
        return None
    noise = parent.find("noise")
    if noise is None:
        return None
    kind = (noise.get("type") or noise.findtext("type") or "gaussian").strip()
    if kind.lower() == "none":
        return None
    if kind.lower() not in ("gaussian", "gaussian_quantized"):
        g.note(noise, f"noise type {kind!r} is treated as gaussian")

    for child in noise:
        if not isinstance(child.tag, str) or child.tag in NOISE_TAGS:
            continue
        if child.tag == "precision" and (child.text or "").strip() and float(child.text) != 0.0:
            g.note(child, "noise <precision> is ignored (readings are not quantized)")
        elif child.tag != "precision" and not is_zero(child.text):
            g.note(child, f"noise <{child.tag}> is ignored")
    return NoiseSpec.of(noise)


def classic_noise_spec(noise: Any, block: str) -> NoiseSpec | None:
    """The classic imu `<noise>`'s `<rate>` or `<accel>` block, for all three axes."""
    el = noise.find(block)
    if el is None:
        return None
    kind = (noise.findtext("type") or "gaussian").strip().lower()
    if kind == "none":
        return None

    return NoiseSpec.of(el)
