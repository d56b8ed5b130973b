"""The typed state on ~/status (core/status.py, core/loop.py) and the simulator's
attempts, one goal after another (sim/attempt.py): without ROS."""

import math

import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.loop import DecisionLoop
from subapf_planner.core.scan import Scan
from subapf_planner.core.status import Outcome, State, Status, parse_status
from subapf_planner.sim.attempt import Attempts
from subapf_planner.sim.world import parse_world

pytestmark = pytest.mark.core

FREE = Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, 0.0)


def test_final_states_and_the_status_text():
    assert {s for s in State if s.final} == {State.REACHED, State.STUCK, State.UNREACHABLE}
    assert not State.MAPPING.final and not State.MAPPING.halted
    assert parse_status('driving: turning') == (State.DRIVING, 'turning')
    assert parse_status('stopped: scan is stale') == (State.STOPPED, 'scan is stale')
    assert parse_status('mapping: mapping') == (State.MAPPING, 'mapping')
    with pytest.raises(ValueError):
        parse_status('hello: world')


def run(loop: DecisionLoop, t0: float, ticks: int, pose=(0.0, 0.0, 0.0)) -> list:
    """``ticks`` planning periods of a still robot in open space from ``t0`` [s]."""
    out = []
    for k in range(ticks):
        t = t0 + 0.2 * k
        loop.update_odom(t, np.array(pose, float), t)
        loop.update_scan(Scan(FREE.ranges, 0.0, FREE.angle_increment, 0.12, 3.5, t), t)
        out.append(loop.tick(t))
        loop.after_tick()
    return out


def test_a_goal_starts_in_mapping_then_drives():
    """With the scan alignment the robot stands for the first scans: state mapping (the
    same zero command as before, when it was reported as stopped), then driving."""
    loop = DecisionLoop(PlannerConfig())
    loop.set_goal(np.array([3.0, 0.0]))
    decisions = run(loop, 0.0, 6)
    states = [d.state for d in decisions]
    first = states.index(State.DRIVING)
    assert 1 <= first <= 3 and set(states[:first]) == {State.MAPPING}, states
    assert all(d.command == (0.0, 0.0) and d.reason == Status.MAPPING and
               d.text == 'mapping: mapping' for d in decisions[:first])
    assert State.STOPPED not in states
    assert decisions[first].command[0] >= 0.0 and State.MAPPING not in states[first:]
    # the paper's method keeps no memory: no mapping
    paper = DecisionLoop(PlannerConfig(attraction_field='euclidean'))
    paper.set_goal(np.array([3.0, 0.0]))
    assert run(paper, 0.0, 1)[0].state is State.DRIVING


def test_the_goal_sent_again_while_mapping_is_the_same_goal():
    loop = DecisionLoop(PlannerConfig())
    loop.set_goal(np.array([3.0, 0.0]))
    assert run(loop, 0.0, 1)[0].state is State.MAPPING
    assert not loop.set_goal(np.array([3.0, 0.0]))   # (a script resends until taken)
    assert loop.state is State.MAPPING
    assert loop.set_goal(np.array([0.0, 3.0]))       # another goal is new


def test_reached_stays_until_the_next_goal():
    """A final state is final: reached stays (no command) until a goal comes, and the
    same goal again is a new attempt."""
    loop = DecisionLoop(PlannerConfig())
    loop.set_goal(np.array([0.005, 0.0]))
    first, *after = run(loop, 0.0, 4)
    assert first.state is State.REACHED and first.command == (0.0, 0.0)
    assert all(d.state is State.REACHED and d.command is None and d.text == first.text
               for d in after)
    assert loop.set_goal(np.array([0.005, 0.0]))
    assert loop.state is State.DRIVING and loop.reason == 'new goal'
    assert run(loop, 1.0, 1)[0].state is State.REACHED
    assert loop.set_goal(np.array([2.0, 0.0]))
    assert not run(loop, 2.0, 1)[0].state.final


WORLD = parse_world({'name': 'open', 'start': [0.0, 0.0, 0.0], 'goal': [1.0, 0.0],
                     'time_limit': 10.0})


def test_each_goal_is_an_attempt_with_its_own_time_limit():
    attempts = Attempts(WORLD)
    here = (0.0, 0.0, 0.0)
    assert attempts.current.number == 1 and attempts.current.start == 0.0
    assert not attempts.goal((1.0, 0.0), 3.0)   # the world's goal, sent: the same attempt
    assert attempts.update(here, False, 9.9) is None
    assert attempts.update(here, False, 10.0) is Outcome.TIMEOUT
    assert attempts.update(here, False, 10.1) is None   # an outcome once
    assert attempts.goal((1.0, 0.0), 12.0)   # the same goal after its outcome: new
    a = attempts.current
    assert (a.number, a.start, a.running) == (2, 12.0, True)
    assert attempts.update(here, False, 21.9) is None   # its limit counts from 12 s
    assert not attempts.goal((1.0, 0.0), 15.0)          # resent while it runs
    assert attempts.update((0.95, 0.0, 0.0), False, 16.0) is Outcome.REACHED
    assert attempts.goal((1.0, 2.0), 17.0) and attempts.current.number == 3
    assert attempts.update((0.95, 0.0, 0.0), False, 26.9) is None
    assert attempts.update((0.95, 0.0, 0.0), False, 27.0) is Outcome.TIMEOUT


def test_a_collision_is_a_contact_that_begins_during_the_attempt():
    attempts = Attempts(WORLD)
    here = (0.0, 0.0, 0.0)
    assert attempts.update(here, True, 1.0) is Outcome.COLLISION
    assert attempts.update(here, True, 1.1) is None
    attempts.goal((0.0, 2.0), 2.0)     # still touching what it hit
    assert attempts.update(here, True, 2.1) is None
    assert attempts.update(here, False, 2.2) is None   # came free
    assert attempts.update(here, True, 2.3) is Outcome.COLLISION
