"""Metrics of a driven path (ground truth): length, clearance, smoothness."""

from __future__ import annotations

import math

import numpy as np

from ..core.robot import BURGER, RobotDescription, to_parent
from .world import World

#: Spacing of the points along a polygon footprint's edges whose clearance is measured [m].
OUTLINE_STEP = 0.01


def path_length(path: np.ndarray) -> float:
    """Length of the driven polyline [m]."""
    if len(path) < 2:
        return 0.0
    return float(np.sum(np.hypot(*np.diff(path[:, :2], axis=0).T)))


def outline_points(robot: RobotDescription, step: float = OUTLINE_STEP) -> np.ndarray:
    """Points (k, 2) along a polygon footprint's edges, ``step`` apart or closer, in the
    base frame [m]."""
    corners = robot.outline()
    out = []
    for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        n = max(1, math.ceil(float(np.hypot(*(b - a))) / step))
        out.append(a + (b - a) * (np.arange(n) / n)[:, None])
    return np.concatenate(out)


def min_clearance(world: World, path: np.ndarray, times: np.ndarray | None = None,
                  robot: RobotDescription = BURGER) -> float:
    """Smallest gap between the robot's footprint and an obstacle surface [m] over the
    poses (x, y, yaw) of ``path``; with ``times`` (one per path point [s]) the moving
    obstacles count where each was at that instant. A disc: its centre's clearance less
    its radius; a polygon: the least clearance of points along its edges (OUTLINE_STEP
    apart), measured at the poses where its circumscribed circle can come nearest."""
    if len(path) == 0:
        return math.nan
    when = [None] * len(path) if times is None or not world.moving else list(times)
    centre = [world.clearance(float(x), float(y), None if t is None else float(t))
              for (x, y), t in zip(path[:, :2], when, strict=True)]
    if not robot.footprint:
        return min(centre) - robot.radius
    edge = outline_points(robot)
    best = math.inf
    for i in np.argsort(centre):
        if centre[i] - robot.radius >= best:
            break   # no later pose can come nearer
        t = when[i]
        points = to_parent(path[i, :3], edge)
        best = min(best, min(world.clearance(float(x), float(y), None if t is None
                                             else float(t)) for x, y in points))
    return best


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
