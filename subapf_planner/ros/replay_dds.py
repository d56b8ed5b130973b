"""Replay a bag through the real ``planner_node`` over DDS, in lockstep with /clock.

The node runs as a child process on a private, localhost-only domain with
``use_sim_time`` and ``enable_stamped_cmd_vel`` matching the bag's cmd_vel type. A
player publishes the recorded ``odom``, ``scan`` and ``goal_pose`` of each
simulated instant of the bag's event stream (bag/events.py, which the in-process
replay reads too), then that instant on ``/clock``; where the bag has a ``cmd_vel``
at that instant, the player waits for the node's own ``cmd_vel`` for it before
going on: a TwistStamped carries its tick's stamp, a Twist is taken as the answer
to the ``/clock`` instant at which it arrives. So the replay runs as fast as the
node answers, and its commands can be compared one by one with the recorded ones
and with the in-process replay (ros/replay.py).
"""

from __future__ import annotations

from pathlib import Path
import subprocess
import time

from geometry_msgs.msg import PoseStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
import numpy as np
import rclpy
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import String

from ..bag.comparison import Comparison
from ..bag.events import STAMPED_CMD, Event, check_topics, events, stamp_ns
from ..bag.reader import BagError
from .conversions import cmd_from_msg, ns_to_stamp
from .processes import join_domain, start, stop

#: Longest wait for the node's answer to one tick [s].
ANSWER_TIMEOUT = 5.0
#: Wall-clock pause around the first tick, so the goal and first inputs are delivered [s].
FIRST_TICK_PAUSE = 0.2
#: The first /clock is set this much before the first tick, so the inputs are fresh [ns].
FIRST_CLOCK_LEAD = 50_000_000
#: Wall-clock pause between the inputs of a tick's instant and its /clock, so they
#: reach the node before the clock makes it tick: DDS does not order messages across
#: topics, and the scan is best effort (never acknowledged) [s].
INPUT_SETTLE = 0.01


def _instants(stream: list[Event]) -> list[tuple[int, list[Event], list[Event]]]:
    """[(t [ns], inputs, recorded commands)] from the bag's events, one per simulated
    time, from the first recorded command on; an input that came after a time's
    commands (a scan that arrived late, bag/events.py) gets an instant of its own at that
    time, without commands: it is handed over after the tick."""
    first_cmd = next((k for k, e in enumerate(stream) if e.role == 'cmd_vel'), None)
    if first_cmd is None:
        return []
    # Before its first command the recorded node only collected inputs (and may have
    # missed some while discovery settled): hand them all over, the newest goal
    # first, then tick at t0.
    t0 = stream[first_cmd].time_ns
    early = stream[:first_cmd]
    goals = [e for e in early if e.role == 'goal']
    instants = [(t0, goals[-1:] + [e for e in early if e.role != 'goal'], [])]
    for e in stream[first_cmd:]:
        t, inputs, cmds = instants[-1]
        if t != e.time_ns or (e.role != 'cmd_vel' and cmds):
            instants.append((e.time_ns, [], []))
        instants[-1][2 if e.role == 'cmd_vel' else 1].append(e)
    return instants


def replay_through_node(path: str, params: str, names: dict[str, str],
                        method: str | None = None, domain: int = 90) -> Comparison:
    """Run the bag through a planner_node process; see the module docstring."""
    stamped = check_topics(path, names) == STAMPED_CMD
    instants = _instants(events(path, names))
    env = join_domain(domain)
    ros_args = ['--params-file', str(Path(params).resolve()), '-p', 'use_sim_time:=true',
                '-p', f'enable_stamped_cmd_vel:={str(stamped).lower()}']
    if method:
        ros_args += ['-p', f'method:={method}']
    child = start('planner_node', ros_args, env, quiet=True)
    context = rclpy.Context()
    rclpy.init(context=context)
    node = Node('subapf_replay_player', context=context)
    try:
        return _play(node, context, child, instants, names, stamped)
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        stop([child])


def _pause(executor, seconds: float) -> None:
    end = time.monotonic() + seconds
    while True:
        executor.spin_once(timeout_sec=0.002)
        if time.monotonic() >= end:
            return


def _play(node: Node, context, child: subprocess.Popen, instants: list,
          names: dict[str, str], stamped: bool) -> Comparison:
    executor = rclpy.executors.SingleThreadedExecutor(context=context)
    executor.add_node(node)
    answers: dict[int, tuple[float, float]] = {}   # tick [ns] -> (v, w)
    clock_now = [0]   # the last /clock published [ns]: a Twist answers that tick

    def on_cmd(msg) -> None:
        t = stamp_ns(msg.header.stamp) if stamped else clock_now[0]
        answers.setdefault(t, cmd_from_msg(msg))

    node.create_subscription(TwistStamped if stamped else Twist, names['cmd_vel'], on_cmd,
                             100)
    statuses: list[str] = []
    node.create_subscription(String, '/subapf_planner/status', lambda m: statuses.append(m.data),
                             100)
    pubs = {'scan': node.create_publisher(LaserScan, names['scan'], qos_profile_sensor_data),
            'odom': node.create_publisher(Odometry, names['odom'], 10),
            'goal': node.create_publisher(PoseStamped, names['goal'], 10)}
    clock = node.create_publisher(Clock, '/clock', 10)

    def publish_clock(ns: int) -> None:
        clock_now[0] = ns
        clock.publish(Clock(clock=ns_to_stamp(ns)))

    deadline = time.monotonic() + 30.0
    while not all(p.get_subscription_count() > 0 for p in (*pubs.values(), clock)) or \
            node.count_publishers(names['cmd_vel']) == 0:
        if child.poll() is not None or time.monotonic() > deadline:
            raise BagError(f'planner_node did not come up (exit code {child.poll()}); run '
                           'subapf-planner with the same parameters to see why')
        executor.spin_once(timeout_sec=0.05)
    times, recorded, replayed = [], [], []
    for i, (t, inputs, cmds) in enumerate(instants):
        if i == 0:
            # Set the node's clock to just before the first tick, so the inputs are fresh,
            # and repeat until its timer has run once (the first /clock may be lost while
            # discovery completes on the node's side). No goal yet: no command.
            end = time.monotonic() + 30.0
            while not statuses and time.monotonic() < end and child.poll() is None:
                publish_clock(max(0, t - FIRST_CLOCK_LEAD))
                _pause(executor, 0.05)
            answers.clear()
        for e in inputs:
            pubs[e.role].publish(e.message)
        settle = INPUT_SETTLE if inputs and cmds else 0.0
        _pause(executor, FIRST_TICK_PAUSE if i == 0 else settle)
        publish_clock(t)
        if not cmds:
            continue
        end = time.monotonic() + ANSWER_TIMEOUT
        while t not in answers and time.monotonic() < end and child.poll() is None:
            executor.spin_once(timeout_sec=0.01)
        for e in cmds:
            times.append(e.time)
            recorded.append(cmd_from_msg(e.message))
            replayed.append(answers.get(t, (np.nan, np.nan)))
    return Comparison(np.asarray(times), np.asarray(recorded, float).reshape(-1, 2),
                      np.asarray(replayed, float).reshape(-1, 2))
