"""The ``progress`` critic: Algorithm 1's score of a sample.

A sample's cost is the distance to the goal of the APF step taken from it (the "next
next move point", eq. 23): Euclidean in the paper's method, through free space along
the navigation field with the memory. Where the field has no value (inside an
inflated obstacle) the Euclidean distance plus UNKNOWN_PENALTY: worse than any way
the field knows, better than a discarded sample.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..apf import apf_step
from ..config import PlannerConfig
from . import Samples

#: Added to the Euclidean distance where the navigation field has no value [m]: more
#: than any distance through a map window (map_size is at most 200 m).
UNKNOWN_PENALTY = 1000.0


class Progress:
    """Distance to go after the next APF step from each sample [m]."""

    name = 'progress'

    def __init__(self, cfg: PlannerConfig) -> None:
        self.cfg = cfg

    def cost(self, samples: Samples) -> NDArray[np.float64]:
        out = np.full(len(samples.points), np.inf)
        safe = samples.safe
        if not np.any(safe):
            return out
        nxt = apf_step(samples.points[safe], samples.goal, samples.repulsors, self.cfg,
                       samples.field)
        euclid = np.linalg.norm(nxt - samples.goal, axis=1)
        if samples.field is None:
            out[safe] = euclid
        else:
            v = samples.field.value(nxt)
            out[safe] = np.where(np.isfinite(v), v, euclid + UNKNOWN_PENALTY)
        return out
