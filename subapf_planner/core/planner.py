"""The planning step: perceive, gate, plan: (pose, scan, goal) -> command + diagnostics.

One cycle of :meth:`Planner.step` (the decision loop, core/loop.py, calls it once
per period):

1. **perceive**: the scan's valid returns -> point obstacles (scan.py, with the
   laser mounting of robot.py), placed with the scan alignment's correction
   (odom -> the memory's frame) as the last scan left it; moving obstacles are
   tracked (tracking.py). With ``attraction_field: geodesic`` (the default) the
   scan then goes into the occupancy memory (memory.py), but only once the
   cycle's command is out (:meth:`Planner.perceive`, from
   DecisionLoop.after_tick; the next step does it first if nobody did, so the
   result is the same): with ``scan_alignment`` it is matched to the memory
   (alignment.py; the correction it finds places the next cycle's robot, scan
   and goal, so drifting odometry does not draw walls twice), then the trail of
   what moved is cleared and the scan written, the moving tracks' points kept
   out. The command does not wait for the memory; the memory a cycle plans with
   holds the scans up to the one before (the scan itself is in the cycle's
   obstacles), its correction is one scan old (what odometry drifts in 0.2 s);
2. **gate**: the inputs (:func:`input_status`: non-finite pose or goal; a scan
   with a bad geometry) and the goal (:func:`goal_status`: reached, inside an
   obstacle; with the memory, unreachable through it) each stop the robot with
   their status;
3. **plan** (:func:`local_plan`, pure): the raw next move point of the APF step,
   eq. (23) (apf.py), circular sampling, Algorithm 1 and the Fig. 5 priority
   (sampling.py), the chosen point -> (v, w) (command.py). With the memory the
   attraction of eq. (21) is replaced by the navigation field (navigation.py);
   last, the command is checked against where the moving tracks will be, and
   replaced when it meets one (evasion.py).

``subharmonic``, ``traditional`` and ``harmonic`` skip the sampling and steer
to the raw point (the paper's ablations); ``dwa`` replaces the APF step, the
sampling and the command shaping (dwa.py). :func:`plan` is steps 2-3 from
obstacle points, for callers without a scan.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .alignment import Match, within_drift
from .apf import apf_step
from .command import Command, forward_blocked, shape_command
from .config import PlannerConfig
from .dwa import dwa_command
from .evasion import Escape, evade
from .memory import SAME_GOAL, NavigationMemory
from .navigation import NavigationField
from .robot import compose, invert, to_parent
from .sampling import SamplingResult, clearance, sample_and_choose
from .scan import Scan, ScanError, scan_to_points, voxel_downsample
from .status import Status
from .tracking import NO_TRACKS, Tracker, Tracks

_EMPTY = np.zeros((0, 2))
#: A place tried and not passed (Planner.avoid_ahead): this far ahead along the field's
#: descent [m] ...
AVOID_AHEAD = 0.5
#: ... a disc of this radius [m] (a door and its sides).
AVOID_RADIUS = 0.35
#: With the scan alignment, the robot stands until the memory holds this many scans: the
#: first walls are established (three hits) from where it started, before any drift; for
#: this many cycles at most (a scan repeated with the same stamp is not taken twice).
FIRST_SCANS = 3
#: Inside goal_tolerance, a cycle that brings the robot less than this closer to the goal
#: ends the approach (it cannot get closer: arrival_distance) [m].
ARRIVAL_PROGRESS = 0.002


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
    #: Where what moves was in the last scans (k, 2) [m]: cleared in the memory.
    trail: NDArray[np.float64]


@dataclass(frozen=True)
class PlanResult:
    """Command and what led to it (points in the odom frame, metres)."""

    command: Command
    raw_point: NDArray[np.float64] | None = None
    chosen_point: NDArray[np.float64] | None = None
    sampling: SamplingResult | None = None
    obstacles: NDArray[np.float64] = field(default_factory=lambda: _EMPTY)
    nearest_distance: float = math.inf
    goal_distance: float = math.nan
    field: NavigationField | None = None
    #: Whether this cycle computed a new navigation field (the expensive part).
    new_field: bool = False
    #: The tracked obstacles of this cycle's scan (core/tracking.py).
    tracks: Tracks = NO_TRACKS
    #: The robot's pose (x, y, yaw) the cycle planned from, in the memory's frame ...
    pose: NDArray[np.float64] | None = None
    #: ... which is odom corrected by this (x, y, yaw) (the scan alignment; Planner.step).
    correction: tuple[float, float, float] = (0.0, 0.0, 0.0)


def input_status(pose: ArrayLike, goal: ArrayLike) -> Status | None:
    """Gate on the inputs: ``invalid_pose`` for a pose that is not three finite numbers
    (x, y, yaw), ``invalid_goal`` for a goal that is not two; None when both are fine."""
    if np.shape(pose) != (3,) or not all(math.isfinite(v) for v in pose):
        return Status.INVALID_POSE
    if np.shape(goal) != (2,) or not all(math.isfinite(v) for v in goal):
        return Status.INVALID_GOAL
    return None


def goal_status(cfg: PlannerConfig, goal_distance: float, goal: NDArray[np.float64],
                obstacles: NDArray[np.float64]) -> Status | None:
    """Gate on the goal, ``goal_distance`` [m] from the robot: ``reached`` within
    goal_tolerance; ``goal_in_obstacle`` when a laser point lies within robot_radius of
    it (the robot could not stand there); None otherwise."""
    if goal_distance <= cfg.goal_tolerance:
        return Status.REACHED
    if float(clearance(goal, obstacles)[0]) < cfg.robot_radius:
        return Status.GOAL_IN_OBSTACLE
    return None


def local_radius(cfg: PlannerConfig) -> float:
    """Obstacle points farther than this from the robot cannot change a planning cycle of
    the APF methods [m]: the raw point and the samples lie within ``max_step + 2 *
    sample_radius`` of it, and no term looks farther than the repulsion's influence (a
    voxel's centroid may lie up to a voxel diagonal from its points), the Fig. 5
    priority distance, the discard distance or the safety corridor."""
    return (max(cfg.influence_distance + math.sqrt(2.0) * cfg.voxel_size,
                cfg.priority_distance, cfg.discard_distance, cfg.safety_distance)
            + cfg.max_step + 2.0 * cfg.sample_radius)


def _situation(pose: NDArray, goal: NDArray, obstacles: ArrayLike) -> dict:
    """Finite obstacle points (m, 2) and the robot's distances to them and to the goal,
    the diagnostics every PlanResult of a cycle carries."""
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    obs = obs[np.all(np.isfinite(obs), axis=1)]
    position = pose[:2]
    return dict(obstacles=obs, nearest_distance=float(clearance(position, obs)[0]),
                goal_distance=float(np.hypot(*(goal - position))))


def plan(cfg: PlannerConfig, pose: ArrayLike, goal: ArrayLike, obstacles: ArrayLike,
         previous: tuple[float, float] = (0.0, 0.0),
         field: NavigationField | None = None) -> PlanResult:
    """Gate and plan one cycle from obstacle points: pose (x, y, yaw), goal (x, y),
    obstacles (m, 2), all in odom; ``previous`` the last command (v, w); ``field`` the
    navigation-function attraction (None: Euclidean, eq. 21).

    Never raises for bad numbers: a non-finite pose or goal gives a stop with
    status ``invalid_pose`` / ``invalid_goal``; non-finite obstacle points are dropped.
    """
    pose = np.asarray(pose, float).ravel()
    goal = np.asarray(goal, float).ravel()
    status = input_status(pose, goal)
    if status is not None:
        return PlanResult(Command(0.0, 0.0, status))
    seen = _situation(pose, goal, obstacles)
    status = goal_status(cfg, seen['goal_distance'], goal, seen['obstacles'])
    if status is not None:
        return PlanResult(Command(0.0, 0.0, status), field=field, **seen)
    return local_plan(cfg, pose, goal, seen, previous, field)


def local_plan(cfg: PlannerConfig, pose: NDArray, goal: NDArray, seen: dict,
               previous: tuple[float, float], field: NavigationField | None) -> PlanResult:
    """Step 3 of the module docstring for inputs that passed the gates; ``seen`` as
    :func:`_situation` gives it."""
    obs = seen['obstacles']
    if cfg.method == 'dwa':
        return _plan_dwa(cfg, pose, goal, previous, seen, field)
    position = pose[:2]
    offset = obs - position
    near = obs[offset[:, 0] ** 2 + offset[:, 1] ** 2 <= local_radius(cfg) ** 2]
    repulsors = voxel_downsample(near, cfg.voxel_size)
    raw = apf_step(position, goal, repulsors, cfg, field)[0]
    sampling = None
    target: NDArray | None = raw
    if cfg.method == 'subharmonic_sampling':
        sampling = sample_and_choose(raw, position, goal, near, repulsors, cfg, field)
        target = sampling.chosen
    cmd = shape_command(pose, target, goal, previous, near, cfg)
    return PlanResult(cmd, raw, target, sampling, field=field, **seen)


def _tracker_settings(cfg: PlannerConfig) -> tuple[float, float, float, float]:
    return (cfg.cluster_gap, cfg.max_mover_size, cfg.track_gate, cfg.moving_speed)


def _tracker(cfg: PlannerConfig) -> Tracker:
    return Tracker(*_tracker_settings(cfg))


def _plan_dwa(cfg: PlannerConfig, pose: NDArray, goal: NDArray,
              previous: tuple[float, float], seen: dict,
              field: NavigationField | None) -> PlanResult:
    obs = seen['obstacles']
    res = dwa_command(pose, goal, previous, voxel_downsample(obs, cfg.voxel_size), cfg, field)
    if not res.admissible:
        return PlanResult(Command(0.0, 0.0, Status.NO_SAFE_MOVE), field=field, **seen)
    v, status = res.v, Status.DRIVING if res.v > 0.0 else Status.TURNING
    if v > 0.0 and forward_blocked(pose, obs, cfg):
        v, status = 0.0, Status.BLOCKED_AHEAD
    return PlanResult(Command(v, res.w, status), None, res.trajectory[-1].copy(), field=field,
                      **seen)


class Planner:
    """The planning step with its state: the last command (acceleration limits) and, with
    the geodesic attraction, the occupancy memory and its navigation field."""

    def __init__(self, cfg: PlannerConfig) -> None:
        self._cfg = cfg
        self.previous: tuple[float, float] = (0.0, 0.0)
        self.memory = NavigationMemory(cfg)
        self.tracker = _tracker(cfg)
        self._escape: Escape | None = None   # the escape of the last cycle, if it evaded
        self._approach: tuple[NDArray, float] | None = None   # last cycle's goal, distance
        #: The last cycle's scan, for the memory (perceive).
        self._perception: Perception | None = None
        self._clear_alignment()

    @property
    def cfg(self) -> PlannerConfig:
        return self._cfg

    @cfg.setter
    def cfg(self, cfg: PlannerConfig) -> None:
        if _tracker_settings(cfg) != _tracker_settings(self._cfg):
            self.tracker = _tracker(cfg)
        self._cfg = cfg
        self._perception = None
        self.memory.reconfigure(cfg)

    def reset(self) -> None:
        """Forget the last command and escape (after a stop, a new goal or a fault); the
        map stays."""
        self.previous = (0.0, 0.0)
        self._escape = None

    def forget(self) -> None:
        """Forget the last command, the map and the tracks (a restarted simulation)."""
        self.reset()
        self.memory.forget()
        self.tracker.reset()
        self._perception = None
        self._approach = None
        self._clear_alignment()

    def _clear_alignment(self) -> None:
        #: The memory's frame in odom: the scan alignment's correction (x, y, yaw).
        self.correction: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self.match: Match | None = None          # the last scan's alignment
        self._aligned_stamp: float | None = None
        self._aligned_from: NDArray | None = None   # odom pose of the last scan matched
        self._goal: tuple[NDArray, NDArray] | None = None   # (in odom, in the memory's frame)
        self._planned_from: NDArray | None = None   # the last cycle's pose (memory's frame)
        self._mapping_cycles = 0   # cycles stood for the first walls (FIRST_SCANS)

    def step(self, pose: ArrayLike, goal: ArrayLike, scan: Scan,
             scan_pose: ArrayLike | None = None, now: float | None = None,
             goal_in_map: bool = False) -> PlanResult:
        """Perceive, gate and plan one cycle (module docstring) for the robot at ``pose``
        (x, y, yaw) in odom driving to ``goal`` (x, y) in odom (with ``goal_in_map``: in
        the memory's frame). The result's points, field and ``pose`` are in the memory's
        frame: odom corrected by ``result.correction`` (the identity without scan
        alignment; the memory's frame is odom as it was at the start).

        ``scan_pose``: base_footprint's odom pose when the scan was taken (default
        ``pose``); a robot that moved since is planned for from ``pose``. ``now`` [s]
        rate-limits the navigation field (None: recomputed whenever the map changed).
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
        tracks, transient = self._track(scan, points, now)
        if cfg.geodesic:   # the memory takes the scan in once the command is out
            self._perception = Perception(scan, base, odom_scan_pose, goal, transient,
                                          tracks.trail)
        seen = _situation(pose, goal, points)
        status = goal_status(cfg, seen['goal_distance'], goal, seen['obstacles'])
        if status is None and cfg.geodesic and cfg.scan_alignment and self._mapping():
            status = Status.MAPPING
        if status is Status.REACHED and self._drives_on(goal, seen['goal_distance']):
            status = None
        self._approach = (goal, seen['goal_distance'])
        field, new_field = None, False
        if status is None and cfg.geodesic:   # the goal through the memory
            field = self.memory.field_for(pose[:2], goal, now)
            new_field = self.memory.recomputed
            if field is None or not field.reachable(pose[:2]):
                status = Status.GOAL_UNREACHABLE
        if status is not None:
            result = PlanResult(Command(0.0, 0.0, status), field=field, new_field=new_field,
                                tracks=tracks, **seen)
        else:
            result = local_plan(cfg, pose, goal, seen, self.previous, field)
            if new_field or tracks is not NO_TRACKS:
                result = dataclasses.replace(result, new_field=new_field, tracks=tracks)
        if status is not Status.REACHED and np.any(tracks.moving) and cfg.method != 'dwa':
            result = self._out_of_the_way(pose, result, points)
        else:
            self._escape = None
        result = dataclasses.replace(result, pose=pose, correction=self.correction)
        self._planned_from = pose
        if result.command.status.stops:
            return self._stop(result)
        self.previous = (result.command.v, result.command.w)
        return result

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
        self.memory.integrate(seen.scan, self.in_map(seen.scan_pose), seen.goal, seen.transient)

    def _mapping(self) -> bool:
        """Whether this cycle stands for the first walls (FIRST_SCANS, the cycle's own
        scan, which the memory takes after it, counted; counts the cycle)."""
        scans = self.memory.grid.scans + (self._perception is not None)
        if scans >= FIRST_SCANS or self._mapping_cycles >= FIRST_SCANS:
            return False
        self._mapping_cycles += 1
        return True

    def _drives_on(self, goal: NDArray, distance: float) -> bool:
        """Inside goal_tolerance at ``distance`` [m] from ``goal``: whether to drive on
        (geodesic only): farther than arrival_distance and at least ARRIVAL_PROGRESS
        closer than the last cycle, or its first cycle inside."""
        cfg = self.cfg
        if not cfg.geodesic or distance <= cfg.arrival_distance:
            return False
        if self._approach is None or not np.array_equal(self._approach[0], goal):
            return True
        before = self._approach[1]
        return before > cfg.goal_tolerance or before - distance >= ARRIVAL_PROGRESS

    def avoid_ahead(self, until: float) -> bool:
        """Mark the place the navigation field leads the robot into next (AVOID_AHEAD
        along its descent from the last cycle's pose, a disc of AVOID_RADIUS) as tried,
        blocked in the field until ``until`` [s]; False without a field or a way."""
        f, pose = self.memory.field, self._planned_from
        if f is None or pose is None:
            return False
        path = f.path(pose[:2], max_length=2.0 * AVOID_AHEAD)
        if len(path) < 2:
            return False
        along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
        self.memory.avoid(path[min(int(np.searchsorted(along, AVOID_AHEAD)), len(path) - 1)],
                          AVOID_RADIUS, until)
        return True

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
        predicted = self.in_map(scan_pose)
        self.match = self.memory.align(base, predicted, self._moving_discs(scan.stamp))
        last, self._aligned_from = self._aligned_from, scan_pose
        if not self.match.accepted or last is None:
            return
        moved = compose(invert(last), scan_pose)   # odometry's motion since the last scan
        pose = within_drift(predicted, self.match.pose, math.hypot(moved[0], moved[1]),
                            moved[2])
        if not np.array_equal(pose, predicted):
            self.correction = compose(pose, invert(scan_pose))

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

    def _anchored(self, goal: NDArray) -> NDArray[np.float64]:
        """The goal (x, y) in the memory's frame: a goal given in odom is the place odom
        had there when the goal came (the correction of then), and stays that place
        while the correction changes."""
        if self._goal is None or np.hypot(*(goal - self._goal[0])) >= SAME_GOAL:
            self._goal = (goal.copy(), to_parent(self.correction, goal)[0])
        return self._goal[1]

    def _track(self, scan: Scan, points: NDArray,
               now: float | None) -> tuple[Tracks, NDArray[np.bool_] | None]:
        """The tracks of this scan, and per beam whether it returned from a moving one."""
        t = scan.stamp if math.isfinite(scan.stamp) else now
        if not self.cfg.tracks_moving or t is None or not math.isfinite(t):
            return NO_TRACKS, None
        tracks = self.tracker.update(points, t, self.memory.log_odds_at(points))
        transient = np.zeros(np.size(scan.ranges), bool)
        transient[np.flatnonzero(scan.valid(self.cfg.obstacle_range))] = tracks.held_points
        return tracks, transient

    def _out_of_the_way(self, pose: NDArray, result: PlanResult,
                        points: NDArray) -> PlanResult:
        """The result with its command replaced when that would meet a moving track."""
        cfg, tracks, cmd = self.cfg, result.tracks, result.command
        static = points[~tracks.moving_points]
        alt = evade(pose, (cmd.v, cmd.w), tracks, static, cfg,
                    forward_blocked(pose, points, cfg),
                    None if self._escape is None else self._escape.advanced())
        self._escape = alt
        if alt is None:
            return result
        return dataclasses.replace(result, command=Command(*alt.command, Status.EVADING))

    def _stop(self, result: PlanResult) -> PlanResult:
        self.reset()
        return result
