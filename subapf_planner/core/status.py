"""Typed states, statuses and outcomes; their string values are what goes on the wire.

``~/status`` carries ``"<State>: <reason>"``; a reason is a :class:`Status`
(``driving: turning``) or a supervision reason (``stopped: scan is stale``).
"""

from __future__ import annotations

from enum import StrEnum


class Status(StrEnum):
    """What one planning cycle decided (core/planner.py, core/command.py)."""

    DRIVING = 'driving'
    TURNING = 'turning'
    BLOCKED_AHEAD = 'blocked_ahead'
    #: The planned command would meet a moving obstacle: replaced (core/evasion.py).
    EVADING = 'evading'
    REACHED = 'reached'
    NO_SAFE_MOVE = 'no_safe_move'
    GOAL_IN_OBSTACLE = 'goal_in_obstacle'
    GOAL_UNREACHABLE = 'goal_unreachable'
    INVALID_SCAN = 'invalid_scan'
    INVALID_POSE = 'invalid_pose'
    INVALID_GOAL = 'invalid_goal'
    #: The scan alignment's memory is new (fewer than planner.FIRST_SCANS scans): the
    #: robot stands while the first walls are established, so that the memory's frame is
    #: odom at the start, not odom turned by the drift of a first turn.
    MAPPING = 'mapping'

    @property
    def stops(self) -> bool:
        """The robot must stand still (a safety or input problem, not the goal)."""
        return self in STOP_STATUSES


STOP_STATUSES = frozenset({Status.NO_SAFE_MOVE, Status.GOAL_IN_OBSTACLE,
                           Status.GOAL_UNREACHABLE, Status.INVALID_SCAN,
                           Status.INVALID_POSE, Status.INVALID_GOAL, Status.MAPPING})


class State(StrEnum):
    """The planner node's state (core/loop.py), the text before the colon."""

    IDLE = 'idle'
    WAITING = 'waiting'
    DRIVING = 'driving'
    REACHED = 'reached'
    STOPPED = 'stopped'
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
