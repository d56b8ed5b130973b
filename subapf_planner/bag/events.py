"""A recorded run as one time-ordered stream of planner inputs and commands.

Both replays (in-process, ros/replay.py, and through a planner_node over DDS,
ros/replay_dds.py) read a bag through :func:`events`, so they see the same
events at the same simulated times in the same order:

* ``odom`` at its header stamp;
* ``scan`` at its header stamp or, when older, at the newest simulated time seen
  before it in the bag, after the commands logged before it at that time: a real
  lidar's scan is stamped at its first beam and arrives a sweep and the driver's
  latency later (so does the simulator's realistic sensor's), and the node could plan
  with it only from the first tick after it arrived;
* ``goal`` (PoseStamped; RViz and the bringup leave its stamp at zero) at the
  newest simulated time seen before it in the bag;
* ``cmd_vel`` at its header stamp when it is a TwistStamped (the node stamps each
  command with its planning tick), and for a Twist, which has no stamp, at the
  newest simulated time seen before it: the tick it answered.

"Newest simulated time seen" is the largest scan or odometry stamp, or ``/clock``
value when the bag has that topic, among the messages logged before. Events are
sorted by time; at equal times inputs come first, then goals, then commands (the
node ticks after what it has received), each kind in log order.

That is where the node most likely took each input; where it truly did, the node
says on ``~/taken`` (planner_node: a TimeReference per scan, odometry and goal_pose
message, stamped with the tick it was taken at). A bag with that topic (and stamped
commands) is replayed by it: each scan and odometry message at the tick that took it
(matched by stamp), the n-th goal at the tick of the n-th goal taken, in the order
the node took them: before the tick's command, but for scans and odometry stamped
after the tick, which the node takes after its command; inputs the node never
received are left out (those stamped before the first tick it tells of, which the
recorder may have missed, at their stamps). DDS orders no two topics, so a scan the simulator sent
before its clock may reach the node after the tick (on a loaded machine) and the
recorder in the other order.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .reader import BagError, read, topics

#: Message type of each input role.
INPUT_TYPES = {'scan': 'sensor_msgs/msg/LaserScan', 'odom': 'nav_msgs/msg/Odometry',
               'goal': 'geometry_msgs/msg/PoseStamped'}
STAMPED_CMD = 'geometry_msgs/msg/TwistStamped'
PLAIN_CMD = 'geometry_msgs/msg/Twist'
#: Accepted cmd_vel types (the node's enable_stamped_cmd_vel true / false).
CMD_TYPES = (STAMPED_CMD, PLAIN_CMD)
ROLES = ('scan', 'odom', 'goal', 'cmd_vel')
#: The planner node's record of what it took (optional in a bag: ``names['taken']``).
TAKEN_TOPIC = '/subapf_planner/taken'
TAKEN_TYPE = 'sensor_msgs/msg/TimeReference'
#: ~/taken's source per role.
TAKEN_SOURCE = {'scan': 'scan', 'odom': 'odom', 'goal': 'goal_pose'}
CLOCK_TOPIC = '/clock'
CLOCK_TYPE = 'rosgraph_msgs/msg/Clock'
#: Order among events at the same time.
_RANK = {'scan': 0, 'odom': 0, 'goal': 1, 'cmd_vel': 2}


@dataclass(frozen=True)
class Event:
    """One recorded message with the simulated time it belongs to [ns]."""

    time_ns: int
    role: str
    message: Any

    @property
    def time(self) -> float:
        """[s], as a node's clock gives it (nanoseconds * 1e-9)."""
        return self.time_ns * 1e-9


def stamp_ns(stamp: Any) -> int:
    """A builtin_interfaces/Time as integer nanoseconds (exact)."""
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def check_topics(path: str | Path, names: dict[str, str]) -> str:
    """BagError naming what is missing or of the wrong type; else the bag's cmd_vel
    type name (one of CMD_TYPES).

    ``names`` maps each role of ROLES to its topic in the bag.
    """
    found = topics(path)
    for role in ROLES:
        topic = names[role]
        want = CMD_TYPES if role == 'cmd_vel' else (INPUT_TYPES[role],)
        if topic not in found:
            raise BagError(f'{path}: no {topic} topic ({role}); topics: '
                           f'{", ".join(sorted(found)) or "none"}')
        if found[topic] not in want:
            raise BagError(f'{path}: {topic} is {found[topic]}, expected {" or ".join(want)}')
    return found[names['cmd_vel']]


def events(path: str | Path, names: dict[str, str]) -> list[Event]:
    """The bag's scan, odom, goal and cmd_vel messages as time-ordered events (see the
    module docstring). Checks the topics first (check_topics). ``names`` maps each
    role to its topic, and optionally 'taken' to the node's ~/taken (default
    TAKEN_TOPIC)."""
    stamped = check_topics(path, names) == STAMPED_CMD
    taken_topic = names.get('taken', TAKEN_TOPIC)
    if stamped and topics(path).get(taken_topic) == TAKEN_TYPE:
        return _as_taken(path, names, taken_topic)
    role = {topic: r for r, topic in names.items() if r in ROLES}
    wanted = set(role)
    if topics(path).get(CLOCK_TOPIC) == CLOCK_TYPE and CLOCK_TOPIC not in wanted:
        wanted.add(CLOCK_TOPIC)
    out: list[tuple[int, int, int, Event]] = []
    now = 0
    for i, m in enumerate(read(path, wanted)):
        r = role.get(m.topic)
        if r is None:   # /clock: only a time source
            now = max(now, stamp_ns(m.message.clock))
            continue
        if r == 'odom':
            t = stamp_ns(m.message.header.stamp)
            now = max(now, t)
        elif r == 'scan' and stamp_ns(m.message.header.stamp) < now:
            # arrived late: at the newest time, after the commands logged before it
            out.append((now, _RANK['cmd_vel'], i, Event(now, r, m.message)))
            continue
        elif r == 'scan':
            t = stamp_ns(m.message.header.stamp)
            now = t
        elif r == 'cmd_vel' and m.type_name == STAMPED_CMD:
            t = stamp_ns(m.message.header.stamp)
        else:   # goal, Twist command
            t = now
        out.append((t, _RANK[r], i, Event(t, r, m.message)))
    out = _snap_plain_commands(out)
    out.sort(key=lambda e: e[:3])
    return [e[3] for e in out]


def _as_taken(path: str | Path, names: dict[str, str], taken_topic: str) -> list[Event]:
    """Events of a bag with the node's ~/taken and stamped commands (module docstring):
    each input at the tick that took it, in the order taken, before the tick's command
    or, stamped after the tick, after it."""
    role = {topic: r for r, topic in names.items() if r in ROLES}
    ticks: dict[tuple[str, int], tuple[int, int]] = {}   # (source, stamp) -> (tick, order)
    goal_ticks: list[tuple[int, int]] = []
    messages = []
    for k, m in enumerate(read(path, set(role) | {taken_topic})):
        if m.topic != taken_topic:
            messages.append((role[m.topic], m))
            continue
        ref = m.message
        at = (stamp_ns(ref.header.stamp), k)   # the tick, and the order taken
        if ref.source == TAKEN_SOURCE['goal']:
            goal_ticks.append(at)
        else:
            ticks.setdefault((ref.source, stamp_ns(ref.time_ref)), at)
    # inputs stamped before the first tick ~/taken tells of: at their stamps
    first = min((at[0] for at in (*ticks.values(), *goal_ticks)), default=0)
    out: list[tuple[int, int, int, Event]] = []
    goals = 0
    for i, (r, m) in enumerate(messages):
        if r == 'cmd_vel':
            t = stamp_ns(m.message.header.stamp)
            out.append((t, 1, i, Event(t, r, m.message)))
            continue
        stamp = stamp_ns(m.message.header.stamp)
        if r == 'goal':
            at = goal_ticks[goals] if goals < len(goal_ticks) else None
            goals += 1
        else:
            at = ticks.get((TAKEN_SOURCE[r], stamp))
            if at is None and stamp < first:   # before the recorder heard ~/taken
                at = (stamp, -1)
        if at is not None:   # (else the node never received it)
            after = r != 'goal' and stamp > at[0]
            out.append((at[0], 2 if after else 0, at[1], Event(at[0], r, m.message)))
    out.sort(key=lambda e: e[:3])
    return [e[3] for e in out]


def _snap_plain_commands(out: list[tuple[int, int, int, Event]]) -> list:
    """Twist commands come from a periodic timer, but the newest clock before one may
    already be the next instant when the node took long to plan: put each on the
    latest tick of the timer's grid at or before it (period: the median spacing of the
    commands; phase: the most common remainder)."""
    plain = [k for k, e in enumerate(out)
             if e[3].role == 'cmd_vel' and not hasattr(e[3].message, 'header')]
    if len(plain) < 3:
        return out
    times = np.array([out[k][0] for k in plain], dtype=np.int64)
    steps = np.diff(times)
    period = int(np.median(steps[steps > 0])) if np.any(steps > 0) else 0
    if period <= 0:
        return out
    rest, counts = np.unique(times % period, return_counts=True)
    phase = int(rest[np.argmax(counts)])
    snapped = phase + (times - phase) // period * period
    out = list(out)
    for k, t in zip(plain, snapped.tolist(), strict=True):
        _, rank, i, e = out[k]
        out[k] = (t, rank, i, Event(t, e.role, e.message))
    return out
