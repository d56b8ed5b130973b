"""Where a differential-drive robot will be: the one unicycle rollout of the package.

A rollout holds a forward speed v and, over each step of ``dt`` seconds, a turn rate;
it is exact for such piecewise-constant rates: a step's chord has length
``v dt sinc(w dt / 2)`` along the heading at the step's middle. DWA's arcs (one turn
rate for the whole horizon) and the evasion's escapes (turn, then straight) are both
rolled out here, each with the step its caller plans with.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def steps(horizon: float, dt: float) -> int:
    """The number of ``dt`` steps that cover ``horizon`` [s] (at least one)."""
    return max(1, int(round(horizon / dt)))


def rollouts(pose: ArrayLike, v: ArrayLike, turn: ArrayLike, dt: float) -> NDArray[np.float64]:
    """Positions (c, k, 2) [m] of c unicycles from ``pose`` (x, y, yaw), each at forward
    speed v (c,) [m/s] and turn rate turn (c, k) [rad/s] held over each ``dt`` [s] step;
    the first point is one step ahead."""
    pose = np.asarray(pose, float)
    v = np.asarray(v, float)
    turn = np.asarray(turn, float)
    half = 0.5 * turn * dt
    yaw0 = pose[2] + np.concatenate([np.zeros((len(v), 1)), np.cumsum(2.0 * half, axis=1)[:, :-1]],
                                    axis=1)
    chord = v[:, None] * dt * np.sinc(half / np.pi)
    mid = yaw0 + half
    return np.stack((pose[0] + np.cumsum(chord * np.cos(mid), axis=1),
                     pose[1] + np.cumsum(chord * np.sin(mid), axis=1)), axis=-1)


def arcs(pose: ArrayLike, v: ArrayLike, w: ArrayLike, horizon: float,
         dt: float) -> NDArray[np.float64]:
    """Positions (c, k, 2) [m] of c unicycles from ``pose`` at constant (v, w) (c,) each,
    every ``dt`` up to ``horizon`` [s] (first point one step ahead)."""
    w = np.asarray(w, float)
    return rollouts(pose, v, np.repeat(w[:, None], steps(horizon, dt), axis=1), dt)
