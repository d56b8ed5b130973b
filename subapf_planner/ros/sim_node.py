"""``sim_node`` (``subapf-sim``): the PyBullet burger stand-in as a ROS 2 node.

Publishes ``/clock`` (rosgraph_msgs/Clock) and stamps everything with
simulated time, ``scan`` (frame base_scan, sensor-data QoS, 5 Hz), ``odom``
(odom -> base_footprint, 20 Hz), ``ground_truth`` (nav_msgs/Odometry in the
world frame) and the run's outcome on ``sim_outcome`` (std_msgs/String:
reached, collision or timeout; transient-local, published once). Subscribes
``cmd_vel`` (TwistStamped, or Twist with enable_stamped_cmd_vel:=false).
Physics advances in steps of 50 ms of simulated time on a wall-clock timer,
``rate`` times faster than real time. ``/tf`` and ``/tf_static`` go out when
tf2_msgs is installed (not among the PyPI ROS wheels; odom carries the same pose).
A world with moving obstacles also gets ``moving_obstacles``
(visualization_msgs/MarkerArray in odom: where each truly is, at the scan rate).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
import sys

from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_msgs.msg import String
from visualization_msgs.msg import MarkerArray

from ..core.params import ConfigError, check_fields, param
from ..core.status import Outcome
from ..sim.faults import FAULT_SEED_OFFSET, ScanDelivery, ScanFaults
from ..sim.outcome import outcome_of
from ..sim.simulator import ROBOT, BurgerSim, SimConfig
from ..sim.world import WorldError, load_world
from .conversions import (
    cmd_from_msg,
    odom_to_msg,
    scan_to_msg,
    seconds_to_stamp,
    transform_msg,
)
from .markers import moving_obstacle_markers
from .parameters import declare, read
from .qos import LATCHED, listened
from .spinning import spin_node

#: Simulated time per timer tick [s]; odometry and /clock go out every tick.
TICK = 0.05
SCAN_PERIOD = 0.2
#: After ``reached`` the simulation goes on while the robot is commanded to move (the
#: planner drives on inside the tolerance to arrival_distance), at most this long [s].
ARRIVAL_TIME = 10.0
#: REP-105 frames of the burger: base_link above base_footprint, base_scan in base_link.
BASE_LINK_HEIGHT = ROBOT.base_link_height
LASER_IN_BASE_LINK = (ROBOT.laser.x, ROBOT.laser.y, ROBOT.laser.z - BASE_LINK_HEIGHT)
#: Shortest wall-clock period of the stepping timer [s].
MIN_TIMER_PERIOD = 0.005


@dataclass(frozen=True)
class SimNodeOptions:
    """The sim node's own parameters (the rest: SimConfig and ScanFaults)."""

    world: str = param('', 'World file (format v1 YAML); required', read_only=True)
    rate: float = param(1.0, 'Simulated seconds per wall-clock second', '', 0.1, 100.0,
                        read_only=True)
    enable_stamped_cmd_vel: bool = param(True, 'Subscribe TwistStamped (true) or Twist',
                                         read_only=True)

    def __post_init__(self) -> None:
        check_fields(self)


#: The parameter groups of the node, in declaration order.
GROUPS = (SimNodeOptions, SimConfig, ScanFaults)


class SimNode(Node):
    def __init__(self, **kwargs) -> None:
        super().__init__('subapf_sim', **kwargs)
        declare(self, *GROUPS)
        options = read(self, SimNodeOptions)
        if not options.world:
            raise WorldError('parameter "world" (a world file) is required')
        self.world = load_world(options.world)
        sim_cfg = read(self, SimConfig)
        self.sim = BurgerSim(self.world, sim_cfg)
        self._scans: ScanDelivery[LaserScan] = ScanDelivery(read(self, ScanFaults),
                                                            sim_cfg.seed + FAULT_SEED_OFFSET)
        self.clock_pub = self.create_publisher(Clock, '/clock', 10)
        self.scan_pub = self.create_publisher(LaserScan, 'scan', qos_profile_sensor_data)
        self.odom_pub = self.create_publisher(Odometry, 'odom', 10)
        self.truth_pub = self.create_publisher(Odometry, 'ground_truth', 10)
        self.outcome_pub = self.create_publisher(String, 'sim_outcome', LATCHED)
        self.moving_pub = self.create_publisher(MarkerArray, 'moving_obstacles', 10) \
            if self.world.moving else None
        self._setup_tf()
        cmd_type = TwistStamped if options.enable_stamped_cmd_vel else Twist
        self.create_subscription(cmd_type, 'cmd_vel', self._on_cmd, 10)
        self.outcome: Outcome | None = None
        self._outcome_time = math.inf
        self._next_scan = 0.0
        # Fast mode: several ticks per timer callback, so the executor's overhead per
        # callback does not cap the speed-up.
        self.ticks_per_call = max(1, int(round(MIN_TIMER_PERIOD * options.rate / TICK)))
        self.timer = self.create_timer(self.ticks_per_call * TICK / options.rate,
                                       self._on_timer)
        self.get_logger().info(f'world {self.world.name} from {options.world}, '
                               f'rate {options.rate}x')

    def _setup_tf(self) -> None:
        """/tf (odom -> base_footprint) and /tf_static (base_footprint -> base_link ->
        base_scan) when tf2_msgs is installed (a Jazzy install has it; the PyPI wheels
        this project tests with do not, and then odom alone carries the pose)."""
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
            transform_msg('base_footprint', 'base_link', (0.0, 0.0, BASE_LINK_HEIGHT), 0.0, 0.0),
            transform_msg('base_link', 'base_scan', LASER_IN_BASE_LINK, 0.0, 0.0)]))

    def _on_cmd(self, msg: Twist | TwistStamped) -> None:
        self.sim.set_command(*cmd_from_msg(msg))

    def _on_timer(self) -> None:
        for _ in range(self.ticks_per_call):
            self._on_tick()

    def _on_tick(self) -> None:
        sim = self.sim
        if self._running():
            sim.step(TICK)
        t = sim.time
        pose, twist = sim.odometry()
        self.odom_pub.publish(odom_to_msg(pose, twist, t))
        if self.tf_pub is not None and listened(self.tf_pub):
            self.tf_pub.publish(self._tf_message(transforms=[transform_msg(
                'odom', 'base_footprint', (pose[0], pose[1], 0.0), pose[2], t)]))
        if listened(self.truth_pub):
            self.truth_pub.publish(odom_to_msg(sim.true_pose(), twist, t, 'world'))
        if t + 1e-9 >= self._next_scan:
            self._next_scan += SCAN_PERIOD
            self._scans.capture(scan_to_msg(replace(sim.scan(), stamp=t), 'base_scan'), t)
            if self.moving_pub is not None and listened(self.moving_pub):
                # where they truly are, at the scan rate
                self.moving_pub.publish(moving_obstacle_markers(
                    self.world.moving_at(t), 'odom', seconds_to_stamp(t)))
        # scans go out scan_latency after capture, stamped with their capture time
        for msg in self._scans.due(t):
            self.scan_pub.publish(msg)
        # the clock last: a node on sim time then has this tick's data when its timers fire
        self.clock_pub.publish(Clock(clock=seconds_to_stamp(t)))
        if self.outcome is None:
            self._check_outcome()

    def _running(self) -> bool:
        """Whether the simulation steps: until the outcome, and after ``reached`` while
        the robot is still commanded to move (the simulator's own command: zero once
        it is older than cmd_timeout), ARRIVAL_TIME at most."""
        if self.outcome is None:
            return True
        return self.outcome is Outcome.REACHED and self.sim.wheel_command() != (0.0, 0.0) \
            and self.sim.time < self._outcome_time + ARRIVAL_TIME

    def close(self) -> None:
        """Release the physics server."""
        self.sim.close()

    def _check_outcome(self) -> None:
        sim = self.sim
        self.outcome = outcome_of(self.world, sim.true_pose(), sim.collided, sim.time)
        if self.outcome is not None:
            self._outcome_time = sim.time
            self.outcome_pub.publish(String(data=str(self.outcome)))
            stood = ' (hit while stopped)' if sim.collided and sim.hit_while_stopped else ''
            self.get_logger().info(f'outcome: {self.outcome}{stood} at t={sim.time:.1f} s')


def main(args: list[str] | None = None) -> int:
    return spin_node(SimNode, 'subapf-sim', (WorldError, ConfigError), SimNode.close, args)


if __name__ == '__main__':
    sys.exit(main())
