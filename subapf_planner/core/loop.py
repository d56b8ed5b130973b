"""The decision loop, without ROS: input freshness, goal, progress, states.

One loop for everything that plans: ``planner_node`` feeds it messages as
arrays with their times and publishes what ``tick`` decides; the replay
(ros/replay.py) feeds it a recorded bag the same way; the benchmark's episode
(sim/episode.py) feeds it the simulator's scans and odometry on simulated time.
Times are seconds on the node's clock (simulated time under ``use_sim_time``).
Each ``tick`` runs the supervisors (core/supervisors.py: goal, inputs, freshness,
given up; then arrival, unreachable, progress with its recoveries) around one
planning step (core/planner.py: perceive, then the cycle's stages).

States (:class:`~.status.State`, the text of ``~/status`` before the colon):
idle, waiting, mapping (the first scans of a new memory, taken standing: the normal
start of a goal), driving, stopped, and the final ones, which stay until the next
goal: reached, stuck (the progress checker gave the goal up), unreachable (no way
through the memory, or the goal inside an obstacle, for ``unreachable_timeout``).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
import math

import numpy as np

from .config import PlannerConfig
from .cycle import PlanResult
from .known_map import KnownMap
from .memory import SAME_GOAL
from .occupancy import OccupancyGrid
from .params import check_fields, param
from .planner import Planner
from .robot import compose, invert, to_parent
from .scan import GRAZING_MEMORY, GRAZING_OBSTACLES, Scan, denoise_each, deskew
from .status import State, Status
from .supervisors import SUPERVISORS, Recoveries

#: Odometry poses kept to place each scan at the pose it was taken from.
POSE_HISTORY = 100
#: An input stamped more than this [s] after the clock is not taken: it was sent before
#: the clock jumped back (a restarted simulation) or by a clock out of step.
FUTURE_STAMP = 1.0


@dataclass(frozen=True)
class Supervision:
    """Limits of the decision loop (config/planner.yaml, supervision section)."""

    scan_timeout: float = param(1.0, 'Stop when the newest scan is older than this', 's',
                                0.05, 10.0)
    odom_timeout: float = param(0.5, 'Stop when the newest odometry is older than this', 's',
                                0.05, 10.0)
    progress_distance: float = param(0.5, 'Progress checker: the robot must move this far '
                                     'within progress_timeout, or the goal is abandoned '
                                     '(state stuck)', 'm', 0.01, 10.0)
    progress_timeout: float = param(10.0, 'Progress checker: time allowed for '
                                    'progress_distance', 's', 1.0, 600.0)
    blocked_timeout: float = param(3.0, 'Progress checker: standing this long with '
                                   'no_safe_move, or blocked_ahead and not turning (the '
                                   'local layer finds no safe move where the field leads, '
                                   'nobody to give way to) starts '
                                   'the recovery without waiting for progress_timeout: a gap '
                                   'that turns out impassable is tried for seconds, not a '
                                   'minute', 's', 0.2, 600.0)
    recoveries: int = param(3, 'Times the progress checker, before it abandons the goal, '
                            'marks the place the field leads into as tried (blocked in the '
                            'field for avoid_time) so that the field leads along another way',
                            '', 0, 100)
    avoid_distance: float = param(0.5, 'The recovery marks the place this far along the '
                                  "field's descent tried (the door or gap the robot is "
                                  'pushing at)', 'm', 0.05, 5.0)
    avoid_radius: float = param(0.35, 'The place marked tried is a disc of this radius (a '
                                'door and its sides)', 'm', 0.05, 5.0)
    avoid_time: float = param(60.0, 'How long a tried place stays blocked in the field (then '
                              'it opens again: a door that was only briefly blocked)', 's',
                              1.0, 3600.0)
    unreachable_timeout: float = param(30.0, 'A goal unreachable through the memory, or '
                                       'inside an obstacle, this long ends the attempt '
                                       '(state unreachable); a way that opens before (a '
                                       'door, someone who walked off) restarts the clock',
                                       's', 1.0, 3600.0)
    giving_way_distance: float = param(2.0, 'The progress checker waits while a moving '
                                       'obstacle is this close (giving way to someone is '
                                       'not being stuck)', 'm', 0.0, 20.0)

    def __post_init__(self) -> None:
        check_fields(self)


@dataclass(frozen=True)
class Decision:
    """What to publish: a command (None: publish nothing), the state and its reason,
    the plan if any."""

    command: tuple[float, float] | None
    state: State
    reason: str
    result: PlanResult | None = None

    @property
    def text(self) -> str:
        """``~/status`` on the wire: ``"state: reason"``."""
        return f'{self.state}: {self.reason}'


class DecisionLoop:
    """One robot's decision loop and its state. Not thread-safe; call from one executor."""

    def __init__(self, cfg: PlannerConfig, limits: Supervision | None = None) -> None:
        self.planner = Planner(cfg)
        self.limits = limits or Supervision()
        self.scan: Scan | None = None
        self.scan_time: float | None = None
        self.pose: np.ndarray | None = None
        self.odom_time: float | None = None
        self.poses: deque = deque(maxlen=POSE_HISTORY)
        self.goal: np.ndarray | None = None
        self.goal_in_map = False
        self.state = State.IDLE
        self.reason = 'no goal'
        self.supervisors = tuple(cls() for cls in SUPERVISORS)
        #: The last scan, as the obstacles and as the memory take it, and its pose (_deskewed)
        self._deskew: tuple[Scan, Scan, Scan, np.ndarray] | None = None
        self.recoveries = Recoveries()

    @property
    def cfg(self) -> PlannerConfig:
        """The planner's configuration (change it with :meth:`reconfigure`)."""
        return self.planner.cfg

    def reconfigure(self, cfg: PlannerConfig, limits: Supervision | None = None) -> None:
        """Plan with ``cfg`` (Planner.reconfigure) and, when given, supervise with
        ``limits`` from the next tick."""
        self.planner.reconfigure(cfg)
        if limits is not None:
            self.limits = limits

    @property
    def correction(self) -> tuple[float, float, float]:
        """The memory's frame in odom (x, y, yaw): the scan alignment's correction as the
        last scan taken into the memory left it."""
        return self.planner.correction

    @property
    def field_seconds(self) -> float:
        """How long the newest navigation field took to compute [s] (wall clock: a
        figure for benchmarks, not for decisions)."""
        return self.planner.memory.compute_seconds

    @property
    def grid(self) -> OccupancyGrid:
        """The occupancy memory (read it, do not change it)."""
        return self.planner.memory.grid

    def after_tick(self) -> None:
        """Do the work that runs between this tick and the next (Planner.after_tick: the
        scan into the memory, then the navigation field marched on a worker thread);
        call it once the tick's command is out. The next tick's decisions are the same
        whether it is called or not."""
        self.planner.after_tick()

    def settle(self) -> None:
        """The work between ticks done and finished (for a caller with no idle time
        between ticks: the bench); the next tick's decisions are the same."""
        self.planner.settle()

    def seed_command(self, command: tuple[float, float]) -> None:
        """The command the robot was last sent by someone else (a replay that starts
        mid-run): the next command's acceleration limits start from it."""
        self.planner.seed(command)

    @property
    def text(self) -> str:
        """The state as ``~/status`` carries it: ``"state: reason"``."""
        return f'{self.state}: {self.reason}'

    def set_goal(self, goal: np.ndarray, in_map: bool = False,
                 path: np.ndarray | None = None) -> bool:
        """A new goal resets the planner; the goal being driven to (or waited for: no
        inputs yet; or stood for: mapping), sent again, does not, whenever it arrives (a
        stuck, stopped or arrived robot retries it). Returns whether the goal was new.
        ``goal`` (x, y) is in odom (the place odom puts there now), or with ``in_map`` in
        the memory's frame (the place in the world, as odom was at the start: what the
        scan alignment keeps still). ``path`` (k, 2), in the goal's frame: a way to the
        goal the navigation field favours (Planner.follow; a goal sent again with a path
        takes the new path); a new goal without one has none."""
        goal = np.asarray(goal, float)
        if self.goal is not None \
                and self.state in (State.DRIVING, State.WAITING, State.MAPPING) \
                and np.hypot(*(goal - self.goal)) < SAME_GOAL \
                and in_map == self.goal_in_map:
            if path is not None:
                self.planner.follow(path, in_map)
            return False
        self.goal, self.goal_in_map = goal.copy(), bool(in_map)
        self.planner.reset()
        self.planner.follow(path, in_map)
        for s in self.supervisors:
            s.reset()
        self.recoveries.tried = 0
        self._set(State.DRIVING, 'new goal')
        return True

    def clear_goal(self) -> None:
        """The goal is done (reached): none until the next."""
        self.goal = None

    def know(self, known: KnownMap | None) -> None:
        """Start the memory from a map the robot already has (core/known_map.py; its pose
        the map frame's in the memory's frame); None: from the scans alone."""
        self.planner.know(known)

    def start_from(self, known: KnownMap, odom_in_map: tuple[float, float, float]) -> None:
        """Start afresh from a localiser's map and its map -> odom (Planner.start_from):
        goals in the memory's frame are then in the map's; the goal is kept."""
        self.planner.start_from(known, odom_in_map)

    def cancel(self, reason: str = 'goal canceled') -> None:
        """Drop the goal (canceled, or the node deactivated): idle, for ``reason``, until
        the next goal; the planner's last command is forgotten, the memory stays."""
        self.goal = None
        self.planner.reset()
        self._set(State.IDLE, reason)

    def remaining(self, result: PlanResult | None) -> float:
        """Distance [m] left to the goal after the tick that gave ``result``: along the
        navigation field's descent where there is a field (the way the robot is led;
        straight on from where the descent stops, 30 m on), else straight from the
        newest odometry; nan without a goal or a pose. A query: changes nothing."""
        if self.goal is None:
            return math.nan
        if result is not None and result.field is not None and result.pose is not None:
            path = result.field.path(result.pose[:2])
            if len(path):
                legs = np.diff(np.vstack([result.pose[:2], path, result.field.goal[:2]]),
                               axis=0)
                return float(np.sum(np.hypot(legs[:, 0], legs[:, 1])))
        if self.pose is None:
            return math.nan
        goal = to_parent(self.correction, self.goal)[0] if self.goal_in_map else self.goal
        return float(np.hypot(*(goal - self.pose[:2])))

    def clock_jumped(self) -> None:
        """The clock jumped (a restarted simulation, a bag played from elsewhere): forget
        every input and its time, keep the goal, and wait for fresh data."""
        self.scan = self.scan_time = self.pose = self.odom_time = None
        self.poses.clear()
        self.planner.forget()
        for s in self.supervisors:
            s.restart()
        if self.goal is not None:
            self._set(State.DRIVING, 'clock jumped')

    def update_scan(self, scan: Scan, now: float) -> None:
        """Take a scan (its stamp: capture time), handled at ``now`` [s]."""
        self.scan, self.scan_time = scan, now

    def update_odom(self, stamp: float, pose: np.ndarray, now: float) -> bool:
        """Take an odometry pose; returns False when its stamp went back in time (the
        pose history is then cleared: a restarted simulator or driver)."""
        jumped = bool(self.poses) and stamp < self.poses[-1][0]
        if jumped:
            self.poses.clear()
        self.pose, self.odom_time = np.asarray(pose, float), now
        self.poses.append((stamp, self.pose))
        return not jumped

    def pose_between(self, stamp: float) -> np.ndarray:
        """The odometry pose at ``stamp`` [s], interpolated between the two poses around
        it (the oldest or the newest beyond them)."""
        poses = self.poses
        if not poses:
            return self.pose
        if stamp <= poses[0][0]:
            return poses[0][1]
        for (t0, p0), (t1, p1) in zip(reversed(list(poses)[:-1]), reversed(poses),
                                      strict=False):
            if t0 <= stamp <= t1:
                f = 0.0 if t1 <= t0 else (stamp - t0) / (t1 - t0)
                dyaw = math.remainder(p1[2] - p0[2], 2 * math.pi)
                return np.array([p0[0] + f * (p1[0] - p0[0]), p0[1] + f * (p1[1] - p0[1]),
                                 math.remainder(p0[2] + f * dyaw, 2 * math.pi)])
            if t1 < stamp:
                break
        return poses[-1][1]

    def sweep_motion(self, scan: Scan, start: np.ndarray | None = None) -> np.ndarray:
        """base_footprint's motion (x, y, yaw) from the scan's first beam to its last, in
        its pose at the first (``start``: pose_between(scan.stamp) if not given), as
        odometry says (zero for a scan taken at once)."""
        n = np.size(scan.ranges)
        if scan.beam_interval <= 0.0 or n < 2 or not math.isfinite(scan.stamp):
            return np.zeros(3)
        start = self.pose_between(scan.stamp) if start is None else start
        end = self.pose_between(scan.stamp + (n - 1) * scan.beam_interval)
        return np.asarray(compose(invert(start), end))

    def _deskewed(self, scan: Scan) -> tuple[Scan, Scan, np.ndarray]:
        """The scan as if taken at its first beam's instant (core/scan.py deskew), its
        ranges' noise averaged along each surface (core/scan.py denoise, by the lidar's
        range_noise_*): for the obstacles and the tracker, on the scan's grid of angles
        (each return at its own direction with deskew_bearings), and for the memory and
        the alignment, each return at its own direction (a return moved to the grid's
        beam is up to half a beam off, by an amount that changes along the sweep: each
        turn would bend the map) and at grazing incidence keeping its range
        (GRAZING_MEMORY); and the odometry pose at that instant, interpolated
        (pose_between); once per scan."""
        if self._deskew is None or self._deskew[0] is not scan:
            cfg = self.cfg
            start = self.pose_between(scan.stamp)
            motion = self.sweep_motion(scan, start)
            exact = deskew(scan, motion, cfg.laser_mount, True)
            straight = exact if cfg.deskew_bearings else deskew(scan, motion, cfg.laser_mount)
            obstacles, = denoise_each(straight, cfg.range_noise_floor,
                                      cfg.range_noise_fraction, (GRAZING_OBSTACLES,))
            memory, = denoise_each(exact, cfg.range_noise_floor, cfg.range_noise_fraction,
                                   (GRAZING_MEMORY,))
            self._deskew = (scan, obstacles, memory, start)
        return self._deskew[1], self._deskew[2], self._deskew[3]

    def silent(self, now: float) -> tuple[bool, bool]:
        """Whether the scan, and the odometry, are silent at ``now`` [s]: none taken
        yet, or the newest older than scan_timeout (odom_timeout)."""
        lim = self.limits
        return (self.scan_time is None or now - self.scan_time > lim.scan_timeout,
                self.odom_time is None or now - self.odom_time > lim.odom_timeout)

    def _set(self, state: State, reason: str) -> None:
        self.state, self.reason = state, reason

    def decide(self, command: tuple[float, float] | None, state: State, reason: str,
               result: PlanResult | None = None) -> Decision:
        """The tick's decision: publish ``command`` (None: nothing), in ``state``."""
        self._set(state, reason)
        return Decision(command, state, reason, result)

    def stop(self, state: State, reason: str, result: PlanResult | None = None) -> Decision:
        """The tick's decision: stand still in ``state`` (the planner's last command
        and what its stages keep for the goal are cleared)."""
        self.planner.reset()
        return self.decide((0.0, 0.0), state, reason, result)

    def hold(self) -> Decision:
        """The tick's decision: stand still in the state and for the reason as they are."""
        return Decision((0.0, 0.0), self.state, self.reason)

    def tick(self, now: float) -> Decision:
        """One planning period at time ``now`` [s]: the supervisors around one planning
        step (core/supervisors.py)."""
        for s in self.supervisors:
            decision = s.before(self, now)
            if decision is not None:
                return decision
        # the scan's pose where the sweep began, interpolated as _deskewed placed its beams
        # (the nearest odometry sample is up to half an odometry period off: at 2 m/s
        # and 20 Hz 5 cm, and the odometry calibration learnt that as a scale)
        scan, for_memory, scan_pose = self._deskewed(self.scan)
        result = self.planner.step(self.pose, self.goal, scan, scan_pose,
                                   now=now, goal_in_map=self.goal_in_map,
                                   memory_scan=for_memory)
        for s in self.supervisors:
            decision = s.after(self, result, now)
            if decision is not None:
                return decision
        cmd = result.command
        if cmd.status.stops:
            # standing for the first scans of a new memory is the normal start of a goal,
            # not a stop: its own state (the same zero command)
            state = State.MAPPING if cmd.status is Status.MAPPING else State.STOPPED
            return self.stop(state, cmd.status, result)
        return self.decide((cmd.v, cmd.w), State.DRIVING, cmd.status, result)
