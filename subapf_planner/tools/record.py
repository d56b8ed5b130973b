"""``subapf-record``: record ROS 2 topics to a rosbag2-compatible MCAP file.

Like ``ros2 bag record -s mcap``: each topic is subscribed (raw CDR, with the
reliability its publishers offer) as soon as it is discovered, messages are
written with their receive time as log_time, and the file is finalised (index
and summary) on Ctrl-C, SIGTERM or after ``--duration`` seconds.
"""

from __future__ import annotations

import argparse
import sys
import time

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions

from ..bag.reader import BagError, message_class
from ..bag.writer import McapRecorder, RecorderError
from ..ros.spinning import stop_on_signals

DEPTH = 500


class RecordNode(Node):
    def __init__(self, wanted: list[str], recorder: McapRecorder) -> None:
        super().__init__('subapf_record')
        self.wanted = [t if t.startswith('/') else '/' + t for t in wanted]
        self.recorder = recorder
        self.subscribed: set[str] = set()
        self.create_timer(0.2, self._discover)

    def _discover(self) -> None:
        for topic, types in self.get_topic_names_and_types():
            if topic not in self.wanted or topic in self.subscribed or not types:
                continue
            offered = self.get_publishers_info_by_topic(topic)
            if not offered:
                continue   # known from a subscriber only: wait to see the publishers' QoS
            best_effort = any(i.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT
                              for i in offered)
            latched = all(i.qos_profile.durability
                                      == DurabilityPolicy.TRANSIENT_LOCAL for i in offered)
            qos = QoSProfile(depth=DEPTH, reliability=ReliabilityPolicy.BEST_EFFORT
                             if best_effort else ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL if latched
                             else DurabilityPolicy.VOLATILE)
            self.recorder.add_topic(topic, types[0])
            self.create_subscription(message_class(types[0]), topic, self._writer(topic), qos,
                                     raw=True)
            self.subscribed.add(topic)
            self.get_logger().info(f'recording {topic} ({types[0]})')

    def _writer(self, topic: str):
        return lambda data: self.recorder.write(topic, data, time.time_ns())


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    p = argparse.ArgumentParser(prog='subapf-record', description=__doc__.splitlines()[0])
    p.add_argument('--topics', nargs='+', required=True, help='topics to record')
    p.add_argument('-o', '--output', required=True, help='MCAP file to write')
    p.add_argument('--duration', type=float, default=None, help='stop after this many seconds')
    args = p.parse_args(rclpy.utilities.remove_ros_args(argv))
    rclpy.init(args=['subapf-record', *argv], signal_handler_options=SignalHandlerOptions.NO)
    stop = stop_on_signals()
    recorder = node = None
    try:
        recorder = McapRecorder(args.output)
        node = RecordNode(args.topics, recorder)
        end = None if args.duration is None else time.monotonic() + args.duration
        while not stop.is_set() and (end is None or time.monotonic() < end):
            rclpy.spin_once(node, timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except (BagError, RecorderError, OSError) as exc:
        print(f'subapf-record: {exc}', file=sys.stderr)
        return 2
    finally:
        if recorder is not None:
            recorder.close()
            print(f'subapf-record: {recorder.count} messages in {args.output}')
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
