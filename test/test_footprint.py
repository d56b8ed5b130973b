"""Polygon footprints (core/footprint.py): Nav2's footprint parameter, contact with the
polygon placed at a pose, turning on the spot, and a rectangle through a door its
circumscribed disc cannot pass."""

import math

import numpy as np
import pytest

from subapf_planner.core.command import forward_blocked, shape_command, turn_blocked
from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.footprint import Footprint, format_footprint, parse_footprint
from subapf_planner.core.params import ConfigError
from subapf_planner.core.robot import JACKAL, ROBOTS
from subapf_planner.core.sampling import safe_samples
from subapf_planner.core.status import Status

pytestmark = pytest.mark.core

BOX = '[[0.3, -0.2], [0.3, 0.2], [-0.3, 0.2], [-0.3, -0.2]]'


def test_the_footprint_parameter_reads_as_nav2_writes_it():
    shape = parse_footprint(BOX)
    assert shape.vertices.tolist() == [[0.3, -0.2], [0.3, 0.2], [-0.3, 0.2], [-0.3, -0.2]]
    assert (shape.half_width, shape.front, shape.inscribed) == (0.2, 0.3, 0.2)
    assert shape.circumscribed == pytest.approx(math.hypot(0.3, 0.2))
    clockwise = parse_footprint('[[0.3, 0.2], [0.3, -0.2], [-0.3, -0.2], [-0.3, 0.2]]')
    assert sorted(clockwise.vertices.tolist()) == sorted(shape.vertices.tolist())
    x, y = clockwise.vertices.T
    assert np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)) > 0.0   # counter-clockwise
    assert parse_footprint('') is None and parse_footprint('[]') is None
    assert parse_footprint(format_footprint(shape.vertices)).vertices.tolist() == \
        shape.vertices.tolist()
    for bad, why in (('[[0.3, 0.2]]', 'three or more'), ('[[0, 1], [2]]', 'not a list'),
                     ('oval', 'not a list'),
                     ('[[0.3, -0.2], [0.0, 0.0], [0.3, 0.2], [-0.3, 0.2], [-0.3, -0.2]]',
                      'convex'),
                     ('[[1, 1], [2, 1], [2, 2], [1, 2]]', 'origin must lie inside')):
        with pytest.raises(ConfigError, match=why):
            parse_footprint(bad)


def test_robot_radius_must_hold_the_footprint():
    cfg = PlannerConfig(footprint=BOX, robot_radius=0.37)
    assert cfg.polygon.front == 0.3
    with pytest.raises(ConfigError, match='robot_radius: 0.3 m does not hold the footprint'):
        PlannerConfig(footprint=BOX, robot_radius=0.3)
    with pytest.raises(ConfigError, match='footprint'):
        PlannerConfig(footprint='[[1, 2]]', robot_radius=0.37)


def test_contact_is_with_the_polygon_where_it_stands_and_how_it_faces():
    shape = parse_footprint(BOX)
    point = np.array([[0.0, 0.25]])   # 5 cm beside the long side
    assert not shape.contact([0.0, 0.0, 0.0], point, 0.03)[0]
    assert shape.contact([0.0, 0.0, 0.0], point, 0.06)[0]
    # turned a quarter: the long side's end now reaches it
    assert shape.contact([0.0, 0.0, math.pi / 2], point, 0.0)[0]
    poses = np.array([[0.0, 0.0, 0.0], [0.0, 0.1, 0.0], [5.0, 5.0, 1.0]])
    assert shape.contact(poses, point, 0.03).tolist() == [False, True, False]
    assert shape.contact(poses, np.zeros((0, 2)), 0.03).tolist() == [False] * 3


def test_a_rectangle_that_cannot_turn_on_the_spot_backs_up_to_make_room():
    """Nose 2 cm from a wall: a turn on the spot would sweep a front corner into it either
    way; the command backs straight up (``backing_up``) while the way behind is clear,
    and stops when it is not. A disc turns freely where it stands."""
    wall = np.column_stack((np.full(41, 0.32), np.linspace(-1.0, 1.0, 41)))
    cfg = PlannerConfig(footprint=BOX, robot_radius=0.37)
    pose = np.zeros(3)
    assert turn_blocked(pose, 1.0, wall, cfg) and turn_blocked(pose, -1.0, wall, cfg)
    assert not turn_blocked(pose, 1.0, np.array([[2.0, 0.0]]), cfg)
    cmd = shape_command(pose, [0.0, 1.0], [0.0, 3.0], (0.0, 0.0), wall, cfg)
    assert cmd.status is Status.BACKING_UP and cmd.v < 0.0 and cmd.w == 0.0
    behind = np.vstack((wall, [[-0.4, 0.0]]))
    assert shape_command(pose, [0.0, 1.0], [0.0, 3.0], (0.0, 0.0), behind, cfg).status \
        is Status.NO_SAFE_MOVE
    assert shape_command(pose, [0.0, 1.0], [0.0, 3.0], (0.0, 0.0), wall,
                         cfg.replace(reverse_speed=0.0)).status is Status.NO_SAFE_MOVE
    disc = shape_command(pose, [0.0, 1.0], [0.0, 3.0], (0.0, 0.0), wall, PlannerConfig())
    assert disc.status is Status.TURNING and disc.w > 0.0
    assert not turn_blocked(pose, 1.0, wall, PlannerConfig())


def test_a_corridor_the_rectangle_fits_is_open_to_it_and_closed_to_its_disc():
    """Walls 0.25 m either side: the Jackal (0.43 m wide) may drive along them; as the
    0.333 m disc that holds it every sample is unsafe, and the corridor ahead is free of
    the walls only for the polygon."""
    cfg = PlannerConfig.for_robot(JACKAL)
    disc = cfg.replace(footprint='', inflation_radius=cfg.robot_radius)
    xs = np.linspace(-1.0, 3.0, 81)
    walls = np.vstack([np.column_stack((xs, np.full(xs.size, y))) for y in (-0.25, 0.25)])
    samples = np.array([[0.2, 0.0], [0.2, 0.05], [0.0, 0.2]])
    clear = np.min(np.hypot(*(samples[:, None] - walls[None]).transpose(2, 0, 1)), axis=1)
    assert safe_samples(samples, clear, np.zeros(2), walls, cfg).tolist() == [True, False,
                                                                              False]
    assert not safe_samples(samples, clear, np.zeros(2), walls, disc).any()
    assert not forward_blocked(np.zeros(3), walls, cfg)
    assert forward_blocked(np.zeros(3), walls, disc)
    ahead = np.array([[0.254 + 0.5, 0.1]])   # within the Jackal's safety reach ahead
    assert forward_blocked(np.zeros(3), ahead, cfg)


@pytest.mark.sim
def test_a_sample_the_forward_check_would_stop_at_is_not_taken():
    """A gap 0.52 m wide for the Jackal (0.43 m), its right side 0.6 m ahead and 0.2 m
    to the right, its left beside the robot 0.33 m to the left: the sample straight
    ahead keeps the polygon clear where it stands, but the way there runs into the
    gap's right side within the command's forward check; a sample a little to the left
    leads in. (Taken straight ahead, the robot stood with blocked_ahead: `barn_001`.)"""
    cfg = PlannerConfig.for_robot(JACKAL)
    left = np.column_stack((np.linspace(-0.3, 0.3, 13), np.full(13, 0.33)))
    right = np.column_stack((np.linspace(0.57, 0.9, 8), np.full(8, -0.2)))
    points = np.vstack((left, right))
    samples = np.array([[0.22, 0.0], [0.22, 0.05]])
    clear = np.min(np.hypot(*(samples[:, None] - points[None]).transpose(2, 0, 1)), axis=1)
    assert not cfg.polygon.contact(np.column_stack((samples, np.arctan2(*samples.T[::-1]))),
                                   points, cfg.sample_clearance - cfg.robot_radius).any()
    assert forward_blocked(np.zeros(3), points, cfg)
    assert safe_samples(samples, clear, np.zeros(2), points, cfg).tolist() == [False, True]


@pytest.mark.parametrize('key, door', [('jackal', 0.6), ('waffle_pi', 0.42)])
def test_a_rectangle_passes_a_door_its_circumscribed_disc_cannot(key, door):
    """The simulated robot (its real rectangle) and a door narrower than the circle that
    holds it: planned with its footprint it drives through without contact; planned as
    that circle the door is closed, and the goal beyond it unreachable."""
    from subapf_planner.sim.episode import run_episode
    from subapf_planner.sim.simulator import SimConfig
    from subapf_planner.sim.world import parse_world
    from subapf_planner.tools.bench import bench_config
    robot = ROBOTS[key]
    assert 2 * robot.radius > door > 2 * parse_footprint(format_footprint(
        robot.footprint)).half_width + 0.1
    half = door / 2
    world = parse_world({
        'name': 'door', 'start': [0.0, 0.0, 0.0], 'goal': [4.0, 0.0], 'time_limit': 90,
        'bounds': [-1.5, -2.5, 5.5, 2.5], 'obstacles': [
            {'box': {'center': [2.0, side * (2.5 + half) / 2], 'size': [0.1, 2.5 - half]}}
            for side in (1, -1)]})
    _, cfg = bench_config(None, key)
    assert cfg.polygon is not None
    sim = SimConfig(robot=key, scan_threads=1)
    through = run_episode(world, cfg, sim).metrics(world)
    assert through['outcome'] == 'reached', through
    assert 0.0 < through['min_clearance'] < (door - 2 * cfg.polygon.half_width) / 2
    disc = run_episode(world, cfg.replace(footprint='', inflation_radius=cfg.robot_radius),
                       sim).metrics(world)
    assert disc['outcome'] == 'unreachable', disc
    assert disc['min_clearance'] > 0.0


def test_every_shipped_polygon_is_one_the_planner_takes():
    for robot in ROBOTS.values():
        cfg = PlannerConfig.for_robot(robot)
        assert (cfg.polygon is None) == (not robot.footprint)
        if robot.footprint:
            assert isinstance(cfg.polygon, Footprint)
            assert cfg.inflation_radius == cfg.polygon.half_width < robot.radius
