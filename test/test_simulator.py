"""The PyBullet burger stand-in: kinematics, lidar geometry, collisions, determinism."""

import math

import numpy as np
import pytest

from subapf_planner.core.robot import BURGER
from subapf_planner.sim.simulator import RobotSim, SimConfig
from subapf_planner.sim.world import parse_world

pytestmark = pytest.mark.sim


def world(obstacles=(), start=(0.0, 0.0, 0.0)):
    return parse_world({'name': 't', 'start': list(start), 'goal': [9.0, 9.0],
                        'obstacles': list(obstacles)})


def test_straight_drive_covers_v_times_t():
    with RobotSim(world()) as sim:
        for _ in range(25):
            sim.set_command(0.2, 0.0)
            sim.step(0.2)
        x, y, yaw = sim.true_pose()
    assert x == pytest.approx(1.0, rel=0.05)
    assert abs(y) < 0.02 and abs(yaw) < 0.02


def test_rotation_covers_w_times_t():
    with RobotSim(world()) as sim:
        for _ in range(5):
            sim.set_command(0.0, 1.0)
            sim.step(0.2)
        x, y, yaw = sim.true_pose()
    assert yaw == pytest.approx(1.0, rel=0.05)
    assert math.hypot(x, y) < 0.01


def test_lidar_range_to_known_box():
    box = {'box': {'center': [2.0, 0.0], 'size': [0.2, 2.0]}}
    with RobotSim(world([box]), SimConfig(sensor='ideal')) as sim:
        scan = sim.scan()
    face = 2.0 - 0.1 - BURGER.laser.x
    assert scan.ranges[0] == pytest.approx(face, abs=1e-3)
    # beam 10 deg off axis hits the same plane at face / cos(10 deg)
    assert scan.ranges[10] == pytest.approx(face / math.cos(math.radians(10)), abs=2e-3)
    assert np.isinf(scan.ranges[180])            # nothing behind
    assert scan.ranges.size == 360 and scan.angle_increment == pytest.approx(math.pi / 180)


def test_driving_into_a_wall_reports_collision():
    box = {'box': {'center': [1.0, 0.0], 'size': [0.2, 2.0]}}
    with RobotSim(world([box])) as sim:
        for _ in range(40):
            sim.set_command(0.2, 0.0)
            sim.step(0.2)
            if sim.collided:
                break
        assert sim.collided
        assert sim.true_pose()[0] == pytest.approx(0.9 - 0.105, abs=0.03)


def test_command_watchdog_stops_the_robot():
    with RobotSim(world(), SimConfig(cmd_timeout=0.5)) as sim:
        sim.set_command(0.2, 0.0)
        sim.step(2.0)
        x_after = sim.true_pose()[0]
        sim.step(1.0)
        assert sim.true_pose()[0] == pytest.approx(x_after, abs=0.01)
        assert x_after < 0.2   # about 0.5 s of driving, not 2 s


def test_same_seed_same_noise():
    cfg = SimConfig(range_noise=0.01, beam_dropout=0.1, seed=7)
    box = {'circle': {'center': [1.5, 0.0], 'radius': 0.3}}
    with RobotSim(world([box]), cfg) as a, RobotSim(world([box]), cfg) as b:
        np.testing.assert_array_equal(a.scan().ranges, b.scan().ranges)
    with RobotSim(world([box]), SimConfig(range_noise=0.01, seed=8)) as c:
        assert not np.array_equal(c.scan().ranges, a_ranges(cfg, box))


def a_ranges(cfg, box):
    with RobotSim(world([box]), cfg) as s:
        return s.scan().ranges


def test_bad_sim_config():
    with pytest.raises(ValueError, match='range_noise'):
        SimConfig(range_noise=-1.0)


def _drive(cfg, commands):
    """Run (v, w, seconds) commands; returns (true, odometry) poses after each 0.2 s."""
    true, odom = [], []
    with RobotSim(world(), cfg) as sim:
        for v, w, seconds in commands:
            for _ in range(int(round(seconds / 0.2))):
                sim.set_command(v, w)
                sim.step(0.2)
                true.append(sim.true_pose())
                odom.append(sim.odometry()[0])
    return np.array(true), np.array(odom)


def test_odometry_drift_grows_as_configured():
    """+2 % distance: odometry's distance from the start is 1.02 x the true one all along
    (the error grows with the distance); +3 % turn rate: its heading turns 1.03 x the
    true turn; with neither, odometry is the truth."""
    cfg = SimConfig(odom_distance_scale=1.02, odom_yaw_scale=1.03)
    true, odom = _drive(cfg, [(0.2, 0.0, 10.0)])
    d_true = np.hypot(*(true[:, :2] - true[0, :2]).T)[5:]
    d_odom = np.hypot(*(odom[:, :2] - odom[0, :2]).T)[5:]
    np.testing.assert_allclose(d_odom / d_true, 1.02, atol=2e-3)
    err = np.hypot(*(odom[:, :2] - true[:, :2]).T)
    assert err[-1] > 0.03 and err[-1] > 3 * err[len(err) // 4]        # it grows
    true, odom = _drive(cfg, [(0.0, 1.0, 4.0)])
    turned_true = np.unwrap(true[:, 2]) - true[0, 2]
    turned_odom = np.unwrap(odom[:, 2]) - odom[0, 2]
    assert turned_odom[-1] / turned_true[-1] == pytest.approx(1.03, abs=2e-3)
    true, odom = _drive(SimConfig(), [(0.2, 0.5, 4.0)])
    np.testing.assert_array_equal(true, odom)


def test_solver_iterations_reach_the_physics_engine():
    import pybullet
    for n in (50, 10):
        with RobotSim(world(), SimConfig(solver_iterations=n)) as sim:
            got = pybullet.getPhysicsEngineParameters(physicsClientId=sim._cid)
            assert got['numSolverIterations'] == n
    with pytest.raises(ValueError, match='solver_iterations'):
        SimConfig(solver_iterations=0)


def test_perfect_odometry_starts_at_the_start_and_then_is_the_true_pose():
    with RobotSim(world(start=(1.0, -2.0, 0.3)), SimConfig()) as sim:
        np.testing.assert_array_equal(sim.odometry()[0], [1.0, -2.0, 0.3])
        sim.set_command(0.2, 0.5)
        sim.step(0.4)
        np.testing.assert_array_equal(sim.odometry()[0], sim.true_pose())
        assert sim.odometry()[0][0] > 1.05


def test_scan_threads_change_the_speed_not_the_ranges():
    """rayTestBatch on one thread (subapf-bench's workers) and on all cores (the default)
    casts the same beams: a forest of cylinders and boxes seen from 12 places, equal to
    the bit, with at least 100 returns each."""
    rng = np.random.default_rng(3)
    obstacles = [{'circle': {'center': [float(x), float(y)], 'radius': 0.2}}
                 for x, y in rng.uniform(-3.0, 3.0, (25, 2)) if math.hypot(x, y) > 0.6]
    obstacles += [{'box': {'center': [0.0, 3.2], 'size': [6.0, 0.2], 'yaw': 0.3}}]
    sims = [RobotSim(world(obstacles), SimConfig(scan_threads=n, sensor='ideal'))
            for n in (1, 0)]
    try:
        for _ in range(12):
            for s in sims:
                s.set_command(0.2, 1.0)
                s.step(0.5)
            one, every = (s.scan().ranges for s in sims)
            assert np.count_nonzero(np.isfinite(one)) >= 100
            np.testing.assert_array_equal(one, every)
    finally:
        for s in sims:
            s.close()
