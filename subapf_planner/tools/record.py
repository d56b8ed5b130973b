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
from rclpy.signals import SignalHandlerOptions

from ..bag.reader import BagError
from ..bag.writer import McapRecorder, RecorderError
from ..ros.spinning import stop_on_signals
from ..ros.tap import TopicTap


class RecordNode(Node):
    def __init__(self, wanted: list[str], recorder: McapRecorder) -> None:
        super().__init__('subapf_record')
        self.tap = TopicTap(self, wanted, recorder, 'recording')


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
