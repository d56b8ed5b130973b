"""``sim_node``'s goals, one attempt at a time, each judged on the ground truth.

The first attempt is at the world's goal, from the start of the simulation (so a
planner given that goal by its parameters is judged as the bringup's). Each goal that
comes on ``goal_pose`` afterwards starts a new attempt with its own time limit (the
world's); the same goal sent again while its attempt runs is that attempt (a goal is
resent until the planner takes it). An attempt ends once, with an outcome
(sim/outcome.py: reached, collision or timeout); the simulation goes on after it, and
the next goal starts the next attempt. A collision is a contact that begins during the
attempt: a robot still touching what it hit when the next goal comes is not a new
collision until it has come free.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from ..core.memory import SAME_GOAL
from ..core.status import Outcome
from .outcome import outcome_of
from .world import World


@dataclass
class Attempt:
    """One goal: where (world frame), when it began, how and when it ended [s]."""

    number: int
    goal: np.ndarray
    start: float
    outcome: Outcome | None = None
    end: float | None = None

    @property
    def running(self) -> bool:
        return self.outcome is None


class Attempts:
    """The attempts of one simulation (module docstring)."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.current = Attempt(1, np.asarray(world.goal, float), 0.0)
        self._contact = False   # the robot touched an obstacle in the last step
        self._blocked = False   # in contact ever since the attempt began

    def goal(self, goal: ArrayLike, now: float) -> bool:
        """A goal (x, y) in the world frame at simulated time ``now`` [s]: whether it
        starts a new attempt (not while the same goal's attempt runs)."""
        goal = np.asarray(goal, float)
        a = self.current
        if a.running and np.hypot(*(goal - a.goal)) < SAME_GOAL:
            return False
        self.current = Attempt(a.number + 1, goal, now)
        self._blocked = self._contact
        return True

    def update(self, true_pose: ArrayLike, contact: bool, now: float) -> Outcome | None:
        """After a step that ended at ``now`` [s] with the robot at ``true_pose`` and
        ``contact`` (whether it touched an obstacle during the step): the running
        attempt's outcome if it ends now, else None."""
        self._contact = contact
        if not contact:
            self._blocked = False
        a = self.current
        if not a.running:
            return None
        world = replace(self.world, goal=(float(a.goal[0]), float(a.goal[1])))
        outcome = outcome_of(world, np.asarray(true_pose), contact and not self._blocked,
                             now - a.start)
        if outcome is not None:
            a.outcome, a.end = outcome, now
        return outcome
