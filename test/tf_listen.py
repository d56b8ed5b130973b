"""Listen to /tf, /tf_static and odom and print what arrived as JSON (run by
test_tf.py in a process that can import tf2_msgs): python tf_listen.py COUNT."""

import json
import sys
import time

from nav_msgs.msg import Odometry
import rclpy
from tf2_msgs.msg import TFMessage

from subapf_planner.ros.conversions import stamp_to_seconds
from subapf_planner.ros.qos import LATCHED


def transform(t) -> dict:
    r, q = t.transform.translation, t.transform.rotation
    return {'parent': t.header.frame_id, 'child': t.child_frame_id,
            'stamp': stamp_to_seconds(t.header.stamp), 'xyz': [r.x, r.y, r.z],
            'q': [q.x, q.y, q.z, q.w]}


def main() -> int:
    count = int(sys.argv[1])
    rclpy.init()
    node = rclpy.create_node('tf_listen')
    got = {'tf': [], 'tf_static': [], 'odom': []}
    node.create_subscription(TFMessage, '/tf', lambda m: got['tf'].extend(
        transform(t) for t in m.transforms), 100)
    node.create_subscription(TFMessage, '/tf_static', lambda m: got['tf_static'].extend(
        transform(t) for t in m.transforms), LATCHED)
    node.create_subscription(Odometry, 'odom', lambda m: got['odom'].append({
        'stamp': stamp_to_seconds(m.header.stamp), 'frame': m.header.frame_id,
        'child': m.child_frame_id, 'xy': [m.pose.pose.position.x, m.pose.pose.position.y],
        'q': [m.pose.pose.orientation.z, m.pose.pose.orientation.w]}), 100)
    end = time.monotonic() + 60.0
    while time.monotonic() < end and (len(got['tf']) < count or not got['tf_static']):
        rclpy.spin_once(node, timeout_sec=0.05)
    print(json.dumps(got))
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
