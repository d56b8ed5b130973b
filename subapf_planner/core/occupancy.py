"""Occupancy memory: a log-odds grid in ``odom`` built from every scan.

The paper's planner has no memory, so it cannot tell it has been somewhere
before, and a potential made of the distance to the goal plus obstacle terms
has minima wherever obstacles close a pocket (docs/paper_notes.md section 3).
This grid is what the navigation field (core/navigation.py) is computed on.

Update rule, per beam of a scan taken at the laser's odom pose:

* a valid return (finite, in [range_min, range_max)) adds ``hit`` to the log
  odds of its end cell and ``miss`` to every cell the beam crossed before it,
  from range_min on (a lidar says nothing about what is closer to it);
* a ``+inf`` return (no echo within range) adds ``miss`` along the whole beam
  from range_min up to ``clear_range`` (at most range_max): open space is
  forgotten obstacles;
* NaN, 0.0, negative and below-range_min returns are not evidence of anything
  (LDS-01 and LDS-02 invalid beams) and change nothing.

With hit places kept (the scan alignment's), a second layer of log odds holds the
walls the alignment matches to: the same rule, but a beam clears only up to what the
caller says its range noise may have made it fall short by. A wall whose returns
that fell long clear the cells in front of it, and nothing clears those behind it,
is drawn behind itself: matches to it lean away from it, scan after scan. The
planning layer is cleared up to each return, so that what the robot may drive
through is not narrowed by the noise.

Log odds are clamped to [LOG_ODDS_MIN, LOG_ODDS_MAX], so a wall seen many
times stays after a few dropped beams, and a thing that moved away is
forgotten after a few scans through it. A cell is occupied when its log odds
are above 0; unknown cells (0) count as free (optimistic, as D* Lite).

Memory is bounded: the grid is a square window of ``size`` metres that
follows the robot (and reaches towards the goal); what leaves it is forgotten.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .known_map import KnownMap, prior
from .scan import Scan

#: Log-odds increments and clamps (a hit outweighs two misses).
HIT = 0.9
MISS = -0.4
LOG_ODDS_MIN = -2.0
LOG_ODDS_MAX = 3.5
#: Distance kept between the robot and the window's edge before it recentres [m].
EDGE_MARGIN = 3.0
#: Returns over which a cell's mean return place is kept (OccupancyGrid.hit_offset).
HIT_MEMORY = 20
#: Log odds from which a cell is an established obstacle (three hits or more: what the
#: memory is sure of; the scan alignment's walls, OccupancyGrid.established_at).
ESTABLISHED = 2.0
#: OccupancyGrid.established_at of a cell that is not established.
NOT_ESTABLISHED = np.iinfo(np.int32).max
#: A known map's walls count as established this many scans before the first.
PRIOR_AGE = 1000


def cell_index(points: ArrayLike, origin: ArrayLike, resolution: float) -> NDArray[np.int64]:
    """(row, col) of the cell of each point (n, 2) [m] on a grid whose cell (0, 0) has its
    corner at ``origin`` (x, y) [m] and whose rows are y: the one world-to-cell rule of
    the occupancy grid and the navigation field. Cells may lie outside any grid."""
    p = np.atleast_2d(np.asarray(points, float))
    return np.floor((p[:, ::-1] - np.asarray(origin, float)[::-1])
                    / resolution).astype(np.int64)


#: The window's per-cell arrays (OccupancyGrid attributes), which shift with it and
#: make up its memory.
LAYERS = ('log_odds', 'hit_offset', 'hit_count', 'established_at', 'wall_odds')


class OccupancyGrid:
    """A ``size`` x ``size`` m log-odds window at ``resolution`` m, in odom.

    ``origin`` is the odom position of the corner of cell (0, 0); cell (i, j)
    covers x in [ox + j*res, ox + (j+1)*res), y in [oy + i*res, ...) (row = y).
    Not thread-safe; one per robot.
    """

    def __init__(self, resolution: float, size: float, hit_places: bool = False) -> None:
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise ValueError(f'map resolution must be positive, got {resolution}')
        self.resolution = float(resolution)
        self.cells = max(8, int(math.ceil(size / resolution)))
        self.log_odds = np.zeros((self.cells, self.cells), np.float32)
        #: With ``hit_places`` (the scan alignment's sub-cell wall position; None
        #: without): the mean place of the returns in each cell, from its centre
        #: (x, y) [m], over the last HIT_MEMORY of them.
        n = self.cells
        self.hit_offset: NDArray[np.float32] | None = \
            np.zeros((n, n, 2), np.float32) if hit_places else None
        self.hit_count: NDArray[np.int16] | None = \
            np.zeros((n, n), np.int16) if hit_places else None
        #: With ``hit_places``: the scan (``scans`` then) from which each cell has been
        #: established, until misses leave it no longer occupied (NOT_ESTABLISHED): how
        #: long a wall has stood, which a person who walked slowly into the memory has
        #: not (core/alignment.py).
        self.established_at: NDArray[np.int32] | None = \
            np.full((n, n), NOT_ESTABLISHED, np.int32) if hit_places else None
        #: With ``hit_places``: the log odds of the scan alignment's walls, marked as
        #: ``log_odds`` but cleared by each beam only up to ``wall_short`` before its
        #: return (OccupancyGrid.update; see the module docstring).
        self.wall_odds: NDArray[np.float32] | None = \
            np.zeros((n, n), np.float32) if hit_places else None
        #: Scans integrated so far.
        self.scans = 0
        self.origin = np.array([-0.5, -0.5]) * self.cells * self.resolution
        self.version = 0   # bumped whenever the occupied set (log odds > 0) changed
        #: A map the robot already has (core/known_map.py): each cell the window takes
        #: in starts from it (None: unknown).
        self.known: KnownMap | None = None

    # --- geometry ---------------------------------------------------------------------
    @property
    def size(self) -> float:
        """Side of the window [m]."""
        return self.cells * self.resolution

    @property
    def nbytes(self) -> int:
        """Memory held by the grid [bytes]."""
        layers = (getattr(self, name) for name in LAYERS)
        return int(sum(a.nbytes for a in layers if a is not None))

    def cell_of(self, points: ArrayLike) -> NDArray[np.int64]:
        """(row, col) of each point (n, 2) [m]; may lie outside the window."""
        return cell_index(points, self.origin, self.resolution)

    def centre_of(self, cells: ArrayLike) -> NDArray[np.float64]:
        """Odom position of cell centres (n, 2) from (row, col)."""
        c = np.atleast_2d(np.asarray(cells, float))
        return self.origin + (c[:, ::-1] + 0.5) * self.resolution

    def inside(self, cells: NDArray[np.int64]) -> NDArray[np.bool_]:
        return np.all((cells >= 0) & (cells < self.cells), axis=1)

    def clear(self, cells: NDArray[np.int64]) -> None:
        """Cells (n, 2; row, col, inside the window) that are occupied become unknown (and
        no longer established): something that moved stood there."""
        hit = self.log_odds[cells[:, 0], cells[:, 1]] > 0.0
        if np.any(hit):
            self.log_odds[cells[hit, 0], cells[hit, 1]] = 0.0
            if self.established_at is not None:
                self.established_at[cells[hit, 0], cells[hit, 1]] = NOT_ESTABLISHED
                self.wall_odds[cells[hit, 0], cells[hit, 1]] = 0.0
            self.version += 1

    def know(self, known: KnownMap | None) -> None:
        """Start every cell of the window from ``known`` now, and each cell a shift
        brings in later (None: cells come in unknown again; those in the window stay)."""
        self.known = known
        if known is not None:
            self._take_prior(np.ones((self.cells, self.cells), bool))

    def _take_prior(self, fresh: NDArray[np.bool_]) -> None:
        """The ``fresh`` cells (a mask of the window) from the known map: its walls as
        walls established PRIOR_AGE scans ago, where returns fell not known (the cell's
        centre)."""
        rows, cols = np.nonzero(fresh)
        values, wall = prior(self.known, self.centre_of(np.column_stack((rows, cols))))
        self.log_odds[rows, cols] = values
        if self.hit_offset is not None:
            self.wall_odds[rows, cols] = values
            self.hit_offset[rows, cols] = 0.0
            self.hit_count[rows, cols] = 0
            self.established_at[rows, cols] = NOT_ESTABLISHED
            self.established_at[rows[wall], cols[wall]] = self.scans - PRIOR_AGE
        self.version += 1

    def occupied(self) -> NDArray[np.bool_]:
        """Occupied cells (log odds > 0), a new array."""
        return self.log_odds > 0.0

    # --- following the robot ----------------------------------------------------------
    def follow(self, robot: ArrayLike, goal: ArrayLike | None = None) -> bool:
        """Recentre the window when its centre is more than EDGE_MARGIN (at most a quarter
        of the window) from where it should be: the robot-goal midpoint when both fit
        with that margin, else the robot shifted towards the goal as far as the margin
        allows. Returns whether it moved."""
        r = np.asarray(robot, float)[:2]
        half = 0.5 * self.size
        margin = min(EDGE_MARGIN, 0.25 * self.size)
        target = r
        if goal is not None:
            g = np.asarray(goal, float)[:2]
            if np.all(np.abs(g - r) <= self.size - 2 * margin):
                target = 0.5 * (r + g)
            else:
                target = r + np.clip(g - r, -(half - margin), half - margin)
        if np.all(np.abs(target - (self.origin + half)) <= margin):
            return False
        self._shift_to(target)
        return True

    def _shift_to(self, centre: NDArray[np.float64]) -> None:
        new_origin = np.round((centre - 0.5 * self.size) / self.resolution) * self.resolution
        d = np.round((new_origin - self.origin) / self.resolution).astype(int)  # (dx, dy)
        n = self.cells
        dx, dy = int(d[0]), int(d[1])
        for name in LAYERS:
            a = getattr(self, name)
            if a is None:   # no hit places kept
                continue
            shifted = np.full_like(a, NOT_ESTABLISHED) if a is self.established_at \
                else np.zeros_like(a)
            if abs(dx) < n and abs(dy) < n:
                src_r = slice(max(dy, 0), n + min(dy, 0))
                dst_r = slice(max(-dy, 0), n + min(-dy, 0))
                src_c = slice(max(dx, 0), n + min(dx, 0))
                dst_c = slice(max(-dx, 0), n + min(-dx, 0))
                shifted[dst_r, dst_c] = a[src_r, src_c]
            setattr(self, name, shifted)
        self.origin = new_origin
        self.version += 1
        if self.known is not None:   # the cells that came in start from the known map
            fresh = np.ones((n, n), bool)
            if abs(dx) < n and abs(dy) < n:
                fresh[dst_r, dst_c] = False
            self._take_prior(fresh)

    # --- scans ------------------------------------------------------------------------
    def update(self, scan: Scan, laser_pose: ArrayLike, clear_range: float = math.inf,
               transient: NDArray[np.bool_] | None = None,
               transient_short: ArrayLike = 0.0, wall_short: ArrayLike = 0.0) -> None:
        """Integrate one scan taken with the laser at ``laser_pose`` (x, y, yaw) in odom
        (see the module docstring for the rule). Its geometry is assumed checked
        (Scan.check: the planner refuses a bad scan before this is called).
        ``transient`` (per beam): returns of something moving or new (held out of the
        memory: core/tracking.py); their beams clear the cells they cross but their end
        cells are not marked, and they stop clearing ``transient_short`` [m] (per beam,
        or one for all) before the return. In the walls' layer (``wall_odds``) every beam
        with a return stops clearing ``wall_short`` [m] (per beam, or one for all) before
        it, or where it stops in the planning layer if that is sooner."""
        self.scans += 1
        r = np.asarray(scan.ranges, float).ravel()
        lx, ly, lyaw = (float(v) for v in laser_pose)
        angles = scan.angles + lyaw
        hit = scan.valid()
        reach = min(scan.range_max, clear_range)
        with np.errstate(invalid='ignore'):
            open_beam = np.isposinf(r) & (reach > scan.range_min)
        lengths = np.where(hit, r, np.where(open_beam, reach, 0.0))
        use = hit | open_beam
        if not np.any(use):
            return
        a, length, ends_hit = angles[use], lengths[use], hit[use]
        marked = ends_hit if transient is None else ends_hit & ~transient[use]
        res = self.resolution
        # free samples at (k + 1/2) cells along each beam, from range_min (the lidar says
        # nothing about what is closer: core/blind_spots.py), stopping half a cell before
        # a return so its own cell is not cleared; built ragged (only the samples a beam
        # has)
        stop = np.where(ends_hit, length - 0.5 * res, length)
        if transient is not None:
            short = np.broadcast_to(np.asarray(transient_short, float), r.shape)[use]
            stop = np.where(ends_hit & transient[use], stop - short, stop)
        first = max(math.ceil(scan.range_min / res - 0.5), 0)
        counts = np.maximum(np.ceil(stop / res - 0.5) - first, 0).astype(np.int64)
        beam = np.repeat(np.arange(a.size), counts)
        k = np.arange(beam.size) - np.repeat(np.cumsum(counts) - counts, counts) + 0.5 \
            + first
        # cells in a box around the laser that holds every beam (not the whole window)
        n = self.cells
        reach_cells = int(math.ceil(float(length.max()) / res)) + 1
        lr, lc = (int(v) for v in self.cell_of((lx, ly))[0])
        c0, r0 = min(max(lc - reach_cells, 0), n), min(max(lr - reach_cells, 0), n)
        c1, r1 = min(max(lc + reach_cells + 1, 0), n), min(max(lr + reach_cells + 1, 0), n)
        if c0 >= c1 or r0 >= r1:
            return
        # a box the window does not cut holds every sample: no bounds checks needed
        box = (r0, r1, c0, c1, (c0, r0) != (lc - reach_cells, lr - reach_cells)
               or (c1, r1) != (lc + reach_cells + 1, lr + reach_cells + 1))
        x0 = (lx - self.origin[0]) / res - c0
        y0 = (ly - self.origin[1]) / res - r0
        c, s = np.cos(a), np.sin(a)
        free = self._flat(x0 + c[beam] * k, y0 + s[beam] * k, box)
        if self.wall_odds is not None:   # the walls' layer: stops ``wall_short`` before
            wall_stop = np.where(ends_hit, np.minimum(stop, length - np.broadcast_to(
                np.asarray(wall_short, float), r.shape)[use]), stop)
            keep = k < wall_stop[beam] / res
            wall_free = self._flat(x0 + c[beam[keep]] * k[keep],
                                   y0 + s[beam[keep]] * k[keep], box)
        end_cols = x0 + c[marked] * length[marked] / res
        end_rows = y0 + s[marked] * length[marked] / res
        ends = self._flat(end_cols, end_rows, box)
        if self.hit_offset is not None:
            self._note_hits(end_cols, end_rows, box)
        cells, old, new = self._fold(self.log_odds, free, ends, box)
        if self.wall_odds is not None:
            self._fold(self.wall_odds, wall_free, ends, box)
        if self.established_at is not None:
            since = self.established_at.reshape(-1)   # a view (C-contiguous)
            first = (new >= ESTABLISHED) & (since[cells] == NOT_ESTABLISHED)
            since[cells[first]] = self.scans
            since[cells[new <= 0.0]] = NOT_ESTABLISHED
        if np.any((old > 0.0) != (new > 0.0)):
            self.version += 1

    def _fold(self, layer: NDArray[np.float32], free: NDArray[np.int64],
              ends: NDArray[np.int64], box: tuple[int, int, int, int, bool]
              ) -> tuple[NDArray[np.int64], NDArray[np.float32], NDArray[np.float32]]:
        """Add MISS to the log odds of ``layer``'s cells at box flat indices ``free`` and
        HIT to those at ``ends``: each touched cell changes once however many beams touch
        it, and a return wins. The touched cells' flat indices in the window, and their
        log odds before and after."""
        r0, r1, c0, c1, _ = box
        mark = np.zeros((r1 - r0) * (c1 - c0), np.int8)
        mark[free] = 1
        mark[ends] = 2
        touched = np.flatnonzero(mark)
        n, w = self.cells, c1 - c0   # box flat index -> the window's flat index
        cells = touched + (touched // w) * (n - w) + (r0 * n + c0)
        flat = layer.reshape(-1)   # a view: every layer is allocated C-contiguous, kept so
        old = flat[cells]
        new = np.minimum(np.maximum(
            old + np.where(mark[touched] == 2, np.float32(HIT), np.float32(MISS)),
            np.float32(LOG_ODDS_MIN)), np.float32(LOG_ODDS_MAX))
        flat[cells] = new
        return cells, old, new

    def _note_hits(self, cols: NDArray[np.float64], rows: NDArray[np.float64],
                   box: tuple[int, int, int, int, bool]) -> None:
        """Fold the returns at continuous (col, row) box coordinates into their cells'
        mean offsets (a running mean over at most HIT_MEMORY returns)."""
        r0, r1, c0, c1, _ = box
        col, row = np.floor(cols).astype(np.int64), np.floor(rows).astype(np.int64)
        ok = (row >= 0) & (row < r1 - r0) & (col >= 0) & (col < c1 - c0)
        if not np.any(ok):
            return
        w = c1 - c0
        flat = row[ok] * w + col[ok]
        cells, inverse, k = np.unique(flat, return_inverse=True, return_counts=True)
        off = np.column_stack((cols[ok] - col[ok] - 0.5, rows[ok] - row[ok] - 0.5)) \
            * self.resolution
        total = np.column_stack([np.bincount(inverse, off[:, i], len(cells)) for i in (0, 1)])
        rr, cc = np.divmod(cells, w)
        rr, cc = rr + r0, cc + c0
        n = self.hit_count[rr, cc].astype(np.float64)
        mean = (self.hit_offset[rr, cc] * n[:, None] + total) / (n + k)[:, None]
        self.hit_offset[rr, cc] = mean
        self.hit_count[rr, cc] = np.minimum(n + k, HIT_MEMORY)

    @staticmethod
    def _flat(cols: NDArray[np.float64], rows: NDArray[np.float64],
              box: tuple[int, int, int, int, bool]) -> NDArray[np.int64]:
        """Flat indices in ``box`` (r0, r1, c0, c1, cut), with repeats, of the cells at
        continuous (col, row) coordinates [cells from the box's corner] inside it; with
        ``cut`` False every point is known to lie inside."""
        h, w, cut = box[1] - box[0], box[3] - box[2], box[4]
        col = np.floor(cols).astype(np.int64)
        row = np.floor(rows).astype(np.int64)
        if not cut:
            return row * w + col
        ok = (row >= 0) & (row < h) & (col >= 0) & (col < w)
        return row[ok] * w + col[ok]
