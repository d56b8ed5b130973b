"""Where a differential-drive robot will be: the one unicycle rollout of the package.

A rollout holds a forward speed v and, over each step of ``dt`` seconds, a turn rate;
it is exact for such piecewise-constant rates: a step's chord has length
``v dt sinc(w dt / 2)`` along the heading at the step's middle. DWA's arcs (one turn
rate for the whole horizon) and the evasion's escapes (turn, then straight) are both
rolled out here, each with the step its caller plans with. :func:`ramped` turns
commanded rates into the rates a base reaches under its acceleration limits.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def steps(horizon: float, dt: float) -> int:
    """The number of ``dt`` steps that cover ``horizon`` [s] (at least one)."""
    return max(1, int(round(horizon / dt)))


def ramped(start: float, target: ArrayLike, limit: float, dt: float) -> NDArray[np.float64]:
    """The mean rate over each ``dt`` [s] step (c, k) of a base that starts at ``start``
    and follows the commanded rates ``target`` (c, k), changing by at most ``limit`` per
    second (a speed [m/s] under an acceleration limit [m/s^2], or a turn rate [rad/s]);
    ``limit`` <= 0: no limit (the target itself)."""
    target = np.asarray(target, float)
    if limit <= 0.0:
        return target.copy()
    step = limit * dt
    out = np.empty_like(target)
    now = np.full(target.shape[0], float(start))
    for j in range(target.shape[1]):
        nxt = now + np.clip(target[:, j] - now, -step, step)
        out[:, j] = 0.5 * (now + nxt)
        now = nxt
    return out


def rollouts(pose: ArrayLike, v: ArrayLike, turn: ArrayLike, dt: float) -> NDArray[np.float64]:
    """Positions (c, k, 2) [m] of c unicycles from ``pose`` (x, y, yaw), each at forward
    speed v (c,) or (c, k) [m/s] and turn rate turn (c, k) [rad/s] held over each ``dt``
    [s] step; the first point is one step ahead."""
    pose = np.asarray(pose, float)
    v = np.asarray(v, float)
    turn = np.asarray(turn, float)
    if v.ndim == 1:
        v = v[:, None]
    half = 0.5 * turn * dt
    yaw0 = pose[2] + np.concatenate([np.zeros((len(v), 1)), np.cumsum(2.0 * half, axis=1)[:, :-1]],
                                    axis=1)
    chord = v * dt * np.sinc(half / np.pi)
    mid = yaw0 + half
    return np.stack((pose[0] + np.cumsum(chord * np.cos(mid), axis=1),
                     pose[1] + np.cumsum(chord * np.sin(mid), axis=1)), axis=-1)


def arcs(pose: ArrayLike, v: ArrayLike, w: ArrayLike, horizon: float,
         dt: float) -> NDArray[np.float64]:
    """Positions (c, k, 2) [m] of c unicycles from ``pose`` at constant (v, w) (c,) each,
    every ``dt`` up to ``horizon`` [s] (first point one step ahead)."""
    w = np.asarray(w, float)
    return rollouts(pose, v, np.repeat(w[:, None], steps(horizon, dt), axis=1), dt)
