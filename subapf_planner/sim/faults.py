"""Sensor faults between the simulator and the planner, one model for every loop.

The in-process episode (sim/episode.py) and ``sim_node`` both pass each captured
scan through :class:`ScanDelivery`: it is lost with probability
``scan_dropout`` and delivered ``scan_latency`` seconds after capture, stamped
with its capture time (the planner places it with the odometry pose of that
time). Beam dropout, range noise and odometry drift are the simulator's own
(``SimConfig``).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

from ..core.params import check_fields, param

T = TypeVar('T')

#: Offset of the fault model's seed from the simulator's.
FAULT_SEED_OFFSET = 7919
#: Slack for comparing simulated times [s].
TIME_EPS = 1e-9


@dataclass(frozen=True)
class ScanFaults:
    """Lost and late scans (seeded)."""

    scan_dropout: float = param(0.0, 'Probability that a scan never reaches the planner', '',
                                0.0, 0.99, read_only=True)
    scan_latency: float = param(0.0, 'Scans reach the planner this long after capture', 's',
                                0.0, 5.0, read_only=True)

    def __post_init__(self) -> None:
        check_fields(self)


class ScanDelivery(Generic[T]):
    """A queue of captured scans: ``capture`` each one, ``due`` returns the arrived ones."""

    def __init__(self, faults: ScanFaults, seed: int) -> None:
        self.faults = faults
        self._rng = np.random.default_rng(seed)
        self._queue: deque[tuple[float, T]] = deque()

    def capture(self, scan: T, stamp: float) -> None:
        """A scan taken at ``stamp`` [s]; it may be lost."""
        if self._rng.random() >= self.faults.scan_dropout:
            self._queue.append((stamp, scan))

    def due(self, now: float) -> list[T]:
        """Scans whose capture time + latency has come by ``now`` [s], oldest first."""
        out = []
        while self._queue and self._queue[0][0] + self.faults.scan_latency <= now + TIME_EPS:
            out.append(self._queue.popleft()[1])
        return out
