"""Planner node in one process: parameters, safety stops, cmd_vel type (rclpy executor);
the simulator node's start held for its listeners."""

import math
import time

from conftest import WORLDS
from geometry_msgs.msg import PoseStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
from rcl_interfaces.msg import ParameterDescriptor
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan, TimeReference
from std_msgs.msg import String

from subapf_planner.core.scan import Scan
from subapf_planner.ros.conversions import odom_to_msg, scan_to_msg
from subapf_planner.ros.planner_node import PlannerNode
from subapf_planner.ros.qos import LATCHED as LATCHED_QOS
from subapf_planner.ros.sim_node import SimNode

pytestmark = pytest.mark.node


@pytest.fixture
def ros():
    context = rclpy.Context()
    rclpy.init(context=context)
    yield context
    rclpy.try_shutdown(context=context)


class Harness:
    """The node under test plus a peer node that feeds and listens, one executor."""

    def __init__(self, context, **overrides):
        params = [Parameter(k, value=v) for k, v in overrides.items()]
        self.node = PlannerNode(context=context, parameter_overrides=params)
        self.peer = rclpy.create_node('peer', context=context)
        self.ex = SingleThreadedExecutor(context=context)
        self.ex.add_node(self.node)
        self.ex.add_node(self.peer)
        stamped = self.node.get_parameter('enable_stamped_cmd_vel').value
        self.cmds = []
        self.states = []
        self.peer.create_subscription(TwistStamped if stamped else Twist, 'cmd_vel',
                                      self.cmds.append, 10)
        self.peer.create_subscription(String, '/subapf_planner/status',
                                      lambda m: self.states.append(m.data), 10)
        self.scan_pub = self.peer.create_publisher(LaserScan, 'scan', qos_profile_sensor_data)
        self.odom_pub = self.peer.create_publisher(Odometry, 'odom', 10)
        self.goal_pub = self.peer.create_publisher(PoseStamped, 'goal_pose', 10)

    def spin_until(self, predicate, timeout=5.0):
        end = self.node.get_clock().now().nanoseconds + timeout * 1e9
        while self.node.get_clock().now().nanoseconds < end:
            self.ex.spin_once(timeout_sec=0.02)
            if predicate():
                return True
        return False

    def feed(self, pose=(0.0, 0.0, 0.0), scan=True, odom=True, ranges=None):
        t = self.node.get_clock().now().nanoseconds * 1e-9
        if scan:
            ranges = np.full(360, np.inf) if ranges is None else ranges
            self.scan_pub.publish(scan_to_msg(Scan(ranges, 0.0, math.pi / 180, 0.12, 3.5, t),
                                              'base_scan'))
        if odom:
            self.odom_pub.publish(odom_to_msg(np.array(pose), (0.0, 0.0), t))

    def goal(self, x, y, frame='odom'):
        g = PoseStamped()
        g.header.frame_id = frame
        g.pose.position.x, g.pose.position.y = float(x), float(y)
        self.wait_matched()
        self.goal_pub.publish(g)

    def wait_matched(self):
        assert self.spin_until(lambda: self.goal_pub.get_subscription_count() > 0
                               and self.odom_pub.get_subscription_count() > 0
                               and len(self.peer.get_publishers_info_by_topic('cmd_vel')) > 0)

    def close(self):
        self.ex.shutdown()
        self.node.destroy_node()
        self.peer.destroy_node()


@pytest.fixture
def harness(ros):
    made = []

    def make(**overrides):
        h = Harness(ros, **overrides)
        made.append(h)
        return h
    yield make
    for h in made:
        h.close()


def test_every_parameter_has_a_descriptor_with_text(harness):
    node = harness().node
    for name in node._parameters:
        if name == 'use_sim_time':
            continue
        d: ParameterDescriptor = node.describe_parameter(name)
        assert d.description, name
    assert node.describe_parameter('danger_distance').floating_point_range[0].to_value == 2.0


def test_runtime_parameter_changes_are_validated(harness):
    node = harness().node
    bad = node.set_parameters([Parameter('danger_distance', value=-1.0)])[0]
    assert not bad.successful
    bad = node.set_parameters([Parameter('method', value='teleport')])[0]
    assert not bad.successful and 'method' in bad.reason
    assert node.get_parameter('method').value == 'subharmonic_sampling'
    ok = node.set_parameters([Parameter('method', value='harmonic')])[0]
    assert ok.successful and node.ctl.cfg.method == 'harmonic'


def test_no_command_before_scan_and_odom_then_drives(harness):
    h = harness()
    h.goal(2.0, 0.0)
    # three ticks with the goal but no inputs: each says why it waits, none commands
    assert h.spin_until(lambda: sum(s.startswith('waiting') for s in h.states) >= 3)
    assert h.cmds == []
    assert h.spin_until(lambda: (h.feed(), any(c.twist.linear.x > 0 for c in h.cmds))[1])
    assert all(isinstance(c, TwistStamped) for c in h.cmds)


def test_stale_odometry_gives_zero_velocity(harness):
    h = harness(odom_timeout=0.3)
    h.goal(2.0, 0.0)
    assert h.spin_until(lambda: (h.feed(), any(c.twist.linear.x > 0 for c in h.cmds))[1])
    h.cmds.clear()
    # scans keep coming, odometry stops
    assert h.spin_until(lambda: (h.feed(odom=False),
                                 'stopped: odometry is stale' in h.states)[1])
    assert h.cmds[-1].twist.linear.x == 0.0 and h.cmds[-1].twist.angular.z == 0.0


def test_goal_reached_gives_zero_velocity(harness):
    h = harness()
    h.goal(0.05, 0.0)
    assert h.spin_until(lambda: (h.feed(), any(s.startswith('reached') for s in h.states))[1])
    assert h.cmds and h.cmds[-1].twist.linear.x == 0.0


def test_goal_in_another_frame_is_refused(harness):
    h = harness()
    h.goal(2.0, 0.0, frame='base_link')
    # three ticks with fresh inputs after the refused goal: still idle, no command
    assert h.spin_until(lambda: (h.feed(), h.states.count('idle: no goal') >= 3)[1])
    assert h.node.ctl.goal is None and h.cmds == []
    h.goal(2.0, 0.0)   # the same goal in odom is taken
    assert h.spin_until(lambda: (h.feed(), any(c.twist.linear.x > 0 for c in h.cmds))[1])
    assert not h.node.ctl.goal_in_map


def test_goal_in_the_map_frame_is_taken_and_the_correction_published(harness):
    from geometry_msgs.msg import TransformStamped
    h = harness()
    corrections = []
    h.peer.create_subscription(TransformStamped, '/subapf_planner/correction',
                               corrections.append, 10)
    h.goal(2.0, 0.0, frame='map')
    assert h.spin_until(lambda: (h.feed(), any(c.twist.linear.x > 0 for c in h.cmds)
                                 and bool(corrections))[1])
    assert h.node.ctl.goal_in_map
    c = corrections[-1]
    assert (c.header.frame_id, c.child_frame_id) == ('map', 'odom')
    assert c.transform.rotation.w == pytest.approx(1.0)   # a still robot: no correction


def test_twist_when_stamped_disabled(harness):
    h = harness(enable_stamped_cmd_vel=False)
    h.goal(2.0, 0.0)
    assert h.spin_until(lambda: (h.feed(), len(h.cmds) > 0)[1])
    assert isinstance(h.cmds[0], Twist)


def test_planning_frequency_change_retimes_the_timer(harness):
    node = harness().node
    assert node.timer.timer_period_ns == 200_000_000
    assert node.set_parameters([Parameter('planning_frequency', value=10.0)])[0].successful
    assert node.timer.timer_period_ns == 100_000_000
    bad = node.set_parameters([Parameter('planning_frequency', value=1000.0)])[0]
    assert not bad.successful and node.timer.timer_period_ns == 100_000_000


def test_wrong_type_at_run_time_is_refused(harness):
    node = harness().node
    result = node.set_parameters([Parameter('danger_distance', value='wide')])[0]
    assert not result.successful
    assert node.get_parameter('danger_distance').value == 0.25


SPIN_SCRIPT = """
import sys
from rclpy.node import Node
from subapf_planner.ros.spinning import spin_node

class Crashing(Node):
    def __init__(self):
        super().__init__('crashing')
        self.create_timer(0.01, self.boom)

    def boom(self):
        raise ValueError('a bug in a callback')

def stopped(node):
    print('on_shutdown ran', flush=True)

sys.exit(spin_node(Crashing, 'crashing', (ValueError,), stopped, []))
"""


def test_memory_and_plan_are_published_in_odom(harness):
    from nav_msgs.msg import OccupancyGrid, Path
    h = harness()
    maps, plans = [], []
    h.peer.create_subscription(OccupancyGrid, '/subapf_planner/map', maps.append, LATCHED_QOS)
    h.peer.create_subscription(Path, '/subapf_planner/plan', plans.append, 10)
    h.goal(3.0, 0.0)
    ranges = np.full(360, np.inf)
    ranges[350:] = ranges[:11] = 1.0              # a wall 1 m ahead, +-10 degrees
    assert h.spin_until(lambda: (h.feed(ranges=ranges), bool(maps and plans))[1])
    grid, plan = maps[-1], plans[-1]
    assert grid.header.frame_id == plan.header.frame_id == 'odom'
    assert grid.info.resolution == pytest.approx(0.05) and grid.info.width == 400
    data = np.asarray(grid.data, np.int8).reshape(grid.info.height, grid.info.width)
    col = int((1.0 - 0.032 - grid.info.origin.position.x) / grid.info.resolution)
    row = int((0.0 - grid.info.origin.position.y) / grid.info.resolution)
    assert data[row - 1:row + 2, col - 1:col + 2].max() > 50     # the wall
    assert data[row, col - 10] < 50 and data[row, col - 10] != -1   # seen free
    assert (data == -1).sum() > 0.5 * data.size                     # mostly never seen
    xy = np.array([[p.pose.position.x, p.pose.position.y] for p in plan.poses])
    assert len(xy) > 10 and np.hypot(*(xy[-1] - (3.0, 0.0))) < 0.1   # ends at the goal
    assert np.abs(xy[:, 1]).max() > 0.15                               # round the wall


def test_memory_topics_can_be_switched_off(harness):
    from nav_msgs.msg import OccupancyGrid, Path
    h = harness(publish_map=False, publish_plan=False)
    got = []
    subs = [h.peer.create_subscription(OccupancyGrid, '/subapf_planner/map', got.append,
                                       LATCHED_QOS),
            h.peer.create_subscription(Path, '/subapf_planner/plan', got.append, 10)]
    # matched both ways first: the node sees the listeners (so, with the topics on, it
    # would publish) and they see its publishers (so they would get what it sends)
    assert h.spin_until(lambda: all(s.get_publisher_count() > 0 for s in subs)
                        and h.node.map_pub.get_subscription_count() > 0
                        and h.node.plan_pub.get_subscription_count() > 0), \
        'the map and plan subscriptions never matched the node'
    h.goal(3.0, 0.0)
    assert h.spin_until(lambda: (h.feed(), any(c.twist.linear.x > 0 for c in h.cmds))[1])
    # then 8 more planning cycles of driving (1.6 s), in which a map (at once, then at
    # map_rate 1 Hz) and a plan (each new field, each second) would have come
    cycles = len(h.states)
    assert h.spin_until(lambda: (h.feed(), len(h.states) >= cycles + 8)[1], timeout=10.0), \
        f'{len(h.states) - cycles} of 8 planning cycles'
    assert got == [] and len(h.cmds) >= 8


def test_views_are_built_only_while_something_subscribes(harness, monkeypatch):
    """Markers, map, plan and correction cost nothing with nobody listening: not even
    built (the builders are counted); a subscriber gets them from its next cycle on."""
    from visualization_msgs.msg import MarkerArray

    import subapf_planner.ros.planner_node as planner_node
    built = {'markers': 0, 'map': 0, 'plan': 0, 'correction': 0}

    def counted(name, build):
        def wrapper(*args, **kwargs):
            built[name] += 1
            return build(*args, **kwargs)
        return wrapper
    for name, attr in (('markers', 'markers_from_result'), ('map', 'grid_to_msg'),
                       ('plan', 'path_to_msg'), ('correction', 'transform_msg')):
        monkeypatch.setattr(planner_node, attr, counted(name, getattr(planner_node, attr)))
    h = harness()
    h.goal(3.0, 0.0)
    assert h.spin_until(lambda: (h.feed(), sum(c.twist.linear.x > 0 for c in h.cmds) >= 5)[1])
    assert built == {'markers': 0, 'map': 0, 'plan': 0, 'correction': 0}
    got = []
    h.peer.create_subscription(MarkerArray, '/subapf_planner/markers', got.append, 10)
    assert h.spin_until(lambda: (h.feed(), len(got) >= 3)[1])
    assert built['markers'] >= 3 and built['map'] == built['plan'] == 0
    assert {m.ns for m in got[-1].markers} >= {'obstacles', 'samples', 'footprint',
                                             'danger_circle'}


def test_scans_and_odometry_are_taken_at_the_tick_not_by_the_executor(harness):
    """The inputs' subscriptions are in a group the executor never runs (PolledGroup):
    a scan and odometry that arrived wait in their queues until the planning tick,
    which says on ~/taken that it took them (what a replay follows: bag/events.py)."""
    h = harness(planning_frequency=0.5)
    refs = []
    h.peer.create_subscription(TimeReference, '/subapf_planner/taken', refs.append, 50)
    # the peer hears the same inputs through ordinary subscriptions, which the executor
    # runs: when it has them, they have reached this process
    heard = {'scan': 0, 'odom': 0}
    for kind, topic, qos in ((LaserScan, 'scan', qos_profile_sensor_data),
                             (Odometry, 'odom', 10)):
        h.peer.create_subscription(kind, topic, lambda _, t=topic: heard.update(
            {t: heard[t] + 1}), qos)
    assert h.spin_until(lambda: h.scan_pub.get_subscription_count() == 2
                        and h.odom_pub.get_subscription_count() == 2), \
        'scan and odom never matched both the node and the peer'
    h.goal(3.0, 0.0)
    assert h.spin_until(lambda: any(s.startswith('waiting') for s in h.states), timeout=8.0)
    for _ in range(3):   # just after a tick: the next is two seconds away
        h.feed()
    polled = [sub for sub, *_ in h.node._inputs]
    assert all(not sub.callback_group.can_execute(sub) for sub in polled)
    # the executor ran until the peer had them all, and 0.3 s more; the 0.5 Hz tick did not
    assert h.spin_until(lambda: heard == {'scan': 3, 'odom': 3}, timeout=1.0), heard
    h.spin_until(lambda: False, timeout=0.3)
    assert h.node.ctl.scan is None and h.node.ctl.pose is None
    assert h.spin_until(lambda: bool(h.cmds), timeout=5.0)   # the tick took them in
    assert h.node.ctl.scan is not None and h.node.ctl.pose is not None
    tick = h.cmds[0].header.stamp
    assert h.spin_until(lambda: sum(r.header.stamp == tick for r in refs) == 6, timeout=2.0)
    at_tick = [r for r in refs if r.header.stamp == tick]
    assert sorted(r.source for r in at_tick) == ['odom'] * 3 + ['scan'] * 3
    assert len({(r.time_ref.sec, r.time_ref.nanosec) for r in at_tick}) == 3   # as fed
    assert [r.source for r in refs if r.header.stamp != tick] == ['goal_pose']


def test_a_publisher_the_polled_inputs_cannot_hear_is_reported(harness, capfd):
    """Odometry is polled at the tick (PolledGroup), so rclpy's QoS-event warning never
    runs for it; while odometry is silent the node looks at its publishers itself: a
    best-effort one, which the reliable subscription never hears, is named, once."""
    h = harness()
    quiet = h.peer.create_publisher(Odometry, 'odom', qos_profile_sensor_data)
    warning = "/odom: the QoS /peer offers is incompatible with this node's"
    seen = []
    assert h.spin_until(lambda: (seen.append(capfd.readouterr().err), warning in seen[-1])[1])
    quiet.publish(Odometry())
    h.spin_until(lambda: (seen.append(capfd.readouterr().err), False)[1], timeout=4.5)
    assert h.node.ctl.pose is None   # nothing came
    assert sum(text.count(warning) for text in seen) == 1   # said once


def test_unheard_publishers_are_those_of_another_type_or_an_incompatible_qos():
    """ros/qos.py unheard_publishers, from endpoint infos built directly: a reliable
    odometry subscription hears reliable publishers only, a best-effort one hears both; a
    publisher of another type is named with both types."""
    from rclpy.qos import ReliabilityPolicy
    from rclpy.topic_endpoint_info import TopicEndpointInfo

    from subapf_planner.ros.qos import type_name, unheard_publishers

    def info(gid, kind='nav_msgs/msg/Odometry', qos=QoSProfile(depth=10)):
        return TopicEndpointInfo(node_name=f'driver{gid}', node_namespace='/robot',
                                 topic_type=kind, endpoint_gid=[gid] * 16, qos_profile=qos)
    best_effort = QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)
    assert type_name(Odometry) == 'nav_msgs/msg/Odometry'
    publishers = [info(1), info(2, qos=best_effort), info(3, 'nav_msgs/msg/Path')]
    found = unheard_publishers('/odom', Odometry, QoSProfile(depth=50), publishers)
    assert set(found) == {bytes([2] * 16), bytes([3] * 16)}
    assert found[bytes([2] * 16)].startswith('/odom: the QoS /robot/driver2 offers')
    assert 'reliab' in found[bytes([2] * 16)].lower()
    assert 'nav_msgs/msg/Path' in found[bytes([3] * 16)]
    assert unheard_publishers('/scan', Odometry, best_effort, publishers[:2]) == {}


def test_the_executor_sleeps_while_polled_messages_wait(harness):
    """Messages waiting in the polled subscriptions do not wake the executor: nothing
    of the inputs (their QoS events included: with Fast DDS they would wake it while a
    message is unread) is in its wait set, so between ticks the process rests."""
    import time
    h = harness(planning_frequency=0.5)
    polled = [sub for sub, *_ in h.node._inputs]
    entities = [e for sub in polled for e in (sub, *sub.event_handlers)]
    assert not any(e.callback_group.can_execute(e) for e in entities)
    h.wait_matched()
    ex = SingleThreadedExecutor(context=h.node.context)
    ex.add_node(h.node)   # the planner alone: the peer's own wake-ups not counted
    cpu, end = time.process_time(), time.monotonic() + 1.5
    while time.monotonic() < end:   # scans and odometry keep coming, 0.5 Hz ticks
        h.feed()
        ex.spin_once(timeout_sec=0.1)
    assert time.process_time() - cpu < 0.5   # a spinning executor takes the whole 1.5 s


def test_spin_node_bad_input_only_while_building_bugs_keep_their_traceback():
    """ros/spinning.py: a bad_input exception from the constructor is a clear message
    and exit code 2; the same exception type raised while spinning is a bug: it
    propagates with its traceback (non-zero exit), after on_shutdown and shutdown."""
    import signal
    import subprocess
    import sys

    from rclpy.node import Node

    from subapf_planner.ros.spinning import spin_node

    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        def bad_parameter() -> Node:
            raise ValueError('danger_distance: 5.0 is out of range')

        shut = []
        assert spin_node(bad_parameter, 'subapf-test', (ValueError,), shut.append, []) == 2
        assert shut == [] and not rclpy.ok()

        class Crashing(Node):
            def __init__(self) -> None:
                super().__init__('crashing')
                self.create_timer(0.01, self.boom)

            def boom(self) -> None:
                raise ValueError('a bug in a callback')

        with pytest.raises(ValueError, match='a bug in a callback'):
            spin_node(Crashing, 'subapf-test', (ValueError,), lambda n: shut.append(n), [])
        assert len(shut) == 1 and isinstance(shut[0], Crashing)   # zero velocity sent
        assert not rclpy.ok()
    finally:
        for s, h in handlers.items():
            signal.signal(s, h)
    r = subprocess.run([sys.executable, '-c', SPIN_SCRIPT], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode not in (0, 2), r.stderr
    assert 'Traceback' in r.stderr and 'ValueError: a bug in a callback' in r.stderr
    assert 'on_shutdown ran' in r.stdout


def test_a_static_chain_sets_the_laser_mounting_unless_a_link_of_it_is_tilted(harness):
    """_on_tf_static, given TFMessage-shaped messages directly (this process need not
    import tf2_msgs): a level chain base_footprint -> base_link -> base_scan replaces
    the parameters' mounting; a tilted link in the chain keeps the parameters'."""
    from types import SimpleNamespace

    from subapf_planner.ros.conversions import transform_msg
    h = harness(laser_x=0.5, laser_y=0.1)
    camera = transform_msg('base_link', 'camera_optical', (0.1, 0.0, 0.2), 0.0, 0.0)
    camera.transform.rotation.x, camera.transform.rotation.w = 0.7071, 0.7071   # tilted
    h.node._on_tf_static(SimpleNamespace(transforms=[
        transform_msg('base_footprint', 'base_link', (0.0, 0.0, 0.01), 0.0, 0.0),
        transform_msg('base_link', 'base_scan', (-0.032, 0.0, 0.17), 0.2, 0.0), camera]))
    assert h.node.ctl.cfg.laser_mount == pytest.approx((-0.032, 0.0, 0.2))
    h = harness(laser_x=0.5, laser_y=0.1)
    scan = transform_msg('base_link', 'base_scan', (-0.032, 0.0, 0.17), 0.0, 0.0)
    scan.transform.rotation.x, scan.transform.rotation.w = 1.0, 0.0   # upside down
    h.node._on_tf_static(SimpleNamespace(transforms=[
        transform_msg('base_footprint', 'base_link', (0.0, 0.0, 0.01), 0.0, 0.0), scan]))
    assert h.node.ctl.cfg.laser_mount == pytest.approx((0.5, 0.1, 0.0))


def test_spin_node_waits_without_polling_and_a_signal_wakes_it():
    """ros/spinning.py: the spin loop waits for its node's timers and messages alone (no
    STOP_POLL wake-ups: a node with nothing to do spins once in 1.5 s), and a SIGINT
    then wakes it: on_shutdown runs within a second of the signal."""
    import os
    import signal
    import threading
    import time

    from rclpy.node import Node

    from subapf_planner.ros import spinning

    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    spins = []

    class Idle(Node):
        def __init__(self) -> None:
            super().__init__('idle')

    original = spinning.SingleThreadedExecutor.spin_once

    def counted(self, timeout_sec=None):
        spins.append(timeout_sec)
        return original(self, timeout_sec)
    sent = []

    def interrupt() -> None:
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)
    timer = threading.Timer(1.5, interrupt)
    shut = []
    try:
        spinning.SingleThreadedExecutor.spin_once = counted
        timer.start()
        assert spinning.spin_node(Idle, 'subapf-test', (ValueError,),
                                  lambda n: shut.append(time.monotonic()), []) == 0
    finally:
        timer.cancel()
        spinning.SingleThreadedExecutor.spin_once = original
        for s, h in handlers.items():
            signal.signal(s, h)
    assert sent and shut and shut[0] - sent[0] < 1.0
    assert spins and set(spins) == {None} and len(spins) <= 2


def test_the_simulator_waits_for_its_listeners_when_asked(ros):
    """start_subscribers: the simulation stays at time 0 until /clock has that many
    subscribers and odom and scan one each (subapf-bringup: the planner and its
    recording), then runs; a replay then has every message from the first."""
    sim = SimNode(context=ros, parameter_overrides=[
        Parameter('world', value=str(WORLDS / 'cluttered_field.yaml')),
        Parameter('start_subscribers', value=2)])
    peer = rclpy.create_node('listener', context=ros)
    try:
        def matched(n):
            end = time.monotonic() + 10.0
            while time.monotonic() < end:   # DDS matches on its own threads
                if sim.clock_pub.get_subscription_count() >= n \
                        and sim.odom_pub.get_subscription_count() >= 1 \
                        and sim.scan_pub.get_subscription_count() >= 1:
                    return True
                time.sleep(0.01)
            return False
        peer.create_subscription(Clock, '/clock', lambda _m: None, 10)
        peer.create_subscription(Odometry, 'odom', lambda _m: None, 10)
        peer.create_subscription(LaserScan, 'scan', lambda _m: None, qos_profile_sensor_data)
        assert matched(1)
        for _ in range(3):
            sim._on_timer()
        assert sim.sim.time == 0.0   # one /clock subscriber of two: held
        peer.create_subscription(Clock, '/clock', lambda _m: None, 10)
        assert matched(2)
        sim._on_timer()
        assert sim.sim.time > 0.0
    finally:
        peer.destroy_node()
        sim.destroy_node()
        sim.close()
