"""The ``contact_check`` filter: the last look at a command before it leaves.

The sampling keeps its next point ``sample_clearance`` from the returns, but the
command that steers there is an arc, not the straight step, and the forward corridor
(core/command.py) looks straight ahead only: turning while driving past a corner, or
alongside someone who edges closer, the footprint may touch what neither saw. As the
"approach" model of Nav2's collision monitor, this stage rolls the cycle's final
command (proposed, replaced by the evasion or the final approach) out for
``contact_time`` seconds (core/rollout.py, in CONTACT_STEP steps) against the scan's
returns and zeroes its forward speed (``blocked_ahead``, the turn kept) when the
footprint would come within ``contact_margin`` of the returns, nearer than it is to
them now. Returns the robot keeps its distance from, or draws away from, do not stop
it: a robot that stopped close to a wall may still drive off along it or away from
it. A disc turns on the spot freely; a polygon keeps the turn only where turning on
the spot for ``contact_time`` brings no corner near a return (core/command.py
``turn_blocked``), else it stands (``no_safe_move``).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .command import Command, turn_blocked
from .config import PlannerConfig
from .cycle import Cycle, Stage
from .rollout import arcs
from .status import Status

#: Rollout step [s] (at 0.22 m/s, 0.011 m of travel between checks).
CONTACT_STEP = 0.05
#: The returns are closed on when the rollout comes this much nearer to them than the
#: robot is now [m] (a wall the robot drives along at a constant distance is not).
CLOSING = 0.005


def gaps(poses: ArrayLike, points: ArrayLike, cfg: PlannerConfig) -> NDArray[np.float64]:
    """Gap between the footprint at each pose (n, 3) and each point (m, 2) (n, m) [m]: the
    polygon's (core/footprint.py) or the disc's of robot_radius."""
    poses = np.atleast_2d(np.asarray(poses, float))
    pts = np.asarray(points, float).reshape(-1, 2)
    shape = cfg.polygon
    if shape is not None:
        return shape.gaps(poses, pts)
    return np.hypot(pts[None, :, 0] - poses[:, None, 0],
                    pts[None, :, 1] - poses[:, None, 1]) - cfg.robot_radius


def closes_on(pose: ArrayLike, v: float, w: float, points: ArrayLike,
              cfg: PlannerConfig) -> bool:
    """Whether driving (v, w) from ``pose`` for contact_time brings the footprint within
    contact_margin of the points, and CLOSING nearer to them than it is at ``pose``."""
    pts = np.asarray(points, float).reshape(-1, 2)
    if v <= 0.0 or cfg.contact_time <= 0.0 or pts.shape[0] == 0:
        return False
    pose = np.asarray(pose, float)
    reach = cfg.robot_radius + v * cfg.contact_time + cfg.contact_margin
    off = pts - pose[:2]
    pts = pts[off[:, 0] ** 2 + off[:, 1] ** 2 <= reach * reach]
    if pts.shape[0] == 0:
        return False
    path = arcs(pose, [v], [w], cfg.contact_time, CONTACT_STEP)[0]
    n = len(path)
    yaws = pose[2] + w * CONTACT_STEP * np.arange(1, n + 1)
    ahead = float(gaps(np.column_stack((path, yaws)), pts, cfg).min())
    return ahead < cfg.contact_margin and ahead < float(gaps(pose, pts, cfg).min()) - CLOSING


class ContactCheck(Stage):
    """Zero the forward speed of a command whose rollout touches a return it closes on."""

    name = 'contact_check'

    def run(self, cycle: Cycle) -> Cycle:
        result = cycle.result
        cmd = result.command
        cfg, pose, points = cycle.cfg, cycle.pose, cycle.obstacles
        if not closes_on(pose, cmd.v, cmd.w, points, cfg):
            return cycle
        if turn_blocked(pose, cmd.w * cfg.contact_time, points, cfg):
            command = Command(0.0, 0.0, Status.NO_SAFE_MOVE)
        else:
            command = Command(0.0, cmd.w, Status.BLOCKED_AHEAD)
        return cycle.with_(result=dataclasses.replace(result, command=command))
