"""Typed states, statuses and outcomes; their string values are what goes on the wire.

``~/status`` carries ``"<State>: <reason>"``; a reason is a :class:`Status`
(``driving: turning``) or a supervision reason (``stopped: scan is stale``).
:func:`parse_status` turns the text back into the typed state and the reason.
"""

from __future__ import annotations

from enum import StrEnum


class Status(StrEnum):
    """What one planning cycle decided (core/planner.py, core/command.py)."""

    DRIVING = 'driving'
    TURNING = 'turning'
    BLOCKED_AHEAD = 'blocked_ahead'
    #: A footprint polygon's corner would sweep into something if it turned on the spot:
    #: it backs straight up to make room (core/command.py).
    BACKING_UP = 'backing_up'
    #: The planned command would meet a moving obstacle: replaced (core/evasion.py).
    EVADING = 'evading'
    REACHED = 'reached'
    NO_SAFE_MOVE = 'no_safe_move'
    GOAL_IN_OBSTACLE = 'goal_in_obstacle'
    GOAL_UNREACHABLE = 'goal_unreachable'
    INVALID_SCAN = 'invalid_scan'
    INVALID_POSE = 'invalid_pose'
    INVALID_GOAL = 'invalid_goal'
    #: The scan alignment's memory is new (fewer than gates.FIRST_SCANS scans, or none
    #: matched to its walls yet): the robot stands while the first walls are established,
    #: so that the memory's frame is odom at the start and a first turn is matched as it
    #: is made, not drawn into the walls with its drift.
    MAPPING = 'mapping'

    @property
    def stops(self) -> bool:
        """The robot must stand still (a safety or input problem, not the goal)."""
        return self in STOP_STATUSES


STOP_STATUSES = frozenset({Status.NO_SAFE_MOVE, Status.GOAL_IN_OBSTACLE,
                           Status.GOAL_UNREACHABLE, Status.INVALID_SCAN,
                           Status.INVALID_POSE, Status.INVALID_GOAL, Status.MAPPING})


class State(StrEnum):
    """The planner node's state (core/loop.py), the text before the colon of
    ``~/status``. The README's state table says what each means and which are final."""

    #: No goal yet.
    IDLE = 'idle'
    #: A goal, but no scan or no odometry yet.
    WAITING = 'waiting'
    #: The normal first state of a goal with the scan alignment: the robot stands for the
    #: first scans of a new memory, until one is matched to its walls (core/gates.py
    #: Mapping, MAPPING_TIME at most).
    MAPPING = 'mapping'
    DRIVING = 'driving'
    #: Held still for a reason that can pass (a stale input, no safe move, no way yet).
    STOPPED = 'stopped'
    #: The goal is reached; stays until the next goal.
    REACHED = 'reached'
    #: The progress checker gave the goal up after its recoveries.
    STUCK = 'stuck'
    #: The goal was unreachable through the memory for ``unreachable_timeout``: given up.
    UNREACHABLE = 'unreachable'

    @property
    def halted(self) -> bool:
        """The robot is held still by a stop (worth a warning)."""
        return self in (State.STOPPED, State.STUCK, State.UNREACHABLE)

    @property
    def gave_up(self) -> bool:
        """The attempt has ended without the goal (until a goal is sent again)."""
        return self in (State.STUCK, State.UNREACHABLE)

    @property
    def final(self) -> bool:
        """The attempt at the goal is over (reached, or given up): the state stays until
        the next goal, and nothing more happens for this one."""
        return self in FINAL_STATES


#: The states that end an attempt (State.final).
FINAL_STATES = frozenset({State.REACHED, State.STUCK, State.UNREACHABLE})


def parse_status(text: str) -> tuple[State, str]:
    """The typed state and the reason of a ``~/status`` text ``"state: reason"``
    (ValueError for a text that does not start with a state)."""
    state, _, reason = text.partition(':')
    return State(state.strip()), reason.strip()


class Outcome(StrEnum):
    """How a simulated run ended (sim/outcome.py)."""

    REACHED = 'reached'
    COLLISION = 'collision'
    TIMEOUT = 'timeout'
    #: The planner gave the goal up (progress checker) before the time limit.
    ABANDONED = 'abandoned'
    #: The planner ended the attempt: no way to the goal through its memory for
    #: ``unreachable_timeout``.
    UNREACHABLE = 'unreachable'
    #: The planner stopped at the goal by its own (odometry, aligned) estimate, but the
    #: robot really stands outside the goal's tolerance: the localisation was off.
    MISSED = 'missed'
