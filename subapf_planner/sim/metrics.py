"""Metrics of a driven path (ground truth): length, clearance, smoothness."""

from __future__ import annotations

import math

import numpy as np

from .world import FOOTPRINT_RADIUS, World


def path_length(path: np.ndarray) -> float:
    """Length of the driven polyline [m]."""
    if len(path) < 2:
        return 0.0
    return float(np.sum(np.hypot(*np.diff(path[:, :2], axis=0).T)))


def min_clearance(world: World, path: np.ndarray, times: np.ndarray | None = None) -> float:
    """Smallest gap between the footprint (FOOTPRINT_RADIUS, the burger's) and an
    obstacle surface [m]; with ``times`` (one per path point [s]) the moving obstacles
    count where each was at that instant."""
    if len(path) == 0:
        return math.nan
    when = [None] * len(path) if times is None or not world.moving else times
    return min(world.clearance(float(x), float(y), None if t is None else float(t))
               for (x, y), t in zip(path[:, :2], when, strict=True)) - FOOTPRINT_RADIUS


def mean_abs_curvature(path: np.ndarray, min_segment: float = 0.01) -> float:
    """Mean |turning angle| / segment length over the polyline [1/m] (smoothness).

    Points closer than ``min_segment`` to the previous kept point are skipped,
    so turning on the spot does not divide by zero.
    """
    pts = [path[0, :2]] if len(path) else []
    for p in path[1:, :2]:
        if np.hypot(*(p - pts[-1])) >= min_segment:
            pts.append(p)
    if len(pts) < 3:
        return 0.0
    seg = np.diff(np.asarray(pts), axis=0)
    heading = np.arctan2(seg[:, 1], seg[:, 0])
    turn = np.abs(np.remainder(np.diff(heading) + np.pi, 2 * np.pi) - np.pi)
    lengths = np.hypot(seg[:, 0], seg[:, 1])
    return float(np.mean(turn / (0.5 * (lengths[1:] + lengths[:-1]))))
