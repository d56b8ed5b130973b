"""Over DDS: the geodesic default drives a generated maze to its goal, and the planner's
memory (~/map) and plan (~/plan) reach other processes with the right types and frames."""

import subprocess
import sys

import pytest
import yaml

from subapf_planner.sim.worldgen import generate, sub_seed

pytestmark = pytest.mark.dds

#: The dev suite's seed (README "World suites").
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
    assert len(plan) > 50 and all(p.header.frame_id == 'odom' for p in plan)
    assert 1 <= len(seen['/subapf_planner/map']) <= len(plan)   # the map at a few Hz at most
