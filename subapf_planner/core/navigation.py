"""Navigation-function attraction: the distance to the goal through free space.

A navigation function has one minimum, the goal (Rimon and Koditschek 1992);
on a grid, the distance to the goal through free cells is one: every cell from
which the goal can be reached has a neighbour closer to it (NF1, Latombe 1991;
docs/paper_notes.md section 5). It replaces the Euclidean attraction of eq. (21)
in the APF step and in the sampling scores, so the potential the robot descends
has no local minimum but the goal; eq. (13)'s repulsion and the circular
sampling stay as the local layer that keeps the path smooth and clear.

Computed by fast marching (scikit-fmm, Sethian 1996), which solves the eikonal
equation |grad T| = 1 / speed and is close to Euclidean (8-connected Dijkstra
overestimates by up to 8 %). Its second-order stencil reaches two cells upwind and
can leave a cell beside a wall or the patch's border lower than all its neighbours
(a pit, found by test_memory.py's property test); each such cell is raised just
above its lowest neighbour (``_fill_pits``), which keeps the one minimum. Only
occupied cells are walls of the field; the
speed is ``MIN_SPEED`` within ``inflation_radius`` of them (a robot found there is
led out, not stranded; and, when asked, within ``gap_clearance``: the sampling's
clearance, so that a gap the local layer will not enter costs as much as contact),
then rises linearly to 1 at ``inflation_radius +
clearance_band``: the field keeps to the middle of passages and takes a
narrow one only when going round costs more. Whether the goal can be reached at
all is decided on the hard inflation: the free cells at least ``inflation_radius``
from every occupied cell, connected (``reachable``). The field is computed on
the part of the grid that matters: the bounding box of the occupied cells, the
robot and the goal, grown by ``CROP_MARGIN`` (outside it everything is unknown,
i.e. free, so the box changes no route through obstacles). The marching runs on
blocks of ``coarsening`` x ``coarsening`` map cells (a block is a wall when any
of its cells is occupied, and as fast as its fastest cell); reachability stays
on the map cells, and a robot the blocks cut off from a goal the cells reach is
given a field marched on the cells.
Units: values in metres of free-space travel (seconds at 1 m/s).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, reduce
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage
import skfmm

from .occupancy import cell_index

#: Speed within inflation_radius of an occupied cell (relative; 1 in open space).
MIN_SPEED = 0.02
#: Free border kept around the box the field is computed on [m].
CROP_MARGIN = 1.0
#: A goal beyond the grid stands in at the border cell nearest it; when that cell is in
#: a wall (a known map's), at the free cell nearest it within this [m].
BORDER_SLACK = 1.0
#: The 8 neighbours (d_row, d_col) and their lengths in cells.
NEIGHBOURS = np.array([(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)])
NEIGHBOUR_LENGTH = np.hypot(NEIGHBOURS[:, 0], NEIGHBOURS[:, 1])
#: Unit vectors (x, y) towards the 8 neighbours (x along columns, y along rows).
NEIGHBOUR_UNIT = NEIGHBOURS[:, ::-1] / NEIGHBOUR_LENGTH[:, None]
#: Border of inf cells around a field's values: the bilinear corners of any point, and
#: their neighbours, index the padded array with no bounds checks.
PAD = 3
#: Single-point directions a field remembers (the newest).
SINGLE_DIRECTIONS_KEPT = 4
#: Bilinear corners (col + 0|1, row + 0|1), in the order of the weights.
_CORNER_RIGHT = np.array([False, True, False, True])
_CORNER_UP = np.array([False, False, True, True])


@dataclass(frozen=True)
class NavigationField:
    """Distance to ``goal`` [m] on a grid patch, inf where blocked or cut off.

    ``origin`` is the odom corner of cell (0, 0); rows are y, columns x.
    """

    origin: NDArray[np.float64]
    resolution: float
    values: NDArray[np.float64]
    goal: NDArray[np.float64]
    #: Cells (rows, cols) connected to the goal through the hard-inflated free space, at
    #: ``passable_resolution`` (the map's), from the same ``origin``.
    passable: NDArray[np.bool_]
    passable_resolution: float

    def reachable(self, point: ArrayLike, radius_cells: int = 3) -> bool:
        """Whether the goal can be reached from ``point`` (a cell within ``radius_cells``
        of it is connected to the goal at the hard inflation)."""
        h, w = self.passable.shape
        row, col = cell_index(np.asarray(point, float)[:2], self.origin,
                              self.passable_resolution)[0]
        r0, r1 = max(row - radius_cells, 0), min(row + radius_cells + 1, h)
        c0, c1 = max(col - radius_cells, 0), min(col + radius_cells + 1, w)
        return bool(r0 < r1 and c0 < c1 and self.passable[r0:r1, c0:c1].any())

    @cached_property
    def padded(self) -> NDArray[np.float64]:
        """``values`` with a border of ``PAD`` inf cells (C-contiguous)."""
        return np.pad(self.values, PAD, constant_values=np.inf)

    @cached_property
    def _neighbour_offsets(self) -> NDArray[np.int64]:
        """Flat offsets of the 8 neighbours in ``padded``."""
        return NEIGHBOURS[:, 0] * (self.values.shape[1] + 2 * PAD) + NEIGHBOURS[:, 1]

    def _corners(self, points: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Bilinear corners of each point: (flat indices into ``padded`` (n, 4), weights
        (n, 4)); corners off the patch fall on the inf border."""
        p = np.atleast_2d(np.asarray(points, float))
        g = (p - self.origin) / self.resolution - 0.5   # continuous (col, row) of centres
        base = np.floor(g)
        f = g - base
        h, w = self.values.shape
        # (np.minimum/np.maximum: np.clip costs more on a few points)
        col = np.minimum(np.maximum(base[:, 0], -2), w).astype(np.int64) + PAD
        row = np.minimum(np.maximum(base[:, 1], -2), h).astype(np.int64) + PAD
        width = w + 2 * PAD
        flat = (row * width + col)[:, None] + np.array([0, 1, width, width + 1])
        fx, fy = f[:, 0:1], f[:, 1:2]
        weights = np.where(_CORNER_RIGHT, fx, 1.0 - fx) * np.where(_CORNER_UP, fy, 1.0 - fy)
        return flat, weights

    def value(self, points: ArrayLike) -> NDArray[np.float64]:
        """Field at each point (n,) [m], bilinear over the finite corners; inf where no
        corner is finite (inside an inflated obstacle, or off the patch)."""
        flat, w = self._corners(points)
        v = self.padded.reshape(-1)[flat]
        ok = np.isfinite(v)
        wsum = np.sum(np.where(ok, w, 0.0), axis=1)
        num = np.sum(np.where(ok, v, 0.0) * w, axis=1)
        with np.errstate(invalid='ignore', divide='ignore'):
            return np.where(wsum > 1e-9, num / np.maximum(wsum, 1e-12), np.inf)

    def _descent(self, flat: NDArray[np.int64]) -> NDArray[np.float64]:
        """Unit steepest-descent direction (..., 2) as (x, y) at cells given by flat indices
        into ``padded``: the sum of the unit vectors to the 8 neighbours weighted by how
        much lower each is per metre; cut-off (inf) cells have none and count for none."""
        padded = self.padded.reshape(-1)
        v = padded[flat]
        v = np.where(np.isfinite(v), v, -np.inf)    # a cut-off cell descends nowhere
        drop = v[..., None] - padded[flat[..., None] + self._neighbour_offsets]
        slope = np.where(drop > 0.0, drop, 0.0) / NEIGHBOUR_LENGTH
        acc = slope @ NEIGHBOUR_UNIT
        norm = np.hypot(acc[..., 0], acc[..., 1])[..., None]
        return np.where(norm > 1e-12, acc / np.maximum(norm, 1e-12), 0.0)

    def direction(self, points: ArrayLike) -> NDArray[np.float64]:
        """Unit descent direction at each point (n, 2): the bilinear blend of its corners'
        steepest descents; where they have none (inside an inflated obstacle), the
        direction to the nearest cell that has one, within a few cells; zero when there
        is none either."""
        p = np.atleast_2d(np.asarray(points, float))
        key = p.tobytes() if p.shape[0] == 1 else None
        if key in self._single_directions:
            return self._single_directions[key].copy()
        flat, w = self._corners(p)
        d = np.einsum('nk,nkj->nj', w, self._descent(flat))
        norm = np.hypot(d[:, 0], d[:, 1])
        out = np.where(norm[:, None] > 1e-9, d / np.maximum(norm, 1e-12)[:, None], 0.0)
        for i in np.flatnonzero(norm <= 1e-9):
            out[i] = self._towards_free(p[i])
        if key is not None:
            if len(self._single_directions) >= SINGLE_DIRECTIONS_KEPT:
                del self._single_directions[next(iter(self._single_directions))]
            self._single_directions[key] = out.copy()
        return out

    @cached_property
    def _single_directions(self) -> dict[bytes, NDArray[np.float64]]:
        """The last few single-point directions (a cycle asks for the robot's twice)."""
        return {}

    def _towards_free(self, point: NDArray[np.float64], radius_cells: int = 6) -> NDArray:
        h, wd = self.values.shape
        row, col = cell_index(point, self.origin, self.resolution)[0]
        r0, r1 = max(row - radius_cells, 0), min(row + radius_cells + 1, h)
        c0, c1 = max(col - radius_cells, 0), min(col + radius_cells + 1, wd)
        if r0 >= r1 or c0 >= c1:
            return np.zeros(2)
        patch = self.values[r0:r1, c0:c1]
        if not np.any(np.isfinite(patch)):
            return np.zeros(2)
        rr, cc = np.nonzero(np.isfinite(patch))
        centres = self.origin + (np.column_stack((cc + c0, rr + r0)) + 0.5) * self.resolution
        # nearest free cell, ties to the lower field value
        dist = np.hypot(*(centres - point).T)
        k = np.lexsort((patch[rr, cc], np.round(dist / self.resolution, 3)))[0]
        v = centres[k] - point
        n = float(np.hypot(*v))
        return v / n if n > 1e-9 else np.zeros(2)

    @cached_property
    def downhill(self) -> NDArray[np.int64]:
        """Per cell (flat index), the flat index of its lowest 8-neighbour when that is
        strictly lower, else -1 (the goal, cut-off cells). Computed once per field."""
        h, w = self.values.shape
        nb = _neighbours(self.padded, PAD, (h, w))
        k = np.argmin(nb, axis=0)
        lower = np.take_along_axis(nb, k[None], axis=0)[0] < self.values
        rows, cols = np.indices((h, w))
        target = (rows + NEIGHBOURS[k, 0]) * w + cols + NEIGHBOURS[k, 1]
        return np.where(lower, target, -1).ravel()

    def path(self, start: ArrayLike, max_length: float = 30.0) -> NDArray[np.float64]:
        """Steepest-descent polyline (k, 2) [m] from ``start`` along the grid (each step to
        the lowest 8-neighbour) until the goal cell or ``max_length``; empty when the
        start is off the patch or cut off from the goal."""
        h, w = self.values.shape
        row, col = (int(v) for v in cell_index(np.asarray(start, float)[:2], self.origin,
                                                self.resolution)[0])
        if not (0 <= row < h and 0 <= col < w) or not np.isfinite(self.values[row, col]):
            return np.zeros((0, 2))
        downhill = self.downhill
        cells = [row * w + col]
        for _ in range(int(max_length / self.resolution)):
            nxt = int(downhill[cells[-1]])
            if nxt < 0:
                break
            cells.append(nxt)
        rc = np.column_stack(np.divmod(np.asarray(cells), w)).astype(float)
        return self.origin + (rc[:, ::-1] + 0.5) * self.resolution


def thin_polyline(points: ArrayLike, spacing: float) -> NDArray[np.float64]:
    """The points (k, 2) of a polyline, walking from the first, which is kept: each next
    one the first at least ``spacing`` [m] from the last one kept, in a straight line (a
    path that zigzags on the grid keeps its points that far apart too), and the last."""
    p = np.asarray(points, float).reshape(-1, 2)
    if len(p) < 3 or spacing <= 0.0:
        return p.copy()
    keep = [0]
    while True:   # the next point at least ``spacing`` from the last one kept
        far = np.flatnonzero(np.hypot(*(p[keep[-1] + 1:] - p[keep[-1]]).T)
                             >= spacing - 1e-9)
        nxt = keep[-1] + 1 + int(far[0]) if far.size else len(p)
        if nxt >= len(p) - 1:
            break
        keep.append(nxt)
    keep.append(len(p) - 1)
    return p[keep]


def densify(points: ArrayLike, spacing: float) -> NDArray[np.float64]:
    """The polyline (k, 2) [m] with points added on each segment so that none are more
    than ``spacing`` [m] apart (its own points kept, in order); non-finite points
    dropped first."""
    p = np.asarray(points, float).reshape(-1, 2)
    p = p[np.all(np.isfinite(p), axis=1)]
    if len(p) < 2 or spacing <= 0.0:
        return p.copy()
    out = [p[:1]]
    for a, b in zip(p[:-1], p[1:], strict=True):
        n = max(int(math.ceil(np.hypot(*(b - a)) / spacing)), 1)
        out.append(a + (b - a) * (np.arange(1, n + 1) / n)[:, None])
    return np.vstack(out)


def crop_box(occupied: NDArray[np.bool_], cells: NDArray[np.int64],
             margin: int) -> tuple[int, int, int, int]:
    """(r0, r1, c0, c1): the box of the occupied cells and ``cells`` (k, 2), grown by
    ``margin`` cells and clipped to the grid."""
    rs = np.concatenate([np.flatnonzero(occupied.any(axis=1)), cells[:, 0]])
    cs = np.concatenate([np.flatnonzero(occupied.any(axis=0)), cells[:, 1]])
    h, w = occupied.shape
    return (max(int(rs.min()) - margin, 0), min(int(rs.max()) + margin + 1, h),
            max(int(cs.min()) - margin, 0), min(int(cs.max()) + margin + 1, w))


def compute_field(occupied: NDArray[np.bool_], origin: ArrayLike, resolution: float,
                  goal: ArrayLike, robot: ArrayLike, inflation_radius: float,
                  clearance_band: float, coarsening: int = 1, route: ArrayLike | None = None,
                  route_discount: float = 0.0, route_width: float = 0.0,
                  gap_clearance: float = 0.0, goal_slack: float = 0.0) -> NavigationField | None:
    """The navigation field to ``goal`` on an occupancy grid (see the module docstring).

    ``coarsening`` > 1 marches on blocks of that many cells a side (fast marching
    costs more than linearly in cells: 2 is about five times faster): a block is a
    wall when any of its cells is occupied (a thin wall never leaks) and as fast as
    its fastest cell (a narrow gap keeps its speed). Reachability stays decided on
    the map's cells; if the blocks cut the robot off from a goal those cells reach
    (a gap narrower than a block or two), the field is marched on the cells instead.
    ``goal`` outside the grid is replaced by the nearest cell of the grid's border (or
    the free cell nearest that within BORDER_SLACK).
    ``inflation_radius`` [m]: the hard inflation (the robot's footprint; see the module
    docstring) and ``clearance_band`` [m] the band beyond it where travel speeds up.
    ``route`` (k, 2) [m]: the way the robot has taken (the last field's ``path``); travel
    within ``route_width`` [m] of it is ``route_discount`` cheaper (route_speed).
    ``gap_clearance`` [m]: travel closer than this to an occupied cell is as slow as in
    contact (MIN_SPEED) though not closed: the clearance the local layer keeps from
    what it sees, so a gap it will not enter costs as much as a wall's face from the
    start (taken only when no other way is open) and the goal stays reachable.
    ``goal_slack`` [m]: a goal within ``inflation_radius`` of an occupied cell is
    replaced by the nearest free cell this close to it (Nav2's planner ``tolerance``:
    walls drawn through a noisy lidar are some centimetres thicker than the walls).
    Returns None when no free cell is within ``goal_slack`` of the goal cell.
    """
    origin = np.asarray(origin, float)
    h, w = occupied.shape
    g = np.asarray(goal, float)[:2]
    k = max(int(coarsening), 1)

    def cell(p: ArrayLike) -> NDArray[np.int64]:
        return np.clip(cell_index(np.asarray(p, float)[:2], origin, resolution)[0], 0,
                       [h - 1, w - 1])

    gc, rc = cell(g), cell(robot)
    beyond = not np.array_equal(gc, cell_index(g, origin, resolution)[0])
    slack = max(goal_slack, BORDER_SLACK) if beyond else goal_slack
    margin = int(math.ceil((CROP_MARGIN + inflation_radius + clearance_band) / resolution))
    r0, r1, c0, c1 = crop_box(occupied, np.array([gc, rc]), margin)
    occ = occupied[r0:r1, c0:c1]
    if k > 1:   # whole blocks: pad with unknown (free) cells beyond the grid
        occ = np.pad(occ, ((0, -occ.shape[0] % k), (0, -occ.shape[1] % k)))
    clear = ndimage.distance_transform_edt(~occ) * resolution if occ.any() \
        else np.full(occ.shape, np.inf)
    free = clear >= inflation_radius
    g_local = nearest_free(free, (gc[0] - r0, gc[1] - c0), slack / resolution)
    if g_local is None:
        return None
    moved = g_local != (gc[0] - r0, gc[1] - c0)
    labels, _ = ndimage.label(free, structure=np.ones((3, 3)))
    passable = labels == labels[g_local]
    if k > 1:   # (the speed is monotone in the clearance: a block's from its largest)
        occ, clear = _blocks(occ, k, np.logical_or), _blocks(clear, k, np.maximum)
    speed = np.clip((clear - inflation_radius) / max(clearance_band, 1e-9), MIN_SPEED, 1.0)
    speed[clear < gap_clearance] = MIN_SPEED
    patch_origin = origin + np.array([c0, r0]) * resolution
    if route is not None and route_discount > 0.0:
        speed = route_speed(speed, patch_origin, k * resolution, route, route_discount,
                            route_width)
    values = _travel_distance(occ, speed, (g_local[0] // k, g_local[1] // k), k * resolution)
    if values is None:
        return None
    inside = 0 <= (g - origin)[0] < w * resolution and 0 <= (g - origin)[1] < h * resolution
    goal_used = g if inside and not moved \
        else patch_origin + (np.array(g_local[::-1]) + 0.5) * resolution
    field = NavigationField(patch_origin, k * resolution, values, goal_used, passable,
                            resolution)
    if k > 1 and field.reachable(robot) and not np.isfinite(field.value(robot)[0]):
        return compute_field(occupied, origin, resolution, goal, robot, inflation_radius,
                             clearance_band, 1, route, route_discount, route_width,
                             gap_clearance, goal_slack)
    return field


def nearest_free(free: NDArray[np.bool_], cell: tuple[int, int],
                 radius_cells: float) -> tuple[int, int] | None:
    """``cell`` (row, col) if it is free, else the free cell of ``free`` nearest it within
    ``radius_cells`` (cell centres' distance; the first in row order on a tie); None
    when there is none."""
    if free[cell]:
        return cell
    r = int(math.floor(radius_cells))
    if r < 1:
        return None
    h, w = free.shape
    r0, r1 = max(cell[0] - r, 0), min(cell[0] + r + 1, h)
    c0, c1 = max(cell[1] - r, 0), min(cell[1] + r + 1, w)
    rows, cols = np.nonzero(free[r0:r1, c0:c1])
    if rows.size == 0:
        return None
    d2 = (rows + r0 - cell[0]) ** 2 + (cols + c0 - cell[1]) ** 2
    k = int(np.argmin(d2))
    if d2[k] > radius_cells ** 2:
        return None
    return int(rows[k] + r0), int(cols[k] + c0)


def route_speed(speed: NDArray[np.float64], origin: ArrayLike, cell: float, route: ArrayLike,
                discount: float, width: float) -> NDArray[np.float64]:
    """``speed`` (relative, on cells of ``cell`` [m] from ``origin``) divided by
    1 - ``discount`` within ``width`` [m] of the polyline ``route`` (k, 2) [m]: travel
    along the way the robot has taken costs ``discount`` less, so another way takes over
    only when it is that much shorter (hysteresis between near-equal ways). Every speed
    stays positive and finite: the field is still a distance with one minimum, the goal.
    The route is taken as a line (densify: a point at least every cell), whatever its
    points' spacing (a global planner's path, the field's own descent); its parts off
    the patch are left out."""
    h, w = speed.shape
    cells = cell_index(densify(route, cell), origin, cell)
    cells = cells[(cells[:, 0] >= 0) & (cells[:, 0] < h) & (cells[:, 1] >= 0)
                  & (cells[:, 1] < w)]
    if not len(cells) or not 0.0 < discount < 1.0:
        return speed
    on = np.zeros((h, w), bool)
    on[cells[:, 0], cells[:, 1]] = True
    near = ndimage.distance_transform_edt(~on) * cell <= width
    return np.where(near, speed / (1.0 - discount), speed)


def _blocks(a: NDArray, k: int, combine: np.ufunc) -> NDArray:
    """``a`` (both sides multiples of ``k``) reduced over blocks of k x k cells with
    ``combine`` (np.maximum, np.logical_or): one strided slice per place in the block,
    about ten times faster than a reshaped reduction over two axes."""
    return reduce(combine, (a[i::k, j::k] for i in range(k) for j in range(k)))


def _travel_distance(walls: NDArray[np.bool_], speed: NDArray[np.float64],
                     goal: tuple[int, int], cell: float) -> NDArray[np.float64] | None:
    """Fast-marching travel time from the ``goal`` cell at ``speed`` (relative, so metres
    in open space) around ``walls``: inf where cut off; None for a degenerate patch."""
    walls = walls.copy()
    walls[goal] = False
    phi = np.ones(walls.shape)
    phi[goal] = -1.0
    try:
        t = skfmm.travel_time(np.ma.MaskedArray(phi, walls), speed, dx=cell)
    except ValueError:   # no zero contour left after masking
        return None
    values = np.ma.filled(np.ma.masked_invalid(t).astype(float), np.inf)
    values[goal] = 0.0
    return _fill_pits(np.maximum(values, 0.0), speed, goal, cell)


def _neighbours(padded: NDArray[np.float64], pad: int,
                shape: tuple[int, int]) -> NDArray[np.float64]:
    """The 8 neighbours' values (8, h, w) of each cell of a field of ``shape`` (h, w),
    from the field ``padded`` with ``pad`` cells of inf (in NEIGHBOURS' order)."""
    h, w = shape
    return np.stack([padded[pad + dr:pad + dr + h, pad + dc:pad + dc + w]
                     for dr, dc in NEIGHBOURS])


def _fill_pits(values: NDArray[np.float64], speed: NDArray[np.float64],
               goal: tuple[int, int], cell: float) -> NDArray[np.float64]:
    """``values`` (changed in place) with every finite cell but the ``goal`` that has no
    strictly lower 8-neighbour raised to its lowest neighbour's value plus its own step
    (``cell`` over its ``speed``), until no such cell is left: what second-order fast
    marching leaves beside a wall or the border, a few cells in a field, mostly none.
    Values only rise and each raise is above a neighbour's value, so it ends; bounded by
    the number of cells in any case."""
    for _ in range(values.size):
        lowest = _neighbours(np.pad(values, 1, constant_values=np.inf), 1,
                             values.shape).min(axis=0)
        pit = np.isfinite(values) & np.isfinite(lowest) & ~(lowest < values)
        pit[goal] = False
        if not pit.any():
            break
        values[pit] = lowest[pit] + cell / speed[pit]
    return values
