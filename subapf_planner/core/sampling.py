"""Circular sampling with clockwise priority (paper Section IV, Algorithm 1, Fig. 4-5).

Around the raw next move point q the planner places N samples on a circle of
radius R, sample 0 on the bearing from q to the goal and the rest *clockwise*
from it. Algorithm 1: a sample within the danger distance d0 of any obstacle
point is discarded (score inf); every other sample is scored by the distance
to the goal of the APF step taken from it (the "next next move point").

Fig. 5 is not in the paper's text; this project reads it as follows:

* ``d`` is the distance from the robot to its nearest obstacle point and
  ``theta`` the angle between the bearings robot->goal and robot->nearest
  obstacle;
* priority applies only when ``d < priority_distance`` and
  ``theta < priority_angle`` (an obstacle close by and in the way);
* the priority sample is the first one, walking clockwise from sample 0, that
  is outside the danger distance *and* about as far from every obstacle as
  the raw next move point (``clearance >= clearance(q) - 0.1 R``): it moves
  round the obstacle rather than towards it. Its score is lowered by
  ``priority_bonus``. Near a wall this is the sample that slides along the
  wall rather than into it, always in the same rotational sense, which is
  what carries the robot out of a local minimum.

The lowest score wins; ties go to the lowest index (the one closest to the goal
bearing, then clockwise). If every sample is discarded there is no safe move
and ``chosen`` is None: the caller stops the robot.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .apf import apf_step
from .config import PlannerConfig
from .navigation import NavigationField

#: A priority sample may be this fraction of R closer to the obstacles than the robot.
PRIORITY_SLACK = 0.1
#: Score added to the Euclidean distance where the navigation field has no value [m].
UNKNOWN_PENALTY = 1000.0


@dataclass(frozen=True)
class SamplingResult:
    """Samples (N, 2) [m], their clearance [m] and score [m] (inf = discarded),
    the priority sample index (-1 for none) and the chosen point or None."""

    samples: NDArray[np.float64]
    clearance: NDArray[np.float64]
    scores: NDArray[np.float64]
    priority_index: int
    chosen_index: int

    @property
    def chosen(self) -> NDArray[np.float64] | None:
        return None if self.chosen_index < 0 else self.samples[self.chosen_index].copy()


def circle_samples(center: ArrayLike, goal: ArrayLike, n: int,
                   radius: float) -> NDArray[np.float64]:
    """N points on the circle, sample 0 towards the goal, then clockwise (Fig. 4b)."""
    c = np.asarray(center, float)
    g = np.asarray(goal, float)
    d = g - c
    start = math.atan2(d[1], d[0]) if np.any(d != 0.0) else 0.0
    angles = start - 2.0 * math.pi * np.arange(n) / n
    return c + radius * np.column_stack((np.cos(angles), np.sin(angles)))


def clearance(points: ArrayLike, obstacles: ArrayLike) -> NDArray[np.float64]:
    """Distance from each point to its nearest obstacle point (inf with no obstacles)."""
    p = np.atleast_2d(np.asarray(points, float))
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    if obs.shape[0] == 0:
        return np.full(p.shape[0], np.inf)
    diff = p[:, None, :] - obs[None, :, :]
    return np.sqrt(np.min(np.einsum('ijk,ijk->ij', diff, diff), axis=1))


def evaluate_samples(samples: ArrayLike, goal: ArrayLike, obstacles: ArrayLike,
                     repulsion_obstacles: ArrayLike, cfg: PlannerConfig,
                     field: NavigationField | None = None) -> tuple[NDArray, NDArray]:
    """Algorithm 1: (clearance, score) per sample; score inf (discarded) closer than
    ``cfg.discard_distance`` to an obstacle point (the danger distance d0 in the paper's
    method).

    ``obstacles`` are all valid points (used for the danger check);
    ``repulsion_obstacles`` are the downsampled points the APF step uses. The score
    is the distance to the goal of the next APF step [m]: Euclidean (the paper), or
    through free space with a navigation ``field`` (where the field has no value,
    inside an inflated obstacle, the Euclidean distance plus UNKNOWN_PENALTY).
    """
    s = np.atleast_2d(np.asarray(samples, float))
    clear = clearance(s, obstacles)
    scores = np.full(s.shape[0], np.inf)
    safe = clear > cfg.discard_distance
    if np.any(safe):
        nxt = apf_step(s[safe], goal, repulsion_obstacles, cfg, field)
        euclid = np.linalg.norm(nxt - np.asarray(goal, float), axis=1)
        if field is None:
            scores[safe] = euclid
        else:
            v = field.value(nxt)
            scores[safe] = np.where(np.isfinite(v), v, euclid + UNKNOWN_PENALTY)
    return clear, scores


def priority_applies(position: ArrayLike, goal: ArrayLike, nearest: ArrayLike | None,
                     cfg: PlannerConfig) -> bool:
    """Fig. 5 condition: nearest obstacle closer than d and within theta of the goal bearing."""
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


def heading_target(point: ArrayLike, goal: ArrayLike,
                   field: NavigationField | None) -> NDArray[np.float64]:
    """Where "towards the goal" points from ``point``: the goal itself, or with a
    navigation field one metre along its steepest descent (the way round obstacles)."""
    p = np.asarray(point, float)
    if field is not None:
        d = field.direction(p)[0]
        if np.any(d != 0.0):
            return p + d
    return np.asarray(goal, float)


def sample_and_choose(raw_point: ArrayLike, position: ArrayLike, goal: ArrayLike,
                      obstacles: ArrayLike, repulsion_obstacles: ArrayLike,
                      cfg: PlannerConfig,
                      field: NavigationField | None = None) -> SamplingResult:
    """Full circular sampling step: samples, Algorithm 1 scores, Fig. 5 priority, choice.

    With a navigation ``field`` the goal bearing of sample 0 and of the Fig. 5 test
    is the field's descent direction, and scores are field values.
    """
    samples = circle_samples(raw_point, heading_target(raw_point, goal, field),
                             cfg.num_samples, cfg.sample_radius)
    clear, scores = evaluate_samples(samples, goal, obstacles, repulsion_obstacles, cfg,
                                     field)
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    prio = -1
    if obs.shape[0]:
        p = np.asarray(position, float)
        dist = np.hypot(*(obs - p).T)
        i_near = int(np.argmin(dist))
        # (the nearest point's distance first: the field's direction is not free)
        if dist[i_near] < cfg.priority_distance and priority_applies(
                p, heading_target(p, goal, field), obs[i_near], cfg):
            raw_clear = float(clearance(raw_point, obs)[0])
            keep = raw_clear - PRIORITY_SLACK * cfg.sample_radius
            ok = np.flatnonzero(np.isfinite(scores) & (clear >= keep))
            if ok.size:
                prio = int(ok[0])
    adjusted = scores.copy()
    if prio >= 0:
        adjusted[prio] -= cfg.priority_bonus
    chosen = int(np.argmin(adjusted)) if np.any(np.isfinite(adjusted)) else -1
    return SamplingResult(samples, clear, scores, prio, chosen)
