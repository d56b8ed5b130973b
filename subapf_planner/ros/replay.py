"""A recorded run replayed through the decision loop in process (``subapf-replay``).

The recorded ``scan``, ``odom`` and ``goal_pose`` go through the same input
checks (ros/intake.py) and the same ``DecisionLoop`` the node runs, in simulated
time order (as fast as possible; the event stream of bag/events.py, which the
DDS replay, ros/replay_dds.py, reads too); at each recorded ``cmd_vel`` the loop
ticks, as the node's timer did: at its stamp (TwistStamped) or, for a Twist bag,
at the simulated time it was recorded at. A recorded zero while the loop has no goal
and nothing to say (the goal reached or given up) is the node stopping the robot as
it shuts down, and is compared as the zero it is.
"""

from __future__ import annotations

import math

import numpy as np

from ..bag.comparison import Comparison
from ..bag.events import events
from ..core.config import PlannerConfig
from ..core.loop import DecisionLoop, Supervision
from .conversions import cmd_from_msg
from .intake import Intake


def replay(path: str, cfg: PlannerConfig, limits: Supervision, names: dict[str, str],
           intake: Intake | None = None) -> Comparison:
    """Run the decision loop over the bag's events (bag/events.py); see the module
    docstring. ``names`` maps each role (scan, odom, goal, cmd_vel) to its topic;
    ``intake`` holds the node's laser_frame and odom_frame (default: the node's
    defaults). Each input is handled at its event's time, as the node handles it."""
    ctl = DecisionLoop(cfg, limits)
    intake = intake or Intake()
    times, recorded, replayed = [], [], []
    skipped = 0
    for e in events(path, names):
        t = e.time
        if e.role == 'scan':
            intake.scan(ctl, e.message, t)
        elif e.role == 'odom':
            intake.odom(ctl, e.message, t)
        elif e.role == 'goal':
            intake.goal(ctl, e.message)
        else:
            command = cmd_from_msg(e.message)
            leading = skipped == len(replayed) and (ctl.scan is None or ctl.pose is None
                                                    or ctl.goal is None)
            decision = ctl.tick(t)
            ctl.after_tick()   # as the node does once its command is out
            if leading:
                skipped += 1
                ctl.seed_command(command)   # the node's state after what it published
            times.append(t)
            recorded.append(command)
            if decision.command is not None:
                replayed.append(decision.command)
            elif ctl.goal is None and command == (0.0, 0.0):
                replayed.append((0.0, 0.0))   # the node's stop on shutdown
            else:
                replayed.append((math.nan, math.nan))
    return Comparison(np.asarray(times), np.asarray(recorded, float).reshape(-1, 2),
                      np.asarray(replayed, float).reshape(-1, 2), skipped)
