"""``subapf-nodeperf``: the nodes' figures over real DDS (a benchmark, not a test).

1. planner_node fed 5 Hz scans (from the simulator, 360 beams) and 20 Hz
   odometry on a private localhost domain, wall-clock time, a goal it never
   reaches: planning-tick-to-cmd_vel latency at the receiver (cmd_vel is
   stamped with its planning tick, so this is planning + publish + DDS),
   median and p99; planner CPU per cycle (process CPU time / cycles, from
   /proc); resident memory (VmRSS) at start and end.
2. The same decision loop in this process on the same inputs, no DDS: its work per
   cycle (tick and the work after the command) back to back, and with the node's idle
   period between cycles. The node works in a burst every 0.2 s; on this machine such
   a burst runs two to three times slower than the same work repeated at once (likely
   caches and predictors gone cold while it sleeps: the ratio is the machine's, not
   the code's), which is most of the gap between the loop's figures and the node's
   CPU per cycle.
3. sim_node at ``rate`` 100 (as fast as it goes): real-time factor
   (simulated seconds per wall second, first /clock to the time-limit outcome), and the in-process
   simulator's real-time factor with the planner in the loop (episode.py).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
import os
from pathlib import Path
import random
import sys
import time

import numpy as np

from ..ros.conversions import stamp_to_seconds
from ..ros.paths import default_params_file, shipped_worlds_dir
from ..ros.processes import join_domain, rss_mib, start, stop


def proc_cpu_seconds(pid: int) -> float:
    """utime + stime of a process [s] (Linux /proc)."""
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


#: The planner node's topics beside cmd_vel, each subscribed in the "watched" run.
VIEWS = (('markers', 'visualization_msgs.msg', 'MarkerArray'),
         ('map', 'nav_msgs.msg', 'OccupancyGrid'), ('plan', 'nav_msgs.msg', 'Path'),
         ('correction', 'geometry_msgs.msg', 'TransformStamped'),
         ('status', 'std_msgs.msg', 'String'))


def node_inputs() -> tuple:
    """The scan and odometry pose the measurements feed: the simulator's, standing in
    the shipped cluttered_field world (1 cm range noise)."""
    from ..sim.simulator import RobotSim, SimConfig
    from ..sim.world import load_world

    world = load_world(shipped_worlds_dir() / 'cluttered_field.yaml')
    with RobotSim(world, SimConfig(range_noise=0.01)) as sim:
        return sim.scan(), sim.odometry()[0]


def planner_figures(seconds: float, domain: int, watched: bool = False) -> dict[str, float]:
    """The planner node's figures; ``watched``: with a subscriber on each of VIEWS (the
    visualisation is built and sent only then)."""
    import importlib

    from geometry_msgs.msg import PoseStamped, TwistStamped
    from nav_msgs.msg import Odometry
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan

    from ..ros.conversions import odom_to_msg, scan_to_msg
    from ..ros.qos import LATCHED

    scan, pose = node_inputs()
    env = join_domain(domain)
    child = start('planner_node', ['--params-file', str(default_params_file()),
                                   '-p', 'progress_timeout:=600.0'], env, quiet=True)
    rclpy.init()
    node = rclpy.create_node('subapf_nodeperf')
    latencies: list[float] = []

    def on_cmd(msg: TwistStamped) -> None:
        sent = stamp_to_seconds(msg.header.stamp)
        latencies.append(node.get_clock().now().nanoseconds * 1e-9 - sent)
    node.create_subscription(TwistStamped, 'cmd_vel', on_cmd, 10)
    views = {name: 0 for name, _, _ in VIEWS}
    for name, module, kind in VIEWS if watched else ():
        qos = LATCHED if name == 'map' else 10
        node.create_subscription(getattr(importlib.import_module(module), kind),
                                 f'/subapf_planner/{name}',
                                 lambda _m, n=name: views.__setitem__(n, views[n] + 1), qos)
    scan_pub = node.create_publisher(LaserScan, 'scan', qos_profile_sensor_data)
    odom_pub = node.create_publisher(Odometry, 'odom', 10)
    goal_pub = node.create_publisher(PoseStamped, 'goal_pose', 10)
    try:
        while goal_pub.get_subscription_count() == 0 or node.count_publishers('cmd_vel') == 0 \
                or any(node.count_publishers(f'/subapf_planner/{n}') == 0
                       for n, _, _ in VIEWS if watched):
            rclpy.spin_once(node, timeout_sec=0.05)
        goal = PoseStamped()
        goal.header.frame_id = 'odom'
        goal.pose.position.x = goal.pose.position.y = 50.0
        goal_pub.publish(goal)
        cpu0, rss0, t0 = proc_cpu_seconds(child.pid), rss_mib(child.pid), time.monotonic()
        next_odom = next_scan = time.monotonic()
        while time.monotonic() - t0 < seconds:
            now = time.monotonic()
            stamp = node.get_clock().now().nanoseconds * 1e-9
            if now >= next_odom:
                odom_pub.publish(odom_to_msg(pose, (0.0, 0.0), stamp))
                next_odom += 0.05
            if now >= next_scan:
                scan_pub.publish(scan_to_msg(replace(scan, stamp=stamp), 'base_scan'))
                next_scan += 0.2
            rclpy.spin_once(node, timeout_sec=0.005)
        cycles = len(latencies)
        cpu = proc_cpu_seconds(child.pid) - cpu0
        rss1 = rss_mib(child.pid)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
        stop([child])
    ms = np.asarray(latencies[1:]) * 1e3
    return {'cycles': cycles, 'latency_ms_median': float(np.median(ms)),
            'latency_ms_p99': float(np.percentile(ms, 99)),
            'cpu_ms_per_cycle': 1e3 * cpu / max(cycles, 1), 'rss_mib_start': rss0,
            'rss_mib_end': rss1, 'views': views}


def loop_cycle_ms(cycles: int = 50, idle: float = 0.0) -> float:
    """Median wall time [ms] of the decision loop's cycle (tick, then after_tick) on
    planner_figures' inputs (a scan every cycle, odometry four times a cycle, the same
    goal), in this process, with ``idle`` [s] of sleep between cycles (the node's: its
    period); the first ten cycles (the memory filling) not counted."""
    from ..core.config import load_config
    from ..core.loop import DecisionLoop, Supervision

    scan, pose = node_inputs()
    loop = DecisionLoop(load_config(default_params_file()), Supervision(progress_timeout=600.0))
    loop.set_goal(np.array([50.0, 50.0]))
    period = loop.cfg.period
    times = []
    for i in range(cycles + 10):
        now = 100.0 + i * period
        for k in range(4):
            loop.update_odom(now + k * period / 4, pose, now + k * period / 4)
        loop.update_scan(replace(scan, stamp=now + period / 2), now + period / 2)
        time.sleep(idle)
        t0 = time.perf_counter()
        loop.tick(now + period)
        loop.after_tick()
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times[10:]))


def sim_node_rtf(domain: int) -> float:
    """Simulated seconds per wall second of sim_node at rate 100 with no robot command:
    from the first /clock seen to the 'timeout' outcome at the world's time limit."""
    import rclpy
    from rosgraph_msgs.msg import Clock
    from std_msgs.msg import String

    from ..ros.sim_node import LATCHED
    from ..sim.world import load_world
    env = join_domain(domain)
    world_file = shipped_worlds_dir() / 'fig6d_big_wall.yaml'
    limit = load_world(world_file).time_limit
    child = start('sim_node', ['-p', f'world:={world_file}', '-p', 'rate:=100.0'], env,
                  quiet=True)
    rclpy.init()
    node = rclpy.create_node('subapf_nodeperf_clock')
    first: list[tuple[float, float]] = []
    done: list[float] = []
    node.create_subscription(String, 'sim_outcome', lambda m: done.append(time.monotonic()),
                             LATCHED)
    sub = node.create_subscription(Clock, '/clock', lambda m: first.append(
        (time.monotonic(), stamp_to_seconds(m.clock))), 1)
    try:
        end = time.monotonic() + 120.0
        while not done and time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.05)
            if first and sub is not None:
                node.destroy_subscription(sub)   # one clock is all we need
                sub = None
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
        stop([child])
    if not first or not done:
        return float('nan')
    return (limit - first[0][1]) / (done[0] - first[0][0])


def episode_rtf() -> float:
    from ..core.config import PlannerConfig
    from ..sim.episode import run_episode
    from ..sim.world import load_world
    world = load_world(shipped_worlds_dir() / 'fig6d_big_wall.yaml')
    t0 = time.perf_counter()
    result = run_episode(world, PlannerConfig())
    return result.time_s / (time.perf_counter() - t0)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog='subapf-nodeperf', description=__doc__.splitlines()[0])
    p.add_argument('--seconds', type=float, default=30.0, help='duration of each measurement')
    p.add_argument('--domain-id', type=int, default=None)
    args = p.parse_args(argv)
    domain = args.domain_id if args.domain_id is not None else random.randint(1, 100)
    for watched in (False, True):
        f = planner_figures(args.seconds, domain, watched)
        seen = ', '.join(f'{n} {c}' for n, c in f['views'].items())
        print(f'planner_node, {f"watched ({seen} messages)" if watched else "unwatched"}: '
              f'{f["cycles"]} cycles; tick-to-cmd_vel latency over DDS median '
              f'{f["latency_ms_median"]:.2f} ms, p99 {f["latency_ms_p99"]:.2f} ms; '
              f'CPU {f["cpu_ms_per_cycle"]:.2f} ms per cycle; RSS '
              f'{f["rss_mib_start"]:.1f} -> {f["rss_mib_end"]:.1f} MiB')
    warm, idle = loop_cycle_ms(), loop_cycle_ms(idle=0.2)
    print(f'decision loop in-process on the same inputs: {warm:.2f} ms a cycle back to back, '
          f'{idle:.2f} ms with 0.2 s idle between cycles as in the node ({idle / warm:.1f}x: '
          "this machine's cost of working in bursts)")
    print(f'sim_node fast mode (rate 100): real-time factor {sim_node_rtf(domain):.1f}x')
    print(f'in-process simulator + planner (fig6d): real-time factor {episode_rtf():.1f}x')
    return 0


if __name__ == '__main__':
    sys.exit(main())
