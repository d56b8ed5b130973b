"""subapf-bringup as a new user meets it: every mistake in its arguments is one line
and exit code 2 before any process starts; a node that does not start is named; the
run is in the user's ROS_DOMAIN_ID (a private one only on request)."""

import argparse
import os
from pathlib import Path
import socket
import subprocess
import sys
import uuid

from conftest import PARAMS, WORLDS, domain_processes, marked_processes, wait_for
import pytest

from subapf_planner.tools.bringup import BringupError, choose_domain

BRINGUP = [sys.executable, '-m', 'subapf_planner.tools.bringup']
ROBOT_FILES = PARAMS.parent / 'robots'
#: The world's goal 1 m ahead of the start: a run of a few seconds.
SHORT = """\
name: short_hop
start: [0.0, 0.0, 0.0]
goal: [1.0, 0.0]
time_limit: 30
obstacles:
  - circle: {center: [-3.0, 3.0], radius: 0.3}
"""


def bringup(env: dict, *args: str, cwd: Path, timeout: float = 240) -> subprocess.CompletedProcess:
    """subapf-bringup with ``args``; afterwards no process it started is left."""
    marker = uuid.uuid4().hex
    r = subprocess.run([*BRINGUP, *args], env=dict(env, SUBAPF_TEST_MARKER=marker),
                       capture_output=True, text=True, timeout=timeout, cwd=cwd)
    wait_for(lambda: not marked_processes(marker), 10.0, 'no process of the bringup left')
    return r


def bad_params(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.node
@pytest.mark.parametrize('case', ['missing', 'a folder', 'not YAML', 'a bad value',
                                  'a robot of your own', 'another laser frame',
                                  'ROS_DOMAIN_ID', 'plot folder'])
def test_a_bad_argument_is_one_line_before_anything_starts(case, tmp_path, ros_env):
    world = str(WORLDS / 'fig6c_circle_in_front.yaml')
    env = dict(ros_env)
    args, expected = {
        'missing': (['--params', 'nowhere.yaml'], '--params nowhere.yaml: no such file'),
        'a folder': (['--params', str(tmp_path)], f'--params {tmp_path}: not a file'),
        'not YAML': (['--params', bad_params(tmp_path, 'yaml.yaml', 'subapf_planner: [oops\n')],
                     'cannot read parameters'),
        'a bad value': (['--params', bad_params(
            tmp_path, 'value.yaml', 'subapf_planner:\n  ros__parameters:\n'
            '    max_linear_velocity: fast\n')], 'max_linear_velocity: expected a number'),
        'a robot of your own': (['--params', bad_params(
            tmp_path, 'own.yaml', 'subapf_planner:\n  ros__parameters:\n    robot: other\n')],
            'is for a robot of your own (robot: other), which the simulator cannot be; '
            'give --robot'),
        'another laser frame': (['--params', bad_params(
            tmp_path, 'laser.yaml', 'subapf_planner:\n  ros__parameters:\n'
            '    laser_frame: laser\n')], 'laser_frame is laser, but the simulator (the '
            'burger) sends its scans in base_scan'),
        'ROS_DOMAIN_ID': ([], "ROS_DOMAIN_ID='moon' is not a domain id"),
        'plot folder': (['--png', str(tmp_path / 'no' / 'run.png')], 'cannot write in'),
    }[case]
    if case == 'ROS_DOMAIN_ID':
        env['ROS_DOMAIN_ID'] = 'moon'
    r = bringup(env, '--world', world, *args, cwd=tmp_path)
    assert r.returncode == 2, r.stdout + r.stderr
    assert r.stdout == ''   # it said nothing of a run: none began
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith('subapf-bringup: error: '), r.stderr
    assert expected in lines[0], lines[0]
    if case != 'ROS_DOMAIN_ID':
        assert domain_processes().get(os.getpid()) is None
        assert [pid for pid, d in domain_processes().items()
                if d == int(ros_env['ROS_DOMAIN_ID'])] == []


@pytest.mark.core
def test_the_domain_comes_from_the_environment_unless_asked_otherwise(monkeypatch):
    def args(domain_id=None, private=False):
        return argparse.Namespace(domain_id=domain_id, private_domain=private)
    assert choose_domain(args(), {}) == (0, "ROS_DOMAIN_ID unset: ROS's default")
    assert choose_domain(args(), {'ROS_DOMAIN_ID': '150'}) == (150, 'ROS_DOMAIN_ID')
    assert choose_domain(args(7), {'ROS_DOMAIN_ID': '150'}) == (7, '--domain-id')
    import subapf_planner.ros.processes as processes
    monkeypatch.setattr(processes, 'domains_in_use', lambda: set(range(1, 100)))
    assert choose_domain(args(private=True), {'ROS_DOMAIN_ID': '150'}) == \
        (100, 'private: --private-domain')   # the one no process uses
    for bad in ('-1', '233', 'x'):
        with pytest.raises(BringupError, match='is not a domain id'):
            choose_domain(args(), {'ROS_DOMAIN_ID': bad})
    with pytest.raises(BringupError, match=r'--domain-id must be in \[0, 101\]'):
        choose_domain(args(500), {})


@pytest.mark.dds
def test_the_run_is_in_the_users_domain(tmp_path, ros_env):
    """No --domain-id: the nodes join ROS_DOMAIN_ID, where a node of the user's (here)
    hears the simulator's clock and the outcome, and the bringup says which domain."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rosgraph_msgs.msg import Clock
    from std_msgs.msg import String

    from subapf_planner.ros.qos import LATCHED
    domain = int(ros_env['ROS_DOMAIN_ID'])
    world = tmp_path / 'short_hop.yaml'
    world.write_text(SHORT)
    context = rclpy.Context()
    rclpy.init(context=context)   # the user's domain: ros_env set it here too
    node = rclpy.create_node('rviz_stand_in', context=context)
    heard = {'clock': 0, 'outcome': []}
    node.create_subscription(Clock, '/clock', lambda m: heard.update(clock=heard['clock'] + 1),
                             10)
    node.create_subscription(String, '/sim_outcome',
                             lambda m: heard['outcome'].append(m.data), LATCHED)
    ex = SingleThreadedExecutor(context=context)
    ex.add_node(node)
    marker = uuid.uuid4().hex
    # at real time (--rate 1) the run lasts a few seconds: discovery between the user's
    # node and the simulator has that long even on a loaded machine (at 4x, 1.5 s was
    # too short once; the latched outcome leaves with its publisher)
    p = subprocess.Popen([*BRINGUP, '--world', str(world), '--rate', '1', '--png',
                          str(tmp_path / 'run.png')], env=dict(ros_env, SUBAPF_TEST_MARKER=marker),
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         cwd=tmp_path)
    try:
        wait_for(lambda: (ex.spin_once(timeout_sec=0.05), p.poll() is not None)[1], 180,
                 'the bringup to end', interval=0.0)
    finally:
        if p.poll() is None:
            p.kill()
        out = p.communicate(timeout=60)[0]
        node.destroy_node()
        rclpy.try_shutdown(context=context)
    assert p.returncode == 0, out
    assert f'domain {domain} (ROS_DOMAIN_ID)' in out.splitlines()[0], out
    assert heard['clock'] > 0 and heard['outcome'] == ['reached'], (heard, out)
    wait_for(lambda: not marked_processes(marker), 10.0, 'no process of the bringup left')


@pytest.mark.core
def test_the_robot_comes_from_the_option_else_the_params_file(tmp_path):
    """--robot wins and brings its config/robots/ file after the params file; a params
    file written for a robot is the planner's as it is, and that robot is simulated."""
    from subapf_planner.tools.bringup import check_params
    values, robot, files = check_params(str(PARAMS))
    assert (robot, files) == ('burger', (str(PARAMS),))
    values, robot, files = check_params(str(PARAMS), 'jackal')
    assert robot == 'jackal' and files == (str(PARAMS), str(ROBOT_FILES / 'jackal.yaml'))
    assert values['max_linear_velocity'] == 2.0 and values['laser_frame'] == 'front_laser'
    values, robot, files = check_params(str(ROBOT_FILES / 'waffle_pi.yaml'))
    assert robot == 'waffle_pi' and files == (str(ROBOT_FILES / 'waffle_pi.yaml'),)
    own = bad_params(tmp_path, 'tb4.yaml', 'subapf_planner:\n  ros__parameters:\n'
                     '    robot: turtlebot4\n    laser_frame: base_scan\n')
    with pytest.raises(BringupError, match='laser_frame is base_scan, but the simulator '
                       r'\(the turtlebot4\) sends its scans in rplidar_link'):
        check_params(own)


@pytest.mark.dds
def test_the_jackal_closes_the_loop_over_dds(tmp_path, bringup_env):
    """--robot jackal: the simulator is a Jackal (its rectangle, its 270 degree lidar on
    front_laser at 50 Hz, base_link, Twist on cmd_vel) and the planner has its file (20 Hz,
    2 m/s, the footprint): the goal 2 m ahead is reached in a few simulated seconds."""
    world = tmp_path / 'short_hop.yaml'
    world.write_text(SHORT.replace('goal: [1.0, 0.0]', 'goal: [2.0, 0.0]'))
    r = bringup(bringup_env, '--world', str(world), '--robot', 'jackal', '--rate', '2',
                '--png', str(tmp_path / 'run.png'), cwd=tmp_path, timeout=180)
    assert r.returncode == 0, r.stdout + r.stderr
    assert 'robot jackal' in r.stdout.splitlines()[0], r.stdout
    done = [line for line in r.stdout.splitlines() if 'outcome reached' in line]
    assert done, r.stdout
    seconds = float(done[0].split('simulated time ')[1].split(' s')[0])
    assert seconds < 8.0, done   # at 2 m/s, where the burger would take 10 s and more


@pytest.mark.dds
def test_a_node_that_does_not_start_is_named(tmp_path, bringup_env):
    """foxglove_node cannot bind its port: its own one-line message, then the bringup's,
    exit 2, the other nodes stopped; no traceback from any process."""
    world = tmp_path / 'short_hop.yaml'
    world.write_text(SHORT)
    with socket.socket() as taken:
        taken.bind(('127.0.0.1', 0))
        taken.listen()
        port = taken.getsockname()[1]
        r = bringup(bringup_env, '--world', str(world), '--rate', '4', '--domain-id',
                    bringup_env['ROS_DOMAIN_ID'], '--foxglove', str(port), cwd=tmp_path)
    text = r.stdout + r.stderr
    assert r.returncode == 2, text
    assert r.stderr.splitlines()[-1] == ('subapf-bringup: error: foxglove_node did not start '
                                         '(exit code 2); its own message is above'), text
    assert f'subapf-foxglove: port: cannot serve on 127.0.0.1:{port}' in text
    assert 'Traceback' not in text and 'Fatal Python error' not in text
    assert [pid for pid, d in domain_processes().items()
            if d == int(bringup_env['ROS_DOMAIN_ID'])] == []
