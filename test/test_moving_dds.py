"""Over DDS: a world with moving obstacles through sim_node and planner_node; the true
positions reach other processes (moving_obstacles); the recorded run replays exactly."""

import subprocess
import sys

import numpy as np
import pytest
import yaml

from subapf_planner.bag.events import TAKEN_TOPIC, TAKEN_TYPE
from subapf_planner.bag.reader import topics
from subapf_planner.sim.world import parse_world

pytestmark = pytest.mark.dds

#: A walker crossing far ahead of the robot and back, and one that never comes near.
WORLD = {
    'name': 'walkers_dds', 'start': [0.0, 0.0, 0.0], 'goal': [3.0, 0.0], 'time_limit': 60,
    'bounds': [-1.0, -2.5, 4.0, 2.5],
    'moving': [{'circle': {'radius': 0.25}, 'path': [[0, 1.5, -2.0], [8, 1.5, 2.0]],
                'loop': True, 'offset': 4.0},
               {'box': {'size': [0.4, 0.3], 'yaw': 0.3}, 'path': [[0, 3.5, 2.0], [20, 3.5, 1.0]]}],
}


def run_and_replay(tmp_path, env, world_file, bag):
    """bringup of the world recorded to ``bag``, then subapf-replay of the bag:
    (bringup result, commands compared, commands within 1e-9)."""
    r = subprocess.run(
        [sys.executable, '-m', 'subapf_planner.tools.bringup', '--world', str(world_file),
         '--rate', '1', '--domain-id', env['ROS_DOMAIN_ID'], '--png',
         str(tmp_path / 'walkers.png'), '--record', str(bag)],
        env=env, capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert 'outcome ' in r.stdout, r.stdout + r.stderr
    rep = subprocess.run([sys.executable, '-m', 'subapf_planner.tools.replay', str(bag),
                          '--tolerance', '1e-9'], capture_output=True, text=True,
                         timeout=120, env=env)
    total = int(rep.stdout.split('commands compared: ')[1].split()[0])
    within = int(rep.stdout.split('within tolerance: ')[1].split()[0])
    return r, total, within


def test_moving_world_through_the_nodes_records_and_replays(tmp_path, bringup_env):
    from rosbags.highlevel import AnyReader
    world_file = tmp_path / 'walkers.yaml'
    world_file.write_text(yaml.safe_dump(WORLD))
    world = parse_world(WORLD)
    bag = tmp_path / 'walkers.mcap'
    # The run, walkers and all, replays through the same decision loop to the last bit,
    # but for the zero the planner sends when bringup stops it (no tick answers that):
    # each input at the tick the node took it (~/taken), however DDS ordered them
    r, total, within = run_and_replay(tmp_path, bringup_env, world_file, bag)
    assert topics(bag).get(TAKEN_TOPIC) == TAKEN_TYPE
    assert total >= 20 and within >= total - 1, (total, within)
    markers, tracked = [], 0
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic == '/moving_obstacles']
        assert conns and conns[0].msgtype == 'visualization_msgs/msg/MarkerArray'
        for conn, _t, raw in reader.messages(connections=conns):
            markers.append(reader.deserialize(raw, conn.msgtype))
        planner = [c for c in reader.connections if c.topic == '/subapf_planner/markers']
        for conn, _t, raw in reader.messages(connections=planner):
            for m in reader.deserialize(raw, conn.msgtype).markers:
                tracked += m.ns == 'tracks' and len(m.points) > 0
    # the planner tracked the walker (~/markers: tracks, velocity, prediction)
    assert tracked >= 3
    assert len(markers) >= 10
    for msg in markers[::5]:
        t = msg.markers[0].header.stamp.sec + 1e-9 * msg.markers[0].header.stamp.nanosec
        got = np.array([(m.pose.position.x, m.pose.position.y) for m in msg.markers])
        assert [m.header.frame_id for m in msg.markers] == ['odom', 'odom']
        # (either side of the stamp's nanosecond: a loop jumps back at its period)
        err = min(np.abs(got - [o.center for o in world.moving_at(t + dt)]).max()
                  for dt in (-1e-6, 1e-6))
        assert err < 1e-5, (t, got)
    assert (tmp_path / 'walkers.png').stat().st_size > 10_000
