"""The planner entry point: (pose, obstacles or scan, goal) -> command + diagnostics.

One planning cycle of ``subharmonic_sampling`` (the paper's full method):

1. laser returns -> point obstacles in odom (scan.py), voxel-downsampled for
   the repulsion sum;
2. raw next move point from the APF step, eq. (23) (apf.py);
3. circular sampling, Algorithm 1 and the Fig. 5 priority (sampling.py);
4. the chosen point -> (v, w) for the differential drive (command.py).

With ``attraction_field: geodesic`` (the default) the scan also goes into the
occupancy memory, and the attraction of steps 2-3 is the navigation field
(memory.py, navigation.py) instead of the Euclidean eq. (21); a goal the field
cannot reach stops the robot with ``goal_unreachable``.

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
from .memory import NavigationMemory
from .navigation import NavigationField
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
    field: NavigationField | None = None


def _finite_points(obstacles: ArrayLike) -> NDArray[np.float64]:
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    return obs[np.all(np.isfinite(obs), axis=1)]


def local_radius(cfg: PlannerConfig) -> float:
    """Obstacle points farther than this from the robot cannot change a planning cycle of
    the APF methods [m]: the raw point and the samples lie within ``max_step + 2 *
    sample_radius`` of it, and no term looks farther than the repulsion's influence (a
    voxel's centroid may lie up to a voxel diagonal from its points), the Fig. 5
    priority distance, the discard distance or the safety corridor."""
    return (max(cfg.influence_distance + math.sqrt(2.0) * cfg.voxel_size,
                cfg.priority_distance, cfg.discard_distance, cfg.safety_distance)
            + cfg.max_step + 2.0 * cfg.sample_radius)


def plan(cfg: PlannerConfig, pose: ArrayLike, goal: ArrayLike, obstacles: ArrayLike,
         previous: tuple[float, float] = (0.0, 0.0),
         field: NavigationField | None = None) -> PlanResult:
    """One planning cycle. pose (x, y, yaw), goal (x, y), obstacles (m, 2), all in odom.
    ``field``: the navigation-function attraction (None: Euclidean, eq. 21).

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
        return _plan_dwa(cfg, pose, goal, obs, previous, common, field)
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
    return PlanResult(cmd, raw, target, sampling, field=field, **common)


def _plan_dwa(cfg: PlannerConfig, pose: NDArray, goal: NDArray, obs: NDArray,
              previous: tuple[float, float], common: dict,
              field: NavigationField | None) -> PlanResult:
    if common['goal_distance'] <= cfg.goal_tolerance:
        return PlanResult(Command(0.0, 0.0, Status.REACHED), **common)
    res = dwa_command(pose, goal, previous, voxel_downsample(obs, cfg.voxel_size), cfg, field)
    if not res.admissible:
        return PlanResult(Command(0.0, 0.0, Status.NO_SAFE_MOVE), **common)
    v, status = res.v, Status.DRIVING if res.v > 0.0 else Status.TURNING
    if v > 0.0 and forward_blocked(pose, obs, cfg):
        v, status = 0.0, Status.BLOCKED_AHEAD
    return PlanResult(Command(v, res.w, status), None, res.trajectory[-1].copy(), field=field,
                      **common)


class Planner:
    """Stateful wrapper: the last command (acceleration limits) and, with the geodesic
    attraction, the occupancy memory and its navigation field."""

    def __init__(self, cfg: PlannerConfig) -> None:
        self._cfg = cfg
        self.previous: tuple[float, float] = (0.0, 0.0)
        self.memory = NavigationMemory(cfg)

    @property
    def cfg(self) -> PlannerConfig:
        return self._cfg

    @cfg.setter
    def cfg(self, cfg: PlannerConfig) -> None:
        self._cfg = cfg
        self.memory.reconfigure(cfg)

    def reset(self) -> None:
        """Forget the last command (after a stop, a new goal or a fault); the map stays."""
        self.previous = (0.0, 0.0)

    def forget(self) -> None:
        """Forget the last command and the map (a restarted simulation)."""
        self.reset()
        self.memory.forget()

    def step(self, pose: ArrayLike, goal: ArrayLike, obstacles: ArrayLike,
             field: NavigationField | None = None) -> PlanResult:
        """Plan from obstacle points in odom (Euclidean attraction unless ``field``)."""
        result = plan(self.cfg, pose, goal, obstacles, self.previous, field)
        self.previous = (result.command.v, result.command.w)
        return result

    def step_scan(self, pose: ArrayLike, goal: ArrayLike, ranges: ArrayLike, angle_min: float,
                  angle_increment: float, range_min: float, range_max: float,
                  scan_pose: ArrayLike | None = None, stamp: float | None = None,
                  now: float | None = None) -> PlanResult:
        """Plan from a laser scan; see scan.scan_to_points.

        ``scan_pose`` is the robot's odom pose when the scan was taken (default:
        ``pose``); a robot that moved since is planned for from ``pose``. With the
        geodesic attraction the scan (identified by ``stamp`` [s]; None: always new)
        goes into the memory and the field is updated (``now`` [s] rate-limits it).
        """
        cfg = self.cfg
        scan_pose = pose if scan_pose is None else scan_pose
        if not np.all(np.isfinite(np.asarray(pose, float))) \
                or not np.all(np.isfinite(np.asarray(goal, float))):
            return self.step(pose, goal, _EMPTY)
        try:
            pts = scan_to_points(ranges, angle_min, angle_increment, range_min, range_max,
                                 scan_pose, (cfg.laser_x, cfg.laser_y, cfg.laser_yaw),
                                 cfg.obstacle_range)
        except ScanError:
            self.reset()
            return PlanResult(Command(0.0, 0.0, Status.INVALID_SCAN))
        if not cfg.geodesic or float(clearance(goal, pts)[0]) < cfg.robot_radius:
            return self.step(pose, goal, pts)   # (plan() stops for a goal in an obstacle)
        self.memory.integrate(ranges, angle_min, angle_increment, range_min, range_max,
                              scan_pose, math.nan if stamp is None else stamp, goal)
        field = self.memory.field_for(np.asarray(pose, float)[:2], goal, now)
        position = np.asarray(pose, float)[:2]
        if float(np.hypot(*(np.asarray(goal, float) - position))) > cfg.goal_tolerance and (
                field is None or not field.reachable(position)):
            self.reset()
            return PlanResult(Command(0.0, 0.0, Status.GOAL_UNREACHABLE), obstacles=pts,
                              field=field)
        return self.step(pose, goal, pts, field)
