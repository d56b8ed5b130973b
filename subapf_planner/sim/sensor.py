"""A 2-D spinning lidar as imperfect as the hardware: the simulator's sensor model.

A real lidar is not a set of exact rays taken at one instant. What this model adds to
the true ranges, per lidar (:data:`LIDARS`, each number's source in ``source``):

* **range noise** growing with range, with a floor near the sensor: the datasheet's
  accuracy bands (``bands``: up to a range, an absolute and a relative accuracy); the
  datasheet's +/- figure is taken as two standard deviations (a 95 % bound);
* **dropped beams**, at random (``dropout``) and in runs, as dark or glossy surfaces
  give (``dark_runs``: the chance per beam that a run starts, ``dark_run_length``: its
  mean length in beams);
* **mixed pixels** at depth edges: a beam whose footprint straddles an object's edge
  returns a range between the object and what lies behind it (``mixed_pixels``: the
  chance for each beam next to a jump of more than MIXED_EDGE), a small cluster
  floating in free space that seems to move as the robot moves;
* **the sweep's own timing**: each beam is taken at its own instant, beam i at
  ``i * time_increment`` after the sweep's first (the scan's stamp), over
  ``scan_time`` = 1 / ``rate``; a turning robot's scan is bent (the simulator casts
  each beam from where the laser is at its instant, sim/simulator.py);
* **latency, jitter and lost scans** between the sweep's end and the planner
  (``latency``, ``jitter``, ``scan_loss``; applied by sim/faults.py's ScanDelivery).

The ideal sensor (``SimConfig.sensor: ideal``) is exact rays at one instant, delivered
at once; ``range_noise`` and ``beam_dropout`` of SimConfig are faults on top of either.
Latency, jitter and scan loss are not on the datasheets: the figures are estimates for
a USB-serial lidar and a ROS driver, stated as such.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import NDArray

#: A jump in range between neighbouring beams larger than this is a depth edge [m]
#: (four map cells: a wall's own roughness and noise at 1 m stay below it).
MIXED_EDGE = 0.2


@dataclass(frozen=True)
class Lidar:
    """One lidar model's figures (SI units; see the module docstring)."""

    name: str
    beams: int
    range_min: float
    range_max: float
    #: Sweeps per second [Hz].
    rate: float
    #: Accuracy bands: (up to this range [m], absolute [m], relative [-]), +/- figures.
    bands: tuple[tuple[float, float, float], ...]
    dropout: float
    dark_runs: float
    dark_run_length: float
    mixed_pixels: float
    #: From the sweep's end to the planner [s], its standard deviation [s], and the
    #: chance that a scan is lost on the way.
    latency: float
    jitter: float
    scan_loss: float
    source: str
    #: What the driver reports for a beam with no return (nothing in range, or a dark
    #: surface): the LDS-01's driver 0.0, the RPLIDAR's +inf. A 0.0 clears no cell of
    #: the memory; an open beam (+inf) clears its whole length.
    no_return: float = 0.0
    #: The field of view [rad] (a whole turn: beams 2 pi / beams apart; less: its first
    #: and last beam at its edges) and its first beam's angle in the laser's frame [rad].
    fov: float = 2.0 * math.pi
    angle_min: float = 0.0

    @property
    def angle_increment(self) -> float:
        """The angle between two beams [rad]."""
        if self.fov >= 2.0 * math.pi - 1e-9:
            return 2.0 * math.pi / self.beams
        return self.fov / max(self.beams - 1, 1)

    def angles(self, beams: int | None = None) -> NDArray[np.float64]:
        """Each beam's angle in the laser's frame [rad] (``beams`` over the same field of
        view: default the lidar's own)."""
        n = self.beams if beams is None else beams
        k = np.arange(n)
        if self.fov >= 2.0 * math.pi - 1e-9:
            return self.angle_min + 2.0 * math.pi * k / n
        return self.angle_min + self.fov * k / max(n - 1, 1)

    @property
    def scan_time(self) -> float:
        """One sweep [s]."""
        return 1.0 / self.rate

    def sigma(self, ranges: NDArray[np.float64]) -> NDArray[np.float64]:
        """The range noise's standard deviation at each range [m]: half the accuracy of
        the band the range falls in (the last band beyond)."""
        r = np.asarray(ranges, float)
        out = np.zeros_like(r)
        done = np.zeros(r.shape, bool)
        for upto, absolute, relative in self.bands:
            here = ~done & (r <= upto)
            out[here] = 0.5 * (absolute + relative * r[here])
            done |= here
        _, absolute, relative = self.bands[-1]
        out[~done] = 0.5 * (absolute + relative * r[~done])
        return out


LIDARS: dict[str, Lidar] = {
    'lds01': Lidar(
        'LDS-01', 360, 0.12, 3.5, 5.0, ((0.5, 0.015, 0.0), (3.5, 0.0, 0.05)),
        dropout=0.02, dark_runs=0.005, dark_run_length=6.0, mixed_pixels=0.5,
        latency=0.03, jitter=0.01, scan_loss=0.01,
        source='ROBOTIS LDS-01 (HLS-LFCD2) datasheet: 360 samples a turn at 300 rpm '
               '(5 Hz), 0.12-3.5 m, accuracy +/-15 mm (0.12-0.5 m), +/-5.0 % (0.5-3.5 m); '
               'dropouts, mixed pixels, latency, jitter and loss estimated'),
    'lds02': Lidar(
        'LDS-02', 360, 0.16, 8.0, 5.0, ((0.3, 0.010, 0.0), (8.0, 0.0, 0.03)),
        dropout=0.02, dark_runs=0.005, dark_run_length=6.0, mixed_pixels=0.5,
        latency=0.03, jitter=0.01, scan_loss=0.01,
        source='ROBOTIS LDS-02 datasheet: 0.16-8 m, 5 Hz, accuracy +/-10 mm (0.16-0.3 m), '
               '+/-3 % (0.3-6 m, taken beyond); dropouts, mixed pixels, latency, jitter '
               'and loss estimated'),
    'rplidar_a1': Lidar(
        'RPLIDAR A1', 720, 0.15, 12.0, 5.5, ((3.0, 0.0, 0.01), (5.0, 0.0, 0.02),
                                            (12.0, 0.0, 0.025)),
        dropout=0.02, dark_runs=0.005, dark_run_length=6.0, mixed_pixels=0.5,
        latency=0.03, jitter=0.01, scan_loss=0.01,
        source='Slamtec RPLIDAR A1 datasheet: 0.15-12 m, 5.5 Hz typical, accuracy 1 % of '
               'range (<= 3 m), 2 % (3-5 m), 2.5 % (5-25 m); 720 beams a turn as the '
               "TurtleBot 4's driver publishes them (estimated); dropouts, mixed pixels, "
               'latency, jitter and loss estimated', no_return=math.inf),
    'lms111': Lidar(
        'SICK LMS111', 541, 0.5, 20.0, 50.0, ((20.0, 0.024, 0.0),),
        dropout=0.01, dark_runs=0.002, dark_run_length=6.0, mixed_pixels=0.5,
        latency=0.01, jitter=0.003, scan_loss=0.005,
        source='SICK LMS111-10100 datasheet: 270 degrees, 0.5 degree resolution at 50 Hz '
               '(541 beams), 0.5-20 m, statistical error 12 mm (one sigma: +/-24 mm taken '
               'as two), its systematic error (+/-30 mm, a fixed offset per unit) left out; '
               'dropouts, mixed pixels (it takes one echo), latency over Ethernet, jitter '
               'and loss estimated', no_return=math.inf, fov=math.radians(270.0),
        angle_min=-math.radians(135.0)),
}


def corrupt(ranges: NDArray[np.float64], lidar: Lidar,
            rng: np.random.Generator) -> NDArray[np.float64]:
    """A sweep's true ranges (n,) [m] (+inf: no return) as the lidar reports them:
    mixed pixels at depth edges, range noise, dropped beams (+inf), in that order (the
    simulator reports beams with no return as the driver does: ``no_return``)."""
    r = np.array(ranges, float)
    n = r.size
    if n == 0:
        return r
    out = r.copy()
    if lidar.mixed_pixels > 0.0 and n > 1:
        for shift in (1, -1):   # each beam against the next and the previous one
            other = np.roll(r, shift)
            if lidar.fov < 2.0 * math.pi - 1e-9:   # the first and last beams are no neighbours
                end = 0 if shift == 1 else -1
                other[end] = r[end]
            with np.errstate(invalid='ignore'):
                edge = np.isfinite(r) & np.isfinite(other) & (np.abs(other - r) > MIXED_EDGE)
            hit = edge & (rng.random(n) < 0.5 * lidar.mixed_pixels)
            u = rng.random(n)
            out[hit] = r[hit] + u[hit] * (other[hit] - r[hit])
    finite = np.isfinite(out)
    out[finite] += lidar.sigma(out[finite]) * rng.standard_normal(int(finite.sum()))
    lost = rng.random(n) < lidar.dropout
    if lidar.dark_runs > 0.0:
        for start in np.flatnonzero(rng.random(n) < lidar.dark_runs):
            length = int(rng.geometric(1.0 / max(lidar.dark_run_length, 1.0)))
            lost[start:start + length] = True
    out[lost] = np.inf
    return out
