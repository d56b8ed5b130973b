"""The final approach: inside the goal tolerance, straight to the goal.

With the geodesic field the goal gate (core/gates.py ``Goal``) lets the robot drive on
inside ``goal_tolerance`` until it is ``arrival_distance`` from the goal, or has come no
closer for ARRIVAL_PATIENCE. There the sampling's step, a point on a circle around the
robot chosen among obstacles, is coarser than what is left to drive: its heading swings
by tenths of a radian from cycle to cycle and the robot stops centimetres short. This
filter replaces the command of such a cycle by one that heads for the goal itself
(core/command.py ``shape_command`` with the goal as the target: turn on the spot when
it lies beyond ``rotate_in_place_angle``, else drive at most what covers the rest in
one period, the forward check still applied), so that the stop is where the robot
thinks the goal is to within millimetres and the pose error alone is left.

Not when a gate stopped the cycle, nor outside the tolerance; the evasion filter, after
it, still replaces its command when a moving track would meet it.
"""

from __future__ import annotations

import dataclasses

from .command import shape_command
from .cycle import Cycle, Stage


class FinalApproach(Stage):
    """Inside ``goal_tolerance``, while the goal gate drives on: head for the goal."""

    name = 'final_approach'

    def run(self, cycle: Cycle) -> Cycle:
        if cycle.status is not None or cycle.result is None \
                or cycle.goal_distance > cycle.cfg.goal_tolerance:
            return cycle
        command = shape_command(cycle.pose, cycle.goal, cycle.goal, cycle.previous,
                                cycle.obstacles, cycle.cfg)
        return cycle.with_(result=dataclasses.replace(cycle.result, command=command,
                                                      chosen_point=cycle.goal))
