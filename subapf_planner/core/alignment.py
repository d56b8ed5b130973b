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
  new: a wall not yet in the map, a person, the other face of a thin wall), and
  so are returns beyond a wall where the memory's wall stops but the wall may go
  on (:func:`_ends`: unknown, not seen-free, beyond; their nearest wall point
  would pull the pose back along the wall) or off the wall along it
  (:func:`_beside`);
* each return weighed by its range's noise and by the squared cosine of its
  incidence on the wall (the angle between its ray and the wall's normal there): an
  occupancy grid draws a wall seen at grazing incidence where the rays that run along
  it stop clearing its cells, a cell or more off, and a grazing return's distance to
  the wall so drawn carries that error over the cosine (through the realistic lidar on
  `building_042`, the grazing returns of a turn into a new corridor pulled the heading
  one way, scan after scan, against those that met the walls square);
* a prior towards the odometry prediction (PRIOR_SIGMA_XY, PRIOR_SIGMA_YAW per
  scan), so that a corridor, which fixes the pose across it but not along it,
  keeps odometry's estimate along it;
* among people: the returns of a piece of the scan no longer than a mover
  (core/tracking.clusters) match only cells that have been walls for
  MIN_WALL_AGE (someone who walked slowly into the memory before the tracker
  knew it moved has not stood that long where it is seen now), and a match needs
  MIN_PIECES landmarks (:func:`landmarks`: one person-sized thing cannot tell a
  walker from the robot's own drift);
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

from .occupancy import ESTABLISHED
from .robot import to_parent
from .scan import range_sigma
from .tracking import extents

#: A piece of the scan no longer than a mover (a person, a chair, a post) is matched only
#: to cells established this long ago or more [s] (counted in scans at the planning rate,
#: core/scan.scans_in; the memory's NavigationMemory.align): a person
#: who walked slowly into the memory, before the tracker knew it moved, has not stood
#: that long where it is seen now. Walls (longer pieces) match at once: a room's walls
#: must correct the pose from the first scans, or the room is drawn with the drift.
MIN_WALL_AGE = 5.0
#: Returns farther than this from every established cell take no part [m].
MAX_CORRESPONDENCE = 0.06
#: A return farther than this along the wall from its nearest wall point takes no part
#: (it is beyond the wall's end) [cells].
ALONG_WALL = 0.75
#: A wall cell is a wall's end when no wall lies this far along it on one side [cells]
#: (_ends).
END_PROBE = 2.0
#: Fewest returns that must take part for a match to count.
MIN_MATCHED = 40
#: A piece of the scan (a cluster of returns: core/tracking.clusters) counts as a
#: landmark of a match with at least this many matched returns ...
MIN_PIECE_MATCHED = 8
#: ... and a match needs this many landmarks, or one longer than a mover can be: a single
#: mover-sized thing cannot tell a person standing (or walking slowly, written into the
#: memory before it was known to move) from the robot's own drift.
MIN_PIECES = 2
#: Gauss-Newton iterations at most, and the step below which it stops [m, rad].
ITERATIONS = 6
CONVERGED = 5e-4
#: Blur of the wall mask whose structure gives the walls' normals [cells].
NORMAL_SIGMA = 1.0
#: A map's wall face is seen from one side when the free space about it lies this much
#: more (its gradient's cosine with the normal) on that side (_free_side).
FREE_SIDE = 0.5
#: Prior standard deviation of the prediction, per scan [m], [rad].
PRIOR_SIGMA_XY = 0.02
PRIOR_SIGMA_YAW = 0.02
#: Standard deviation of one return's distance to the wall [m] (the laser's noise plus
#: half a cell).
RETURN_SIGMA = 0.03
#: The prior's information (inverse covariance) on (x, y, yaw), read-only.
INFO_PRIOR = np.diag([PRIOR_SIGMA_XY ** -2, PRIOR_SIGMA_XY ** -2, PRIOR_SIGMA_YAW ** -2])
INFO_PRIOR.setflags(write=False)
#: A match that moves the prediction more than this is refused [m], [rad].
MAX_STEP_XY = 0.03
MAX_STEP_YAW = 0.03
#: A map the robot already has, started from a localiser's map -> odom (Planner.start_from),
#: is first matched in a wider basin (:func:`localise`): the localiser's error is not a
#: wheel's drift of millimetres. The passes' reach, coarse to fine [m] ...
LOCALISE_REACH = (0.4, 0.2, 0.1)
#: ... the localiser's uncertainty as that match's prior [m], [rad] ...
LOCALISE_SIGMA_XY = 0.3
LOCALISE_SIGMA_YAW = 0.1
#: ... and the most it may move the pose (a bigger step is a wrong match) [m], [rad].
LOCALISE_MAX_XY = 0.5
LOCALISE_MAX_YAW = 0.2
#: Scans are matched so until one such match is accepted, for this long at most after the
#: map was taken [s] (then the wheels' bounds again: a map that does not fit is no
#: localisation).
LOCALISE_TIME = 2.0
#: Drift the wheels can add, per metre driven and per radian turned, and so the most a
#: match may move the prediction since the last scan [m/m], [m/rad], [rad/m], [rad/rad].
DRIFT_XY_PER_M = 0.05
DRIFT_XY_PER_RAD = 0.01
DRIFT_YAW_PER_M = 0.02
DRIFT_YAW_PER_RAD = 0.05


@dataclass(frozen=True)
class DistanceField:
    """For the cells of a window (rows = y; cell (0, 0) with its corner at ``origin``
    [m]; ``shape`` (h, w)): which established obstacle cell is the nearest (``index``,
    h * w + 1, the cells flat, row by row, then one for points off the window: its row
    in ``table``), and per wall cell (k of them) a row of ``table`` (k + 1, 8): the wall
    point (x, y) [m], the wall's unit normal there (x, y), ``inf`` where the memory's
    wall ends but the wall may go on (:func:`_ends`; else 0: added to the distance, it
    leaves no distance there), 1 where it was established fewer than
    ``min_wall_scans`` scans before the field was made (OccupancyGrid.established_at;
    else 0) and the normal turned to the free side of a map's face (x, y; zeros where
    either side: _free_side). The last row, k, is for points off the window: no wall
    point, an end (no distance), not new, either side. The table is per wall cell, not
    per window cell: a field is made every few scans and read at a few hundred returns,
    so what a return needs is looked up, in one gather, when it is asked for."""

    index: NDArray[np.int32]
    table: NDArray[np.float64]
    shape: tuple[int, int]
    origin: NDArray[np.float64]
    resolution: float
    #: Whether any face is seen from one side only (a map's: _free_side).
    one_sided: bool = False

    def lookup(self, points: NDArray[np.float64]
               ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Per point (n, 2): the nearest wall point (n, 2), the wall's normal there (n, 2),
        the distance (n,) [m], inf outside the window and where the nearest wall point is
        where the memory's wall ends but the wall may go on (a return there may lie
        beyond it, where the memory has not seen the wall yet), and whether that wall
        cell has been established for fewer than ``min_wall_scans`` scans (n,) (False
        outside the window)."""
        found = self.table[self._rows(points)]
        near = found[:, :2]
        d = np.hypot(*(points - near).T) + found[:, 4]
        return near, found[:, 2:4], d, found[:, 5] > 0.0

    def free_side(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Per point (n, 2): the free side of its nearest wall point's face, as a unit
        normal, where only one side is free (a map's face: _free_side); zeros else."""
        return self.table[self._rows(points), 6:8]

    def _rows(self, points: NDArray[np.float64]) -> NDArray[np.int32]:
        """Each point's row of ``table`` (its nearest wall cell's; the last off the window)."""
        cells = np.floor((points - self.origin) / self.resolution).astype(np.int64)
        h, w = self.shape
        col, row = cells[:, 0], cells[:, 1]
        inside = (col >= 0) & (row >= 0) & (col < w) & (row < h)
        return self.index[np.where(inside, row * w + col, -1)]


def _ends(wall: NDArray[np.bool_], normal: NDArray[np.float64],
          seen_free: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Which wall cells (those of ``np.nonzero(wall)``, with their unit ``normal`` (k, 2))
    are where what the memory holds of a wall ends but the wall may go on (k,): no wall
    cell within one cell of the point END_PROBE cells along the wall (across its normal)
    on one side or the other, and that point not ``seen_free`` (unknown: not yet seen,
    behind someone, beyond the laser's range; or a wall too new to trust). Where the
    memory has seen free space beyond (a door's jamb, a corner), the end is a real one
    and stays: it is what fixes the pose along a corridor. Out of the mask counts as
    wall."""
    h, w = wall.shape
    near_wall = ndimage.binary_dilation(wall, np.ones((3, 3), bool))
    rows, cols = np.nonzero(wall)
    t = normal[:, ::-1] * np.array([1.0, -1.0])   # (x, y) along: (ny, -nx)
    end = np.zeros(rows.size, bool)
    for sign in (1.0, -1.0):
        c = np.rint(cols + sign * END_PROBE * t[:, 0]).astype(np.int64)
        r = np.rint(rows + sign * END_PROBE * t[:, 1]).astype(np.int64)
        inside = (r >= 0) & (c >= 0) & (r < h) & (c < w)
        ri, ci = r[inside], c[inside]
        open_end = ~near_wall[ri, ci] & ~seen_free[ri, ci]
        end[np.flatnonzero(inside)[open_end]] = True
    return end


def _normals(wall: NDArray[np.bool_]) -> NDArray[np.float64]:
    """Unit normal (k, 2) of the walls of a mask at its wall cells (``np.nonzero(wall)``):
    the principal direction of the structure tensor of the blurred mask (across a line
    of cells; any at a lone cell)."""
    blurred = ndimage.gaussian_filter(wall.astype(np.float32), NORMAL_SIGMA)
    gy, gx = ndimage.sobel(blurred, axis=0), ndimage.sobel(blurred, axis=1)
    sxx, syy, sxy = (ndimage.gaussian_filter(v, NORMAL_SIGMA)[wall]
                     for v in (gx * gx, gy * gy, gx * gy))
    angle = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)   # of the larger eigenvalue
    return np.stack((np.cos(angle), np.sin(angle)), axis=-1).astype(np.float64)


def _free_side(free: NDArray[np.bool_], unhit: NDArray[np.bool_], rows: NDArray[np.int64],
               cols: NDArray[np.int64], normal: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per wall cell (``rows``, ``cols``, its unit ``normal`` (k, 2)): the normal turned to
    the side seen free where only that side is and the cell is ``unhit`` (a map's face,
    which the laser sees from that side only); zeros elsewhere (either side)."""
    blurred = ndimage.gaussian_filter(free.astype(np.float32), NORMAL_SIGMA)
    towards = np.column_stack((ndimage.sobel(blurred, axis=1)[rows, cols],
                               ndimage.sobel(blurred, axis=0)[rows, cols]))
    along = np.einsum('ij,ij->i', normal, towards)
    one_sided = unhit & (np.abs(along) > FREE_SIDE * np.hypot(*towards.T) + 1e-6)
    return np.where(one_sided[:, None], normal * np.sign(along)[:, None], 0.0)


def distance_field(log_odds: NDArray[np.float32], origin: NDArray[np.float64],
                   resolution: float, around: NDArray[np.float64], reach: float,
                   hit_offset: NDArray[np.float32] | None = None,
                   established_at: NDArray[np.int32] | None = None,
                   scans: int = 0, min_wall_scans: int = 0,
                   hit_count: NDArray[np.int16] | None = None) -> DistanceField | None:
    """The field of the established cells of a log-odds grid (corner of cell (0, 0) at
    ``origin``) within ``reach`` [m] of the box of the points ``around`` (n, 2); None
    when that window holds no established cell. ``hit_offset`` (the grid's, h x w x 2
    [m]) places each wall point where the returns fell in its cell: matching to cell
    centres would pull the pose by up to half a cell. ``established_at`` (the grid's,
    h x w: the scan from which each cell has been established) and ``scans`` (the
    grid's count now) tell how long each wall has stood: those established fewer than
    ``min_wall_scans`` scans ago are young (DistanceField.lookup). ``hit_count`` (the
    grid's, h x w): a wall cell no return has hit (a known map's: core/known_map.py) is
    one only where it faces space seen free, its face; a map draws a wall as thick as
    its cells make it, and a return matched to the inside of one is as near to a wall
    as one on its face."""
    lo_xy = around.min(axis=0) - reach
    hi_xy = around.max(axis=0) + reach
    n_rows, n_cols = log_odds.shape
    c0, r0 = (max(int(v), 0) for v in np.floor((lo_xy - origin) / resolution))
    c1, r1 = (int(v) for v in np.ceil((hi_xy - origin) / resolution))
    c1, r1 = min(c1, n_cols), min(r1, n_rows)
    if c0 >= c1 - 1 or r0 >= r1 - 1:
        return None
    wall = log_odds[r0:r1, c0:c1] >= ESTABLISHED
    free = log_odds[r0:r1, c0:c1] < 0.0
    unhit = None if hit_count is None else wall & (hit_count[r0:r1, c0:c1] == 0)
    if unhit is not None and unhit.any():   # a map's walls: their faces only
        wall &= ~unhit | ndimage.binary_dilation(free)
    else:
        unhit = None
    if not np.any(wall):
        return None
    rows, cols = ndimage.distance_transform_edt(~wall, return_distances=False,
                                                return_indices=True)
    wall_rows, wall_cols = np.nonzero(wall)
    index = np.zeros(wall.shape, np.int32)
    index[wall_rows, wall_cols] = np.arange(wall_rows.size, dtype=np.int32)
    corner = origin + np.array([c0, r0]) * resolution
    point = corner + (np.stack((wall_cols, wall_rows), axis=-1) + 0.5) * resolution
    if hit_offset is not None:   # where the returns fell in the cell, not its centre
        point = point + hit_offset[r0:r1, c0:c1][wall_rows, wall_cols]
    normals = _normals(wall)
    new = np.zeros(wall_rows.size, bool) if established_at is None else \
        established_at[r0:r1, c0:c1][wall_rows, wall_cols].astype(np.int64) \
        > scans - min_wall_scans
    end = _ends(wall, normals, free)
    table = np.zeros((wall_rows.size + 1, 8))
    table[:-1, 0:2], table[:-1, 2:4] = point, normals
    table[:-1, 4], table[:-1, 5] = np.where(end, np.inf, 0.0), new
    if unhit is not None:   # a map's face: which side of it is free
        table[:-1, 6:8] = _free_side(free, unhit[wall_rows, wall_cols], wall_rows, wall_cols,
                                     normals)
    table[-1, 4] = np.inf   # off the window: no wall point, an end (no distance), not new
    return DistanceField(np.append(index[rows, cols].ravel(), np.int32(wall_rows.size)),
                         table, wall.shape, corner, resolution,
                         bool(np.any(table[:, 6:8])))


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


def _beside(points: NDArray[np.float64], near: NDArray[np.float64],
            normal: NDArray[np.float64], d: NDArray[np.float64],
            resolution: float, reach: NDArray[np.float64] | float = MAX_CORRESPONDENCE
            ) -> NDArray[np.bool_]:
    """Which returns take part: those within MAX_CORRESPONDENCE of a wall and beside it,
    no more than ALONG_WALL cells from their nearest wall point along the wall. A return
    beyond the end of a wall the memory holds (the part ahead not yet established) has
    the wall's end as its nearest point; its residual there would pull the pose back
    along the wall (a corridor's far end, a room's new wall)."""
    off = points - near
    along = np.abs(off[:, 0] * normal[:, 1] - off[:, 1] * normal[:, 0])
    return (d <= reach) & (along <= ALONG_WALL * resolution)


def _extents(points: NDArray[np.float64], pieces: NDArray[np.int64]) -> NDArray[np.float64]:
    """The extent (bounding-box diagonal [m]) of each piece, by label (max label + 1,)."""
    return extents(points, pieces, int(pieces.max()) + 1 if len(pieces) else 0)


def landmarks(points: NDArray[np.float64], pieces: NDArray[np.int64],
              mover_size: float) -> int:
    """How many landmarks matched ``points`` (m, 2) [m] of the scan's pieces (their
    cluster labels, m) make: each piece with MIN_PIECE_MATCHED of them counts one, and one
    whose matched points span more than ``mover_size`` [m] (no mover is that long: a
    wall) counts MIN_PIECES."""
    if not len(pieces):
        return 0
    span = _extents(points, pieces)[np.bincount(pieces) >= MIN_PIECE_MATCHED]
    return int(np.sum(np.where(span > mover_size, MIN_PIECES, 1)))


def _taking_part(field: DistanceField, world: NDArray[np.float64],
                 small: NDArray[np.bool_], reach: NDArray[np.float64] | float
                 = MAX_CORRESPONDENCE, eye: NDArray[np.float64] | None = None
                 ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """For the returns at ``world`` (n, 2) [m]: the nearest wall point, the normal, the
    distance (DistanceField.lookup) and which take part: beside a wall (:func:`_beside`),
    for those of ``small`` pieces a wall that has stood (not young), and with ``eye``
    (the laser, x, y [m]) one of whose faces a map holds the free side (_free_side) only
    if that side faces the laser (a return on the far face of a map's wall is one from
    its near face, offset)."""
    near, normal, d, young = field.lookup(world)
    use = _beside(world, near, normal, d, field.resolution, reach) & ~(small & young)
    if eye is not None and field.one_sided:
        side = field.free_side(world)
        use &= np.einsum('ij,ij->i', side, eye - near) >= 0.0
    return near, normal, d, use


def align(base_points: NDArray[np.float64], predicted: NDArray[np.float64],
          field: DistanceField | None, pieces: NDArray[np.int64] | None = None,
          mover_size: float = math.inf, noise: tuple[float, float] = (0.0, 0.0),
          origin: tuple[float, float] = (0.0, 0.0), *, reach: float = MAX_CORRESPONDENCE,
          max_step: tuple[float, float] = (MAX_STEP_XY, MAX_STEP_YAW),
          info_prior: NDArray[np.float64] = INFO_PRIOR) -> Match:
    """The pose of base_footprint that puts ``base_points`` (n, 2; the returns in
    base_footprint [m]) on the field's walls, starting from and drawn towards
    ``predicted`` (x, y, yaw); see the module docstring. With ``pieces`` (each point's
    cluster label, n), a match is accepted only when its matched returns make MIN_PIECES
    landmarks (:func:`landmarks`; ``mover_size`` [m] the longest a mover can be), and
    the returns of pieces no longer than that match only walls that have stood
    MIN_WALL_AGE (DistanceField.lookup). ``origin``: the laser's position (x, y) in
    base_footprint [m], where the rays start (each return's incidence on its wall).
    ``reach`` [m] (at least twice a return's sigma), ``max_step`` [m, rad] and
    ``info_prior`` (the prediction's information on x, y, yaw) are the default scan's
    MAX_CORRESPONDENCE, MAX_STEP_* and INFO_PRIOR; :func:`localise` widens them."""
    prior = np.asarray(predicted, float).copy()
    if field is None or len(base_points) < MIN_MATCHED:
        return Match(prior, False, 0, math.nan)
    small = np.zeros(len(base_points), bool) if pieces is None else \
        _extents(base_points, pieces)[pieces] <= mover_size
    pose = prior.copy()
    # each return weighed by its range's noise (``noise``: the lidar's floor [m] and
    # fraction of the range), on top of the map's own (RETURN_SIGMA); a noisy far
    # return may lie farther from its wall
    sigma = np.hypot(RETURN_SIGMA, range_sigma(np.hypot(*base_points.T), *noise))
    weight_all = sigma ** -2
    reach = np.maximum(reach, 2.0 * sigma)
    rays = base_points - np.asarray(origin, float)
    rays /= np.maximum(np.hypot(*rays.T), 1e-9)[:, None]   # in base_footprint
    laser = np.asarray(origin, float)[None]
    for _ in range(ITERATIONS):
        world = to_parent(pose, base_points)
        near, normal, d, use = _taking_part(field, world, small, reach,
                                            to_parent(pose, laser)[0])
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
        # and by its incidence: the wall's normal in base_footprint against its ray
        n_base = np.column_stack((c * n[:, 0] + s * n[:, 1], -s * n[:, 0] + c * n[:, 1]))
        w_ret = weight_all[use] * np.einsum('ij,ij->i', n_base, rays[use]) ** 2
        h = (jac.T * w_ret) @ jac + info_prior
        b = (jac.T * w_ret) @ res + info_prior @ off
        step = -np.linalg.solve(h, b)
        pose = pose + step
        if np.hypot(step[0], step[1]) < CONVERGED and abs(step[2]) < CONVERGED:
            break
    off = pose - prior
    off[2] = math.remainder(off[2], 2 * math.pi)
    _, _, d, use = _taking_part(field, to_parent(pose, base_points), small, reach,
                                to_parent(pose, laser)[0])
    matched = int(np.count_nonzero(use))
    shift = float(np.hypot(off[0], off[1]))
    ok = matched >= MIN_MATCHED and shift <= max_step[0] and abs(off[2]) <= max_step[1]
    if ok and pieces is not None:
        ok = landmarks(base_points[use], pieces[use], mover_size) >= MIN_PIECES
    rms = float(np.sqrt(np.mean(d[use] ** 2))) if matched else math.nan
    return Match(pose if ok else prior, bool(ok), matched, rms)


def localise(base_points: NDArray[np.float64], predicted: NDArray[np.float64],
             field: DistanceField | None, pieces: NDArray[np.int64] | None = None,
             mover_size: float = math.inf, noise: tuple[float, float] = (0.0, 0.0),
             origin: tuple[float, float] = (0.0, 0.0)) -> Match:
    """:func:`align` in a wider basin, for a pose from a localiser on a map the robot
    already has (its error decimetres, not a wheel's millimetres): passes of
    LOCALISE_REACH, coarse to fine, each from the last one's pose and drawn to the
    prediction with the localiser's uncertainty (LOCALISE_SIGMA_*), then one at the
    default reach; accepted when that last pass is and the pose moved no more than
    LOCALISE_MAX_*. The arguments are align's."""
    prior = np.asarray(predicted, float)
    info = np.diag([LOCALISE_SIGMA_XY ** -2, LOCALISE_SIGMA_XY ** -2,
                    LOCALISE_SIGMA_YAW ** -2])
    pose, match = prior, Match(prior, False, 0, math.nan)
    for reach in (*LOCALISE_REACH, MAX_CORRESPONDENCE):
        match = align(base_points, pose, field, pieces, mover_size, noise, origin,
                      reach=reach, max_step=(math.inf, math.inf), info_prior=info)
        pose = match.pose
    off = pose - prior
    ok = match.accepted and math.hypot(off[0], off[1]) <= LOCALISE_MAX_XY and \
        abs(math.remainder(off[2], 2 * math.pi)) <= LOCALISE_MAX_YAW
    return Match(pose if ok else prior, bool(ok), match.matched, match.rms)
