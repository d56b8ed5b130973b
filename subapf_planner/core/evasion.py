"""Getting out of the way: the planned command checked against where the moving
obstacles will be, and replaced when it meets one.

The APF command (core/planner.py) only sees where things are. Each cycle this
layer rolls the command out for ``prediction_horizon`` seconds (a unicycle at
constant (v, w), ROLLOUT_DT steps) against each moving track's constant-velocity
prediction (core/tracking.py): the gap between the footprint and the track's
disc must stay above ``moving_clearance``. When it does not, a small set of
escape commands is rolled out the same way: forward, slower, turning, standing
still, and backing up at ``reverse_speed`` (the burger backs at up to 0.22
m/s); a candidate is admissible only if its first EVASION_COMMIT seconds keep
``robot_radius + STATIC_MARGIN`` from every laser point that is not a moving
track's, and the safety corridor does not block its forward speed. Among the
admissible ones that keep the clearance, the one closest to the planned command
wins (the robot steps aside rather than turns back); when none keeps it, the one
with the largest gap (it never stands still in an obstacle's way while a way out
exists). Time-weighted so that a meeting soon counts more than one later.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from .config import PlannerConfig
from .tracking import Tracks

#: Rollout step [s].
ROLLOUT_DT = 0.2
#: An escape must clear the static points for this long [s] ...
EVASION_COMMIT = 1.0
#: ... by this much beyond the footprint [m].
STATIC_MARGIN = 0.02
#: A meeting t seconds ahead counts as a gap this much larger per second [m/s]
#: (soon matters more than later).
TIME_DISCOUNT = 0.05
#: Angular rates of the escape candidates, as fractions of the top turn rate.
TURN_FRACTIONS = (-0.6, -0.3, 0.0, 0.3, 0.6)


def rollout(pose: NDArray[np.float64], v: float, w: float, horizon: float) -> NDArray:
    """Positions (k, 2) [m] of a unicycle from ``pose`` (x, y, yaw) at constant (v, w),
    every ROLLOUT_DT up to ``horizon`` [s] (first point one step ahead)."""
    t = np.arange(1, int(round(horizon / ROLLOUT_DT)) + 1) * ROLLOUT_DT
    yaw = pose[2] + w * t
    if abs(w) < 1e-9:
        x = pose[0] + v * t * math.cos(pose[2])
        y = pose[1] + v * t * math.sin(pose[2])
    else:
        x = pose[0] + v / w * (np.sin(yaw) - math.sin(pose[2]))
        y = pose[1] - v / w * (np.cos(yaw) - math.cos(pose[2]))
    return np.column_stack((x, y))


def moving_gap(path: NDArray[np.float64], tracks: Tracks, robot_radius: float) -> float:
    """Smallest time-discounted gap [m] between the footprint along ``path`` (one point per
    ROLLOUT_DT from one step ahead) and the moving tracks' predicted discs; inf with
    none."""
    m = tracks.moving
    if not np.any(m):
        return math.inf
    t = (np.arange(len(path)) + 1)[:, None] * ROLLOUT_DT
    where = tracks.position[m][None] + t[..., None] * tracks.velocity[m][None]   # (k, n, 2)
    gap = np.hypot(*(path[:, None, :] - where).transpose(2, 0, 1)) - tracks.radius[m] \
        - robot_radius
    return float(np.min(gap + TIME_DISCOUNT * t))


def _static_clear(pose: NDArray, path: NDArray, static: NDArray, radius: float) -> bool:
    if len(static) == 0:
        return True
    k = max(1, int(round(EVASION_COMMIT / ROLLOUT_DT)))
    near = path[:k]
    d = np.hypot(*(near[:, None, :] - static[None]).transpose(2, 0, 1))
    return bool(d.min() >= radius + STATIC_MARGIN)


def evade(pose: NDArray[np.float64], planned: tuple[float, float], tracks: Tracks,
          static: NDArray[np.float64], cfg: PlannerConfig, blocked_ahead: bool,
          committed: tuple[float, float] | None = None) -> tuple[float, float] | None:
    """A replacement for the ``planned`` (v, w) when its rollout meets a moving track
    (see the module docstring), or None to keep it. ``static``: the laser points that
    are not moving tracks' (m, 2); ``blocked_ahead``: the safety corridor holds a point
    (forward candidates are then inadmissible); ``committed``: the escape of the last
    cycle, kept while it still keeps the clearance (no dithering between escapes)."""
    horizon = cfg.prediction_horizon
    v0, w0 = planned
    if moving_gap(rollout(pose, v0, w0, horizon), tracks, cfg.robot_radius) \
            >= cfg.moving_clearance:
        return None
    speeds = [cfg.max_linear_velocity, 0.5 * cfg.max_linear_velocity, 0.0]
    if cfg.reverse_speed > 0.0:
        speeds.append(-cfg.reverse_speed)
    best, best_key = None, None
    candidates = [(v, f * cfg.max_angular_velocity) for v in speeds for f in TURN_FRACTIONS]
    for v, w in candidates:
        if v > 0.0 and blocked_ahead:
            continue
        path = rollout(pose, v, w, horizon)
        if v != 0.0 and not _static_clear(pose, path, static, cfg.robot_radius):
            continue
        gap = moving_gap(path, tracks, cfg.robot_radius)
        # safe ones: the committed escape, else the closest to the plan; otherwise the
        # largest gap
        kept = committed is not None and (v, w) == committed
        key = (0, -1.0 if kept else abs(v - v0) + 0.1 * abs(w - w0)) \
            if gap >= cfg.moving_clearance else (1, -gap)
        if best_key is None or key < best_key:
            best, best_key = (v, w), key
    return best
