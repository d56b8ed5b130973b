"""Attractive and repulsive potentials with analytic derivatives (paper Section II).

Signs follow docs/paper_notes.md section 1, not the paper's printed
equations: every repulsive potential here is *high* near an obstacle, so that
descending the total potential moves the robot away from obstacles.

=============  ===========================  =====================================
kind           potential phi(r)             paper
=============  ===========================  =====================================
traditional    +a / r                       eq. (8) printed as -1/r (Khatib)
harmonic       -a * log10(r)                eq. (6)/(9) (Kim & Khosla)
subharmonic    +a * exp(-k r^2)             eq. (13) printed as -a exp(-k r^2)
=============  ===========================  =====================================

``r`` is the distance to an obstacle point [m]. The radial derivative of the
harmonic potential is ``-a / (r ln 10)``; the paper's eq. (11) prints ``ln10/r``.
The Laplacian of the subharmonic potential is ``4 a k exp(-k r^2) (k r^2 - 1)``:
non-negative only for ``r >= d0 = 1/sqrt(k)`` (eq. 18-20).

All functions are vectorised, never modify their inputs and return new arrays.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

REPULSION_KINDS = ('traditional', 'harmonic', 'subharmonic')
LN10 = math.log(10.0)
#: Distances are floored here so that 1/r and log r stay finite [m].
MIN_DISTANCE = 1e-6


def _floored(r: ArrayLike) -> NDArray[np.float64]:
    return np.maximum(np.asarray(r, dtype=float), MIN_DISTANCE)


def _check_kind(kind: str) -> None:
    if kind not in REPULSION_KINDS:
        raise ValueError(f'unknown repulsion kind {kind!r}; expected one of {REPULSION_KINDS}')


def repulsive_value(kind: str, r: ArrayLike, gain: float, k: float) -> NDArray[np.float64]:
    """phi(r) of one obstacle point at distance r [m]."""
    _check_kind(kind)
    r = _floored(r)
    if kind == 'traditional':
        return gain / r
    if kind == 'harmonic':
        return -gain * np.log10(r)
    return gain * np.exp(-k * r * r)


def repulsive_dr(kind: str, r: ArrayLike, gain: float, k: float) -> NDArray[np.float64]:
    """d phi / d r (negative: the potential falls away from the obstacle)."""
    _check_kind(kind)
    r = _floored(r)
    if kind == 'traditional':
        return -gain / (r * r)
    if kind == 'harmonic':
        return -gain / (r * LN10)
    return -2.0 * gain * k * r * np.exp(-k * r * r)


def repulsive_laplacian(kind: str, r: ArrayLike, gain: float, k: float) -> NDArray[np.float64]:
    """2-D Laplacian phi'' + phi'/r of a radial potential (eq. 4)."""
    _check_kind(kind)
    r = _floored(r)
    if kind == 'traditional':
        return gain / r ** 3
    if kind == 'harmonic':
        return np.zeros_like(r)
    return 4.0 * gain * k * np.exp(-k * r * r) * (k * r * r - 1.0)


def max_subharmonic_slope(gain: float, k: float) -> float:
    """Largest |d phi/d r| of a exp(-k r^2): a sqrt(2k) exp(-1/2), at r = 1/sqrt(2k)."""
    return gain * math.sqrt(2.0 * k) * math.exp(-0.5)


def attractive_value(kind: str, points: ArrayLike, goal: ArrayLike,
                     gain: float) -> NDArray[np.float64]:
    """Attractive potential: a_att r^2 (eq. 21, 'quadratic') or a_att r ('conic')."""
    r = np.linalg.norm(np.asarray(points, float) - np.asarray(goal, float), axis=-1)
    if kind == 'quadratic':
        return gain * r * r
    if kind == 'conic':
        return gain * r
    raise ValueError(f'unknown attraction kind {kind!r}')


def attractive_gradient(kind: str, points: ArrayLike, goal: ArrayLike,
                        gain: float) -> NDArray[np.float64]:
    """Gradient of the attractive potential, shape (..., 2); zero at the goal."""
    diff = np.asarray(points, float) - np.asarray(goal, float)
    if kind == 'quadratic':
        return 2.0 * gain * diff
    if kind == 'conic':
        r = np.linalg.norm(diff, axis=-1, keepdims=True)
        return gain * diff / np.maximum(r, MIN_DISTANCE)
    raise ValueError(f'unknown attraction kind {kind!r}')


def repulsive_field(kind: str, points: ArrayLike, obstacles: ArrayLike, gain: float,
                    k: float, *, nearest_only: bool = False,
                    influence: float = math.inf) -> tuple[NDArray, NDArray]:
    """Total repulsive potential and its gradient at each point.

    points: (n, 2) [m]; obstacles: (m, 2) [m]. Obstacles farther than
    ``influence`` contribute nothing. With ``nearest_only`` only the closest
    obstacle point counts (eq. 7); otherwise the contributions add (eq. 9-10).
    Returns (values (n,), gradients (n, 2)).
    """
    pairs = _pairs(points, obstacles, nearest_only)
    if pairs is None:
        n = np.atleast_2d(np.asarray(points, float)).shape[0]
        return np.zeros(n), np.zeros((n, 2))
    diff, dist = pairs
    active = dist <= influence
    safe = np.maximum(dist, MIN_DISTANCE)
    value = np.where(active, repulsive_value(kind, safe, gain, k), 0.0)
    return value.sum(axis=1), _gradient(kind, diff, safe, active, gain, k)


def repulsive_gradient(kind: str, points: ArrayLike, obstacles: ArrayLike, gain: float,
                       k: float, *, nearest_only: bool = False,
                       influence: float = math.inf) -> NDArray[np.float64]:
    """The gradient (n, 2) of :func:`repulsive_field`, the same numbers, without its
    values (what the APF step needs)."""
    pairs = _pairs(points, obstacles, nearest_only)
    if pairs is None:
        return np.zeros((np.atleast_2d(np.asarray(points, float)).shape[0], 2))
    diff, dist = pairs
    return _gradient(kind, diff, np.maximum(dist, MIN_DISTANCE), dist <= influence, gain, k)


def _pairs(points: ArrayLike, obstacles: ArrayLike,
           nearest_only: bool) -> tuple[NDArray, NDArray] | None:
    """Offsets (n, m, 2) from each obstacle point to each point and their lengths (n, m)
    [m] (m = 1: the nearest only); None without obstacles."""
    p = np.atleast_2d(np.asarray(points, float))
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    if obs.shape[0] == 0:
        return None
    diff = p[:, None, :] - obs[None, :, :]
    dist = np.hypot(diff[..., 0], diff[..., 1])
    if nearest_only:
        idx = np.argmin(dist, axis=1)
        rows = np.arange(p.shape[0])
        diff = diff[rows, idx][:, None, :]
        dist = dist[rows, idx][:, None]
    return diff, dist


def _gradient(kind: str, diff: NDArray, safe: NDArray, active: NDArray, gain: float,
              k: float) -> NDArray[np.float64]:
    """Sum over the obstacle points of phi'(r) * offset / r, inactive ones left out."""
    slope = np.where(active, repulsive_dr(kind, safe, gain, k), 0.0)
    return ((slope / safe)[..., None] * diff).sum(axis=1)
