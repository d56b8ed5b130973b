"""ROS 2 message <-> numpy conversions, in one place (no node, no rclpy.init needed)."""

from __future__ import annotations

import math

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, TransformStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
import numpy as np
from sensor_msgs.msg import LaserScan
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from ..core.controller import ScanInput
from ..core.planner import PlanResult
from ..core.scan import voxel_downsample


def stamp_to_seconds(stamp: Time) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def seconds_to_stamp(t: float) -> Time:
    ns = int(round(t * 1e9))
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def scan_from_msg(msg: LaserScan) -> ScanInput:
    """LaserScan -> ScanInput. Geometry is checked later by scan.scan_to_points."""
    return ScanInput(np.asarray(msg.ranges, dtype=float), float(msg.angle_min),
                     float(msg.angle_increment), float(msg.range_min), float(msg.range_max),
                     stamp_to_seconds(msg.header.stamp))


def scan_to_msg(ranges: np.ndarray, angle_min: float, angle_increment: float,
                range_min: float, range_max: float, stamp: float, frame_id: str,
                scan_time: float = 0.2) -> LaserScan:
    msg = LaserScan()
    msg.header.stamp = seconds_to_stamp(stamp)
    msg.header.frame_id = frame_id
    msg.angle_min = float(angle_min)
    msg.angle_increment = float(angle_increment)
    msg.angle_max = float(angle_min + angle_increment * (len(ranges) - 1))
    msg.range_min = float(range_min)
    msg.range_max = float(range_max)
    msg.scan_time = float(scan_time)
    msg.time_increment = float(scan_time / max(len(ranges), 1))
    msg.ranges = np.asarray(ranges, dtype=np.float32).tolist()
    return msg


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Yaw of a quaternion (normalised first); NaN for a zero or non-finite one."""
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if not math.isfinite(n) or n < 1e-9:
        return math.nan
    x, y, z, w = x / n, y / n, z / n, w / n
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


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


def _marker(ns: str, mid: int, mtype: int, frame: str, stamp: Time, scale: float,
            rgba: tuple[float, float, float, float]) -> Marker:
    m = Marker()
    m.header.frame_id = frame
    m.header.stamp = stamp
    m.ns, m.id, m.type, m.action = ns, mid, mtype, Marker.ADD
    m.pose.orientation.w = 1.0
    m.scale.x = m.scale.y = m.scale.z = scale
    m.color = ColorRGBA(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3])
    return m


def _points(xy: np.ndarray) -> list[Point]:
    return [Point(x=float(x), y=float(y), z=0.0) for x, y in np.asarray(xy).reshape(-1, 2)]


def markers_from_result(result: PlanResult, frame: str, stamp: Time,
                        danger_distance: float, position: np.ndarray,
                        voxel: float = 0.05) -> MarkerArray:
    """Obstacle points (voxel-downsampled, as the repulsion sees them), raw next move
    point, samples coloured by score, chosen point and the danger circle around the
    robot, for RViz or Foxglove."""
    out = MarkerArray()
    obs = _marker('obstacles', 0, Marker.POINTS, frame, stamp, 0.03, (0.9, 0.2, 0.2, 1.0))
    obs.points = _points(voxel_downsample(result.obstacles, voxel))
    out.markers.append(obs)
    for ns, point, rgba in (('raw_point', result.raw_point, (1.0, 0.6, 0.0, 1.0)),
                            ('chosen_point', result.chosen_point, (0.0, 0.8, 0.0, 1.0))):
        m = _marker(ns, 0, Marker.SPHERE, frame, stamp, 0.04, rgba)
        if point is None:
            m.action = Marker.DELETE
        else:
            m.pose.position.x, m.pose.position.y = float(point[0]), float(point[1])
        out.markers.append(m)
    samples = _marker('samples', 0, Marker.POINTS, frame, stamp, 0.02, (0.2, 0.2, 1.0, 1.0))
    if result.sampling is not None:
        samples.points = _points(result.sampling.samples)
        scores = result.sampling.scores
        finite = scores[np.isfinite(scores)]
        lo, hi = (finite.min(), finite.max()) if finite.size else (0.0, 1.0)
        for s in scores:
            if not np.isfinite(s):
                samples.colors.append(ColorRGBA(r=0.3, g=0.3, b=0.3, a=0.6))
            else:
                t = float((s - lo) / (hi - lo)) if hi > lo else 0.0
                samples.colors.append(ColorRGBA(r=t, g=1.0 - t, b=0.2, a=1.0))
    out.markers.append(samples)
    ring = _marker('danger_circle', 0, Marker.LINE_STRIP, frame, stamp, 0.01,
                   (1.0, 0.0, 0.0, 0.5))
    a = np.linspace(0.0, 2.0 * math.pi, 37)
    ring.points = _points(np.column_stack((position[0] + danger_distance * np.cos(a),
                                           position[1] + danger_distance * np.sin(a))))
    out.markers.append(ring)
    return out
