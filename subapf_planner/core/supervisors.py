"""Supervisors: the decision loop's stages around the planning step (core/loop.py).

Each tick runs them in this order; the first that decides ends the tick:

* before the planning step (``before``: may decide without planning):
  ``goal`` (no goal: idle, or still reached after the last one), ``inputs`` (no
  scan or odometry yet: waiting),
  ``freshness`` (a scan older than ``scan_timeout`` or odometry older than
  ``odom_timeout``: stopped), ``given_up`` (a goal given up stays given up until it
  is sent again);
* after it (``after``: may decide from the plan): ``arrival`` (``reached``: the goal
  is done), ``unreachable`` (no way to the goal, or the goal inside an obstacle, for
  ``unreachable_timeout``: given up), ``progress`` (the progress checker: no
  ``progress_distance`` in ``progress_timeout``, or standing with ``no_safe_move`` (or
  ``blocked_ahead`` not turning) for ``blocked_timeout``, starts a recovery (core/recovery.py),
  at most ``recoveries`` times a goal, then gives the goal up as stuck; it waits while
  a moving obstacle is within ``giving_way_distance``).

What no supervisor decides, the plan does: a command that stops the robot is
``stopped`` (``mapping`` for the first scans of a new memory, taken standing), any
other ``driving``. A supervisor keeps its own clock (``reset`` for a
new goal, ``restart`` after a clock jump).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .command import Command
from .cycle import PlanResult
from .recovery import AvoidAhead
from .status import State, Status

if TYPE_CHECKING:
    from .loop import Decision, DecisionLoop

#: Statuses under which the goal cannot be reached for now; unreachable_timeout of them
#: ends the attempt.
NO_WAY = (Status.GOAL_UNREACHABLE, Status.GOAL_IN_OBSTACLE)
#: A command held at ``blocked_ahead`` that turns slower than this [rad/s] stands as
#: surely as ``no_safe_move`` does (the local target straight ahead in a gap the
#: footprint does not pass: the Jackal's `barn_001` stood so for 10 s, until the
#: progress checker's clock): it counts towards ``blocked_timeout`` as well.
STANDING_TURN_RATE = 0.1


def standing(command: Command) -> bool:
    """Whether ``command`` keeps the robot where it is for want of a safe move."""
    return command.status is Status.NO_SAFE_MOVE or (
        command.status is Status.BLOCKED_AHEAD and command.v == 0.0
        and abs(command.w) < STANDING_TURN_RATE)


class Supervisor:
    """A stage of the decision loop's tick (module docstring); by default it decides
    nothing and keeps nothing."""

    name = 'supervisor'

    def before(self, loop: DecisionLoop, now: float) -> Decision | None:
        return None

    def after(self, loop: DecisionLoop, result: PlanResult, now: float) -> Decision | None:
        return None

    def reset(self) -> None:
        """A new goal."""
        self.restart()

    def restart(self) -> None:
        """The clock jumped: forget the times kept."""


class NoGoal(Supervisor):
    name = 'goal'

    def before(self, loop: DecisionLoop, now: float) -> Decision | None:
        if loop.goal is None:
            if loop.state is State.REACHED:   # a final state stays until the next goal
                return loop.decide(None, State.REACHED, loop.reason)
            return loop.decide(None, State.IDLE, 'no goal')
        return None


class Inputs(Supervisor):
    name = 'inputs'

    def before(self, loop: DecisionLoop, now: float) -> Decision | None:
        if loop.scan is None or loop.pose is None:
            return loop.decide(None, State.WAITING,
                               f'no {"scan" if loop.scan is None else "odom"} yet')
        return None


class Freshness(Supervisor):
    name = 'freshness'

    def before(self, loop: DecisionLoop, now: float) -> Decision | None:
        scan_silent, odom_silent = loop.silent(now)
        if scan_silent:
            return loop.stop(State.STOPPED, 'scan is stale')
        if odom_silent:
            return loop.stop(State.STOPPED, 'odometry is stale')
        return None


class GivenUp(Supervisor):
    name = 'given_up'

    def before(self, loop: DecisionLoop, now: float) -> Decision | None:
        if loop.state.gave_up:
            return loop.hold()
        return None


class Arrival(Supervisor):
    name = 'arrival'

    def after(self, loop: DecisionLoop, result: PlanResult, now: float) -> Decision | None:
        if result.command.status is Status.REACHED:
            loop.clear_goal()
            return loop.stop(State.REACHED, 'goal within tolerance', result)
        return None


class Unreachable(Supervisor):
    """Gives the goal up once NO_WAY has lasted longer than unreachable_timeout (any
    other status restarts the clock: a door that opens, someone who walked off)."""

    name = 'unreachable'

    def __init__(self) -> None:
        self._since: float | None = None

    def restart(self) -> None:
        self._since = None

    def after(self, loop: DecisionLoop, result: PlanResult, now: float) -> Decision | None:
        if result.command.status not in NO_WAY:
            self._since = None
            return None
        if self._since is None:
            self._since = now
        timeout = loop.limits.unreachable_timeout
        if now - self._since <= timeout:
            return None
        tried = loop.recoveries.tried
        why = result.no_way or str(result.command.status)
        return loop.stop(State.UNREACHABLE, f'no way to the goal for {timeout:g} s ({why}'
                         f'{f"; ways tried: {tried}" if tried else ""}), goal abandoned',
                         result)


class Recoveries:
    """The recoveries of one goal (core/recovery.py) and how many were tried."""

    def __init__(self) -> None:
        self.behaviours = (AvoidAhead(),)
        self.tried = 0

    def attempt(self, loop: DecisionLoop, now: float) -> bool:
        """Run the next recovery, if any is left for this goal and one applies."""
        lim = loop.limits
        if self.tried >= lim.recoveries:
            return False
        planner = loop.planner
        for behaviour in self.behaviours:
            if behaviour.run(planner.memory, planner.planned_from, lim.avoid_distance,
                             lim.avoid_radius, now + lim.avoid_time):
                self.tried += 1
                return True
        return False


class Progress(Supervisor):
    """The progress checker (module docstring)."""

    name = 'progress'

    def __init__(self) -> None:
        self._anchor: tuple[np.ndarray, float] | None = None   # where and when it last moved
        self._blocked_since: float | None = None   # since when it stands (standing)

    def restart(self) -> None:
        self._anchor = self._blocked_since = None

    def after(self, loop: DecisionLoop, result: PlanResult, now: float) -> Decision | None:
        cmd, lim = result.command, loop.limits
        if giving_way(result, loop.pose, lim.giving_way_distance):
            self._anchor = self._blocked_since = None
        if cmd.status.stops and cmd.status is not Status.NO_SAFE_MOVE:
            self._blocked_since = None
            return None   # stopped for a reason of its own: not the progress checker's
        self._move_anchor(loop.pose, lim.progress_distance, now)
        if not standing(cmd):
            self._blocked_since = None
        elif self._blocked_since is None:
            self._blocked_since = now
        blocked = self._blocked_since is not None and now - self._blocked_since > \
            lim.blocked_timeout
        late = now - self._anchor[1] > lim.progress_timeout
        if not (late or blocked):
            return None
        command = (0.0, 0.0) if cmd.status.stops else (cmd.v, cmd.w)   # (standing at a gap)
        if loop.recoveries.attempt(loop, now):
            self._anchor = self._blocked_since = None
            tried, most = loop.recoveries.tried, loop.limits.recoveries
            why = 'no progress' if late else 'no safe move'
            return loop.decide(command, State.DRIVING, f'{why}: the way ahead marked '
                               f'tried ({tried} of {most}), another way', result)
        if not late:
            return None   # no recovery left: given up only on the progress checker's clock
        return loop.stop(State.STUCK, 'no progress, goal abandoned', result)

    def _move_anchor(self, pose: np.ndarray, distance: float, now: float) -> None:
        """Start the clock anew where the robot is when it has none or has moved
        ``distance`` [m] from where it started."""
        if self._anchor is None or np.hypot(*(pose[:2] - self._anchor[0])) >= distance:
            self._anchor = (pose[:2].copy(), now)


def giving_way(result: PlanResult, pose: np.ndarray, distance: float) -> bool:
    """A moving track is within ``distance`` [m] of the robot (at ``pose`` in odom, or
    the result's own pose: the tracks are in the memory's frame): giving way to someone
    is not being stuck."""
    t = result.tracks
    if not np.any(t.moving):
        return False
    pose = pose if result.pose is None else result.pose
    return bool(np.min(np.hypot(*(t.position[t.moving] - pose[:2]).T)) < distance)


#: The supervisors of every tick, in order (module docstring).
SUPERVISORS = (NoGoal, Inputs, Freshness, GivenUp, Arrival, Unreachable, Progress)
