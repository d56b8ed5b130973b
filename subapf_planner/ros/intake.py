"""The planner's inputs from messages, checked once: for planner_node and the replay.

Each function takes one message into a :class:`~subapf_planner.core.loop.DecisionLoop`
and returns what a person should be told (None: nothing), so the node logs it
(throttled) and the in-process replay (ros/replay.py) takes the same messages
in the same way:

* a scan or odometry stamped more than FUTURE_STAMP after the clock is dropped
  (sent before the clock jumped back: a restarted simulator's last messages must not
  be taken as its successor's);
* a scan in a frame other than ``laser_frame`` (empty: any) is dropped; a scan
  whose ranges do not match its header is used (LDS-02 varies its count) with a
  warning;
* odometry with a non-finite pose is dropped; a stamp going back in time clears
  the pose history;
* a goal in a frame other than ``odom_frame`` (or empty) or ``map_frame`` (the
  memory's frame: odom as it was at the start, kept still by the scan
  alignment), or with a non-finite position, is refused (an error), the
  previous goal kept; a path to follow (ros/actions.py) the same, and an empty one.
"""

from __future__ import annotations

from dataclasses import dataclass

from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry, Path
import numpy as np
from sensor_msgs.msg import LaserScan

from ..core.loop import FUTURE_STAMP, DecisionLoop
from ..core.scan import geometry_warning
from .conversions import pose_from_odom, scan_from_msg, stamp_to_seconds


@dataclass(frozen=True)
class Intake:
    """The frames the inputs must be in (the node's ``laser_frame`` and ``odom_frame``)."""

    laser_frame: str = 'base_scan'
    odom_frame: str = 'odom'
    #: The name of the memory's frame (odom corrected by the scan alignment).
    map_frame: str = 'map'

    def scan(self, loop: DecisionLoop, msg: LaserScan, now: float) -> str | None:
        """Take a scan handled at ``now`` [s]; a warning, or None."""
        if self.laser_frame and msg.header.frame_id != self.laser_frame:
            return (f'scan in frame "{msg.header.frame_id}", expected "{self.laser_frame}": '
                    'dropped')
        if problem := _ahead('scan', msg, now):
            return problem
        loop.update_scan(scan_from_msg(msg), now)
        problem = geometry_warning(len(msg.ranges), msg.angle_min, msg.angle_max,
                                   msg.angle_increment)
        return f'scan header: {problem}' if problem else None

    def odom(self, loop: DecisionLoop, msg: Odometry, now: float) -> str | None:
        """Take odometry handled at ``now`` [s]; a warning, or None."""
        if problem := _ahead('odometry', msg, now):
            return problem
        pose = pose_from_odom(msg)
        if not np.all(np.isfinite(pose)):
            return 'odometry with a non-finite pose: dropped'
        if not loop.update_odom(stamp_to_seconds(msg.header.stamp), pose, now):
            return 'odometry stamp went back in time: pose history cleared'
        return None

    def goal(self, loop: DecisionLoop, msg: PoseStamped) -> tuple[bool, str | None]:
        """Take a goal: (whether it is a new goal, the reason it was refused or None)."""
        goal = np.array([msg.pose.position.x, msg.pose.position.y], dtype=float)
        return self._goal(loop, goal, msg.header.frame_id, None)

    def path(self, loop: DecisionLoop, msg: Path) -> tuple[bool, str | None]:
        """Take a path to follow (its last pose the goal; the path's frame): as goal."""
        points = np.array([[p.pose.position.x, p.pose.position.y] for p in msg.poses],
                          dtype=float).reshape(-1, 2)
        if not len(points):
            return False, 'an empty path refused'
        return self._goal(loop, points[-1], msg.header.frame_id, points)

    def _goal(self, loop: DecisionLoop, goal: np.ndarray, frame: str,
              path: np.ndarray | None) -> tuple[bool, str | None]:
        what = 'goal' if path is None else 'path'
        if frame not in ('', self.odom_frame, self.map_frame):
            return False, (f'{what} in frame "{frame}" refused: give it in '
                           f'"{self.odom_frame}" or "{self.map_frame}"')
        if not np.all(np.isfinite(goal)) or (path is not None and not np.all(np.isfinite(path))):
            return False, f'{what} with a non-finite position refused'
        return loop.set_goal(goal, in_map=frame == self.map_frame, path=path), None


def _ahead(what: str, msg, now: float) -> str | None:
    """Why a message stamped more than FUTURE_STAMP after ``now`` [s] is dropped."""
    ahead = stamp_to_seconds(msg.header.stamp) - now
    if ahead > FUTURE_STAMP:
        return (f'{what} stamped {ahead:.2f} s after the clock (sent before the clock '
                'jumped back?): dropped')
    return None
