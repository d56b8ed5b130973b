"""How a run ends, judged on the ground truth: one function for the benchmark's
episode and ``sim_node``."""

from __future__ import annotations

import numpy as np

from ..core.status import Outcome
from .world import World


def outcome_of(world: World, true_pose: np.ndarray, collided: bool, time: float,
               time_limit: float | None = None,
               stopped_at_goal: bool | None = None) -> Outcome | None:
    """How the run stands, or None while it goes on. With ``stopped_at_goal`` (the
    planner's word: it stopped, believing it is at the goal; the benchmark's episode)
    REACHED when it stopped inside the world's goal tolerance, MISSED when it stopped
    outside: where the robot stands is what a user sees. Without it (None: ``sim_node``,
    which does not hear the planner) REACHED once the robot is inside. Then COLLISION
    on contact, TIMEOUT at ``time_limit`` (default: the world's) [s]."""
    limit = world.time_limit if time_limit is None else time_limit
    inside = float(np.hypot(*(np.asarray(true_pose[:2], float) - world.goal))) \
        <= world.goal_tolerance
    if inside and stopped_at_goal is not False:
        return Outcome.REACHED
    if stopped_at_goal:
        return Outcome.MISSED
    if collided:
        return Outcome.COLLISION
    if time >= limit - 1e-9:
        return Outcome.TIMEOUT
    return None
