"""A map the robot already has as the memory's prior (core/known_map.py): where its
cells land in the window, through a shift, under scans that disagree with it, and the
field it gives before any scan."""

import math

import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.known_map import PRIOR_FREE, PRIOR_WALL, KnownMap, KnownMapError
from subapf_planner.core.memory import NavigationMemory
from subapf_planner.core.occupancy import OccupancyGrid
from subapf_planner.core.scan import Scan

pytestmark = pytest.mark.core


def room(resolution=0.05):
    """A 6 x 4 m map (its frame's corner at (-1, -1)): a room walled at its bottom, top
    and left edges, free inside, unknown beyond x = 4 m, with a wall across it at
    x = 2 m and a 1 m door in that at y in [1.5, 2.5]."""
    h, w = int(4 / resolution), int(6 / resolution)
    cells = np.zeros((h, w), np.int8)
    cells[:, int(5 / resolution):] = -1
    xs = -1 + (np.arange(w) + 0.5) * resolution
    ys = -1 + (np.arange(h) + 0.5) * resolution
    wall_col = np.flatnonzero(np.abs(xs - 2.0) < resolution)
    door = (ys > 1.5) & (ys < 2.5)
    cells[np.ix_(~door, wall_col)] = 100
    cells[:2, :] = cells[-2:, :] = 100
    cells[:, :2] = 100
    return cells, (-1.0, -1.0), resolution


def test_the_map_is_read_in_the_memory_frame_it_is_placed_in():
    cells, origin, res = room()
    known = KnownMap(cells, origin, res, pose=(1.0, 0.5, math.pi / 2))
    # the map's (2.0, 0.0), on the wall, is at (1.0, 0.5) + rot90 (2.0, 0.0) = (1.0, 2.5)
    assert known.at([(1.0, 2.5)])[0] == 100
    assert known.at([(1.0 - 2.0, 0.5 + 0.5)])[0] == 0      # the map's (0.5, 2.0): the door
    assert known.at([(100.0, 100.0)])[0] == -1              # off the map
    with pytest.raises(KnownMapError):
        KnownMap(np.zeros((0, 3), np.int8), origin, res)
    with pytest.raises(KnownMapError):
        KnownMap(cells, origin, float('nan'))


def test_the_window_starts_from_the_map_and_a_shift_brings_more_of_it_in():
    cells, origin, res = room()
    grid = OccupancyGrid(0.05, 4.0, hit_places=True)   # a 4 m window round the origin
    grid.know(KnownMap(cells, origin, res))

    def at(x, y):
        r, c = grid.cell_of([(x, y)])[0]
        return grid.log_odds[r, c]
    assert at(0.0, 0.0) == PRIOR_FREE and at(1.99, 0.0) == PRIOR_WALL
    assert at(1.99, 2.0 - 0.05) in (PRIOR_FREE, PRIOR_WALL)   # (the door's edge)
    assert at(-1.5, 0.0) == 0.0   # off the map: unknown
    assert grid.established_at[grid.cell_of([(1.99, 0.0)])[0][0],
                               grid.cell_of([(1.99, 0.0)])[0][1]] < 0   # long established
    # the window moves on to x 3 to 7 m: what comes in is the map's, free up to x = 4 m
    # and unknown beyond
    grid.follow((5.0, 0.0))
    assert at(3.5, 0.0) == PRIOR_FREE and at(4.5, 0.0) == 0.0


def wall_scan(distance, n=360, stamp=0.0):
    """A scan from (0, 0, 0) seeing a wall at x = ``distance`` straight ahead (+-20 deg)
    and nothing elsewhere."""
    angles = -math.pi + np.arange(n) * 2 * math.pi / n
    ranges = np.full(n, np.inf)
    ahead = np.abs(angles) < math.radians(20)
    ranges[ahead] = distance / np.cos(angles[ahead])
    return Scan(ranges, -math.pi, 2 * math.pi / n, 0.12, 3.5, stamp)


def test_scans_overrule_the_map_a_closed_door_and_a_wall_gone():
    cells, origin, res = room()
    cells[:, :] = np.where(cells == 100, 0, cells)   # the map: no wall at all ...
    mem = NavigationMemory(PlannerConfig(field_worker=False, scan_alignment=False))
    mem.know(KnownMap(cells, origin, res))
    mem.integrate(wall_scan(1.0, stamp=0.0), (0.0, 0.0, 0.0))
    mem.integrate(wall_scan(1.0, stamp=0.2), (0.0, 0.0, 0.0))   # ... but one at x = 1 m
    near = mem.grid.cell_of([(x, 0.0) for x in np.arange(0.9, 1.06, 0.01)])
    assert mem.grid.log_odds[near[:, 0], near[:, 1]].max() > 0.0
    cells2, _, _ = room()
    mem2 = NavigationMemory(PlannerConfig(field_worker=False, scan_alignment=False))
    mem2.know(KnownMap(cells2, origin, res))   # the map's wall at x = 2 m, seen through
    for k in range(8):
        mem2.integrate(wall_scan(3.0, stamp=0.2 * k), (0.0, 0.0, 0.0))
    r, c = mem2.grid.cell_of([(1.99, 0.0)])[0]
    assert mem2.grid.log_odds[r, c] <= 0.0


def test_before_any_scan_the_field_leads_through_the_maps_door():
    cells, origin, res = room()
    mem = NavigationMemory(PlannerConfig(field_worker=False))
    start, goal = (0.5, 0.0), (3.5, 0.0)   # the wall between them, the door at y 1.5-2.5
    blind = mem.field_for(start, goal, -math.inf)[0].path(start)
    assert np.abs(blind[:, 1]).max() < 0.2   # without the map: straight at the wall
    mem.know(KnownMap(cells, origin, res))
    path = mem.field_for(start, goal, -math.inf)[0].path(start)
    crossing = path[np.argmin(np.abs(path[:, 0] - 2.0))]
    assert 1.5 < crossing[1] < 2.5 and np.hypot(*(path[-1] - goal)) < 0.1
