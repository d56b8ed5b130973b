"""Live view over the Foxglove WebSocket protocol: subapf-bringup --foxglove serves a
run with moving obstacles; a WebSocket client (as Foxglove would) subscribes to every
channel and decodes each message from the schema the server advertised (rosbags, not
rclpy)."""

import asyncio
import json
import signal
import socket
import struct
import subprocess
import sys
import time

from conftest import with_paths
import pytest
import yaml

from subapf_planner.ros.foxglove_node import SUBPROTOCOL, FoxgloveOptions

pytestmark = pytest.mark.dds

WORLD = {
    'name': 'foxglove_walkers', 'start': [0.0, 0.0, 0.0], 'goal': [3.0, 0.0],
    'time_limit': 60, 'bounds': [-1.0, -2.5, 4.0, 2.5],
    'obstacles': [{'circle': {'center': [1.5, 1.2], 'radius': 0.2}}],
    'moving': [{'circle': {'radius': 0.25}, 'path': [[0, 1.5, -2.0], [8, 1.5, 2.0]],
                'loop': True, 'offset': 4.0},
               {'box': {'size': [0.4, 0.3], 'yaw': 0.3}, 'path': [[0, 3.5, 2.0], [20, 3.5, 1.0]]}],
}
#: Every channel the run must serve, with its ROS type.
EXPECTED = {
    '/scan': 'sensor_msgs/msg/LaserScan', '/odom': 'nav_msgs/msg/Odometry',
    '/ground_truth': 'nav_msgs/msg/Odometry', '/tf': 'tf2_msgs/msg/TFMessage',
    '/tf_static': 'tf2_msgs/msg/TFMessage', '/cmd_vel': 'geometry_msgs/msg/TwistStamped',
    '/goal_pose': 'geometry_msgs/msg/PoseStamped',
    '/moving_obstacles': 'visualization_msgs/msg/MarkerArray',
    '/subapf_planner/markers': 'visualization_msgs/msg/MarkerArray',
    '/subapf_planner/map': 'nav_msgs/msg/OccupancyGrid',
    '/subapf_planner/plan': 'nav_msgs/msg/Path', '/subapf_planner/status': 'std_msgs/msg/String',
}
#: A channel that delivered nothing this long after its subscription is subscribed
#: again [s].
RESUBSCRIBE = 2.0
#: Messages kept per channel (the latched /tf_static and the goal come once).
KEEP = 3
ONCE = {'/tf_static', '/goal_pose'}


def delivered(got: dict, wanted=None) -> bool:
    """Each of ``wanted`` (default EXPECTED) delivered its messages."""
    return all(len(got.get(t, ())) >= (1 if t in ONCE else KEEP) for t in wanted or EXPECTED)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


async def watch(port: int, timeout: float, run: subprocess.Popen,
                wanted: tuple[str, ...] = tuple(EXPECTED)) -> tuple[dict, dict]:
    """Connect (retrying while the server starts and ``run`` lives), subscribe to each
    advertised channel; return (channel by topic, [(log_time, payload)] by topic) once
    each ``wanted`` topic delivered its messages (``delivered``), or at ``timeout``."""
    import websockets
    end = time.monotonic() + timeout
    while True:
        try:
            ws = await websockets.connect(f'ws://127.0.0.1:{port}', subprotocols=[SUBPROTOCOL],
                                          max_size=None)
            break
        except OSError:
            if time.monotonic() > end or run.poll() is not None:
                raise
            await asyncio.sleep(0.5)
    channels, by_sub, got, asked, sub_of = {}, {}, {}, {}, {}

    async def subscribe(chans: list[dict]) -> None:
        """Subscribe to ``chans``, after unsubscribing any earlier subscription of them."""
        old = [sub_of[ch['topic']] for ch in chans if ch['topic'] in sub_of]
        if old:
            await ws.send(json.dumps({'op': 'unsubscribe', 'subscriptionIds': old}))
        subs = []
        for ch in chans:
            by_sub[len(by_sub) + 1] = ch['topic']
            sub_of[ch['topic']] = len(by_sub)
            asked[ch['topic']] = time.monotonic()
            subs.append({'id': len(by_sub), 'channelId': ch['id']})
        await ws.send(json.dumps({'op': 'subscribe', 'subscriptions': subs}))

    async with ws:
        assert ws.subprotocol == SUBPROTOCOL
        while time.monotonic() < end and not delivered(got, wanted):
            try:
                frame = await asyncio.wait_for(ws.recv(), RESUBSCRIBE)
            except asyncio.TimeoutError:
                frame = None
            except websockets.ConnectionClosed:
                break   # the run ended and the relay with it
            # foxglove-sdk 0.30 may refuse a subscription sent right after the advertise
            # ("unknown channel", seen in CI): subscribe again to what delivered nothing
            late = [ch for topic, ch in channels.items() if topic in wanted
                    and topic not in got and time.monotonic() - asked[topic] > RESUBSCRIBE]
            if late:
                await subscribe(late)
            if frame is None:
                continue
            if isinstance(frame, str):
                msg = json.loads(frame)
                if msg['op'] == 'advertise':
                    channels.update({ch['topic']: ch for ch in msg['channels']})
                    await subscribe(msg['channels'])
                continue
            assert frame[0] == 1   # message data: opcode, subscription id, log time, payload
            sub, log_time = struct.unpack_from('<IQ', frame, 1)
            kept = got.setdefault(by_sub[sub], [])
            if len(kept) < KEEP:
                kept.append((log_time, frame[13:]))
    return channels, got


def test_bringup_serves_every_channel_to_a_foxglove_client(bringup_env, tf2_msgs_built,
                                                          tmp_path):
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore
    env = with_paths(bringup_env, tf2_msgs_built)
    world = tmp_path / 'walkers.yaml'
    world.write_text(yaml.safe_dump(WORLD))
    port, log = free_port(), tmp_path / 'bringup.log'
    with open(log, 'w') as out:
        run = subprocess.Popen(
            [sys.executable, '-m', 'subapf_planner.tools.bringup', '--world', str(world),
             '--domain-id', env['ROS_DOMAIN_ID'], '--foxglove', str(port),
             '--png', str(tmp_path / 'w.png')],
            env=env, stdout=out, stderr=subprocess.STDOUT, cwd=tmp_path)
    try:
        channels, got = asyncio.run(watch(port, 120.0, run))
        run.wait(timeout=180)
    finally:
        if run.poll() is None:
            run.send_signal(signal.SIGINT)   # the bringup stops its nodes
            run.wait(timeout=30)
    assert delivered(got), ({t: len(got.get(t, ())) for t in EXPECTED}, sorted(channels),
                            log.read_text())
    assert 'outcome reached' in log.read_text(), log.read_text()
    decoded = {}
    for topic, type_name in EXPECTED.items():
        ch = channels[topic]
        assert (ch['encoding'], ch['schemaEncoding'], ch['schemaName']) == \
            ('cdr', 'ros2msg', type_name)
        store = get_typestore(Stores.EMPTY)
        store.register(get_types_from_msg(ch['schema'], type_name))
        times = [t for t, _ in got[topic]]
        assert times == sorted(times) and abs(times[0] / 1e9 - time.time()) < 600
        decoded[topic] = [store.deserialize_cdr(data, type_name) for _, data in got[topic]]
    scan = decoded['/scan'][-1]
    assert scan.header.frame_id == 'base_scan' and len(scan.ranges) == 360
    for topic in ('/odom', '/ground_truth'):
        assert decoded[topic][-1].child_frame_id == 'base_footprint'
    assert {(t.header.frame_id, t.child_frame_id) for m in decoded['/tf']
            for t in m.transforms} == {('odom', 'base_footprint')}
    assert {(t.header.frame_id, t.child_frame_id) for t in decoded['/tf_static'][0].transforms} \
        == {('base_footprint', 'base_link'), ('base_link', 'base_scan')}
    grid = decoded['/subapf_planner/map'][-1]
    assert grid.header.frame_id == 'odom'
    assert len(grid.data) == grid.info.width * grid.info.height > 0
    plan = decoded['/subapf_planner/plan'][-1]
    assert plan.header.frame_id == 'odom' and len(plan.poses) >= 2
    assert {m.ns for m in decoded['/subapf_planner/markers'][-1].markers} >= {
        'obstacles', 'samples', 'chosen_point', 'footprint', 'danger_circle', 'tracks'}
    assert len(decoded['/moving_obstacles'][-1].markers) == 2
    goal = decoded['/goal_pose'][0].pose.position
    assert (goal.x, goal.y) == (3.0, 0.0)


def test_foxglove_options_refuse_bad_values():
    from subapf_planner.core.params import ConfigError
    with pytest.raises(ConfigError, match='port'):
        FoxgloveOptions(port=70000)
    with pytest.raises(ConfigError, match='topics'):
        FoxgloveOptions(topics='  ')


def test_a_taken_port_is_a_clear_error(ros_env):
    with socket.socket() as taken:
        taken.bind(('127.0.0.1', 0))
        taken.listen()
        r = subprocess.run([sys.executable, '-m', 'subapf_planner.ros.foxglove_node',
                            '--ros-args', '-p', f'port:={taken.getsockname()[1]}'],
                           env=ros_env, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2, r.stderr
    assert 'subapf-foxglove: port: cannot serve on 127.0.0.1:' in r.stderr
    assert 'Traceback' not in r.stderr


def test_a_client_that_connects_late_still_gets_the_latched_topics(ros_env, tf2_msgs_built,
                                                                    tmp_path):
    """/tf_static is published once (transient local); a Foxglove client that connects
    after the relay got it still gets it, as a late DDS subscriber would."""
    from test_tf import WORLD, wait_for_line

    from subapf_planner.ros.processes import start, stop
    env = with_paths(ros_env, tf2_msgs_built)
    port = free_port()
    nodes = [start('sim_node', ['-p', f'world:={WORLD}'], env, log=tmp_path / 'sim.log'),
             start('foxglove_node', ['-p', f'port:={port}'], env, log=tmp_path / 'fox.log')]
    try:
        wait_for_line(tmp_path / 'fox.log', 'serving /tf_static')
        # once a first client has the one message, the relay has it (it keeps a latched
        # message before it passes it on): the second client comes after it went out.
        # (The relay takes it as soon as it sees the topic, so the first is late too.)
        channels, got = asyncio.run(watch(port, 30.0, nodes[1], wanted=('/tf_static',)))
        assert got.get('/tf_static'), ('the first client got no /tf_static, neither live '
                                       "nor the relay's latched copy", sorted(channels),
                                       (tmp_path / 'fox.log').read_text())
        channels, got = asyncio.run(watch(port, 30.0, nodes[1], wanted=('/tf_static',)))
    finally:
        stop(nodes)
    assert len(got.get('/tf_static', ())) >= 1, (sorted(channels), got.keys())
