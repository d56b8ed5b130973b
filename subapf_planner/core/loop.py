"""The decision loop, without ROS: input freshness, goal, progress, states.

One loop for everything that plans: ``planner_node`` feeds it messages as
arrays with their times and publishes what ``tick`` decides; the replay
(ros/replay.py) feeds it a recorded bag the same way; the benchmark's episode
(sim/episode.py) feeds it the simulator's scans and odometry on simulated time.
Times are seconds on the node's clock (simulated time under ``use_sim_time``).
Each ``tick`` supervises (goal, freshness, progress) and runs one planning step
(core/planner.py: perceive, gate, plan).

States (:class:`~.status.State`, the text of ``~/status`` before the colon):
idle, waiting, driving, reached, stopped, stuck (the progress checker gave the
goal up), unreachable (no way through the memory, or the goal inside an obstacle,
for ``unreachable_timeout``).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
import math

import numpy as np

from .config import PlannerConfig
from .memory import SAME_GOAL
from .occupancy import OccupancyGrid
from .params import check_fields, param
from .planner import Planner, PlanResult
from .scan import Scan
from .status import State, Status

#: Odometry poses kept to place each scan at the pose it was taken from.
POSE_HISTORY = 100
#: A scan is placed with the odometry pose nearest its stamp, if within this [s].
POSE_MATCH = 0.1
#: The progress checker waits while a moving obstacle is this close [m]: giving way to
#: someone is not being stuck.
GIVING_WAY_DISTANCE = 2.0


#: Statuses under which the goal cannot be reached for now; unreachable_timeout of them
#: ends the attempt.
NO_WAY = (Status.GOAL_UNREACHABLE, Status.GOAL_IN_OBSTACLE)


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
    recoveries: int = param(3, 'Times the progress checker, before it abandons the goal, '
                            'marks the place the field leads into as tried (blocked in the '
                            'field for avoid_time) so that the field leads along another way',
                            '', 0, 100)
    avoid_time: float = param(60.0, 'How long a tried place stays blocked in the field (then '
                              'it opens again: a door that was only briefly blocked)', 's',
                              1.0, 3600.0)
    unreachable_timeout: float = param(30.0, 'A goal unreachable through the memory, or '
                                       'inside an obstacle, this long ends the attempt '
                                       '(state unreachable); a way that opens before (a '
                                       'door, someone who walked off) restarts the clock',
                                       's', 1.0, 3600.0)

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
        self._progress: tuple[np.ndarray, float] | None = None
        self._unreachable_since: float | None = None
        self._tried = 0   # ways marked tried for this goal (recoveries)

    @property
    def cfg(self) -> PlannerConfig:
        return self.planner.cfg

    @cfg.setter
    def cfg(self, cfg: PlannerConfig) -> None:
        self.planner.cfg = cfg

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
        self.planner.previous = (float(command[0]), float(command[1]))

    @property
    def text(self) -> str:
        """The state as ``~/status`` carries it: ``"state: reason"``."""
        return f'{self.state}: {self.reason}'

    def set_goal(self, goal: np.ndarray, in_map: bool = False) -> bool:
        """A new goal resets the planner; the goal being driven to (or waited for: no
        inputs yet), sent again, does not, whenever it arrives (a stuck or stopped robot
        retries it). Returns whether the goal was new. ``goal`` (x, y) is in odom (the
        place odom puts there now), or with ``in_map`` in the memory's frame (the place
        in the world, as odom was at the start: what the scan alignment keeps still)."""
        goal = np.asarray(goal, float)
        if self.goal is not None and self.state in (State.DRIVING, State.WAITING) \
                and np.hypot(*(goal - self.goal)) < SAME_GOAL \
                and in_map == self.goal_in_map:
            return False
        self.goal, self.goal_in_map = goal.copy(), bool(in_map)
        self.planner.reset()
        self._progress = self._unreachable_since = None
        self._tried = 0
        self._set(State.DRIVING, 'new goal')
        return True

    def clock_jumped(self) -> None:
        """The clock jumped (a restarted simulation, a bag played from elsewhere): forget
        every input and its time, keep the goal, and wait for fresh data."""
        self.scan = self.scan_time = self.pose = self.odom_time = None
        self.poses.clear()
        self.planner.forget()
        self._progress = self._unreachable_since = None
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

    def pose_at(self, stamp: float) -> np.ndarray:
        """Odometry pose nearest ``stamp`` (within POSE_MATCH; the newest on a tie),
        else the newest."""
        best, nearest = math.inf, self.pose
        for t, pose in reversed(self.poses):   # stamps never fall: nearer, then farther
            gap = abs(t - stamp)
            if gap > best:
                break
            if gap < best:
                best, nearest = gap, pose
        return nearest if best <= POSE_MATCH else self.pose

    def _set(self, state: State, reason: str) -> None:
        self.state, self.reason = state, reason

    def _decide(self, command: tuple[float, float] | None, state: State, reason: str,
                result: PlanResult | None = None) -> Decision:
        self._set(state, reason)
        return Decision(command, state, reason, result)

    def silent(self, now: float) -> tuple[bool, bool]:
        """Whether the scan, and the odometry, are silent at ``now`` [s]: none taken
        yet, or the newest older than scan_timeout (odom_timeout)."""
        lim = self.limits
        return (self.scan_time is None or now - self.scan_time > lim.scan_timeout,
                self.odom_time is None or now - self.odom_time > lim.odom_timeout)

    def _stop(self, state: State, reason: str, result: PlanResult | None = None) -> Decision:
        self.planner.reset()
        return self._decide((0.0, 0.0), state, reason, result)

    def tick(self, now: float) -> Decision:
        """One planning period at time ``now`` [s]."""
        lim = self.limits
        if self.goal is None:
            return self._decide(None, State.IDLE, 'no goal')
        if self.scan is None or self.pose is None:
            return self._decide(None, State.WAITING,
                                f'no {"scan" if self.scan is None else "odom"} yet')
        scan_silent, odom_silent = self.silent(now)
        if scan_silent:
            return self._stop(State.STOPPED, 'scan is stale')
        if odom_silent:
            return self._stop(State.STOPPED, 'odometry is stale')
        if self.state.gave_up:
            return Decision((0.0, 0.0), self.state, self.reason)
        result = self.planner.step(self.pose, self.goal, self.scan,
                                   self.pose_at(self.scan.stamp), now,
                                   goal_in_map=self.goal_in_map)
        cmd = result.command
        if cmd.status is Status.REACHED:
            self.goal = None
            return self._stop(State.REACHED, 'goal within tolerance', result)
        if self._unreachable_too_long(cmd.status, now):
            tried = f' (every way tried: {self._tried})' if self._tried else ''
            return self._stop(State.UNREACHABLE, f'no way to the goal for '
                              f'{lim.unreachable_timeout:g} s{tried}, goal abandoned', result)
        if _giving_way(result, self.pose):
            self._progress = None
        if cmd.status.stops:
            if cmd.status is Status.NO_SAFE_MOVE and self._no_progress(now):
                return self._recover(result, (0.0, 0.0), now)   # standing at a gap
            return self._stop(State.STOPPED, cmd.status, result)
        if self._no_progress(now):
            return self._recover(result, (cmd.v, cmd.w), now)
        return self._decide((cmd.v, cmd.w), State.DRIVING, cmd.status, result)

    def _recover(self, result: PlanResult, command: tuple[float, float],
                 now: float) -> Decision:
        """No progress: mark the way ahead tried (Planner.avoid_ahead) and go on, at most
        ``recoveries`` times for a goal; then abandon it (state stuck)."""
        lim = self.limits
        if self._tried < lim.recoveries and self.planner.avoid_ahead(now + lim.avoid_time):
            self._tried += 1
            self._progress = None
            return self._decide(command, State.DRIVING,
                                f'no progress: the way ahead marked tried ({self._tried} of '
                                f'{lim.recoveries}), another way', result)
        return self._stop(State.STUCK, 'no progress, goal abandoned', result)

    def _unreachable_too_long(self, status: Status, now: float) -> bool:
        """Whether ``goal_unreachable`` or ``goal_in_obstacle`` (NO_WAY: a goal the
        robot cannot stand at is no nearer) has lasted longer than unreachable_timeout
        (any other status restarts the clock)."""
        if status not in NO_WAY:
            self._unreachable_since = None
            return False
        if self._unreachable_since is None:
            self._unreachable_since = now
        return now - self._unreachable_since > self.limits.unreachable_timeout

    def _no_progress(self, now: float) -> bool:
        if self._progress is None or np.hypot(*(self.pose[:2] - self._progress[0])) >= \
                self.limits.progress_distance:
            self._progress = (self.pose[:2].copy(), now)
            return False
        return now - self._progress[1] > self.limits.progress_timeout


def _giving_way(result: PlanResult, pose: np.ndarray) -> bool:
    """A moving track is within GIVING_WAY_DISTANCE of the robot (at ``pose`` in odom,
    or the result's own pose: the tracks are in the memory's frame)."""
    t = result.tracks
    if not np.any(t.moving):
        return False
    pose = pose if result.pose is None else result.pose
    return bool(np.min(np.hypot(*(t.position[t.moving] - pose[:2]).T)) < GIVING_WAY_DISTANCE)
