"""Laser scan arrays to point obstacles in the odom frame, and voxel downsampling.

Invalid beams are dropped, whatever the driver's convention: NaN (LDS-02 empty
beams), +/-inf (Gazebo no-return), 0.0 (LDS-01 invalid), negative values,
values below ``range_min`` and values at or beyond ``range_max`` (no return).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .robot import to_parent


class ScanError(ValueError):
    """The scan's geometry is unusable (e.g. angle_increment not positive)."""


#: The longest sweep a scan's time_increment may describe [s] (Scan.beam_interval):
#: lidars sweep at 5-40 Hz.
MAX_SWEEP = 1.0


@dataclass(frozen=True, eq=False)
class Scan:
    """One 2-D laser sweep in the laser's frame (``base_scan``), as every layer passes it:
    the simulator makes it, the node's conversion builds it from a LaserScan, the decision
    loop holds it and the planner, the memory and the occupancy grid take it whole.

    ranges [m] (any value; see :func:`valid_beams`), beam i at ``angle_min + i *
    angle_increment`` [rad], valid returns in [range_min, range_max) [m], ``stamp``:
    capture time of beam 0 [s] (NaN: unknown, every use of it is new); beam i taken
    ``i * time_increment`` [s] after it (0: all at once), a sweep every ``scan_time``
    [s] (0: unknown), as sensor_msgs/LaserScan has them. ``bearings`` (one per beam
    [rad], in the laser's frame; None: the beams' own angles): where each return lies
    once the sweep is de-skewed (:func:`deskew`), which no grid of angles can hold
    exactly.
    """

    ranges: NDArray[np.float64]
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    stamp: float = math.nan
    time_increment: float = 0.0
    scan_time: float = 0.0
    bearings: NDArray[np.float64] | None = None

    def check(self) -> None:
        """Raise ScanError for a non-finite geometry or an angle_increment <= 0 with more
        than one beam (an empty scan is fine: open space)."""
        geometry = (self.angle_min, self.angle_increment, self.range_min, self.range_max)
        if not all(math.isfinite(v) for v in geometry):
            raise ScanError(f'non-finite scan geometry {geometry}')
        if np.size(self.ranges) > 1 and self.angle_increment <= 0.0:
            raise ScanError(f'angle_increment must be positive, got {self.angle_increment}')
        if self.bearings is not None and np.size(self.bearings) != np.size(self.ranges):
            raise ScanError(f'{np.size(self.bearings)} bearings for {np.size(self.ranges)} '
                            'beams')

    @property
    def beam_interval(self) -> float:
        """``time_increment`` [s] when it describes a sweep (finite, positive, the whole
        sweep within MAX_SWEEP), else 0: taken at once. A driver's NaN or a sweep of
        minutes must not bend the scan nor date its beams."""
        inc = self.time_increment
        ok = math.isfinite(inc) and inc > 0.0 \
            and inc * max(np.size(self.ranges) - 1, 0) <= MAX_SWEEP
        return float(inc) if ok else 0.0

    @property
    def angles(self) -> NDArray[np.float64]:
        """Angle of each beam (of its return, for a de-skewed scan) in the laser frame
        [rad]."""
        if self.bearings is not None:
            return self.bearings
        return beam_angles(np.size(self.ranges), self.angle_min, self.angle_increment)

    def valid(self, max_range: float = math.inf) -> NDArray[np.bool_]:
        """Mask of usable returns (:func:`valid_beams`), no farther than ``max_range``."""
        return valid_beams(self.ranges, self.range_min, self.range_max, max_range)


def scans_in(seconds: float, period: float) -> int:
    """How many scans make ``seconds`` [s] when one is taken each ``period`` [s] (the
    planner takes one a planning cycle; at least one). What the memory waits for is a
    time: the same seconds at 5 Hz and at 20 Hz."""
    return max(1, round(seconds / period))


def full_turn(n: int, angle_increment: float) -> bool:
    """Whether ``n`` beams ``angle_increment`` [rad] apart go round the whole circle (the
    last beam next to the first)."""
    return n * abs(angle_increment) >= 2.0 * math.pi - 0.5 * abs(angle_increment)


def on_grid(flags: NDArray[np.bool_] | None, grid: Scan, exact: Scan
            ) -> NDArray[np.bool_] | None:
    """Per-beam ``flags`` of a scan on its grid of angles (``grid``), for the returns of
    the same sweep kept at their own bearings (``exact``: each return of its beam, at its
    direction; :func:`deskew`): each return takes the flag of the grid's beam its
    direction is nearest (the beam it landed in there). Unchanged when both scans are on
    the grid or both keep their bearings."""
    if flags is None or exact.bearings is None or grid.bearings is not None or not len(flags):
        return flags
    n = len(flags)
    with np.errstate(invalid='ignore'):
        k = np.rint((exact.bearings - grid.angle_min) / grid.angle_increment)
    k = np.where(np.isfinite(k), k, 0).astype(np.int64)
    k = np.mod(k, n) if full_turn(n, grid.angle_increment) else np.clip(k, 0, n - 1)
    return flags[k]


def beam_angles(n: int, angle_min: float, angle_increment: float) -> NDArray[np.float64]:
    """Angle of each beam in the laser frame [rad]."""
    return angle_min + angle_increment * np.arange(n)


def valid_beams(ranges: ArrayLike, range_min: float, range_max: float,
                max_range: float = math.inf) -> NDArray[np.bool_]:
    """Mask of usable returns: finite, positive, in [range_min, range_max) and <= max_range."""
    r = np.asarray(ranges, dtype=float)
    with np.errstate(invalid='ignore'):
        return (np.isfinite(r) & (r > 0.0) & (r >= range_min) & (r < range_max)
                & (r <= max_range))


def scan_to_points(scan: Scan, pose: ArrayLike, mount: ArrayLike = (0.0, 0.0, 0.0),
                   max_range: float = math.inf) -> NDArray[np.float64]:
    """The scan's valid returns as (m, 2) points in the frame ``pose`` is given in [m].

    pose: (x, y, yaw) of base_footprint in odom [m, m, rad] when the scan was taken;
    mount: (x, y, yaw) of the laser in base_footprint (RobotDescription.laser.planar).
    Raises ScanError for a bad geometry (Scan.check) or a non-finite pose or mounting;
    an empty scan gives an empty (0, 2) array.
    """
    scan.check()
    if not all(math.isfinite(float(v)) for v in (*pose, *mount)):
        raise ScanError('non-finite robot pose or laser offset')
    r = np.asarray(scan.ranges, dtype=float).ravel()
    mask = scan.valid(max_range)
    rv = r[mask]
    a = scan.angles[mask]
    # laser frame -> base frame -> odom frame
    in_laser = np.column_stack((rv * np.cos(a), rv * np.sin(a)))
    return to_parent(pose, to_parent(mount, in_laser))


def deskew(scan: Scan, motion: ArrayLike, mount: ArrayLike = (0.0, 0.0, 0.0),
           bearings: bool = False) -> Scan:
    """The scan as if every beam had been taken at its first beam's instant: ``motion``
    (x, y, yaw) is base_footprint's motion from the first beam to the last, in its pose
    at the first (from odometry); beam i, taken ``i * time_increment`` after the first,
    is placed with the fraction i / (n - 1) of it (a constant twist over the sweep),
    ``mount`` the laser in base_footprint. Each return's direction and range from the
    laser at the first beam are then kept as they are (``bearings``: Scan.bearings, in
    the order of the beams), or the return lands in the beam of the scan's grid of
    angles nearest its direction (the nearest return when several land in one; a beam
    none lands in has no return, NaN: it clears no cell), up to half a beam off, by an
    amount that changes slowly along the sweep (docs/alignment.md). A scan taken all at
    once (time_increment 0), or with no motion, or de-skewed already, is returned as it
    is. Beams with no return keep it. The beams keep their instants (time_increment):
    what moved during the sweep is where it was when its beam saw it (the tracker
    dates its clusters by them); so a scan is de-skewed once (DecisionLoop._deskewed)."""
    n = np.size(scan.ranges)
    motion = np.array(motion, float).ravel()
    if motion.size == 3 and math.isfinite(motion[2]):   # a sweep turns less than a turn
        motion[2] = math.remainder(motion[2], 2 * math.pi)
    if n < 2 or scan.beam_interval <= 0.0 or scan.bearings is not None \
            or not np.all(np.isfinite(motion)) or not np.any(motion):
        return scan
    scan.check()
    r = np.asarray(scan.ranges, float).ravel()
    hit = scan.valid()
    f = np.arange(n) / (n - 1)
    mx, my, myaw = (float(v) for v in mount)
    # the laser at beam i in the laser's frame at the first beam: mount^-1 . m_i . mount,
    # m_i = f_i * motion (base_footprint's motion so far)
    th = f * motion[2]
    px = f * motion[0] + np.cos(th) * mx - np.sin(th) * my - mx
    py = f * motion[1] + np.sin(th) * mx + np.cos(th) * my - my
    c0, s0 = math.cos(myaw), math.sin(myaw)
    lx, ly = c0 * px + s0 * py, -s0 * px + c0 * py
    a = scan.angles + th   # (the laser's yaw moved by as much as the base's)
    ex = lx[hit] + r[hit] * np.cos(a[hit])
    ey = ly[hit] + r[hit] * np.sin(a[hit])
    geometry = (scan.angle_min, scan.angle_increment, scan.range_min, scan.range_max,
                scan.stamp, scan.time_increment, scan.scan_time)
    if bearings:
        ranges, directions = r.copy(), a
        ranges[hit] = np.hypot(ex, ey)
        directions[hit] = np.arctan2(ey, ex)
        return Scan(ranges, *geometry, directions)
    inc = scan.angle_increment
    bins = np.rint(np.mod(np.arctan2(ey, ex) - scan.angle_min, 2.0 * math.pi) / inc
                   ).astype(np.int64)
    if full_turn(n, inc):
        bins %= n                       # a full turn: the last bin is next to the first
    keep = bins < n
    dist = np.hypot(ex, ey)[keep]
    bins = bins[keep]
    out = np.where(hit, np.nan, r)   # returns re-binned below; no-return beams kept
    order = np.argsort(-dist)   # nearest written last: it wins its bin
    out[bins[order]] = dist[order]
    return Scan(out, *geometry)


def range_sigma(ranges: ArrayLike, floor: float, fraction: float) -> NDArray[np.float64]:
    """The lidar's range noise (standard deviation) [m] at ``ranges`` [m]: ``floor`` near
    it, ``fraction`` of the range farther out (PlannerConfig.range_noise_*)."""
    return np.maximum(floor, fraction * np.asarray(ranges, float))


#: The most oblique incidence at which denoise moves a return onto its line: the cosine
#: of the angle between the ray and the line's normal. For the obstacles and the tracker
#: (a cluster's centroid steady) ...
GRAZING_OBSTACLES = 0.3
#: ... and for the memory and the scan alignment (DecisionLoop._deskewed). Across
#: seven beams at a grazing incidence a line spans a long stretch of surface; where the
#: surface is not straight at that length (jambs, shelves, a wall's steps) the return
#: moves along its ray by several times the line's misfit, and on the same stretch by
#: as much each time the robot passes at that angle: with exact rays along a corridor of
#: stepped walls, perfect odometry and the obstacles' bound, the memory's walls were
#: drawn so that the alignment took the robot to have driven 1 % farther than it had
#: (test/test_alignment.py::test_stepped_walls_do_not_stretch_the_drive). At 0.7 the
#: procedural building family's long straight walls, seen at a slant through the LDS-01's
#: noise, kept too much of it (docs/alignment.md): 0.5 is between the two.
GRAZING_MEMORY = 0.5


def denoise(scan: Scan, floor: float, fraction: float, half_window: int = 3,
            grazing: float = GRAZING_OBSTACLES) -> Scan:
    """The scan smoothed along its surfaces (:func:`denoise_each` with one bound)."""
    return denoise_each(scan, floor, fraction, (grazing,), half_window)[0]


def denoise_each(scan: Scan, floor: float, fraction: float, grazing: Sequence[float],
                 half_window: int = 3) -> tuple[Scan, ...]:
    """The scan with each return moved along its ray onto the line through it and its
    neighbours on the same surface: up to ``half_window`` beams on either side, valid, no
    farther in range than four of the lidar's standard deviations (``floor`` [m], or
    ``fraction`` of the range farther out) plus what a surface at 70 degrees from its
    normal adds per beam; the line fitted to their points by total least squares. A
    lidar's range noise is independent from beam to beam, a wall is straight over a few
    beams: seven beams on one wall leave about 0.4 of the noise, and walls drawn from
    them are as thin as the map's cells. A line, unlike a mean of ranges, leaves a wall
    seen at a slant where it is. A return with fewer than two neighbours (a depth edge,
    a lone return such as a mixed pixel), one whose line its ray meets at a grazing
    angle (the cosine of the incidence below the bound), and a beam with no return are
    left as they are: one scan per bound of ``grazing``, the lines fitted once. Without
    noise (both 0) the scan is returned as it is."""
    n = np.size(scan.ranges)
    if n < 3 or half_window < 1 or (floor <= 0.0 and fraction <= 0.0) \
            or not math.isfinite(scan.angle_min) or not math.isfinite(scan.angle_increment):
        return (scan,) * len(grazing)   # (a scan with no geometry is refused by the planner)
    r = np.asarray(scan.ranges, float).ravel()
    hit = scan.valid()
    rr = np.where(hit, r, 0.0)
    a = scan.angles
    ux, uy = np.cos(a), np.sin(a)
    x, y = rr * ux, rr * uy
    sigma = range_sigma(rr, floor, fraction)
    full = full_turn(n, scan.angle_increment)
    count = hit.astype(float)
    sx, sy, sxx, syy, sxy = x * count, y * count, x * x * count, y * y * count, x * y * count
    for k in range(1, half_window + 1):
        allowed = 4.0 * sigma + k * rr * abs(scan.angle_increment) * math.tan(math.radians(70))
        for shift in (k, -k):
            other_hit = np.roll(hit, shift)
            if not full and shift > 0:   # no wrap-around at the ends of a partial sweep
                other_hit[:shift] = False
            elif not full:
                other_hit[shift:] = False
            same = hit & other_hit & (np.abs(np.roll(rr, shift) - rr) <= allowed)
            ox, oy = np.roll(x, shift), np.roll(y, shift)
            count += same
            sx, sy = sx + same * ox, sy + same * oy
            sxx, syy, sxy = sxx + same * ox * ox, syy + same * oy * oy, sxy + same * ox * oy
    c = np.maximum(count, 1.0)
    mx, my = sx / c, sy / c
    cxx, cyy, cxy = sxx / c - mx * mx, syy / c - my * my, sxy / c - mx * my
    along = 0.5 * np.arctan2(2.0 * cxy, cxx - cyy)   # the line's direction
    nx, ny = -np.sin(along), np.cos(along)          # its normal
    meet = nx * ux + ny * uy
    with np.errstate(divide='ignore', invalid='ignore'):
        on_line = (nx * mx + ny * my) / meet
    ok = hit & (count >= 3.0) & np.isfinite(on_line) & (np.abs(on_line - rr) <= 4.0 * sigma)
    return tuple(Scan(np.where(ok & (np.abs(meet) >= bound), on_line, r), scan.angle_min,
                      scan.angle_increment, scan.range_min, scan.range_max, scan.stamp,
                      scan.time_increment, scan.scan_time, scan.bearings) for bound in grazing)


def geometry_warning(n: int, angle_min: float, angle_max: float,
                     angle_increment: float) -> str | None:
    """Why a scan's header is suspicious, or None. Such a scan is still used, with beam
    i at angle_min + i * angle_increment (LDS-02 beam counts vary from scan to scan)."""
    if n < 2 or not math.isfinite(angle_increment) or angle_increment <= 0.0:
        return None   # no usable geometry: scan_to_points refuses the scan itself
    if n * angle_increment > 2.0 * math.pi + angle_increment:
        return f'{n} beams of {angle_increment:.5f} rad cover more than a full turn'
    if not (math.isfinite(angle_min) and math.isfinite(angle_max)):
        return None
    span = (angle_max - angle_min) / angle_increment
    if not math.isfinite(span):
        return f"angle_increment {angle_increment:g} rad is too small for the header's span"
    expected = int(round(span)) + 1
    if abs(expected - n) > 1:
        return f'{n} ranges, but angle_min/angle_max/angle_increment describe {expected}'
    return None


def voxel_downsample(points: ArrayLike, voxel: float) -> NDArray[np.float64]:
    """One point per square cell of side ``voxel`` [m] (the centroid of the cell's points).

    A voxel of 0 returns a copy of the input.
    """
    p = np.asarray(points, float).reshape(-1, 2)
    if voxel <= 0.0 or p.shape[0] == 0:
        return p.copy()
    cells = np.floor(p / voxel).astype(np.int64)
    key = (cells[:, 0] << 32) + (cells[:, 1] & 0xFFFFFFFF)
    _, inverse, counts = np.unique(key, return_inverse=True, return_counts=True)
    sx = np.bincount(inverse, weights=p[:, 0], minlength=counts.size)
    sy = np.bincount(inverse, weights=p[:, 1], minlength=counts.size)
    return np.column_stack((sx, sy)) / counts[:, None]
