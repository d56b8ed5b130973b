"""Recoveries: what the decision loop does when the progress checker finds the robot
making no progress (core/supervisors.py), before it gives the goal up.

``avoid_ahead``, the one recovery: the place the navigation field leads the robot into
next (``avoid_distance`` along its descent from the pose the last cycle planned from,
a disc of ``avoid_radius``) is marked tried: blocked in the field until ``avoid_time``
has passed (core/memory.py ``avoid``), so that the field leads along another way; the
map itself is not changed, so a door that was only briefly blocked opens again.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .memory import NavigationMemory


class AvoidAhead:
    """Mark the way ahead tried (module docstring)."""

    name = 'avoid_ahead'

    def run(self, memory: NavigationMemory, pose: NDArray[np.float64] | None, distance: float,
            radius: float, until: float) -> bool:
        """Mark the place ``distance`` [m] along the field's descent from ``pose`` (x, y,
        ...; the memory's frame), a disc of ``radius`` [m], tried until ``until`` [s];
        False without a field, a pose or a way out of it."""
        f = memory.field
        if f is None or pose is None:
            return False
        path = f.path(pose[:2], max_length=2.0 * distance)
        if len(path) < 2:
            return False
        along = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
        memory.avoid(path[min(int(np.searchsorted(along, distance)), len(path) - 1)],
                     radius, until)
        return True
