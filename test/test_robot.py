"""One robot description: the planner's defaults, the simulator, its URDF, the world
checks and the solvability check all say the same thing about the burger; frames."""

from importlib import resources
import math
import xml.etree.ElementTree as ET

from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.robot import BURGER, RobotDescription, compose, to_parent
from subapf_planner.core.scan import scan_to_points
from subapf_planner.sim import solvability, world
from subapf_planner.sim.simulator import ROBOT, BurgerSim, SimConfig
from subapf_planner.sim.world import parse_world

pytestmark = pytest.mark.sim


def test_planner_defaults_are_the_burger():
    cfg = PlannerConfig()
    assert cfg.laser_mount == BURGER.laser.planar
    assert (cfg.robot_radius, cfg.inflation_radius) == (BURGER.radius, BURGER.radius)
    assert cfg.sample_clearance == cfg.dwa_clearance == BURGER.clearance
    assert (cfg.max_linear_velocity, cfg.max_angular_velocity) == (
        BURGER.max_linear_velocity, BURGER.max_angular_velocity)
    assert PlannerConfig.for_robot(BURGER) == cfg


def test_a_config_for_another_robot_derives_its_clearances():
    big = RobotDescription('big', 0.2, BURGER.laser, 0.05, 0.3, 0.5, 1.5)
    cfg = PlannerConfig.for_robot(big, method='dwa')
    assert (cfg.robot_radius, cfg.inflation_radius) == (0.2, 0.2)
    assert cfg.sample_clearance == cfg.dwa_clearance == pytest.approx(0.23)
    assert (cfg.max_linear_velocity, cfg.method) == (0.5, 'dwa')


def test_simulator_world_and_solvability_use_the_same_robot():
    assert ROBOT is BURGER
    sim = SimConfig()
    assert (sim.max_linear_velocity, sim.max_angular_velocity) == (
        BURGER.max_linear_velocity, BURGER.max_angular_velocity)
    assert world.FOOTPRINT_RADIUS == BURGER.radius
    assert solvability.SOLVE_RADIUS == pytest.approx(BURGER.radius + 0.05, abs=1e-12)


def test_urdf_matches_the_description():
    urdf = resources.files('subapf_planner.sim') / 'urdf' / 'burger_standin.urdf'
    root = ET.fromstring(urdf.read_text())
    body = [c for c in root.iter('cylinder')
            if float(c.get('length')) > 0.05]   # the body, not the wheels
    assert [float(c.get('radius')) for c in body] == [BURGER.radius]
    wheels = {j.get('name'): [float(v) for v in j.find('origin').get('xyz').split()]
              for j in root.iter('joint')}
    left, right = wheels['wheel_left_joint'], wheels['wheel_right_joint']
    assert left[1] - right[1] == pytest.approx(BURGER.wheel_separation)
    assert left[2] == right[2] == pytest.approx(BURGER.wheel_radius)


def test_simulated_wall_lands_where_the_planners_mounting_puts_it():
    """A wall 2 m ahead seen by the simulator's laser and converted with the planner's
    default mounting lies on the wall (the ideal sensor, noise 0.01 m): the two agree on
    where the laser is. With the mounting off by 0.1 m the same points miss the wall by
    that much."""
    doc = {'name': 'wall', 'start': [0.0, 0.0, 0.3], 'goal': [1.0, 0.0],
           'obstacles': [{'box': {'center': [2.05, 0.0], 'size': [0.1, 6.0]}}]}
    w = parse_world(doc)
    with BurgerSim(w, SimConfig(seed=1, sensor='ideal',
                                range_noise=0.01)) as sim:
        sim.step(0.2)
        pose, scan = sim.true_pose(), sim.scan()
    ahead = np.abs(np.remainder(scan.angles + pose[2] + math.pi, 2 * math.pi) - math.pi) < 0.5
    scan_ahead = type(scan)(np.where(ahead, scan.ranges, np.inf), scan.angle_min,
                            scan.angle_increment, scan.range_min, scan.range_max)
    points = scan_to_points(scan_ahead, pose, PlannerConfig().laser_mount)
    assert len(points) > 40
    assert np.abs(points[:, 0] - 2.0).max() < 0.04
    shifted = scan_to_points(scan_ahead, pose, np.add(PlannerConfig().laser_mount, (0.1, 0, 0)))
    assert np.median(shifted[:, 0] - 2.0) == pytest.approx(0.1 * math.cos(pose[2]), abs=0.02)


poses = st.tuples(st.floats(-10, 10), st.floats(-10, 10), st.floats(-math.pi, math.pi))


@given(a=poses, b=poses, p=st.tuples(st.floats(-5, 5), st.floats(-5, 5)))
@settings(max_examples=200, deadline=None)
def test_compose_and_to_parent_agree(a, b, p):
    """A point in b's frame, taken to a's parent through b then a, lands where the
    composed pose a*b takes it; and to_parent of the origin is the pose's position."""
    through = to_parent(a, to_parent(b, [p]))
    direct = to_parent(compose(a, b), [p])
    np.testing.assert_allclose(through, direct, atol=1e-9)
    np.testing.assert_allclose(to_parent(a, [(0.0, 0.0)])[0], a[:2], atol=1e-12)


def test_chain_composes_the_links_from_the_base_to_the_leaf():
    from subapf_planner.core.robot import chain
    links = {'base_link': ('base_footprint', (0.0, 0.0, 0.0)),
             'base_scan': ('base_link', (-0.032, 0.0, 0.0)),
             'turned': ('base_scan', (0.1, 0.0, math.pi / 2)),
             'tip': ('turned', (0.1, 0.0, 3.0))}
    pose, frames = chain(links, 'base_footprint', 'base_scan')
    assert pose == pytest.approx((-0.032, 0.0, 0.0)) and frames == ['base_scan', 'base_link']
    (x, y, yaw), frames = chain(links, 'base_footprint', 'tip')
    assert (x, y) == pytest.approx((0.068, 0.1)) and yaw == pytest.approx(
        math.remainder(math.pi / 2 + 3.0, 2 * math.pi))
    assert frames == ['tip', 'turned', 'base_scan', 'base_link']
    assert chain(links, 'base_footprint', 'base_footprint') == ((0.0, 0.0, 0.0), [])
    assert chain(links, 'odom', 'base_scan') is None          # not connected
    assert chain({'a': ('b', (0, 0, 0)), 'b': ('a', (0, 0, 0))}, 'c', 'a') is None   # a loop
