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

from .footprint import Footprint


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
class Body:
    """What the simulator builds the robot's body from, beyond its footprint and wheels
    (SI units): the body's mass [kg], its height [m] and how far above the ground it
    starts [m], its inertia about base_footprint's axes (ixx, iyy, izz) [kg m^2] (None:
    a uniform prism of the footprint), the wheels' width [m] and motor torque limit
    [N m]. The body and two caster spheres (half-way to the footprint's front and back,
    the body's bottom high) are one frictionless link: only the wheels push on the ground."""

    mass: float = 1.0
    height: float = 0.12
    bottom: float = 0.022
    inertia: tuple[float, float, float] | None = None
    #: Height of the centre of mass above the ground [m] (None: the body's middle).
    mass_height: float | None = None
    wheel_width: float = 0.018
    wheel_torque: float = 0.5
    #: Each wheel's mass [kg] and inertia (ixx, iyy, izz) [kg m^2] (None: sim/body.py's).
    wheel_mass: float | None = None
    wheel_inertia: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class RobotDescription:
    """A differential-drive robot: footprint (a disc or a polygon), laser, wheels, limits
    and planning rate (SI units)."""

    name: str
    #: Radius of the circle that holds the footprint [m] (with a polygon: at least its
    #: farthest vertex's distance from the base frame's origin).
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
    #: The footprint as a convex polygon, its vertices (x, y) [m] in the base frame
    #: counter-clockwise, as Nav2's ``footprint``; empty: the disc of ``radius``.
    footprint: tuple[tuple[float, float], ...] = ()
    #: The lidar's model: its beams, field of view, rate and datasheet errors
    #: (sim/sensor.py LIDARS), and its field of view [rad] (less than a turn: the robot
    #: does not see behind it, and never reverses).
    lidar: str = 'lds01'
    laser_fov: float = 2.0 * math.pi
    #: The lidar's range noise as the planner models it (PlannerConfig.range_noise_floor
    #: and range_noise_fraction): a standard deviation [m] near it, and a fraction of
    #: the range farther out, the datasheet's accuracy taken as two standard deviations
    #: (the LDS-01's: +/-15 mm below 0.5 m, +/-5 % to 3.5 m).
    range_noise: tuple[float, float] = (0.0075, 0.025)
    #: How often the planner plans [Hz].
    planning_frequency: float = 5.0
    #: The simulator's body beyond footprint and wheels.
    body: Body = Body()

    def __post_init__(self) -> None:
        for key, value in (('radius', self.radius), ('wheel_radius', self.wheel_radius),
                           ('wheel_separation', self.wheel_separation),
                           ('max_linear_velocity', self.max_linear_velocity),
                           ('max_angular_velocity', self.max_angular_velocity),
                           ('planning_frequency', self.planning_frequency)):
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f'{self.name}: {key} must be positive, got {value}')
        if len(self.range_noise) != 2 or not all(
                math.isfinite(v) and v >= 0.0 for v in self.range_noise):
            raise ValueError(f'{self.name}: range_noise must be (floor [m], fraction), both '
                             f'finite and not negative, got {self.range_noise}')
        if self.footprint:
            shape = Footprint(np.asarray(self.footprint, float))   # ValueError if no polygon
            if self.radius < shape.circumscribed - 1e-9:
                raise ValueError(f'{self.name}: radius {self.radius} m is less than the '
                                 f"footprint's farthest vertex, {shape.circumscribed:.4f} m")

    @property
    def inscribed_radius(self) -> float:
        """Radius of the largest circle about the base frame's origin inside the footprint
        [m]: the distance to its nearest edge (the disc's radius for a disc)."""
        if not self.footprint:
            return self.radius
        return Footprint(np.asarray(self.footprint, float)).inscribed

    def outline(self, sides: int = 32) -> NDArray[np.float64]:
        """The footprint's vertices (k, 2) [m] in the base frame, counter-clockwise: the
        polygon, or a ``sides``-gon round the disc (its vertices on the circle)."""
        if self.footprint:
            return np.asarray(self.footprint, float)
        a = 2.0 * math.pi * np.arange(sides) / sides
        return self.radius * np.column_stack((np.cos(a), np.sin(a)))

    @property
    def clearance(self) -> float:
        """Gap the local layer keeps between a laser point and the robot's centre (samples,
        DWA arcs): the footprint plus CLEARANCE_MARGIN [m]."""
        return round(self.radius + CLEARANCE_MARGIN, 6)

    @property
    def safety_distance(self) -> float:
        """Reach of the forward safety corridor from the robot's centre: the footprint
        plus SAFETY_MARGIN or SAFETY_TIME of travel at top speed, the longer [m]."""
        return round(self.radius + max(SAFETY_MARGIN,
                                       SAFETY_TIME * self.max_linear_velocity), 6)

    @property
    def sees_all_round(self) -> bool:
        """Whether its laser sees the whole turn (behind it too)."""
        return self.laser_fov >= 2.0 * math.pi - 1e-9

    @property
    def pace(self) -> float:
        """How far the robot goes in one planning period at top speed, over the burger's
        (0.22 m/s at 5 Hz: 0.044 m): the planner's step lengths scale by it."""
        return (self.max_linear_velocity / self.planning_frequency) / BURGER_STEP

    @property
    def solve_radius(self) -> float:
        """Radius of the disc that must fit through every generated world: the footprint
        plus SOLVE_MARGIN [m]."""
        return round(self.radius + SOLVE_MARGIN, 6)


#: Margin of the local layer's clearance over the footprint [m] (laser noise 0.01 m,
#: one 0.02 m step of lag).
CLEARANCE_MARGIN = 0.03
#: Margin of the forward safety corridor over the footprint [m] (0.18 m for the burger:
#: at 0.22 m/s, 0.3 s of travel) ...
SAFETY_MARGIN = 0.075
#: ... or this much travel at top speed, the longer [s].
SAFETY_TIME = 0.3
#: The burger's travel in one planning period at top speed (0.22 m/s, 5 Hz) [m].
BURGER_STEP = 0.22 / 5.0
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
    body=Body(mass=1.0, height=0.12, bottom=0.022, inertia=(0.0045, 0.0045, 0.0055),
              mass_height=0.06, wheel_width=0.018, wheel_torque=0.5, wheel_mass=0.03,
              wheel_inertia=(1e-5, 1e-5, 1.6e-5)),
    source='ROBOTIS e-Manual "Specifications" (0.22 m/s, 2.84 rad/s, 138 x 178 mm); '
    'turtlebot3_description/urdf/turtlebot3_burger.urdf (base_scan at (-0.032, 0, 0.172) '
    'in base_link, base_link 0.010 m up; wheels 0.033 m, 0.160 m apart); Nav2 '
    'robot_radius 0.105 m of the turtlebot3 package; LDS-01 0.12-3.5 m (an LDS-02 '
    'burger: 0.16-8 m, set obstacle_range); Jazzy turtlebot3_node takes TwistStamped')
#: TurtleBot3 Waffle Pi (and the discontinued Waffle: same base, limits and laser).
WAFFLE_PI = RobotDescription(
    name='turtlebot3_waffle_pi', radius=0.25, laser=LaserMount(-0.064, 0.0, 0.131, 0.0),
    wheel_radius=0.033, wheel_separation=0.288, max_linear_velocity=0.26,
    max_angular_velocity=1.82, base_link_height=0.010, laser_frame='base_scan',
    laser_range=3.5, stamped_cmd_vel=True,
    footprint=((0.084, -0.153), (0.084, 0.153), (-0.197, 0.153), (-0.197, -0.153)),
    body=Body(mass=1.8, height=0.12, bottom=0.022, wheel_width=0.018, wheel_torque=0.9),
    source='ROBOTIS e-Manual "Specifications" (0.26 m/s, 1.82 rad/s, 281 x 306 mm, '
    '1.8 kg); turtlebot3_description/urdf/turtlebot3_waffle_pi.urdf.xacro (base_scan at '
    '(-0.064, 0, 0.121) in base_link, base_link 0.010 m up; wheels 0.033 m, 0.288 m '
    'apart; body box 0.266 m square centred 0.064 m behind the axle, its rear 0.197 m '
    'behind it): the footprint 281 mm long from that rear, 306 mm wide (the wheels), its '
    'rear corners 0.249 m from base_footprint, hence the 0.25 m radius; LDS-01 '
    '0.12-3.5 m; the motor torque estimated')
#: TurtleBot 4 (standard and lite: an iRobot Create 3 base with an RPLIDAR A1M8).
TURTLEBOT4 = RobotDescription(
    name='turtlebot4', radius=0.175, laser=LaserMount(-0.04, 0.0, 0.193, math.pi / 2),
    wheel_radius=0.03575, wheel_separation=0.233, max_linear_velocity=0.26,
    max_angular_velocity=1.0, base_link_height=0.0, base_frame='base_link',
    laser_frame='rplidar_link', laser_range=12.0, stamped_cmd_vel=True, lidar='rplidar_a1',
    range_noise=(0.0025, 0.005),
    body=Body(mass=3.3, height=0.1, bottom=0.02, wheel_width=0.02, wheel_torque=1.5),
    source='turtlebot4_navigation/config/nav2.yaml for Jazzy (robot_radius 0.175 m; '
    'velocity_smoother max_velocity 0.26 m/s, 1.0 rad/s; enable_stamped_cmd_vel true); '
    'turtlebot4_description/urdf/standard/turtlebot4.urdf.xacro (rplidar_link 0.04 m '
    'behind base_link, turned by +pi/2, about 0.193 m up); irobot_create_description '
    '(body radius 0.164 m, wheels 0.03575 m, 0.233 m apart; base_link on the ground: '
    'it is the base frame; 3.3 kg); RPLIDAR A1M8 0.15-12 m, accuracy 1 % of the range up '
    'to 3 m (Slamtec datasheet; the range noise: half of it, and at 0.5 m near the '
    'laser); the motor torque estimated')
#: Clearpath Jackal as the BARN Challenge runs it: a SICK LMS111 on its front mount,
#: planning at 20 Hz. Its four wheels (skid steering) are two in the simulator, at the
#: track, with casters: the same kinematics as its diff-drive controller's.
JACKAL = RobotDescription(
    name='jackal', radius=0.333, laser=LaserMount(0.12, 0.0, 0.40, 0.0),
    wheel_radius=0.098, wheel_separation=0.376, max_linear_velocity=2.0,
    max_angular_velocity=4.0, base_link_height=0.0, base_frame='base_link',
    laser_frame='front_laser', laser_range=20.0, stamped_cmd_vel=False,
    max_linear_acceleration=3.4, max_angular_acceleration=13.0,
    footprint=((0.254, -0.215), (0.254, 0.215), (-0.254, 0.215), (-0.254, -0.215)),
    lidar='lms111', laser_fov=math.radians(270.0), planning_frequency=20.0,
    range_noise=(0.012, 0.0),
    body=Body(mass=17.0, height=0.185, bottom=0.065, wheel_width=0.04, wheel_torque=17.0),
    source='Clearpath Jackal specifications (outer dimensions 508 x 430 x 250 mm, the '
    'footprint here, bumpers and wheels included: its farthest corner 0.333 m out; 17 kg; '
    '2.0 m/s); jackal_control/config/control.yaml (2.0 m/s, 4.0 rad/s, 20 m/s^2, '
    '25 rad/s^2); jackal_description jackal.urdf.xacro (wheel radius 0.098 m, track '
    '0.376 m, wheel width 0.040 m; the front mount 0.12 m ahead of base_link) and '
    'sick_lms1xx_mount.urdf.xacro (the focal point 0.149 m above the bracket: about '
    '0.40 m up); SICK LMS111-10100 datasheet (statistical error 12 mm, the range '
    'noise; its systematic +/-30 mm a fixed offset per unit); the BARN Challenge (a SICK '
    'LMS1xx, 270 degrees; ROS Noetic: Twist on cmd_vel; the challenge costmap footprint '
    '0.42 x 0.33 m is narrower than the wheels); '
    "the 20 Hz planning rate is this package's choice for a 2 m/s robot; the body's "
    'bottom (0.065 m) and motor torque (17 N m: 20 m/s^2 for 17 kg on 0.098 m wheels) '
    "are estimates; the accelerations are what the wheels' grip gives, not the "
    "controller's 20 m/s^2 and 25 rad/s^2: the simulated base (friction 1.0) brakes "
    'from 1 m/s and 4 rad/s to a stop in 0.3 s, 3.4 m/s^2 and 13 rad/s^2 '
    '(test_robot.py::test_the_planner_asks_no_more_acceleration_than_the_base_gives)')
#: The robots config/robots/ has a parameter file for, by file name.
ROBOTS = {'burger': BURGER, 'waffle_pi': WAFFLE_PI, 'turtlebot4': TURTLEBOT4, 'jackal': JACKAL}


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
