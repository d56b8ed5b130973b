"""ROS 2 message <-> numpy conversions, in one place (no node, no rclpy.init needed)."""

from __future__ import annotations

import array
import math

from builtin_interfaces.msg import Time
from geometry_msgs.msg import PoseStamped, TransformStamped, Twist, TwistStamped
from nav_msgs.msg import OccupancyGrid as GridMsg
from nav_msgs.msg import Odometry, Path
import numpy as np
from sensor_msgs.msg import LaserScan

from ..bag.events import stamp_ns
from ..core.known_map import KnownMap, KnownMapError
from ..core.occupancy import OccupancyGrid
from ..core.robot import compose
from ..core.scan import Scan


def stamp_to_seconds(stamp: Time) -> float:
    """A header stamp as seconds, as rclpy's clock gives them (integer ns * 1e-9): the one
    stamp conversion of the package (bag/events.stamp_ns is the exact integer)."""
    return stamp_ns(stamp) * 1e-9


def ns_to_stamp(ns: int) -> Time:
    """Integer nanoseconds as a header stamp (exact)."""
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def seconds_to_stamp(t: float) -> Time:
    return ns_to_stamp(int(round(t * 1e9)))


def scan_from_msg(msg: LaserScan) -> Scan:
    """LaserScan -> Scan (stamp [s]: its first beam's instant; time_increment, scan_time
    as the driver gave them, a negative or non-finite one taken as 0: unknown). Its
    geometry is checked by the planner (Scan.check)."""
    def seconds(v: float) -> float:
        return float(v) if math.isfinite(v) and v > 0.0 else 0.0
    return Scan(np.asarray(msg.ranges, dtype=float), float(msg.angle_min),
                float(msg.angle_increment), float(msg.range_min), float(msg.range_max),
                stamp_to_seconds(msg.header.stamp), seconds(msg.time_increment),
                seconds(msg.scan_time))


def scan_to_msg(scan: Scan, frame_id: str, scan_time: float = 0.2) -> LaserScan:
    """Scan -> LaserScan in ``frame_id``, stamped with the scan's stamp (its first
    beam's instant); its time_increment and scan_time, or for a scan taken at once
    (time_increment 0) ``scan_time`` [s] (5 Hz: 0.2) and a time_increment of 0."""
    n = len(scan.ranges)
    msg = LaserScan()
    msg.header.stamp = seconds_to_stamp(scan.stamp)
    msg.header.frame_id = frame_id
    msg.angle_min = float(scan.angle_min)
    msg.angle_increment = float(scan.angle_increment)
    msg.angle_max = float(scan.angle_min + scan.angle_increment * (n - 1))
    msg.range_min = float(scan.range_min)
    msg.range_max = float(scan.range_max)
    msg.scan_time = float(scan.scan_time or scan_time)
    msg.time_increment = float(scan.time_increment)
    msg.ranges = np.asarray(scan.ranges, dtype=np.float32).tolist()
    return msg


def _unit_quaternion(x: float, y: float, z: float, w: float
                     ) -> tuple[float, float, float, float] | None:
    """The quaternion normalised; None for a zero or non-finite one."""
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if not math.isfinite(n) or n < 1e-9:
        return None
    return x / n, y / n, z / n, w / n


def _yaw_of_unit(x: float, y: float, z: float, w: float) -> float:
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Yaw of a quaternion (normalised first); NaN for a zero or non-finite one."""
    q = _unit_quaternion(x, y, z, w)
    return math.nan if q is None else _yaw_of_unit(*q)


def pose_from_odom(msg: Odometry) -> np.ndarray:
    """(x, y, yaw) of the child frame in the odom frame; NaN where the message is bad."""
    p = msg.pose.pose.position
    q = msg.pose.pose.orientation
    return np.array([p.x, p.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)], dtype=float)


def odom_to_msg(pose: np.ndarray, twist: tuple[float, float], stamp: float,
                frame_id: str = 'odom', child_frame_id: str = 'base_footprint') -> Odometry:
    msg = Odometry()
    msg.header.stamp = seconds_to_stamp(stamp)
    msg.header.frame_id = frame_id
    msg.child_frame_id = child_frame_id
    msg.pose.pose.position.x = float(pose[0])
    msg.pose.pose.position.y = float(pose[1])
    msg.pose.pose.orientation.z = math.sin(float(pose[2]) / 2.0)
    msg.pose.pose.orientation.w = math.cos(float(pose[2]) / 2.0)
    msg.twist.twist.linear.x = float(twist[0])
    msg.twist.twist.angular.z = float(twist[1])
    return msg


def pose_msg(pose: np.ndarray, frame: str, stamp: Time) -> PoseStamped:
    """A planar pose (x, y, yaw) [m, m, rad] as geometry_msgs/PoseStamped."""
    msg = PoseStamped()
    msg.header.frame_id = frame
    msg.header.stamp = stamp
    msg.pose.position.x, msg.pose.position.y = float(pose[0]), float(pose[1])
    msg.pose.orientation.z = math.sin(0.5 * float(pose[2]))
    msg.pose.orientation.w = math.cos(0.5 * float(pose[2]))
    return msg


def transform_msg(parent: str, child: str, xyz: tuple[float, float, float], yaw: float,
                  stamp: float) -> TransformStamped:
    """A TransformStamped parent -> child (REP-105 frames), rotation about z only."""
    t = TransformStamped()
    t.header.stamp = seconds_to_stamp(stamp)
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = \
        map(float, xyz)
    t.transform.rotation.z = math.sin(yaw / 2.0)
    t.transform.rotation.w = math.cos(yaw / 2.0)
    return t


#: Roll or pitch beyond this and a transform is not level: a 2-D laser tilted (or
#: mounted upside down) is not what laser_x, laser_y, laser_yaw describe [rad].
LEVEL_TOLERANCE = 0.05


def planar_transform(t: TransformStamped) -> tuple[str, str, tuple[float, float, float],
                                                   bool]:
    """(parent, child, (x, y, yaw), level) of a transform: its planar part, and whether
    its roll and pitch are within LEVEL_TOLERANCE (the rotation normalised first; a
    zero or non-finite one is not level, its yaw NaN)."""
    r = t.transform.rotation
    v = t.transform.translation
    q = _unit_quaternion(r.x, r.y, r.z, r.w)
    yaw, level = math.nan, False
    if q is not None:
        x, y, z, w = q
        yaw = _yaw_of_unit(x, y, z, w)
        roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
        pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
        level = abs(roll) <= LEVEL_TOLERANCE and abs(pitch) <= LEVEL_TOLERANCE
    return t.header.frame_id, t.child_frame_id, (float(v.x), float(v.y), yaw), level


def cmd_to_msg(v: float, w: float, stamped: bool, stamp: Time | None = None,
               frame_id: str = 'base_link') -> Twist | TwistStamped:
    twist = Twist()
    twist.linear.x = float(v)
    twist.angular.z = float(w)
    if not stamped:
        return twist
    msg = TwistStamped()
    if stamp is not None:
        msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.twist = twist
    return msg


def cmd_from_msg(msg: Twist | TwistStamped) -> tuple[float, float]:
    """(v, w) of a Twist or TwistStamped."""
    twist = msg.twist if isinstance(msg, TwistStamped) else msg
    return float(twist.linear.x), float(twist.angular.z)


def grid_to_msg(grid: OccupancyGrid, frame: str, stamp: Time,
                frame_pose: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> GridMsg:
    """The occupancy memory as nav_msgs/OccupancyGrid: occupancy probability 0-100 from
    the log odds, -1 where nothing was ever seen; row-major from cell (0, 0).
    ``frame_pose``: the pose of the memory's frame in ``frame`` (the origin is turned
    with it)."""
    msg = GridMsg()
    msg.header.frame_id = frame
    msg.header.stamp = stamp
    msg.info.map_load_time = stamp
    msg.info.resolution = float(grid.resolution)
    msg.info.width = msg.info.height = int(grid.cells)
    x, y, yaw = compose(frame_pose, (float(grid.origin[0]), float(grid.origin[1]), 0.0))
    msg.info.origin.position.x, msg.info.origin.position.y = x, y
    msg.info.origin.orientation.z = math.sin(0.5 * yaw)
    msg.info.origin.orientation.w = math.cos(0.5 * yaw)
    lo = grid.log_odds.astype(np.float64)
    data = np.rint(100.0 / (1.0 + np.exp(-lo))).astype(np.int8)
    data[lo == 0.0] = -1
    msg.data = array.array('b', data.tobytes())   # (a list is checked element by element)
    return msg


def path_to_msg(points: np.ndarray, frame: str, stamp: Time) -> Path:
    """A polyline (k, 2) [m] as nav_msgs/Path (orientations along the path)."""
    msg = Path()
    msg.header.frame_id = frame
    msg.header.stamp = stamp
    pts = np.asarray(points, float).reshape(-1, 2)
    heading = np.arctan2(*np.diff(pts, axis=0, append=pts[-1:]).T[::-1]) if len(pts) else []
    for (x, y), yaw in zip(pts, heading, strict=True):
        pose = PoseStamped()
        pose.header = msg.header
        pose.pose.position.x, pose.pose.position.y = float(x), float(y)
        pose.pose.orientation.z = math.sin(0.5 * yaw)
        pose.pose.orientation.w = math.cos(0.5 * yaw)
        msg.poses.append(pose)
    return msg


def known_map_from_msg(msg: GridMsg) -> KnownMap:
    """A nav_msgs/OccupancyGrid (map_server's, slam_toolbox's) as a KnownMap in its own
    frame (the origin's yaw kept); KnownMapError when it is malformed."""
    info = msg.info
    n = info.width * info.height
    if n == 0 or len(msg.data) != n:
        raise KnownMapError(f'map of {info.width} x {info.height} cells with '
                            f'{len(msg.data)} values')
    cells = np.asarray(msg.data, np.int8).reshape(info.height, info.width)
    o = info.origin
    yaw = yaw_from_quaternion(o.orientation.x, o.orientation.y, o.orientation.z,
                              o.orientation.w)
    return KnownMap(cells, (0.0, 0.0), float(info.resolution),
                    pose=(float(o.position.x), float(o.position.y), float(yaw)))


def known_map_to_msg(known: KnownMap, frame: str, stamp: Time) -> GridMsg:
    """A KnownMap placed at the identity as nav_msgs/OccupancyGrid in ``frame``."""
    msg = GridMsg()
    msg.header.frame_id = frame
    msg.header.stamp = stamp
    h, w = np.shape(known.cells)
    msg.info.resolution = float(known.resolution)
    msg.info.width, msg.info.height = int(w), int(h)
    msg.info.origin.position.x, msg.info.origin.position.y = map(float, known.origin)
    msg.info.origin.orientation.w = 1.0
    msg.data = array.array('b', np.ascontiguousarray(known.cells, np.int8).tobytes())
    return msg
