"""Arrival (core/gates.py, arrival_distance; core/approach.py, final_approach): inside
goal_tolerance the default drives on towards the goal itself while a cycle still brings
it closer, so that a pose error of a few centimetres leaves the robot inside the
tolerance; the paper's method stops on entering it."""

import math

import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.planner import Planner
from subapf_planner.core.scan import Scan
from subapf_planner.core.status import Status

pytestmark = pytest.mark.core

OPEN = np.full(360, np.inf)   # nothing in range


def step(planner, pose, goal, k):
    return planner.step(np.asarray(pose, float), goal,
                        Scan(OPEN, 0.0, 2 * math.pi / 360, 0.12, 3.5, float(k)),
                        now=float(k))


def test_inside_the_tolerance_it_drives_on_while_it_gets_closer():
    cfg = PlannerConfig()
    planner = Planner(cfg)
    goal = (1.0, 0.0)
    res = step(planner, (1.0 - 0.12, 0.0, 0.0), goal, 0)     # inside the tolerance
    assert 0.12 < cfg.goal_tolerance
    assert res.command.status is not Status.REACHED and res.command.v > 0.0
    res = step(planner, (1.0 - 0.11, 0.0, 0.0), goal, 1)     # 1 cm closer: on
    assert res.command.status is not Status.REACHED and res.command.v > 0.0
    res = step(planner, (1.0 - 0.11, 0.0, 0.0), goal, 2)     # no closer: there
    assert res.command.status is Status.REACHED and res.command.v == 0.0
    res = step(planner, (1.0 - 0.005, 0.0, 0.0), goal, 3)    # within arrival_distance
    assert 0.005 < cfg.arrival_distance and res.command.status is Status.REACHED


def test_a_few_cycles_without_progress_do_not_end_the_approach():
    """Turning towards a goal a few centimetres off the robot's axis brings it no closer
    for a cycle or two: the approach goes on for ARRIVAL_PATIENCE without getting closer,
    then ends; any progress restarts the wait."""
    from subapf_planner.core.gates import ARRIVAL_PATIENCE
    planner = Planner(PlannerConfig())
    goal = (1.0, 0.0)

    def at(distance, t):
        return planner.step(np.array([1.0 - distance, 0.0, 0.0]), goal,
                            Scan(OPEN, 0.0, 2 * math.pi / 360, 0.12, 3.5, t), now=t)

    t = 0.0
    assert at(0.12, t).command.status is not Status.REACHED
    while t + 0.2 < ARRIVAL_PATIENCE - 1e-9:                     # no closer, 0.8 s
        t += 0.2
        assert at(0.12, t).command.status is not Status.REACHED
    t += 0.2
    assert at(0.10, t).command.status is not Status.REACHED      # 2 cm closer: on
    t += ARRIVAL_PATIENCE
    assert at(0.10, t).command.status is Status.REACHED          # no closer for 1 s


def test_a_new_goal_starts_a_new_approach():
    planner = Planner(PlannerConfig())
    step(planner, (0.88, 0.0, 0.0), (1.0, 0.0), 0)
    step(planner, (0.89, 0.0, 0.0), (1.0, 0.0), 1)
    res = step(planner, (0.89, 0.0, 0.0), (1.0, 0.01), 2)    # another goal, no closer
    assert res.command.status is not Status.REACHED


@pytest.mark.parametrize('cfg', [PlannerConfig(arrival_distance=0.15),
                                 PlannerConfig(method='subharmonic_sampling',
                                               attraction_field='euclidean')],
                         ids=['arrival at the tolerance', 'paper'])
def test_without_it_the_robot_stops_on_entering_the_tolerance(cfg):
    res = step(Planner(cfg), (1.0 - 0.12, 0.0, 0.0), (1.0, 0.0), 0)
    assert res.command.status is Status.REACHED and res.command.v == 0.0


def drive(cfg, pose, goal, seconds=8.0):
    """Close the loop on a unicycle that does what it is told for a period; the planner's
    last result and where the robot ends."""
    planner, pose = Planner(cfg), np.asarray(pose, float)
    t, res = 0.0, None
    while t < seconds:
        res = planner.step(pose, goal, Scan(OPEN, 0.0, 2 * math.pi / 360, 0.12, 3.5, t),
                           now=t)
        if res.command.status is Status.REACHED:
            break
        v, w = res.command.v, res.command.w
        pose = pose + cfg.period * np.array([v * math.cos(pose[2] + 0.5 * w * cfg.period),
                                             v * math.sin(pose[2] + 0.5 * w * cfg.period),
                                             w])
        t += cfg.period
    return res, pose


@pytest.mark.parametrize('start', [(0.88, 0.0, 0.0), (0.9, 0.06, -0.3), (0.95, -0.08, 0.5),
                                   (1.1, 0.05, 0.0), (0.92, 0.02, math.pi / 2)])
def test_the_final_approach_stops_at_the_goal_itself(start):
    """Inside the tolerance, from ahead of, beside or past the goal, heading any way: the
    robot heads for the goal and stops within arrival_distance of it (plus a period's
    step at the approach's speed), not centimetres short."""
    cfg = PlannerConfig()
    goal = np.array([1.0, 0.0])
    assert math.dist(start[:2], goal) < cfg.goal_tolerance
    res, pose = drive(cfg, start, goal)
    assert res.command.status is Status.REACHED
    assert math.dist(pose[:2], goal) <= cfg.arrival_distance + cfg.approach_speed * cfg.period


def test_the_final_approach_heads_for_the_goal():
    """Its command turns towards the goal (to the right here) and its chosen point is the
    goal; off, the sampled step leads; a goal behind is turned to on the spot."""
    cfg = PlannerConfig()
    res = step(Planner(cfg), (0.9, 0.05, 0.0), (1.0, 0.0), 0)
    assert res.command.status is Status.DRIVING and res.command.w < 0.0 < res.command.v
    np.testing.assert_array_equal(res.chosen_point, (1.0, 0.0))
    res = step(Planner(cfg.replace(final_approach=False)), (0.9, 0.05, 0.0), (1.0, 0.0), 0)
    assert not np.array_equal(res.chosen_point, (1.0, 0.0))
    res = step(Planner(cfg), (1.1, 0.0, 0.0), (1.0, 0.0), 0)
    assert res.command.status is Status.TURNING and res.command.v == 0.0
