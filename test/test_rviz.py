"""config/subapf.rviz against the running nodes: every topic it displays is published
(by sim_node or planner_node, in one process) with the type its display takes and a
QoS it can match, the goal tool's topic is the planner's goal_pose, and the views'
messages are in the fixed frame."""

from pathlib import Path

from conftest import PARAMS
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
import yaml

from subapf_planner.bag.reader import message_class
from subapf_planner.ros.planner_node import PlannerNode
from subapf_planner.ros.sim_node import SimNode

pytestmark = pytest.mark.node

RVIZ = PARAMS.parent / 'subapf.rviz'
#: The message type each display class takes.
DISPLAY_TYPES = {
    'rviz_default_plugins/Map': 'nav_msgs/msg/OccupancyGrid',
    'rviz_default_plugins/LaserScan': 'sensor_msgs/msg/LaserScan',
    'rviz_default_plugins/Odometry': 'nav_msgs/msg/Odometry',
    'rviz_default_plugins/Path': 'nav_msgs/msg/Path',
    'rviz_default_plugins/MarkerArray': 'visualization_msgs/msg/MarkerArray',
}
#: A world with something moving, so sim_node publishes moving_obstacles.
WORLD = """\
name: rviz_check
start: [0.0, 0.0, 0.0]
goal: [3.0, 0.0]
time_limit: 60
obstacles:
  - circle: {center: [1.5, 1.0], radius: 0.3}
moving:
  - circle: {radius: 0.3}
    path: [[0.0, 1.0, -2.0], [20.0, 1.0, 2.0]]
"""


def rviz_topics(config: dict) -> dict[str, dict]:
    """Topic -> the display's Topic block, for every display and tool with a topic."""
    manager = config['Visualization Manager']
    out = {}
    for item in manager['Displays'] + manager['Tools']:
        if 'Topic' in item:
            out[item['Topic']['Value']] = dict(item['Topic'], Class=item['Class'])
    return out


def display_qos(block: dict) -> QoSProfile:
    """The QoS a display subscribes with, from its Topic block."""
    return QoSProfile(
        depth=int(block['Depth']),
        reliability=ReliabilityPolicy.RELIABLE if block['Reliability Policy'] == 'Reliable'
        else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL
        if block['Durability Policy'] == 'Transient Local' else DurabilityPolicy.VOLATILE)


def frame_of(msg) -> str | None:
    """The frame a message is drawn in (a MarkerArray's: its markers', when it has any)."""
    if hasattr(msg, 'markers'):
        frames = {m.header.frame_id for m in msg.markers}
        return frames.pop() if len(frames) == 1 else None
    return msg.header.frame_id


def test_rviz_config_names_what_the_nodes_publish(tmp_path: Path):
    config = yaml.safe_load(RVIZ.read_text())
    fixed = config['Visualization Manager']['Global Options']['Fixed Frame']
    topics = rviz_topics(config)
    world = tmp_path / 'world.yaml'
    world.write_text(WORLD)
    context = rclpy.Context()
    rclpy.init(context=context)
    try:
        sim = SimNode(context=context, parameter_overrides=[
            Parameter('world', value=str(world)), Parameter('rate', value=2.0)])
        planner = PlannerNode(context=context, parameter_overrides=[
            Parameter('use_sim_time', value=True), Parameter('goal_from_parameters', value=True),
            Parameter('goal_x', value=3.0), Parameter('goal_y', value=0.0)])
        peer = rclpy.create_node('rviz_stand_in', context=context)
        ex = SingleThreadedExecutor(context=context)
        for n in (sim, planner, peer):
            ex.add_node(n)
        frames = {}
        for topic, block in topics.items():
            if block['Class'] in DISPLAY_TYPES:   # as RViz would, with its QoS
                peer.create_subscription(
                    message_class(DISPLAY_TYPES[block['Class']]), topic,
                    lambda m, t=topic: frame_of(m) and frames.setdefault(t, frame_of(m)),
                    display_qos(block))
        end = sim.get_clock().now().nanoseconds + 30e9
        while len(frames) < len(DISPLAY_TYPES) + 1 and sim.get_clock().now().nanoseconds < end:
            ex.spin_once(timeout_sec=0.05)
        for topic, block in topics.items():
            if block['Class'] == 'rviz_default_plugins/SetGoal':   # RViz publishes it
                subs = peer.get_subscriptions_info_by_topic(topic)
                # the planner and the simulator (which serves each new goal)
                assert {s.topic_type for s in subs} == {'geometry_msgs/msg/PoseStamped'}
                assert {s.node_name for s in subs} >= {'subapf_planner', 'subapf_sim'}, subs
                continue
            pubs = peer.get_publishers_info_by_topic(topic)
            assert pubs, f'{topic}: nobody publishes it'
            assert {p.topic_type for p in pubs} == {DISPLAY_TYPES[block['Class']]}, topic
            for p in pubs:
                if block['Reliability Policy'] == 'Reliable':
                    assert p.qos_profile.reliability == ReliabilityPolicy.RELIABLE, topic
                if block['Durability Policy'] == 'Transient Local':
                    assert p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL, topic
            assert topic in frames, f'{topic}: nothing arrived'
        # what is drawn without tf is in the fixed frame; the scan comes through /tf
        drawn = {t: f for t, f in frames.items() if t != '/scan'}
        assert set(drawn.values()) == {fixed}, drawn
        assert frames['/scan'] == 'base_scan'
        ex.shutdown()
        for n in (sim, planner, peer):
            n.destroy_node()
        sim.close()
    finally:
        rclpy.try_shutdown(context=context)
