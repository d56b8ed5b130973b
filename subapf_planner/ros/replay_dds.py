"""Replay a bag through the real ``planner_node`` over DDS, in lockstep with /clock.

The node runs as a child process on a private, localhost-only domain with
``use_sim_time``. A player publishes the recorded ``odom``, ``scan`` and
``goal_pose`` of each simulated instant, then that instant on ``/clock``; where
the bag has a ``cmd_vel`` stamped at that instant, the player waits for the
node's own ``cmd_vel`` with the same stamp before going on. So the replay runs
as fast as the node answers, and its commands can be compared one by one with
the recorded ones and with the in-process replay (replay.py).
"""

from __future__ import annotations

from pathlib import Path
import subprocess
import time

from geometry_msgs.msg import PoseStamped, TwistStamped
from nav_msgs.msg import Odometry
import numpy as np
import rclpy
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import String

from ..bag.reader import BagError, read
from ..tools.replay import Comparison, check_topics
from .conversions import cmd_from_msg, seconds_to_stamp, stamp_to_seconds
from .processes import join_domain, start, stop

#: Longest wait for the node's answer to one tick [s].
ANSWER_TIMEOUT = 5.0
#: Wall-clock pause around the first tick, so the goal and first inputs are delivered [s].
FIRST_TICK_PAUSE = 0.2


def _instants(path: str, names: dict[str, str]) -> list[tuple[float, list, list]]:
    """[(t, inputs [(role, msg)], recorded commands [(v, w)])] in simulated time order,
    from the first recorded command on."""
    role = {topic: r for r, topic in names.items()}
    inputs: dict[float, list] = {}
    cmds: dict[float, list] = {}
    now = 0.0
    for m in read(path, set(names.values())):
        r = role[m.topic]
        if r in ('scan', 'odom'):
            now = max(now, stamp_to_seconds(m.message.header.stamp))
            inputs.setdefault(stamp_to_seconds(m.message.header.stamp), []).append(
                (r, m.message))
        elif r == 'goal':
            inputs.setdefault(now, []).append((r, m.message))
        else:
            cmds.setdefault(stamp_to_seconds(m.message.header.stamp), []).append(
                cmd_from_msg(m.message))
    times = sorted(set(inputs) | set(cmds))
    if not cmds:
        return []
    # Before its first command the recorded node only collected inputs (and may have
    # missed some while discovery settled): hand them all over, then tick at t0.
    t0 = min(cmds)
    early = [item for t in times if t <= t0 for item in inputs.get(t, [])]
    goals = [item for item in early if item[0] == 'goal']
    early = goals[-1:] + [item for item in early if item[0] != 'goal']
    return [(t0, early, cmds[t0])] + [(t, inputs.get(t, []), cmds.get(t, []))
                                      for t in times if t > t0]


def replay_through_node(path: str, params: str, names: dict[str, str],
                        method: str | None = None, domain: int = 90) -> Comparison:
    """Run the bag through a planner_node process; see the module docstring."""
    check_topics(path, names)
    instants = _instants(path, names)
    env = join_domain(domain)
    ros_args = ['--params-file', str(Path(params).resolve()), '-p', 'use_sim_time:=true']
    if method:
        ros_args += ['-p', f'method:={method}']
    child = start('planner_node', ros_args, env, quiet=True)
    context = rclpy.Context()
    rclpy.init(context=context)
    node = Node('subapf_replay_player', context=context)
    try:
        return _play(node, context, child, instants, names)
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
          names: dict[str, str]) -> Comparison:
    executor = rclpy.executors.SingleThreadedExecutor(context=context)
    executor.add_node(node)
    answers: dict[float, tuple[float, float]] = {}
    node.create_subscription(TwistStamped, names['cmd_vel'], lambda m: answers.__setitem__(
        stamp_to_seconds(m.header.stamp), cmd_from_msg(m)), 100)
    statuses: list[str] = []
    node.create_subscription(String, '/subapf_planner/status', lambda m: statuses.append(m.data),
                             100)
    pubs = {'scan': node.create_publisher(LaserScan, names['scan'], qos_profile_sensor_data),
            'odom': node.create_publisher(Odometry, names['odom'], 10),
            'goal': node.create_publisher(PoseStamped, names['goal'], 10)}
    clock = node.create_publisher(Clock, '/clock', 10)
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
            # discovery completes on the node's side).
            end = time.monotonic() + 30.0
            while not statuses and time.monotonic() < end and child.poll() is None:
                clock.publish(Clock(clock=seconds_to_stamp(max(0.0, t - 0.05))))
                _pause(executor, 0.05)
        for r, msg in inputs:
            pubs[r].publish(msg)
        _pause(executor, FIRST_TICK_PAUSE if i == 0 else 0.0)
        clock.publish(Clock(clock=seconds_to_stamp(t)))
        if not cmds:
            continue
        end = time.monotonic() + ANSWER_TIMEOUT
        while t not in answers and time.monotonic() < end and child.poll() is None:
            executor.spin_once(timeout_sec=0.01)
        for v_w in cmds:
            times.append(t)
            recorded.append(v_w)
            replayed.append(answers.get(t, (np.nan, np.nan)))
    return Comparison(np.asarray(times), np.asarray(recorded, float).reshape(-1, 2),
                      np.asarray(replayed, float).reshape(-1, 2))
