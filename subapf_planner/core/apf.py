"""The artificial potential field step (paper eq. 23) from a point to its raw next move point."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .config import PlannerConfig
from .navigation import NavigationField
from .potentials import attractive_gradient, repulsive_gradient

#: Planner method -> repulsion kind of potentials.py.
REPULSION_OF_METHOD = {
    'subharmonic_sampling': 'subharmonic',
    'subharmonic': 'subharmonic',
    'traditional': 'traditional',
    'harmonic': 'harmonic',
}


def apf_force(points: ArrayLike, goal: ArrayLike, obstacles: ArrayLike,
              cfg: PlannerConfig, field: NavigationField | None = None) -> NDArray[np.float64]:
    """F = -grad(phi_att + phi_rep) at each point, shape (n, 2).

    The total potential is eq. (23) with the signs of docs/paper_notes.md section 1:
    ``phi = phi_att(r_goal) + sum_i phi_rep(r_i)``, phi_rep per ``cfg.method``.
    With a navigation ``field`` (core/navigation.py) phi_att is ``a_att`` times the
    distance to the goal through free space instead of eq. (21)'s Euclidean one: a
    pull of constant magnitude ``field_gain`` along the field's steepest descent.
    """
    kind = REPULSION_OF_METHOD[cfg.method]
    p = np.atleast_2d(np.asarray(points, float))
    grad_rep = repulsive_gradient(kind, p, obstacles, cfg.repulsion_gain, cfg.k,
                                  nearest_only=cfg.repulsion_mode == 'nearest',
                                  influence=cfg.influence_distance)
    if field is not None:
        grad_att = -cfg.field_gain * field.direction(p)
    else:
        grad_att = attractive_gradient(cfg.attraction, p, goal, cfg.attraction_gain)
    return -(grad_att + grad_rep)


def apf_step(points: ArrayLike, goal: ArrayLike, obstacles: ArrayLike,
             cfg: PlannerConfig, field: NavigationField | None = None) -> NDArray[np.float64]:
    """Raw next move point(s): ``p + eta * F``, the step clipped to ``max_step`` [m]
    and to the distance to the goal (the step never jumps past the goal).
    """
    p = np.atleast_2d(np.asarray(points, float))
    step = cfg.step_gain * apf_force(p, goal, obstacles, cfg, field)
    length = np.linalg.norm(step, axis=1, keepdims=True)
    to_goal = np.linalg.norm(p - np.asarray(goal, float), axis=1, keepdims=True)
    limit = np.minimum(cfg.max_step, np.maximum(to_goal, 1e-9))
    scale = np.where(length > limit, limit / np.maximum(length, 1e-12), 1.0)
    return p + step * scale
