"""The planner entry point: (pose, obstacles or scan, goal) -> command + diagnostics.

One planning cycle of ``subharmonic_sampling`` (the paper's full method):

1. laser returns -> point obstacles in odom (scan.py), voxel-downsampled for
   the repulsion sum;
2. raw next move point from the APF step, eq. (23) (apf.py);
3. circular sampling, Algorithm 1 and the Fig. 5 priority (sampling.py);
4. the chosen point -> (v, w) for the differential drive (command.py).

``subharmonic``, ``traditional`` and ``harmonic`` skip step 3 and steer to the
raw point (the paper's ablations); ``dwa`` replaces steps 2-4 (dwa.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .apf import apf_step
from .command import Command, forward_blocked, shape_command
from .config import PlannerConfig
from .dwa import dwa_command
from .sampling import SamplingResult, clearance, sample_and_choose
from .scan import ScanError, scan_to_points, voxel_downsample
from .status import Status

_EMPTY = np.zeros((0, 2))


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


def _finite_points(obstacles: ArrayLike) -> NDArray[np.float64]:
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    return obs[np.all(np.isfinite(obs), axis=1)]


def plan(cfg: PlannerConfig, pose: ArrayLike, goal: ArrayLike, obstacles: ArrayLike,
         previous: tuple[float, float] = (0.0, 0.0)) -> PlanResult:
    """One planning cycle. pose (x, y, yaw), goal (x, y), obstacles (m, 2), all in odom.

    Never raises for bad numbers: a non-finite pose or goal gives a stop with
    status ``invalid_pose`` / ``invalid_goal``; non-finite obstacle points are dropped.
    """
    pose = np.asarray(pose, float).ravel()
    goal = np.asarray(goal, float).ravel()
    if pose.shape != (3,) or not np.all(np.isfinite(pose)):
        return PlanResult(Command(0.0, 0.0, Status.INVALID_POSE))
    if goal.shape != (2,) or not np.all(np.isfinite(goal)):
        return PlanResult(Command(0.0, 0.0, Status.INVALID_GOAL))
    obs = _finite_points(obstacles)
    position = pose[:2]
    nearest = float(clearance(position, obs)[0])
    goal_distance = float(np.hypot(*(goal - position)))
    common = dict(obstacles=obs, nearest_distance=nearest, goal_distance=goal_distance)
    if goal_distance > cfg.goal_tolerance and float(clearance(goal, obs)[0]) < cfg.robot_radius:
        return PlanResult(Command(0.0, 0.0, Status.GOAL_IN_OBSTACLE), **common)
    if cfg.method == 'dwa':
        return _plan_dwa(cfg, pose, goal, obs, previous, common)
    repulsors = voxel_downsample(obs, cfg.voxel_size)
    raw = apf_step(position, goal, repulsors, cfg)[0]
    sampling = None
    target: NDArray | None = raw
    if cfg.method == 'subharmonic_sampling':
        sampling = sample_and_choose(raw, position, goal, obs, repulsors, cfg)
        target = sampling.chosen
    cmd = shape_command(pose, target, goal, previous, obs, cfg)
    return PlanResult(cmd, raw, target, sampling, **common)


def _plan_dwa(cfg: PlannerConfig, pose: NDArray, goal: NDArray, obs: NDArray,
              previous: tuple[float, float], common: dict) -> PlanResult:
    if common['goal_distance'] <= cfg.goal_tolerance:
        return PlanResult(Command(0.0, 0.0, Status.REACHED), **common)
    res = dwa_command(pose, goal, previous, voxel_downsample(obs, cfg.voxel_size), cfg)
    if not res.admissible:
        return PlanResult(Command(0.0, 0.0, Status.NO_SAFE_MOVE), **common)
    v, status = res.v, Status.DRIVING if res.v > 0.0 else Status.TURNING
    if v > 0.0 and forward_blocked(pose, obs, cfg):
        v, status = 0.0, Status.BLOCKED_AHEAD
    return PlanResult(Command(v, res.w, status), None, res.trajectory[-1].copy(), **common)


class Planner:
    """Stateful wrapper: remembers the last command for the acceleration limits."""

    def __init__(self, cfg: PlannerConfig) -> None:
        self.cfg = cfg
        self.previous: tuple[float, float] = (0.0, 0.0)

    def reset(self) -> None:
        """Forget the last command (after a stop, a new goal or a fault)."""
        self.previous = (0.0, 0.0)

    def step(self, pose: ArrayLike, goal: ArrayLike, obstacles: ArrayLike) -> PlanResult:
        """Plan from obstacle points in odom."""
        result = plan(self.cfg, pose, goal, obstacles, self.previous)
        self.previous = (result.command.v, result.command.w)
        return result

    def step_scan(self, pose: ArrayLike, goal: ArrayLike, ranges: ArrayLike, angle_min: float,
                  angle_increment: float, range_min: float, range_max: float,
                  scan_pose: ArrayLike | None = None) -> PlanResult:
        """Plan from a laser scan; see scan.scan_to_points.

        ``scan_pose`` is the robot's odom pose when the scan was taken (default:
        ``pose``); a robot that moved since is planned for from ``pose``.
        """
        cfg = self.cfg
        scan_pose = pose if scan_pose is None else scan_pose
        if not np.all(np.isfinite(np.asarray(pose, float))):
            return self.step(pose, goal, _EMPTY)
        try:
            pts = scan_to_points(ranges, angle_min, angle_increment, range_min, range_max,
                                 scan_pose, (cfg.laser_x, cfg.laser_y, cfg.laser_yaw),
                                 cfg.obstacle_range)
        except ScanError:
            self.reset()
            return PlanResult(Command(0.0, 0.0, Status.INVALID_SCAN))
        return self.step(pose, goal, pts)
