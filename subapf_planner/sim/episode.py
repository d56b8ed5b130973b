"""One benchmark run: the simulator and the node's decision loop, in one process.

At each planning period the ``DecisionLoop`` (the loop ``planner_node``
runs) gets the simulator's odometry and the scans that the fault model
delivers, on simulated time: staleness stops, the progress checker and the
goal states apply as in the node. Its command goes to the simulated base (no
command while it waits: the base's watchdog stops the robot, as on a real
burger); the simulator then advances one period. No DDS and no wall-clock
sleeping, so a run takes milliseconds per simulated second. The loop under
``subapf-bench``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import time

import numpy as np

from ..core.config import PlannerConfig
from ..core.known_map import KnownMap
from ..core.loop import DecisionLoop, Supervision
from ..core.robot import ROBOTS
from ..core.scan import Scan
from ..core.status import Outcome, State
from .faults import FAULT_SEED_OFFSET, ScanDelivery, ScanFaults, delivery_faults
from .metrics import mean_abs_curvature, min_clearance, path_length
from .outcome import outcome_of
from .simulator import RobotSim, SimConfig
from .world import World

#: How a run ends when the planner gives the goal up.
GAVE_UP = {State.STUCK: Outcome.ABANDONED, State.UNREACHABLE: Outcome.UNREACHABLE}


@dataclass(frozen=True)
class EpisodeResult:
    """Outcome and metrics of one run; ``path`` is the ground truth (k, 3) per cycle."""

    world: str
    method: str
    outcome: Outcome
    time_s: float
    path: np.ndarray
    plan_ms: np.ndarray
    final_distance: float
    statuses: dict[str, int] = field(default_factory=dict)
    #: Per planning cycle, whether it computed a new navigation field.
    field_recomputed: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))
    #: Simulated time of each ``path`` point [s].
    times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: A collision with the base commanded to stand still (it counts as a collision).
    hit_while_stopped: bool = False
    #: Per new navigation field, how long computing it took [ms] (in the cycle, or on
    #: the memory's worker thread between cycles: core/memory.py).
    field_ms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: Per tick, how long the work after its command took [ms]
    #: (DecisionLoop.after_tick: the scan matched to and written into the memory).
    after_ms: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: Per planning cycle, the distance from the pose the planner planned from (odometry
    #: corrected by the scan alignment) to the true pose [m] (the memory's frame is the
    #: world's: the simulator's odom starts at the world's start pose).
    pose_error: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: Whether anything in the world moves (evading in a world where nothing does is a
    #: ghost's doing).
    moving_world: bool = False
    #: Per planning cycle (with pose_error), odometry's own distance to the true pose [m].
    odom_error: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: The decision loop's state and reason at the end ('unreachable: no way to the goal
    #: for 30 s (why), goal abandoned').
    final_state: str = ''
    #: The robot simulated (core/robot.py ROBOTS).
    robot: str = 'burger'

    @property
    def cycles(self) -> int:
        return int(self.plan_ms.size)

    def metrics(self, world: World) -> dict[str, float | int | str]:
        """The results.json record of this run (docs/results.md)."""
        return {
            'world': self.world,
            'method': self.method,
            'outcome': str(self.outcome),
            'time_s': round(self.time_s, 3),
            'path_length': round(path_length(self.path), 4),
            'min_clearance': round(min_clearance(world, self.path, self.times,
                                                 ROBOTS[self.robot]), 4),
            'mean_abs_curvature': round(mean_abs_curvature(self.path), 4),
            'plan_ms_median': round(float(np.median(self.plan_ms)), 4) if self.cycles else 0.0,
            'plan_ms_p99': round(float(np.percentile(self.plan_ms, 99)), 4)
            if self.cycles else 0.0,
            'cycles': self.cycles,
            'final_distance': round(self.final_distance, 4),
            'goal_tolerance': world.goal_tolerance,
            'statuses': dict(self.statuses),
            'hit_while_stopped': self.hit_while_stopped,
            'pose_error_final': round(float(self.pose_error[-1]), 4)
            if self.pose_error.size else None,
            'pose_error_max': round(float(self.pose_error.max()), 4)
            if self.pose_error.size else None,
            'odom_error_final': round(float(self.odom_error[-1]), 4)
            if self.odom_error.size else None,
            'evading_cycles': int(self.statuses.get('evading', 0)),
            'moving_world': self.moving_world,
            'final_state': self.final_state,
            'robot': self.robot,
        }


def run_episode(world: World, cfg: PlannerConfig, sim_cfg: SimConfig | None = None,
                time_limit: float | None = None, faults: ScanFaults | None = None,
                limits: Supervision | None = None, label: str | None = None,
                known_map: KnownMap | None = None) -> EpisodeResult:
    """Drive the world's start to its goal until the planner stops there by its own
    estimate (``reached`` when the truth is inside the world's tolerance then,
    ``missed`` when it is not: outcome_of), gives the goal up (``abandoned``: the
    progress checker; ``unreachable``: no way through its memory for
    ``unreachable_timeout``), collides or runs out of time. ``label`` names the method
    in the result (default ``cfg.method``). ``known_map``: the memory starts from it
    (sim/solvability.world_map: the world's static obstacles)."""
    sim_cfg = sim_cfg or SimConfig()
    delivery: ScanDelivery[Scan] = ScanDelivery(delivery_faults(sim_cfg, faults),
                                                sim_cfg.seed + FAULT_SEED_OFFSET)
    cfg = cfg.replace(goal_tolerance=min(cfg.goal_tolerance, world.goal_tolerance))
    ctl = DecisionLoop(cfg, limits)
    if known_map is not None:
        ctl.know(known_map)
    ctl.set_goal(np.asarray(world.goal, float), in_map=True)   # a place in the world
    path, times, plan_ms, recomputed, statuses, field_ms, after_ms = [], [], [], [], {}, [], []
    pose_error = []   # per planning cycle: the planned-from pose's distance to the truth
    odom_error = []   # ... and odometry's own
    with RobotSim(world, sim_cfg) as sim:
        while True:
            truth = sim.true_pose()
            path.append(truth)
            times.append(sim.time)
            outcome = outcome_of(world, truth, sim.collided, sim.time, time_limit,
                                 stopped_at_goal=ctl.state is State.REACHED)
            if outcome is None and ctl.state.gave_up:
                outcome = GAVE_UP[ctl.state]
            if outcome is not None:
                break
            now = sim.time
            odom, _ = sim.odometry()
            ctl.update_odom(now, odom, now)
            for sweep in sim.sweeps():
                delivery.capture(sweep, sim.sweep_end(sweep))
            for scan in delivery.due(now):
                ctl.update_scan(scan, now)
            ctl.settle()   # as a node's idle time between ticks would (not timed)
            t0 = time.perf_counter()
            decision = ctl.tick(now)
            if decision.result is not None:
                plan_ms.append((time.perf_counter() - t0) * 1e3)
                recomputed.append(decision.result.new_field)
                if decision.result.pose is not None:
                    pose_error.append(float(np.hypot(*(decision.result.pose[:2]
                                                       - truth[:2]))))
                    odom_error.append(float(np.hypot(*(odom[:2] - truth[:2]))))
                if decision.result.new_field:
                    field_ms.append(ctl.field_seconds * 1e3)
            key = str(decision.result.command.status) if decision.result is not None \
                else decision.text
            statuses[key] = statuses.get(key, 0) + 1
            if decision.command is not None:
                sim.set_command(*decision.command)
            t0 = time.perf_counter()
            ctl.after_tick()   # as the node does once the command is out
            after_ms.append((time.perf_counter() - t0) * 1e3)
            sim.step(cfg.period)
        final = float(np.hypot(*(sim.true_pose()[:2] - np.asarray(world.goal, float))))
        elapsed = sim.time
        hit_while_stopped = outcome is Outcome.COLLISION and sim.hit_while_stopped
    return EpisodeResult(world.name, label or cfg.method, outcome, elapsed, np.asarray(path),
                         np.asarray(plan_ms), final, statuses, np.asarray(recomputed, bool),
                         np.asarray(times), hit_while_stopped, np.asarray(field_ms),
                         np.asarray(after_ms), np.asarray(pose_error), bool(world.moving),
                         np.asarray(odom_error), ctl.text, sim_cfg.robot)
