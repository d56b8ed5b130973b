"""Validated, frozen planner configuration (SI units, radians).

Every field carries its description, unit and admissible range in its metadata.
The ROS node builds its ParameterDescriptors from the same metadata, and
``config/planner.yaml`` documents the same names, so the three cannot drift
apart (``test/test_config.py`` checks the YAML against this module).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import functools
import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import yaml

from .critics import critic_class
from .footprint import Footprint, format_footprint, parse_footprint
from .params import ConfigError, build, check_fields, param
from .robot import BURGER, RobotDescription

#: Repulsive potentials of the paper, plus the Dynamic Window baseline.
APF_METHODS = ('subharmonic_sampling', 'subharmonic', 'traditional', 'harmonic')
METHODS = APF_METHODS + ('dwa',)


@dataclass(frozen=True)
class PlannerConfig:
    """All parameters of the planner core; see docs/parameters.md."""

    # --- method and potentials (paper Sections II-III) ---------------------------------
    method: str = param('subharmonic_sampling', "Planner: the paper's full method, "
                         'its ablations, or the DWA baseline', choices=METHODS)
    attraction: str = param('conic', 'Attractive potential: quadratic a_att*r^2 (eq. 21) or '
                             'conic a_att*r (constant-magnitude pull, what Section II-C '
                             'asks of the goal field)', choices=('conic', 'quadratic'))
    attraction_gain: float = param(1.0, 'a_att of eq. (21)', '1/m (quadratic) or - (conic)',
                                    0.0, 100.0)
    repulsion_gain: float = param(0.5, 'a of eq. (13); scale of the 1/r and -log10 r '
                                   'repulsions too', 'm (1/r), - (others)', 0.0, 100.0)
    danger_distance: float = param(0.25, 'd0 of eq. (20); sets k = 1/d0^2 of eq. (13); '
                                    'samples closer than d0 to an obstacle are discarded',
                                    'm', 0.05, 2.0)
    repulsion_mode: str = param('nearest', 'Repel from the nearest point only (eq. 7) or sum '
                                 'over all (voxel-downsampled) points (eq. 9-10)',
                                 choices=('nearest', 'sum'))
    influence_distance: float = param(1.0, 'Obstacle points farther than this exert no '
                                       'repulsion', 'm', 0.1, 10.0)
    # --- APF step (eq. 23) -------------------------------------------------------------
    step_gain: float = param(0.05, 'eta: raw next move point = p + eta * F', 'm', 1e-4, 1.0)
    max_step: float = param(0.1, 'Longest raw step; also never past the goal', 'm',
                             0.005, 1.0)
    # --- circular sampling (Section IV, Algorithm 1, Fig. 5) ---------------------------
    num_samples: int = param(16, 'N points on the sampling circle', '', 3, 360)
    sample_radius: float = param(0.05, 'R, radius of the sampling circle', 'm', 0.001, 1.0)
    priority_distance: float = param(1.0, 'd threshold of Fig. 5: priority only when the '
                                      'nearest obstacle is closer than this', 'm', 0.0, 5.0)
    priority_angle: float = param(0.8, 'theta threshold of Fig. 5: priority only when goal '
                                   'and nearest obstacle bearings differ by less', 'rad',
                                   0.0, math.pi)
    priority_bonus: float = param(0.25, 'priority critic: subtracted from the score of the '
                                   'priority sample', 'm', 0.0, 10.0)
    critics: tuple[str, ...] = param(('progress', 'priority'), 'Scoring terms of the '
                                     'circular sampling, summed in this order '
                                     '(core/critics/): progress (Algorithm 1: distance to '
                                     'go after the next APF step), priority (Fig. 5); a '
                                     'critic of your own as module:Class')
    # --- scan conversion ---------------------------------------------------------------
    voxel_size: float = param(0.05, 'Grid cell for downsampling laser points (one point per '
                               "cell), so a wall's push does not grow with beam density",
                               'm', 0.0, 1.0)
    obstacle_range: float = param(3.5, 'Laser returns beyond this are ignored', 'm',
                                   0.1, 100.0)
    laser_x: float = param(BURGER.laser.x, 'Laser position in base_footprint (x)', 'm',
                           -2.0, 2.0)
    laser_y: float = param(BURGER.laser.y, 'Laser position in base_footprint (y)', 'm',
                           -2.0, 2.0)
    laser_yaw: float = param(BURGER.laser.yaw, 'Laser yaw in base_footprint', 'rad',
                             -math.pi, math.pi)
    # --- command shaping (differential drive, TurtleBot3 burger limits) ---------------
    planning_frequency: float = param(5.0, 'Planning rate (paper: 5 Hz)', 'Hz', 0.5, 100.0)
    max_linear_velocity: float = param(BURGER.max_linear_velocity, 'Top speed', 'm/s',
                                       0.0, 5.0)
    max_angular_velocity: float = param(BURGER.max_angular_velocity, 'Top turn rate',
                                        'rad/s', 0.0, 10.0)
    max_linear_acceleration: float = param(1.0, 'Linear acceleration limit', 'm/s^2',
                                            0.01, 20.0)
    max_angular_acceleration: float = param(3.2, 'Angular acceleration limit', 'rad/s^2',
                                             0.01, 50.0)
    heading_gain: float = param(2.5, 'w = heading_gain * heading error', '1/s', 0.0, 50.0)
    rotate_in_place_angle: float = param(0.9, 'Turn on the spot when the heading error '
                                          'exceeds this', 'rad', 0.0, math.pi)
    goal_tolerance: float = param(0.15, 'xy goal tolerance; stop inside it', 'm', 0.01, 5.0)
    arrival_distance: float = param(0.01, 'With the geodesic field: once inside '
                                    'goal_tolerance, drive on towards the goal until this '
                                    'close, or until it has come no closer for a second '
                                    '(core/gates.py ARRIVAL_PATIENCE; so that '
                                    'a pose error of a few centimetres, drift the scan '
                                    'alignment has not yet corrected, still leaves the '
                                    'robot inside the tolerance; final_approach heads '
                                    'for the goal there); goal_tolerance or more: '
                                    'stop on entering it', 'm', 0.0, 5.0)
    final_approach: bool = param(True, 'With the geodesic field: inside goal_tolerance, '
                                 'head for the goal itself instead of the sampled step '
                                 '(core/approach.py), so that the robot stops where it '
                                 'thinks the goal is, not centimetres short of it')
    slowdown_distance: float = param(0.4, 'Speed scales down linearly inside this distance '
                                      'of the goal', 'm', 0.0, 10.0)
    approach_speed: float = param(0.055, 'Least speed the slow-down near the goal comes to '
                                  "(a quarter of the burger's top speed: a fast robot's "
                                  'quarter would pass the goal tolerance in a period)',
                                  'm/s', 0.0, 5.0)
    robot_radius: float = param(BURGER.radius, 'Robot radius: half-width of the forward safety '
                                 'corridor; the field inflates obstacles by it (with a '
                                 'footprint: the circle that holds it)', 'm', 0.0, 2.0)
    footprint: str = param('', "The robot's footprint as a convex polygon in base_footprint, "
                           "Nav2's format '[[x, y], ...]' (clockwise is reversed): samples, "
                           'the corridor ahead and turns on the spot are checked against it '
                           "(core/footprint.py); '': a disc of robot_radius")
    safety_distance: float = param(BURGER.safety_distance, 'Forward speed is zeroed while an '
                                    'obstacle point lies in the corridor ahead closer than this '
                                    'to the centre '
                                    '(0.075 m ahead of the footprint; stopping from 0.22 m/s '
                                    'takes 0.024 m)', 'm', 0.0, 2.0)
    contact_time: float = param(0.3, 'With the geodesic field: the last command is rolled '
                                "out this long (a planning period, the scan's latency and "
                                "braking) against the scan's returns, and its forward speed "
                                'zeroed where the footprint would come within contact_margin '
                                'of a return it closes on (core/contact_check.py); 0: off',
                                's', 0.0, 5.0)
    contact_margin: float = param(0.02, "Gap the command's rollout keeps from the returns it "
                                  "closes on (less than the sampling's margin over the "
                                  'footprint, so that a planned move is not refused)', 'm',
                                  0.0, 0.5)
    # --- memory and navigation-function attraction (core/occupancy.py, navigation.py) --
    attraction_field: str = param('geodesic', 'Attraction: geodesic (distance to the goal '
                                  'through the occupancy memory, a navigation function with '
                                  'no local minimum but the goal; the default) or euclidean '
                                  "(the paper's eq. 21 exactly, samples discarded within "
                                  'danger_distance)', choices=('geodesic', 'euclidean'))
    sample_clearance: float = param(BURGER.clearance, 'With the geodesic field: samples '
                                    'closer than this to a laser point are discarded '
                                    '(robot_radius + 0.03 m; the paper uses danger_distance, '
                                    'which closes every gap narrower than 2 d0)', 'm',
                                    0.0, 2.0)
    field_gain: float = param(8.0, 'a_att of the geodesic attraction: a pull of this constant '
                              'magnitude along the field (stronger than the Euclidean one, '
                              "so eq. (13)'s repulsion bends the path but cannot turn it back "
                              'in a passage narrower than 2 d0)', '', 0.0, 100.0)
    map_size: float = param(20.0, 'Side of the square occupancy window that follows the '
                            'robot (memory bound: (map_size/map_resolution)^2 * 4 bytes, 18 '
                            'with scan_alignment)',
                            'm', 2.0, 200.0)
    map_resolution: float = param(0.05, 'Occupancy cell size', 'm', 0.01, 0.5)
    field_coarsening: int = param(2, 'The navigation field is marched on blocks of this '
                                  'many map cells a side (2: 0.1 m blocks, about five times '
                                  'faster than cells); reachability and inflation stay on '
                                  'the map cells', '', 1, 8)
    inflation_radius: float = param(BURGER.radius, 'Field: cells closer than this to an '
                                    'occupied cell are in contact (travel there is 50 times '
                                    'slower; a goal there is unreachable, and so is one that '
                                    'only gaps narrower than twice this lead to)', 'm',
                                    0.0, 2.0)
    gap_clearance: float = param(0.0, 'Field: travel closer than this to a wall in the '
                                 'memory is as slow as contact, so a gap narrower than '
                                 'twice this is taken only when no other way is open '
                                 '(sample_clearance plus half a cell, 0.16, makes the field '
                                 'agree with the sampling); 0, the default: only within '
                                 'inflation_radius (measured: through a noisy lidar the '
                                 "memory's walls are thicker than the walls and it closed "
                                 'real gaps; docs/memory.md)', 'm', 0.0, 2.0)
    goal_slack: float = param(0.075, 'Field: a goal within inflation_radius of a wall in the '
                              'memory is replaced by the nearest free cell this close to it '
                              "(Nav2's planner tolerance: walls drawn through a noisy lidar "
                              'are some centimetres thick), and it is inside an obstacle '
                              'only with a laser point within robot_radius - goal_slack; '
                              '0: such a goal is unreachable. Keep it under goal_tolerance',
                              'm', 0.0, 1.0)
    inflation_band: float = param(0.22, 'Field: beyond inflation_radius, travel speeds up '
                                  'linearly to full over this band, so the field keeps to the '
                                  'middle of passages', 'm', 0.0, 2.0)
    route_discount: float = param(0.0, 'Field: travel along the route the robot has taken '
                                  "to the goal (the last field's descent from where it was, "
                                  'route_width either side) costs this fraction less, so '
                                  'another way must be that much shorter to take over (no '
                                  'dithering between two near-equal ways; 0, the default: '
                                  'none; docs/memory.md)', '',
                                  0.0, 0.9)
    route_width: float = param(0.3, 'Field: half-width of the route route_discount favours',
                               'm', 0.0, 2.0)
    path_discount: float = param(0.5, 'Field: travel along a path given to follow (the '
                                 "follow_path action: a global planner's path, path_width "
                                 'either side) costs this fraction less, so the robot keeps '
                                 'to it and leaves it where the scan shows it blocked or a '
                                 'way off it is that much shorter (docs/nav2.md)', '',
                                 0.0, 0.9)
    path_width: float = param(0.2, 'Field: half-width of the path path_discount favours',
                              'm', 0.0, 2.0)
    field_period: float = param(1.0, 'Shortest time between two field computations (sooner '
                                'for a new goal, or when the robot leaves the patch)', 's',
                                0.0, 60.0)
    field_worker: bool = param(True, "A field that only brings the map's changes in is "
                               'marched on a worker thread between cycles and used from the '
                               'next cycle: a tick never waits for it (the map reaches the '
                               'field a cycle late; docs/performance.md)')
    scan_alignment: bool = param(True, 'Match each scan to the memory before it is written '
                                 '(core/alignment.py): drifting wheel odometry is corrected, '
                                 'and the memory, the field and the goal live in the '
                                 'corrected frame (with the geodesic attraction; '
                                 'docs/alignment.md). Switching it starts an empty map')
    odometry_calibration: bool = param(True, "Learn odometry's distance and turn scales "
                                       'from scan-to-scan registration and predict the '
                                       "scan alignment's pose with them "
                                       '(core/odometry_calibration.py; with scan_alignment)')
    range_noise_floor: float = param(0.0075, "The lidar's range noise (standard deviation) "
                                     'near it: each scan is averaged along its surfaces '
                                     'by it (core/scan.py denoise), the scan alignment '
                                     'weighs each return by it, the tracker looks that '
                                     'far along a ray for what has stood (LDS-01: '
                                     '+/-15 mm below 0.5 m, taken as 2 sigma; 0 and 0: '
                                     'no averaging)', 'm', 0.0, 1.0)
    range_noise_fraction: float = param(0.025, '... and as a fraction of the range farther '
                                        'out (LDS-01: +/-5 % from 0.5 to 3.5 m, 2 sigma)',
                                        '', 0.0, 1.0)
    deskew_bearings: bool = param(False, "The obstacles' and the tracker's de-skewed scans "
                                  "keep each return's exact direction (core/scan.py deskew) "
                                  "instead of moving it to the nearest beam of the scan's "
                                  'grid, up to half a beam off (the tracker sees more ghosts '
                                  'in clutter); the memory and the scan alignment always '
                                  'keep them (docs/alignment.md)')
    # --- moving obstacles (core/tracking.py, core/evasion.py) ------------------------
    track_moving: bool = param(True, 'Track moving obstacles from the scans (clusters, '
                               'constant-velocity Kalman filters): their points stay out of '
                               'the memory, and the command is checked against where they '
                               "will be (with the geodesic attraction; the paper's method "
                               'and DWA do without)')
    cluster_gap: float = param(0.15, 'Laser points closer than this belong to one cluster',
                               'm', 0.01, 1.0)
    max_mover_size: float = param(1.2, 'Clusters longer than this are walls, never tracked',
                                  'm', 0.1, 10.0)
    track_gate: float = param(0.6, "A cluster farther than this from a track's prediction "
                              'is not that track', 'm', 0.05, 5.0)
    moving_speed: float = param(0.04, 'A track at least this fast moves', 'm/s', 0.0, 5.0)
    prediction_horizon: float = param(3.0, 'How far ahead moving tracks are predicted and '
                                      'the command rolled out against them (at 2 s, an escape '
                                      'that ran ahead of a walker into clutter or another '
                                      "walker's lane was seen too late)", 's', 0.2, 10.0)
    moving_clearance: float = param(0.1, 'Gap kept between the footprint and a moving '
                                    "track's predicted disc", 'm', 0.0, 2.0)
    reverse_speed: float = param(BURGER.max_linear_velocity, 'Speed at which the robot may '
                                 'back away from something coming at it (0: never '
                                 'reverses; the robot backs at up to its top speed: '
                                 'slower, a walker at that speed catches it)', 'm/s', 0.0,
                                 5.0)
    escape_ramps: bool = param(False, 'Escapes are rolled out changing speed and turn rate '
                               'from the last command at max_linear_acceleration and '
                               'max_angular_acceleration (where those are what the base '
                               'can do, as a robot description states them: a 2 m/s robot '
                               'brakes over 0.6 m); off: at the commanded rates at once '
                               '(limits that tune a controller; the escape is sent '
                               'unlimited)')
    escape_turn_weight: float = param(0.1, 'Among the escapes that keep moving_clearance, '
                                      'the one closest to the planned command wins: '
                                      '|v - v_plan| + this * |w - w_plan| (a difference of '
                                      'turn rate counts this much against one of speed, so '
                                      'the robot steps aside rather than turns back)',
                                      'm/rad', 0.0, 10.0)
    # --- DWA baseline (Fox, Burgard, Thrun 1997) ---------------------------------------
    dwa_clearance: float = param(BURGER.clearance, 'DWA: arcs passing closer than this to an '
                                 'obstacle point are inadmissible (robot_radius + 0.03 m)',
                                 'm', 0.0, 2.0)
    dwa_horizon: float = param(2.0, 'DWA rollout horizon', 's', 0.2, 10.0)
    dwa_rollout_step: float = param(0.1, 'DWA: arcs are checked every this long (at top '
                                    'speed a step should stay below dwa_clearance)', 's',
                                    0.01, 1.0)
    dwa_v_samples: int = param(7, 'DWA linear velocity samples', '', 2, 50)
    dwa_w_samples: int = param(15, 'DWA angular velocity samples', '', 3, 101)
    dwa_heading_weight: float = param(0.2, 'DWA weight of the goal term (weights tuned once '
                                      'on the dev suite, docs/design.md)', '', 0.0, 100.0)
    dwa_clearance_weight: float = param(0.6, 'DWA weight of the clearance term', '',
                                         0.0, 100.0)
    dwa_velocity_weight: float = param(0.4, 'DWA weight of the forward-speed term', '',
                                        0.0, 100.0)

    def __post_init__(self) -> None:
        check_fields(self)
        for name in self.critics:
            critic_class(name)   # ConfigError for a name that is no critic
        shape = self.polygon   # ConfigError for a footprint that is no convex polygon
        if shape is not None and shape.circumscribed > self.robot_radius + 1e-6:
            raise ConfigError(f'robot_radius: {self.robot_radius} m does not hold the '
                              f'footprint (its farthest vertex is {shape.circumscribed:.3f} m '
                              'out)')
        if self.sample_radius >= self.danger_distance * 4:
            raise ConfigError('sample_radius: must be below 4 * danger_distance '
                              f'({self.sample_radius} >= {4 * self.danger_distance})')

    @functools.cached_property
    def polygon(self) -> Footprint | None:
        """The footprint's polygon; None: a disc of robot_radius."""
        return parse_footprint(self.footprint)

    @property
    def k(self) -> float:
        """k of eq. (13), from the danger distance by eq. (20): k = 1 / d0^2 [1/m^2]."""
        return 1.0 / self.danger_distance ** 2

    @property
    def geodesic(self) -> bool:
        """The navigation-function attraction is on (for DWA: its goal term, as the global
        dynamic window of Brock and Khatib 1999)."""
        return self.attraction_field == 'geodesic'

    @property
    def discard_distance(self) -> float:
        """Samples closer than this to a laser point are discarded (Algorithm 1) [m]."""
        return self.sample_clearance if self.geodesic else self.danger_distance

    @property
    def tracks_moving(self) -> bool:
        """Moving obstacles are tracked: with the memory (geodesic attraction) only."""
        return self.track_moving and self.geodesic

    @property
    def laser_mount(self) -> tuple[float, float, float]:
        """(x, y, yaw) of the laser in base_footprint [m, m, rad]."""
        return (self.laser_x, self.laser_y, self.laser_yaw)

    @property
    def period(self) -> float:
        """Planning period [s]."""
        return 1.0 / self.planning_frequency

    @classmethod
    def for_robot(cls, robot: RobotDescription, **changes: Any) -> 'PlannerConfig':
        """The defaults for ``robot``: its footprint, laser mounting and limits, and the
        clearances derived from its footprint (inflation, samples, DWA); ``changes`` on
        top (validated)."""
        return from_mapping({**robot_fields(robot), **changes})

    def replace(self, **changes: Any) -> 'PlannerConfig':
        """Copy with some fields changed (validated)."""
        return from_mapping({**dataclasses.asdict(self), **changes})


def robot_fields(robot: RobotDescription) -> dict[str, float]:
    """The PlannerConfig fields that come from ``robot``: its footprint and the clearances
    derived from it (inflation, samples, DWA, the safety corridor), its laser's mounting
    and range (at most half the default occupancy window: a return beyond it has no
    cell) and range noise, its limits and planning rate, and the lengths the planner
    steps by, scaled by how far the robot goes in one period (RobotDescription.pace:
    the sampling circle, the longest raw step, the slow-down before the goal; 1 for
    the burger, whose figures they are), and its acceleration limits where the robot
    states them (the escapes then rolled out under them); a robot whose laser does not
    see behind it never reverses (reverse_speed 0)."""
    mount = robot.laser
    pace = robot.pace
    # a polygon: the field keeps the half-width from walls (a gap the robot drives
    # straight through), the sampling and the command check the polygon itself
    inflation = Footprint(np.asarray(robot.footprint, float)).half_width \
        if robot.footprint else robot.radius
    accelerations = {
        name: value for name, value in (
            ('max_linear_acceleration', robot.max_linear_acceleration),
            ('max_angular_acceleration', robot.max_angular_acceleration)) if value is not None}
    return {
        'robot_radius': robot.radius, 'inflation_radius': inflation,
        'footprint': format_footprint(robot.footprint) if robot.footprint else '',
        'sample_clearance': robot.clearance, 'dwa_clearance': robot.clearance,
        'safety_distance': robot.safety_distance,
        'laser_x': mount.x, 'laser_y': mount.y, 'laser_yaw': round(mount.yaw, 6),
        'obstacle_range': min(robot.laser_range, PlannerConfig.map_size / 2),
        'max_linear_velocity': robot.max_linear_velocity,
        'reverse_speed': robot.max_linear_velocity if robot.sees_all_round else 0.0,
        'max_angular_velocity': robot.max_angular_velocity,
        'planning_frequency': robot.planning_frequency,
        'range_noise_floor': robot.range_noise[0], 'range_noise_fraction': robot.range_noise[1],
        'sample_radius': round(PlannerConfig.sample_radius * pace, 4),
        'max_step': round(PlannerConfig.max_step * pace, 4),
        'slowdown_distance': round(PlannerConfig.slowdown_distance * pace, 4),
        'escape_ramps': len(accelerations) == 2, **accelerations}


#: The PlannerConfig limits bounded by what the robot can do: field -> the
#: RobotDescription attribute that bounds it (robot_limits).
ROBOT_LIMITS = {
    'max_linear_velocity': 'max_linear_velocity',
    'reverse_speed': 'max_linear_velocity',
    'max_angular_velocity': 'max_angular_velocity',
    'max_linear_acceleration': 'max_linear_acceleration',
    'max_angular_acceleration': 'max_angular_acceleration',
}


def beyond_robot(cfg: PlannerConfig, robot: RobotDescription
                 ) -> list[tuple[str, float, float]]:
    """(field, its value, the robot's limit) of each limit of ``cfg`` above what ``robot``
    can do (ROBOT_LIMITS; a limit the description does not state is not checked)."""
    out = []
    for name, attr in ROBOT_LIMITS.items():
        limit = getattr(robot, attr)
        value = getattr(cfg, name)
        if limit is not None and value > limit + 1e-9:
            out.append((name, value, limit))
    return out


def beyond_robot_text(name: str, value: float, limit: float, robot: RobotDescription) -> str:
    """One line naming a limit, its value and the robot's."""
    unit = _unit(name)
    return (f'{name}: {value:g} {unit} is beyond what the {robot.name} can do '
            f'({limit:g} {unit}, core/robot.py)')


def _unit(name: str) -> str:
    return PlannerConfig.__dataclass_fields__[name].metadata['unit']


def clamp_to_robot(cfg: PlannerConfig, robot: RobotDescription
                   ) -> tuple[PlannerConfig, list[str]]:
    """``cfg`` with each limit beyond what ``robot`` can do set to the robot's, and one
    line per limit clamped naming both numbers."""
    beyond = beyond_robot(cfg, robot)
    if not beyond:
        return cfg, []
    notes = [f'{beyond_robot_text(name, value, limit, robot)}: clamped to {limit:g} '
             f'{_unit(name)}' for name, value, limit in beyond]
    return cfg.replace(**{name: limit for name, _, limit in beyond}), notes


def field_specs() -> list[dataclasses.Field]:
    """The dataclass fields, for building ROS parameter descriptors."""
    return list(dataclasses.fields(PlannerConfig))


def from_mapping(values: Mapping[str, Any], *, ignore_unknown: bool = False) -> PlannerConfig:
    """Build a config from a mapping; unknown keys are an error unless ignored."""
    return build(PlannerConfig, values, ignore_unknown=ignore_unknown)


def load_params_file(path: str | Path, node_name: str = 'subapf_planner') -> dict[str, Any]:
    """The ``ros__parameters`` of ``node_name`` in a ROS 2 params YAML file."""
    path = Path(path)
    try:
        doc = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise ConfigError(f'{path}: cannot read parameters: {exc}') from exc
    if not isinstance(doc, dict):
        raise ConfigError(f'{path}: expected a mapping at the top level')
    for key in (node_name, '/' + node_name, '/**'):
        section = doc.get(key)
        if isinstance(section, dict) and isinstance(section.get('ros__parameters'), dict):
            return dict(section['ros__parameters'])
    raise ConfigError(f'{path}: no "{node_name}: ros__parameters:" section')


def load_config(path: str | Path, node_name: str = 'subapf_planner',
                **overrides: Any) -> PlannerConfig:
    """PlannerConfig from a params file; node-only parameters in it are ignored."""
    values = load_params_file(path, node_name)
    values.update({k: v for k, v in overrides.items() if v is not None})
    try:
        return from_mapping(values, ignore_unknown=True)
    except ConfigError as exc:
        raise ConfigError(f'{path}: {exc}') from exc
