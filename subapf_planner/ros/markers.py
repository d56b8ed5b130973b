"""RViz/Foxglove markers of one planning cycle: what the planner saw and chose."""

from __future__ import annotations

import math

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point
import numpy as np
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from ..core.planner import PlanResult
from ..core.robot import compose, invert
from ..core.scan import voxel_downsample
from ..sim.world import Box, Circle


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
    return [Point(x=x, y=y) for x, y in np.asarray(xy, float).reshape(-1, 2).tolist()]


def _placed(m: Marker, pose: tuple[float, float, float]) -> Marker:
    """The marker with its pose composed after ``pose`` (x, y, yaw): its points, given in
    the frame whose pose in the header's frame that is, drawn where they are."""
    yaw = 2.0 * math.atan2(m.pose.orientation.z, m.pose.orientation.w)
    x, y, yaw = compose(pose, (m.pose.position.x, m.pose.position.y, yaw))
    m.pose.position.x, m.pose.position.y = x, y
    m.pose.orientation.z, m.pose.orientation.w = math.sin(0.5 * yaw), math.cos(0.5 * yaw)
    return m


def _circle(pose: np.ndarray, radius: float, n: int = 36) -> np.ndarray:
    """(n + 2, 2) points of a circle of ``radius`` [m] round ``pose`` (x, y, yaw),
    starting and ending ahead of it, then its centre: the closed outline and the
    heading as one line strip."""
    a = pose[2] + np.linspace(0.0, 2.0 * math.pi, n + 1)
    ring = np.column_stack((pose[0] + radius * np.cos(a), pose[1] + radius * np.sin(a)))
    return np.vstack((ring, pose[None, :2]))


def markers_from_result(result: PlanResult, frame: str, stamp: Time,
                        danger_distance: float, robot_radius: float,
                        voxel: float = 0.05) -> MarkerArray:
    """Obstacle points (voxel-downsampled, as the repulsion sees them), raw next move
    point, samples coloured by score, chosen point, the moving tracks, the robot's
    footprint (radius [m], with its heading) and the danger circle round it, for RViz
    or Foxglove, in ``frame`` (odom: each marker's pose carries the memory frame's
    place in it, ``invert(result.correction)``)."""
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
    out.markers.extend(track_markers(result, frame, stamp))
    for ns, radius, rgba in (('footprint', robot_radius, (0.1, 0.1, 0.1, 0.9)),
                             ('danger_circle', danger_distance, (1.0, 0.0, 0.0, 0.5))):
        ring = _marker(ns, 0, Marker.LINE_STRIP, frame, stamp, 0.01, rgba)
        if result.pose is not None:
            ring.points = _points(_circle(np.asarray(result.pose, float), radius))
        out.markers.append(ring)
    if result.correction != (0.0, 0.0, 0.0):
        memory_frame = invert(result.correction)
        out.markers = [_placed(m, memory_frame) for m in out.markers]
    return out


#: Seconds of prediction drawn for each moving track.
PREDICTION_SHOWN = 2.0


def track_markers(result: PlanResult, frame: str, stamp: Time) -> list[Marker]:
    """The moving tracks of a cycle: their positions (orange points), velocity arrows
    (one LINE_LIST: position -> position + velocity * 1 s) and predicted paths
    (position -> position + velocity * PREDICTION_SHOWN, thin). Three markers always
    (empty when nothing moves), so a viewer's old tracks are replaced."""
    t = result.tracks
    moving = t.moving
    pos, vel = t.position[moving], t.velocity[moving]
    here = _marker('tracks', 0, Marker.POINTS, frame, stamp, 0.08, (1.0, 0.5, 0.0, 1.0))
    here.points = _points(pos)
    arrows = _marker('track_velocity', 0, Marker.LINE_LIST, frame, stamp, 0.02,
                     (1.0, 0.3, 0.0, 1.0))
    arrows.points = _points(np.column_stack((pos, pos + vel)).reshape(-1, 2))
    paths = _marker('track_prediction', 0, Marker.LINE_LIST, frame, stamp, 0.01,
                    (1.0, 0.7, 0.2, 0.6))
    paths.points = _points(np.column_stack((pos, pos + PREDICTION_SHOWN * vel)).reshape(-1, 2))
    return [here, arrows, paths]


def moving_obstacle_markers(obstacles: tuple[Circle | Box, ...], frame: str,
                            stamp: Time) -> MarkerArray:
    """The true outlines of a world's moving obstacles (sim_node's ``moving_obstacles``):
    a cylinder per circle, a box per box, 0.5 m tall, ids in world order."""
    out = MarkerArray()
    for i, o in enumerate(obstacles):
        kind = Marker.CYLINDER if isinstance(o, Circle) else Marker.CUBE
        m = _marker('moving_obstacles', i, kind, frame, stamp, 1.0, (1.0, 0.55, 0.0, 0.8))
        m.pose.position.x, m.pose.position.y = (float(v) for v in o.center)
        m.pose.position.z = 0.25
        if isinstance(o, Circle):
            m.scale.x = m.scale.y = 2.0 * o.radius
        else:
            m.scale.x, m.scale.y = (float(v) for v in o.size)
            m.pose.orientation.z, m.pose.orientation.w = math.sin(o.yaw / 2), math.cos(o.yaw / 2)
        m.scale.z = 0.5
        out.markers.append(m)
    return out
