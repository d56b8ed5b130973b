"""A map the robot already has (a SLAM map, map_server's), as the memory's prior.

:class:`KnownMap` holds an occupancy grid in nav_msgs/OccupancyGrid's convention (-1
unknown, 0 free to 100 occupied; rows are y, cell (0, 0)'s corner at ``origin`` in the
map's frame) and where the map's frame is in the memory's frame. The memory
(core/occupancy.py) starts each cell of its window from it as :func:`prior` says, and
again each cell a shift of the window brings in: occupied cells as walls established
long ago (the scan alignment matches scans to them: the map localises the robot),
free cells as seen free, unknown cells unknown. Scans then change them as they change
any cell: a door closed since the map was made is seen, a table moved away is cleared
after a few scans through it.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: map_server's thresholds (Nav2's defaults, occupied_thresh 0.65, free_thresh 0.25):
#: a cell at or above OCCUPIED_AT is a wall, one at or below FREE_AT free, between them
#: and -1 unknown.
OCCUPIED_AT = 65
FREE_AT = 25
#: The log odds a wall of the map starts with (established: a few misses do not clear
#: it; seven scans through it do), and a free cell (two hits make it occupied).
PRIOR_WALL = 2.5
PRIOR_FREE = -1.0


class KnownMapError(ValueError):
    """A map that cannot be used (not 2-D, a bad resolution or origin)."""


@dataclass(frozen=True, eq=False)
class KnownMap:
    """An occupancy grid (h, w) in its own frame, and that frame's pose (x, y, yaw) in
    the memory's frame [m, m, rad]."""

    cells: NDArray[np.int8]
    #: The corner of cell (0, 0) in the map's frame [m] (nav_msgs/MapMetaData origin,
    #: whose yaw is taken as 0, as map_server writes it).
    origin: tuple[float, float]
    resolution: float
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        cells = np.asarray(self.cells)
        if cells.ndim != 2 or cells.size == 0:
            raise KnownMapError(f'a known map must be a non-empty 2-D grid, got shape '
                                f'{cells.shape}')
        if not (math.isfinite(self.resolution) and self.resolution > 0.0):
            raise KnownMapError(f'map resolution must be positive, got {self.resolution}')
        if not all(math.isfinite(v) for v in (*self.origin, *self.pose)):
            raise KnownMapError('map origin and pose must be finite')

    def at(self, points: ArrayLike) -> NDArray[np.int8]:
        """The map's value at each point (n, 2) [m] of the memory's frame (-1 off it)."""
        p = np.asarray(points, float).reshape(-1, 2)
        x, y, yaw = self.pose
        c, s = math.cos(yaw), math.sin(yaw)
        rel = p - (x, y)   # into the map's frame: the inverse of to_parent(pose, .)
        local = np.column_stack((c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]))
        cols = np.floor((local[:, 0] - self.origin[0]) / self.resolution).astype(np.int64)
        rows = np.floor((local[:, 1] - self.origin[1]) / self.resolution).astype(np.int64)
        h, w = np.shape(self.cells)
        inside = (rows >= 0) & (rows < h) & (cols >= 0) & (cols < w)
        out = np.full(len(p), -1, np.int8)
        out[inside] = np.asarray(self.cells)[rows[inside], cols[inside]]
        return out


def prior(known: KnownMap, centres: ArrayLike) -> tuple[NDArray[np.float32],
                                                       NDArray[np.bool_]]:
    """The log odds the memory starts cells with centres (n, 2) [m] (memory's frame) from,
    and which of them are the map's walls."""
    v = known.at(centres).astype(np.int16)
    wall = v >= OCCUPIED_AT
    out = np.zeros(len(v), np.float32)
    out[wall] = PRIOR_WALL
    out[(v >= 0) & (v <= FREE_AT)] = PRIOR_FREE
    return out, wall
