"""TF for real, with tf2_msgs built where no ROS install provides it (conftest's
tf2_msgs_built): sim_node's /tf and /tf_static (REP-105 frames, stamps), and the
planner reading the laser mounting from /tf_static over its parameters."""

import json
import subprocess
import sys
import time

from conftest import REPO, WORLDS, with_paths
import pytest

from subapf_planner.core.robot import BURGER
from subapf_planner.ros.processes import start, stop

pytestmark = pytest.mark.dds

WORLD = WORLDS / 'fig6c_circle_in_front.yaml'


def test_sim_node_publishes_tf_and_tf_static(ros_env, tf2_msgs_built, tmp_path):
    env = with_paths(ros_env, tf2_msgs_built)
    sim = start('sim_node', ['-p', f'world:={WORLD}', '-p', 'rate:=2.0'], env,
                log=tmp_path / 'sim.log')
    try:
        r = subprocess.run([sys.executable, str(REPO / 'test' / 'tf_listen.py'), '20'],
                           env=env, capture_output=True, text=True, timeout=90)
    finally:
        stop([sim])
    assert r.returncode == 0, r.stderr + (tmp_path / 'sim.log').read_text()
    got = json.loads(r.stdout)
    static = {(t['parent'], t['child']): t for t in got['tf_static']}
    assert set(static) == {('base_footprint', 'base_link'), ('base_link', 'base_scan')}
    assert static['base_footprint', 'base_link']['xyz'] == pytest.approx(
        [0.0, 0.0, BURGER.base_link_height])
    assert static['base_link', 'base_scan']['xyz'] == pytest.approx(
        [BURGER.laser.x, BURGER.laser.y, BURGER.laser.z - BURGER.base_link_height])
    assert len(got['tf']) >= 20
    assert {(t['parent'], t['child']) for t in got['tf']} == {('odom', 'base_footprint')}
    # each /tf is the odometry of the same tick: same stamp (simulated time), same pose
    odom = {o['stamp']: o for o in got['odom']}
    matched = [t for t in got['tf'] if t['stamp'] in odom]
    assert len(matched) >= 10 and all(t['stamp'] > 0.0 for t in matched)
    for t in matched:
        o = odom[t['stamp']]
        assert (o['frame'], o['child']) == ('odom', 'base_footprint')
        assert t['xyz'][:2] == pytest.approx(o['xy'], abs=1e-9)
        assert t['q'][2:] == pytest.approx(o['q'], abs=1e-9)
    stamps = [t['stamp'] for t in got['tf']]
    assert stamps == sorted(stamps)


def wait_for_line(log, needle: str, timeout: float = 60.0) -> str:
    """The first line of the file ``log`` holding ``needle`` (waits for it)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        for line in log.read_text().splitlines() if log.exists() else ():
            if needle in line:
                return line
        time.sleep(0.2)
    raise AssertionError(f'no "{needle}" in {log}:\n{log.read_text()}')


def test_the_laser_mounting_from_tf_static_wins_over_the_parameters(ros_env, tf2_msgs_built,
                                                                    tmp_path):
    env = with_paths(ros_env, tf2_msgs_built)
    wrong = ['-p', 'laser_x:=0.5', '-p', 'laser_y:=0.1', '-p', 'laser_yaw:=0.3']
    planner = start('planner_node', wrong, env, log=tmp_path / 'planner.log')
    sim = None
    try:
        line = wait_for_line(tmp_path / 'planner.log', 'laser mounting from parameters')
        assert '(0.5, 0.1, 0.3)' in line and 'until /tf_static' in line
        sim = start('sim_node', ['-p', f'world:={WORLD}'], env, log=tmp_path / 'sim.log')
        line = wait_for_line(tmp_path / 'planner.log', 'laser mounting from /tf_static')
    finally:
        stop([p for p in (planner, sim) if p is not None])
    assert '(base_footprint -> base_scan)' in line
    x, y, yaw = BURGER.laser.planar
    assert f'x={x:.3f} m y={y:.3f} m yaw={yaw:.3f} rad' in line


def test_without_tf2_msgs_the_planner_says_the_parameters_give_the_mounting(ros_env,
                                                                            tmp_path):
    planner = start('planner_node', ['-p', 'laser_x:=0.5'], ros_env,
                    log=tmp_path / 'planner.log')
    try:
        line = wait_for_line(tmp_path / 'planner.log', 'laser mounting from parameters')
    finally:
        stop([planner])
    assert '0.5' in line and 'tf2_msgs not installed' in line
