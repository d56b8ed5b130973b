"""``planner_node`` (``subapf-planner``): scan + odom + goal -> cmd_vel at 5 Hz.

Topics (relative, so namespaces and remapping work):
  in:  scan (sensor_msgs/LaserScan, sensor-data QoS), odom (nav_msgs/Odometry),
       goal_pose (geometry_msgs/PoseStamped, in the odom frame or map_frame); with
       use_map, map (nav_msgs/OccupancyGrid, transient local) and /tf's map_frame ->
       odom_frame: a map the robot already has and its localiser
  actions: navigate_to_pose, follow_path (nav2_msgs; ros/actions.py)
  out: cmd_vel (geometry_msgs/TwistStamped, or Twist with
       enable_stamped_cmd_vel:=false), ~/status (std_msgs/String,
       "state: reason"), ~/markers (visualization_msgs/MarkerArray),
       ~/map (nav_msgs/OccupancyGrid, transient local, the occupancy memory),
       ~/plan (nav_msgs/Path, the navigation field's steepest descent, sent for each
       new field and as the robot moves), ~/correction (geometry_msgs/
       TransformStamped map_frame -> odom: the scan alignment's drift correction),
       ~/taken (sensor_msgs/TimeReference: each scan, odometry and goal_pose message
       the node took, and the tick it took it at: what a replay of a recording
       follows); markers, map and plan are drawn in odom; everything but
       cmd_vel is built and sent only while something subscribes

Scans and odometry are taken at the planning tick (ros/spinning.PolledGroup), so
only the timer (and goals, parameters, /clock) wakes the process. While one of them
is silent past its timeout, the node looks at its publishers and warns, once each,
about those it cannot hear (another message type, an incompatible QoS).

The node only translates messages and parameters and drives one timer; the
decisions are subapf_planner.core.loop's, the input checks ros/intake.py's.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
import sys

from geometry_msgs.msg import PoseStamped, TransformStamped, Twist, TwistStamped
from nav_msgs.msg import OccupancyGrid as GridMsg
from nav_msgs.msg import Odometry, Path
import numpy as np
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import JumpThreshold
from rclpy.duration import Duration
from rclpy.exceptions import ParameterException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import LaserScan, TimeReference
from std_msgs.msg import Header, String
from visualization_msgs.msg import MarkerArray

from ..bag.events import TAKEN_SOURCE, stamp_ns
from ..core.config import (
    ConfigError,
    PlannerConfig,
    beyond_robot,
    beyond_robot_text,
    clamp_to_robot,
)
from ..core.known_map import KnownMapError
from ..core.loop import DecisionLoop, Supervision
from ..core.navigation import thin_polyline
from ..core.params import check_fields, param
from ..core.robot import ROBOTS, RobotDescription, chain, invert, to_parent
from .actions import navigation_actions
from .conversions import (
    cmd_to_msg,
    grid_to_msg,
    known_map_from_msg,
    path_to_msg,
    planar_transform,
    transform_msg,
)
from .intake import Intake
from .markers import markers_from_result
from .parameters import declare, read, warn_undeclared
from .qos import LATCHED, listened, unheard_publishers
from .spinning import SHUTDOWN_ACK_TIMEOUT, PolledGroup, spin_node, taken
from .usage import node_usage

NODE_NAME = 'subapf_planner'
#: A forward clock jump longer than this, or any backward one, resets the inputs [s].
CLOCK_JUMP = 1.0
#: Points of ~/plan are this far apart, and it is sent again when the robot moved this
#: far, for a new field, or PLAN_PERIOD after the last one [m].
PLAN_SPACING = 0.25
#: Longest time between two ~/plan messages while the field is used [s].
PLAN_PERIOD = 1.0
#: While scan or odometry is silent past its timeout, its publishers are looked at this
#: often, for one this node cannot hear [s].
SILENCE_CHECK = 2.0
#: Odometry queued between two ticks (taken at the tick, not on arrival): 2.5 s at 20 Hz,
#: 10 planning periods of the default.
ODOM_QUEUE = 50
#: ~/taken's queue: a tick's inputs (a scan and four odometry messages at 5 Hz).
TAKEN_QUEUE = 50
#: /tf messages queued between two ticks (taken at the tick, for map -> odom).
TF_QUEUE = 100


#: The value of the ``robot`` parameter for a robot of one's own (limits not checked).
OTHER_ROBOT = 'other'


@dataclass(frozen=True)
class NodeOptions:
    """The planner node's own parameters (the rest: PlannerConfig and Supervision)."""

    robot: str = param('burger', 'The robot (core/robot.py; config/robots/<robot>.yaml sets '
                       'it): a velocity limit beyond what it can do is clamped to its own at '
                       'start, with a warning, and refused at run time; other: a robot of '
                       'your own, limits not checked', choices=(*ROBOTS, OTHER_ROBOT),
                       read_only=True)
    goal_from_parameters: bool = param(False, 'Drive to (goal_x, goal_y) at start instead of '
                                       'waiting for goal_pose', read_only=True)
    goal_x: float = param(0.0, 'Goal x in odom_frame (with goal_from_parameters)', 'm',
                          -1e6, 1e6, read_only=True)
    goal_y: float = param(0.0, 'Goal y in odom_frame (with goal_from_parameters)', 'm',
                          -1e6, 1e6, read_only=True)
    enable_stamped_cmd_vel: bool = param(True, 'Publish TwistStamped (true) or Twist (false)',
                                         read_only=True)
    publish_markers: bool = param(True, 'Publish ~/markers (visualization_msgs/MarkerArray) '
                                  'at marker_rate while something subscribes')
    marker_rate: float = param(5.0, 'Largest rate of ~/markers (at most one per planning '
                               'cycle)', 'Hz', 0.1, 50.0)
    publish_map: bool = param(True, 'Publish the occupancy memory on ~/map '
                              '(nav_msgs/OccupancyGrid, transient local) at map_rate '
                              'while something subscribes')
    map_rate: float = param(1.0, 'Rate of ~/map', 'Hz', 0.1, 5.0)
    publish_plan: bool = param(True, "Publish the field's steepest-descent path from the "
                               'robot on ~/plan (nav_msgs/Path) for each new field, and '
                               'when the robot moved 0.25 m or a second passed, while '
                               'something subscribes')
    laser_frame: str = param('base_scan', 'Expected scan frame_id; empty accepts any')
    base_frame: str = param('base_footprint', "The robot's base frame: the laser mounting is "
                            'read from /tf_static as this frame -> laser_frame when it is '
                            'there (else laser_x, laser_y, laser_yaw)', read_only=True)
    odom_frame: str = param('odom', 'Frame of odometry and goals')
    use_map: bool = param(True, 'Start the memory from a map the robot already has: once a '
                          'map is on map (nav_msgs/OccupancyGrid, transient local: '
                          "map_server's, slam_toolbox's) and map_frame -> odom_frame on /tf "
                          "(a localiser's), the memory's frame becomes the map's and the "
                          'memory starts from the map (a newer map: its cells again); '
                          'docs/nav2.md',
                          read_only=True)
    map_frame: str = param('map', "Name of the memory's frame (odom as it was at the start, "
                           'kept still by scan_alignment): goals may be given in it, and '
                           '~/correction is its transform to odom_frame (a topic, not /tf: '
                           'a localiser may own map -> odom)')

    def __post_init__(self) -> None:
        check_fields(self)

    @property
    def robot_description(self) -> RobotDescription | None:
        """What the robot can do (None: a robot of one's own)."""
        return ROBOTS.get(self.robot)


#: The parameter groups of the node with their titles, in declaration order (also the
#: sections of config/planner.yaml and of --help).
SECTIONS = (('node (ros/planner_node.py)', NodeOptions),
            ('supervision (core/loop.py)', Supervision),
            ('planner core (core/config.py)', PlannerConfig))
GROUPS = tuple(cls for _, cls in SECTIONS)


class PlannerParts:
    """The planner node's work, set up in the two steps of a managed node (Nav2's
    servers): ``_configure`` (parameters read, the decision loop built, publishers,
    subscriptions and action servers made) and ``_activate`` (the planning timer);
    ``_deactivate`` and ``_cleanup`` undo them. PlannerNode does both at once;
    ros/lifecycle_node.py's node on its transitions. A mixin of an rclpy Node."""

    #: Configured and not yet cleaned up; active (the timer running).
    configured = False
    active = False

    def _declare_parameters(self) -> None:
        declare(self, *GROUPS)
        warn_undeclared(self)   # a misspelt name: said, with the closest one

    def _make_publisher(self, msg_type, topic: str, qos):
        return self.create_publisher(msg_type, topic, qos)

    def _configure(self) -> None:
        """Read the parameters (a bad value raises ConfigError naming it) and make
        everything but the timer; nothing is published until _activate."""
        self._undo: list = []   # how to take each part down again, in order made
        self.options = read(self, NodeOptions)
        self.ctl = DecisionLoop(self._within_robot(read(self, PlannerConfig)),
                                read(self, Supervision))
        self.intake = self._intake()
        self._pending: dict[type, object] = {}   # groups validated by the on-set callback
        self.add_on_set_parameters_callback(self._validate_parameters)
        self.add_post_set_parameters_callback(self._apply_parameters)
        self._undo += [
            lambda: self.remove_on_set_parameters_callback(self._validate_parameters),
            lambda: self.remove_post_set_parameters_callback(self._apply_parameters)]

        stamped = self.options.enable_stamped_cmd_vel
        self.cmd_pub = self._publisher(TwistStamped if stamped else Twist, 'cmd_vel', 10)
        self.status_pub = self._publisher(String, '~/status', 10)
        self.marker_pub = self._publisher(MarkerArray, '~/markers', 10)
        self.map_pub = self._publisher(GridMsg, '~/map', LATCHED)
        self.plan_pub = self._publisher(Path, '~/plan', 10)
        self.correction_pub = self._publisher(TransformStamped, '~/correction', 10)
        self.taken_pub = self._publisher(TimeReference, '~/taken', TAKEN_QUEUE)
        #: (role, stamp) of the inputs taken since the last ~/taken went out
        self._taken: list[tuple[str, object]] = []
        self._map_time: float | None = None
        self._markers_time: float | None = None
        self._plan_sent: tuple | None = None   # (field, robot position, time) of ~/plan
        # taken at the tick (_take_arrived_inputs), never by the executor
        polled = PolledGroup()
        self._inputs = (
            (self._subscription(LaserScan, 'scan', self._on_scan, qos_profile_sensor_data,
                                callback_group=polled), self._on_scan, TAKEN_SOURCE['scan']),
            (self._subscription(Odometry, 'odom', self._on_odom, QoSProfile(depth=ODOM_QUEUE),
                                callback_group=polled), self._on_odom,
             TAKEN_SOURCE['odom']))
        self._subscription(PoseStamped, 'goal_pose', self._on_goal, 10)
        self._silence_checked = -float('inf')   # when the silent inputs were looked at
        self._unheard: set[bytes] = set()   # publishers warned about (endpoint GIDs)

        #: /tf_static so far: child -> (parent, planar pose, level); the mounting read
        #: from it (None: the parameters').
        self._links: dict[str, tuple[str, tuple[float, float, float], bool]] = {}
        self._tf_mount: tuple[float, float, float] | None = None
        self._setup_tf_static()
        self._setup_known_map()
        self._last_state = ''
        self.timer = None
        jump = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=Duration(seconds=CLOCK_JUMP),
                          min_backward=Duration(nanoseconds=-1), on_clock_change=False),
            post_callback=self._on_clock_jump)
        self._undo.append(jump.unregister)
        self.actions = navigation_actions(self)
        if self.actions is not None:
            self._undo.append(self.actions.destroy)
        self.configured = True

    def _publisher(self, msg_type, topic: str, qos):
        pub = self._make_publisher(msg_type, topic, qos)
        self._undo.append(lambda: self._destroy_publisher(pub))
        return pub

    def _destroy_publisher(self, pub) -> None:
        self.destroy_publisher(pub)

    def _subscription(self, msg_type, topic: str, callback, qos, **kwargs):
        sub = self.create_subscription(msg_type, topic, callback, qos, **kwargs)
        self._undo.append(lambda: self.destroy_subscription(sub))
        return sub

    def _activate(self) -> None:
        """Start planning: the timer (and the goal of the parameters, if asked)."""
        cfg = self.ctl.cfg
        self.timer = self.create_timer(cfg.period, self._on_timer)
        self.active = True
        if self.options.goal_from_parameters:
            self._set_goal(np.array([self.options.goal_x, self.options.goal_y]))
        self.get_logger().info(
            f'method={cfg.method} d0={cfg.danger_distance} m '
            f'samples={cfg.num_samples} R={cfg.sample_radius} m '
            f'rate={cfg.planning_frequency} Hz v_max={cfg.max_linear_velocity} m/s '
            f'cmd_vel={self.cmd_pub.msg_type.__name__}')

    def _deactivate(self, why: str) -> None:
        """Stop planning: the goal dropped (an action's goal aborted with ``why``), a zero
        command sent and acknowledged (bounded), the timer gone."""
        if self.timer is not None:
            self.destroy_timer(self.timer)
            self.timer = None
        if self.actions is not None:
            self.actions.preempt(why)
        self.cancel_goal(why)
        self.active = False

    def _cleanup(self) -> None:
        """Take down everything _configure made (in reverse order)."""
        for undo in reversed(getattr(self, '_undo', [])):
            undo()
        self._undo = []
        self.configured = False

    # --- parameters -------------------------------------------------------------------
    def _within_robot(self, cfg: PlannerConfig) -> PlannerConfig:
        """At start: each limit beyond what the robot can do (``robot``) clamped to the
        robot's, with a warning naming both numbers, and the parameter set to it."""
        robot = self.options.robot_description
        if robot is None:
            return cfg
        beyond = beyond_robot(cfg, robot)
        cfg, notes = clamp_to_robot(cfg, robot)
        for note in notes:
            self.get_logger().warn(f'{note} (robot: {self.options.robot}; a robot of your '
                                   f'own: robot:={OTHER_ROBOT})')
        # (before the callbacks are added: nothing else to validate or apply)
        self.set_parameters([Parameter(name, value=limit) for name, _, limit in beyond])
        return cfg

    def _validate_parameters(self, params: list) -> SetParametersResult:
        """Refuse a change that makes any parameter group invalid, or a limit beyond what
        the robot can do (old values kept); the groups built here are what the post-set
        callback applies."""
        changes = {p.name: p.value for p in params}
        try:
            self._pending = {group: read(self, group, changes) for group in GROUPS}
        except ConfigError as exc:
            self._pending = {}
            return SetParametersResult(successful=False, reason=str(exc))
        robot = self._pending[NodeOptions].robot_description
        beyond = beyond_robot(self._pending[PlannerConfig], robot) if robot else []
        if beyond:
            self._pending = {}
            return SetParametersResult(successful=False, reason='; '.join(
                beyond_robot_text(*b, robot) for b in beyond))
        return SetParametersResult(successful=True)

    def _apply_parameters(self, params: list) -> None:
        """Apply accepted changes: the core's configuration, the limits, the timer."""
        pending, self._pending = self._pending, {}
        if not pending:
            return
        cfg = pending[PlannerConfig]
        if cfg.planning_frequency != self.ctl.cfg.planning_frequency \
                and self.timer is not None:
            self.timer.timer_period_ns = int(cfg.period * 1e9)
        self.options = pending[NodeOptions]
        self.intake = self._intake()
        self.ctl.reconfigure(self._mounted(cfg), pending[Supervision])

    # --- the laser mounting from /tf_static --------------------------------------------
    def _setup_tf_static(self) -> None:
        o = self.options
        try:
            from tf2_msgs.msg import TFMessage
        except ImportError:
            self.get_logger().info(f'laser mounting from parameters {self.ctl.cfg.laser_mount}'
                                   ' (tf2_msgs not installed: /tf_static not read)')
            return
        self._subscription(TFMessage, '/tf_static', self._on_tf_static, LATCHED)
        self.get_logger().info(f'laser mounting from parameters {self.ctl.cfg.laser_mount} '
                               f'until /tf_static gives {o.base_frame} -> {o.laser_frame}')

    # --- a map the robot already has ---------------------------------------------------
    def _setup_known_map(self) -> None:
        """``map`` and /tf (polled at the tick) when use_map and tf2_msgs are there."""
        self._known_msg = None   # the newest map not yet taken, ...
        self._odom_in_map: tuple[float, float, float] | None = None   # ... the localiser's
        self._map_taken = False   # the memory's frame is the map's
        self._tf_sub = None
        if not self.options.use_map:
            return
        try:
            from tf2_msgs.msg import TFMessage
        except ImportError:
            self.get_logger().info('map not used (tf2_msgs not installed: no map -> odom)')
            return
        self._subscription(GridMsg, 'map', self._on_map, LATCHED)
        self._tf_sub = self._subscription(TFMessage, '/tf', lambda _: None,
                                          QoSProfile(depth=TF_QUEUE),
                                          callback_group=PolledGroup())

    def _on_map(self, msg: GridMsg) -> None:
        self._known_msg = msg

    def _take_known_map(self) -> None:
        """The localiser's newest map -> odom from /tf; then a new map, if one came, as the
        memory's start (DecisionLoop.start_from)."""
        o = self.options
        if self._tf_sub is None:
            return
        for msg in taken(self._tf_sub):
            for t in msg.transforms:
                pose = planar_transform(t)[2]
                if t.header.frame_id == o.map_frame and t.child_frame_id == o.odom_frame \
                        and all(map(math.isfinite, pose)):
                    self._odom_in_map = pose
        if self._known_msg is None or self._odom_in_map is None:
            return
        msg, self._known_msg = self._known_msg, None
        if msg.header.frame_id not in ('', o.map_frame):
            self.get_logger().warn(f'map in frame "{msg.header.frame_id}", not '
                                   f'"{o.map_frame}": not used')
            return
        try:
            known = known_map_from_msg(msg)
        except KnownMapError as exc:
            self.get_logger().warn(f'map not used: {exc}')
            return
        h, w = known.cells.shape
        if self._map_taken:   # a newer map (slam_toolbox's): the cells taken again
            self.ctl.know(known)
            self.get_logger().info(f'memory taken again from a new map ({w} x {h} cells)')
            return
        self._map_taken = True
        self.ctl.start_from(known, self._odom_in_map)
        x, y, yaw = self._odom_in_map
        self.get_logger().info(f'memory started from the map ({w} x {h} cells of '
                               f'{known.resolution:g} m), {o.map_frame} -> {o.odom_frame} '
                               f'({x:.2f}, {y:.2f}, {yaw:.3f} rad): goals in '
                               f'"{o.map_frame}" are in the map')

    def _on_tf_static(self, msg) -> None:
        for t in msg.transforms:
            parent, child, pose, level = planar_transform(t)
            self._links[child] = (parent, pose, level)
        o = self.options
        links = {c: (p, pose) for c, (p, pose, _) in self._links.items()}
        found = chain(links, o.base_frame, o.laser_frame) if o.laser_frame else None
        if found is None or found[0] == self._tf_mount:
            return
        mount, frames = found
        tilted = [f for f in frames if not self._links[f][2]]
        if tilted:
            self.get_logger().warn(f'/tf_static: {", ".join(tilted)} not level: laser '
                                   f'mounting kept from parameters {self.ctl.cfg.laser_mount}')
            return
        self._tf_mount = mount
        self.ctl.reconfigure(self._mounted(self.ctl.cfg))
        self.get_logger().info(
            f'laser mounting from /tf_static ({o.base_frame} -> {o.laser_frame}): '
            f'x={mount[0]:.3f} m y={mount[1]:.3f} m yaw={mount[2]:.3f} rad '
            '(laser_x, laser_y, laser_yaw not used)')

    def _mounted(self, cfg: PlannerConfig) -> PlannerConfig:
        """``cfg`` with the mounting /tf_static gave, if it gave one."""
        if self._tf_mount is None:
            return cfg
        x, y, yaw = self._tf_mount
        return cfg.replace(laser_x=x, laser_y=y, laser_yaw=yaw)

    def _on_clock_jump(self, jump) -> None:
        self.get_logger().warn(f'clock jumped by {jump.delta.nanoseconds * 1e-9:+.2f} s '
                               '(simulation restarted?): inputs reset')
        self.ctl.clock_jumped()   # (rcl re-arms the timer itself after a jump back)

    # --- inputs -----------------------------------------------------------------------
    def now_seconds(self) -> float:
        """The node's clock [s]."""
        return self.get_clock().now().nanoseconds * 1e-9

    def _warn(self, problem: str | None) -> None:
        if problem:
            self.get_logger().warn(problem, throttle_duration_sec=5.0)

    def _on_scan(self, msg: LaserScan) -> None:
        self._warn(self.intake.scan(self.ctl, msg, self.now_seconds()))

    def _on_odom(self, msg: Odometry) -> None:
        self._warn(self.intake.odom(self.ctl, msg, self.now_seconds()))

    def _on_goal(self, msg: PoseStamped) -> None:
        if not self.active:
            self.get_logger().warn('goal_pose ignored: the planner is not active')
            return
        self._taken.append((TAKEN_SOURCE['goal'], msg.header.stamp))
        if self.take_goal(msg) is None and self.actions is not None:
            self.actions.preempt('preempted by a goal on goal_pose')

    def take_goal(self, msg: PoseStamped | Path) -> str | None:
        """A goal (a pose, or a path to follow to its end) from goal_pose or an action:
        taken (None), or why it is refused (logged)."""
        new, refused = (self.intake.path if isinstance(msg, Path) else self.intake.goal)(
            self.ctl, msg)
        if refused:
            self.get_logger().error(refused)
        elif new:
            self._took_goal()
        return refused

    def cancel_goal(self, why: str) -> None:
        """Drop the goal for ``why`` and stop the robot: a zero velocity sent and
        acknowledged (at most SHUTDOWN_ACK_TIMEOUT)."""
        self.ctl.cancel(why)
        self.stop_robot()
        if not self.cmd_pub.wait_for_all_acked(
                Duration(nanoseconds=int(SHUTDOWN_ACK_TIMEOUT * 1e9))):
            self.get_logger().warn(f'{why}: the zero velocity was not acknowledged within '
                                   f'{SHUTDOWN_ACK_TIMEOUT} s')
        self._last_state = self.ctl.text
        if listened(self.status_pub):
            self.status_pub.publish(String(data=self.ctl.text))

    def _set_goal(self, goal: np.ndarray) -> None:
        if self.ctl.set_goal(goal):
            self._took_goal()

    def _took_goal(self) -> None:
        """Log a new goal and say on ~/status at once that it was taken (``driving: new
        goal``), so that a final state that follows is this goal's, even one the first
        tick decides (a goal already within the tolerance)."""
        goal = self.ctl.goal
        self.get_logger().info(f'goal ({goal[0]:.2f}, {goal[1]:.2f})')
        self._last_state = self.ctl.text
        if listened(self.status_pub):
            self.status_pub.publish(String(data=self.ctl.text))

    # --- the planning cycle -----------------------------------------------------------
    def _take_arrived_inputs(self, tick_ns: int) -> list:
        """The scans and odometry that arrived since the last tick (the executor never
        hands them over: PolledGroup): those stamped at or before the tick are taken in
        now; later ones are returned, to be taken in after the tick (each noted for
        ~/taken)."""
        later = []
        for sub, handler, role in self._inputs:
            for msg in taken(sub):
                self._taken.append((role, msg.header.stamp))
                if stamp_ns(msg.header.stamp) <= tick_ns:
                    handler(msg)
                else:
                    later.append((handler, msg))
        return later

    def _explain_silence(self, now: float) -> None:
        """Warn, once per publisher, about each publisher of a silent input (scan or
        odometry older than its timeout, or none yet) whose messages this node can never
        receive. rclpy warns of these from a subscription's QoS events, which the
        executor does not wait on for the polled inputs (ros/spinning.PolledGroup)."""
        if 0.0 <= now - self._silence_checked < SILENCE_CHECK:
            return
        self._silence_checked = now
        for (sub, _, _), silent in zip(self._inputs, self.ctl.silent(now), strict=True):
            if not silent:
                continue
            found = unheard_publishers(sub.topic_name, sub.msg_type, sub.qos_profile,
                                       self.get_publishers_info_by_topic(sub.topic_name))
            for gid, problem in found.items():
                if gid not in self._unheard:
                    self._unheard.add(gid)
                    self.get_logger().warn(problem)

    def _on_timer(self) -> None:
        if self.actions is not None:
            self.actions.before_tick()   # a cancel request first: no command after it
        self._take_known_map()
        tick = self.get_clock().now()
        later = self._take_arrived_inputs(tick.nanoseconds)
        self._explain_silence(tick.nanoseconds * 1e-9)
        decision = self.ctl.tick(tick.nanoseconds * 1e-9)
        for handler, msg in later:
            handler(msg)
        if decision.command is not None:   # the command first, stamped with the tick time
            self._publish_cmd(*decision.command, stamp=tick.to_msg())
        self._publish_taken(tick)
        # then the scan into the memory (so ~/map shows it) and the field marched until
        # the next tick: neither holds the command up
        self.ctl.after_tick()
        self._publish_views(decision, tick)
        self._publish_memory(decision, tick)
        if decision.state.halted and decision.text != self._last_state:
            self.get_logger().warn(decision.text)
        self._last_state = decision.text
        if listened(self.status_pub):
            self.status_pub.publish(String(data=decision.text))
        if self.actions is not None:
            self.actions.after_tick(decision, tick.to_msg())

    def _publish_taken(self, tick) -> None:
        """~/taken: one TimeReference per input (role, stamp) taken at this tick or
        since the last (header stamp: the tick; time_ref: the input's stamp; source: its
        role), in the order taken; only while something subscribes. The tick planned
        with all but the scans and odometry stamped after it, which were taken after its
        command."""
        inputs, self._taken = self._taken, []
        if not inputs or not listened(self.taken_pub):
            return
        header = Header(stamp=tick.to_msg())
        for role, stamp in inputs:
            self.taken_pub.publish(TimeReference(header=header, time_ref=stamp, source=role))

    def _publish_views(self, decision, tick) -> None:
        """~/markers at marker_rate and ~/correction each cycle, each only while
        something subscribes."""
        result, now, cfg = decision.result, tick.nanoseconds * 1e-9, self.ctl.cfg
        if result is None:
            return
        if self.options.publish_markers and listened(self.marker_pub) \
                and _due(self._markers_time, now, 1.0 / self.options.marker_rate, cfg.period):
            self._markers_time = now
            self.marker_pub.publish(markers_from_result(
                result, self.options.odom_frame, tick.to_msg(), cfg.danger_distance,
                cfg.robot_radius, cfg.voxel_size))
        if cfg.geodesic and listened(self.correction_pub):   # with the tick's scan matched
            correction = self.ctl.correction
            self.correction_pub.publish(transform_msg(
                self.options.map_frame, self.options.odom_frame,
                (*correction[:2], 0.0), correction[2], now))

    def _publish_memory(self, decision, tick) -> None:
        """~/plan for each new field, and when the robot moved PLAN_SPACING or PLAN_PERIOD
        passed (its points PLAN_SPACING apart); ~/map at most at map_rate."""
        if not self.ctl.cfg.geodesic:
            return
        frame, now = self.options.odom_frame, tick.nanoseconds * 1e-9
        result = decision.result
        field = result.field if result is not None else None
        memory_frame = invert(self.ctl.correction)   # its pose in odom
        if self.options.publish_plan and field is not None and result.pose is not None \
                and listened(self.plan_pub):
            here = result.pose[:2]
            last = self._plan_sent
            if last is None or last[0] is not field \
                    or _due(last[2], now, PLAN_PERIOD, self.ctl.cfg.period) \
                    or np.hypot(*(here - last[1])) >= PLAN_SPACING:
                self._plan_sent = (field, here.copy(), now)
                self.plan_pub.publish(path_to_msg(
                    to_parent(memory_frame, thin_polyline(field.path(here), PLAN_SPACING)),
                    frame, tick.to_msg()))
        if self.options.publish_map and listened(self.map_pub) \
                and _due(self._map_time, now, 1.0 / self.options.map_rate,
                         self.ctl.cfg.period):
            self._map_time = now
            self.map_pub.publish(grid_to_msg(self.ctl.grid, frame, tick.to_msg(),
                                             memory_frame))

    def _intake(self) -> Intake:
        o = self.options
        return Intake(o.laser_frame, o.odom_frame, o.map_frame)

    def _publish_cmd(self, v: float, w: float, stamp=None) -> None:
        stamped = self.cmd_pub.msg_type is TwistStamped
        self.cmd_pub.publish(cmd_to_msg(v, w, stamped,
                                        stamp or self.get_clock().now().to_msg()))

    def stop_robot(self) -> None:
        """Zero velocity, e.g. on shutdown (nothing while not active: a managed node's
        publishers are off then)."""
        if self.active:
            self._publish_cmd(0.0, 0.0)


class PlannerNode(PlannerParts, Node):
    """Runs the core planner on a timer; every safety decision stops the robot."""

    def __init__(self, **kwargs) -> None:
        super().__init__(NODE_NAME, **kwargs)
        self._declare_parameters()
        self._configure()   # a bad start value raises ConfigError naming it (exit code 2)
        self._activate()


def _due(last: float | None, now: float, period: float, tick: float) -> bool:
    """Whether a message last sent at ``last`` [s] (None: never) is due again at the
    planning tick ``now``: ``period`` [s] later to the nearest tick (ticks are ``tick``
    [s] apart), or the clock went back."""
    return last is None or now < last or now - last >= period - 0.5 * tick


def usage() -> str:
    """``subapf-planner --help``."""
    return node_usage(
        'subapf-planner', 'planner_node', NODE_NAME, """
        The subapf_planner local planner node: scan (sensor_msgs/LaserScan), odom
        (nav_msgs/Odometry) and a goal on goal_pose (geometry_msgs/PoseStamped in odom or
        map_frame, e.g. RViz's 2D Goal Pose) in; cmd_vel (TwistStamped, or Twist with
        enable_stamped_cmd_vel:=false) out at planning_frequency; ~/status (std_msgs/String
        "state: reason"; states idle, waiting, mapping, driving, stopped and the final
        reached, stuck, unreachable), ~/markers, ~/map, ~/plan, ~/correction.

        Example: subapf-planner --ros-args --params-file config/planner.yaml
        --params-file config/robots/waffle_pi.yaml -p use_sim_time:=true""",
        SECTIONS, 'A robot file, config/robots/<robot>.yaml (burger, waffle_pi, '
        "turtlebot4), loaded after it, sets that robot's own: robot, footprint and "
        'clearances, laser frame and mounting, limits, cmd_vel type '
        '(launch/planner.launch.py robot:=... loads both).')


def main(args: list[str] | None = None) -> int:
    return spin_node(PlannerNode, 'subapf-planner: bad parameter',
                     (ConfigError, ParameterException), PlannerNode.stop_robot, args,
                     usage=usage)


if __name__ == '__main__':
    sys.exit(main())

