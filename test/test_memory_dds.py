"""Over DDS: the geodesic default drives a generated maze to its goal, and the planner's
memory (~/map) and plan (~/plan) reach other processes with the right types and frames."""

import subprocess
import sys

import numpy as np
import pytest
import yaml

from subapf_planner.sim.worldgen import generate, sub_seed

pytestmark = pytest.mark.dds

#: The dev suite's seed (docs/worlds.md, "World suites").
DEV_SEED = 2026


def dev_world(tmp_path, family: str, index: int):
    name = f'{family}_{index:03d}'
    path = tmp_path / f'{name}.yaml'
    path.write_text(yaml.safe_dump(generate(family, sub_seed(DEV_SEED, family, index), name)))
    return path


def test_bringup_drives_a_maze_and_publishes_map_and_plan(tmp_path, bringup_env):
    from rosbags.highlevel import AnyReader
    world = dev_world(tmp_path, 'maze', 0)
    bag = tmp_path / 'maze.mcap'
    # rate 2, not 5: the node plans in wall-clock time, and a field computation of
    # 30 ms on a busy machine is 150 ms of simulated delay at 5x (a robot that weaves)
    r = subprocess.run(
        [sys.executable, '-m', 'subapf_planner.tools.bringup', '--world', str(world),
         '--rate', '2', '--domain-id', bringup_env['ROS_DOMAIN_ID'], '--png',
         str(tmp_path / 'maze.png'), '--record', str(bag), '--record-topics', '/odom',
         '/subapf_planner/map', '/subapf_planner/plan'],
        env=bringup_env, capture_output=True, text=True, timeout=400, cwd=tmp_path)
    assert r.returncode == 0 and 'outcome reached' in r.stdout, r.stdout + r.stderr
    seen = {}
    with AnyReader([bag]) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        for conn, _t, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            seen.setdefault(conn.topic, []).append(msg)
    assert types['/subapf_planner/map'] == 'nav_msgs/msg/OccupancyGrid'
    assert types['/subapf_planner/plan'] == 'nav_msgs/msg/Path'
    grid, plan = seen['/subapf_planner/map'][-1], seen['/subapf_planner/plan']
    assert grid.header.frame_id == 'odom' and grid.info.width == grid.info.height == 400
    assert max(grid.data) > 50 and min(grid.data) == -1     # walls seen, much unseen
    # a plan per new field, per 0.25 m driven or per second: at least one per 2 s of a
    # run of 25 s or more; its points 0.25 m apart (the last step may be shorter)
    assert len(plan) >= 12 and all(p.header.frame_id == 'odom' for p in plan)
    for p in plan:   # one pose only at the end: within 0.25 m of the goal, driving on
        xy = np.array([(q.pose.position.x, q.pose.position.y) for q in p.poses])
        assert len(xy) >= 1 and np.all(np.hypot(*np.diff(xy[:-1], axis=0).T) >= 0.25 - 1e-6)
    assert all(len(p.poses) >= 2 for p in plan[:len(plan) // 2])   # far from the goal
    # the map at map_rate (1 Hz of the simulated clock) at most, to the nearest planning
    # tick (5 Hz: a message is due from half a tick before its period is up)
    stamps = [m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec
              for m in seen['/subapf_planner/map']]
    assert len(stamps) >= 1 and np.all(np.diff(stamps) >= 1.0 - 0.1 - 1e-6)
    assert len(stamps) <= (stamps[-1] - stamps[0]) * 1.0 + 1.5, stamps
