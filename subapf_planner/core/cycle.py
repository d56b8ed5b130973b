"""One planning cycle as a value, and the stages that work on it.

:meth:`Planner.step <subapf_planner.core.planner.Planner.step>` builds a :class:`Cycle`
from the inputs (the robot's pose, the goal and the scan's returns placed in the
memory's frame, the moving tracks, the time) and hands it along its stages, each a
small object with a ``name`` and a ``run(cycle) -> cycle``:

* **gates** (core/gates.py) may stop the cycle with a status (the goal reached or
  inside an obstacle, the first scans being mapped, no way through the memory); the
  first gate that sets ``status`` ends the gates;
* one **proposer** (core/proposers.py: the APF step with circular sampling and its
  critics, the APF step alone, DWA) turns a cycle no gate stopped into a command;
* **filters** (core/approach.py, core/filters.py) see every cycle's command and may
  replace it (the approach to the goal inside its tolerance, the evasion of moving
  obstacles).

Which stages run follows from the parameters (:func:`~subapf_planner.core.pipeline.
stage_names`). A stage keeps what it must remember between cycles in itself, changes
nothing else, and forgets it on ``reset`` (a stop or a new goal) or ``forget`` (a new
world); it reads its parameters from ``cycle.cfg``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import NDArray

from .command import Command
from .config import PlannerConfig
from .navigation import NavigationField
from .sampling import SamplingResult
from .status import Status
from .tracking import NO_TRACKS, Tracks

_EMPTY = np.zeros((0, 2))


@dataclass(frozen=True)
class PlanResult:
    """Command and what led to it (points in the memory's frame, metres)."""

    command: Command
    raw_point: NDArray[np.float64] | None = None
    chosen_point: NDArray[np.float64] | None = None
    sampling: SamplingResult | None = None
    obstacles: NDArray[np.float64] = dataclasses.field(default_factory=lambda: _EMPTY)
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
    #: With goal_unreachable: why the memory holds no way (NavigationMemory.no_way).
    no_way: str = ''


@dataclass(frozen=True)
class Cycle:
    """One planning cycle, as its stages see it (the memory's frame, SI units)."""

    cfg: PlannerConfig
    #: The cycle's time on the decision loop's clock [s], and the planning period [s].
    now: float
    dt: float
    #: The robot's pose (x, y, yaw) and the goal (x, y).
    pose: NDArray[np.float64]
    goal: NDArray[np.float64]
    #: The scan's returns placed at the pose the scan was taken from (m, 2), in beam
    #: order (non-finite ones included: a bad return is dropped from ``obstacles``).
    points: NDArray[np.float64]
    #: The finite returns (m, 2), and the robot's distances to them and to the goal [m].
    obstacles: NDArray[np.float64]
    nearest_distance: float
    goal_distance: float
    #: The moving-obstacle tracks of this scan (NO_TRACKS without the tracker), where
    #: they were when it was taken.
    tracks: Tracks
    #: The last command (v, w): the acceleration limits start from it.
    previous: tuple[float, float]
    #: Scans in the memory, this cycle's counted (0 without the memory).
    memory_scans: int = 0
    #: Whether a scan has been matched to the memory's walls (the scan alignment's match
    #: accepted at least once since the memory began).
    aligned: bool = False
    #: How old the scan is [s] (now minus its stamp; 0 when unknown).
    scan_age: float = 0.0
    #: The navigation field (None: the Euclidean attraction) and whether it is new.
    field: NavigationField | None = None
    new_field: bool = False
    #: With goal_unreachable: why the memory holds no way (NavigationMemory.no_way).
    no_way: str = ''
    #: Set by a gate: the cycle stops the robot with this status.
    status: Status | None = None
    #: The command and what led to it: set by the proposer (or, for a stopped cycle,
    #: by :meth:`stopped`), replaced by filters.
    result: PlanResult | None = None

    def with_(self, **changes) -> Cycle:
        """A copy with ``changes``."""
        return dataclasses.replace(self, **changes)

    def seen(self) -> dict:
        """The diagnostics every PlanResult of the cycle carries."""
        return dict(obstacles=self.obstacles, nearest_distance=self.nearest_distance,
                    goal_distance=self.goal_distance, field=self.field,
                    new_field=self.new_field, tracks=self.tracks, no_way=self.no_way)

    def stopped(self) -> Cycle:
        """The cycle with the result of standing still with its ``status``."""
        return self.with_(result=PlanResult(Command(0.0, 0.0, self.status), **self.seen()))


class Stage:
    """A stage of the cycle: ``run`` it on a cycle; ``reset`` (a stop, a new goal) and
    ``forget`` (a new world) clear what it keeps between cycles (nothing, here)."""

    name = 'stage'

    def run(self, cycle: Cycle) -> Cycle:
        raise NotImplementedError

    def reset(self) -> None:
        """Forget what the last cycles left for this goal (a stop, a new goal)."""

    def forget(self) -> None:
        """Forget everything (a new world: a restarted simulation)."""
        self.reset()
