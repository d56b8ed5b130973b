"""Real multi-process DDS runs: bringup over two worlds, recorded MCAP read by rosbags."""

import json
import os
from pathlib import Path
import selectors
import signal
import subprocess
import sys
import time

from conftest import PARAMS, WORLDS, colour_pixels, domain_processes, wait_for
import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.sim.episode import run_episode
from subapf_planner.sim.world import load_world
from subapf_planner.tools.plots import METHOD_STYLE

pytestmark = pytest.mark.dds


def bringup(tmp_path: Path, world: str, env: dict[str, str], *extra: str,
            timeout: float = 240):
    """subapf-bringup on the domain of ``env`` (the bringup_env fixture)."""
    return subprocess.run(
        [sys.executable, '-m', 'subapf_planner.tools.bringup', '--world', str(WORLDS / world),
         '--rate', '5', '--domain-id', env['ROS_DOMAIN_ID'], '--png', str(tmp_path / 'run.png'),
         *extra], env=env, capture_output=True, text=True, timeout=timeout, cwd=tmp_path)


@pytest.mark.parametrize('world', ['fig6c_circle_in_front.yaml', 'fig6d_big_wall.yaml'])
def test_bringup_reaches_goal_like_the_in_process_run(tmp_path, world, bringup_env):
    bag = tmp_path / 'run.mcap'
    result = bringup(tmp_path, world, bringup_env, '--record', str(bag))
    assert result.returncode == 0, result.stdout + result.stderr
    assert 'outcome reached' in result.stdout
    # the plot shows the driven path (the method's colour: > 300 pixels, its legend line
    # alone has about 50), the obstacles (grey fill) and the start, goal and axes (black)
    png = tmp_path / 'run.png'
    drawn = {what: colour_pixels(png, colour) for what, colour in (
        ('path', METHOD_STYLE['subharmonic_sampling'][0]), ('obstacles', '0.55'),
        ('markers and axes', 'black'))}
    assert drawn['path'] > 300 and drawn['obstacles'] > 5000 \
        and drawn['markers and axes'] > 1000, drawn
    in_process = run_episode(load_world(WORLDS / world), PlannerConfig())
    assert in_process.outcome == 'reached'
    check_bag_with_rosbags(bag)


def check_bag_with_rosbags(bag: Path, outcome: bool = True, whole_run: bool = True):
    """An independent reader (rosbags) opens the MCAP and decodes every topic's CDR;
    ``whole_run``: the bag holds the whole run (its counts), else only some of it."""
    from rosbags.highlevel import AnyReader
    with AnyReader([bag]) as reader:
        topics = {c.topic: c.msgtype for c in reader.connections}
        assert topics['/scan'] == 'sensor_msgs/msg/LaserScan'
        assert topics['/cmd_vel'] == 'geometry_msgs/msg/TwistStamped'
        counts = {}
        last = {}
        for conn, _t, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            last[conn.topic] = msg
    if whole_run:
        assert counts['/scan'] > 50 and counts['/odom'] > 100 and counts['/cmd_vel'] > 50
    assert min(counts[t] for t in ('/scan', '/odom', '/cmd_vel')) >= 1
    assert counts['/goal_pose'] >= 1
    if outcome:
        assert counts['/subapf_planner/markers'] > 10
        assert last['/sim_outcome'].data == 'reached'
    assert len(last['/scan'].ranges) == 360 and last['/scan'].header.frame_id == 'base_scan'
    assert np.isfinite(last['/odom'].pose.pose.position.x)


def test_bad_world_and_bad_parameters_exit_with_clear_errors(tmp_path, ros_env):
    env = ros_env
    bad = tmp_path / 'bad.yaml'
    bad.write_text('name: x\nstart: [0, 0]\ngoal: [1, 1]\n')
    r = subprocess.run([sys.executable, '-m', 'subapf_planner.tools.bringup', '--world', str(bad)],
                       capture_output=True, text=True, timeout=60, env=env)
    assert r.returncode == 2 and 'start: expected a list of 3 numbers' in r.stderr
    r = subprocess.run([sys.executable, '-m', 'subapf_planner.tools.bringup', '--world',
                        str(WORLDS / 'u_trap.yaml'), '--domain-id', '500'],
                       capture_output=True, text=True, timeout=60, env=env)
    assert r.returncode == 2 and '--domain-id must be in [0, 101]' in r.stderr
    r = subprocess.run([sys.executable, '-m', 'subapf_planner.ros.planner_node', '--ros-args',
                        '--params-file', str(PARAMS), '-p', 'method:=teleport'],
                       capture_output=True, text=True, timeout=60, env=env)
    assert r.returncode == 2 and "method: 'teleport' is not one of" in r.stderr
    for bad in ('danger_distance:=5.0', 'danger_distance:=wide', 'num_samples:=2.5'):
        r = subprocess.run([sys.executable, '-m', 'subapf_planner.ros.planner_node', '--ros-args',
                            '-p', bad], capture_output=True, text=True, timeout=60, env=env)
        assert r.returncode == 2 and bad.split(':=')[0] in r.stderr, (bad, r.stderr)
        assert 'Traceback' not in r.stderr


def test_standalone_recorder_finalises_on_sigint_and_replays(tmp_path, bringup_env):
    """Run with the paper's memoryless method: with the default's occupancy memory a
    replay is exact only when the live node got every scan before its tick, which a
    loaded machine at 5x does not give (docs/recording.md)."""
    env = bringup_env
    paper = tmp_path / 'paper.yaml'
    paper.write_text(PARAMS.read_text().replace('attraction_field: geodesic',
                                                'attraction_field: euclidean'))
    bag = tmp_path / 'rec.mcap'
    rec = subprocess.Popen([sys.executable, '-m', 'subapf_planner.tools.record', '--topics',
                            '/scan', '/odom', '/cmd_vel', '/goal_pose', '/clock', '-o', str(bag)],
                           env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        log = subscribe_recorder_first(rec)
        # the bringup records the run too: the reference the recorder is measured by
        result = bringup(tmp_path, 'fig6c_circle_in_front.yaml', env, '--record',
                         str(tmp_path / 'ref.mcap'), '--params', str(paper))
        assert result.returncode == 0, result.stdout + result.stderr
    finally:
        rec.send_signal(signal.SIGINT)
        out, err = rec.communicate(timeout=30)
    assert rec.returncode == 0, log + err
    assert 'messages in' in out
    # it holds the run from DDS discovery on, and its best-effort scans can drop under
    # load (seen in CI: 46 scans); what it must not lose is checked below
    check_bag_with_rosbags(bag, outcome=False, whole_run=False)
    replays = {name: replay_summary(tmp_path / name, paper, env)
               for name in ('rec.mcap', 'ref.mcap')}
    total, silent, within = replays['rec.mcap']
    # A recorder in another process matches the run's publishers only once DDS discovery
    # has seen the bringup's processes, which on a loaded machine takes a while of the 5x
    # simulated run (seen: the first 8 commands idle, 28 on a loaded CI machine, all
    # before its first one). Once matched, a reliable subscription with a deep queue
    # must lose nothing: every command the bringup's own bag holds from the recorder's
    # first command on is in the recorder's bag.
    stamps = {name: cmd_vel_stamps(tmp_path / name) for name in ('rec.mcap', 'ref.mcap')}
    assert stamps['rec.mcap'], stamps
    after_match = [s for s in stamps['ref.mcap'] if s >= stamps['rec.mcap'][0]]
    assert len(after_match) >= 10, stamps
    assert not set(after_match) - set(stamps['rec.mcap']), stamps
    # silent at most on the zero the planner published on shutdown, after the goal was
    # reached: no planning tick answers it
    assert total >= 10 and silent <= 1, replays
    # A recorder in another process sees the inputs in its own order, not always in the
    # node's (DDS orders messages per topic, not across topics), and a loaded machine
    # makes that worse: the standalone recorder's bag must replay about as faithfully
    # as the bringup's own recording of the same run (idle: 99 of 99 for both).
    ref_total, _, ref_within = replays['ref.mcap']
    assert within / total >= ref_within / ref_total - 0.1 and within >= 0.75 * total, replays


def replay_summary(bag: Path, params: Path, env: dict[str, str]) -> tuple[int, int, int]:
    """(commands compared, replay silent on, within 1e-9) of subapf-replay on ``bag``."""
    r = subprocess.run([sys.executable, '-m', 'subapf_planner.tools.replay', str(bag),
                        '--tolerance', '1e-9', '--params', str(params)], capture_output=True,
                       text=True, timeout=120, env=env)
    # exit 0 exactly when no command diverged, 1 otherwise (2: the bag was unusable)
    exact = 'first divergence: none' in r.stdout
    assert r.returncode == (0 if exact else 1), r.stdout + r.stderr
    total = int(r.stdout.split('commands compared: ')[1].split()[0])
    silent = int(r.stdout.split('replay silent on ')[1].split(';')[0])
    within = int(r.stdout.split('within tolerance: ')[1].split()[0])
    return total, silent, within


def cmd_vel_stamps(bag: Path) -> list[int]:
    """Header stamps [ns] of the bag's /cmd_vel commands, in log order."""
    from rosbags.highlevel import AnyReader
    with AnyReader([bag]) as reader:
        stamp = (reader.deserialize(raw, c.msgtype).header.stamp
                 for c, _t, raw in reader.messages([c for c in reader.connections
                                                    if c.topic == '/cmd_vel']))
        return [s.sec * 1_000_000_000 + s.nanosec for s in stamp]


def subscribe_recorder_first(rec: subprocess.Popen, timeout: float = 60.0) -> str:
    """Stand-in publishers with the graph's QoS until the recorder (which subscribes to a
    topic once it sees a publisher) records all five topics, so it misses nothing of
    the real run; returns the recorder's log so far."""
    from geometry_msgs.msg import PoseStamped, TwistStamped
    from nav_msgs.msg import Odometry
    import rclpy
    from rclpy.qos import qos_profile_sensor_data
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import LaserScan

    from subapf_planner.ros.qos import LATCHED
    context = rclpy.Context()
    rclpy.init(context=context)   # on the test's domain (bringup_env set it)
    node = rclpy.create_node('stand_in', context=context)
    for msg, topic, qos in ((LaserScan, '/scan', qos_profile_sensor_data),
                            (Odometry, '/odom', 10), (TwistStamped, '/cmd_vel', 10),
                            (PoseStamped, '/goal_pose', LATCHED), (Clock, '/clock', 10)):
        node.create_publisher(msg, topic, qos)
    log = b''
    deadline = time.monotonic() + timeout
    try:
        with selectors.DefaultSelector() as sel:   # raw reads: no text buffer to miss
            sel.register(rec.stderr.fileno(), selectors.EVENT_READ)
            while log.count(b'recording /') < 5:
                assert time.monotonic() < deadline and rec.poll() is None, log.decode()
                if sel.select(timeout=0.5):
                    log += os.read(rec.stderr.fileno(), 65536)
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    return log.decode()


def test_short_soak_reports_and_passes(tmp_path, bringup_env):
    # (subapf-soak picks its runs' domains itself, from --seed: this lease only keeps
    # the soak's own process off the other tests' domains)
    env = bringup_env
    r = subprocess.run([sys.executable, '-m', 'subapf_planner.tools.soak', '--runs', '1',
                        '--rate', '2', '--worlds',
                        str(WORLDS / 'fig6c_circle_in_front.yaml'), '--out', str(tmp_path)],
                       capture_output=True, text=True, timeout=240, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    doc = json.loads((tmp_path / 'soak.json').read_text())
    assert doc['summary']['runs'] == 1 and doc['summary']['collisions'] == 0
    assert doc['runs'][0]['outcome'] == 'reached'
    assert set(doc['runs'][0]['rss_mib']) == {'sim_node', 'planner_node'}
    assert (tmp_path / 'logs').is_dir()


def processes_in_domain(domain: int) -> list[int]:
    return [pid for pid, d in domain_processes().items() if d == domain]


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM])
def test_bringup_interrupted_stops_everything_and_finalises_the_bag(tmp_path, sig,
                                                                   bringup_env):
    from geometry_msgs.msg import TwistStamped
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    env = bringup_env
    domain = int(env['ROS_DOMAIN_ID'])
    bag = tmp_path / 'cut.mcap'
    # the run's forward commands, heard as the recorder hears them (reliable, the domain)
    context = rclpy.Context()
    rclpy.init(context=context)   # on the test's domain (bringup_env set it)
    node = rclpy.create_node('cmd_listener', context=context)
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(node)
    forward = []
    node.create_subscription(TwistStamped, '/cmd_vel', lambda m: forward.append(m)
                             if m.twist.linear.x > 0.0 else None, 100)
    p = subprocess.Popen([sys.executable, '-m', 'subapf_planner.tools.bringup', '--world',
                          str(WORLDS / 'fig6d_big_wall.yaml'), '--domain-id', str(domain),
                          '--record', str(bag), '--png', str(tmp_path / 'p.png')],
                         env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = []
    try:
        for line in p.stdout:
            lines.append(line)
            if 'planner driving' in line:
                break
        # the check below can see them: bringup, sim_node and planner_node are in the domain
        assert len(processes_in_domain(domain)) >= 3, ''.join(lines)

        def driven():
            ex.spin_once(timeout_sec=0.05)
            assert p.poll() is None, ''.join(lines)
            return len(forward) >= 5
        # a second of driving (5 forward commands at 5 Hz) before the interruption
        wait_for(driven, 30.0, lambda: f'5 forward commands on /cmd_vel ({len(forward)} '
                 f'came): {"".join(lines)}', interval=0.0)
    except BaseException:
        p.send_signal(signal.SIGINT)   # the bringup stops its nodes
        p.communicate(timeout=60)
        raise
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    p.send_signal(sig)
    out, _ = p.communicate(timeout=60)
    text = ''.join(lines) + out
    assert p.returncode == 1, text
    assert 'outcome interrupted' in text and 'Traceback' not in text
    assert processes_in_domain(domain) == []
    from rosbags.highlevel import AnyReader
    with AnyReader([bag]) as reader:
        cmds = [c for c in reader.connections if c.topic == '/cmd_vel']
        forward = [reader.deserialize(raw, c.msgtype).twist.linear.x
                   for c, _, raw in reader.messages(connections=cmds)]
    # the bag was finalised with the driving in it (a cut bag does not open)
    assert sum(v > 0.0 for v in forward) >= 3, forward
