"""Circular sampling (Algorithm 1, Fig. 5) and the APF step."""

import math

from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest

from subapf_planner.core.apf import apf_force, apf_step
from subapf_planner.core.command import shape_command
from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.critics.priority import priority_applies
from subapf_planner.core.planner import local_radius, plan
from subapf_planner.core.sampling import circle_samples, clearance, sample_and_choose
from subapf_planner.core.scan import voxel_downsample
from subapf_planner.core.status import Status

pytestmark = pytest.mark.core

CFG = PlannerConfig()
PAPER = PlannerConfig(attraction_field='euclidean')
coords = st.floats(-3.0, 3.0, allow_nan=False)
obstacle_sets = arrays(np.float64, st.tuples(st.integers(0, 40), st.just(2)), elements=coords)


def test_samples_start_towards_goal_and_go_clockwise():
    s = circle_samples([0, 0], [0, 5], 8, 1.0)
    np.testing.assert_allclose(s[0], [0, 1], atol=1e-12)
    np.testing.assert_allclose(s[2], [1, 0], atol=1e-12)   # clockwise: north, then east
    np.testing.assert_allclose(np.hypot(*s.T), 1.0)


@pytest.mark.parametrize('cfg', [CFG, PAPER], ids=['default', 'paper'])
@given(obs=obstacle_sets, px=coords, py=coords, gx=coords, gy=coords)
@settings(max_examples=300, deadline=None)
def test_chosen_point_never_within_the_discard_distance(cfg, obs, px, py, gx, gy):
    """Algorithm 1: d0 in the paper's method, sample_clearance with the geodesic field."""
    assert cfg.discard_distance == (cfg.sample_clearance if cfg is CFG else cfg.danger_distance)
    pos = np.array([px, py])
    raw = apf_step(pos, [gx, gy], obs, cfg)[0]
    res = sample_and_choose(raw, pos, [gx, gy], obs, obs, cfg)
    if res.chosen is not None:
        assert clearance(res.chosen, obs)[0] > cfg.discard_distance
    else:
        assert np.all(clearance(res.samples, obs) <= cfg.discard_distance)
    assert np.all(np.isinf(res.scores[res.clearance <= cfg.discard_distance]))


def test_all_samples_in_danger_gives_no_choice():
    # a dense ring of obstacles 0.1 m around the robot: every sample is inside d0
    a = np.linspace(0, 2 * np.pi, 90, endpoint=False)
    ring = 0.1 * np.column_stack((np.cos(a), np.sin(a)))
    res = sample_and_choose([0, 0], [0, 0], [3, 0], ring, ring, CFG)
    assert res.chosen is None and res.chosen_index == -1
    assert np.all(np.isinf(res.scores))


def test_free_space_chooses_the_goal_ward_sample():
    res = sample_and_choose([0, 0.1], [0, 0], [0, 5], np.zeros((0, 2)), np.zeros((0, 2)), CFG)
    assert res.chosen_index == 0 and res.priority_index == -1


def test_priority_slides_clockwise_along_a_wall():
    """Robot below a wall, goal behind it: the bonus sample moves round (east), not into it."""
    wall = np.column_stack((np.linspace(-2, 2, 81), np.full(81, 0.45)))
    pos = np.array([0.0, 0.0])
    goal = np.array([0.0, 3.0])
    assert priority_applies(pos, goal, [0.0, 0.45], CFG)
    raw = apf_step(pos, goal, wall, CFG)[0]
    res = sample_and_choose(raw, pos, goal, wall, wall, CFG)
    assert res.priority_index > 0
    chosen = res.chosen
    assert chosen[0] > raw[0] + 0.5 * CFG.sample_radius          # east: clockwise from north
    assert clearance(chosen, wall)[0] >= clearance(raw, wall)[0] - 0.1 * CFG.sample_radius


def test_priority_not_applied_when_obstacle_beside_the_way():
    assert not priority_applies([0, 0], [0, 3], [0.5, 0.0], CFG)     # 90 deg off the goal
    assert not priority_applies([0, 0], [0, 3], [0.0, 2.0], CFG)     # farther than d


def test_apf_step_limits():
    obs = np.array([[0.0, 0.02]])
    step = apf_step([0, 0], [0, 5], obs, CFG.replace(method='traditional'))[0]
    assert np.hypot(*step) <= CFG.max_step + 1e-12
    near_goal = apf_step([0, 0], [0.01, 0], np.zeros((0, 2)), CFG)[0]
    assert np.hypot(*(near_goal - [0.01, 0])) < 1e-9   # never past the goal


@given(px=coords, py=coords)
@settings(max_examples=50, deadline=None)
def test_force_is_attractive_without_obstacles(px, py):
    f = apf_force([px, py], [1.0, 1.0], np.zeros((0, 2)), CFG)[0]
    d = np.array([1.0 - px, 1.0 - py])
    if np.hypot(*d) > 1e-6:
        assert np.dot(f, d) > 0
        assert np.hypot(*f) == pytest.approx(CFG.attraction_gain)  # conic: constant pull


def test_inputs_not_mutated():
    obs = np.random.default_rng(0).uniform(-1, 1, (30, 2))
    obs0 = obs.copy()
    pos = np.array([0.0, 0.0])
    sample_and_choose(apf_step(pos, [2, 2], obs, CFG)[0], pos, [2, 2], obs, obs, CFG)
    np.testing.assert_array_equal(obs, obs0)
    assert pos.tolist() == [0.0, 0.0]
    assert math.isinf(clearance([0, 0], np.zeros((0, 2)))[0])


@pytest.mark.parametrize('cfg', [CFG, PAPER, PAPER.replace(repulsion_mode='sum'),
                                 PAPER.replace(method='traditional', influence_distance=0.3)],
                         ids=['default', 'paper', 'sum', 'traditional'])
@given(seed=st.integers(0, 2**31 - 1), yaw=st.floats(-math.pi, math.pi),
       gx=coords, gy=coords)
@settings(max_examples=150, deadline=None)
def test_points_beyond_the_local_radius_change_nothing(cfg, seed, yaw, gx, gy):
    """plan() skips obstacle points farther than local_radius() from the robot; the cycle
    computed on every point (what it skips included) gives the same command."""
    rng = np.random.default_rng(seed)
    radius = local_radius(cfg)
    # points on both sides of the local radius, and a few near the robot
    ring = rng.uniform(radius - 0.4, radius + 0.4, 120)
    angle = rng.uniform(-math.pi, math.pi, ring.size)
    obs = np.vstack([np.column_stack((ring * np.cos(angle), ring * np.sin(angle))),
                     rng.uniform(-1.2, 1.2, (rng.integers(0, 12), 2))])
    obs = obs[np.hypot(*obs.T) > 0.2]
    pose, goal = np.array([0.0, 0.0, yaw]), np.array([gx, gy])
    result = plan(cfg, pose, goal, obs)
    repulsors = voxel_downsample(obs, cfg.voxel_size)
    raw = apf_step(pose[:2], goal, repulsors, cfg)[0]
    target = raw
    if result.command.status in (Status.GOAL_IN_OBSTACLE, Status.REACHED):
        return   # the goal gates (test_command.py), not the local plan
    if cfg.method == 'subharmonic_sampling':
        sampling = sample_and_choose(raw, pose[:2], goal, obs, repulsors, cfg)
        target = sampling.chosen
        np.testing.assert_allclose(result.sampling.scores, sampling.scores, rtol=0, atol=1e-12)
        assert result.sampling.priority_index == sampling.priority_index
    expected = shape_command(pose, target, goal, (0.0, 0.0), obs, cfg)
    np.testing.assert_allclose(result.raw_point, raw, rtol=0, atol=1e-12)
    if target is None:
        assert result.chosen_point is None
    else:
        np.testing.assert_allclose(result.chosen_point, target, rtol=0, atol=1e-12)
    assert result.command.status == expected.status
    assert result.command.v == pytest.approx(expected.v, abs=1e-9)
    assert result.command.w == pytest.approx(expected.w, abs=1e-9)
