"""The contact check (core/contact_check.py): the last command's rollout against the
scan's returns."""

import math

import numpy as np
import pytest

from subapf_planner.core.command import forward_blocked
from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.contact_check import closes_on, gaps
from subapf_planner.core.robot import ROBOTS

pytestmark = pytest.mark.core

CFG = PlannerConfig()
R = CFG.robot_radius


def test_turning_into_a_corner_beside_the_corridor_is_stopped():
    """A return just outside the corridor ahead, on the side the robot turns to: the
    corridor does not see it, the arc would touch it."""
    corner = np.array([[0.03, R + 0.01]])
    assert not forward_blocked((0.0, 0.0, 0.0), corner, CFG)
    assert closes_on((0.0, 0.0, 0.0), 0.2, 1.0, corner, CFG)
    # turning away from it, or driving straight past it at its distance, is not stopped
    assert not closes_on((0.0, 0.0, 0.0), 0.2, -1.0, corner, CFG)
    beside = np.array([[0.0, R + 0.01], [-0.05, R + 0.01]])
    assert not closes_on((0.0, 0.0, 0.0), 0.2, 0.0, beside, CFG)


def test_a_robot_close_to_a_wall_may_drive_away_but_not_into_it():
    wall = np.column_stack((np.linspace(-1.0, 1.0, 81), np.full(81, R + 0.005)))
    pose = (0.0, 0.0, 0.0)
    assert closes_on(pose, 0.2, 1.0, wall, CFG)        # turning towards it
    assert not closes_on(pose, 0.2, -1.0, wall, CFG)   # turning away
    assert not closes_on(pose, 0.0, 1.0, wall, CFG)    # a disc turns on the spot


@pytest.mark.parametrize('v, w', [(0.22, 0.0), (0.22, 1.5), (0.1, -2.0), (0.05, 0.5)])
def test_it_stops_exactly_where_the_rollout_comes_within_the_margin(v, w):
    """A return placed on the rollout at a gap below or above the margin."""
    t = CFG.contact_time
    yaw = w * t
    end = (np.array([math.sin(yaw), 1.0 - math.cos(yaw)]) * v / w) if w else np.array([v * t, 0.0])
    heading = np.array([math.cos(yaw), math.sin(yaw)])
    for gap, stops in ((CFG.contact_margin - 0.005, True), (CFG.contact_margin + 0.01, False)):
        point = end + heading * (R + gap)
        assert closes_on((0.0, 0.0, 0.0), v, w, point[None], CFG) == stops, (gap, point)


def test_a_polygon_is_checked_as_its_polygon():
    """The waffle's rectangle: a return beside its flank, inside its circumscribed disc,
    is no contact when driving straight along it, but the rectangle's front corner
    turning into it is."""
    cfg = PlannerConfig.for_robot(ROBOTS['waffle_pi'])
    shape = cfg.polygon
    side = np.array([[shape.front - 0.02, shape.half_width + 0.015]])
    assert gaps((0.0, 0.0, 0.0), side, cfg)[0, 0] == pytest.approx(0.015)
    assert np.hypot(*side[0]) < cfg.robot_radius
    assert not closes_on((0.0, 0.0, 0.0), 0.2, 0.0, side, cfg)
    assert closes_on((0.0, 0.0, 0.0), 0.2, 1.0, side, cfg)
