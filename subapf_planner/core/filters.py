"""Filters: stages that see every cycle's command, proposed or stopped, and may replace
it (core/cycle.py).

* ``evasion`` (with the tracker, for the APF methods): the command is rolled out
  against where the moving tracks will be (carried forward from the scan's time to
  the cycle's) and replaced by an escape when it would meet one (core/evasion.py);
  the chosen escape is committed, so the next cycle weighs it again one period on.
  Not once the goal is reached.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .command import Command, forward_blocked
from .cycle import Cycle, Stage
from .evasion import Escape, evade
from .status import Status

#: The tracks are carried forward to the cycle's time by at most this [s] (a scan older
#: than the scan timeout stops the robot anyway).
MAX_AGE = 1.0


class Evasion(Stage):
    """Replace a command that would meet a moving track by an escape (``evading``)."""

    name = 'evasion'

    def __init__(self) -> None:
        self._escape: Escape | None = None   # the escape of the last cycle, if it evaded

    def reset(self) -> None:
        self._escape = None

    def run(self, cycle: Cycle) -> Cycle:
        tracks, result = cycle.tracks, cycle.result
        if cycle.status is Status.REACHED or not np.any(tracks.moving):
            self._escape = None
            return cycle
        cfg, pose, points = cycle.cfg, cycle.pose, cycle.points
        cmd = result.command
        alt = evade(pose, (cmd.v, cmd.w), tracks.ahead(min(cycle.scan_age, MAX_AGE)),
                    points[~tracks.moving_points], cfg,
                    forward_blocked(pose, points, cfg),
                    None if self._escape is None else self._escape.advanced(), cycle.previous)
        self._escape = alt
        if alt is None:
            return cycle
        return cycle.with_(result=dataclasses.replace(
            result, command=Command(*alt.command, Status.EVADING)))
