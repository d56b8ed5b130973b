"""The bringup's own node: sends the goal, watches the outcome, optionally records MCAP."""

from __future__ import annotations

import subprocess
import time

from geometry_msgs.msg import PoseStamped, TwistStamped
from nav_msgs.msg import OccupancyGrid, Odometry, Path
import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan, TimeReference
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from ..bag.writer import McapRecorder, type_name_of
from .conversions import pose_from_odom, stamp_to_seconds
from .processes import rss_mib
from .qos import LATCHED
from .spinning import stop_on_signals

#: Depth of the recording subscriptions: deep enough that a busy recorder loses nothing.
RECORD_DEPTH = 500
#: Once the simulator reports the goal reached, how long the run goes on while the
#: planner still drives (arrival_distance: it drives on inside the tolerance) [s, wall].
ARRIVAL_WAIT = 10.0
_SENSOR = QoSProfile(depth=RECORD_DEPTH, reliability=ReliabilityPolicy.BEST_EFFORT)
_RELIABLE = QoSProfile(depth=RECORD_DEPTH)
_LATCHED_DEEP = QoSProfile(depth=RECORD_DEPTH, durability=DurabilityPolicy.TRANSIENT_LOCAL)
#: topic -> (type, QoS) recorded by --record (absolute names of the bringup graph).
RECORDED = {
    '/scan': (LaserScan, _SENSOR),
    '/odom': (Odometry, _RELIABLE),
    '/cmd_vel': (TwistStamped, _RELIABLE),
    '/goal_pose': (PoseStamped, _RELIABLE),
    '/clock': (Clock, _RELIABLE),
    '/ground_truth': (Odometry, _RELIABLE),
    '/sim_outcome': (String, LATCHED),
    '/subapf_planner/status': (String, _RELIABLE),
    '/subapf_planner/taken': (TimeReference, _RELIABLE),
    '/subapf_planner/markers': (MarkerArray, _RELIABLE),
    '/subapf_planner/plan': (Path, _RELIABLE),
    '/subapf_planner/map': (OccupancyGrid, _LATCHED_DEEP),
    '/moving_obstacles': (MarkerArray, _RELIABLE),
}
CLOCK = '/clock'
#: Longest the recorder drains its queues on close [s].
DRAIN_TIMEOUT = 5.0
#: Recorded only when asked for by name (--record-topics): the map is 160 kB a message.
ON_REQUEST = {'/subapf_planner/map'}
#: Recorded topics a replay needs from the first message: their recording waits for a
#: publisher (when recorded).
NEEDED = ('/scan', '/odom', '/cmd_vel', '/subapf_planner/taken')
#: /clock's subscribers the simulator waits for (sim_node start_subscribers; and one
#: each on odom and scan: the planner's): the planner's and the supervisor's, which
#: subscribes once its recording listens.
START_SUBSCRIBERS = 2
#: Longest wait for the recording to listen to every publisher before the run starts
#: anyway (with a warning) [s, wall].
LISTEN_TIMEOUT = 30.0


class Supervisor:
    """Owns rclpy in the bringup process for one run."""

    def __init__(self, world, record: str | None, method: str | None = None,
                 record_topics: list[str] | None = None) -> None:
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        self.stop = stop_on_signals()   # Ctrl-C or SIGTERM end the run cleanly
        self.world = world
        self.method = method
        self.node = Node('subapf_bringup')
        self.recorder = McapRecorder(record) if record else None
        self._written = 0   # messages recorded (close drains until none come)
        self.path: list = []
        self.sim_time = 0.0
        #: Simulated time when the outcome came (the last ground truth then) [s].
        self.outcome_time: float | None = None
        self.outcome: str | None = None
        self.status = ''
        self.rss_mib: dict[str, list[float]] = {}
        # latched, so a recorder that starts late still gets the goal
        self.goal_pub = self.node.create_publisher(PoseStamped, '/goal_pose', LATCHED)
        self.node.create_subscription(String, '/sim_outcome', self._on_outcome, LATCHED)
        self.node.create_subscription(Odometry, '/ground_truth', self._on_truth, 10)
        self.node.create_subscription(String, '/subapf_planner/status', self._on_status, 10)
        #: The recording's subscriptions but /clock's, which starts the run (_start).
        self._recorded: dict[str, object] = {}
        self._clock = None
        chosen = (record_topics or set(RECORDED) - ON_REQUEST) if record else ()
        self._record_clock = CLOCK in chosen
        for topic, (msg_type, _) in RECORDED.items():
            if topic in chosen:
                self.recorder.add_topic(topic, type_name_of(msg_type))
                if topic != CLOCK:
                    self._recorded[topic] = self._subscribe(topic)

    def _subscribe(self, topic: str):
        msg_type, qos = RECORDED[topic]
        return self.node.create_subscription(msg_type, topic, self._recording(topic), qos,
                                             raw=True)

    def _deaf(self) -> list[str]:
        """The recorded topics whose subscription has not matched every publisher of the
        topic yet (or, for those a replay needs, none)."""
        return sorted(topic for topic, sub in self._recorded.items()
                      if sub.get_publisher_count() < max(int(topic in NEEDED),
                                                         self.node.count_publishers(topic)))

    def _start(self, since: float) -> None:
        """Subscribe /clock (recorded or not) once the recording listens to every
        publisher, or LISTEN_TIMEOUT after ``since``: the simulator, waiting for
        START_SUBSCRIBERS on /clock, starts the run then."""
        if self._clock is not None:
            return
        deaf = self._deaf()
        if deaf and time.monotonic() - since < LISTEN_TIMEOUT:
            return
        if deaf:
            print(f'subapf-bringup: the recording does not hear {deaf} after '
                  f'{LISTEN_TIMEOUT:g} s; starting anyway', flush=True)
        self._clock = self._subscribe(CLOCK) if self._record_clock else \
            self.node.create_subscription(Clock, CLOCK, lambda _msg: None, 10)

    def _recording(self, topic: str):
        def write(data: bytes) -> None:
            self.recorder.write(topic, data, time.time_ns())
            self._written += 1
        return write

    def _on_outcome(self, msg: String) -> None:
        if self.outcome is None:   # the simulator goes on after it: the first is the run's
            self.outcome, self.outcome_time = msg.data, self.sim_time

    def _on_truth(self, msg: Odometry) -> None:
        self.path.append(pose_from_odom(msg))
        self.sim_time = stamp_to_seconds(msg.header.stamp)

    def _on_status(self, msg: String) -> None:
        if msg.data.split(':')[0] != self.status.split(':')[0]:
            print(f'subapf-bringup: planner {msg.data}', flush=True)
        self.status = msg.data

    def _send_goal(self) -> None:
        goal = PoseStamped()
        goal.header.frame_id = 'odom'
        goal.pose.position.x, goal.pose.position.y = map(float, self.world.goal)
        goal.pose.orientation.w = 1.0
        self.goal_pub.publish(goal)

    def run(self, children: list[subprocess.Popen], timeout: float,
            names: tuple[str, ...] = ()) -> str:
        """Spin until the simulator reports an outcome (for ``reached``: and the planner
        has stopped driving, or ARRIVAL_WAIT later), a child dies, or the timeout.
        Samples each named child's resident memory once a second into ``rss_mib``."""
        started = time.monotonic()
        deadline = started + timeout
        goal_sent_at = None
        arrived_at = None
        next_sample = time.monotonic()
        while time.monotonic() < deadline:
            if self.stop.is_set():
                return 'interrupted'
            if names and time.monotonic() >= next_sample:
                next_sample += 1.0
                for name, child in zip(names, children, strict=True):
                    self.rss_mib.setdefault(name, []).append(rss_mib(child.pid))
            rclpy.spin_once(self.node, timeout_sec=0.05)
            self._start(started)
            if self.outcome == 'reached' and self.status.startswith('driving'):
                arrived_at = arrived_at or time.monotonic()   # it drives on to the goal
                if time.monotonic() - arrived_at < ARRIVAL_WAIT:
                    continue
            if self.outcome is not None:
                return self.outcome
            dead = [(name, c) for name, c in zip(names or ('a node',) * len(children),
                                                  children, strict=True)
                     if c.poll() is not None]
            if dead:
                name, child = dead[0]
                if child.returncode == 2:   # spin_node: bad parameters, world or port
                    return f'failed: {name} did not start (exit code 2)'
                return f'failed: {name} exited with code {child.returncode}'
            # (re)send the goal until the planner has taken it
            waiting = not self.status or self.status.startswith(('idle', 'waiting'))
            if self.goal_pub.get_subscription_count() > 0 and waiting and (
                    goal_sent_at is None or time.monotonic() - goal_sent_at > 1.0):
                self._send_goal()
                goal_sent_at = time.monotonic()
        return 'failed: wall-clock timeout'

    def close(self) -> None:
        if self.recorder is not None:
            # drain what is already queued (the nodes are stopped: nothing new comes; what
            # they sent last, e.g. the planner's zero velocity, was acknowledged, so it is
            # here), at most DRAIN_TIMEOUT, then finalise the file
            deadline = time.monotonic() + DRAIN_TIMEOUT
            idle = 0
            while idle < 5 and time.monotonic() < deadline:
                before = self._written
                rclpy.spin_once(self.node, timeout_sec=0.01)
                idle = idle + 1 if self._written == before else 0
            self.recorder.close()
        self.node.destroy_node()
        rclpy.try_shutdown()

