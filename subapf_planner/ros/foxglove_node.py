"""``foxglove_node`` (``subapf-foxglove``): a run served live to Foxglove.

A WebSocket server (the foxglove-sdk package, protocol ``foxglove.sdk.v1``) that
relays the planner's and the simulator's topics as they are: raw CDR with their
``ros2msg`` schemas (the message definitions a rosbag2 MCAP holds), one channel
per topic, advertised once the topic has a publisher. Foxglove decodes them as
it decodes a ROS 2 bag: open ``ws://HOST:PORT`` (Open connection, Foxglove
WebSocket). By default it serves the scan, odometry, ground truth, /tf and
/tf_static, the goal, cmd_vel, the moving obstacles, the outcome and the
planner's memory map, plan, markers (obstacle points, samples and their scores,
chosen point, footprint, danger circle, tracks), status and drift correction.
Nothing is deserialised: the relay costs a copy per message, in its own process.
"""

from __future__ import annotations

from dataclasses import dataclass
import sys

from rclpy.node import Node

try:
    import foxglove
except ImportError:   # a Jazzy workspace without the pip line: a clear error at start
    foxglove = None

from ..bag.writer import RecorderError, message_definition
from ..core.params import ConfigError, check_fields, param
from .parameters import declare, read, warn_undeclared
from .spinning import spin_node
from .tap import TopicTap
from .usage import node_usage

#: Topics served by default (relative ones in the relay's namespace): what
#: config/subapf.rviz shows, and the rest of a run.
SERVED = ('scan', 'odom', 'ground_truth', '/tf', '/tf_static', 'goal_pose', 'cmd_vel',
          'moving_obstacles', 'sim_outcome', 'subapf_planner/markers', 'subapf_planner/map',
          'subapf_planner/plan', 'subapf_planner/status', 'subapf_planner/correction')
#: The WebSocket subprotocol the SDK's server speaks.
SUBPROTOCOL = 'foxglove.sdk.v1'


@dataclass(frozen=True)
class FoxgloveOptions:
    """The relay's parameters."""

    port: int = param(8765, 'WebSocket port (0: any free port, logged at start)', '', 0,
                      65535, read_only=True)
    host: str = param('127.0.0.1', 'Address to listen on (0.0.0.0: every interface)',
                      read_only=True)
    topics: str = param(' '.join(SERVED), 'Topics to serve, separated by spaces (relative '
                        "names in the node's namespace)", read_only=True)

    def __post_init__(self) -> None:
        check_fields(self)
        if not self.topics.split():
            raise ConfigError('topics: no topic to serve')


#: The parameter groups of the node with their titles (also config/planner.yaml's).
SECTIONS = (('node (ros/foxglove_node.py)', FoxgloveOptions),)


class FoxgloveNode(Node):
    """Serves ``topics`` over the Foxglove WebSocket protocol (see the module)."""

    def __init__(self, **kwargs) -> None:
        super().__init__('subapf_foxglove', **kwargs)
        declare(self, FoxgloveOptions)
        warn_undeclared(self)
        options = read(self, FoxgloveOptions)
        if foxglove is None:
            raise ConfigError('the foxglove-sdk package is not installed '
                              '(pip install foxglove-sdk)')
        self.fg_context = foxglove.Context()
        #: The last message of each latched (transient local) topic, sent again to each
        #: client that subscribes, as a late DDS subscriber would get it: a Foxglove
        #: opened after the start still gets /tf_static and the map.
        self.latched: dict[str, tuple[bytes, int]] = {}
        try:
            self.server = foxglove.start_server(name='subapf_planner', host=options.host,
                                                port=options.port, context=self.fg_context,
                                                server_listener=self)
        except RuntimeError as exc:   # the address is taken or cannot be bound
            raise ConfigError(f'port: cannot serve on {options.host}:{options.port}: '
                              f'{exc}') from exc
        self.channels: dict[str, object] = {}
        self.tap = TopicTap(self, options.topics.split(), self, 'serving')
        self.get_logger().info(f'Foxglove WebSocket on ws://{options.host}:{self.server.port}')

    def add_topic(self, topic: str, type_name: str) -> bool:
        """A channel for the topic: CDR messages, the type's ros2msg definition as schema
        (False, with an error logged, when the definition cannot be found)."""
        try:
            definition = message_definition(type_name)
        except RecorderError as exc:
            self.get_logger().error(f'not serving {topic}: {exc}')
            return False
        schema = foxglove.Schema(name=type_name, encoding='ros2msg', data=definition.encode())
        self.channels[topic] = foxglove.Channel(topic, schema=schema, message_encoding='cdr',
                                                context=self.fg_context)
        return True

    def write(self, topic: str, data: bytes, log_time: int) -> None:
        channel = self.channels.get(topic)
        if channel is None:
            return
        if self.tap.latched.get(topic):
            self.latched[topic] = (data, log_time)
        channel.log(data, log_time=log_time)

    def on_subscribe(self, client, channel) -> None:
        """A client subscribed (the SDK's server thread): a latched topic's last message
        again (every subscriber of the channel gets it; for a latched topic a repeat
        is harmless)."""
        last = self.latched.get(channel.topic)
        if last is not None:
            self.channels[channel.topic].log(last[0], log_time=last[1])

    def destroy_node(self) -> None:
        self.server.stop()
        super().destroy_node()


def usage() -> str:
    """``subapf-foxglove --help``."""
    return node_usage(
        'subapf-foxglove', 'foxglove_node', 'subapf_foxglove', """
        Serves the run live to Foxglove: a WebSocket server (foxglove-sdk) that relays the
        planner's and the simulator's topics as they are on DDS (raw CDR with their
        ros2msg schemas). In Foxglove: Open connection, Foxglove WebSocket,
        ws://localhost:8765.

        Example: subapf-foxglove --ros-args -p port:=8765""", SECTIONS)


def main(args: list[str] | None = None) -> int:
    return spin_node(FoxgloveNode, 'subapf-foxglove', (ConfigError,), args=args,
                     usage=usage)


if __name__ == '__main__':
    sys.exit(main())
