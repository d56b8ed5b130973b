"""Topics taken as they are published, for a recorder or a relay.

Each wanted topic is subscribed as soon as the graph shows a publisher of it:
raw CDR (nothing deserialised), with the reliability and durability its
publishers offer (best effort if any offers only that; transient local only if
all do, so a latched map reaches a late joiner), and each message is handed to
a sink with its receive time. ``subapf-record`` writes them to MCAP, the
Foxglove relay serves them over a WebSocket.
"""

from __future__ import annotations

import time
from typing import Protocol

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from ..bag.reader import message_class

#: Subscription queue depth: how many messages may wait for the sink.
DEPTH = 500
#: How often the graph is looked at for new topics [s].
DISCOVERY_PERIOD = 0.2


class Sink(Protocol):
    def add_topic(self, topic: str, type_name: str) -> bool | None:
        """A new topic of ROS type ``type_name`` (e.g. sensor_msgs/msg/LaserScan);
        False if the sink cannot take it (it is then not subscribed, nor asked again)."""

    def write(self, topic: str, data: bytes, log_time: int) -> None:
        """One CDR message of ``topic``, received at ``log_time`` [ns since the epoch]."""


def offered_qos(offered: list, depth: int = DEPTH) -> QoSProfile:
    """The subscription QoS that matches every publisher in ``offered`` (TopicEndpointInfo
    list): best effort if one of them is, transient local if all of them are."""
    best_effort = any(i.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
                      for i in offered)
    latched = bool(offered) and all(i.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
                                    for i in offered)
    return QoSProfile(depth=depth,
                      reliability=ReliabilityPolicy.BEST_EFFORT if best_effort
                      else ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL if latched
                      else DurabilityPolicy.VOLATILE)


class TopicTap:
    """Subscribes ``node`` to each of ``wanted`` (relative names resolved in the node's
    namespace, with its remappings) once published, and hands every message to
    ``sink``. ``subscribed`` maps each topic to its type; each new one is logged as
    "<verb> <topic> (<type>)"."""

    def __init__(self, node: Node, wanted: list[str], sink: Sink, verb: str = 'taking') -> None:
        self.node, self.sink, self.verb = node, sink, verb
        self.wanted = {node.resolve_topic_name(t) for t in wanted}
        self.subscribed: dict[str, str] = {}
        #: Per subscribed topic: whether its publishers all latch (transient local).
        self.latched: dict[str, bool] = {}
        self.refused: set[str] = set()
        node.create_timer(DISCOVERY_PERIOD, self.discover)

    def discover(self) -> None:
        """Subscribe the wanted topics that now have a publisher (called by the timer)."""
        for topic, types in self.node.get_topic_names_and_types():
            if topic not in self.wanted or topic in self.subscribed or topic in self.refused \
                    or not types:
                continue
            offered = self.node.get_publishers_info_by_topic(topic)
            if not offered:
                continue   # known from a subscriber only: wait to see the publishers' QoS
            if self.sink.add_topic(topic, types[0]) is False:
                self.refused.add(topic)
                continue
            qos = offered_qos(offered)
            self.latched[topic] = qos.durability == DurabilityPolicy.TRANSIENT_LOCAL
            self.node.create_subscription(message_class(types[0]), topic, self._handing(topic),
                                          qos, raw=True)
            self.subscribed[topic] = types[0]
            self.node.get_logger().info(f'{self.verb} {topic} ({types[0]})')

    def _handing(self, topic: str):
        return lambda data: self.sink.write(topic, data, time.time_ns())
