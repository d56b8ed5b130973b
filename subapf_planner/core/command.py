"""Command shaping for a differential drive: next move point -> (v, w).

Defaults are the TurtleBot3 burger's limits (0.22 m/s, 2.84 rad/s); the goal
gates (reached, inside an obstacle) come before this (core/planner.py).
Order of rules: no safe point -> stop; heading error beyond
``rotate_in_place_angle`` -> turn on the spot; otherwise drive at the speed
that covers the step in one planning period, scaled by cos(heading error) and
slowed inside ``slowdown_distance`` of the goal; then acceleration limits;
last, the safety corridor zeroes forward speed while an obstacle point lies
ahead, within ``robot_radius`` of the heading line and closer than
``safety_distance`` to the centre (with a footprint polygon: within its half-width;
and where turning on the spot would sweep a corner into something it backs straight
up, ``backing_up``, while the way behind is clear, else stops). Stops are immediate
(not rate limited).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike

from .config import PlannerConfig
from .footprint import TURN_MARGIN
from .status import Status

#: Backing up to make room for a turn: at this fraction of the top speed (at most
#: reverse_speed), while nothing lies within BACKING_REACH [m] behind the footprint.
BACKING_SPEED = 0.25
BACKING_REACH = 0.15


@dataclass(frozen=True)
class Command:
    """Velocity command in base_footprint: v [m/s] forward, w [rad/s] counter-clockwise."""

    v: float
    w: float
    status: Status


def wrap_angle(a: float) -> float:
    """Angle wrapped to [-pi, pi] [rad]."""
    return math.remainder(a, 2.0 * math.pi)


def _robot_frame(pose: ArrayLike, points: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Points (m, 2) in the frame of the robot at ``pose``: ahead (x) and left (y) [m]."""
    obs = np.asarray(points, float).reshape(-1, 2)
    x, y, yaw = (float(v) for v in pose)
    dx, dy = obs[:, 0] - x, obs[:, 1] - y
    c, s = math.cos(yaw), math.sin(yaw)
    return c * dx + s * dy, -s * dx + c * dy


def forward_blocked(pose: ArrayLike, obstacles: ArrayLike, cfg: PlannerConfig) -> bool:
    """True when an obstacle point lies ahead (x > 0 in the robot frame), within the
    corridor |y| <= robot_radius and closer than safety_distance to the centre; with a
    footprint polygon, within its half-width and closer than safety_distance -
    robot_radius to its front."""
    shape = cfg.polygon
    if shape is not None:
        return bool(shape.corridor(pose, obstacles, corridor_reach(cfg))[0])
    fx, fy = _robot_frame(pose, obstacles)
    if fx.size == 0:
        return False
    hit = (fx > 0.0) & (np.abs(fy) <= cfg.robot_radius) & (np.hypot(fx, fy)
                                                             < cfg.safety_distance)
    return bool(np.any(hit))


def corridor_reach(cfg: PlannerConfig) -> float:
    """How far ahead of a footprint polygon's origin the forward check looks [m]: its
    front plus safety_distance - robot_radius."""
    return cfg.polygon.front + cfg.safety_distance - cfg.robot_radius


def backward_blocked(pose: ArrayLike, obstacles: ArrayLike, cfg: PlannerConfig) -> bool:
    """With a footprint polygon, whether an obstacle point lies behind it within its
    half-width and BACKING_REACH of its rear (True for a disc: it never backs up here)."""
    shape = cfg.polygon
    if shape is None:
        return True
    fx, fy = _robot_frame(pose, obstacles)
    rear = float(shape.vertices[:, 0].min())
    hit = (fx < 0.0) & (np.abs(fy) <= shape.half_width + TURN_MARGIN) \
        & (fx > rear - BACKING_REACH)
    return bool(np.any(hit))


def turn_blocked(pose: ArrayLike, turn: float, obstacles: ArrayLike,
                 cfg: PlannerConfig) -> bool:
    """With a footprint polygon, whether turning on the spot by ``turn`` [rad] brings a
    corner within TURN_MARGIN of an obstacle point (a disc turns freely)."""
    shape = cfg.polygon
    if shape is None:
        return False
    return shape.turn_contact(pose, turn, obstacles, TURN_MARGIN)


def _clamp(value: float, limit: float) -> float:
    """``value`` within [-limit, limit] (limit >= 0)."""
    return min(max(float(value), -limit), limit)


def _rate_limit(value: float, previous: float, max_rate: float, dt: float) -> float:
    step = max_rate * dt
    return min(max(value, previous - step), previous + step)


def shape_command(pose: ArrayLike, target: ArrayLike | None, goal: ArrayLike,
                  previous: tuple[float, float], obstacles: ArrayLike,
                  cfg: PlannerConfig) -> Command:
    """(v, w) that moves the robot at ``pose`` (x, y, yaw) towards ``target`` (None: no
    safe point, a stop), slowing down near ``goal``; ``previous`` is the last (v, w)."""
    x, y, yaw = (float(v) for v in pose)
    gx, gy = (float(v) for v in goal)
    dist_goal = math.hypot(gx - x, gy - y)
    if target is None:
        return Command(0.0, 0.0, Status.NO_SAFE_MOVE)
    tx, ty = (float(v) for v in target)
    dist = math.hypot(tx - x, ty - y)
    alpha = wrap_angle(math.atan2(ty - y, tx - x) - yaw) if dist > 1e-9 else 0.0
    w = _clamp(cfg.heading_gain * alpha, cfg.max_angular_velocity)
    if abs(alpha) > cfg.rotate_in_place_angle:
        v, status = 0.0, Status.TURNING
        if turn_blocked(pose, alpha, obstacles, cfg):
            # a polygon's corner would sweep into something: back up to make room, or stop
            if cfg.reverse_speed <= 0.0 or backward_blocked(pose, obstacles, cfg):
                return Command(0.0, 0.0, Status.NO_SAFE_MOVE)
            return Command(-min(cfg.reverse_speed, BACKING_SPEED * cfg.max_linear_velocity),
                           0.0, Status.BACKING_UP)
    else:
        slow = 1.0
        if cfg.slowdown_distance > 0.0:
            floor = min(1.0, cfg.approach_speed / cfg.max_linear_velocity) \
                if cfg.max_linear_velocity > 0.0 else 1.0
            slow = min(1.0, max(floor, dist_goal / cfg.slowdown_distance))
        v = min(cfg.max_linear_velocity * slow, dist / cfg.period) * math.cos(alpha)
        v, status = max(v, 0.0), Status.DRIVING
    v_prev, w_prev = previous
    v = _rate_limit(v, v_prev, cfg.max_linear_acceleration, cfg.period)
    w = _rate_limit(w, w_prev, cfg.max_angular_acceleration, cfg.period)
    v = min(max(v, 0.0), cfg.max_linear_velocity)
    w = _clamp(w, cfg.max_angular_velocity)
    if v > 0.0 and forward_blocked(pose, obstacles, cfg):
        v, status = 0.0, Status.BLOCKED_AHEAD
    return Command(v, w, status)
