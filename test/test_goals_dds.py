"""Goal after goal over DDS, as a user drives it: sim_node and planner_node started by
hand (as sim.launch.py does), goals sent on goal_pose. The simulator keeps simulating
after each outcome and serves the next goal with a time limit of its own; the
README's goal script waits for the outcome."""

import re
import subprocess
import sys
import time

from conftest import PARAMS, REPO, ChildGraph
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry
import numpy as np
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rosgraph_msgs.msg import Clock
from std_msgs.msg import String

from subapf_planner.core.status import State, parse_status
from subapf_planner.ros.conversions import pose_from_odom, stamp_to_seconds
from subapf_planner.ros.processes import join_domain, start, stop
from subapf_planner.ros.qos import LATCHED

pytestmark = pytest.mark.dds

#: An open floor: the world's goal 1 m ahead; 15 s of simulated time per goal.
OPEN_FLOOR = """\
name: open_floor
start: [0.0, 0.0, 0.0]
goal: [1.0, 0.0]
time_limit: 15
obstacles:
  - circle: {center: [-3.0, 3.0], radius: 0.3}
"""
RATE = 2.0


class Graph(ChildGraph):
    """sim_node and planner_node as child processes, and a node here that sends goals
    and hears the clock, the outcomes, the planner's states and the ground truth."""

    def __init__(self, domain: int, tmp_path):
        self.log_dir = tmp_path
        self.world = tmp_path / 'open_floor.yaml'
        self.world.write_text(OPEN_FLOOR)
        self.env = join_domain(domain)
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node('user', context=self.context)
        self.ex = SingleThreadedExecutor(context=self.context)
        self.ex.add_node(self.node)
        self.clock = 0.0
        self.outcomes: list[tuple[str, float]] = []   # (outcome, clock when heard)
        self.states: list[str] = []
        self.pose = None
        self.node.create_subscription(Clock, '/clock', self._on_clock, 10)
        self.node.create_subscription(String, 'sim_outcome', lambda m: self.outcomes.append(
            (m.data, self.clock)), LATCHED)
        self.node.create_subscription(String, '/subapf_planner/status',
                                      lambda m: self.states.append(m.data), 100)
        self.node.create_subscription(Odometry, 'ground_truth', lambda m: setattr(
            self, 'pose', pose_from_odom(m)), 10)
        self.goal_pub = self.node.create_publisher(PoseStamped, 'goal_pose', 10)
        self.children = [
            start('sim_node', ['-p', f'world:={self.world}', '-p', f'rate:={RATE}'],
                  self.env, log=tmp_path / 'sim.log'),
            start('planner_node', ['--params-file', str(PARAMS), '-p', 'use_sim_time:=true'],
                  self.env, log=tmp_path / 'planner.log')]

    def _on_clock(self, msg):
        self.clock = stamp_to_seconds(msg.clock)

    def state(self) -> State | None:
        return parse_status(self.states[-1])[0] if self.states else None

    def send_goal(self, x: float, y: float) -> None:
        """Send (x, y) in odom, again every half second until the planner says it took
        it (``driving: new goal`` on its status), as the README's script does."""
        goal = PoseStamped()
        goal.header.frame_id = 'odom'
        goal.pose.position.x, goal.pose.position.y = float(x), float(y)
        self.until(lambda: self.goal_pub.get_subscription_count() == 2, 60,
                   'the simulator and the planner subscribing goal_pose')
        self.states.clear()
        sent = [-1.0]

        def taken():
            if 'driving: new goal' in self.states:
                return True
            if time.monotonic() - sent[0] > 0.5:
                self.goal_pub.publish(goal)
                sent[0] = time.monotonic()
            return False
        self.until(taken, 60, f'the planner taking the goal ({x:.2f}, {y:.2f})')

    def close(self):
        stop(self.children)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


@pytest.fixture
def graph(ros_env, tmp_path):
    g = Graph(int(ros_env['ROS_DOMAIN_ID']), tmp_path)
    yield g
    g.close()


def outcome_of_goal(graph: Graph, n: int, final: State) -> float:
    """Wait for the n-th outcome (1-based) and for the planner's final state; the
    simulated time the outcome came at."""
    graph.until(lambda: len(graph.outcomes) >= n, 120, f'outcome {n}')
    assert len(graph.outcomes) == n, graph.outcomes   # one per attempt
    if final is not None:
        graph.until(lambda: graph.state() is final, 60, f'planner state {final}')
    return graph.outcomes[-1][1]


def clock_goes_on(graph: Graph, since: float, seconds: float = 2.0) -> None:
    graph.until(lambda: graph.clock > since + seconds, 60,
                f'/clock past {since + seconds:.1f} s (it stood at {graph.clock:.1f} s)')


def test_the_simulator_serves_goal_after_goal_after_reached_and_after_timeout(graph):
    """The world's goal (reached), a goal too far for the time limit (timeout: the limit
    counts from that goal, not from the start), then two near goals (reached): after
    each outcome /clock keeps advancing and the next goal is served."""
    graph.send_goal(1.0, 0.0)   # the world's goal: the simulator's first attempt
    reached = outcome_of_goal(graph, 1, State.REACHED)
    assert graph.outcomes[0][0] == 'reached'
    clock_goes_on(graph, reached)
    # a second goal, 6 m away: at 0.22 m/s at least 27 s, the limit is 15 s from it
    sent = graph.clock
    graph.send_goal(1.0, -6.0)
    timed_out = outcome_of_goal(graph, 2, None)
    assert graph.outcomes[1][0] == 'timeout', graph.outcomes
    # (the outcome is judged on the simulator's clock: its own limit, from the goal on;
    # heard here a little later than it came)
    assert 15.0 - 0.5 <= timed_out - sent <= 15.0 + 2.0, (sent, timed_out)
    assert timed_out > 15.0 + reached   # not the world's limit from the start
    assert not graph.state().final   # the planner drives on: only the simulator's limit
    clock_goes_on(graph, timed_out)
    # a third and a fourth goal, each 0.8 m from where the robot is
    for n, heading in ((3, 0.0), (4, np.pi / 2)):
        x, y = graph.pose[:2] + 0.8 * np.array([np.cos(heading), np.sin(heading)])
        graph.send_goal(x, y)
        at = outcome_of_goal(graph, n, State.REACHED)
        assert graph.outcomes[-1][0] == 'reached', graph.outcomes
        assert np.hypot(*(graph.pose[:2] - (x, y))) < 0.15
        clock_goes_on(graph, at)
    log = (graph.log_dir / 'sim.log').read_text()
    assert 'attempt 4: goal' in log and 'Traceback' not in log


def readme_goal_script() -> str:
    """The rclpy script of the README's "Sending a goal" section."""
    text = (REPO / 'README.md').read_text()
    section = re.split(r'\n##+ ', text.split('### Sending a goal\n', 1)[1], maxsplit=1)[0]
    scripts = re.findall(r'```python\n(.+?)\n```', section, re.S)
    assert len(scripts) == 1
    return scripts[0] + '\n'


def test_the_readme_goal_script_waits_for_the_outcome(graph, tmp_path):
    script = tmp_path / 'send_goal.py'
    script.write_text(readme_goal_script())
    t0 = time.monotonic()
    r = subprocess.run([sys.executable, str(script)], env=graph.env, capture_output=True,
                       text=True, timeout=180)
    assert r.returncode == 0, r.stdout + r.stderr + graph.logs()
    assert r.stdout.strip().splitlines()[-1] == 'reached', r.stdout
    # it waited for the outcome: the robot stands at the script's goal, (2.0, 0.5)
    graph.until(lambda: graph.pose is not None, 30, 'ground truth')
    assert np.hypot(*(graph.pose[:2] - (2.0, 0.5))) < 0.2, (graph.pose, time.monotonic() - t0)
