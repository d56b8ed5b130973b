"""Moving obstacles tracked from the scans: clusters, association, constant-velocity
Kalman filters; which points move.

Each scan's obstacle points (odom, in beam order) are cut into clusters where
two neighbours are ``cluster_gap`` or more apart (laser scan segmentation); a
cluster longer than ``max_mover_size`` (NEW_SIZE_FACTOR times that when it stands on
cells the memory saw free), straight (a piece of wall seen at a grazing angle; one that
surely bends like a person is not, however shallow its arc), or
standing mostly on the memory's established obstacles, is a wall and is never
tracked. The others are
associated with the tracks predicted to this scan's time (Hungarian assignment,
scipy, within ``track_gate`` and the prediction's uncertainty: GATE_CHI2) and update
their filter; unmatched clusters start
tentative tracks, and a track unseen for MAX_MISSES scans is dropped, but for one that
moves and is, in part at least, where the lidar cannot see (behind a 270-degree laser,
within its ``range_min``): it is carried on by its filter for up to COAST_TIME, as
someone who walks behind the robot is still there.

The filter (per track, vectorised over all tracks) is the constant-velocity
model: state (x, y, vx, vy) [m, m/s], white-acceleration process noise of
density ACCEL_NOISE [m^2/s^3], the cluster's centroid measured with
MEASUREMENT_SIGMA [m]. A hand-written filter of 4 states costs a few array
operations for every track at once; filterpy's per-object KalmanFilter costs a
Python object per track per step for the same equations.

A track **moves** when it has been seen MIN_HITS times, its estimated speed is
at least ``moving_speed``, it has been MOVE_DISTANCE from where it was first seen
at some time (NEW_MOVE_DISTANCE if it was new then: standing on cells the memory
had seen free; someone walking to and fro stays a mover), and it has left that
place. How far it went is measured at the scans it is seen (not from predictions);
it has left the place when fewer than STILL_FRACTION of the points it was first seen
at have a return of another cluster within VACATED_RADIUS (or two standard
deviations of the return's range noise), not counting the returns of tracks that
moved at the last scan and have gone twice MOVE_DISTANCE (someone walking behind
another steps where the first was first seen): a piece of a long wall that noise and
dropped beams cut out of it, sliding along it as the robot drives, is still where it
began, the rest of the wall returning there. It is
**held** out of the occupancy memory while it moves, and while its cluster is new
and stands mostly on cells the memory has seen free (something new where there
was nothing: held NEW_OBJECT_SCANS scans, then written if it did not move).
Held points are still obstacles for the local layer; a person walking by leaves
no trail of "wall".

What the tracker waits for is counted in scans, the evidence it has, at any rate;
what the memory waits for (STANDING_TIME, alignment.MIN_WALL_AGE) is a time. Counted
in seconds at the Jackal's 20 Hz (four times the burger's scans), the tracker kept
unseen tracks and held new objects so long that posts of the BARN worlds, hidden
behind each other and seen again, seemed to move (docs/robots.md).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from .occupancy import ESTABLISHED

#: Process noise density of the constant-velocity model [m^2/s^3].
ACCEL_NOISE = 0.5
#: Standard deviation of a centroid measurement [m].
MEASUREMENT_SIGMA = 0.05
#: Initial standard deviation of a new track's velocity [m/s]: a walker at up to 1.5 m/s
#: is in the gate of the track it started at the next scan.
INITIAL_SPEED_SIGMA = 1.0
#: A cluster is associated with a track only within this squared Mahalanobis distance of
#: the track's prediction (its position's covariance plus MEASUREMENT_SIGMA; chi-square,
#: 2 degrees of freedom, 95 %), as well as within ``track_gate``. A track that has stood
#: still for a few scans is sure of where it is and that it does not move: the centroid
#: of another piece of clutter 0.3 m away is not its next measurement, where a distance
#: gate alone let a track hop from piece to piece, gather the hops as speed and move
#: (static clutter through a realistic lidar). A new track's uncertain velocity still
#: lets it follow a walker.
GATE_CHI2 = 5.99
#: Scans a track may go unseen before it is dropped ...
MAX_MISSES = 3
#: ... but a moving track where the lidar cannot see is kept this long unseen [s]
#: (predicted at its last velocity: a walker at 1.7 m/s behind the Jackal, whose laser
#: sees nothing in the quarter behind it, was dropped 0.15 s after it left the field of
#: view and ran into the robot from behind a second later: `crossing_000`).
COAST_TIME = 2.0
#: Where an unseen track is looked for: its predicted centre and four places round it
#: (times its radius grown by its uncertainty); hidden if any of them is.
PROBES = np.array([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
#: Scans before a track's speed says whether it moves.
MIN_HITS = 3
#: A new object in seen-free space is held out of the memory this many scans.
NEW_OBJECT_SCANS = 15
#: A track moves only once it is this far from where it was first seen [m]: the centroid
#: of a static object's visible side wanders less as the robot drives past it.
MOVE_DISTANCE = 0.3
#: ... or this far, if it was new when first seen (standing on cells the memory had
#: seen free: something came where there was nothing). At MOVE_DISTANCE alone, a walker
#: at the robot's top speed was known to move 1.4 s after it was first seen (0.8 s with
#: this), too late to get out of its way; at this distance for every track, static
#: clutter seemed to move and the gaps between it closed (docs/moving_obstacles.md).
NEW_MOVE_DISTANCE = 0.15
#: Points of a cluster kept from when its track was first seen ...
FIRST_POINTS = 12
#: ... and a track moves only once fewer than STILL_FRACTION of them have a return of
#: another cluster within VACATED_RADIUS [m] (or two standard deviations of that return's
#: range noise): something that moves leaves the place it was first seen at, a piece of
#: wall whose centroid only seems to move does not (tracking._still_there).
STILL_FRACTION = 0.5
VACATED_RADIUS = 0.1
#: A cluster whose points lie this close to a line [m] (the smaller principal standard
#: deviation), and that is longer than THIN_LENGTH [m], is a piece of wall: a wall seen
#: at a grazing angle breaks into short straight pieces whose centroids slide along
#: it as the robot drives, while a person or a post shows a curved side ...
THIN_STD = 0.02
THIN_LENGTH = 0.25
#: ... unless its points bend at least this much [1/m] (the curvature of the parabola
#: fitted to them across their main axis; 2.5: a disc of radius 0.4 m): a person 0.2 m
#: from the lidar shows a wide, shallow arc with most beams on its middle (0.017 m off
#: a line over 0.3 m, a curvature of 4.6 for a disc of radius 0.25 m in
#: `fast_crossing_003`, taken for a wall and lost as it closed on the robot), while a
#: straight piece 0.27 m long, its points 0.02 m off the line, bends less than 2.7 in
#: 999 of 1000 draws.
THIN_CURVATURE = 2.5
#: ... and that bend is this many of its standard errors (the fit's residuals): a few
#: returns of a straight piece through a noisy lidar may bend as much by chance.
BEND_SIGNIFICANCE = 4.0
#: Fewer laser points than this are no cluster to track (a wall seen edge-on breaks into
#: single points; a person 3.5 m away still shows eight).
MIN_POINTS = 3
#: Clusters considered per scan at most (the largest first; a bound on the cycle).
MAX_CLUSTERS = 40
#: Scans whose held points are cleared from the memory (a mover found late: up to
#: MOVE_DISTANCE at 0.15 m/s).
TRAIL_SCANS = 12
#: Log odds below which a cell counts as seen free (two misses).
FREE_LOG_ODDS = -0.5
#: Fraction of a cluster's points on seen-free cells that makes it new.
NEW_FRACTION = 0.5
#: A cluster up to this many times max_mover_size is still tracked when it is new
#: (NEW_FRACTION of it on seen-free cells): a wall does not stand where the memory saw
#: free space, people walking together do.
NEW_SIZE_FACTOR = 2.0
#: Log odds from which a cell is an established obstacle (three hits or more) ...
WALL_LOG_ODDS = ESTABLISHED
#: ... and the fraction of a cluster's points on such cells that makes it part of the
#: map: a piece of wall whose visible part changes as the robot drives, not a mover.
WALL_FRACTION = 0.5


#: A cluster with this fraction of its points on obstacles that have stood STANDING_TIME
#: [s] or more (NavigationMemory.standing) stands where
#: something has stood for a while: it is not moving, whatever its centroid does. A walker
#: leaves such cells within a few scans; a person who stood there and walks off, too.
HELD_UP_FRACTION = 0.5
STANDING_TIME = 2.0


@dataclass(frozen=True)
class Tracks:
    """The tracks after a scan: position (n, 2) [m] and velocity (n, 2) [m/s] in odom,
    radius (n,) [m] (half its cluster's extent), whether each moves (n,; by its
    speed), whether it is held out of the memory (n,; it moves, or it is new in seen-free
    space), and per scan point the index of its track or -1."""

    position: NDArray[np.float64]
    velocity: NDArray[np.float64]
    radius: NDArray[np.float64]
    moving: NDArray[np.bool_]
    held: NDArray[np.bool_]
    point_track: NDArray[np.int64]
    #: Where the held tracks' points were in the scans before this one (k, 2) [m]: cells
    #: the memory may have taken for walls before the track was known to move.
    trail: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2)))

    def _of_points(self, flags: NDArray[np.bool_]) -> NDArray[np.bool_]:
        return _of_points(self.point_track, flags)

    @property
    def held_points(self) -> NDArray[np.bool_]:
        """Per scan point: it belongs to a track held out of the memory."""
        return self._of_points(self.held)

    @property
    def moving_points(self) -> NDArray[np.bool_]:
        """Per scan point: it belongs to a moving track."""
        return self._of_points(self.moving)

    @property
    def unmoved_points(self) -> NDArray[np.bool_]:
        """Per scan point: it belongs to a track held out of the memory because it is
        new, not because it moves."""
        return self._of_points(self.held & ~self.moving)

    def ahead(self, dt: float) -> Tracks:
        """The tracks ``dt`` [s] later: each where its velocity takes it (a scan is some
        tenths of a second old when it is planned with: the sweep, the driver's latency,
        the wait for the tick)."""
        if dt <= 0.0 or not len(self.position):
            return self
        return Tracks(self.position + dt * self.velocity, self.velocity, self.radius,
                      self.moving, self.held, self.point_track, self.trail)

    def predicted(self, t: float) -> NDArray[np.float64]:
        """Positions of the moving tracks ``t`` seconds ahead (k, 2) [m]."""
        return self.position[self.moving] + t * self.velocity[self.moving]


NO_TRACKS = Tracks(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros(0, bool),
                   np.zeros(0, bool), np.zeros(0, np.int64))


def clusters(points: NDArray[np.float64], gap: float) -> tuple[NDArray[np.int64], int]:
    """Label of each point (n,) and the number of clusters of a scan's points in beam
    order: a new cluster starts where a point is ``gap`` [m] or more from the one
    before it (the segmentation of a laser scan); the last cluster joins the first when
    the sweep closes on it."""
    n = len(points)
    if n == 0:
        return np.zeros(0, np.int64), 0
    step = np.hypot(*np.diff(points, axis=0).T)
    labels = np.concatenate([[0], np.cumsum(step >= gap)]).astype(np.int64)
    count = int(labels[-1]) + 1
    if count > 1 and np.hypot(*(points[0] - points[-1])) < gap:
        labels[labels == count - 1] = 0
        count -= 1
    return labels, count


def extents(points: NDArray[np.float64], labels: NDArray[np.int64],
            count: int) -> NDArray[np.float64]:
    """The extent (bounding-box diagonal [m]) of each of ``count`` clusters (count,) of
    ``points`` (n, 2) by their ``labels`` (n,); inf for a label no point has. A
    scan's clusters are runs of points in beam order (:func:`clusters`: the last run
    may carry the first's label): reduced per run, then per label over the runs."""
    lo = np.full((count, 2), np.inf)
    hi = np.full((count, 2), -np.inf)
    if len(labels):
        starts = np.flatnonzero(np.concatenate(([True], labels[1:] != labels[:-1])))
        run = labels[starts]
        np.minimum.at(lo, run, np.minimum.reduceat(points, starts, axis=0))
        np.maximum.at(hi, run, np.maximum.reduceat(points, starts, axis=0))
    return np.hypot(*(hi - lo).T)


class Tracker:
    """Tracks of one robot. Not thread-safe."""

    #: Per-track arrays, one row per track, appended and filtered together.
    PER_TRACK = ('x', 'P', 'hits', 'misses', 'new_age', 'radius', 'ids', 'first',
                 'first_points', 'went', 'moved', 'seen_at')

    def __init__(self, gap: float, max_size: float, gate: float, moving_speed: float) -> None:
        self.gap, self.max_size, self.gate, self.moving_speed = gap, max_size, gate, moving_speed
        self.reset()

    def reset(self) -> None:
        """No tracks, no history, no time."""
        self.x = np.zeros((0, 4))        # state (x, y, vx, vy) [m, m/s]
        self.P = np.zeros((0, 4, 4))     # its covariance
        self.hits = np.zeros(0, np.int64)
        self.misses = np.zeros(0, np.int64)
        self.new_age = np.zeros(0, np.int64)   # scans since first seen as new, or -1
        self.radius = np.zeros(0)
        self.ids = np.zeros(0, np.int64)
        self.first = np.zeros((0, 2))   # where each track was first seen [m]
        # (n, FIRST_POINTS, 2) [m]: its cluster's points then (NaN: none)
        self.first_points = np.zeros((0, FIRST_POINTS, 2))
        self.went = np.zeros(0)          # the farthest it has been from there [m]
        self.moved = np.zeros(0, bool)   # whether it moved at the last scan it was seen
        self.seen_at = np.zeros(0)       # when it was last seen [s]
        self._next_id = 0
        #: (track ids, points) of the last TRAIL_SCANS scans
        self._history: list[tuple[NDArray[np.int64], NDArray[np.float64]]] = []
        self.time: float | None = None
        self._last: Tracks | None = None

    @property
    def last(self) -> Tracks | None:
        """The tracks of the last scan taken (None before the first)."""
        return self._last

    def _append(self, **rows: NDArray) -> None:
        """New tracks: the rows of every PER_TRACK array."""
        for name in self.PER_TRACK:
            setattr(self, name, np.concatenate([getattr(self, name), rows[name]]))

    def _keep(self, mask: NDArray[np.bool_]) -> None:
        """Only the tracks of ``mask``, in every PER_TRACK array."""
        for name in self.PER_TRACK:
            setattr(self, name, getattr(self, name)[mask])

    def _predict(self, dt: float) -> None:
        f = np.eye(4)
        f[0, 2] = f[1, 3] = dt
        q = ACCEL_NOISE
        noise = q * np.array([[dt ** 3 / 3, 0, dt ** 2 / 2, 0], [0, dt ** 3 / 3, 0, dt ** 2 / 2],
                              [dt ** 2 / 2, 0, dt, 0], [0, dt ** 2 / 2, 0, dt]])
        self.x = self.x @ f.T
        self.P = f @ self.P @ f.T + noise

    def _correct(self, rows: NDArray[np.int64], z: NDArray[np.float64],
                 lag: NDArray[np.float64]) -> None:
        """Kalman update of tracks ``rows`` by centroids ``z`` (k, 2) [m] measured
        ``lag`` (k,) [s] after the tracks' time (the sweep took them then): the
        measurement is the position plus lag times the velocity."""
        cov = self.P[rows]
        h = np.zeros((len(rows), 2, 4))
        h[:, 0, 0] = h[:, 1, 1] = 1.0
        h[:, 0, 2] = h[:, 1, 3] = lag
        ph = cov @ h.transpose(0, 2, 1)
        s = h @ ph + MEASUREMENT_SIGMA ** 2 * np.eye(2)
        gain = ph @ np.linalg.inv(s)
        innovation = z - np.einsum('nij,nj->ni', h, self.x[rows])
        self.x[rows] += np.einsum('nij,nj->ni', gain, innovation)
        self.P[rows] = cov - gain @ h @ cov

    def update(self, points: NDArray[np.float64], t: float,
               log_odds_at: NDArray[np.float64],
               standing: NDArray[np.bool_] | None = None,
               after: NDArray[np.float64] | None = None,
               sigma: NDArray[np.float64] | None = None,
               hidden: Callable[[NDArray[np.float64]], NDArray[np.bool_]] | None = None
               ) -> Tracks:
        """Take a scan's obstacle points (n, 2) at time ``t`` [s] with the memory's log
        odds at each (n,; 0 off the map), whether each is on an obstacle that has stood
        STANDING_TIME (n,; none when not given) and how long after ``t`` each was
        taken (n, [s]; a spinning lidar's beam i is i * time_increment after the first:
        a walker seen late in the sweep is measured where it was then; none: all at
        ``t``) and each one's range noise (n, [m]; none: VACATED_RADIUS alone), before
        the scan is written, and which places (k, 2) this scan cannot see (None: it
        sees all round); returns the tracks, at time ``t``.
        A scan at the same time as the last is not taken again (the tracks stand)."""
        if self.time is not None and t == self.time and self._last is not None:
            return self._last   # the same scan again (a tick without a new one)
        dt = 0.0 if self.time is None else t - self.time
        if not dt >= 0.0:
            self.reset()   # time went back (a restarted simulation)
            dt = 0.0
        self.time = t
        if dt > 0.0 and len(self.x):
            self._predict(dt)
        labels, count = clusters(points, self.gap)
        cents, sizes, new, mapped, thin = _cluster_features(points, labels, count, log_odds_at)
        members = np.bincount(labels, minlength=count)
        lag = np.zeros(count) if after is None or not count else \
            np.bincount(labels, after, count) / members
        held_up = np.zeros(count, bool) if standing is None or not count else \
            np.bincount(labels, standing, count) / members >= HELD_UP_FRACTION
        # walls are not tracked: long clusters (but up to NEW_SIZE_FACTOR times as long
        # where the memory saw free space: people side by side, or one close enough to
        # show their whole width), straight ones, those on the map's established obstacles
        fits = (sizes <= self.max_size) | ((new >= NEW_FRACTION)
                                           & (sizes <= NEW_SIZE_FACTOR * self.max_size))
        small = np.flatnonzero(fits & (mapped < WALL_FRACTION) & ~thin)
        small = small[np.argsort(-sizes[small], kind='stable')][:MAX_CLUSTERS]
        track_of = np.full(count, -1, np.int64)
        n_tracks = len(self.x)
        if n_tracks and small.size:
            # each track where it was when the sweep saw each cluster
            at = self.x[:, None, :2] + lag[None, small, None] * self.x[:, None, 2:]
            diff = cents[None, small] - at
            cost = np.hypot(*diff.transpose(2, 0, 1))
            s_inv = np.linalg.inv(self.P[:, :2, :2] + MEASUREMENT_SIGMA ** 2 * np.eye(2))
            near = (cost <= self.gate) \
                & (np.einsum('tki,tij,tkj->tk', diff, s_inv, diff) <= GATE_CHI2)
            rows, cols = linear_sum_assignment(np.where(near, cost, 1e6))
            ok = near[rows, cols]
            rows, cols = rows[ok], cols[ok]
            self._correct(rows, cents[small[cols]], lag[small[cols]])
            track_of[small[cols]] = rows
        seen = np.zeros(n_tracks, bool)
        seen[track_of[track_of >= 0]] = True
        self.hits[seen] += 1
        self.misses[seen] = 0
        self.seen_at[seen] = t
        self.misses[~seen] += 1
        self.new_age[seen & (self.new_age >= 0)] += 1
        fresh = [k for k in small if track_of[k] < 0]
        if fresh:
            m = len(fresh)
            track_of[fresh] = n_tracks + np.arange(m)
            p0 = np.diag([MEASUREMENT_SIGMA ** 2] * 2 + [INITIAL_SPEED_SIGMA ** 2] * 2)
            self._append(x=np.column_stack((cents[fresh], np.zeros((m, 2)))),
                         P=np.repeat(p0[None], m, axis=0), hits=np.ones(m, np.int64),
                         misses=np.zeros(m, np.int64),
                         new_age=np.where(new[fresh] >= NEW_FRACTION, 0, -1).astype(np.int64),
                         radius=np.zeros(m), ids=self._next_id + np.arange(m),
                         first=cents[fresh], first_points=_some_points(points, labels, fresh),
                         went=np.zeros(m), seen_at=np.full(m, t),
                         moved=np.zeros(m, bool))
            self._next_id += m
        keep = self.misses <= MAX_MISSES
        coast = ~keep & self.moved & (t - self.seen_at <= COAST_TIME)
        if hidden is not None and np.any(coast):
            # hidden in part: its disc, grown by two standard deviations of where it is
            reach = self.radius[coast] + 2.0 * np.sqrt(self.P[coast, 0, 0] + self.P[coast, 1, 1])
            probes = self.x[coast, None, :2] + reach[:, None, None] * PROBES[None]
            coast[coast] = hidden(probes.reshape(-1, 2)).reshape(len(reach), -1).any(axis=1)
            keep |= coast
        remap = np.cumsum(keep) - 1
        self._keep(keep)
        if remap.size:
            track_of = np.where(track_of >= 0, remap[np.maximum(track_of, 0)], -1)
        visible = track_of >= 0
        self.radius[track_of[visible]] = 0.5 * sizes[visible]
        speed = np.hypot(self.x[:, 2], self.x[:, 3])
        # how far it went from where it was first seen: measured when seen (a lost scan's
        # prediction is not a motion seen)
        rows = track_of[visible]
        self.went[rows] = np.maximum(self.went[rows],
                                     np.hypot(*(self.x[rows, :2] - self.first[rows]).T))
        went = np.where(self.new_age >= 0, NEW_MOVE_DISTANCE, MOVE_DISTANCE)
        # where the memory has obstacles under (most of) its points, it stands on what
        # the robot has seen stand there: it does not move, whatever its centroid does
        # (the visible side of clutter changes as the robot drives; noise, dropped beams
        # and mixed pixels at its edges move its centroid); one that moved keeps moving
        # until it stands on such cells (a walker passing close to a wall)
        free = np.zeros(len(self.x), bool)
        free[track_of[visible]] = ~held_up[visible]
        unseen = np.ones(len(self.x), bool)
        unseen[track_of[visible]] = False
        free |= unseen & self.moved
        moving = (self.hits >= MIN_HITS) & (speed >= self.moving_speed) \
            & (self.went >= went) & free
        point_track = track_of[labels] if count else np.zeros(0, np.int64)
        # and it has left where it was first seen: returns there of its own or of another
        # that moved at the last scan, twice MOVE_DISTANCE from where it was first seen,
        # do not hold it (one walking behind another steps where the first was first
        # seen; two pieces of clutter that seem to move have not gone that far)
        mover_point = _of_points(point_track, self.moved & (self.went >= 2.0 * MOVE_DISTANCE))
        for k in np.flatnonzero(moving):
            other = (point_track != k) & ~mover_point
            moving[k] = not _still_there(self.first_points[k], points[other],
                                         None if sigma is None else sigma[other])
        self.moved = moving.copy()
        held = moving | ((self.new_age >= 0) & (self.new_age < NEW_OBJECT_SCANS))
        # held[id] by track id; the last slot (id -1: a point of no track) stays False
        held_by_id = np.zeros(self._next_id + 1, bool)
        held_by_id[self.ids[held]] = True
        trail = [pts[held_by_id[ids]] for ids, pts in self._history] if np.any(held) else []
        self._history = (self._history + [(np.where(point_track >= 0, self.ids[
            np.maximum(point_track, 0)] if len(self.ids) else -1, -1), points)])[-TRAIL_SCANS:]
        self._last = Tracks(self.x[:, :2].copy(), self.x[:, 2:].copy(), self.radius.copy(),
                            moving, held, point_track,
                            np.vstack(trail) if trail else np.zeros((0, 2)))
        return self._last


def _of_points(point_track: NDArray[np.int64], flags: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Per point: whether the track it belongs to (``point_track``, -1: none) is flagged
    in ``flags`` (one per track)."""
    if not flags.size:
        return np.zeros(point_track.shape, bool)
    return (point_track >= 0) & flags[np.maximum(point_track, 0)]


def _some_points(points: NDArray[np.float64], labels: NDArray[np.int64],
                 which: list[int]) -> NDArray[np.float64]:
    """Up to FIRST_POINTS points (k, FIRST_POINTS, 2) [m] of each cluster in ``which``,
    spread over it in beam order; NaN where a cluster has fewer."""
    out = np.full((len(which), FIRST_POINTS, 2), np.nan)
    for row, k in enumerate(which):
        mine = points[labels == k]
        pick = np.unique(np.linspace(0, len(mine) - 1, FIRST_POINTS).round().astype(int))
        out[row, :len(pick)] = mine[pick]
    return out


def _still_there(first: NDArray[np.float64], others: NDArray[np.float64],
                 sigma: NDArray[np.float64] | None) -> bool:
    """Whether at least STILL_FRACTION of the points a track was first seen at
    (``first``, (m, 2) [m], NaN: none) have a return of this scan not its own
    (``others``, (n, 2)) within VACATED_RADIUS, or two standard deviations of that
    return's range noise ``sigma`` (n,) if more: the place is not vacated. A wall cut
    into a piece that slides along it as the robot drives (noise and dropped beams
    breaking it up) is still where its track began, the rest of the wall returning
    there; someone who walked off has left it (or hides it: behind them, it counts
    as left), their own returns aside: a walker crossing the robot's way slides along
    its own outline."""
    first = first[np.isfinite(first[:, 0])]
    if not len(others) or not len(first):
        return False
    reach = VACATED_RADIUS if sigma is None else np.maximum(VACATED_RADIUS, 2.0 * sigma)
    near = np.hypot(*(first[:, None, :] - others[None, :, :]).transpose(2, 0, 1)) <= reach
    return bool(np.count_nonzero(near.any(axis=1)) >= STILL_FRACTION * len(first))


def _cluster_features(points: NDArray[np.float64], labels: NDArray[np.int64], count: int,
                      log_odds_at: NDArray[np.float64]) -> tuple[NDArray, ...]:
    """Per cluster: centroid (k, 2), extent (bounding-box diagonal, k) [m], fraction of
    its points on seen-free cells and on established obstacles (k,), and whether it is a
    straight piece or too few points to track (k,; THIN_*, BEND_SIGNIFICANCE, MIN_POINTS)."""
    n = np.bincount(labels, minlength=count).astype(float)
    cents = np.column_stack([np.bincount(labels, points[:, i], count) for i in (0, 1)]) \
        / n[:, None]
    sizes = extents(points, labels, count)
    new = np.bincount(labels, log_odds_at < FREE_LOG_ODDS, count) / n
    mapped = np.bincount(labels, log_odds_at >= WALL_LOG_ODDS, count) / n
    d = points - cents[labels]
    sxx, syy, sxy = (np.bincount(labels, a * b, count) / n
                     for a, b in ((d[:, 0], d[:, 0]), (d[:, 1], d[:, 1]), (d[:, 0], d[:, 1])))
    smallest = 0.5 * (sxx + syy) - np.sqrt(0.25 * (sxx - syy) ** 2 + sxy ** 2)
    # each point along the cluster's main axis (u) and across it (w); the bend: w fitted
    # by a (u^2 - mean u^2), the curvature 2a
    axis = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)[labels]
    u = d[:, 0] * np.cos(axis) + d[:, 1] * np.sin(axis)
    w = d[:, 1] * np.cos(axis) - d[:, 0] * np.sin(axis)
    q = u ** 2 - (np.bincount(labels, u ** 2, count) / n)[labels]
    qq = np.maximum(np.bincount(labels, q * q, count), 1e-12)
    a = np.bincount(labels, w * q, count) / qq
    # ... and how sure that bend is: a over its standard error (the fit's residuals)
    rest = np.bincount(labels, (w - a[labels] * q) ** 2, count) / np.maximum(n - 2, 1)
    sure = np.abs(a) >= BEND_SIGNIFICANCE * np.sqrt(rest / qq)
    bends = (2.0 * np.abs(a) >= THIN_CURVATURE) & sure
    thin = ((np.sqrt(np.maximum(smallest, 0.0)) < THIN_STD) & (sizes > THIN_LENGTH)
            & ~bends) | (n < MIN_POINTS)
    return cents, sizes, new, mapped, thin
