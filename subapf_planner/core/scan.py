"""Laser scan arrays to point obstacles in the odom frame, and voxel downsampling.

Invalid beams are dropped, whatever the driver's convention: NaN (LDS-02 empty
beams), +/-inf (Gazebo no-return), 0.0 (LDS-01 invalid), negative values,
values below ``range_min`` and values at or beyond ``range_max`` (no return).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray


class ScanError(ValueError):
    """The scan's geometry is unusable (e.g. angle_increment not positive)."""


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


def scan_to_points(ranges: ArrayLike, angle_min: float, angle_increment: float,
                   range_min: float, range_max: float, pose: ArrayLike,
                   laser_offset: ArrayLike = (0.0, 0.0, 0.0),
                   max_range: float = math.inf) -> NDArray[np.float64]:
    """Valid laser returns as (m, 2) points in the frame the robot ``pose`` is given in.

    pose: (x, y, yaw) of base_footprint in odom [m, m, rad];
    laser_offset: (x, y, yaw) of the laser in base_footprint.
    Raises ScanError for a non-finite geometry or an angle_increment <= 0 with
    more than one beam; an empty scan gives an empty (0, 2) array.
    """
    r = np.asarray(ranges, dtype=float).ravel()
    geometry = (angle_min, angle_increment, range_min, range_max)
    if not all(math.isfinite(v) for v in geometry):
        raise ScanError(f'non-finite scan geometry {geometry}')
    if r.size > 1 and angle_increment <= 0.0:
        raise ScanError(f'angle_increment must be positive, got {angle_increment}')
    x, y, yaw = (float(v) for v in pose)
    lx, ly, lyaw = (float(v) for v in laser_offset)
    if not all(math.isfinite(v) for v in (x, y, yaw, lx, ly, lyaw)):
        raise ScanError('non-finite robot pose or laser offset')
    mask = valid_beams(r, range_min, range_max, max_range)
    rv = r[mask]
    a = beam_angles(r.size, angle_min, angle_increment)[mask] + lyaw
    # laser frame -> base frame -> odom frame
    bx = lx + rv * np.cos(a)
    by = ly + rv * np.sin(a)
    c, s = math.cos(yaw), math.sin(yaw)
    return np.column_stack((x + c * bx - s * by, y + s * bx + c * by))


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
    expected = int(round((angle_max - angle_min) / angle_increment)) + 1
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
