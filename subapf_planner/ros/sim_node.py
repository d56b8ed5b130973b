"""``sim_node`` (``subapf-sim``): the PyBullet simulator of one robot as a ROS 2 node.

The robot is ``robot`` (core/robot.py: the burger by default), in its own frames.
Publishes ``/clock`` (rosgraph_msgs/Clock) and stamps everything with
simulated time, ``scan`` (the robot's laser frame, base_scan for a TurtleBot3,
sensor-data QoS, at its lidar's rate: 5 Hz for the LDS-01), ``odom``
(odom -> the robot's base frame, 20 Hz), ``ground_truth`` (nav_msgs/Odometry in the
world frame) and each attempt's outcome on ``sim_outcome`` (std_msgs/String:
reached, collision or timeout; transient-local, once per attempt). Subscribes
``cmd_vel`` (TwistStamped, or Twist with enable_stamped_cmd_vel:=false) and
``goal_pose`` (geometry_msgs/PoseStamped in odom or map: the world frame at the
start), as the planner does. The first attempt is at the world's goal from the
start; each new goal starts another, with its own time limit (sim/attempt.py).
The simulation never stops at an outcome: /clock goes on, and the next goal is
served. Physics advances in steps of 50 ms of simulated time on a wall-clock timer,
``rate`` times faster than real time. ``/tf`` and ``/tf_static`` go out when
tf2_msgs is installed (not among the PyPI ROS wheels; odom carries the same pose).
A world with moving obstacles also gets ``moving_obstacles``
(visualization_msgs/MarkerArray in odom: where each truly is, at the scan rate).
With ``publish_map`` the world's map goes out on ``map`` (nav_msgs/OccupancyGrid,
transient local) and, with tf2_msgs, ``map`` -> ``odom`` on /tf, as map_server and a
localiser give them (with ``map_error_*`` added: a localiser's error).
"""

from __future__ import annotations

from dataclasses import dataclass
import sys

from geometry_msgs.msg import PoseStamped, Twist, TwistStamped
from nav_msgs.msg import OccupancyGrid as GridMsg
from nav_msgs.msg import Odometry
import numpy as np
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from ..core.params import ConfigError, check_fields, param
from ..core.robot import RobotDescription, compose, invert
from ..sim.attempt import Attempts
from ..sim.faults import FAULT_SEED_OFFSET, ScanDelivery, ScanFaults, delivery_faults
from ..sim.simulator import RobotSim, SimConfig
from ..sim.solvability import world_map
from ..sim.world import WorldError, load_world
from .conversions import (
    cmd_from_msg,
    known_map_to_msg,
    odom_to_msg,
    scan_to_msg,
    seconds_to_stamp,
    transform_msg,
)
from .markers import moving_obstacle_markers
from .parameters import declare, read, warn_undeclared
from .qos import LATCHED, listened
from .spinning import spin_node
from .usage import node_usage

#: Simulated time per timer tick [s]; odometry and /clock go out every tick.
TICK = 0.05
#: How often map -> odom and the moving obstacles' markers go out [s].
SCAN_PERIOD = 0.2
#: Frames a goal on goal_pose may be given in: the simulator's odom frame, and map (the
#: planner's memory frame: odom as it was at the start); both are the world frame.
GOAL_FRAMES = ('', 'odom', 'map')
#: Shortest wall-clock period of the stepping timer [s].
MIN_TIMER_PERIOD = 0.005


def static_links(robot: RobotDescription
                 ) -> list[tuple[str, str, tuple[float, float, float], float]]:
    """The robot's fixed frames as /tf_static has them (REP-105): (parent, child, xyz
    [m], yaw [rad]): base_footprint -> base_link -> the laser, or base_link -> the laser
    for a robot whose base frame is base_link."""
    laser, height = robot.laser, robot.base_link_height
    links = [('base_link', robot.laser_frame, (laser.x, laser.y, laser.z - height), laser.yaw)]
    if robot.base_frame != 'base_link':
        links.insert(0, (robot.base_frame, 'base_link', (0.0, 0.0, height), 0.0))
    return links


@dataclass(frozen=True)
class SimNodeOptions:
    """The sim node's own parameters (the rest: SimConfig and ScanFaults)."""

    world: str = param('', 'World file (format v1 YAML); required', read_only=True)
    rate: float = param(1.0, 'Simulated seconds per wall-clock second', '', 0.1, 100.0,
                        read_only=True)
    enable_stamped_cmd_vel: bool = param(True, 'Subscribe TwistStamped (true) or Twist',
                                         read_only=True)
    publish_map: bool = param(False, "Publish the world's map on map (nav_msgs/OccupancyGrid, "
                              'transient local: its static obstacles at 0.05 m, as map_server '
                              'would) and, with tf2_msgs, map -> odom on /tf at the scan rate, '
                              'as a localiser would: where odom truly is in the world, with '
                              'map_error_x/y/yaw added', read_only=True)
    map_error_x: float = param(0.0, "The localiser's error in map -> odom (x)", 'm', -10.0,
                               10.0, read_only=True)
    map_error_y: float = param(0.0, "The localiser's error in map -> odom (y)", 'm', -10.0,
                               10.0, read_only=True)
    map_error_yaw: float = param(0.0, "The localiser's error in map -> odom (yaw)", 'rad',
                                 -3.15, 3.15, read_only=True)
    start_subscribers: int = param(0, 'Hold the simulation at time 0 until /clock has this '
                                   'many subscribers, and odom and scan one each (a node on '
                                   'simulated time and a recorder each subscribe /clock: the '
                                   'run starts when they listen, none of its first messages '
                                   'lost); 0: start at once', '', 0, 100, read_only=True)

    def __post_init__(self) -> None:
        check_fields(self)


#: The parameter groups of the node with their titles, in declaration order (also the
#: sections of config/planner.yaml and of --help).
SECTIONS = (('node (ros/sim_node.py)', SimNodeOptions),
            ('simulator (sim/simulator.py)', SimConfig),
            ('scan faults (sim/faults.py)', ScanFaults))
GROUPS = tuple(cls for _, cls in SECTIONS)


class SimNode(Node):
    def __init__(self, **kwargs) -> None:
        super().__init__('subapf_sim', **kwargs)
        declare(self, *GROUPS)
        warn_undeclared(self)
        options = read(self, SimNodeOptions)
        if not options.world:
            raise WorldError('parameter "world" (a world file) is required: --ros-args -p '
                             'world:=FILE (see --help)')
        self.world = load_world(options.world)
        sim_cfg = read(self, SimConfig)
        self.sim = RobotSim(self.world, sim_cfg)
        self.robot = self.sim.robot
        self._scans: ScanDelivery[LaserScan] = ScanDelivery(
            delivery_faults(sim_cfg, read(self, ScanFaults)), sim_cfg.seed + FAULT_SEED_OFFSET)
        self.clock_pub = self.create_publisher(Clock, '/clock', 10)
        self.scan_pub = self.create_publisher(LaserScan, 'scan', qos_profile_sensor_data)
        self.odom_pub = self.create_publisher(Odometry, 'odom', 10)
        self.truth_pub = self.create_publisher(Odometry, 'ground_truth', 10)
        self.outcome_pub = self.create_publisher(String, 'sim_outcome', LATCHED)
        self.moving_pub = self.create_publisher(MarkerArray, 'moving_obstacles', 10) \
            if self.world.moving else None
        self._setup_tf()
        self._map_error = (options.map_error_x, options.map_error_y, options.map_error_yaw) \
            if options.publish_map else None
        if options.publish_map:
            self.create_publisher(GridMsg, 'map', LATCHED).publish(
                known_map_to_msg(world_map(self.world), 'map', seconds_to_stamp(0.0)))
        cmd_type = TwistStamped if options.enable_stamped_cmd_vel else Twist
        self.create_subscription(cmd_type, 'cmd_vel', self._on_cmd, 10)
        self.create_subscription(PoseStamped, 'goal_pose', self._on_goal, 10)
        self.attempts = Attempts(self.world)
        self._next_scan = 0.0
        self._start_subscribers = options.start_subscribers
        # Fast mode: several ticks per timer callback, so the executor's overhead per
        # callback does not cap the speed-up.
        self.ticks_per_call = max(1, int(round(MIN_TIMER_PERIOD * options.rate / TICK)))
        self.timer = self.create_timer(self.ticks_per_call * TICK / options.rate,
                                       self._on_timer)
        self.get_logger().info(f'world {self.world.name} from {options.world}, '
                               f'rate {options.rate}x, robot {sim_cfg.robot}')

    def _setup_tf(self) -> None:
        """/tf (odom -> the base frame) and /tf_static (base_footprint -> base_link ->
        the laser, or base_link -> the laser for a robot whose base frame is base_link)
        when tf2_msgs is installed (a Jazzy install has it; the PyPI wheels this project
        tests with do not, and then odom alone carries the pose)."""
        try:
            from tf2_msgs.msg import TFMessage
        except ImportError:
            self.tf_pub = None
            self.get_logger().info('tf2_msgs not installed: no /tf published')
            return
        self._tf_message = TFMessage
        self.tf_pub = self.create_publisher(TFMessage, '/tf', 10)
        static = self.create_publisher(TFMessage, '/tf_static', LATCHED)
        static.publish(TFMessage(transforms=[
            transform_msg(parent, child, xyz, yaw, 0.0)
            for parent, child, xyz, yaw in static_links(self.robot)]))

    def _on_cmd(self, msg: Twist | TwistStamped) -> None:
        self.sim.set_command(*cmd_from_msg(msg))

    def _on_goal(self, msg: PoseStamped) -> None:
        """A goal (the planner's too): a new attempt, unless it is the running one's."""
        goal = np.array([msg.pose.position.x, msg.pose.position.y], dtype=float)
        if msg.header.frame_id not in GOAL_FRAMES or not np.all(np.isfinite(goal)):
            self.get_logger().info(f'goal in frame "{msg.header.frame_id}" at {goal}: not '
                                   'an attempt (the planner refuses it too)')
            return
        if self.attempts.goal(goal, self.sim.time):
            a = self.attempts.current
            self.get_logger().info(
                f'attempt {a.number}: goal ({goal[0]:.2f}, {goal[1]:.2f}) at '
                f't={a.start:.1f} s, time limit {self.world.time_limit:g} s')

    def _on_timer(self) -> None:
        if self._start_subscribers:   # held at time 0 until enough listen
            clocked = self.clock_pub.get_subscription_count()
            if clocked < self._start_subscribers or not listened(self.odom_pub) \
                    or not listened(self.scan_pub):
                return
            self.get_logger().info(f'{clocked} subscribers to /clock: simulating')
            self._start_subscribers = 0
        for _ in range(self.ticks_per_call):
            self._on_tick()

    def _on_tick(self) -> None:
        sim = self.sim
        sim.collided = False   # re-armed each tick: whether it touched during this one
        sim.step(TICK)
        t = sim.time
        pose, twist = sim.odometry()
        base = self.robot.base_frame
        self.odom_pub.publish(odom_to_msg(pose, twist, t, child_frame_id=base))
        if self.tf_pub is not None and listened(self.tf_pub):
            self.tf_pub.publish(self._tf_message(transforms=[transform_msg(
                'odom', base, (pose[0], pose[1], 0.0), pose[2], t)]))
        if listened(self.truth_pub):
            self.truth_pub.publish(odom_to_msg(sim.true_pose(), twist, t, 'world'))
        for sweep in sim.sweeps():   # as the lidar's driver publishes them
            self._scans.capture(scan_to_msg(sweep, self.robot.laser_frame),
                                sim.sweep_end(sweep))
        if t + 1e-9 >= self._next_scan:
            self._next_scan += SCAN_PERIOD
            if self._map_error is not None and self.tf_pub is not None:
                # odom in the world (the map), as a localiser finds it, with its error
                odom_in_map = compose(self._map_error,
                                      compose(sim.true_pose(), invert(pose)))
                self.tf_pub.publish(self._tf_message(transforms=[transform_msg(
                    'map', 'odom', (odom_in_map[0], odom_in_map[1], 0.0), odom_in_map[2],
                    t)]))
            if self.moving_pub is not None and listened(self.moving_pub):
                # where they truly are, at the scan rate
                self.moving_pub.publish(moving_obstacle_markers(
                    self.world.moving_at(t), 'odom', seconds_to_stamp(t)))
        # scans go out after the lidar's latency and the faults', stamped with their
        # first beam's instant
        for msg in self._scans.due(t):
            self.scan_pub.publish(msg)
        # the clock last: a node on sim time then has this tick's data when its timers fire
        self.clock_pub.publish(Clock(clock=seconds_to_stamp(t)))
        self._check_outcome()

    def close(self) -> None:
        """Release the physics server."""
        self.sim.close()

    def _check_outcome(self) -> None:
        sim = self.sim
        outcome = self.attempts.update(sim.true_pose(), sim.collided, sim.time)
        if outcome is not None:
            a = self.attempts.current
            self.outcome_pub.publish(String(data=str(outcome)))
            stood = ' (hit while stopped)' if sim.collided and sim.hit_while_stopped else ''
            self.get_logger().info(
                f'outcome: {outcome}{stood} at t={sim.time:.1f} s (attempt {a.number}, '
                f'{sim.time - a.start:.1f} s after its goal); simulating on, the next goal '
                'on goal_pose starts the next attempt')


def usage() -> str:
    """``subapf-sim --help``."""
    return node_usage(
        'subapf-sim', 'sim_node', 'subapf_sim', """
        The PyBullet simulator of a robot of core/robot.py (parameter robot: burger,
        waffle_pi, turtlebot4, jackal): loads the world file (parameter world, required;
        format v1, docs/worlds.md), subscribes cmd_vel and goal_pose, publishes /clock,
        scan (the robot's laser frame, at its lidar's rate), odom (20 Hz), ground_truth,
        moving_obstacles, /tf and /tf_static (with tf2_msgs), and on sim_outcome
        (std_msgs/String, transient local) the outcome of each attempt: reached,
        collision or timeout.

        The first attempt is at the world's goal from the start; each goal sent on
        goal_pose (frame odom or map: the world frame) starts another, with the world's
        time limit of its own. After an outcome the simulation goes on (/clock keeps
        advancing) and serves the next goal.

        Example: subapf-sim --ros-args -p world:=sim/worlds/fig6d_big_wall.yaml
        -p rate:=5.0""",
        SECTIONS)


def main(args: list[str] | None = None) -> int:
    return spin_node(SimNode, 'subapf-sim', (WorldError, ConfigError), SimNode.close, args,
                     usage=usage)


if __name__ == '__main__':
    sys.exit(main())
