"""Command shaping for a differential drive: next move point -> (v, w).

Defaults are the TurtleBot3 burger's limits (0.22 m/s, 2.84 rad/s); the goal
gates (reached, inside an obstacle) come before this (core/planner.py).
Order of rules: no safe point -> stop; heading error beyond
``rotate_in_place_angle`` -> turn on the spot; otherwise drive at the speed
that covers the step in one planning period, scaled by cos(heading error) and
slowed inside ``slowdown_distance`` of the goal; then acceleration limits;
last, the safety corridor zeroes forward speed while an obstacle point lies
ahead, within ``robot_radius`` of the heading line and closer than
``safety_distance`` to the centre. Stops are immediate (not rate limited).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike

from .config import PlannerConfig
from .status import Status


@dataclass(frozen=True)
class Command:
    """Velocity command in base_footprint: v [m/s] forward, w [rad/s] counter-clockwise."""

    v: float
    w: float
    status: Status


def wrap_angle(a: float) -> float:
    """Angle wrapped to [-pi, pi] [rad]."""
    return math.remainder(a, 2.0 * math.pi)


def forward_blocked(pose: ArrayLike, obstacles: ArrayLike, cfg: PlannerConfig) -> bool:
    """True when an obstacle point lies ahead (x > 0 in the robot frame), within the
    corridor |y| <= robot_radius and closer than safety_distance to the centre."""
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    if obs.shape[0] == 0:
        return False
    x, y, yaw = (float(v) for v in pose)
    dx, dy = obs[:, 0] - x, obs[:, 1] - y
    c, s = math.cos(yaw), math.sin(yaw)
    fx = c * dx + s * dy
    fy = -s * dx + c * dy
    hit = (fx > 0.0) & (np.abs(fy) <= cfg.robot_radius) & (np.hypot(fx, fy)
                                                             < cfg.safety_distance)
    return bool(np.any(hit))


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
    else:
        slow = 1.0
        if cfg.slowdown_distance > 0.0:
            slow = min(1.0, max(0.25, dist_goal / cfg.slowdown_distance))
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
