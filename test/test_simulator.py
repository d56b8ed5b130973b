"""The PyBullet burger stand-in: kinematics, lidar geometry, collisions, determinism."""

import math

import numpy as np
import pytest

from subapf_planner.sim.simulator import ROBOT, BurgerSim, SimConfig
from subapf_planner.sim.world import parse_world

pytestmark = pytest.mark.sim


def world(obstacles=(), start=(0.0, 0.0, 0.0)):
    return parse_world({'name': 't', 'start': list(start), 'goal': [9.0, 9.0],
                        'obstacles': list(obstacles)})


def test_straight_drive_covers_v_times_t():
    with BurgerSim(world()) as sim:
        for _ in range(25):
            sim.set_command(0.2, 0.0)
            sim.step(0.2)
        x, y, yaw = sim.true_pose()
    assert x == pytest.approx(1.0, rel=0.05)
    assert abs(y) < 0.02 and abs(yaw) < 0.02


def test_rotation_covers_w_times_t():
    with BurgerSim(world()) as sim:
        for _ in range(5):
            sim.set_command(0.0, 1.0)
            sim.step(0.2)
        x, y, yaw = sim.true_pose()
    assert yaw == pytest.approx(1.0, rel=0.05)
    assert math.hypot(x, y) < 0.01


def test_lidar_range_to_known_box():
    box = {'box': {'center': [2.0, 0.0], 'size': [0.2, 2.0]}}
    with BurgerSim(world([box]), SimConfig(range_noise=0.0)) as sim:
        scan = sim.scan()
    face = 2.0 - 0.1 - ROBOT.laser.x
    assert scan.ranges[0] == pytest.approx(face, abs=1e-3)
    # beam 10 deg off axis hits the same plane at face / cos(10 deg)
    assert scan.ranges[10] == pytest.approx(face / math.cos(math.radians(10)), abs=2e-3)
    assert np.isinf(scan.ranges[180])            # nothing behind
    assert scan.ranges.size == 360 and scan.angle_increment == pytest.approx(math.pi / 180)


def test_driving_into_a_wall_reports_collision():
    box = {'box': {'center': [1.0, 0.0], 'size': [0.2, 2.0]}}
    with BurgerSim(world([box])) as sim:
        for _ in range(40):
            sim.set_command(0.2, 0.0)
            sim.step(0.2)
            if sim.collided:
                break
        assert sim.collided
        assert sim.true_pose()[0] == pytest.approx(0.9 - 0.105, abs=0.03)


def test_command_watchdog_stops_the_robot():
    with BurgerSim(world(), SimConfig(cmd_timeout=0.5)) as sim:
        sim.set_command(0.2, 0.0)
        sim.step(2.0)
        x_after = sim.true_pose()[0]
        sim.step(1.0)
        assert sim.true_pose()[0] == pytest.approx(x_after, abs=0.01)
        assert x_after < 0.2   # about 0.5 s of driving, not 2 s


def test_same_seed_same_noise():
    cfg = SimConfig(range_noise=0.01, beam_dropout=0.1, seed=7)
    box = {'circle': {'center': [1.5, 0.0], 'radius': 0.3}}
    with BurgerSim(world([box]), cfg) as a, BurgerSim(world([box]), cfg) as b:
        np.testing.assert_array_equal(a.scan().ranges, b.scan().ranges)
    with BurgerSim(world([box]), SimConfig(range_noise=0.01, seed=8)) as c:
        assert not np.array_equal(c.scan().ranges, a_ranges(cfg, box))


def a_ranges(cfg, box):
    with BurgerSim(world([box]), cfg) as s:
        return s.scan().ranges


def test_bad_sim_config():
    with pytest.raises(ValueError, match='range_noise'):
        SimConfig(range_noise=-1.0)
