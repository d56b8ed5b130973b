"""The planning step: (pose, scan, goal) -> command + diagnostics, as a pipeline.

One call of :meth:`Planner.step` (the decision loop, core/loop.py, calls it once per
period) is one cycle (core/cycle.py):

1. **inputs**: a pose or goal that is not finite numbers, or a scan with a bad
   geometry, stops the robot (``invalid_pose``, ``invalid_goal``, ``invalid_scan``);
2. **perceive**: the scan's valid returns -> point obstacles (scan.py, with the
   laser mounting of robot.py), placed with the scan alignment's correction (odom
   -> the memory's frame) as the last scan left it; moving obstacles are tracked
   (tracking.py). With the memory the scan goes into it only once the cycle's command
   is out (:meth:`Planner.perceive`, from DecisionLoop.after_tick; the next step does
   it first if nobody did, so the result is the same): with ``scan_alignment`` it is
   matched to the memory (alignment.py; the correction it finds places the next
   cycle's robot, scan and goal), then the trail of what moved is cleared and the
   scan written, the moving tracks' points kept out;
3. **stages** (core/pipeline.py chooses them from the parameters): the gates
   (core/gates.py: goal, mapping, reachability), the proposer (core/proposers.py:
   the APF step with circular sampling and its critics, the APF step alone, DWA),
   the filters (core/filters.py: evasion);
4. **finish**: the result carries the pose planned from and the correction; a
   command that stops the robot clears the last command and the stages' memory of
   this goal (``reset``).

:func:`plan` is the goal gate and the proposer from obstacle points, for callers
without a scan or a memory.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .alignment import LOCALISE_TIME, Match, within_drift
from .blind_spots import blind_obstacles, unseen
from .command import Command
from .config import PlannerConfig
from .cycle import Cycle, PlanResult
from .gates import goal_status, input_status
from .known_map import KnownMap
from .memory import SAME_GOAL, NavigationMemory
from .navigation import NavigationField
from .occupancy import ESTABLISHED
from .odometry_calibration import OdometryCalibration, scaled
from .pipeline import Pipeline
from .proposers import local_radius
from .robot import compose, invert, to_parent
from .sampling import clearance
from .scan import Scan, ScanError, on_grid, range_sigma, scan_to_points, scans_in
from .status import Status
from .tracking import NO_TRACKS, STANDING_TIME, Tracker, Tracks

__all__ = ['Perception', 'PlanResult', 'Planner', 'goal_status', 'input_status',
           'local_radius', 'plan']

#: Returns this close to something that moves [m] take no part in the odometry's
#: calibration.
MOVER_MARGIN = 0.1


@dataclass(frozen=True)
class Perception:
    """A cycle's scan waiting to go into the memory once the command is out
    (Planner.perceive)."""

    scan: Scan
    #: Its returns (m, 2) in base_footprint [m], in beam order.
    base: NDArray[np.float64]
    #: base_footprint's odom pose (x, y, yaw) when it was taken.
    scan_pose: NDArray[np.float64]
    #: The goal (x, y) in the memory's frame [m] (the window follows it).
    goal: NDArray[np.float64]
    #: Per beam: whether it returned from something moving (None: no tracker).
    transient: NDArray[np.bool_] | None
    #: Per beam: whether it returned from something held out of the memory because it
    #: is new, not because it moves (None: no tracker).
    unmoved: NDArray[np.bool_] | None
    #: Where what moves was in the last scans (k, 2) [m]: cleared in the memory.
    trail: NDArray[np.float64]


def _situation(pose: NDArray, goal: NDArray, obstacles: ArrayLike) -> dict:
    """Finite obstacle points (m, 2) and the robot's distances to them and to the goal."""
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    obs = obs[np.all(np.isfinite(obs), axis=1)]
    position = pose[:2]
    return dict(obstacles=obs, nearest_distance=float(clearance(position, obs)[0]),
                goal_distance=float(np.hypot(*(goal - position))))


def plan(cfg: PlannerConfig, pose: ArrayLike, goal: ArrayLike, obstacles: ArrayLike,
         previous: tuple[float, float] = (0.0, 0.0),
         field: NavigationField | None = None) -> PlanResult:
    """The goal gate and the proposer of ``cfg.method`` for one cycle from obstacle
    points: pose (x, y, yaw), goal (x, y), obstacles (m, 2), all in one frame;
    ``previous`` the last command (v, w); ``field`` the navigation-function attraction
    (None: Euclidean, eq. 21).

    Never raises for bad numbers: a non-finite pose or goal gives a stop with
    status ``invalid_pose`` / ``invalid_goal``; non-finite obstacle points are dropped.
    """
    pose = np.asarray(pose, float).ravel()
    goal = np.asarray(goal, float).ravel()
    status = input_status(pose, goal)
    if status is not None:
        return PlanResult(Command(0.0, 0.0, status))
    seen = _situation(pose, goal, obstacles)
    cycle = Cycle(cfg, 0.0, cfg.period, pose, goal, seen['obstacles'], tracks=NO_TRACKS,
                  previous=previous, field=field, **seen)
    cycle = cycle.with_(status=goal_status(cfg, cycle.goal_distance, goal, cycle.obstacles))
    if cycle.status is not None:
        return cycle.stopped().result
    return Pipeline(cfg, None).proposer.run(cycle).result


def _tracker_settings(cfg: PlannerConfig) -> tuple[float, float, float, float]:
    return (cfg.cluster_gap, cfg.max_mover_size, cfg.track_gate, cfg.moving_speed)


def _tracker(cfg: PlannerConfig) -> Tracker:
    return Tracker(*_tracker_settings(cfg))


def _near(points: NDArray, centres: NDArray, radii: NDArray) -> NDArray[np.bool_]:
    """Which ``points`` (n, 2) lie within MOVER_MARGIN of one of the discs (k, 2; k,)."""
    if not len(radii) or not len(points):
        return np.zeros(len(points), bool)
    d = np.hypot(*(points[:, None, :] - centres[None, :, :]).transpose(2, 0, 1))
    return np.any(d <= radii + MOVER_MARGIN, axis=1)


class Planner:
    """The planning step with its state: the last command (acceleration limits), the
    stages (core/pipeline.py) with what they remember, and, with the geodesic
    attraction, the occupancy memory and its navigation field."""

    def __init__(self, cfg: PlannerConfig) -> None:
        self._cfg = cfg
        self.previous: tuple[float, float] = (0.0, 0.0)
        self.memory = NavigationMemory(cfg)
        self.tracker = _tracker(cfg)
        self.pipeline = Pipeline(cfg, self.memory)
        #: The last cycle's scan, for the memory (perceive).
        self._perception: Perception | None = None
        self._clear_alignment()

    @property
    def cfg(self) -> PlannerConfig:
        """The configuration (change it with :meth:`reconfigure`)."""
        return self._cfg

    def reconfigure(self, cfg: PlannerConfig) -> None:
        """Plan with ``cfg`` from the next cycle. The same configuration again changes
        nothing; another one drops the scan waiting for the memory (its returns were
        placed with the old laser mounting), rebuilds the tracker when its settings
        changed and the memory when its grid did (core/memory.py), and chooses the
        stages anew (each keeps what it remembers)."""
        if cfg == self._cfg:
            return
        if _tracker_settings(cfg) != _tracker_settings(self._cfg):
            self.tracker = _tracker(cfg)
        self._cfg = cfg
        self._perception = None
        self.memory.reconfigure(cfg)
        self.pipeline.configure(cfg)

    def seed(self, command: tuple[float, float]) -> None:
        """The command (v, w) the robot was last sent: the next command's acceleration
        limits start from it."""
        self.previous = (float(command[0]), float(command[1]))

    def reset(self) -> None:
        """Forget the last command and what the stages keep for the goal (after a stop,
        a new goal or a fault); the map stays."""
        self.previous = (0.0, 0.0)
        self.pipeline.reset()

    def forget(self) -> None:
        """Forget the last command, the map, the tracks and the stages' memory (a
        restarted simulation)."""
        self.reset()
        self.memory.forget()
        self.tracker.reset()
        self.pipeline.forget()
        self._perception = None
        self._clear_alignment()

    def _clear_alignment(self) -> None:
        #: The memory's frame in odom: the scan alignment's correction (x, y, yaw).
        self.correction: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self.match: Match | None = None          # the last scan's alignment
        #: Whether a scan's match has been accepted since the memory began.
        self.aligned = False
        self._aligned_stamp: float | None = None
        self._aligned_from: NDArray | None = None   # odom pose of the last scan matched
        #: Scans left to match in a localiser's basin (start_from; alignment.localise).
        self._localising = 0
        self._goal: tuple[NDArray, NDArray] | None = None   # (in odom, in the memory's frame)
        self._planned_from: NDArray | None = None   # the last cycle's pose (memory's frame)
        #: Odometry's distance and turn scales, learnt (with odometry_calibration).
        self.odometry = OdometryCalibration()

    @property
    def planned_from(self) -> NDArray[np.float64] | None:
        """The pose (x, y, yaw) the last cycle planned from, in the memory's frame."""
        return self._planned_from

    def step(self, pose: ArrayLike, goal: ArrayLike, scan: Scan,
             scan_pose: ArrayLike | None = None, *, now: float,
             goal_in_map: bool = False, memory_scan: Scan | None = None) -> PlanResult:
        """One cycle (module docstring) at time ``now`` [s] for the robot at ``pose``
        (x, y, yaw) in odom driving to ``goal`` (x, y) in odom (with ``goal_in_map``: in
        the memory's frame). The result's points, field and ``pose`` are in the memory's
        frame: odom corrected by ``result.correction`` (the identity without scan
        alignment; the memory's frame is odom as it was at the start).

        ``scan_pose``: base_footprint's odom pose when the scan was taken (default
        ``pose``); a robot that moved since is planned for from ``pose``. ``now`` paces
        the navigation field (field_period; -inf: a new field whenever the map
        changed). ``memory_scan``: the same sweep as the memory and the scan alignment
        take it (DecisionLoop._deskewed: not denoised at grazing incidence; default
        ``scan``).
        """
        cfg = self.cfg
        pose = np.asarray(pose, float).ravel()
        goal = np.asarray(goal, float).ravel()
        status = input_status(pose, goal)
        if status is not None:
            return self._stop(PlanResult(Command(0.0, 0.0, status)))
        scan_pose = pose if scan_pose is None else np.asarray(scan_pose, float).ravel()
        self.perceive()   # the last cycle's scan, if after_tick did not take it in
        odom_scan_pose = scan_pose
        try:   # perceive: the returns placed with the correction of the last scan
            pose, scan_pose = self.in_map(pose), self.in_map(scan_pose)
            goal = goal if goal_in_map else self._anchored(goal)
            base = scan_to_points(scan, (0.0, 0.0, 0.0), cfg.laser_mount, cfg.obstacle_range)
        except ScanError:
            return self._stop(PlanResult(Command(0.0, 0.0, Status.INVALID_SCAN)))
        points = to_parent(scan_pose, base)   # the returns in base_footprint, then placed
        tracks, transient, unmoved = self._track(scan, points, scan_pose, now)
        if cfg.geodesic:   # the memory takes the scan in once the command is out
            seen, seen_base = scan, base
            if memory_scan is not None and memory_scan is not scan \
                    and np.size(memory_scan.ranges) == np.size(scan.ranges):
                seen = memory_scan
                seen_base = scan_to_points(seen, (0.0, 0.0, 0.0), cfg.laser_mount,
                                           cfg.obstacle_range)
                transient = on_grid(transient, scan, seen)
                unmoved = on_grid(unmoved, scan, seen)
            self._perception = Perception(seen, seen_base, odom_scan_pose, goal, transient,
                                          unmoved, tracks.trail)
        obstacles = points
        if cfg.geodesic:   # what the lidar cannot see now, the memory remembers
            blind = blind_obstacles(self.memory.grid, pose, compose(scan_pose, cfg.laser_mount),
                                    scan, local_radius(cfg), cfg.robot_radius, cfg.polygon)
            obstacles = np.vstack((points, blind)) if len(blind) else points
        cycle = Cycle(cfg, now, cfg.period, pose, goal, points, tracks=tracks,
                      previous=self.previous,
                      memory_scans=self.memory.grid.scans + (self._perception is not None),
                      aligned=self.aligned,
                      scan_age=now - scan.stamp if math.isfinite(scan.stamp) else 0.0,
                      **_situation(pose, goal, obstacles))
        result = self._run_stages(cycle)
        result = dataclasses.replace(result, pose=pose, correction=self.correction)
        self._planned_from = pose
        if result.command.status.stops:
            return self._stop(result)
        self.previous = (result.command.v, result.command.w)
        return result

    def _run_stages(self, cycle: Cycle) -> PlanResult:
        """The gates until one stops the cycle, the proposer if none did, the filters."""
        stages = self.pipeline
        for gate in stages.gates:
            cycle = gate.run(cycle)
            if cycle.status is not None:
                break
        cycle = stages.proposer.run(cycle) if cycle.status is None else cycle.stopped()
        for f in stages.filters:
            cycle = f.run(cycle)
        return cycle.result

    def after_tick(self) -> None:
        """The work between this cycle and the next, once the command is out: the scan
        into the memory (perceive), then the navigation field marched on the memory's
        worker (core/memory.py)."""
        self.perceive()
        self.memory.start_marching()

    def settle(self) -> None:
        """after_tick, and the field waited for (a caller with no idle time)."""
        self.perceive()
        self.memory.settle()

    def perceive(self) -> None:
        """Take the last cycle's scan into the memory, if not done yet: match it to the
        memory (with ``scan_alignment``: the correction the next cycle places the robot
        with), clear the trail of what moved, write it. For after the cycle's command is
        out (DecisionLoop.after_tick): the command does not wait for the memory. Not
        called, the next step calls it first: the same memory either way."""
        if self._perception is None:
            return
        seen, self._perception = self._perception, None
        if self.cfg.scan_alignment:
            self._align(seen.scan, seen.base, seen.scan_pose)
        if len(seen.trail):
            self.memory.clear(seen.trail)
        self.memory.integrate(seen.scan, self.in_map(seen.scan_pose), seen.goal, seen.transient,
                              seen.unmoved)

    def in_map(self, pose: ArrayLike) -> NDArray[np.float64]:
        """An odom pose (x, y, yaw) in the memory's frame (odom corrected by the scan
        alignment; odom itself without it)."""
        return np.array(compose(self.correction, pose))

    def _align(self, scan: Scan, base: NDArray, scan_pose: NDArray) -> None:
        """Match a new scan (not one already matched: same stamp), its returns ``base``
        (m, 2) in base_footprint, to the memory and update the correction when the
        match is accepted, by no more than odometry can have drifted since the last
        scan (core/alignment.py: within_drift)."""
        if scan.stamp == self._aligned_stamp:
            return
        self._aligned_stamp = scan.stamp
        discs = self._moving_discs(scan.stamp)
        last, self._aligned_from = self._aligned_from, scan_pose
        predicted = self.in_map(scan_pose)
        moved = None if last is None else compose(invert(last), scan_pose)
        # odometry's motion since the last scan: the most the pose may be corrected by
        distance, turn = (0.0, 0.0) if moved is None else (math.hypot(moved[0], moved[1]),
                                                            moved[2])
        if self._localising > 0:   # a localiser's map -> odom: its error, not drift
            self._localising -= 1
            self.match = self.memory.align(base, predicted, discs, wide=True)
            if self.match.accepted:
                self.aligned = True
                self._localising = 0
                self._place(self.match.pose, scan_pose)
                return
        if self.cfg.odometry_calibration:
            if moved is not None:   # the motion as calibrated
                predicted = np.array(compose(self.in_map(last),
                                             scaled(moved, self.odometry.scales)))
            placed = to_parent(predicted, base)   # what walks left out, walls kept
            self.odometry.observe(base[~_near(placed, *discs) & self._on_walls(placed)],
                                  scan_pose)
            if moved is not None:   # the scans' own registration, no faster than drift
                predicted = within_drift(predicted, self.odometry.correct(predicted),
                                         distance, turn)
        self.match = self.memory.align(base, predicted, discs)
        self.aligned = self.aligned or self.match.accepted
        pose = predicted
        if moved is not None and self.match.accepted:
            pose = within_drift(predicted, self.match.pose, distance, turn)
        self._place(pose, scan_pose)

    def _place(self, pose: NDArray, scan_pose: NDArray) -> None:
        """The correction that puts the odom pose ``scan_pose`` at ``pose`` (x, y, yaw) in
        the memory's frame (unchanged when it is there already), and odometry's
        calibration told where the scan was taken."""
        if not np.array_equal(pose, self.in_map(scan_pose)):
            self.correction = tuple(float(v) for v in compose(pose, invert(scan_pose)))
        self.odometry.place(pose)

    def _on_walls(self, points: NDArray) -> NDArray[np.bool_]:
        """Which ``points`` (n, 2) [m] in the memory's frame lie on or beside (one cell)
        a cell the memory is sure of (established): not what walks through it."""
        grid = self.memory.grid
        cells = grid.cell_of(points)
        found = np.zeros(len(points), bool)
        for step in ((0, 0), (0, 1), (0, -1), (1, 0), (-1, 0), (1, 1), (1, -1), (-1, 1),
                     (-1, -1)):
            c = cells + step
            ok = grid.inside(c)
            found[ok] |= grid.log_odds[c[ok, 0], c[ok, 1]] >= ESTABLISHED
        return found

    def _moving_discs(self, t: float) -> tuple[NDArray, NDArray]:
        """Where the last scan's tracks that move, are held out of the memory or seem to
        move (speed at least moving_speed) are at time ``t`` [s] (k, 2), and their radii
        (k,) [m]: the scan alignment leaves their returns out (a walker written into the
        map before it was known to move would otherwise drag the pose with it)."""
        last = self.tracker.last
        if last is None or not len(last.position):
            return np.zeros((0, 2)), np.zeros(0)
        speed = np.hypot(*last.velocity.T)
        keep = last.held | last.moving | (speed >= self.cfg.moving_speed)
        dt = t - self.tracker.time if math.isfinite(t) and self.tracker.time is not None \
            else 0.0
        return last.position[keep] + dt * last.velocity[keep], last.radius[keep]

    def know(self, known: KnownMap | None) -> None:
        """Start the memory from a map the robot already has (its pose in the memory's
        frame in it; None: none): NavigationMemory.know."""
        self.memory.know(known)

    def start_from(self, known: KnownMap, odom_in_map: ArrayLike) -> None:
        """Start afresh from a localiser's map: the memory's frame becomes the map's
        frame, odom placed in it at ``odom_in_map`` (x, y, yaw: the localiser's map ->
        odom), the memory taken from ``known`` (in that frame) and what it held before
        dropped (placed in another frame); the scan alignment goes on from there."""
        self.memory.know(None)   # (so that forget does not read the old map in first)
        self.forget()
        self.correction = tuple(float(v) for v in odom_in_map)
        self.memory.know(known)
        self._localising = scans_in(LOCALISE_TIME, self.cfg.period)

    def follow(self, path: ArrayLike | None, in_map: bool = False) -> None:
        """Favour ``path`` (k, 2) [m] in the navigation field (path_discount) until the
        next call; None: no path. A path in odom (``in_map`` False) is anchored as a goal
        is: the places odom has there now."""
        if path is None:
            self.memory.follow(None)
            return
        p = np.asarray(path, float).reshape(-1, 2)
        self.memory.follow(p if in_map else to_parent(self.correction, p))

    def _anchored(self, goal: NDArray) -> NDArray[np.float64]:
        """The goal (x, y) in the memory's frame: a goal given in odom is the place odom
        had there when the goal came (the correction of then), and stays that place
        while the correction changes."""
        if self._goal is None or np.hypot(*(goal - self._goal[0])) >= SAME_GOAL:
            self._goal = (goal.copy(), to_parent(self.correction, goal)[0])
        return self._goal[1]

    def _track(self, scan: Scan, points: NDArray, scan_pose: NDArray,
               now: float) -> tuple[Tracks, NDArray[np.bool_] | None,
                                    NDArray[np.bool_] | None]:
        """The tracks of this scan (its returns ``points`` in the memory's frame, taken
        at ``scan_pose``), per beam whether it returned from one held out of the memory
        (moving or new), and whether from one held because it is new, not moving. The
        tracker is told which returns are on what has stood for STANDING_TIME,
        within two standard deviations of their range noise along their rays
        (NavigationMemory.standing)."""
        t = scan.stamp if math.isfinite(scan.stamp) else now
        if not self.cfg.tracks_moving or not math.isfinite(t):
            return NO_TRACKS, None, None
        laser = compose(scan_pose, self.cfg.laser_mount)
        origin = laser[:2]
        noise = range_sigma(np.hypot(*(points - origin).T), self.cfg.range_noise_floor,
                            self.cfg.range_noise_fraction)
        beams = np.flatnonzero(scan.valid(self.cfg.obstacle_range))   # those of points
        tracks = self.tracker.update(points, t, self.memory.log_odds_at(points),
                                     self.memory.standing(points, origin, 2.0 * noise,
                                                          scans_in(STANDING_TIME,
                                                                   self.cfg.period)),
                                     beams * scan.beam_interval, noise,
                                     lambda places: unseen(places, laser, scan))
        transient = np.zeros(np.size(scan.ranges), bool)
        transient[beams] = tracks.held_points
        unmoved = np.zeros(np.size(scan.ranges), bool)
        unmoved[beams] = tracks.unmoved_points
        return tracks, transient, unmoved

    def _stop(self, result: PlanResult) -> PlanResult:
        self.reset()
        return result
