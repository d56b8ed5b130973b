"""The realistic lidar (sim/sensor.py, the simulator's sweeps): noise that grows with
range as the datasheet says, dropped beams at random and in runs, mixed pixels at depth
edges, a sweep whose beams are taken at their own instants (bent when the robot
turns), and the faults between the sweep and the planner."""

import dataclasses
import math

import numpy as np
import pytest

from subapf_planner.core.robot import BURGER, compose, to_parent
from subapf_planner.core.scan import scan_to_points
from subapf_planner.sim.faults import ScanDelivery, ScanFaults, delivery_faults
from subapf_planner.sim.sensor import LIDARS, MIXED_EDGE, corrupt
from subapf_planner.sim.simulator import RobotSim, SimConfig
from subapf_planner.sim.world import parse_world

pytestmark = pytest.mark.sim

LDS01 = LIDARS['lds01']
#: The LDS-01's range errors alone: no dropped beams, no mixed pixels.
NOISE_ONLY = dataclasses.replace(LDS01, dropout=0.0, dark_runs=0.0, mixed_pixels=0.0)


def world(obstacles=(), start=(0.0, 0.0, 0.0)):
    return parse_world({'name': 't', 'start': list(start), 'goal': [9.0, 9.0],
                        'obstacles': list(obstacles)})


@pytest.mark.parametrize('r, sigma', [(0.3, 0.0075), (1.0, 0.025), (3.0, 0.075)])
def test_range_noise_grows_with_range_as_the_datasheet_says(r, sigma):
    """LDS-01: +/-15 mm below 0.5 m, +/-5 % from 0.5 to 3.5 m, taken as 2 sigma."""
    assert LDS01.sigma(np.array([r]))[0] == pytest.approx(sigma)
    rng = np.random.default_rng(1)
    out = corrupt(np.full(20000, r), NOISE_ONLY, rng)
    assert np.std(out - r) == pytest.approx(sigma, rel=0.05)
    assert abs(np.mean(out - r)) < 0.05 * sigma + 1e-4


def test_beams_are_dropped_at_random_and_in_runs():
    lidar = dataclasses.replace(LDS01, mixed_pixels=0.0)
    rng = np.random.default_rng(2)
    lost = np.concatenate([np.isinf(corrupt(np.full(360, 1.0), lidar, rng))
                           for _ in range(200)])
    expected = lidar.dropout + lidar.dark_runs * lidar.dark_run_length
    assert lost.mean() == pytest.approx(expected, rel=0.25)
    # runs: a lost beam's neighbour is lost far more often than the average beam
    after_lost = lost[1:][lost[:-1]].mean()
    assert after_lost > 5 * lost.mean()
    alone = dataclasses.replace(lidar, dark_runs=0.0)
    lost = np.isinf(corrupt(np.full(72000, 1.0), alone, rng))
    assert lost[1:][lost[:-1]].mean() == pytest.approx(alone.dropout, abs=0.01)


def test_mixed_pixels_fall_between_an_edge_and_what_lies_behind():
    """A post 1 m away in front of a wall 3 m away: beams at the post's edges return
    ranges between the two, and only there."""
    true = np.full(360, 3.0)
    true[170:190] = 1.0
    lidar = dataclasses.replace(NOISE_ONLY, mixed_pixels=1.0, bands=((10.0, 0.0, 0.0),))
    rng = np.random.default_rng(3)
    mixed = np.zeros(360, int)
    for _ in range(200):
        out = corrupt(true, lidar, rng)
        between = (out > 1.0 + 1e-9) & (out < 3.0 - 1e-9)
        mixed += between
    edges = {169, 170, 189, 190}
    assert set(np.flatnonzero(mixed)) == edges
    assert all(mixed[i] > 50 for i in edges)
    none = dataclasses.replace(lidar, mixed_pixels=0.0)
    assert np.array_equal(corrupt(true, none, rng), true)
    assert 3.0 - 1.0 > MIXED_EDGE


def _room():
    """A closed 4 x 4 m room around the origin."""
    walls = [((0.0, 2.05), (4.2, 0.1)), ((0.0, -2.05), (4.2, 0.1)),
             ((2.05, 0.0), (0.1, 4.2)), ((-2.05, 0.0), (0.1, 4.2))]
    return world([{'box': {'center': list(c), 'size': list(s)}} for c, s in walls])


def _off_walls(points):
    """Each point's distance to the room's inner walls (|x| = 2 or |y| = 2) [m]."""
    return np.min(np.abs(np.abs(points) - 2.0), axis=1)


def test_a_lidar_with_less_than_a_turn_sees_its_field_of_view_only():
    """The Jackal's LMS111: 541 beams from -135 to +135 degrees, 50 sweeps a second, each
    taken over its 20 ms; a wall right behind the robot is not in them, one ahead is. The
    mixed pixels do not join the first beam to the last (they are no neighbours)."""
    doc = {'name': 'behind', 'start': [0.0, 0.0, 0.0], 'goal': [1.0, 0.0],
           'obstacles': [{'box': {'center': [-1.5, 0.0], 'size': [0.1, 1.0]}},
                         {'box': {'center': [2.0, 0.0], 'size': [0.1, 6.0]}}]}
    with RobotSim(parse_world(doc), SimConfig(robot='jackal', seed=3)) as sim:
        sim.step(0.2)
        sweeps = sim.sweeps()
    assert len(sweeps) == 10
    scan = sweeps[-1]
    assert scan.ranges.size == 541 and scan.scan_time == pytest.approx(0.02)
    assert scan.angle_min == pytest.approx(-0.75 * math.pi)
    assert scan.angles[-1] == pytest.approx(0.75 * math.pi)
    points = scan_to_points(scan, (0.0, 0.0, 0.0), (0.12, 0.0, 0.0))
    assert len(points) > 200 and points[:, 0].min() > 1.8   # nothing of the wall behind
    ahead = np.abs(points[:, 1]) < 0.5
    assert np.abs(points[ahead, 0] - 1.95).max() < 0.1
    lidar = LIDARS['lms111']
    edge = np.r_[np.full(270, 1.0), np.full(271, 5.0)]   # near on the right, far on the left
    for seed in range(20):
        out = corrupt(edge, dataclasses.replace(lidar, dropout=0.0, dark_runs=0.0,
                                                mixed_pixels=1.0, bands=((20.0, 0.0, 0.0),)),
                      np.random.default_rng(seed))
        assert out[0] == 1.0 and out[-1] == 5.0   # not mixed across the blind sector


def test_a_turning_robots_sweep_is_bent_and_each_beams_own_pose_unbends_it(monkeypatch):
    """Turning at 2 rad/s, the sweep's beams are taken over 0.2 s: placed at the pose
    of the sweep's first beam, the late beams miss the walls by decimetres; placed at
    the pose of their own instant (the truth, recorded while stepping), they lie on
    them within 5 mm: the simulator casts each beam from where the laser was at its
    instant, not at the physics step after it. With the ideal sensor every beam is taken
    at once."""
    import subapf_planner.sim.simulator as simulator
    exact = dataclasses.replace(NOISE_ONLY, bands=((10.0, 0.0, 0.0),))
    monkeypatch.setattr(simulator, 'LIDARS', {**LIDARS, 'lds01': exact})   # timing alone
    with RobotSim(_room(), SimConfig(sensor='realistic', lidar='lds01')) as sim:
        poses = {0.0: sim.true_pose()}
        for _ in range(100):   # 0.5 s: whole sweeps in the middle of the turn
            sim.set_command(0.0, 2.0)
            sim.step(0.005)
            poses[round(sim.time, 6)] = sim.true_pose()
        sweeps = sim.sweeps()
    sweep = next(s for s in sweeps if s.stamp > 0.1)   # (the first starts standing)
    assert sweep.time_increment == pytest.approx(0.2 / 360)
    assert sweep.scan_time == pytest.approx(0.2)
    at_start = scan_to_points(sweep, poses[round(sweep.stamp, 6)], BURGER.laser.planar)
    ok = np.isfinite(sweep.ranges)
    instants = [sweep.stamp + i * sweep.time_increment for i in range(360)]
    times = np.array(sorted(poses))
    track = np.array([poses[t] for t in times])
    track[:, 2] = np.unwrap(track[:, 2])

    def at(t):   # the true pose at instant t, between the recorded steps
        return [np.interp(t, times, track[:, k]) for k in range(3)]
    own = np.array([to_parent(compose(at(ti), BURGER.laser.planar),
                              [[r * math.cos(a), r * math.sin(a)]])[0]
                    for ti, r, a in zip(instants, sweep.ranges, sweep.angles, strict=True)])
    late = np.arange(360)[ok] > 300
    assert np.max(_off_walls(own[ok])) < 0.005   # each beam at its own instant
    assert np.median(_off_walls(at_start[late])) > 0.1
    with RobotSim(_room(), SimConfig(sensor='ideal')) as sim:
        sim.set_command(0.0, 2.0)
        sim.step(0.4)
        ideal = sim.sweeps()
    assert ideal and all(s.time_increment == 0.0 for s in ideal)


def test_the_lidar_latency_jitter_and_losses_come_on_top_of_the_faults():
    cfg = SimConfig(sensor='realistic')
    f = delivery_faults(cfg, ScanFaults(scan_dropout=0.2, scan_latency=0.1))
    assert f.scan_latency == pytest.approx(LDS01.latency + 0.1)
    assert f.scan_dropout == pytest.approx(1 - (1 - LDS01.scan_loss) * 0.8)
    assert delivery_faults(SimConfig(sensor='ideal'), ScanFaults()) == ScanFaults()
    d = ScanDelivery(ScanFaults(scan_latency=0.05, scan_jitter=0.02), seed=4)
    for k in range(200):
        d.capture(k, 0.2 * k)
    arrived, t = [], 0.0
    while len(arrived) < 200 and t < 100.0:
        arrived += [(k, t) for k in d.due(t)]
        t += 0.001
    assert [k for k, _ in arrived] == list(range(200))          # in order
    delays = np.array([t - 0.2 * k for k, t in arrived])
    assert delays.min() >= 0.05 - 1e-3 and 0.055 < delays.mean() < 0.08


def _square_ranges(poses, angles, half=2.0):
    """Ranges from laser poses (n, 3) along beam angles (n,) to the walls |x|, |y| = half."""
    a = poses[:, 2] + angles
    c, s = np.cos(a), np.sin(a)
    with np.errstate(divide='ignore', invalid='ignore'):
        tx = np.where(c > 0, (half - poses[:, 0]) / c, (-half - poses[:, 0]) / c)
        ty = np.where(s > 0, (half - poses[:, 1]) / s, (-half - poses[:, 1]) / s)
    return np.minimum(np.where(np.isfinite(tx) & (tx > 0), tx, np.inf),
                      np.where(np.isfinite(ty) & (ty > 0), ty, np.inf))


@pytest.mark.core
@pytest.mark.parametrize('motion', [(0.0, 0.0, 0.5), (0.04, 0.0, 0.3), (0.04, 0.0, -0.5)])
def test_deskew_puts_a_bent_sweep_back_on_the_walls(motion):
    """A sweep of 360 beams whose laser turns and drives by ``motion`` (x, y, yaw)
    between its first beam and its last (a constant twist): placed at the first beam's
    pose as it is, its late returns miss the walls of the square room by decimetres;
    de-skewed with the motion (core/scan.py deskew), every return is within 2.5 cm of a
    wall (its new beam's direction is off by half a beam at most: 0.5 degrees at the
    corners' 2.8 m), and the median within 5 mm; keeping the bearings, every return is
    back on its wall, in the order of its beams."""
    from subapf_planner.core.scan import Scan, deskew
    n = 360
    f = np.arange(n) / (n - 1)
    m = np.asarray(motion)
    poses = np.column_stack((f * m[0], f * m[1], f * m[2]))   # the laser, base = laser
    angles = 2 * math.pi * np.arange(n) / n
    scan = Scan(_square_ranges(poses, angles), 0.0, 2 * math.pi / n, 0.1, 10.0, 0.0,
                0.2 / n, 0.2)
    bent = scan_to_points(scan, (0.0, 0.0, 0.0))
    assert np.percentile(_off_walls(bent), 95) > 0.1
    straight = deskew(scan, m)
    pts = scan_to_points(straight, (0.0, 0.0, 0.0))
    assert len(pts) > 0.9 * n and straight.bearings is None
    assert np.max(_off_walls(pts)) < 0.025 and np.median(_off_walls(pts)) < 0.005
    assert straight.time_increment == scan.time_increment and straight.stamp == scan.stamp
    assert deskew(scan, np.zeros(3)) is scan
    exact = deskew(scan, m, bearings=True)
    pts = scan_to_points(exact, (0.0, 0.0, 0.0))
    assert len(pts) == n and np.max(_off_walls(pts)) < 1e-9
    assert np.all(np.abs(np.diff(np.unwrap(exact.angles))) < 2 * scan.angle_increment)
    assert deskew(exact, m, bearings=True) is exact   # de-skewed once


@pytest.mark.core
def test_a_sweep_across_pi_is_deskewed_with_its_small_turn():
    """A robot heading along -x turns 0.3 rad through +-pi during a sweep: odometry's
    yaw jumps from near +pi to near -pi between two poses. The loop's sweep motion is
    the 0.3 rad turn (compose's yaw in [-pi, pi]), not 0.3 - 2 pi, and the de-skewed
    sweep lies on the square room's walls. Found in the static dev suite: with the
    whole turn, de-skewing smeared every return round the robot, the memory drew walls
    across open floor there and the run ended ``unreachable``."""
    from subapf_planner.core.config import PlannerConfig
    from subapf_planner.core.loop import DecisionLoop
    from subapf_planner.core.scan import Scan
    n = 360
    yaw0, turn = math.pi - 0.15, 0.3
    f = np.arange(n) / (n - 1)
    poses = np.column_stack((np.zeros(n), np.zeros(n), yaw0 + f * turn))
    angles = 2 * math.pi * np.arange(n) / n
    scan = Scan(_square_ranges(poses, angles), 0.0, 2 * math.pi / n, 0.1, 10.0, 1.0,
                0.2 / n, 0.2)
    ctl = DecisionLoop(PlannerConfig(laser_x=0.0, laser_y=0.0, laser_yaw=0.0))
    for k in range(6):   # odometry at 25 Hz over the sweep, its yaw in (-pi, pi]
        t = 1.0 + 0.04 * k
        ctl.update_odom(t, np.array([0.0, 0.0, math.remainder(yaw0 + turn * (t - 1.0) / 0.2,
                                                                2 * math.pi)]), t)
    motion = ctl.sweep_motion(scan)
    assert motion[2] == pytest.approx(turn * (n - 1) / n, abs=1e-6)
    straight, _, _ = ctl._deskewed(scan)
    pts = scan_to_points(straight, (0.0, 0.0, yaw0))
    assert len(pts) > 0.9 * n
    assert np.median(_off_walls(pts)) < 0.005 and np.percentile(_off_walls(pts), 95) < 0.025


@pytest.mark.core
def test_denoise_averages_along_a_surface_and_keeps_edges_and_lone_returns():
    """denoise: a wall 2 m ahead through the LDS-01's noise (5 cm sigma there) is left
    with under half of it; a box in front of the wall keeps its edge (no beam is pulled
    between the two surfaces), and a lone return between them (a mixed pixel) stays."""
    from subapf_planner.core.scan import Scan, denoise
    n = 360
    angles = np.radians(np.arange(n))
    rng = np.random.default_rng(3)
    truth = np.full(n, np.inf)
    front = (angles > np.radians(-60) + 2 * math.pi) | (angles < np.radians(60))
    truth[front] = 2.0 / np.cos(np.where(angles[front] > math.pi, angles[front] - 2 * math.pi,
                                         angles[front]))
    box = (angles > np.radians(10)) & (angles < np.radians(30))
    truth[box] = 1.0
    sigma = 0.025 * np.where(np.isfinite(truth), truth, 0.0)
    noisy = truth + rng.normal(0.0, 1.0, n) * sigma
    noisy[np.radians(40).round(3) == angles.round(3)] = 1.5   # a lone return
    scan = Scan(noisy, 0.0, math.radians(1.0), 0.12, 3.5)
    out = denoise(scan, 0.0075, 0.025).ranges
    wall = front & ~box & np.isfinite(truth) & (truth < 3.4)
    wall &= ~np.isin(np.arange(n), [9, 10, 11, 29, 30, 31, 39, 40, 41])   # next to edges
    before = np.std(noisy[wall] - truth[wall])
    assert np.std(out[wall] - truth[wall]) < 0.5 * before
    assert np.all(np.abs(out[box] - 1.0) < 0.1) and np.all(out[wall] > 1.5)   # edges kept
    assert out[40] == 1.5                                           # the lone return
    assert np.array_equal(np.isfinite(out), np.isfinite(noisy))     # no return stays none
    assert denoise(scan, 0.0, 0.0) is scan                          # no noise: as it is


@pytest.mark.sim
def test_a_static_cluttered_field_through_the_realistic_lidar_has_no_moving_track():
    """The shipped cluttered field (posts and boxes, nothing moving) through the LDS-01's
    noise, dropped beams and mixed pixels: the robot reaches the goal and never evades;
    no cycle takes a piece of the clutter for a mover."""
    from subapf_planner.core.config import PlannerConfig
    from subapf_planner.ros.paths import shipped_worlds_dir
    from subapf_planner.sim.episode import run_episode
    from subapf_planner.sim.world import load_world
    world = load_world(shipped_worlds_dir() / 'cluttered_field.yaml')
    result = run_episode(world, PlannerConfig(), SimConfig(sensor='realistic', seed=4))
    assert str(result.outcome) == 'reached'
    assert result.statuses.get('evading', 0) == 0, result.statuses
