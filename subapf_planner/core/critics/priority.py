"""The ``priority`` critic: the paper's Fig. 5 clockwise priority, as a bonus.

Fig. 5 is not in the paper's text; this package reads it as follows (docs/design.md, "The
algorithm"; docs/paper_notes.md):

* ``d`` is the distance from the robot to its nearest obstacle point and ``theta``
  the angle between the bearings robot->goal (with the memory: robot->one metre
  along the field's descent) and robot->nearest obstacle;
* priority applies only when ``d < priority_distance`` and ``theta <
  priority_angle`` (an obstacle close by and in the way);
* the priority sample is the first one, walking clockwise from sample 0, that
  survived the discard *and* is about as far from every obstacle as the raw next
  move point (``clearance >= clearance(q) - PRIORITY_SLACK R``): it moves round the
  obstacle rather than towards it. Its cost is ``-priority_bonus``; every other
  sample's is 0. Near a wall this is the sample that slides along the wall rather
  than into it, always in the same rotational sense, which is what carries the robot
  out of a local minimum.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..config import PlannerConfig
from ..sampling import clearance, heading_target
from . import Samples

#: A priority sample may be this fraction of R closer to the obstacles than the raw
#: point (a sample exactly as far would be lost to rounding along a straight wall).
PRIORITY_SLACK = 0.1


def priority_applies(position: ArrayLike, goal: ArrayLike, nearest: ArrayLike | None,
                     cfg: PlannerConfig) -> bool:
    """Fig. 5 condition: nearest obstacle closer than d and within theta of the goal
    bearing."""
    if nearest is None:
        return False
    p = np.asarray(position, float)
    to_obs = np.asarray(nearest, float) - p
    to_goal = np.asarray(goal, float) - p
    d = float(np.hypot(*to_obs))
    if d >= cfg.priority_distance or not np.any(to_goal != 0.0):
        return False
    theta = abs(math.remainder(math.atan2(to_obs[1], to_obs[0])
                               - math.atan2(to_goal[1], to_goal[0]), 2.0 * math.pi))
    return theta < cfg.priority_angle


def priority_index(samples: Samples, cfg: PlannerConfig) -> int:
    """The Fig. 5 priority sample's index, -1 when priority does not apply or no sample
    qualifies."""
    obs = samples.obstacles
    if not len(obs):
        return -1
    p = samples.position
    dist = np.hypot(*(obs - p).T)
    i_near = int(np.argmin(dist))
    # (the nearest point's distance first: the field's direction is not free)
    if dist[i_near] >= cfg.priority_distance or not priority_applies(
            p, heading_target(p, samples.goal, samples.field), obs[i_near], cfg):
        return -1
    raw_clear = float(clearance(samples.raw, obs)[0])
    keep = raw_clear - PRIORITY_SLACK * cfg.sample_radius
    ok = np.flatnonzero(samples.safe & (samples.clearance >= keep))
    return int(ok[0]) if ok.size else -1


class Priority:
    """``-priority_bonus`` for the Fig. 5 priority sample, 0 for the others [m]."""

    name = 'priority'

    def __init__(self, cfg: PlannerConfig) -> None:
        self.cfg = cfg

    def cost(self, samples: Samples) -> NDArray[np.float64]:
        out = np.zeros(len(samples.points))
        i = priority_index(samples, self.cfg)
        if i >= 0:
            out[i] = -self.cfg.priority_bonus
        return out
