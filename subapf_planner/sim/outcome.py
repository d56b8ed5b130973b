"""How a run ends, judged on the ground truth: one function for the benchmark's
episode and ``sim_node``."""

from __future__ import annotations

import numpy as np

from ..core.status import Outcome
from .world import World


def outcome_of(world: World, true_pose: np.ndarray, collided: bool, time: float,
               time_limit: float | None = None) -> Outcome | None:
    """REACHED inside the world's goal tolerance, else COLLISION on contact, else
    TIMEOUT at ``time_limit`` (default: the world's) [s]; None while the run goes on."""
    limit = world.time_limit if time_limit is None else time_limit
    if float(np.hypot(*(np.asarray(true_pose[:2], float) - world.goal))) \
            <= world.goal_tolerance:
        return Outcome.REACHED
    if collided:
        return Outcome.COLLISION
    if time >= limit - 1e-9:
        return Outcome.TIMEOUT
    return None
