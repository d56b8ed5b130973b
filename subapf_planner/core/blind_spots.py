"""Blind spots: what the lidar cannot see now, the memory remembers.

A lidar reports nothing closer than its ``range_min`` nor outside its field of view: the
Jackal's SICK LMS111 sees nothing within 0.5 m of itself (0.62 m ahead of the robot's
centre) nor in the quarter behind it. A door's jamb the robot turns beside, a post it
passes, drop out of the scan exactly when they matter, and a planner that plans from the
scan alone drives into them. The occupancy memory holds them from when they were seen;
the scan's beams say nothing about the blind zone (OccupancyGrid.update clears only from
``range_min`` on), so what it holds there stands until the lidar sees the place again,
as a costmap's obstacle layer keeps what its sensor no longer sees.

:func:`unseen` says which places a scan cannot see; :func:`blind_obstacles` takes the
memory's established cells within a reach of the robot that the scan cannot see and
that lie outside the footprint (a cell under the robot is the memory's error, not an
obstacle: taking it would stop the robot for good). The planner adds them to the
cycle's obstacles, not to the scan's returns (the tracker sees only what the lidar
does). With a lidar whose blind zone lies within the footprint and that sees all round
(the TurtleBots' LDS-01), there is nothing to add.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .footprint import Footprint
from .occupancy import ESTABLISHED, OccupancyGrid
from .scan import Scan


def unseen(points: ArrayLike, laser_pose: ArrayLike, scan: Scan) -> NDArray[np.bool_]:
    """Which ``points`` (n, 2) a scan taken with the laser at ``laser_pose`` (x, y, yaw)
    cannot see: closer to the laser than ``scan.range_min``, or outside the angles its
    beams cover (half a beam beyond the first and the last)."""
    pts = np.asarray(points, float).reshape(-1, 2)
    x, y, yaw = (float(v) for v in laser_pose)
    dx, dy = pts[:, 0] - x, pts[:, 1] - y
    blind = dx * dx + dy * dy < scan.range_min ** 2
    n, inc = np.size(scan.ranges), scan.angle_increment
    span = n * inc
    if n > 1 and span < 2.0 * math.pi:
        after_first = np.mod(np.arctan2(dy, dx) - yaw - (scan.angle_min - 0.5 * inc),
                             2.0 * math.pi)
        blind |= after_first > span
    return blind


def remembered(grid: OccupancyGrid, centre: ArrayLike, reach: float) -> NDArray[np.float64]:
    """The places (m, 2) of the established cells (log odds at least ESTABLISHED) within
    ``reach`` [m] of ``centre`` (x, y): where the returns fell in each cell with the
    scan alignment's hit places, else the cell's centre."""
    c = np.asarray(centre, float).ravel()[:2]
    res, n = grid.resolution, grid.cells
    lo = np.floor((c - reach - grid.origin) / res).astype(int).clip(0, n)
    hi = np.ceil((c + reach - grid.origin) / res).astype(int).clip(0, n)
    window = grid.log_odds[lo[1]:hi[1], lo[0]:hi[0]]
    rows, cols = np.nonzero(window >= ESTABLISHED)
    rows, cols = rows + lo[1], cols + lo[0]
    places = grid.centre_of(np.column_stack((rows, cols))) if rows.size else np.zeros((0, 2))
    if rows.size and grid.hit_offset is not None:
        places = places + grid.hit_offset[rows, cols]
    return places[np.hypot(*(places - c).T) <= reach] if rows.size else places


def blind_obstacles(grid: OccupancyGrid, pose: ArrayLike, laser_pose: ArrayLike,
                    scan: Scan, reach: float, radius: float,
                    footprint: Footprint | None = None) -> NDArray[np.float64]:
    """What the memory holds within ``reach`` [m] of the robot at ``pose`` (x, y, yaw)
    that the scan cannot see (:func:`unseen`) and that lies outside its footprint
    (the polygon, else the disc of ``radius`` [m]) (m, 2)."""
    pose = np.asarray(pose, float).ravel()
    places = remembered(grid, pose[:2], reach)
    if places.size == 0:
        return places
    places = places[unseen(places, laser_pose, scan)]
    if places.size == 0:
        return places
    if footprint is not None:
        return places[~footprint.covers(pose, places)]
    return places[np.hypot(*(places - pose[:2]).T) > radius]
