"""Command shaping for the differential drive."""

import math

import numpy as np
import pytest

from subapf_planner.core.command import forward_blocked, shape_command
from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.planner import plan

pytestmark = pytest.mark.core

CFG = PlannerConfig()
NONE = np.zeros((0, 2))


def test_goal_reached_is_a_gate_before_the_command():
    """Within the tolerance the planner stops with ``reached`` whatever the obstacles (the
    goal gate, core/planner.py), even with a laser point on the goal itself."""
    for obstacles in (NONE, np.array([[0.1, 0.0]])):
        r = plan(CFG, (0, 0, 0), (0.1, 0), obstacles, (0.2, 0))
        assert (r.command.v, r.command.w, r.command.status) == (0.0, 0.0, 'reached')
    # just outside it the same goal is driven to, or refused when a point lies on it
    assert plan(CFG, (0, 0, 0), (0.16, 0), NONE, (0.2, 0)).command.status == 'driving'
    assert plan(CFG, (0, 0, 0), (0.16, 0), np.array([[0.16, 0.0]])).command.status == \
        'goal_in_obstacle'


def test_no_safe_move_stops():
    c = shape_command((0, 0, 0), None, (3, 0), (0.2, 0.5), NONE, CFG)
    assert (c.v, c.w, c.status) == (0.0, 0.0, 'no_safe_move')


def test_rotate_in_place_when_target_behind():
    c = shape_command((0, 0, 0), (-0.05, 0.001), (-3, 0), (0.0, 0.0), NONE, CFG)
    assert c.v == 0.0 and c.status == 'turning' and c.w > 0


def test_limits_and_acceleration():
    c = shape_command((0, 0, 0), (1.0, 0.0), (5, 0), (0.0, 0.0), NONE, CFG)
    assert c.v == pytest.approx(CFG.max_linear_acceleration * CFG.period)
    c = shape_command((0, 0, 0), (1.0, 0.0), (5, 0), (0.22, 0.0), NONE, CFG)
    assert c.v == pytest.approx(CFG.max_linear_velocity)
    c = shape_command((0, 0, 0), (0.0, 1.0), (0, 5), (0.0, 2.84), NONE, CFG)
    assert abs(c.w) <= CFG.max_angular_velocity


def test_slowdown_near_goal():
    far = shape_command((0, 0, 0), (0.1, 0), (3.0, 0), (0.22, 0), NONE, CFG)
    near = shape_command((0, 0, 0), (0.1, 0), (0.2, 0), (0.22, 0), NONE, CFG)
    assert near.v < far.v


def test_forward_corridor_blocks_only_ahead():
    ahead = np.array([[0.15, 0.05]])        # within safety_distance (0.18 m) of the centre
    assert not forward_blocked((0, 0, 0), np.array([[0.2, 0.05]]), CFG)   # beyond it
    beside = np.array([[0.0, 0.2]])
    behind = np.array([[-0.15, 0.0]])
    assert forward_blocked((0, 0, 0), ahead, CFG)
    assert not forward_blocked((0, 0, 0), beside, CFG)
    assert not forward_blocked((0, 0, 0), behind, CFG)
    assert forward_blocked((1, 1, math.pi / 2), ahead[:, ::-1] + 1, CFG)
    c = shape_command((0, 0, 0), (0.1, 0.0), (3, 0), (0.2, 0), ahead, CFG)
    assert c.v == 0.0 and c.status == 'blocked_ahead'
