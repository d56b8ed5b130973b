"""The planner's memory: the occupancy grid and the navigation field on it.

Integrates each scan once (at the laser's odom pose when it was taken) and
recomputes the field when the goal changes, when the robot leaves the patch
the field covers, or, when the occupied cells changed, at most every
``field_period`` seconds (the field is the expensive part of a cycle;
core/navigation.py). A scan that only confirms what the map holds changes no
occupied cell and costs no field.

With ``field_worker`` (on by default), a field that only brings the map's changes
in is marched on a worker thread from the cycle's map, while the cycle goes on
with the field it has, and is taken at the next call (waited for if it is not
done yet); a field needed at once (a new goal, a place avoided or opened again,
the robot off the patch, no field yet) is still computed in the cycle. The same
calls give the same fields whatever the timing (the bench, the replay and the
node agree), and a planning tick does not wait for the marching (a node's thread
is idle between ticks; the marching holds the GIL, so it takes no time from
anything but that idle time).
"""

from __future__ import annotations

from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
import math
import time
import weakref

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from .alignment import MIN_WALL_AGE, DistanceField, Match, align, distance_field, localise
from .config import PlannerConfig
from .known_map import KnownMap
from .navigation import NavigationField, compute_field, nearest_free
from .occupancy import ESTABLISHED, NOT_ESTABLISHED, OccupancyGrid
from .robot import compose, to_parent
from .scan import Scan, range_sigma, scans_in
from .tracking import clusters

#: Goals closer than this are the same goal (the field's, the controller's) [m].
SAME_GOAL = 1e-3
#: The alignment's distance field is made anew after this many scans (new walls join
#: it) or when a scan reaches beyond it ...
DISTANCE_FIELD_SCANS = 5
#: ... and covers this much around the scan that made it [m].
DISTANCE_FIELD_MARGIN = 1.0
#: A return may have fallen long by this many standard deviations of its range noise:
#: its beam clears the walls' layer (and, held while new, the planning layer) only up
#: to this before it (NavigationMemory.integrate).
NOISE_BAND = 2.0
#: Returns this far beyond a moving track's disc are the alignment's again [m].
MOVING_MARGIN = 0.3
#: The route a field favours is its descent this far from the robot [m] (beyond the
#: window's 20 m side: to the goal, or out of the window towards it).
ROUTE_LENGTH = 60.0


def _grid_settings(cfg: PlannerConfig) -> tuple[float, float, bool]:
    return (cfg.map_resolution, cfg.map_size, cfg.scan_alignment)


def _grid(cfg: PlannerConfig) -> OccupancyGrid:
    """The occupancy window of ``cfg``, keeping the returns' places only for the scan
    alignment (the only reader: 10 more bytes a cell and work on every scan)."""
    return OccupancyGrid(*_grid_settings(cfg))


@dataclass(frozen=True)
class FieldJob:
    """A navigation field to march between cycles: compute_field's inputs as a cycle
    took them, and what the field is installed as."""

    #: The window's occupied cells and avoided places then (h, w) ...
    blocked: NDArray[np.bool_]
    #: ... and its established cells and avoided places (the field where the occupied
    #: ones leave no way: NavigationMemory._compute).
    sure: NDArray[np.bool_]
    #: The window's corner then (x, y) [m].
    origin: NDArray[np.float64]
    goal: NDArray[np.float64]
    position: NDArray[np.float64]
    #: (goal cell, map version, established cells) the field is for
    #: (NavigationMemory._key).
    key: tuple
    #: When the cycle took the map [s].
    time: float
    #: The way the field favours (compute_field's route), how much cheaper travel along
    #: it is and within what half-width [m] (Route).
    route: Route | None = None


@dataclass(frozen=True)
class Route:
    """A polyline (k, 2) [m] in the memory's frame the field favours: travel within
    ``width`` [m] of it costs ``discount`` less (compute_field's route)."""

    points: NDArray[np.float64]
    discount: float
    width: float


class NavigationMemory:
    """Occupancy grid + navigation field for one robot. Not thread-safe."""

    def __init__(self, cfg: PlannerConfig) -> None:
        self.cfg = cfg
        self.grid = _grid(cfg)
        self.field: NavigationField | None = None
        self._field_key: tuple | None = None    # (goal, grid version) of self.field
        self._field_time = -math.inf
        self._scan_stamp: float | None = None
        self.computations = 0     # fields computed so far
        #: How long the last field took to compute [s] (wall clock, in the cycle or the
        #: worker: a figure for subapf-perf, not for decisions).
        self.compute_seconds = 0.0
        #: Whether the occupied cells left no way when the field was made (_compute).
        self.field_unsure = False
        self._distance: DistanceField | None = None   # the alignment's, and its age
        self._distance_age = 0
        self._hard_free_cache: tuple | None = None   # no_way's free cells, per map state
        #: Places tried and not passed: (x, y, radius [m], until [s]) (see ``avoid``).
        self.avoided: list[tuple[float, float, float, float]] = []
        #: A field to march between cycles (start_marching starts it) ...
        self._due: FieldJob | None = None
        #: ... and once started, the field being marched in the worker, and its job.
        self._pending: tuple[Future, FieldJob] | None = None
        self._worker: ThreadPoolExecutor | None = None
        #: The last field's descent from where the robot was (x, y) (k, 2) [m], and the
        #: goal key it leads to: the next field of that goal favours it (route_discount).
        self.route: NDArray[np.float64] | None = None
        self._route_goal: tuple | None = None
        #: A path given to follow (x, y) (k, 2) in the memory's frame (follow): favoured
        #: by path_discount instead of the route taken.
        self.path: NDArray[np.float64] | None = None
        #: A map the robot already has, the grid's prior (know).
        self.known: KnownMap | None = None

    def reconfigure(self, cfg: PlannerConfig) -> None:
        """A new configuration; a new map size or resolution, or the scan alignment
        switched, starts an empty map."""
        if _grid_settings(cfg) != _grid_settings(self.cfg):
            self.cfg = cfg
            self.forget()
        self.cfg = cfg
        self._field_key = None
        self._drop_pending()

    def know(self, known: KnownMap | None) -> None:
        """Start the grid from ``known`` (core/known_map.py; None: from nothing, as the
        cells leave the window), and keep it through ``forget``."""
        self.known = known
        self.grid.know(known)
        self._field_key, self._distance, self._hard_free_cache = None, None, None
        self._drop_pending()

    def forget(self) -> None:
        """Drop the map and the field (the world may have changed: a restarted
        simulation); a known map is taken again."""
        self.grid = _grid(self.cfg)
        if self.known is not None:
            self.grid.know(self.known)
        self.field, self._field_key, self._field_time = None, None, -math.inf
        self._scan_stamp = None
        self._distance, self._distance_age = None, 0
        self._hard_free_cache = None
        self.avoided = []
        self.route, self._route_goal = None, None
        self._drop_pending()

    def _drop_pending(self) -> None:
        """Forget the field due or being marched (its result, once done, is dropped)."""
        self._due = None
        if self._pending is not None:
            self._pending[0].cancel()
            self._pending = None

    def start_marching(self) -> None:
        """Start marching the field the last call took the map for (if any) on the worker
        thread. For after the cycle's command is out: the marching holds the GIL
        (scikit-fmm does not release it), so started within the cycle it would hold up
        the rest of it. Not called, the next call marches it itself (the same field)."""
        job, self._due = self._due, None
        if job is None:
            return
        if self._worker is None:
            self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix='field')
            weakref.finalize(self, self._worker.shutdown, wait=False)
        self._pending = (self._worker.submit(self._compute, job.blocked, job.sure,
                                             job.origin, job.goal, job.position, job.route),
                         job)

    def settle(self) -> None:
        """Start the field due and wait until it is done; the next call takes it as it
        would have anyway. What a node's idle time between ticks gives the worker, for a
        caller with no idle time (the bench's simulator holds the GIL)."""
        self.start_marching()
        if self._pending is not None:
            self._pending[0].exception()

    def _march_later(self, goal: NDArray, position: NDArray, now: float) -> None:
        """Take the map as it is now for a field to march between cycles
        (start_marching); the next call takes that field."""
        key = self._key(goal)
        self._due = FieldJob(*self._blocked(now), self.grid.origin.copy(), goal, position,
                             key, now, self._route_for(key))

    def _compute(self, blocked: NDArray[np.bool_], sure: NDArray[np.bool_], origin: NDArray,
                 goal: NDArray, position: NDArray, route: Route | None
                 ) -> tuple[NavigationField | None, float, NDArray | None, bool]:
        """The field, how long it took [s], with route_discount its descent from
        ``position`` (the route the next field favours), and whether the ``blocked``
        cells left no way from ``position``. Where they leave none, the field is the one
        over the ``sure`` cells if that has a way: it leads through cells occupied but
        not established (a return or two: a mixed pixel, a noisy far return, something
        seen once at the edge of the laser's reach) to look at them again. A goal is
        given up only for walls the memory is sure of."""
        cfg = self.cfg
        t0 = time.perf_counter()

        def march(cells: NDArray[np.bool_]) -> NavigationField | None:
            return compute_field(cells, origin, self.grid.resolution, goal, position,
                                 inflation_radius=cfg.inflation_radius,
                                 clearance_band=cfg.inflation_band,
                                 coarsening=cfg.field_coarsening,
                                 route=None if route is None else route.points,
                                 route_discount=0.0 if route is None else route.discount,
                                 route_width=0.0 if route is None else route.width,
                                 gap_clearance=cfg.gap_clearance, goal_slack=cfg.goal_slack)
        field, unsure = march(blocked), False
        if field is None or not field.reachable(position):
            other, unsure = march(sure), True
            if other is not None and other.reachable(position):
                field = other
        seconds = time.perf_counter() - t0
        if field is None or cfg.route_discount <= 0.0 or self.path is not None:
            return field, seconds, None, unsure
        return field, seconds, field.path(position, ROUTE_LENGTH), unsure

    def _route_for(self, key: tuple) -> Route | None:
        """The route a field for ``key`` favours: a path given to follow, else the last
        route taken, if it led to that goal."""
        cfg = self.cfg
        if self.path is not None:
            return Route(self.path, cfg.path_discount, cfg.path_width)
        if self.route is None or self._route_goal != key[0]:
            return None
        return Route(self.route, cfg.route_discount, cfg.route_width)

    def follow(self, path: ArrayLike | None) -> None:
        """Favour ``path`` (k, 2) [m] in the memory's frame (None: no path) in the
        fields from now on (path_discount): the next field is computed afresh."""
        if path is None:
            self.path = None
        else:
            self.path = np.array(path, float).reshape(-1, 2)
            self.route, self._route_goal = None, None
        self._field_key = None
        self._drop_pending()

    def _install(self, computed: tuple[NavigationField | None, float, NDArray | None, bool],
                 key: tuple, when: float) -> None:
        self.field, self.compute_seconds, route, self.field_unsure = computed
        self._field_key, self._field_time = key, when
        self.route, self._route_goal = (None, None) if route is None or not len(route) \
            else (route, key[0])
        self.computations += 1

    def _key(self, goal: NDArray) -> tuple:
        """What a field to ``goal`` depends on: the goal, the map's occupied cells, and,
        while there is no field or the occupied cells left no way (_compute), how many are
        established."""
        sure = int(np.count_nonzero(self.grid.log_odds >= ESTABLISHED)) \
            if self.field is None or self.field_unsure else -1
        return (tuple(np.round(goal / SAME_GOAL).astype(int)), self.grid.version, sure)

    def integrate(self, scan: Scan, scan_pose: ArrayLike, goal: ArrayLike | None = None,
                  transient: NDArray[np.bool_] | None = None,
                  unmoved: NDArray[np.bool_] | None = None) -> bool:
        """Add a scan taken with base_footprint at ``scan_pose`` unless the scan with its
        stamp was added already (a NaN stamp is always new); ``transient`` marks the beams
        that returned from something held out of the memory (OccupancyGrid.update), and
        ``unmoved`` those of them held because it is new, not because it moves: their
        beams clear only up to NOISE_BAND standard deviations of their range noise before
        the return (a standing object held while it is new is not cleared from under
        itself by its returns that fell long; a mover's clear up to it, or its trail
        stays). In the walls' layer the alignment matches to, every beam but a mover's
        clears only up to that band (core/occupancy.py: a wall is not drawn behind
        itself)."""
        if self._scan_stamp is not None and scan.stamp == self._scan_stamp:
            return False
        self._scan_stamp = scan.stamp
        self.grid.follow(scan_pose, goal)
        band = NOISE_BAND * range_sigma(np.nan_to_num(scan.ranges, posinf=0.0),
                                        self.cfg.range_noise_floor,
                                        self.cfg.range_noise_fraction)
        short = 0.0 if unmoved is None else np.where(unmoved, band, 0.0)
        wall_short = band
        if transient is not None:   # a mover's beams clear up to it
            moves = transient if unmoved is None else transient & ~unmoved
            wall_short = np.where(moves, 0.0, band)
        self.grid.update(scan, compose(scan_pose, self.cfg.laser_mount), self.cfg.obstacle_range,
                         transient, short, wall_short)
        return True

    def align(self, base: ArrayLike, predicted: ArrayLike,
              moving: tuple[NDArray, NDArray] | None = None, wide: bool = False) -> Match:
        """Match a scan's returns ``base`` (m, 2) in base_footprint [m] (scan_to_points
        at the identity, in beam order) to the map: the pose of base_footprint
        (core/alignment.py) from the ``predicted`` one (x, y, yaw) in the map's frame.
        ``moving``: discs (centres (k, 2), radii (k,) [m]) whose returns, and
        MOVING_MARGIN around them, take no part. ``wide``: in the wider basin of a
        localiser's error (alignment.localise). The distance field is reused for
        DISTANCE_FIELD_SCANS scans while it covers the scan."""
        base = np.asarray(base, float).reshape(-1, 2)
        pred = np.asarray(predicted, float)
        here = to_parent(pred, base)
        if moving is not None and len(moving[0]) and len(base):
            centres, radii = moving
            d = np.hypot(*(here[:, None, :] - centres[None]).transpose(2, 0, 1))
            still = np.all(d > radii[None] + MOVING_MARGIN, axis=1)
            base, here = base[still], here[still]
        pieces = clusters(base, self.cfg.cluster_gap)[0]
        if len(base) == 0:
            return align(base, pred, None)
        f = self._distance
        reach = np.array([0.0, 0.0]) if f is None else f.origin + np.array(
            f.shape[::-1]) * f.resolution
        stale = f is None or self._distance_age >= DISTANCE_FIELD_SCANS or np.any(
            here.min(axis=0) < f.origin) or np.any(here.max(axis=0) > reach)
        if stale:
            g = self.grid
            # the walls' layer; their ages are the planning layer's (a cell established in
            # the walls' layer alone is young: person-sized pieces do not match it; ages
            # of the walls' layer's own lost real-building tasks, docs/alignment.md)
            walls = g.log_odds if g.wall_odds is None else g.wall_odds
            self._distance = distance_field(walls, g.origin, g.resolution, here,
                                            DISTANCE_FIELD_MARGIN, g.hit_offset,
                                            g.established_at, g.scans,
                                            scans_in(MIN_WALL_AGE, self.cfg.period),
                                            g.hit_count)
            self._distance_age = 0
        self._distance_age += 1
        return (localise if wide else align)(
            base, pred, self._distance, pieces, self.cfg.max_mover_size,
            (self.cfg.range_noise_floor, self.cfg.range_noise_fraction),
            self.cfg.laser_mount[:2])

    def avoid(self, point: ArrayLike, radius: float, until: float) -> None:
        """Block the cells within ``radius`` [m] of ``point`` in the navigation field
        until time ``until`` [s] (a place the robot could not pass: the field then leads
        along the next way; the map itself is not changed, so once the time is up the
        place is open again)."""
        self.avoided.append((float(point[0]), float(point[1]), float(radius), float(until)))
        self._field_key = None
        self._drop_pending()

    def _blocked(self, now: float | None) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
        """The occupied cells, and the established ones, each with the avoided places
        still in force at ``now`` (_compute)."""
        return (self._avoided_in(self.grid.occupied(), now),
                self._avoided_in(self.grid.log_odds >= ESTABLISHED, None))

    def _avoided_in(self, occ: NDArray[np.bool_], now: float | None) -> NDArray[np.bool_]:
        """``occ`` with the avoided places still in force at ``now`` blocked (None: as
        they are)."""
        if now is not None:
            self.avoided = [a for a in self.avoided if now < a[3]]
        if not self.avoided:
            return occ
        res, origin = self.grid.resolution, self.grid.origin
        for x, y, r, _ in self.avoided:
            c0, r0 = (int(v) for v in np.floor((np.array([x, y]) - r - origin) / res))
            c1, r1 = (int(v) + 1 for v in np.floor((np.array([x, y]) + r - origin) / res))
            c0, r0 = max(c0, 0), max(r0, 0)
            c1, r1 = min(c1, occ.shape[1]), min(r1, occ.shape[0])
            if c0 >= c1 or r0 >= r1:
                continue
            cy = origin[1] + (np.arange(r0, r1) + 0.5) * res
            cx = origin[0] + (np.arange(c0, c1) + 0.5) * res
            occ[r0:r1, c0:c1] |= (cx[None] - x) ** 2 + (cy[:, None] - y) ** 2 <= r * r
        return occ

    def no_way(self, position: ArrayLike, goal: ArrayLike) -> str:
        """Why the memory holds no way from ``position`` to ``goal`` (x, y) [m] (a query,
        for goal_unreachable), at the field's hard inflation (``inflation_radius``; the
        goal moved by up to ``goal_slack``): the goal within it of a wall, every way
        closed by the walls themselves, or only by places tried (``avoid``). A goal
        beyond the window is taken at its edge (said so)."""
        g = self.grid
        free, labels = self._hard_free()
        cells = g.cell_of(np.array([position, goal], float).reshape(2, 2))
        beyond = '' if g.inside(cells[1:])[0] else ' (the goal beyond the window, taken ' \
            'at its edge)'
        robot, target = np.clip(cells, 0, np.array(free.shape) - 1)
        target = nearest_free(free, tuple(target), self.cfg.goal_slack / g.resolution)
        if target is None:
            return (f'the goal is within inflation_radius of a wall in the memory, with no '
                    f'free cell within goal_slack{beyond}')
        near = np.zeros_like(free)
        r0, c0 = np.maximum(robot - 3, 0)
        near[r0:robot[0] + 4, c0:robot[1] + 4] = True   # (field.reachable's 3 cells)
        if not np.isin(labels[free & near], labels[tuple(target)]).any():
            return f'the walls in the memory close every way{beyond}'
        if self.avoided:
            return f'every way through the walls tried{beyond}'
        return f"no way at the field's resolution{beyond}"

    def _hard_free(self) -> tuple[NDArray[np.bool_], NDArray[np.int32]]:
        """The cells at least ``inflation_radius`` from every established cell (the walls
        that close a goal: _compute) and their 8-connected labels, made once for each
        state of the map (no_way is asked every cycle the goal is unreachable)."""
        g = self.grid
        sure = g.log_odds >= ESTABLISHED
        key = (g.version, int(np.count_nonzero(sure)), *g.origin, self.cfg.inflation_radius)
        if self._hard_free_cache is None or self._hard_free_cache[0] != key:
            occ = sure
            clear = ndimage.distance_transform_edt(~occ) * g.resolution if occ.any() \
                else np.full(occ.shape, np.inf)
            free = clear >= self.cfg.inflation_radius
            labels, _ = ndimage.label(free, structure=np.ones((3, 3)))
            self._hard_free_cache = (key, free, labels)
        return self._hard_free_cache[1], self._hard_free_cache[2]

    def clear(self, points: ArrayLike) -> None:
        """Cells under ``points`` (n, 2) [m] that are occupied become unknown: something
        that moved stood there (core/tracking.py's trail)."""
        cells = self.grid.cell_of(np.asarray(points, float).reshape(-1, 2))
        self.grid.clear(cells[self.grid.inside(cells)])

    def log_odds_at(self, points: ArrayLike) -> NDArray[np.float32]:
        """The map's log odds at each point (n, 2) [m] (0, unknown, off the window)."""
        cells = self.grid.cell_of(np.asarray(points, float).reshape(-1, 2))
        inside = self.grid.inside(cells)
        out = np.zeros(len(cells), np.float32)
        out[inside] = self.grid.log_odds[cells[inside, 0], cells[inside, 1]]
        return out

    def standing(self, points: ArrayLike, origin: ArrayLike, reach: ArrayLike,
                 scans: int) -> NDArray[np.bool_]:
        """Per laser return (n, 2) [m], taken from ``origin`` (x, y): whether a cell within
        ``reach`` (n,) [m] of it along its ray (the range's noise) has been an established
        obstacle for ``scans`` scans or more (OccupancyGrid.established_at; without it, as
        without the scan alignment, established at all). A return that noise put in front
        of a wall, on cells its own rays saw free, or behind it, on cells never seen, is
        still on the wall; a walker's returns are not on what has stood that long."""
        points = np.asarray(points, float).reshape(-1, 2)
        out = np.zeros(len(points), bool)
        if not len(points):
            return out
        g = self.grid
        ray = points - np.asarray(origin, float)[:2]
        unit = ray / np.maximum(np.hypot(*ray.T), 1e-9)[:, None]
        reach = np.broadcast_to(np.asarray(reach, float), (len(points),))
        for k in (-1.0, -0.5, 0.0, 0.5, 1.0):
            cells = g.cell_of(points + (k * reach)[:, None] * unit)
            inside = g.inside(cells)
            r, c = cells[inside, 0], cells[inside, 1]
            if g.established_at is None:
                old = g.log_odds[r, c] >= ESTABLISHED
            else:
                since = g.established_at[r, c].astype(np.int64)
                old = (since != NOT_ESTABLISHED) & (g.scans - since >= scans)
            out[np.flatnonzero(inside)[old]] = True
        return out

    def _covers(self, position: np.ndarray) -> bool:
        f = self.field
        if f is None:
            return False
        h, w = f.values.shape
        rel = (position - f.origin) / f.resolution
        return bool(0 <= rel[0] < w and 0 <= rel[1] < h)

    def field_for(self, position: ArrayLike, goal: ArrayLike,
                  now: float) -> tuple[NavigationField | None, bool]:
        """The field to ``goal`` (None: the goal is blocked in the map) at time ``now``
        [s], recomputed per the module docstring, and whether this call installed a new
        one. ``now`` -inf: no field_period (a new field whenever the occupied cells
        changed, computed in the call)."""
        p = np.asarray(position, float)[:2]
        g = np.asarray(goal, float)[:2]
        timed = math.isfinite(now)
        installed = self.computations
        self.start_marching()   # (if nobody did since the last call)
        if self._pending is not None:   # the field marched since the last call
            (marching, job), self._pending = self._pending, None
            self._install(marching.result(), job.key, job.time)
        if timed and any(now >= a[3] for a in self.avoided):
            self._field_key = None   # an avoided place opens again
        key = self._key(g)
        same_goal = self._field_key is not None and self._field_key[0] == key[0]
        fresh = same_goal and (key[1:] == self._field_key[1:] or (
            timed and now - self._field_time < self.cfg.field_period))
        covered = self.field is None or self._covers(p)
        if fresh and covered:
            return self.field, self.computations != installed
        if self.cfg.field_worker and same_goal and covered and self.field is not None \
                and timed:
            self._march_later(g, p, now)   # only the map's changes: the next call has it
            return self.field, self.computations != installed
        self._install(self._compute(*self._blocked(now if timed else None), self.grid.origin,
                                    g, p, self._route_for(key)), key,
                      now if timed else -math.inf)
        return self.field, True
