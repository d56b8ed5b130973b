"""A navigate_to_pose client as nav2_simple_commander's BasicNavigator uses the action
(send_goal_async, feedback callback, get_result_async, cancel_goal_async), run by
test_nav2_dds.py in a process that can import nav2_msgs. Each line of stdin is one
task, each answer one JSON line on stdout:

  goal X Y [FRAME]        send, wait for the result
  path X0 Y0 X1 Y1 ...    follow_path through these points (odom), wait for the result
  preempt X1 Y1 X2 Y2     send the first, once it has feedback send the second
  cancel X Y D            send, once the distance left fell by D metres cancel, wait

An answer: {"results": [{"status": "SUCCEEDED" | "ABORTED" | "CANCELED", "error_code",
"error_msg", "feedback": [{"t", "distance_remaining", "navigation_time",
"estimated_time_remaining", "recoveries", "x", "y"} or, following a path,
{"t", "distance_to_goal", "speed"}, ...]}, ...]}.
"""

import json
import sys
import time

from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from nav2_msgs.action import FollowPath, NavigateToPose
import rclpy
from rclpy.action import ActionClient

STATUS = {GoalStatus.STATUS_SUCCEEDED: 'SUCCEEDED', GoalStatus.STATUS_ABORTED: 'ABORTED',
          GoalStatus.STATUS_CANCELED: 'CANCELED'}
TIMEOUT = 240.0


class Client:
    def __init__(self):
        rclpy.init()
        self.node = rclpy.create_node('nav2_client')
        self.action = ActionClient(self.node, NavigateToPose, 'navigate_to_pose')
        self.follow = ActionClient(self.node, FollowPath, 'follow_path')

    def spin_until(self, done, timeout=TIMEOUT):
        end = time.monotonic() + timeout
        while not done():
            if time.monotonic() > end:
                raise TimeoutError('navigate_to_pose: no answer')
            rclpy.spin_once(self.node, timeout_sec=0.05)

    def send(self, x, y, frame='odom'):
        goal = NavigateToPose.Goal()
        goal.pose.header.frame_id = frame
        goal.pose.header.stamp = self.node.get_clock().now().to_msg()
        goal.pose.pose.position.x, goal.pose.pose.position.y = float(x), float(y)
        goal.pose.pose.orientation.w = 1.0
        record = {'feedback': []}

        def on_feedback(msg):
            fb = msg.feedback
            record['feedback'].append({
                't': time.monotonic(), 'distance_remaining': fb.distance_remaining,
                'navigation_time': fb.navigation_time.sec + fb.navigation_time.nanosec * 1e-9,
                'estimated_time_remaining': fb.estimated_time_remaining.sec
                + fb.estimated_time_remaining.nanosec * 1e-9,
                'recoveries': fb.number_of_recoveries, 'frame': fb.current_pose.header.frame_id,
                'x': fb.current_pose.pose.position.x, 'y': fb.current_pose.pose.position.y})
        return self._sent(self.action, goal, record, on_feedback)

    def send_path(self, *xy):
        goal = FollowPath.Goal()
        goal.path.header.frame_id = 'odom'
        for x, y in zip(xy[::2], xy[1::2], strict=True):
            pose = PoseStamped()
            pose.header.frame_id = 'odom'
            pose.pose.position.x, pose.pose.position.y = float(x), float(y)
            pose.pose.orientation.w = 1.0
            goal.path.poses.append(pose)
        record = {'feedback': []}

        def on_feedback(msg):
            record['feedback'].append({'t': time.monotonic(),
                                       'distance_to_goal': msg.feedback.distance_to_goal,
                                       'speed': msg.feedback.speed})
        return self._sent(self.follow, goal, record, on_feedback)

    def _sent(self, action, goal, record, on_feedback):
        self.spin_until(lambda: action.wait_for_server(timeout_sec=0.1))
        sent = action.send_goal_async(goal, feedback_callback=on_feedback)
        self.spin_until(sent.done)
        handle = sent.result()
        record['accepted'] = handle.accepted
        record['handle'] = handle
        if handle.accepted:
            record['result'] = handle.get_result_async()
        return record

    def finish(self, record):
        if record['accepted']:
            self.spin_until(record['result'].done)
            answer = record['result'].result()
            record.update(status=STATUS.get(answer.status, str(answer.status)),
                          error_code=answer.result.error_code,
                          error_msg=answer.result.error_msg)
        else:
            record['status'] = 'REJECTED'
        del record['handle']
        record.pop('result', None)
        return record


def preempt(client: Client, x1, y1, x2, y2) -> list[dict]:
    first = client.send(x1, y1)
    client.spin_until(lambda: first['feedback'])
    second = client.send(x2, y2)
    return [client.finish(first), client.finish(second)]


def cancel(client: Client, x, y, metres) -> list[dict]:
    record = client.send(x, y)
    fb = record['feedback']
    client.spin_until(lambda: fb and max(f['distance_remaining'] for f in fb)
                      - fb[-1]['distance_remaining'] >= float(metres))
    canceling = record['handle'].cancel_goal_async()
    client.spin_until(canceling.done)
    return [client.finish(record)]


def main() -> int:
    client = Client()
    tasks = {'goal': lambda *a: [client.finish(client.send(*a))],
             'preempt': lambda *a: preempt(client, *a),
             'cancel': lambda *a: cancel(client, *a),
             'path': lambda *a: [client.finish(client.send_path(*a))]}
    for line in sys.stdin:
        if words := line.split():
            results = tasks[words[0]](*words[1:])
            print(json.dumps({'results': results}), flush=True)
    client.node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
