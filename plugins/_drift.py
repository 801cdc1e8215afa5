"""A slowly drifting sensor bias, shared by the imu and gps plugins.

The process is hector_gazebo_plugins' `SensorModel` (the error model of its IMU, GPS, sonar, magnetometer),
per axis: a first-order Gauss-Markov process of frequency `f` (1 / correlation time) and scale `sigma`,
updated at every reading, `dt` seconds apart:

    b <- b * exp(-f * dt) + dt * N(0, sqrt(2 f) * sigma)

The caller draws the starting value (hector: N(0, sigma)). The step is scaled by `dt`, not `sqrt(dt)`, as
in hector: its stationary spread, sigma * sqrt(dt) for small f * dt, depends on the reading rate, so a run
of a few minutes keeps close to its starting bias (with the default f = 1/3600 Hz, the bias moves by about
sigma * sqrt(2 f dt t) in t seconds).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


class DriftingBias:
    """A bias per axis that drifts at every `update()`; `value` is the current one (a numpy array)."""

    def __init__(
        self,
        rng: np.random.Generator,
        start: Sequence[float] | np.ndarray,
        sigma: Sequence[float] | np.ndarray,
        frequency: Sequence[float] | np.ndarray,
        dt: float,
    ):
        self.rng = rng
        self.value = np.array(start, dtype=float)
        n = len(self.value)
        sigma_ = np.broadcast_to(np.asarray(sigma, dtype=float), (n,))
        f = np.broadcast_to(np.asarray(frequency, dtype=float), (n,))
        self.decay = np.exp(-f * dt)
        self.step = dt * np.sqrt(2.0 * f) * sigma_
        # a frequency of 0 is a constant bias: no draws, so the other noise streams are unchanged
        self.on = bool(np.any(f > 0))

    def update(self) -> np.ndarray:
        """One reading later: the new bias."""
        if self.on:
            self.value = self.value * self.decay + self.step * self.rng.standard_normal(len(self.value))
        return self.value
