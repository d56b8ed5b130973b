"""Occupancy memory and navigation field (core/occupancy.py, core/navigation.py)."""

import math
import threading

from hypothesis import example, given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.memory import NavigationMemory
from subapf_planner.core.navigation import NEIGHBOURS, compute_field, densify, thin_polyline
from subapf_planner.core.occupancy import ESTABLISHED, LOG_ODDS_MAX, OccupancyGrid
from subapf_planner.core.planner import Planner
from subapf_planner.core.scan import Scan
from subapf_planner.core.status import Status
from subapf_planner.core.tracking import FREE_LOG_ODDS

pytestmark = pytest.mark.core

RES = 0.05


def one_beam(grid, r, yaw=0.0, origin=(0.0, 0.0)):
    grid.update(Scan([r], 0.0, 0.01, 0.12, 3.5), (origin[0], origin[1], yaw))


def test_a_beam_marks_its_end_and_clears_what_it_crossed():
    grid = OccupancyGrid(RES, 10.0)
    grid.log_odds[:] = 1.0                     # everything believed occupied
    one_beam(grid, 2.0)
    occ = grid.occupied()
    end = tuple(grid.cell_of([2.0, 0.0])[0])
    assert occ[end] and grid.log_odds[end] > 1.0
    for x in np.arange(0.15, 1.9, 0.05):      # crossed cells lost evidence
        assert grid.log_odds[tuple(grid.cell_of([x, 0.0])[0])] < 1.0, x
    # closer than range_min (0.12 m) the lidar says nothing: kept (core/blind_spots.py)
    assert grid.log_odds[tuple(grid.cell_of([0.05, 0.0])[0])] == 1.0
    assert grid.log_odds[tuple(grid.cell_of([2.5, 0.0])[0])] == 1.0   # beyond: untouched
    assert grid.log_odds[tuple(grid.cell_of([0.0, 1.0])[0])] == 1.0   # off the beam


@pytest.mark.parametrize('bad', [math.nan, 0.0, -1.0, 0.05])
def test_invalid_returns_change_nothing(bad):
    grid = OccupancyGrid(RES, 10.0)
    one_beam(grid, bad)
    assert not grid.log_odds.any()


def test_open_beam_clears_up_to_its_range():
    grid = OccupancyGrid(RES, 10.0)
    grid.log_odds[:] = 0.5
    grid.update(Scan([math.inf], 0.0, 0.01, 0.12, 3.5), (0.0, 0.0, 0.0), clear_range=2.0)
    assert grid.log_odds[tuple(grid.cell_of([1.9, 0.0])[0])] < 0.5
    assert grid.log_odds[tuple(grid.cell_of([2.2, 0.0])[0])] == 0.5
    assert grid.log_odds[tuple(grid.cell_of([0.05, 0.0])[0])] == 0.5   # within range_min


def test_a_held_new_object_is_not_cleared_by_its_own_returns_that_fell_long():
    """Returns held out of the memory mark nothing. Those of something held because it
    is new (NavigationMemory.integrate's ``unmoved``) clear their rays only up to two
    standard deviations of their range noise before them (``transient_short``): a box
    standing 1.5 m ahead, held while it is new, whose returns through the LDS-01's
    noise fall long as often as short, is not cleared from under itself (it stayed new
    and, its visible side changing, seemed to move, held for ever). A mover's returns
    clear up to themselves (else its trail stays), and clear the box's cells."""
    def after(short: float) -> float:
        grid = OccupancyGrid(RES, 10.0)
        rng = np.random.default_rng(4)
        for _ in range(20):   # 3.75 cm of noise at 1.5 m
            grid.update(Scan([1.5 + rng.normal(0.0, 0.0375)], 0.0, 0.01, 0.12, 3.5),
                        (0.0, 0.0, 0.0), transient=np.array([True]), transient_short=short)
        for x in (0.5, 1.0):   # the way to it is cleared either way
            assert grid.log_odds[tuple(grid.cell_of([x, 0.0])[0])] < 0.0
        return float(grid.log_odds[tuple(grid.cell_of([1.5, 0.0])[0])])
    assert after(2.0 * 0.0375) == 0.0   # never seen through: unknown, as it was
    assert after(0.0) < FREE_LOG_ODDS   # seen free (tracking): where the box stands
    for unmoved, before_it in ((True, 0.0), (False, -1.0)):   # new / moving
        memory = NavigationMemory(PlannerConfig(laser_x=0.0, laser_y=0.0, laser_yaw=0.0))
        scan = Scan(np.full(360, 1.5), 0.0, math.radians(1.0), 0.12, 3.5, 1.0)
        memory.integrate(scan, (0.0, 0.0, 0.0), None, np.ones(360, bool),
                         np.full(360, unmoved))
        at = {x: memory.grid.log_odds[tuple(memory.grid.cell_of([x, 0.0])[0])]
              for x in (1.0, 1.45)}
        assert memory.grid.log_odds.max() <= 0.0 and at[1.0] < 0.0
        assert np.sign(at[1.45]) == before_it, (unmoved, at)


def test_a_wall_is_drawn_where_its_noisy_returns_are_not_behind_them():
    """A wall 1.5 m ahead seen through the LDS-01's noise (3.75 cm there). In the planning
    layer each return that fell long clears the cells in front of it: the cell of the
    wall's face (1.45-1.50 m) is cleared as often as marked and never established, and
    the wall is drawn from the cell behind it. In the walls' layer the alignment matches
    to (``wall_odds``) a beam clears only up to two standard deviations before its
    return, and the face's cell is established."""
    grid = OccupancyGrid(RES, 10.0, hit_places=True)
    rng = np.random.default_rng(7)
    for _ in range(200):
        grid.update(Scan([1.5 + rng.normal(0.0, 0.0375)], 0.0, 0.01, 0.12, 3.5),
                    (0.0, 0.0, 0.0), wall_short=2.0 * 0.0375)
    face, behind = (tuple(grid.cell_of([x, 0.0])[0]) for x in (1.475, 1.525))
    assert grid.wall_odds[face] >= ESTABLISHED > grid.log_odds[face]
    assert grid.wall_odds[behind] >= ESTABLISHED and grid.log_odds[behind] >= ESTABLISHED
    for x in (0.5, 1.0, 1.4):   # the way to it is cleared in both
        cell = tuple(grid.cell_of([x, 0.0])[0])
        assert grid.log_odds[cell] < 0.0 and grid.wall_odds[cell] < 0.0
    assert OccupancyGrid(RES, 10.0).wall_odds is None   # kept for the alignment only


def test_an_obstacle_seen_then_seen_through_is_forgotten():
    grid = OccupancyGrid(RES, 10.0)
    for _ in range(20):
        one_beam(grid, 1.0)                   # a thing at 1 m, seen often
    cell = tuple(grid.cell_of([1.0, 0.0])[0])
    assert grid.log_odds[cell] == pytest.approx(LOG_ODDS_MAX)
    scans = 0
    while grid.occupied()[cell]:
        one_beam(grid, 3.0)                   # it moved away: the beam now reaches 3 m
        scans += 1
    assert scans <= 10


def test_memory_stays_bounded_on_a_long_drive():
    grid = OccupancyGrid(RES, 20.0)
    size = grid.nbytes
    ranges = np.full(360, 1.5)
    for k in range(400):                      # 200 m straight, scanning all the way
        x = 0.5 * k
        grid.follow((x, 0.0))
        grid.update(Scan(ranges, 0.0, 2 * math.pi / 360, 0.12, 3.5), (x, 0.0, 0.0))
        robot = grid.cell_of([x, 0.0])[0]
        assert grid.inside(robot[None])[0]
    assert grid.nbytes == size == 400 * 400 * 4   # log odds (no scan alignment)
    assert OccupancyGrid(0.05, 20.0, hit_places=True).nbytes == 400 * 400 * (4 + 8 + 2 + 4 + 4)
    # only what is near the robot is remembered
    assert grid.centre_of(np.argwhere(grid.occupied()))[:, 0].min() > 200.0 - 20.0


def test_window_reaches_towards_a_far_goal():
    grid = OccupancyGrid(RES, 20.0)
    assert grid.follow((0.0, 0.0), (15.0, 0.0))
    centre = grid.origin + grid.size / 2
    assert 5.0 <= centre[0] <= 10.0           # robot and goal both inside


# --- the field ------------------------------------------------------------------------
def field_on(occ, goal, robot=(0.1, 0.1), inflation=0.0, soft=0.0, coarsening=1, route=None,
             discount=0.0):
    return compute_field(occ, (0.0, 0.0), RES, goal, robot, inflation, soft, coarsening,
                         route, discount, 0.3)


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), fill=st.floats(0.0, 0.35),
       inflation=st.sampled_from([0.0, 0.06, 0.125]), soft=st.sampled_from([0.0, 0.2]),
       coarsening=st.sampled_from([1, 2, 3]), discount=st.sampled_from([0.0, 0.2, 0.6]))
# second-order fast marching left a pit at the patch's border here (navigation._fill_pits)
@example(seed=2663, fill=0.109375, inflation=0.06, soft=0.0, coarsening=1, discount=0.0)
def test_no_local_minimum_but_the_goal(seed, fill, inflation, soft, coarsening, discount):
    """Every reachable cell but the goal's has an 8-neighbour with a strictly lower value
    (on the cells the field is marched on: map cells, or blocks of them), also with a
    route favoured (any polyline: the route_discount hysteresis keeps the guarantee)."""
    rng = np.random.default_rng(seed)
    occ = rng.random((40, 40)) < fill
    free = np.argwhere(~occ)
    if len(free) == 0:
        return
    gr, gc = free[rng.integers(len(free))]
    goal = ((gc + 0.5) * RES, (gr + 0.5) * RES)
    route = np.cumsum(rng.normal(0.0, 0.1, (30, 2)), axis=0) + rng.random(2) * 40 * RES
    f = field_on(occ, goal, goal, inflation, soft, coarsening, route, discount)
    if f is None:                               # goal inside the inflation
        return
    v = f.values                                # (the patch the field was computed on)
    h, w = v.shape
    padded = np.pad(v, 1, constant_values=np.inf)
    lowest = np.min([padded[1 + dr:1 + dr + h, 1 + dc:1 + dc + w] for dr, dc in NEIGHBOURS],
                    axis=0)
    reachable = np.isfinite(v)
    reachable[np.unravel_index(np.argmin(np.where(reachable, v, np.inf)), v.shape)] = False
    assert np.all(lowest[reachable] < v[reachable])


@pytest.mark.parametrize('coarsening', [1, 2])
def test_field_is_close_to_euclidean_in_open_space_and_agrees_with_differences(coarsening):
    occ = np.zeros((200, 200), bool)
    goal = np.array([5.0, 5.0])
    f = field_on(occ, goal, robot=(9.0, 9.0), coarsening=coarsening)   # robot, goal, margin
    assert f.resolution == pytest.approx(coarsening * RES)
    rng = np.random.default_rng(3)
    pts = rng.uniform(4.5, 8.5, (200, 2))   # inside the patch, off its border
    pts = pts[np.hypot(*(pts - goal).T) > 10 * f.resolution]   # 8-neighbour quantisation
    d = np.hypot(*(pts - goal).T)
    assert np.all(np.abs(f.value(pts) - d) <= 0.02 * d + 2 * f.resolution)   # ~Euclidean
    # the descent direction points at the goal, and matches -grad by central differences
    dirs = f.direction(pts)
    to_goal = (goal - pts) / d[:, None]
    # (8-neighbour descent: a few degrees of quantisation)
    assert np.all(np.sum(dirs * to_goal, axis=1) > math.cos(math.radians(8)))
    h = 0.02
    gx = (f.value(pts + [h, 0]) - f.value(pts - [h, 0])) / (2 * h)
    gy = (f.value(pts + [0, h]) - f.value(pts - [0, h])) / (2 * h)
    grad = np.column_stack((gx, gy))
    cos = -np.sum(grad * dirs, axis=1) / np.linalg.norm(grad, axis=1)
    assert np.all(cos > math.cos(math.radians(8)))


@pytest.mark.parametrize('coarsening', [1, 2])
def test_the_field_goes_round_a_wall_and_through_a_narrow_gap(coarsening):
    occ = np.zeros((100, 100), bool)
    occ[50, :] = True                            # a wall across y = 2.525 m
    gap = slice(40, 40 + 6)                      # 6 cells = 0.30 m of free cells
    occ[50, gap] = False
    cfg = PlannerConfig()
    inflation = cfg.inflation_radius
    f = field_on(occ, (2.0, 4.0), robot=(2.0, 1.0), inflation=inflation,
                 soft=cfg.inflation_band, coarsening=coarsening)
    assert f is not None
    start = np.array([4.5, 1.0])
    assert np.isfinite(f.value(start)[0]) and f.reachable(start)
    path = f.path(start)
    crossing = path[np.argmin(np.abs(path[:, 1] - 2.525))]
    assert 2.0 <= crossing[0] <= 2.3             # through the gap
    assert np.hypot(*(path[-1] - (2.0, 4.0))) < 2 * f.resolution
    # closed wall: the other side cannot be reached
    occ[50, gap] = True
    f = field_on(occ, (2.0, 4.0), robot=(2.0, 1.0), inflation=inflation,
                 coarsening=coarsening)
    assert not np.isfinite(f.value(start)[0]) and not f.reachable(start)
    # a gap narrower than twice the inflation radius: the field goes through it (slowly,
    # so that a robot pushed into it is led on), but the goal counts as unreachable
    occ[50, 42:45] = False                       # 3 cells = 0.15 m
    f = field_on(occ, (2.0, 4.0), robot=(2.0, 1.0), inflation=inflation,
                 soft=cfg.inflation_band, coarsening=coarsening)
    assert np.isfinite(f.value(start)[0]) and not f.reachable(start)


def test_a_gap_the_blocks_close_is_marched_on_the_map_cells():
    """Two free cells between walls, straddling two blocks: every block holds a wall, so
    the coarse field is cut at the gap; the map cells pass a small robot through it."""
    occ = np.zeros((60, 60), bool)
    occ[30, :] = True
    occ[30, 29:31] = False                       # cells 29 and 30: blocks (28, 29), (30, 31)
    goal, robot = (1.5, 2.5), (1.5, 0.5)
    coarse = field_on(occ, goal, robot, inflation=0.04, coarsening=2)
    fine = field_on(occ, goal, robot, inflation=0.04, coarsening=1)
    assert coarse.resolution == pytest.approx(RES)          # fell back to the map cells
    assert np.array_equal(coarse.values, fine.values)
    assert coarse.value(robot)[0] == pytest.approx(2.0, abs=0.1)   # straight through


def _two_ways(shift):
    """A 6 m x 6 m map with a 3 m wide block across the middle, ``shift`` [m] right of
    centre: the robot at (3, 0.5) and the goal at (3, 5.5) have a way round either side."""
    occ = np.zeros((120, 120), bool)
    c0 = int(round((1.5 + shift) / RES))
    occ[50:70, c0:c0 + 60] = True
    return occ


def _side(path, shift):
    """The side of the block a path passes ('left', 'right')."""
    middle = path[np.argmin(np.abs(path[:, 1] - 3.0))]
    return 'left' if middle[0] < 3.0 + shift else 'right'


def test_the_route_taken_is_kept_until_another_way_is_clearly_shorter():
    """route_discount: the field leads the robot on round the side it has taken while the
    other way is less than the discount shorter (no dithering between two near-equal
    ways), and round the other once it is clearly shorter."""
    robot, goal = (3.0, 0.5), (3.0, 5.5)
    taken = field_on(_two_ways(-0.1), goal, robot, 0.105, 0.22, 2).path(robot)
    assert _side(taken, -0.1) == 'right'      # the shorter way when it was taken
    for shift, expected in ((0.1, 'right'), (0.3, 'right'), (0.6, 'left')):
        # (in the field's metres the right way 4 %, 13 %, 28 % longer than the left)
        assert _side(field_on(_two_ways(shift), goal, robot, 0.105, 0.22, 2).path(robot),
                     shift) == 'left'         # without the route: the shorter way
        kept = field_on(_two_ways(shift), goal, robot, 0.105, 0.22, 2, taken, 0.2)
        assert _side(kept.path(robot), shift) == expected
    # the memory keeps each field's descent as the next one's route, with the discount only
    for discount, kept in ((0.2, True), (0.0, False)):
        mem = NavigationMemory(PlannerConfig(route_discount=discount, field_worker=False))
        mem.field_for((0.0, 0.0), (2.0, 0.0), -math.inf)
        assert bool(mem.route is not None
                    and np.hypot(*(mem.route[-1] - (2.0, 0.0))) < 0.1) is kept


def test_a_path_given_to_follow_is_descended_and_left_where_the_memory_blocks_it():
    """NavigationMemory.follow (the follow_path action): in open space the field leads
    along a given path 25 % longer than the straight way (path_discount 0.5: within
    path_width and a cell of it), not
    straight; where the scan shows the path blocked it leads round and still to the goal
    (one minimum); without a path, straight again."""
    start, goal = (0.0, 0.0), (4.0, 0.0)
    bend = np.array([[0.0, 0.0], [2.0, 1.5], [4.0, 0.0]])   # 5 m against 4 m

    def off_path(descent):
        d = np.hypot(*(descent[:, None, :] - densify(bend, 0.01)[None]).transpose(2, 0, 1))
        return d.min(axis=1).max()
    mem = NavigationMemory(PlannerConfig(field_worker=False))
    straight = mem.field_for(start, goal, -math.inf)[0].path(start)
    assert np.abs(straight[:, 1]).max() < 0.15
    mem.follow(bend)
    along = mem.field_for(start, goal, -math.inf)[0].path(start)
    assert off_path(along) < 0.3 and np.hypot(*(along[-1] - goal)) < 0.1
    # a wall seen across the bend: the descent leaves the path there and reaches the goal
    ranges, amin, inc, rmin, rmax = enclosure_scan(1.0)
    ranges = np.full_like(ranges, np.inf)
    bearing = np.arange(len(ranges)) * inc + amin
    ranges[np.abs(bearing - math.atan2(1.5, 2.0)) < 0.12] = 2.4   # a wall 0.6 m wide
    mem.integrate(Scan(ranges, amin, inc, rmin, rmax, 0.0), (0.0, 0.0, 0.0))
    field = mem.field_for(start, goal, -math.inf)[0]
    around = field.path(start)
    assert field.reachable(start) and np.hypot(*(around[-1] - goal)) < 0.1
    assert off_path(around) > 0.4
    mem.follow(None)
    again = mem.field_for(start, goal, -math.inf)[0].path(start)
    assert np.abs(again[:, 1]).max() < 0.15


def test_a_goal_beyond_the_grid_whose_border_cell_is_a_wall_stands_in_beside_it():
    """A goal beyond the window is taken at the border cell nearest it; where that cell
    is in a wall (a known map's wall at the window's edge) the field leads to the free
    cell nearest it within BORDER_SLACK, not nowhere."""
    occ = np.zeros((60, 60), bool)
    occ[25:36, 57:] = True   # a wall against the right border, rows 25-35
    far = (20.0, 30 * RES + 0.5 * RES)   # beyond the right edge, level with the wall
    field = field_on(occ, far, robot=(0.5, 1.5), inflation=0.1)
    assert field is not None and field.reachable((0.5, 1.5))
    end = field.path((0.5, 1.5))[-1]
    assert end[0] > 50 * RES and abs(end[1] - far[1]) <= 1.0 + RES
    assert field_on(occ, (2.9, far[1]), robot=(0.5, 1.5), inflation=0.1) is None   # inside


def test_goal_in_an_inflated_obstacle_has_no_field():
    occ = np.zeros((60, 60), bool)
    occ[30, 30] = True
    assert field_on(occ, (1.5, 1.525), inflation=0.125) is None


def enclosure_scan(radius, n=360):
    return np.full(n, radius), 0.0, 2 * math.pi / n, 0.12, 3.5


def test_planner_stops_for_an_enclosed_goal_and_drives_when_it_opens():
    planner = Planner(PlannerConfig())
    pose = np.array([0.0, 0.0, 0.0])
    ranges, amin, inc, rmin, rmax = enclosure_scan(1.0)
    ranges = ranges.copy()
    goal = (2.0, 0.0)                            # outside a closed ring of radius ~1 m
    for k in range(3):   # the ring seen twice (a cycle plans on the scans before its own)
        res = planner.step(pose, goal, Scan(ranges, amin, inc, rmin, rmax, k), now=k)
    assert res.command.status is not Status.GOAL_UNREACHABLE   # not sure of it yet
    for k in range(3, 5):   # three times and more: established
        res = planner.step(pose, goal, Scan(ranges, amin, inc, rmin, rmax, k), now=k)
    assert res.command.status is Status.GOAL_UNREACHABLE and res.command.v == 0.0
    assert res.no_way == 'the walls in the memory close every way'
    ranges[-30:] = np.inf                        # an opening appears (and stays)
    ranges[:30] = np.inf
    for k in range(5, 14):
        res = planner.step(pose, goal, Scan(ranges, amin, inc, rmin, rmax, k), now=k)
    assert res.command.status is not Status.GOAL_UNREACHABLE


@pytest.mark.parametrize('coarsening', [1, 2])
def test_a_goal_a_few_centimetres_inside_the_inflation_is_led_to_beside_it(coarsening):
    """A wall along y = 1 m (cells 20-21), the goal 0.115 m from its cells' centres,
    inside an inflation of 0.15 m: with goal_slack the field leads to the nearest free
    cell (0.035 m farther out), as the memory's walls are drawn some centimetres thick;
    without it, or with the goal on the wall, there is no field."""
    occ = np.zeros((60, 60), bool)
    occ[20:22, :] = True
    robot, goal = (1.5, 2.5), (1.525, 1.19)   # 0.115 m from row 21's centres

    def field(goal, slack):
        return compute_field(occ, (0.0, 0.0), RES, goal, robot, 0.15, 0.2, coarsening,
                             goal_slack=slack)
    assert field(goal, 0.0) is None
    f = field(goal, 0.075)
    assert f is not None and f.reachable(robot)
    assert f.goal == pytest.approx((1.525, 1.225))   # 0.15 m from row 21's centres
    end = f.path(robot, 5.0)[-1]
    assert np.hypot(*(end - f.goal)) < 0.1 and end[1] > 1.19   # led there, not into the wall
    assert field((1.525, 1.025), 0.075) is None      # on the wall: 0.1 m to a free cell


def test_the_memory_says_why_it_holds_no_way():
    """NavigationMemory.no_way: what closes the way, for the unreachable state's reason
    and the bench (a goal in a wall, the walls, places tried)."""
    mem = NavigationMemory(PlannerConfig(field_worker=False))
    ranges, amin, inc, rmin, rmax = enclosure_scan(1.0)
    ranges = ranges.copy()
    ranges[:20] = ranges[-20:] = np.inf      # a ring of radius 1 m, open towards +x
    for k in range(3):                       # seen three times: established
        mem.integrate(Scan(ranges, amin, inc, rmin, rmax, float(k)), (0.0, 0.0, 0.0))
    assert mem.no_way((0.0, 0.0), (0.0, 1.0)) == ('the goal is within inflation_radius of a '
                                                  'wall in the memory, with no free cell '
                                                  'within goal_slack')
    field, _ = mem.field_for((0.0, 0.0), (3.0, 0.0), now=0.0)
    assert field.reachable((0.0, 0.0))      # out through the opening
    mem.avoid((1.0, 0.0), 0.4, until=10.0)   # the opening tried
    field, _ = mem.field_for((0.0, 0.0), (3.0, 0.0), now=1.0)
    assert not field.reachable((0.0, 0.0))
    assert mem.no_way((0.0, 0.0), (3.0, 0.0)) == 'every way through the walls tried'
    for k in range(3, 8):                    # the ring closes (the opening's cells, seen
        #                                          free three times, established by then)
        mem.integrate(Scan(*enclosure_scan(1.0), float(k)), (0.0, 0.0, 0.0))
    assert mem.no_way((0.0, 0.0), (3.0, 0.0)) == 'the walls in the memory close every way'
    assert mem.no_way((0.0, 0.0), (30.0, 0.0)).endswith('taken at its edge)')


def test_a_goal_is_given_up_only_for_walls_the_memory_is_sure_of():
    """One return seen once from afar right beside the goal (a mixed pixel at a depth
    edge) leaves the goal open, and the field leads there to look again; once the return
    is established (three of them), the goal is closed and the memory says why."""
    mem = NavigationMemory(PlannerConfig(field_worker=False))
    n = 360
    ranges = np.full(n, np.inf)
    ranges[0] = 3.0                           # straight ahead, 3 m
    hit = mem.grid.centre_of(mem.grid.cell_of([[3.0 + PlannerConfig().laser_x, 0.0]]))[0]
    goal = (float(hit[0]), float(hit[1]))
    for k in range(3):
        mem.integrate(Scan(ranges, 0.0, 2 * math.pi / n, 0.12, 3.5, float(k)),
                      (0.0, 0.0, 0.0))
        assert mem.grid.occupied()[tuple(mem.grid.cell_of([goal])[0])]
        field, _ = mem.field_for((0.0, 0.0), goal, now=float(k))
        if k < 2:                             # log odds 0.9, 1.8: not established
            assert field is not None and field.reachable((0.0, 0.0))
    assert field is None
    assert mem.no_way((0.0, 0.0), goal).startswith('the goal is within inflation_radius')


def _first_fields(cfg: PlannerConfig) -> NavigationMemory:
    """A memory that computed a field, kept it while the map changed within
    field_period, and computed one for a new goal at 0.4 s."""
    mem = NavigationMemory(cfg)
    mem.integrate(Scan(*enclosure_scan(2.0), 0.0), (0.0, 0.0, 0.0))
    assert mem.field_for((0, 0), (1.0, 0.0), now=0.0)[1]
    mem.integrate(Scan(*enclosure_scan(1.5), 0.2), (0.0, 0.0, 0.0))
    assert not mem.field_for((0, 0), (1.0, 0.0), now=0.2)[1]   # grid changed, within period
    assert mem.field_for((0, 0), (0.0, 1.0), now=0.4)[1]       # new goal
    mem.integrate(Scan(*enclosure_scan(1.2), 1.5), (0.0, 0.0, 0.0))
    return mem


def test_memory_recomputes_on_a_new_goal_and_at_most_every_field_period():
    mem = _first_fields(PlannerConfig(field_period=1.0, field_worker=False))   # in the call
    assert mem.field_for((0, 0), (0.0, 1.0), now=1.5)[1]   # grid changed, field_period over
    mem.integrate(Scan(*enclosure_scan(1.2), 3.0), (0.0, 0.0, 0.0))
    assert not mem.field_for((0, 0), (0.0, 1.0), now=3.0)[1]   # the same walls: no change


def test_with_the_worker_the_map_changes_reach_the_field_at_the_next_call():
    cfg = PlannerConfig(field_period=1.0, field_worker=True)
    mem = _first_fields(cfg)
    before = mem.field
    field, new = mem.field_for((0, 0), (0.0, 1.0), now=1.5)   # grid changed, period over:
    assert field is before and not new                        # marched in the worker ...
    # ... not before the cycle is over (start_marching: DecisionLoop.after_tick) ...
    assert not any(t.name.startswith('field') for t in threading.enumerate())
    mem.start_marching()
    assert any(t.name.startswith('field') for t in threading.enumerate())
    after, new = mem.field_for((0, 0), (0.0, 1.0), now=1.7)
    assert new and after is not before   # ... and taken at the next call
    # the field marched in the worker is the one the cycle would have computed (from the
    # same map and the same route)
    alone = _first_fields(cfg.replace(field_worker=False))
    np.testing.assert_array_equal(alone.field_for((0, 0), (0.0, 1.0), now=1.5)[0].values,
                                  after.values)


def test_a_field_being_marched_is_dropped_for_a_new_goal_or_a_forgotten_map():
    mem = NavigationMemory(PlannerConfig(field_period=1.0, field_worker=True))
    mem.integrate(Scan(*enclosure_scan(2.0), 0.0), (0.0, 0.0, 0.0))
    mem.field_for((0, 0), (1.0, 0.0), now=0.0)
    mem.integrate(Scan(*enclosure_scan(1.5), 1.2), (0.0, 0.0, 0.0))
    mem.field_for((0, 0), (1.0, 0.0), now=1.2)   # marching the map's changes
    new_goal, new = mem.field_for((0, 0), (0.0, 1.0), now=1.4)
    assert new and np.allclose(new_goal.goal, (0.0, 1.0))   # in the cycle
    assert mem.field_for((0, 0), (0.0, 1.0), now=1.6)[0] is new_goal   # the old job: gone
    mem.integrate(Scan(*enclosure_scan(1.2), 2.6), (0.0, 0.0, 0.0))
    mem.field_for((0, 0), (0.0, 1.0), now=2.6)
    mem.forget()
    assert mem.field is None and mem.field_for((0, 0), (0.0, 1.0), now=2.8)[0] is not None


def test_a_thinned_polyline_keeps_its_ends_and_its_spacing():
    line = np.column_stack((np.arange(0.0, 2.05, 0.1), np.zeros(21)))   # 2 m in 0.1 m steps
    thin = thin_polyline(line, 0.25)
    np.testing.assert_allclose(thin[0], line[0])
    np.testing.assert_allclose(thin[-1], line[-1])
    gaps = np.diff(thin[:, 0])
    assert np.all(gaps[:-1] >= 0.25 - 1e-9) and np.all(gaps[:-1] <= 0.3 + 1e-9)
    assert len(thin) < len(line)
    np.testing.assert_allclose(thin_polyline(line[:2], 0.25), line[:2])   # too short: as is
    # a path that zigzags on 0.1 m blocks (down-right, up-right: 0.28 m along it, 0.2 m
    # across): its points stay 0.25 m apart in a straight line
    zigzag = np.column_stack((np.arange(0.0, 3.05, 0.1), 0.1 * (np.arange(31) % 2)))
    thin = thin_polyline(zigzag, 0.25)
    assert np.all(np.hypot(*np.diff(thin[:-1], axis=0).T) >= 0.25 - 1e-9)
    np.testing.assert_allclose(thin[[0, -1]], zigzag[[0, -1]])


@given(stamps=st.lists(st.integers(0, 40), min_size=1, max_size=30, unique=True),
       asked=st.integers(-100, 500))
@settings(max_examples=200, deadline=None)
def test_the_odometry_at_a_stamp_is_interpolated_between_the_poses_around_it(stamps, asked):
    """DecisionLoop.pose_between: of the odometry kept, the pose at the scan's stamp
    interpolated between the two poses around it; before the oldest the oldest, after
    the newest the newest (here x = the pose's index: the interpolation is np.interp)."""
    from subapf_planner.core.loop import DecisionLoop
    loop = DecisionLoop(PlannerConfig())
    times = np.sort(np.asarray(stamps)) * 0.05
    for i, t in enumerate(times):
        assert loop.update_odom(float(t), np.array([float(i), -2.0 * i, 0.1 * i]), float(t))
    stamp = asked * 0.005
    x = np.interp(stamp, times, np.arange(len(times)))
    np.testing.assert_allclose(loop.pose_between(stamp), [x, -2.0 * x, 0.1 * x], atol=1e-9)


def test_a_scan_is_planned_from_the_odometry_interpolated_at_its_stamp(monkeypatch):
    """DecisionLoop.tick hands the planner the odometry pose at the scan's stamp,
    interpolated between the poses around it (as the de-skewing places its beams), not
    the nearest pose: a 50 Hz lidar between 20 Hz odometry is up to 25 ms off it."""
    from subapf_planner.core.loop import DecisionLoop
    loop = DecisionLoop(PlannerConfig())
    seen = []
    real = loop.planner.step

    def step(pose, goal, scan, scan_pose=None, **kw):
        seen.append(np.array(scan_pose))
        return real(pose, goal, scan, scan_pose, **kw)

    monkeypatch.setattr(loop.planner, 'step', step)
    loop.set_goal(np.array([3.0, 0.0]))
    loop.update_odom(0.0, np.array([0.0, 0.0, 0.0]), 0.0)
    loop.update_odom(0.05, np.array([0.1, 0.0, 0.0]), 0.05)
    loop.update_scan(Scan(np.full(360, np.inf), 0.0, 2 * math.pi / 360, 0.12, 3.5, 0.02),
                     0.05)
    loop.tick(0.05)
    np.testing.assert_allclose(seen[-1], [0.04, 0.0, 0.0], atol=1e-12)
