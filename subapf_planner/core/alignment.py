"""Scan alignment: each scan matched to the occupancy memory before it is written,
so that drifting wheel odometry does not draw a wall twice.

The map side is a distance field: for every cell of a window around the scan,
the nearest *established* obstacle cell (log odds at least ESTABLISHED, three
hits or more: what the memory is sure of; scipy's exact Euclidean distance
transform) and the wall's normal there (the structure tensor of the blurred
wall mask). The scan side is its returns in base_footprint. The pose (x, y,
yaw) of base_footprint that puts the returns on the walls is found by
Gauss-Newton on the squared residuals (the likelihood-field matcher of Thrun,
Burgard and Fox, "Probabilistic Robotics", ch. 6.4, in its least-squares form,
as Hector SLAM's, with point-to-line residuals as in ICP), where

* the residual of a return is its distance to the nearest wall point along the
  wall's normal there (point-to-line: the end of a wall does not pull the pose
  along it), the wall point being where the returns fell in that cell
  (OccupancyGrid.hit_offset), not its centre;
* returns farther than MAX_CORRESPONDENCE from every wall left out (something
  new: a wall not yet in the map, a person, the other face of a thin wall);
* a prior towards the odometry prediction (PRIOR_SIGMA_XY, PRIOR_SIGMA_YAW per
  scan), so that a corridor, which fixes the pose across it but not along it,
  keeps odometry's estimate along it;
* acceptance only when at least MIN_MATCHED returns take part and the step from
  the prediction is below MAX_STEP_XY / MAX_STEP_YAW (drift between two scans
  is millimetres; a bigger step is a wrong match). Otherwise the prediction
  stands.

What the planner takes of a match is bounded by how far odometry can have drifted
since the last one (within_drift: DRIFT_* per metre driven and radian turned):
standing still nothing moves the pose, neither a person walking past nor the
matcher's own error on a map it builds as it goes.

Pure numpy/scipy, arrays in and out, nothing kept between calls.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from .robot import to_parent

#: Log odds from which a cell is an obstacle the matcher trusts (three hits).
ESTABLISHED = 2.0
#: Returns farther than this from every established cell take no part [m].
MAX_CORRESPONDENCE = 0.06
#: Fewest returns that must take part for a match to count.
MIN_MATCHED = 40
#: Gauss-Newton iterations at most, and the step below which it stops [m, rad].
ITERATIONS = 6
CONVERGED = 5e-4
#: Blur of the wall mask whose structure gives the walls' normals [cells].
NORMAL_SIGMA = 1.0
#: Prior standard deviation of the prediction, per scan [m], [rad].
PRIOR_SIGMA_XY = 0.02
PRIOR_SIGMA_YAW = 0.02
#: Standard deviation of one return's distance to the wall [m] (the laser's noise plus
#: half a cell).
RETURN_SIGMA = 0.03
#: A match that moves the prediction more than this is refused [m], [rad].
MAX_STEP_XY = 0.03
MAX_STEP_YAW = 0.03
#: Drift the wheels can add, per metre driven and per radian turned, and so the most a
#: match may move the prediction since the last scan [m/m], [m/rad], [rad/m], [rad/rad].
DRIFT_XY_PER_M = 0.05
DRIFT_XY_PER_RAD = 0.01
DRIFT_YAW_PER_M = 0.02
DRIFT_YAW_PER_RAD = 0.05


@dataclass(frozen=True)
class DistanceField:
    """For the cells of a window (rows = y; cell (0, 0) with its corner at ``origin``
    [m]): the nearest established obstacle cell's centre (h, w, 2) [m] and the wall's
    unit normal there (h, w, 2), and the distance to it (h, w) [m]."""

    values: NDArray[np.float32]
    nearest: NDArray[np.float64]
    normal: NDArray[np.float64]
    origin: NDArray[np.float64]
    resolution: float

    def at(self, points: NDArray[np.float64]) -> tuple[NDArray, NDArray, NDArray]:
        """Per point (n, 2): the nearest wall point (n, 2), the wall's normal there (n, 2),
        and the distance (n,) [m]; inf outside the window."""
        cells = np.floor((points - self.origin) / self.resolution).astype(np.int64)
        h, w = self.values.shape
        inside = (cells[:, 0] >= 0) & (cells[:, 1] >= 0) & (cells[:, 0] < w) \
            & (cells[:, 1] < h)
        d = np.full(len(points), np.inf)
        near = np.zeros((len(points), 2))
        normal = np.zeros((len(points), 2))
        r, c = cells[inside, 1], cells[inside, 0]
        near[inside] = self.nearest[r, c]
        normal[inside] = self.normal[r, c]
        d[inside] = np.hypot(*(points[inside] - near[inside]).T)
        return near, normal, d


def _normals(wall: NDArray[np.bool_]) -> NDArray[np.float64]:
    """Unit normal (h, w, 2) of the walls of a mask at each cell: the principal direction
    of the structure tensor of the blurred mask (across a line of cells; any at a
    lone cell)."""
    blurred = ndimage.gaussian_filter(wall.astype(np.float32), NORMAL_SIGMA)
    gy, gx = ndimage.sobel(blurred, axis=0), ndimage.sobel(blurred, axis=1)
    sxx, syy, sxy = (ndimage.gaussian_filter(v, NORMAL_SIGMA)
                     for v in (gx * gx, gy * gy, gx * gy))
    angle = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)   # of the larger eigenvalue
    return np.stack((np.cos(angle), np.sin(angle)), axis=-1).astype(np.float64)


def distance_field(log_odds: NDArray[np.float32], origin: NDArray[np.float64],
                   resolution: float, around: NDArray[np.float64], reach: float,
                   hit_offset: NDArray[np.float32] | None = None) -> DistanceField | None:
    """The field of the established cells of a log-odds grid (corner of cell (0, 0) at
    ``origin``) within ``reach`` [m] of the box of the points ``around`` (n, 2); None
    when that window holds no established cell. ``hit_offset`` (the grid's, h x w x 2
    [m]) places each wall point where the returns fell in its cell: matching to cell
    centres would pull the pose by up to half a cell."""
    lo_xy = around.min(axis=0) - reach
    hi_xy = around.max(axis=0) + reach
    n_rows, n_cols = log_odds.shape
    c0, r0 = (max(int(v), 0) for v in np.floor((lo_xy - origin) / resolution))
    c1, r1 = (int(v) for v in np.ceil((hi_xy - origin) / resolution))
    c1, r1 = min(c1, n_cols), min(r1, n_rows)
    if c0 >= c1 - 1 or r0 >= r1 - 1:
        return None
    wall = log_odds[r0:r1, c0:c1] >= ESTABLISHED
    if not np.any(wall):
        return None
    dist, (rows, cols) = ndimage.distance_transform_edt(~wall, return_indices=True)
    corner = origin + np.array([c0, r0]) * resolution
    nearest = corner + (np.stack((cols, rows), axis=-1) + 0.5) * resolution
    if hit_offset is not None:   # where the returns fell in the cell, not its centre
        nearest = nearest + hit_offset[r0:r1, c0:c1][rows, cols]
    normal = _normals(wall)[rows, cols]
    return DistanceField((dist * resolution).astype(np.float32), nearest, normal, corner,
                         resolution)


def within_drift(predicted: NDArray[np.float64], matched: NDArray[np.float64],
                 driven: float, turned: float) -> NDArray[np.float64]:
    """The matched pose (x, y, yaw) moved back towards the ``predicted`` one so that the
    correction changes no more than odometry can have drifted since the last scan,
    ``driven`` [m] and ``turned`` [rad] ago (DRIFT_*): standing still, odometry does not
    drift, and nothing (a person walking past, the matcher's own error) moves the pose."""
    off = np.asarray(matched, float) - predicted
    off[2] = math.remainder(off[2], 2 * math.pi)
    turned = abs(turned)
    limit_xy = DRIFT_XY_PER_M * driven + DRIFT_XY_PER_RAD * turned
    limit_yaw = DRIFT_YAW_PER_M * driven + DRIFT_YAW_PER_RAD * turned
    shift = math.hypot(off[0], off[1])
    if shift > limit_xy:
        off[:2] *= limit_xy / shift
    off[2] = min(max(off[2], -limit_yaw), limit_yaw)
    return np.asarray(predicted, float) + off


@dataclass(frozen=True)
class Match:
    """An alignment: the pose (x, y, yaw) of base_footprint, whether it was accepted
    (else ``pose`` is the prediction), how many returns took part, and their RMS
    distance to the walls [m]."""

    pose: NDArray[np.float64]
    accepted: bool
    matched: int
    rms: float


def align(base_points: NDArray[np.float64], predicted: NDArray[np.float64],
          field: DistanceField | None) -> Match:
    """The pose of base_footprint that puts ``base_points`` (n, 2; the returns in
    base_footprint [m]) on the field's walls, starting from and drawn towards
    ``predicted`` (x, y, yaw); see the module docstring."""
    prior = np.asarray(predicted, float).copy()
    if field is None or len(base_points) < MIN_MATCHED:
        return Match(prior, False, 0, math.nan)
    pose = prior.copy()
    info_prior = np.diag([PRIOR_SIGMA_XY ** -2, PRIOR_SIGMA_XY ** -2, PRIOR_SIGMA_YAW ** -2])
    w_ret = RETURN_SIGMA ** -2
    for _ in range(ITERATIONS):
        world = to_parent(pose, base_points)
        near, normal, d = field.at(world)
        use = d <= MAX_CORRESPONDENCE
        if np.count_nonzero(use) < MIN_MATCHED:
            return Match(prior, False, int(np.count_nonzero(use)), math.nan)
        c, s = math.cos(pose[2]), math.sin(pose[2])
        p, n = base_points[use], normal[use]
        # point-to-line residual n . (q - wall point) and its derivative by (x, y, yaw)
        res = np.einsum('ij,ij->i', n, world[use] - near[use])
        dyaw = np.column_stack((-s * p[:, 0] - c * p[:, 1], c * p[:, 0] - s * p[:, 1]))
        jac = np.column_stack((n[:, 0], n[:, 1], np.einsum('ij,ij->i', n, dyaw)))
        off = pose - prior
        off[2] = math.remainder(off[2], 2 * math.pi)
        h = w_ret * jac.T @ jac + info_prior
        b = w_ret * jac.T @ res + info_prior @ off
        step = -np.linalg.solve(h, b)
        pose = pose + step
        if np.hypot(step[0], step[1]) < CONVERGED and abs(step[2]) < CONVERGED:
            break
    off = pose - prior
    off[2] = math.remainder(off[2], 2 * math.pi)
    near, normal, d = field.at(to_parent(pose, base_points))
    use = d <= MAX_CORRESPONDENCE
    matched = int(np.count_nonzero(use))
    shift = float(np.hypot(off[0], off[1]))
    ok = matched >= MIN_MATCHED and shift <= MAX_STEP_XY and abs(off[2]) <= MAX_STEP_YAW
    rms = float(np.sqrt(np.mean(d[use] ** 2))) if matched else math.nan
    return Match(pose if ok else prior, bool(ok), matched, rms)
