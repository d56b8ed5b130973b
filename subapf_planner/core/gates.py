"""Gates: the stages that may stop a cycle before anything is planned (core/cycle.py).

In the order :func:`~subapf_planner.core.pipeline.stage_names` runs them:

* ``goal``: the goal reached (within ``goal_tolerance``; with the memory, once the
  approach is over: see :class:`Goal`) or inside an obstacle (a laser point within
  ``robot_radius`` of it);
* ``mapping`` (with the scan alignment): the robot stands until the memory holds its
  first scans and its walls hold a match of the scan to them, so that the memory's
  frame is odom at the start and a first turn is matched as it is made;
* ``reachability`` (with the memory): the navigation field to the goal, and
  ``goal_unreachable`` when the memory holds no way to it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .alignment import MIN_MATCHED
from .config import PlannerConfig
from .cycle import Cycle, Stage
from .memory import NavigationMemory
from .sampling import clearance
from .status import Status

#: With the scan alignment, the robot stands until the memory holds this many scans
#: (the occupancy grid's walls are established by three hits) and, unless the scan holds
#: too few returns for a match (alignment.MIN_MATCHED: a hall wider than the lidar's
#: reach), a scan's match to the memory has been accepted: through the LDS-01's noise a
#: wall's returns scatter over several cells, three scans establish too few of them, and
#: a first turn made before the walls hold a match kept its drift for the whole run
#: (docs/alignment.md) ...
FIRST_SCANS = 3
#: ... for this long at most [s] (what is seen may hold no match).
MAPPING_TIME = 2.0
#: Inside goal_tolerance the approach goes on while the robot gets this much closer to the
#: goal than it has been [m] at least once every ARRIVAL_PATIENCE [s]: a cycle or two
#: spent turning towards the goal (a few centimetres off its axis the heading to it is
#: steep) does not end it, a robot that cannot get closer stops (arrival_distance). The
#: time the robot needs to turn to face the goal at its top turn rate is added.
ARRIVAL_PROGRESS = 0.002
ARRIVAL_PATIENCE = 1.0


def input_status(pose: ArrayLike, goal: ArrayLike) -> Status | None:
    """``invalid_pose`` for a pose that is not three finite numbers (x, y, yaw),
    ``invalid_goal`` for a goal that is not two; None when both are fine."""
    if np.shape(pose) != (3,) or not all(math.isfinite(v) for v in pose):
        return Status.INVALID_POSE
    if np.shape(goal) != (2,) or not all(math.isfinite(v) for v in goal):
        return Status.INVALID_GOAL
    return None


def goal_status(cfg: PlannerConfig, goal_distance: float, goal: NDArray[np.float64],
                obstacles: NDArray[np.float64]) -> Status | None:
    """``reached`` within goal_tolerance of the goal, ``goal_in_obstacle`` when a laser
    point lies within robot_radius of it (the robot could not stand there; with the
    memory, within robot_radius - goal_slack: the field leads to a place up to
    goal_slack from a goal a noisy lidar shows too close to a wall); None otherwise."""
    if goal_distance <= cfg.goal_tolerance:
        return Status.REACHED
    slack = cfg.goal_slack if cfg.geodesic else 0.0
    if float(clearance(goal, obstacles)[0]) < cfg.robot_radius - slack:
        return Status.GOAL_IN_OBSTACLE
    return None


class Goal(Stage):
    """``reached`` or ``goal_in_obstacle`` (:func:`goal_status`). With the memory, the
    approach goes on inside goal_tolerance while the robot is farther than
    ``arrival_distance`` and gets ARRIVAL_PROGRESS closer than it has been at least once
    every ARRIVAL_PATIENCE, plus the time to turn to face the goal (a pose error of a
    few centimetres still leaves it inside the tolerance)."""

    name = 'goal'

    def __init__(self) -> None:
        #: Inside the tolerance: the goal, the least distance to it so far and when [s].
        self._approach: tuple[NDArray, float, float] | None = None

    def forget(self) -> None:
        self._approach = None

    def run(self, cycle: Cycle) -> Cycle:
        status = goal_status(cycle.cfg, cycle.goal_distance, cycle.goal, cycle.obstacles)
        if status is Status.REACHED and self.drives_on(cycle):
            status = None
        if cycle.goal_distance > cycle.cfg.goal_tolerance:
            self._approach = None
        return cycle.with_(status=status)

    def drives_on(self, cycle: Cycle) -> bool:
        """Inside goal_tolerance: whether to drive on (geodesic only; see the class)."""
        cfg, distance = cycle.cfg, cycle.goal_distance
        if not cfg.geodesic or distance <= cfg.arrival_distance:
            return False
        if self._approach is None or not np.array_equal(self._approach[0], cycle.goal) \
                or distance <= self._approach[1] - ARRIVAL_PROGRESS:
            self._approach = (cycle.goal, distance, cycle.now)   # closer than ever: on
            return True
        # a goal the robot must first turn to (behind it, after passing it) adds that turn
        x, y, yaw = cycle.pose
        turn = abs(math.remainder(math.atan2(cycle.goal[1] - y, cycle.goal[0] - x) - yaw,
                                  2.0 * math.pi))
        return cycle.now - self._approach[2] < ARRIVAL_PATIENCE + turn / max(
            cfg.max_angular_velocity, 1e-9)


class Mapping(Stage):
    """``mapping`` while the memory holds fewer than FIRST_SCANS scans (for FIRST_SCANS
    cycles at most: a scan repeated with the same stamp is not taken twice) or, while the
    scan holds enough returns for a match, none has been matched to its walls yet
    (Cycle.aligned); MAPPING_TIME at most from the first cycle it stood; not once the
    robot is inside the goal tolerance. Once over, it does not come back for the same
    memory."""

    name = 'mapping'

    def __init__(self) -> None:
        self._since: float | None = None   # when it first stood [s]
        self._cycles = 0   # cycles stood so far
        self._over = False

    def forget(self) -> None:
        self._since, self._cycles, self._over = None, 0, False

    def run(self, cycle: Cycle) -> Cycle:
        if self._over or cycle.goal_distance <= cycle.cfg.goal_tolerance:
            return cycle
        if self._since is None:
            self._since = cycle.now
        first = cycle.memory_scans >= FIRST_SCANS or self._cycles >= FIRST_SCANS
        matchable = np.count_nonzero(np.isfinite(cycle.points).all(axis=1)) >= MIN_MATCHED
        if (first and (cycle.aligned or not matchable)) \
                or cycle.now - self._since >= MAPPING_TIME:
            self._over = True
            return cycle
        self._cycles += 1
        return cycle.with_(status=Status.MAPPING)


class Reachability(Stage):
    """The navigation field to the goal through the memory (core/memory.py);
    ``goal_unreachable`` when there is none or the robot's position has no value in it
    (no way; why: NavigationMemory.no_way)."""

    name = 'reachability'

    def __init__(self, memory: NavigationMemory) -> None:
        self.memory = memory

    def run(self, cycle: Cycle) -> Cycle:
        field, new = self.memory.field_for(cycle.pose[:2], cycle.goal, cycle.now)
        if field is not None and field.reachable(cycle.pose[:2]):
            return cycle.with_(field=field, new_field=new)
        return cycle.with_(field=field, new_field=new, status=Status.GOAL_UNREACHABLE,
                           no_way=self.memory.no_way(cycle.pose[:2], cycle.goal))
