"""One benchmark run: simulator and planner in lockstep, in one process.

At each planning period the planner gets the current scan and odometry,
its command is applied, and the simulator advances one period of simulated
time. No DDS and no wall-clock sleeping, so a run takes milliseconds per
simulated second. The same loop underlies ``subapf-bench``.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
import math
import time

import numpy as np

from ..core.config import PlannerConfig
from ..core.planner import Planner
from .simulator import BurgerSim, SimConfig
from .world import FOOTPRINT_RADIUS, World

OUTCOMES = ('reached', 'collision', 'timeout')


@dataclass(frozen=True)
class EpisodeResult:
    """Outcome and metrics of one run; ``path`` is the ground truth (k, 3) per cycle."""

    world: str
    method: str
    outcome: str
    time_s: float
    path: np.ndarray
    plan_ms: np.ndarray
    final_distance: float
    statuses: dict[str, int] = field(default_factory=dict)

    @property
    def cycles(self) -> int:
        return int(self.plan_ms.size)

    def metrics(self, world: World) -> dict[str, float | int | str]:
        """The results.json record of this run (see README 'Benchmark')."""
        return {
            'world': self.world,
            'method': self.method,
            'outcome': self.outcome,
            'time_s': round(self.time_s, 3),
            'path_length': round(path_length(self.path), 4),
            'min_clearance': round(min_clearance(world, self.path), 4),
            'mean_abs_curvature': round(mean_abs_curvature(self.path), 4),
            'plan_ms_median': round(float(np.median(self.plan_ms)), 4) if self.cycles else 0.0,
            'plan_ms_p99': round(float(np.percentile(self.plan_ms, 99)), 4)
            if self.cycles else 0.0,
            'cycles': self.cycles,
            'final_distance': round(self.final_distance, 4),
            'goal_tolerance': world.goal_tolerance,
            'statuses': dict(self.statuses),
        }


def path_length(path: np.ndarray) -> float:
    """Length of the driven polyline [m]."""
    if len(path) < 2:
        return 0.0
    return float(np.sum(np.hypot(*np.diff(path[:, :2], axis=0).T)))


def min_clearance(world: World, path: np.ndarray) -> float:
    """Smallest gap between the footprint (radius 0.105 m) and an obstacle surface [m]."""
    if len(path) == 0:
        return math.nan
    return min(world.clearance(float(x), float(y)) for x, y in path[:, :2]) - FOOTPRINT_RADIUS


def mean_abs_curvature(path: np.ndarray, min_segment: float = 0.01) -> float:
    """Mean |turning angle| / segment length over the polyline [1/m] (smoothness).

    Points closer than ``min_segment`` to the previous kept point are skipped,
    so turning on the spot does not divide by zero.
    """
    pts = [path[0, :2]] if len(path) else []
    for p in path[1:, :2]:
        if np.hypot(*(p - pts[-1])) >= min_segment:
            pts.append(p)
    if len(pts) < 3:
        return 0.0
    seg = np.diff(np.asarray(pts), axis=0)
    heading = np.arctan2(seg[:, 1], seg[:, 0])
    turn = np.abs(np.remainder(np.diff(heading) + np.pi, 2 * np.pi) - np.pi)
    lengths = np.hypot(seg[:, 0], seg[:, 1])
    return float(np.mean(turn / (0.5 * (lengths[1:] + lengths[:-1]))))


@dataclass(frozen=True)
class Faults:
    """Sensor faults between simulator and planner: a scan is lost with probability
    ``scan_dropout`` (the planner keeps the last one it got) and reaches the planner
    ``scan_delay`` planning periods after capture (placed with the pose at capture)."""

    scan_dropout: float = 0.0
    scan_delay: int = 0

    def __post_init__(self) -> None:
        if not 0.0 <= self.scan_dropout < 1.0:
            raise ValueError(f'scan_dropout: {self.scan_dropout} is outside [0, 1)')
        if not 0 <= self.scan_delay <= 50:
            raise ValueError(f'scan_delay: {self.scan_delay} is outside [0, 50] periods')


def run_episode(world: World, cfg: PlannerConfig, sim_cfg: SimConfig | None = None,
                time_limit: float | None = None, faults: Faults | None = None) -> EpisodeResult:
    """Drive the world's start to its goal with ``cfg.method``; stop at the first outcome."""
    limit = world.time_limit if time_limit is None else time_limit
    faults = faults or Faults()
    rng = np.random.default_rng((sim_cfg.seed if sim_cfg else 0) + 7919)
    in_flight: deque = deque()   # (scan, odom pose at capture) not yet delivered
    delivered = None
    goal = np.asarray(world.goal, float)
    cfg = cfg.replace(goal_tolerance=min(cfg.goal_tolerance, world.goal_tolerance))
    planner = Planner(cfg)
    path, plan_ms, statuses = [], [], {}
    outcome = 'timeout'
    with BurgerSim(world, sim_cfg) as sim:
        while True:
            truth = sim.true_pose()
            path.append(truth)
            if np.hypot(*(truth[:2] - goal)) <= world.goal_tolerance:
                outcome = 'reached'
                break
            if sim.collided:
                outcome = 'collision'
                break
            if sim.time >= limit - 1e-9:
                break
            odom, _ = sim.odometry()
            if rng.random() >= faults.scan_dropout:
                in_flight.append((sim.scan(), odom))
            while in_flight and len(in_flight) > faults.scan_delay:
                delivered = in_flight.popleft()
            if delivered is None:   # nothing has arrived yet: wait, as the node does
                sim.step(cfg.period)
                continue
            scan, scan_pose = delivered
            t0 = time.perf_counter()
            result = planner.step_scan(odom, goal, scan.ranges, scan.angle_min,
                                       scan.angle_increment, scan.range_min, scan.range_max,
                                       scan_pose)
            plan_ms.append((time.perf_counter() - t0) * 1e3)
            status = result.command.status
            statuses[status] = statuses.get(status, 0) + 1
            sim.set_command(result.command.v, result.command.w)
            sim.step(cfg.period)
        final = float(np.hypot(*(sim.true_pose()[:2] - goal)))
        elapsed = sim.time
    return EpisodeResult(world.name, cfg.method, outcome, elapsed, np.asarray(path),
                         np.asarray(plan_ms), final, statuses)
