"""Dynamic Window Approach baseline (Fox, Burgard and Thrun, 1997).

The classic local planner a TurtleBot3 user would otherwise pick. Velocity
pairs (v, w) reachable within one planning period under the acceleration
limits are rolled out as circular arcs over ``dwa_horizon`` seconds; an arc
that passes closer than ``dwa_clearance`` to an obstacle point is not
admissible (turning on the spot always is, since the footprint is round).
Among the admissible arcs the one maximising

    heading_weight * heading + clearance_weight * clearance + velocity_weight * v/v_max

wins. Each term lies in [0, 1] (heading: 1 - |goal bearing error at the arc's
end| / pi; clearance: capped at 1 m; speed: v / v_max). Unlike the paper, the
terms are not min-max normalised over the window, which would blow tiny
clearance differences up and make the robot turn on the spot.

With a navigation field (core/navigation.py) the goal term is the progress
along it instead, ``0.5 + 0.5 * (F(start) - F(end)) / (v_max * horizon)``
clipped to [0, 1]: the global dynamic window approach of Brock and Khatib
(1999), NF1 on a grid under a dynamic window, the classic way to give DWA the
memory it lacks (docs/paper_notes.md section 5).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .config import PlannerConfig
from .navigation import NavigationField
from .rollout import arcs
from .sampling import clearance

#: Clearances above this count as fully clear in the score [m].
CLEARANCE_CAP = 1.0


@dataclass(frozen=True)
class DwaResult:
    """Chosen (v [m/s], w [rad/s]), whether any arc was admissible, and the chosen arc."""

    v: float
    w: float
    admissible: bool
    trajectory: NDArray[np.float64]


def rollout(pose: ArrayLike, v: NDArray, w: NDArray, cfg: PlannerConfig) -> NDArray[np.float64]:
    """Positions (k, T, 2) of k unicycle arcs (v, w) from pose (x, y, yaw) over
    dwa_horizon, in steps of dwa_rollout_step (core/rollout.py)."""
    return arcs(pose, v, w, cfg.dwa_horizon, cfg.dwa_rollout_step)


def dwa_command(pose: ArrayLike, goal: ArrayLike, previous: tuple[float, float],
                obstacles: ArrayLike, cfg: PlannerConfig,
                field: NavigationField | None = None) -> DwaResult:
    """Best admissible (v, w) of the dynamic window around ``previous`` (clipped to the
    velocity limits, so a ``previous`` outside them cannot yield a command outside)."""
    v0, w0 = previous
    dt = cfg.period
    v_max, w_max = cfg.max_linear_velocity, cfg.max_angular_velocity
    v_lo, v_hi = np.clip([v0 - cfg.max_linear_acceleration * dt,
                          v0 + cfg.max_linear_acceleration * dt], 0.0, v_max)
    w_lo, w_hi = np.clip([w0 - cfg.max_angular_acceleration * dt,
                          w0 + cfg.max_angular_acceleration * dt], -w_max, w_max)
    vs, ws = np.meshgrid(np.linspace(v_lo, v_hi, cfg.dwa_v_samples),
                         np.linspace(w_lo, w_hi, cfg.dwa_w_samples))
    vs, ws = vs.ravel(), ws.ravel()
    paths = rollout(pose, vs, ws, cfg)
    k, steps, _ = paths.shape
    clear = clearance(paths.reshape(-1, 2), obstacles).reshape(k, steps).min(axis=1)
    admissible = (clear > cfg.dwa_clearance) | (vs <= 1e-9)
    if not np.any(admissible):
        return DwaResult(0.0, 0.0, False, np.asarray(pose, float)[None, :2].copy())
    end = paths[:, -1, :]
    if field is not None:
        heading = _field_progress(field, np.asarray(pose, float)[:2], end, cfg)
    else:
        end_yaw = float(pose[2]) + ws * cfg.dwa_horizon
        g = np.asarray(goal, float)
        bearing = np.arctan2(g[1] - end[:, 1], g[0] - end[:, 0])
        heading = 1.0 - np.abs(np.remainder(bearing - end_yaw + np.pi, 2 * np.pi)
                               - np.pi) / np.pi
    score = (cfg.dwa_heading_weight * heading
             + cfg.dwa_clearance_weight * np.minimum(clear, CLEARANCE_CAP) / CLEARANCE_CAP
             + cfg.dwa_velocity_weight * vs / max(cfg.max_linear_velocity, 1e-9))
    score = np.where(admissible, score, -np.inf)
    best = int(np.argmax(score))
    return DwaResult(float(vs[best]), float(ws[best]), True, paths[best].copy())


def _field_progress(field: NavigationField, start: NDArray, ends: NDArray,
                    cfg: PlannerConfig) -> NDArray[np.float64]:
    """Goal term with a navigation field: progress along it over the arc, in [0, 1]."""
    f0 = float(field.value(start)[0])
    f_end = field.value(ends)
    if not np.isfinite(f0):
        f0 = float(np.min(f_end[np.isfinite(f_end)], initial=0.0))
    reach = max(cfg.max_linear_velocity * cfg.dwa_horizon, 1e-9)
    with np.errstate(invalid='ignore'):
        progress = np.where(np.isfinite(f_end), (f0 - f_end) / reach, -1.0)
    return np.clip(0.5 + 0.5 * progress, 0.0, 1.0)
