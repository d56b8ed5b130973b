"""The robot, described once: footprint, laser mounting, wheels, limits; and its frames.

Every part of the package that needs a fact about the robot takes it from a
:class:`RobotDescription`: the planner's parameter defaults (core/config.py),
the simulator (sim/simulator.py and its URDF, tied by ``test/test_robot.py``),
the world checks (sim/world.py) and the solvability check (sim/solvability.py).
The clearances the planner keeps are derived from the footprint here.

Frames follow REP-105: ``odom`` -> ``base_footprint`` (the robot's pose, x
forward, y left, on the ground) -> ``base_scan`` (the laser). A planar pose is
(x, y, yaw) [m, m, rad]; :func:`compose` and :func:`to_parent` are the only
places a pose is applied.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray


@dataclass(frozen=True)
class LaserMount:
    """base_scan in base_footprint: x, y, z [m] and yaw [rad] (a level 2-D laser)."""

    x: float
    y: float
    z: float
    yaw: float = 0.0

    @property
    def planar(self) -> tuple[float, float, float]:
        """(x, y, yaw) of the mounting [m, m, rad]."""
        return (self.x, self.y, self.yaw)


@dataclass(frozen=True)
class RobotDescription:
    """A differential-drive robot with a round footprint (SI units)."""

    name: str
    #: Radius of the circle that holds the footprint [m].
    radius: float
    laser: LaserMount
    wheel_radius: float
    wheel_separation: float
    max_linear_velocity: float
    max_angular_velocity: float
    #: Height of base_link above base_footprint [m].
    base_link_height: float = 0.0

    @property
    def clearance(self) -> float:
        """Gap the local layer keeps between a laser point and the robot's centre (samples,
        DWA arcs): the footprint plus CLEARANCE_MARGIN [m]."""
        return round(self.radius + CLEARANCE_MARGIN, 6)

    @property
    def solve_radius(self) -> float:
        """Radius of the disc that must fit through every generated world: the footprint
        plus SOLVE_MARGIN [m]."""
        return round(self.radius + SOLVE_MARGIN, 6)


#: Margin of the local layer's clearance over the footprint [m] (laser noise 0.01 m,
#: one 0.02 m step of lag).
CLEARANCE_MARGIN = 0.03
#: Margin a generated world's narrowest gap keeps over the footprint, each side [m].
SOLVE_MARGIN = 0.05

#: TurtleBot3 burger (ROBOTIS e-Manual, "Specifications" and its URDF
#: turtlebot3_burger.urdf): 0.105 m navigation radius (Nav2 robot_radius of the
#: turtlebot3 package), base_scan at (-0.032, 0, 0.172) in base_link, base_link 0.010 m
#: above base_footprint; wheels 0.033 m radius, 0.160 m apart; 0.22 m/s, 2.84 rad/s.
BURGER = RobotDescription(
    name='turtlebot3_burger', radius=0.105, laser=LaserMount(-0.032, 0.0, 0.182, 0.0),
    wheel_radius=0.033, wheel_separation=0.160, max_linear_velocity=0.22,
    max_angular_velocity=2.84, base_link_height=0.010)


def compose(parent: ArrayLike, child: ArrayLike) -> tuple[float, float, float]:
    """The pose ``child`` (x, y, yaw), given in the frame whose pose is ``parent``,
    expressed in parent's frame: e.g. base_scan in odom from base_footprint in odom and
    the mounting."""
    x, y, yaw = (float(v) for v in parent)
    cx, cy, cyaw = (float(v) for v in child)
    c, s = math.cos(yaw), math.sin(yaw)
    return (x + c * cx - s * cy, y + s * cx + c * cy, yaw + cyaw)


def invert(pose: ArrayLike) -> tuple[float, float, float]:
    """The pose of the parent frame in the frame whose pose is ``pose`` (x, y, yaw):
    compose(pose, invert(pose)) is the identity."""
    x, y, yaw = (float(v) for v in pose)
    c, s = math.cos(yaw), math.sin(yaw)
    return (-c * x - s * y, s * x - c * y, -yaw)


def to_parent(pose: ArrayLike, points: ArrayLike) -> NDArray[np.float64]:
    """Points (n, 2) given in the frame whose pose is ``pose`` (x, y, yaw), expressed in
    the frame the pose is given in [m]."""
    x, y, yaw = (float(v) for v in pose)
    p = np.asarray(points, float).reshape(-1, 2)
    c, s = math.cos(yaw), math.sin(yaw)
    return np.column_stack((x + c * p[:, 0] - s * p[:, 1], y + s * p[:, 0] + c * p[:, 1]))
