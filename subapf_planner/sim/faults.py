"""Sensor faults between the simulator and the planner, one model for every loop.

The in-process episode (sim/episode.py) and ``sim_node`` both pass each captured
scan through :class:`ScanDelivery`: it is lost with probability
``scan_dropout`` and delivered ``scan_latency`` seconds after capture, plus a
delay drawn with standard deviation ``scan_jitter`` (never before the scan
before it), stamped with its capture time (the planner places it with the
odometry pose of that time). :func:`delivery_faults` adds the realistic
lidar's own latency, jitter and loss (sim/sensor.py) to these. Beam dropout,
range noise and odometry drift are the simulator's own (``SimConfig``).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

from ..core.params import check_fields, param
from .simulator import SimConfig

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
                                0.0, 10.0, read_only=True)
    scan_jitter: float = param(0.0, 'Standard deviation of a further delay (half-normal)',
                               's', 0.0, 1.0, read_only=True)

    def __post_init__(self) -> None:
        check_fields(self)


def delivery_faults(sim_cfg: SimConfig, extra: ScanFaults | None = None) -> ScanFaults:
    """The faults a scan meets on its way to the planner: the realistic lidar's latency,
    jitter and loss (none for the ideal sensor), with ``extra`` on top (latencies add,
    jitters add in quadrature, losses are independent)."""
    extra = extra or ScanFaults()
    if not sim_cfg.realistic:
        return extra
    lidar = sim_cfg.model
    return ScanFaults(1.0 - (1.0 - lidar.scan_loss) * (1.0 - extra.scan_dropout),
                      lidar.latency + extra.scan_latency,
                      float(np.hypot(lidar.jitter, extra.scan_jitter)))


class ScanDelivery(Generic[T]):
    """A queue of captured scans: ``capture`` each one, ``due`` returns the arrived ones."""

    def __init__(self, faults: ScanFaults, seed: int) -> None:
        self.faults = faults
        self._rng = np.random.default_rng(seed)
        self._queue: deque[tuple[float, T]] = deque()   # (arrival time, scan)
        self._last_arrival = -np.inf

    def capture(self, scan: T, stamp: float) -> None:
        """A scan taken at ``stamp`` [s]; it may be lost."""
        f = self.faults
        if self._rng.random() < f.scan_dropout:
            return
        delay = f.scan_latency
        if f.scan_jitter > 0.0:
            delay += abs(f.scan_jitter * float(self._rng.standard_normal()))
        self._last_arrival = max(self._last_arrival, stamp + delay)
        self._queue.append((self._last_arrival, scan))

    def due(self, now: float) -> list[T]:
        """Scans that have arrived by ``now`` [s], oldest first."""
        out = []
        while self._queue and self._queue[0][0] <= now + TIME_EPS:
            out.append(self._queue.popleft()[1])
        return out
