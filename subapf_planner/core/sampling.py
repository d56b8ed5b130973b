"""Circular sampling with clockwise priority (paper Section IV, Algorithm 1, Fig. 4-5).

Around the raw next move point q the planner places N samples on a circle of
radius R, sample 0 on the bearing from q to the goal (with the memory: along the
navigation field's descent) and the rest *clockwise* from it. Algorithm 1: a sample
within the discard distance of any obstacle point (the danger distance d0 in the
paper's method) is discarded (score inf); every other sample is scored by the
critics the ``critics`` parameter lists (core/critics/): by default ``progress``,
the distance to the goal of the APF step taken from it (the "next next move
point"), and ``priority``, the Fig. 5 priority sample's bonus
(core/critics/priority.py says how this package reads Fig. 5).

A robot with a footprint polygon (``footprint``) is placed on each sample, facing the
way it drives there, instead (safe_samples).

The lowest score wins; ties go to the lowest index (the one closest to the goal
bearing, then clockwise). If every sample is discarded there is no safe move
and ``chosen`` is None: the caller stops the robot.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .command import corridor_reach
from .config import PlannerConfig
from .critics import Critic, Samples, make_critics
from .navigation import NavigationField


@dataclass(frozen=True)
class SamplingResult:
    """Samples (N, 2) [m], their clearance [m], each critic's cost (N,) by name and
    the score [m] (their sum; inf = discarded), and the chosen point or None."""

    samples: NDArray[np.float64]
    clearance: NDArray[np.float64]
    costs: dict[str, NDArray[np.float64]]
    scores: NDArray[np.float64]
    chosen_index: int

    @property
    def chosen(self) -> NDArray[np.float64] | None:
        return None if self.chosen_index < 0 else self.samples[self.chosen_index].copy()

    @property
    def priority_index(self) -> int:
        """The Fig. 5 priority sample (the one the ``priority`` critic favoured), -1 for
        none."""
        bonus = self.costs.get('priority')
        hit = np.flatnonzero(bonus < 0.0) if bonus is not None else ()
        return int(hit[0]) if len(hit) else -1


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


def safe_samples(samples: NDArray[np.float64], clear: NDArray[np.float64],
                 position: ArrayLike, obstacles: ArrayLike,
                 cfg: PlannerConfig) -> NDArray[np.bool_]:
    """Algorithm 1's test: the samples farther than the discard distance from every
    obstacle point; with a footprint polygon and the memory's field, instead those where
    the polygon, placed on the sample facing the way the robot drives there from
    ``position``, keeps sample_clearance - robot_radius from every point
    (core/footprint.py), and whose way from ``position`` the command's forward check
    (core/command.py forward_blocked) leaves open: a sample straight ahead in a gap
    the footprint passes only a few centimetres to one side was chosen, and the
    robot stood with blocked_ahead where a sample to that side would have led it in
    (the Jackal's `barn_001`)."""
    shape = cfg.polygon
    if shape is None or not cfg.geodesic:
        return clear > cfg.discard_distance
    way = samples - np.asarray(position, float)
    heading = np.arctan2(way[:, 1], way[:, 0])
    poses = np.column_stack((samples, heading))
    start = np.column_stack((np.broadcast_to(np.asarray(position, float)[:2],
                                             samples.shape), heading))
    return ~shape.contact(poses, obstacles, cfg.sample_clearance - cfg.robot_radius) \
        & ~shape.corridor(start, obstacles, corridor_reach(cfg))


def sample_and_choose(raw_point: ArrayLike, position: ArrayLike, goal: ArrayLike,
                      obstacles: ArrayLike, repulsion_obstacles: ArrayLike,
                      cfg: PlannerConfig, field: NavigationField | None = None,
                      critics: tuple[Critic, ...] | None = None) -> SamplingResult:
    """Full circular sampling step: samples, Algorithm 1's discard, the critics' costs
    summed (``critics``: built from ``cfg.critics`` when not given), the choice.

    ``obstacles`` are all valid points near the robot (the discard and the priority
    test); ``repulsion_obstacles`` the downsampled points the APF step uses. With a
    navigation ``field`` the goal bearing of sample 0 is the field's descent direction.
    """
    samples = circle_samples(raw_point, heading_target(raw_point, goal, field),
                             cfg.num_samples, cfg.sample_radius)
    clear = clearance(samples, obstacles)
    ctx = Samples(samples, clear, safe_samples(samples, clear, position, obstacles, cfg),
                  np.asarray(raw_point, float), np.asarray(position, float),
                  np.asarray(goal, float), np.asarray(obstacles, float).reshape(-1, 2),
                  np.asarray(repulsion_obstacles, float).reshape(-1, 2), field)
    costs = {c.name: c.cost(ctx) for c in (make_critics(cfg) if critics is None else critics)}
    scores = np.where(ctx.safe, 0.0, np.inf) if not costs else None
    for cost in costs.values():
        scores = cost.copy() if scores is None else scores + cost
    scores[~ctx.safe] = np.inf
    chosen = int(np.argmin(scores)) if np.any(np.isfinite(scores)) else -1
    return SamplingResult(samples, clear, costs, scores, chosen)
