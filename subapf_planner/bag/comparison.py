"""Recorded vs replayed commands, as both replays (in-process and over DDS) report them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Comparison:
    """Recorded vs replayed commands: times [s], (v, w) arrays (n, 2), NaN = none.

    ``skipped`` leading commands were published before the bag holds a scan, an
    odometry message and a goal (the recording started after the node did):
    they cannot be replayed and are left out of the comparison.
    """

    times: np.ndarray
    recorded: np.ndarray
    replayed: np.ndarray
    skipped: int = 0

    @property
    def diff(self) -> np.ndarray:
        d = np.abs(self.replayed - self.recorded)
        d = np.where(np.isnan(d), np.inf, d)
        d[:self.skipped] = 0.0
        return d

    def first_divergence(self, tol_v: float, tol_w: float) -> float | None:
        bad = (self.diff[:, 0] > tol_v) | (self.diff[:, 1] > tol_w)
        return float(self.times[np.argmax(bad)]) if np.any(bad) else None
