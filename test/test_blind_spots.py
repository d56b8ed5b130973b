"""Blind spots (core/blind_spots.py): what the lidar cannot see now (closer than its
range_min, outside its field of view), the memory remembers, and the planner avoids."""

import math

import numpy as np
import pytest

from subapf_planner.core.blind_spots import blind_obstacles, unseen
from subapf_planner.core.command import forward_blocked
from subapf_planner.core.footprint import parse_footprint
from subapf_planner.core.occupancy import OccupancyGrid
from subapf_planner.core.planner import Planner
from subapf_planner.core.scan import Scan
from subapf_planner.core.status import Status
from subapf_planner.tools.bench import bench_config

pytestmark = pytest.mark.core

#: A 270-degree lidar that sees nothing within 0.5 m (the Jackal's SICK LMS111).
LMS = dict(angle_min=-math.radians(135.0), angle_increment=math.radians(0.5),
           range_min=0.5, range_max=20.0)


def lms(ranges, stamp=0.0):
    return Scan(np.asarray(ranges, float), LMS['angle_min'], LMS['angle_increment'],
                LMS['range_min'], LMS['range_max'], stamp)


def test_unseen_is_what_is_too_close_or_outside_the_field_of_view():
    scan = lms(np.full(541, np.inf))
    laser = (1.0, 2.0, math.pi / 2)   # looking along +y
    points = np.array([[1.0, 2.3],    # ahead, 0.3 m: too close
                       [1.0, 3.0],    # ahead, 1 m: seen
                       [1.0, 1.0],    # behind, 1 m: outside 270 degrees
                       [2.0, 2.0],    # to the right, 1 m (-90 degrees): seen
                       [1.0 - 0.7, 2.0 - 0.72]])   # behind-left, -225 = 135 degrees: edge
    np.testing.assert_array_equal(unseen(points, laser, scan),
                                  [True, False, True, False, True])
    full = Scan(np.full(360, np.inf), 0.0, math.radians(1.0), 0.12, 3.5, 0.0)
    np.testing.assert_array_equal(unseen(points, laser, full),
                                  [False, False, False, False, False])


def test_blind_obstacles_are_remembered_walls_unseen_and_off_the_footprint():
    grid = OccupancyGrid(0.05, 10.0)
    for p in ([0.5, 0.0], [0.0, 0.1], [-0.8, 0.0], [2.0, 0.0], [0.3, 0.3]):
        grid.log_odds[tuple(grid.cell_of(p)[0])] = 3.0   # established
    scan = lms(np.full(541, np.inf))
    rect = parse_footprint('[[0.25, -0.2], [0.25, 0.2], [-0.25, 0.2], [-0.25, -0.2]]')
    got = blind_obstacles(grid, (0.0, 0.0, 0.0), (0.1, 0.0, 0.0), scan, 1.5, 0.33, rect)
    # 0.5 ahead (0.4 from the laser: too close), 0.8 behind (outside the view) and the
    # one 0.3/0.3 (0.36 from the laser) are kept; 2 m ahead is seen (and beyond reach);
    # (0, 0.1) lies under the footprint
    assert sorted(np.round(got, 3).tolist()) == sorted(
        np.round(grid.centre_of(grid.cell_of([[0.5, 0.0], [-0.8, 0.0], [0.3, 0.3]])),
                 3).tolist())


def test_a_beam_leaves_what_is_within_range_min_alone():
    grid = OccupancyGrid(0.05, 10.0)
    jamb = (0.35, 0.0)
    grid.log_odds[tuple(grid.cell_of(jamb)[0])] = 3.0
    for _ in range(10):   # nothing returns: the jamb is too close to echo
        grid.update(lms(np.full(541, np.inf)), (0.0, 0.0, 0.0), clear_range=5.0)
    assert grid.log_odds[tuple(grid.cell_of(jamb)[0])] == 3.0
    assert grid.log_odds[tuple(grid.cell_of((1.0, 0.0))[0])] < 0.0   # beyond: cleared


def test_the_planner_stops_for_a_jamb_its_lidar_no_longer_sees():
    """A post seen 1.5 m ahead, then, once the robot is 0.6 m from it, inside the
    lidar's blind zone: the scan has nothing, the forward check still stops the robot."""
    _, cfg = bench_config(None, 'jackal')
    cfg = cfg.replace(laser_x=0.12, laser_y=0.0, laser_yaw=0.0)
    planner = Planner(cfg)
    post = np.array([2.0, 0.0])
    goal = (4.0, 0.0)

    def scan_from(x, t):
        angles = LMS['angle_min'] + LMS['angle_increment'] * np.arange(541)
        laser = np.array([x + 0.12, 0.0])
        d = post - laser
        r = np.where(np.abs(np.remainder(angles - math.atan2(d[1], d[0]) + math.pi,
                                         2 * math.pi) - math.pi) < 0.02,
                     np.hypot(*d), np.inf)
        r[r < LMS['range_min']] = np.inf
        return lms(r, t)

    t = 0.0
    for k in range(50):   # standing at x = 0.5 (past the mapping stand): the post is seen
        t = 0.05 * k
        planner.step(np.array([0.5, 0.0, 0.0]), goal, scan_from(0.5, t), now=t)
    planner.perceive()
    near = scan_from(1.4, t + 0.05)
    assert not np.isfinite(near.ranges).any()   # 0.48 m from the laser: no echo
    res = planner.step(np.array([1.4, 0.0, 0.0]), goal, near, now=t + 0.05)
    assert forward_blocked(np.array([1.4, 0.0, 0.0]), res.obstacles, cfg)
    assert res.command.v == 0.0 and res.command.status is Status.BLOCKED_AHEAD
    # without the memory (the paper's method) the scan is all there is
    paper = cfg.replace(attraction_field='euclidean')
    assert not forward_blocked(np.array([1.4, 0.0, 0.0]),
                               Planner(paper).step(np.array([1.4, 0.0, 0.0]), goal, near,
                                                   now=0.0).obstacles, paper)
