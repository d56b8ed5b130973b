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

from collections.abc import Mapping
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
    #: The frame odometry gives the pose of (REP-105: base_footprint), and the laser's
    #: frame (its scans' frame_id) and rated largest range [m].
    base_frame: str = 'base_footprint'
    laser_frame: str = 'base_scan'
    laser_range: float = 3.5
    #: Whether its base takes geometry_msgs/TwistStamped on cmd_vel (else Twist).
    stamped_cmd_vel: bool = True
    #: Where each number comes from.
    source: str = ''
    #: Largest accelerations the robot can do [m/s^2, rad/s^2]; None: no source states
    #: one (the shipped robots: their Nav2 configs' acceleration limits are tuning, not
    #: the base's), and the planner's are then not checked against it.
    max_linear_acceleration: float | None = None
    max_angular_acceleration: float | None = None

    @property
    def clearance(self) -> float:
        """Gap the local layer keeps between a laser point and the robot's centre (samples,
        DWA arcs): the footprint plus CLEARANCE_MARGIN [m]."""
        return round(self.radius + CLEARANCE_MARGIN, 6)

    @property
    def safety_distance(self) -> float:
        """Reach of the forward safety corridor from the robot's centre: the footprint
        plus SAFETY_MARGIN [m]."""
        return round(self.radius + SAFETY_MARGIN, 6)

    @property
    def solve_radius(self) -> float:
        """Radius of the disc that must fit through every generated world: the footprint
        plus SOLVE_MARGIN [m]."""
        return round(self.radius + SOLVE_MARGIN, 6)


#: Margin of the local layer's clearance over the footprint [m] (laser noise 0.01 m,
#: one 0.02 m step of lag).
CLEARANCE_MARGIN = 0.03
#: Margin of the forward safety corridor over the footprint [m] (0.18 m for the burger:
#: at 0.22 m/s, 0.3 s of travel).
SAFETY_MARGIN = 0.075
#: Margin a generated world's narrowest gap keeps over the footprint, each side [m].
SOLVE_MARGIN = 0.05

#: TurtleBot3 burger (ROBOTIS e-Manual, "Specifications" and its URDF
#: turtlebot3_burger.urdf): 0.105 m navigation radius (Nav2 robot_radius of the
#: turtlebot3 package), base_scan at (-0.032, 0, 0.172) in base_link, base_link 0.010 m
#: above base_footprint; wheels 0.033 m radius, 0.160 m apart; 0.22 m/s, 2.84 rad/s.
BURGER = RobotDescription(
    name='turtlebot3_burger', radius=0.105, laser=LaserMount(-0.032, 0.0, 0.182, 0.0),
    wheel_radius=0.033, wheel_separation=0.160, max_linear_velocity=0.22,
    max_angular_velocity=2.84, base_link_height=0.010, laser_frame='base_scan',
    laser_range=3.5, stamped_cmd_vel=True,
    source='ROBOTIS e-Manual "Specifications" (0.22 m/s, 2.84 rad/s, 138 x 178 mm); '
    'turtlebot3_description/urdf/turtlebot3_burger.urdf (base_scan at (-0.032, 0, 0.172) '
    'in base_link, base_link 0.010 m up; wheels 0.033 m, 0.160 m apart); Nav2 '
    'robot_radius 0.105 m of the turtlebot3 package; LDS-01 0.12-3.5 m (an LDS-02 '
    'burger: 0.16-8 m, set obstacle_range); Jazzy turtlebot3_node takes TwistStamped')
#: TurtleBot3 Waffle Pi (and the discontinued Waffle: same base, limits and laser).
WAFFLE_PI = RobotDescription(
    name='turtlebot3_waffle_pi', radius=0.24, laser=LaserMount(-0.064, 0.0, 0.131, 0.0),
    wheel_radius=0.033, wheel_separation=0.288, max_linear_velocity=0.26,
    max_angular_velocity=1.82, base_link_height=0.010, laser_frame='base_scan',
    laser_range=3.5, stamped_cmd_vel=True,
    source='ROBOTIS e-Manual "Specifications" (0.26 m/s, 1.82 rad/s, 281 x 306 mm); '
    'turtlebot3_description/urdf/turtlebot3_waffle_pi.urdf.xacro (base_scan at '
    '(-0.064, 0, 0.121) in base_link, base_link 0.010 m up; wheels 0.033 m, 0.288 m '
    'apart; body box 0.266 m square centred 0.064 m behind the axle: its rear corners '
    '0.238 m from base_footprint, hence the 0.24 m radius); LDS-01 0.12-3.5 m')
#: TurtleBot 4 (standard and lite: an iRobot Create 3 base with an RPLIDAR A1M8).
TURTLEBOT4 = RobotDescription(
    name='turtlebot4', radius=0.175, laser=LaserMount(-0.04, 0.0, 0.193, math.pi / 2),
    wheel_radius=0.03575, wheel_separation=0.233, max_linear_velocity=0.26,
    max_angular_velocity=1.0, base_link_height=0.0, base_frame='base_link',
    laser_frame='rplidar_link', laser_range=12.0, stamped_cmd_vel=True,
    source='turtlebot4_navigation/config/nav2.yaml for Jazzy (robot_radius 0.175 m; '
    'velocity_smoother max_velocity 0.26 m/s, 1.0 rad/s; enable_stamped_cmd_vel true); '
    'turtlebot4_description/urdf/standard/turtlebot4.urdf.xacro (rplidar_link 0.04 m '
    'behind base_link, turned by +pi/2, about 0.193 m up); irobot_create_description '
    '(body radius 0.164 m, wheels 0.03575 m, 0.233 m apart; base_link on the ground: '
    'it is the base frame); RPLIDAR A1M8 0.15-12 m')
#: The robots config/robots/ has a parameter file for, by file name.
ROBOTS = {'burger': BURGER, 'waffle_pi': WAFFLE_PI, 'turtlebot4': TURTLEBOT4}


def compose(parent: ArrayLike, child: ArrayLike) -> tuple[float, float, float]:
    """The pose ``child`` (x, y, yaw), given in the frame whose pose is ``parent``,
    expressed in parent's frame: e.g. base_scan in odom from base_footprint in odom and
    the mounting. The yaw in [-pi, pi] [rad]: a motion between two poses either side of
    +-pi is the small turn between them, not a turn and a whole one."""
    x, y, yaw = (float(v) for v in parent)
    cx, cy, cyaw = (float(v) for v in child)
    c, s = math.cos(yaw), math.sin(yaw)
    return (x + c * cx - s * cy, y + s * cx + c * cy, math.remainder(yaw + cyaw, 2 * math.pi))


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


def chain(links: Mapping[str, tuple[str, tuple[float, float, float]]], base: str,
          leaf: str, max_links: int = 32
          ) -> tuple[tuple[float, float, float], list[str]] | None:
    """The planar pose (x, y, yaw) of frame ``leaf`` in frame ``base`` from ``links``
    (child -> (parent, its pose in the parent)), walking from ``leaf`` up through its
    parents, and the child frames of the links it took (leaf first); None when ``base``
    is not among them (or the links loop). The yaw is wrapped to [-pi, pi]."""
    poses, frames = [], []
    frame = leaf
    while frame != base:
        if frame not in links or len(poses) >= max_links:
            return None
        frames.append(frame)
        frame, pose = links[frame]
        poses.append(pose)
    out = (0.0, 0.0, 0.0)
    for pose in reversed(poses):
        out = compose(out, pose)
    return (out[0], out[1], math.remainder(out[2], 2.0 * math.pi)), frames
