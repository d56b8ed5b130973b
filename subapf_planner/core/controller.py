"""The planner node's decisions, without ROS: input freshness, goal, progress, states.

``planner_node`` feeds it messages as arrays with their times and publishes
what ``tick`` decides; ``subapf-replay`` feeds it a recorded bag the same way,
so a replay reproduces the node's commands. Times are seconds on the node's
clock (simulated time under ``use_sim_time``).

States (the text of ``~/status`` before the colon): idle, waiting, driving,
reached, stopped, stuck.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from .config import PlannerConfig
from .planner import Planner, PlanResult

#: Odometry poses kept to place each scan at the pose it was taken from.
POSE_HISTORY = 100
#: A scan is placed with the odometry pose nearest its stamp, if within this [s].
POSE_MATCH = 0.1
#: Goals closer than this to the current one are the same goal [m].
SAME_GOAL = 1e-3
#: Core statuses that stop the robot.
STOP_STATUSES = ('no_safe_move', 'goal_in_obstacle', 'invalid_scan', 'invalid_pose',
                 'invalid_goal')


@dataclass(frozen=True)
class Supervision:
    """Node-level limits (config/planner.yaml, node section)."""

    scan_timeout: float = 1.0
    odom_timeout: float = 0.5
    progress_distance: float = 0.5
    progress_timeout: float = 10.0


@dataclass(frozen=True)
class ScanInput:
    """A scan's arrays and stamp [s] (see conversions.ScanArrays)."""

    ranges: np.ndarray
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    stamp: float


@dataclass(frozen=True)
class Decision:
    """What to publish: a command (None: publish nothing), the state, the plan if any."""

    command: tuple[float, float] | None
    state: str
    result: PlanResult | None = None


class PlannerController:
    """One robot's planning loop state. Not thread-safe; call from one executor."""

    def __init__(self, cfg: PlannerConfig, limits: Supervision | None = None) -> None:
        self.planner = Planner(cfg)
        self.limits = limits or Supervision()
        self.scan: ScanInput | None = None
        self.scan_time: float | None = None
        self.pose: np.ndarray | None = None
        self.odom_time: float | None = None
        self.poses: deque = deque(maxlen=POSE_HISTORY)
        self.goal: np.ndarray | None = None
        self.state = 'idle: no goal'
        self._progress: tuple[np.ndarray, float] | None = None

    @property
    def cfg(self) -> PlannerConfig:
        return self.planner.cfg

    @cfg.setter
    def cfg(self, cfg: PlannerConfig) -> None:
        self.planner.cfg = cfg

    def set_goal(self, goal: np.ndarray) -> bool:
        """A new goal resets the planner; the goal being driven to, sent again while
        driving, does not (a stuck or stopped robot retries it).
        Returns whether the goal was new."""
        goal = np.asarray(goal, float)
        if self.goal is not None and self.state.startswith('driving') \
                and np.hypot(*(goal - self.goal)) < SAME_GOAL:
            return False
        self.goal = goal.copy()
        self.planner.reset()
        self._progress = None
        self.state = 'driving: new goal'
        return True

    def clock_jumped(self) -> None:
        """The clock jumped (a restarted simulation, a bag played from elsewhere): forget
        every input and its time, keep the goal, and wait for fresh data."""
        self.scan = self.scan_time = self.pose = self.odom_time = None
        self.poses.clear()
        self.planner.reset()
        self._progress = None
        if self.goal is not None:
            self.state = 'driving: clock jumped'

    def update_scan(self, scan: ScanInput, now: float) -> None:
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
        t, pose = min(reversed(self.poses), key=lambda tp: abs(tp[0] - stamp))
        return pose if abs(t - stamp) <= POSE_MATCH else self.pose

    def _stop(self, state: str) -> Decision:
        self.planner.reset()
        self.state = state
        return Decision((0.0, 0.0), state)

    def tick(self, now: float) -> Decision:
        """One planning period at time ``now`` [s]."""
        lim = self.limits
        if self.goal is None:
            self.state = 'idle: no goal'
            return Decision(None, self.state)
        if self.scan is None or self.pose is None:
            self.state = f'waiting: no {"scan" if self.scan is None else "odom"} yet'
            return Decision(None, self.state)
        if now - self.scan_time > lim.scan_timeout:
            return self._stop('stopped: scan is stale')
        if now - self.odom_time > lim.odom_timeout:
            return self._stop('stopped: odometry is stale')
        if self.state.startswith('stuck'):
            return Decision((0.0, 0.0), self.state)
        s = self.scan
        result = self.planner.step_scan(self.pose, self.goal, s.ranges, s.angle_min,
                                        s.angle_increment, s.range_min, s.range_max,
                                        self.pose_at(s.stamp))
        cmd = result.command
        if cmd.status == 'reached':
            self.goal = None
            decision = self._stop('reached: goal within tolerance')
        elif cmd.status in STOP_STATUSES:
            decision = self._stop(f'stopped: {cmd.status}')
        elif self._no_progress(now):
            decision = self._stop('stuck: no progress, goal abandoned')
        else:
            self.state = f'driving: {cmd.status}'
            decision = Decision((cmd.v, cmd.w), self.state)
        return Decision(decision.command, decision.state, result)

    def _no_progress(self, now: float) -> bool:
        if self._progress is None or np.hypot(*(self.pose[:2] - self._progress[0])) >= \
                self.limits.progress_distance:
            self._progress = (self.pose[:2].copy(), now)
            return False
        return now - self._progress[1] > self.limits.progress_timeout
