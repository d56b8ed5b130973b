"""Scan alignment (core/alignment.py): a known offset recovered, a corridor left alone
along its axis, wrong or empty matches refused, the correction no faster than wheels
drift; and with the simulator, a drifting run whose corrected pose stays near the
truth."""

import math

import numpy as np
import pytest

from subapf_planner.core.alignment import (
    DRIFT_XY_PER_M,
    DRIFT_YAW_PER_M,
    LOCALISE_MAX_XY,
    MAX_STEP_XY,
    MIN_MATCHED,
    MIN_WALL_AGE,
    _ends,
    align,
    distance_field,
    landmarks,
    localise,
    within_drift,
)
from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.known_map import KnownMap
from subapf_planner.core.occupancy import ESTABLISHED, NOT_ESTABLISHED, OccupancyGrid
from subapf_planner.core.planner import Planner
from subapf_planner.core.robot import to_parent
from subapf_planner.core.scan import Scan, scans_in

RES = 0.05
#: Scans a wall must have stood to be matched by a small piece, at the default 5 Hz.
YOUNG = scans_in(MIN_WALL_AGE, PlannerConfig().period)


def grid_with(walls: np.ndarray) -> OccupancyGrid:
    """A 20 m grid whose cells under ``walls`` (n, 2) are established obstacles."""
    g = OccupancyGrid(RES, 20.0)
    cells = g.cell_of(walls)
    g.log_odds[cells[:, 0], cells[:, 1]] = 3.5
    return g


def segment(a, b, step=0.01):
    a, b = np.asarray(a, float), np.asarray(b, float)
    t = np.linspace(0.0, 1.0, int(np.hypot(*(b - a)) / step) + 1)[:, None]
    return a + t * (b - a)


def room():
    """A 6 x 4 m room (walls through cell centres) with a round pillar."""
    x0, x1, y0, y1 = -2.975, 3.025, -1.975, 2.025
    a = np.linspace(0, 2 * math.pi, 90)
    return np.vstack([segment((x0, y0), (x1, y0)), segment((x1, y0), (x1, y1)),
                      segment((x1, y1), (x0, y1)), segment((x0, y1), (x0, y0)),
                      np.column_stack((1.0 + 0.3 * np.cos(a), 0.5 + 0.3 * np.sin(a)))])


def seen_from(walls: np.ndarray, pose, noise=0.01, seed=0) -> np.ndarray:
    """What a 360-beam laser at ``pose`` sees of the wall points: the nearest per degree,
    with range noise, in base_footprint (n, 2)."""
    rel = walls - np.asarray(pose[:2])
    ang = np.remainder(np.arctan2(rel[:, 1], rel[:, 0]) - pose[2], 2 * math.pi)
    rng_ = np.hypot(*rel.T)
    beam = np.round(np.degrees(ang)).astype(int) % 360
    order = np.lexsort((rng_, beam))
    first = order[np.r_[True, np.diff(beam[order]) != 0]]
    first = first[rng_[first] < 3.5]
    r = rng_[first] + np.random.default_rng(seed).normal(0.0, noise, first.size)
    a = ang[first]
    return np.column_stack((r * np.cos(a), r * np.sin(a)))


def match(grid, base, predicted):
    field = distance_field(grid.log_odds, grid.origin, RES, to_parent(predicted, base), 0.4)
    return align(base, np.asarray(predicted, float), field)


@pytest.mark.core
def test_a_known_offset_is_recovered():
    """The prediction 2.5 cm, 1.5 cm and 0.7 degrees off (drift builds up about a
    millimetre per scan; this is what a refused stretch can leave): the match is within
    8 mm and 0.1 degrees of the true pose (the prior holds back a few mm)."""
    walls = room()
    true = np.array([0.4, -0.3, 0.2])
    base = seen_from(walls, true)
    m = match(grid_with(walls), base, true + [0.025, -0.015, 0.012])
    assert m.accepted and m.matched > 200 and m.rms < 0.03
    assert np.hypot(*(m.pose[:2] - true[:2])) < 0.008
    assert abs(m.pose[2] - true[2]) < math.radians(0.1)


def thick_room() -> KnownMap:
    """room() as a map_server map (free 0, walls 100) draws it: each wall three cells
    thick, its face where the laser sees it and the rest behind; in the map's frame."""
    xs = np.arange(-4.0, 4.0, RES) + RES / 2
    ys = np.arange(-3.0, 3.0, RES) + RES / 2
    x, y = np.meshgrid(xs, ys)
    x0, x1, y0, y1 = -2.975, 3.025, -1.975, 2.025   # room()'s walls: the faces' cells
    inside = (x > x0 + 0.01) & (x < x1 - 0.01) & (y > y0 + 0.01) & (y < y1 - 0.01)
    band = (x > x0 - 0.11) & (x < x1 + 0.11) & (y > y0 - 0.11) & (y < y1 + 0.11)
    pillar = np.hypot(x - 1.0, y - 0.5) < 0.31
    return KnownMap(np.where(band & ~inside | pillar, 100, 0).astype(np.int8),
                    (-4.0, -3.0), RES)


@pytest.mark.core
def test_a_known_maps_thick_wall_is_matched_at_its_face():
    """A map draws a wall three cells thick; a return inside it is as far from the wall as
    from its face, not matched to the cell it fell in (the scans' own walls, hit by
    returns, are matched where the returns fell)."""
    g = OccupancyGrid(RES, 20.0, hit_places=True)
    g.know(thick_room())
    inside = np.array([[-3.025, 0.325]])   # in the left wall, a cell behind its face
    face = distance_field(g.log_odds, g.origin, RES, inside, 0.4, g.hit_offset,
                          hit_count=g.hit_count)
    assert face.lookup(inside)[2][0] == pytest.approx(0.05, abs=0.01)
    whole = distance_field(g.log_odds, g.origin, RES, inside, 0.4, g.hit_offset)
    assert whole.lookup(inside)[2][0] < 0.01


@pytest.mark.core
@pytest.mark.parametrize('off', [(0.12, -0.08, 0.05), (-0.2, 0.1, -0.08)])
def test_a_localisers_decimetres_are_taken_out_on_its_map(off):
    """On a map the robot already has, a localiser's error (decimetres, degrees) is not a
    wheel's millimetres: the scan alignment refuses such a step, localise takes it (to
    within 1.5 cm and 0.3 degrees), and refuses one beyond LOCALISE_MAX_XY."""
    walls = room()
    g = OccupancyGrid(RES, 20.0, hit_places=True)
    g.know(thick_room())
    true = np.array([0.4, -0.3, 0.2])
    base = seen_from(walls, true)
    predicted = true + off
    field = distance_field(g.log_odds, g.origin, RES, to_parent(predicted, base), 1.0,
                           g.hit_offset, hit_count=g.hit_count)
    assert not align(base, predicted, field).accepted
    m = localise(base, predicted, field)
    assert m.accepted
    assert np.hypot(*(m.pose[:2] - true[:2])) < 0.015 and abs(m.pose[2] - true[2]) < 0.005
    far = true + [LOCALISE_MAX_XY + 0.2, 0.0, 0.0]
    m = localise(base, far, distance_field(g.log_odds, g.origin, RES, to_parent(far, base),
                                           1.0, g.hit_offset, hit_count=g.hit_count))
    assert not m.accepted and np.array_equal(m.pose, far)


@pytest.mark.core
def test_a_corridor_is_corrected_across_and_left_alone_along():
    """Two long parallel walls fix the pose across the corridor and in heading, not along
    it: the across offset is removed, the along one is odometry's (the prediction),
    not a slide."""
    walls = np.vstack([segment((-6.0, -0.625), (6.0, -0.625)),
                       segment((-6.0, 0.625), (6.0, 0.625))])
    true = np.array([0.0, 0.1, 0.0])
    base = seen_from(walls, true)
    m = match(grid_with(walls), base, true + [0.015, 0.02, 0.008])
    assert m.accepted
    assert abs(m.pose[1] - true[1]) < 0.004 and abs(m.pose[2] - true[2]) < 0.002
    assert m.pose[0] - true[0] == pytest.approx(0.015, abs=0.003)


@pytest.mark.core
@pytest.mark.parametrize('seed', [0, 1, 2])
def test_a_wall_drawn_off_where_it_was_seen_grazing_does_not_turn_the_heading(seed):
    """A corridor whose left wall the memory drew 5 cm out at its far end (a grid draws
    a wall seen at grazing incidence a cell or more off), its end wall square ahead:
    from the true pose the match keeps the heading within 4 mrad, the returns weighed
    by their incidence on the walls (unweighed, the far grazing returns turned it by
    8 mrad, and the drift bound let such turns through scan after scan)."""
    def corridor(left_end_y):
        return np.vstack([segment((-1.0, 0.375), (3.0, left_end_y)),
                          segment((-1.0, -0.375), (3.0, -0.375)),
                          segment((3.025, -0.375), (3.025, 0.375))])
    true = np.array([0.0, 0.0, 0.0])
    base = seen_from(corridor(0.375), true, seed=seed)
    m = match(grid_with(corridor(0.425)), base, true)
    assert m.accepted
    assert abs(m.pose[2]) < 0.004 and np.hypot(*m.pose[:2]) < 0.003


@pytest.mark.core
def test_no_map_few_returns_or_a_jump_are_refused():
    walls = room()
    true = np.array([0.4, -0.3, 0.2])
    base = seen_from(walls, true)
    empty = OccupancyGrid(RES, 20.0)
    assert not match(empty, base, true).accepted                       # nothing to match
    m = match(grid_with(walls), base[:10], true)                        # too few returns
    assert not m.accepted and np.array_equal(m.pose, true)
    far = true + [MAX_STEP_XY + 0.03, 0.0, 0.0]                        # a jump: refused,
    m = match(grid_with(walls), base, far)                              # the prediction
    assert not m.accepted and np.array_equal(m.pose, far)               # stands


@pytest.mark.core
def test_a_correction_changes_no_faster_than_odometry_can_drift():
    predicted = np.array([1.0, 2.0, 0.3])
    matched = predicted + [0.02, -0.01, 0.01]
    assert np.array_equal(within_drift(predicted, matched, 0.0, 0.0), predicted)  # standing
    np.testing.assert_allclose(within_drift(predicted, matched, 1.0, 0.0), matched)  # 1 m
    off = within_drift(predicted, matched, 0.1, 0.0) - predicted       # 0.1 m: cut to the
    assert np.hypot(*off[:2]) == pytest.approx(DRIFT_XY_PER_M * 0.1)   # limit, in the
    assert off[0] * -0.01 == pytest.approx(off[1] * 0.02)              # match's direction
    assert off[2] == pytest.approx(DRIFT_YAW_PER_M * 0.1)
    assert np.array_equal(predicted, [1.0, 2.0, 0.3])                  # input untouched


def ranges_from(walls: np.ndarray, pose) -> np.ndarray:
    """360 ranges of a laser at ``pose`` (beam i at i degrees): the nearest wall point
    within 0.15 degrees of the beam, inf beyond 3.5 m or where none is."""
    rel = walls - np.asarray(pose[:2])
    ang = np.degrees(np.remainder(np.arctan2(rel[:, 1], rel[:, 0]) - pose[2], 2 * math.pi))
    r = np.hypot(*rel.T)
    beam = np.round(ang).astype(int) % 360
    on = np.abs(np.remainder(ang - beam + 180.0, 360.0) - 180.0) < 0.15
    ranges = np.full(360, np.inf)
    np.minimum.at(ranges, beam[on], r[on])
    ranges[ranges >= 3.5] = np.inf
    return ranges


@pytest.mark.core
def test_the_planner_corrects_drift_while_it_drives_and_not_while_it_stands():
    """A room mapped from the start; after 1 m of driving whose odometry says 2 cm less
    than the truth, the correction takes the 2 cm (within the matcher's 8 mm); then the
    walls seem 2 cm and 0.3 degrees off (a person pushing the scan, the matcher's own
    error): standing still, odometry cannot have drifted, and the correction stays."""
    walls = np.vstack([segment(a, b, 0.004) for a, b in (
        ((-2.0, -1.5), (2.5, -1.5)), ((2.5, -1.5), (2.5, 1.5)), ((2.5, 1.5), (-2.0, 1.5)),
        ((-2.0, 1.5), (-2.0, -1.5)), ((0.8, 0.6), (1.4, 0.6)), ((1.4, 0.6), (1.4, 1.0)))])
    planner = Planner(PlannerConfig(scan_alignment=True, laser_x=0.0, laser_y=0.0,
                                    laser_yaw=0.0))
    k = 0

    def scan_at(true, odom):
        nonlocal k
        k += 1
        planner.step(np.asarray(odom, float), (2.0, -1.0),
                     Scan(ranges_from(walls, true), 0.0, math.radians(1.0), 0.12, 3.5,
                          0.2 * k), now=0.2 * k)
        planner.after_tick()   # the scan matched once the command is out, as the node does
        return np.asarray(planner.correction)

    for _ in range(6):                                   # the room mapped, no drift
        c = scan_at((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert np.abs(c).max() < 0.005
    for x in np.arange(1, 11) * 0.1:                    # driving 1 m, 2 cm short
        c = scan_at((x * 1.02, 0.0, 0.0), (x, 0.0, 0.0))
    assert c[0] == pytest.approx(0.02, abs=0.008) and abs(c[1]) < 0.008
    for _ in range(4):                                   # standing: nothing moves it
        assert np.array_equal(scan_at((1.04, 0.0, 0.005), (1.0, 0.0, 0.0)), c)


@pytest.mark.core
def test_started_from_a_localisers_map_the_first_scans_take_its_error_out():
    """The planner started from a map and a localiser's map -> odom 0.1 m and 0.03 rad
    off (Planner.start_from): standing still (where the wheels' drift bound lets nothing
    through), the first scan's match in the localiser's basin brings the planned pose
    to within 1.5 cm and 0.3 degrees of the truth, and the next scans keep it there."""
    walls = room()
    planner = Planner(PlannerConfig(scan_alignment=True, laser_x=0.0, laser_y=0.0,
                                    laser_yaw=0.0))
    planner.start_from(thick_room(), (0.1, 0.0, 0.03))
    true = np.array([0.4, -0.3, 0.2])
    odom = true   # odom truly is the map's frame; the localiser says otherwise
    for k in range(1, 5):
        planner.step(odom, (2.0, -1.0), Scan(ranges_from(walls, true), 0.0,
                                             math.radians(1.0), 0.12, 3.5, 0.2 * k),
                     now=0.2 * k)
        planner.after_tick()
        pose = planner.in_map(odom)
        assert np.hypot(*(pose[:2] - true[:2])) < 0.015 and abs(pose[2] - true[2]) < 0.005


@pytest.mark.sim
def test_the_scan_goes_into_the_memory_after_the_command_the_same_either_way():
    """A tick plans with the memory as the scan before left it (its own scan is among
    its obstacles); after_tick (the node: once cmd_vel is out) matches the scan to the
    memory and writes it. A caller that never calls after_tick gets the same done first
    thing in the next tick: the same commands, correction and memory, here with
    drifting odometry through a cluttered field."""
    from subapf_planner.core.loop import DecisionLoop
    from subapf_planner.ros.paths import shipped_worlds_dir
    from subapf_planner.sim.simulator import RobotSim, SimConfig
    from subapf_planner.sim.world import load_world
    world = load_world(shipped_worlds_dir() / 'cluttered_field.yaml')
    told, left = DecisionLoop(PlannerConfig()), DecisionLoop(PlannerConfig())
    for ctl in (told, left):
        ctl.set_goal(np.asarray(world.goal, float), in_map=True)
    sim_cfg = SimConfig(sensor='ideal', range_noise=0.01, odom_distance_scale=1.02,
                        odom_yaw_scale=1.03)
    with RobotSim(world, sim_cfg) as sim:
        start = sim.true_pose()
        for _ in range(30):
            odom, scan = sim.odometry()[0], sim.scan()
            for ctl in (told, left):
                ctl.update_odom(sim.time, odom, sim.time)
                ctl.update_scan(scan, sim.time)
            scans = told.grid.scans
            decision = told.tick(sim.time)
            assert told.grid.scans == scans          # not written in the tick ...
            told.after_tick()
            assert told.grid.scans == scans + 1      # ... but once the command is out
            assert left.tick(sim.time).command == decision.command
            sim.set_command(*decision.command)
            sim.step(0.2)
        driven = float(np.hypot(*(sim.true_pose()[:2] - start[:2])))
    left.settle()
    told.settle()
    assert driven > 0.5
    assert told.planner.correction == left.planner.correction != (0.0, 0.0, 0.0)
    np.testing.assert_array_equal(told.grid.log_odds, left.grid.log_odds)


def _drive_between(world, sim_cfg, legs):
    """Drive start -> goal -> start ... (``legs`` times there and back, each goal a place
    in the world) with the default planner; returns (metres driven, per cycle the
    corrected and the odometry position errors [m], for each goal the planner reached
    the true distance to it then [m], collided)."""
    from subapf_planner.core.loop import DecisionLoop
    from subapf_planner.core.status import State
    from subapf_planner.sim.simulator import RobotSim
    # the planner told the lidar it has (exact rays with 1 cm noise)
    ctl = DecisionLoop(PlannerConfig(scan_alignment=True, range_noise_floor=0.01,
                                     range_noise_fraction=0.0))
    goals = [np.asarray(world.goal, float), np.asarray(world.start[:2], float)] * legs
    misses, driven, corrected, odometry = [], 0.0, [], []
    ctl.set_goal(goals[0], in_map=True)
    with RobotSim(world, sim_cfg) as sim:
        last = sim.true_pose()
        while sim.time < 300.0 * legs and not sim.collided and not ctl.state.gave_up:
            truth = sim.true_pose()
            driven += float(np.hypot(*(truth[:2] - last[:2])))
            last = truth
            if ctl.state is State.REACHED:   # where the robot really is then
                misses.append(float(np.hypot(*(truth[:2] - goals[len(misses)]))))
                if len(misses) == len(goals):
                    break
                ctl.set_goal(goals[len(misses)], in_map=True)
            odom = sim.odometry()[0]
            ctl.update_odom(sim.time, odom, sim.time)
            ctl.update_scan(sim.scan(), sim.time)
            d = ctl.tick(sim.time)
            if d.command is not None:
                sim.set_command(*d.command)
            if d.result is not None and d.result.pose is not None:
                corrected.append(np.hypot(*(d.result.pose[:2] - truth[:2])))
                odometry.append(np.hypot(*(odom[:2] - truth[:2])))
            sim.step(0.2)
    return driven, np.array(corrected), np.array(odometry), misses, sim.collided


@pytest.mark.sim
@pytest.mark.slow
def test_drifting_odometry_is_corrected_over_60_m_of_a_building():
    """Odometry +2 % in distance, +3 % in turn rate, back and forth through a generated
    building floor (building_007 of the dev suite) for more than 60 m: odometry ends
    metres off; the aligned pose stays within 0.1 m of the truth all along (measured:
    0.056 m over 65.2 m, odometry 2.5 m off; 0.067 m over 66.7 m before the rules among
    people), and the robot really stops within the goal tolerance of every goal (a
    place in the world), without a collision."""
    from subapf_planner.sim.simulator import SimConfig
    from subapf_planner.sim.world import parse_world
    from subapf_planner.sim.worldgen import generate, sub_seed
    world = parse_world(generate('building', sub_seed(2026, 'building', 7), 'building_007'))
    drift = SimConfig(sensor='ideal', range_noise=0.01, odom_distance_scale=1.02,
                      odom_yaw_scale=1.03)
    driven, corrected, odometry, misses, collided = _drive_between(world, drift, legs=2)
    assert driven > 60.0 and len(misses) == 4 and not collided
    assert max(misses) <= world.goal_tolerance      # it stops there in truth
    assert odometry.max() > 1.0                     # the drift is real ...
    assert corrected.max() < 0.1                    # ... and corrected


def _stepped_corridor():
    """A corridor 12 m long and about 2 m wide whose walls are 5 cm steps (as a
    building's map drawn in 5 cm cells, or shelves and jambs, are), with four posts."""
    rng = np.random.default_rng(1)
    boxes = []
    for side in (1.0, -1.0):
        step = 0
        for i in range(-20, 261):
            step = int(np.clip(step + rng.integers(-1, 2), 0, 2))
            boxes.append({'box': {'center': [0.05 * i + 0.025, side * (1.05 + 0.05 * step)],
                                  'size': [0.05, 0.1 + 0.1 * (2 - step)]}})
    boxes += [{'box': {'center': [x, 0.0], 'size': [0.1, 2.6]}} for x in (-1.05, 13.05)]
    boxes += [{'box': {'center': [x, y], 'size': [0.2, 0.2]}}
              for x, y in ((2.0, 0.85), (4.5, -0.85), (7.0, 0.85), (9.5, -0.85))]
    return {'name': 'stepped_corridor', 'start': [0.0, 0.0, 0.0], 'goal': [12.0, 0.0],
            'goal_tolerance': 0.15, 'time_limit': 150, 'bounds': [-1.5, -1.5, 13.5, 1.5],
            'obstacles': boxes}


@pytest.mark.sim
def test_stepped_walls_do_not_stretch_the_drive():
    """Exact rays and perfect odometry along 12 m of stepped walls, the planner expecting
    the LDS-01's noise: the memory's walls, drawn from returns that are not moved onto
    lines at grazing incidence (scan.GRAZING_MEMORY), keep the aligned pose within 8 cm
    of the truth all the way (0.062 m at the bound of 0.5, 0.037 m at 0.7), and the robot
    stops in the goal's tolerance. (Moved onto lines as the obstacles' are, bound 0.3,
    the alignment took the robot to have driven 1 % farther than it had: 0.13 m off at
    the goal, a miss.)"""
    from subapf_planner.sim.episode import run_episode
    from subapf_planner.sim.simulator import SimConfig
    from subapf_planner.sim.world import parse_world
    world = parse_world(_stepped_corridor())
    result = run_episode(world, PlannerConfig(), SimConfig(sensor='ideal'))
    assert str(result.outcome) == 'reached'
    assert result.odom_error.max() == 0.0 and result.pose_error.max() < 0.08


def disc(centre, radius=0.25, n=120):
    a = np.linspace(0, 2 * math.pi, n, endpoint=False)
    return np.column_stack((centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a)))


@pytest.mark.core
def test_one_mover_sized_thing_is_no_landmark_two_or_a_wall_are():
    """A person-sized disc is all the map holds near the robot (someone who walked
    slowly into the memory): its returns fit, but a match on them alone is refused, the
    prediction stands. Two such things, or a wall longer than a mover, are landmarks."""
    from subapf_planner.core.tracking import clusters
    true = np.array([0.0, 0.0, 0.0])
    off = true + [0.01, -0.01, 0.01]
    for walls, accepted in ((disc((0.5, 0.2)), False),
                            (np.vstack([disc((0.5, 0.2)), disc((-0.4, -0.5))]), True),
                            (segment((-1.5, 0.925), (1.5, 0.925)), True)):
        base = seen_from(walls, true, noise=0.0)
        g = grid_with(walls)
        field = distance_field(g.log_odds, g.origin, RES, to_parent(off, base), 0.4)
        m = align(base, off, field, clusters(base, 0.15)[0], 1.2)
        assert m.matched >= MIN_MATCHED
        assert m.accepted is accepted
        if not accepted:
            assert np.array_equal(m.pose, off)
    assert landmarks(np.zeros((30, 2)), np.zeros(30, np.int64), 1.2) == 1
    assert landmarks(np.zeros((7, 2)), np.zeros(7, np.int64), 1.2) == 0   # too few returns


@pytest.mark.core
def test_small_things_match_only_walls_that_have_stood_min_wall_age():
    """The grid notes the scan from which a cell has been established (three hits) and
    forgets it once misses leave it no longer occupied. The field tells which walls are
    young (established fewer than MIN_WALL_AGE ago: YOUNG scans at 5 Hz): the returns of
    a piece no longer than a mover match only older ones (a person who stood in the memory a few
    seconds is not a landmark), a wall's returns match at once."""
    from subapf_planner.core.tracking import clusters
    g = OccupancyGrid(RES, 20.0, hit_places=True)
    ranges = np.full(360, np.inf)
    ranges[0] = 1.0                                   # one return straight ahead
    scan = Scan(ranges, 0.0, math.radians(1.0), 0.12, 3.5)
    cell = tuple(g.cell_of([[1.0, 0.0]])[0])
    for _ in range(3):
        g.update(scan, (0.0, 0.0, 0.0))
    assert g.log_odds[cell] >= ESTABLISHED and g.established_at[cell] == 3
    for _ in range(YOUNG + 2):
        f = distance_field(g.log_odds, g.origin, RES, np.array([[1.0, 0.0]]), 0.4,
                           g.hit_offset, g.established_at, g.scans, YOUNG)
        assert f.lookup(np.array([[1.0, 0.0]]))[3][0] == (g.scans - 3 < YOUNG)
        g.update(scan, (0.0, 0.0, 0.0))
    ranges[0] = 2.0                                   # it went: beams now pass through
    for _ in range(10):
        g.update(Scan(ranges, 0.0, math.radians(1.0), 0.12, 3.5), (0.0, 0.0, 0.0))
    assert g.log_odds[cell] <= 0.0 and g.established_at[cell] == NOT_ESTABLISHED

    true = np.array([0.0, 0.0, 0.0])
    for walls, small in ((np.vstack([disc((0.5, 0.2)), disc((-0.4, -0.5))]), True),
                         (np.vstack([segment((-1.5, 0.925), (1.5, 0.925)),
                                     segment((-1.5, -0.925), (1.5, -0.925))]), False)):
        g = grid_with(walls)
        base = seen_from(walls, true, noise=0.0)
        pieces = clusters(base, 0.15)[0]
        for age in (YOUNG - 1, YOUNG):
            since = np.where(g.log_odds >= ESTABLISHED, 100 - age, NOT_ESTABLISHED)
            f = distance_field(g.log_odds, g.origin, RES, base, 0.4, None,
                               since.astype(np.int32), 100, YOUNG)
            m = align(base, true, f, pieces, 1.2)
            assert m.accepted is (not small or age >= YOUNG)


@pytest.mark.core
def test_a_walls_end_is_found_and_returns_beyond_it_do_not_pull():
    """The two end cells of a straight wall are its ends, none between; and a corridor
    known only up to x = 1 m, with a wall across behind the robot, seen from the true
    pose up to 3.5 m: the match stays at the truth (the returns beyond the known ends
    take no part)."""
    wall = np.zeros((5, 20), bool)
    wall[2, 3:15] = True
    normal = np.zeros((5, 20, 2))
    normal[..., 1] = 1.0
    cells = np.argwhere(wall)
    ends = cells[_ends(wall, normal[wall], np.zeros_like(wall))]          # unknown beyond
    assert not _ends(wall, normal[wall], ~wall).any()        # seen free beyond: a jamb
    assert sorted(map(tuple, ends)) == [(2, 3), (2, 14)]
    known = np.vstack([segment((-1.525, -0.625), (1.0, -0.625)),
                       segment((-1.525, 0.625), (1.0, 0.625)),
                       segment((-1.525, -0.625), (-1.525, 0.625))])
    seen = np.vstack([segment((-1.525, -0.625), (4.0, -0.625)),
                      segment((-1.525, 0.625), (4.0, 0.625)),
                      segment((-1.525, -0.625), (-1.525, 0.625))])
    true = np.array([0.0, 0.0, 0.0])
    m = match(grid_with(known), seen_from(seen, true, noise=0.0), true)
    assert m.accepted
    assert np.hypot(*(m.pose[:2] - true[:2])) < 0.004


@pytest.mark.core
def test_with_the_alignment_the_robot_stands_until_its_walls_hold_a_match():
    """The memory's frame is odom at the start: the robot stands (``mapping``, a stop)
    until the memory holds FIRST_SCANS scans and a scan has been matched to its walls, so
    that a first turn is matched as it is made and its drift is not drawn into the walls
    everything after is matched to; then it drives, and standing does not come back.
    Where the scan holds too few returns for a match it stands FIRST_SCANS scans, where
    its returns hold none (nothing stands still in them) MAPPING_TIME at most. Without
    the alignment it drives at once."""
    from subapf_planner.core.gates import FIRST_SCANS, MAPPING_TIME
    from subapf_planner.core.status import Status
    walls = room()
    period = 0.2
    rng = np.random.default_rng(3)
    for aligned, seen in ((True, 'room'), (True, 'nothing'), (True, 'shuffled'),
                          (False, 'room')):
        planner = Planner(PlannerConfig(scan_alignment=aligned, laser_x=0.0, laser_y=0.0,
                                        laser_yaw=0.0))
        statuses, matched = [], []
        for k in range(15):
            ranges = {'room': lambda: ranges_from(walls, (0.0, 0.0, 0.0)),
                      'nothing': lambda: np.full(360, np.inf),
                      'shuffled': lambda: rng.uniform(0.5, 3.0, 360)}[seen]()
            scan = Scan(ranges, 0.0, math.radians(1.0), 0.12, 3.5, period * (k + 1))
            r = planner.step(np.zeros(3), (2.0, -1.0), scan, now=period * (k + 1))
            statuses.append(r.command.status)
            matched.append(planner.aligned)
            if r.command.status is Status.MAPPING:
                assert (r.command.v, r.command.w) == (0.0, 0.0)
        mapping = [s is Status.MAPPING for s in statuses]
        if not aligned:
            assert not any(mapping)
            continue
        stood = mapping.index(False)
        assert not any(mapping[stood:])   # once over, never again
        if seen == 'room':   # walls established by three hits: the fourth scan matched
            assert stood > FIRST_SCANS and matched[stood] and not matched[stood - 1]
        else:
            assert not any(matched)
            assert stood == (FIRST_SCANS - 1 if seen == 'nothing'
                             else round(MAPPING_TIME / period))


@pytest.mark.core
def test_the_distance_field_looks_up_the_nearest_wall_cell():
    """DistanceField.lookup against brute force over the window's wall cells: for 400
    points in and around the window, the nearest wall point is the centre of a wall cell
    that is nearest to the point's cell (ties either way), its distance is to that point;
    points off the window have no wall (distance inf, not young)."""
    g = grid_with(room())
    around = np.array([[-1.0, -0.5], [1.5, 1.0]])
    f = distance_field(g.log_odds, g.origin, RES, around, 0.6)
    h, w = f.shape
    corner = f.origin
    rows, cols = np.nonzero(g.log_odds[...] >= ESTABLISHED)
    centres = g.origin + (np.column_stack((cols, rows)) + 0.5) * RES
    in_window = np.all((centres >= corner) & (centres < corner + np.array([w, h]) * RES),
                       axis=1)
    centres = centres[in_window]
    pts = np.random.default_rng(5).uniform(corner - 0.5, corner + np.array([w, h]) * RES
                                           + 0.5, (400, 2))
    near, normal, d, young = f.lookup(pts)
    cells = np.floor((pts - corner) / RES)
    inside = np.all((cells >= 0) & (cells < [w, h]), axis=1)
    assert 50 < inside.sum() < 400
    assert np.all(np.isinf(d[~inside])) and not young.any()
    cell_centres = corner + (cells[inside] + 0.5) * RES
    best = np.min(np.hypot(*(cell_centres[:, None] - centres[None]).transpose(2, 0, 1)),
                  axis=1)
    got = np.hypot(*(cell_centres - near[inside]).T)
    np.testing.assert_allclose(got, best, atol=1e-9)
    finite = np.isfinite(d[inside])   # (off a wall's open end: inf)
    np.testing.assert_allclose(d[inside][finite],
                               np.hypot(*(pts[inside] - near[inside]).T)[finite])
    np.testing.assert_allclose(np.hypot(*normal[inside].T), 1.0)
