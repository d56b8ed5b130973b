"""Bad input: fuzzing the core and the node, and each kind of malformed message."""

import math

from geometry_msgs.msg import PoseStamped
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from nav_msgs.msg import Odometry
import numpy as np
import pytest
import rclpy
from rclpy.parameter import Parameter
from sensor_msgs.msg import LaserScan

from subapf_planner.core.command import Command, forward_blocked
from subapf_planner.core.config import METHODS, PlannerConfig
from subapf_planner.core.gates import FIRST_SCANS
from subapf_planner.core.loop import DecisionLoop, Supervision
from subapf_planner.core.planner import Planner, PlanResult, plan
from subapf_planner.core.scan import Scan, geometry_warning
from subapf_planner.core.status import State, Status
from subapf_planner.ros.planner_node import PlannerNode

pytestmark = pytest.mark.node

CFG = PlannerConfig()
weird = st.one_of(st.floats(-10, 10), st.sampled_from([math.nan, math.inf, -math.inf, 0.0]))
coord = st.floats(-4.0, 4.0)
points = arrays(np.float64, st.tuples(st.integers(0, 60), st.just(2)),
                elements=st.one_of(st.floats(-3, 3), st.sampled_from([math.nan, math.inf])))


def check_command(cmd, pose, obstacles, cfg=CFG):
    assert math.isfinite(cmd.v) and math.isfinite(cmd.w)
    assert 0.0 <= cmd.v <= cfg.max_linear_velocity + 1e-12
    assert abs(cmd.w) <= cfg.max_angular_velocity + 1e-12
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    obs = obs[np.all(np.isfinite(obs), axis=1)]
    if np.all(np.isfinite(pose)) and forward_blocked(pose, obs, cfg):
        assert cmd.v == 0.0   # never forward into what it sees inside the danger distance


@given(method=st.sampled_from(METHODS), x=coord, y=coord, yaw=st.floats(-7, 7), gx=weird,
       gy=weird, obstacles=points, v0=st.floats(-1, 1), w0=st.floats(-5, 5))
@settings(max_examples=2000, deadline=None)
def test_fuzz_core_plan(method, x, y, yaw, gx, gy, obstacles, v0, w0):
    cfg = CFG.replace(method=method)
    result = plan(cfg, (x, y, yaw), (gx, gy), obstacles, (v0, w0))
    check_command(result.command, (x, y, yaw), obstacles, cfg)
    if not (math.isfinite(gx) and math.isfinite(gy)):
        assert result.command.status == 'invalid_goal'


@given(ranges=arrays(np.float64, st.integers(0, 400), elements=weird),
       angle_min=weird, inc=weird, rmin=weird, rmax=weird, pose=st.tuples(coord, coord, weird))
@settings(max_examples=1000, deadline=None)
def test_fuzz_core_scans(ranges, angle_min, inc, rmin, rmax, pose):
    result = Planner(CFG).step(pose, (2.0, 2.0), Scan(ranges, angle_min, inc, rmin, rmax),
                               now=0.0)
    check_command(result.command, pose, result.obstacles)


# --- the node, in one process: callbacks and timer called directly -------------------------

@pytest.fixture(scope='module')
def node():
    context = rclpy.Context()
    rclpy.init(context=context)
    n = PlannerNode(context=context, parameter_overrides=[Parameter('scan_timeout', value=10.0),
                                                          Parameter('odom_timeout', value=10.0)])
    yield n
    n.destroy_node()
    rclpy.try_shutdown(context=context)


class Captured:
    """A fresh decision loop in the node (no state from earlier examples), with what the
    node publishes and what the loop decided recorded."""

    def __init__(self, node):
        self.node, self.cmds, self.decisions = node, [], []
        node.ctl = DecisionLoop(node.ctl.cfg, node.ctl.limits)
        node._publish_cmd = lambda v, w, stamp=None: self.cmds.append((v, w))
        tick = node.ctl.tick

        def recording_tick(now):
            d = tick(now)
            self.decisions.append(d)
            return d
        node.ctl.tick = recording_tick


def scan_msg(ranges, angle_min, inc, rmin, rmax, frame, angle_max=None):
    m = LaserScan()
    m.header.frame_id = frame
    m.ranges = [float(r) for r in ranges]
    m.angle_min, m.angle_increment, m.range_min, m.range_max = angle_min, inc, rmin, rmax
    m.angle_max = angle_max if angle_max is not None else angle_min + inc * (len(ranges) - 1)
    return m


def odom_msg(x, y, q, cov=0.0, stamp=0):
    m = Odometry()
    m.header.stamp.sec = stamp
    m.pose.pose.position.x, m.pose.pose.position.y = x, y
    o = m.pose.pose.orientation
    o.x, o.y, o.z, o.w = q
    m.pose.covariance = [cov] * 36
    return m


def goal_msg(x, y, frame='odom'):
    g = PoseStamped()
    g.header.frame_id = frame
    g.pose.position.x, g.pose.position.y = x, y
    return g


@given(ranges=st.lists(weird, max_size=400), angle_min=weird, inc=weird, rmin=weird,
       rmax=weird, angle_max=st.one_of(st.none(), weird),
       frame=st.sampled_from(['base_scan', 'laser', '']),
       x=st.one_of(coord, st.just(math.nan)), y=coord,
       q=st.tuples(weird, weird, weird, weird), cov=weird,
       goal=st.one_of(st.none(), st.tuples(weird, weird, st.sampled_from(['odom', 'map']))))
@settings(max_examples=1000, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_fuzz_node(node, ranges, angle_min, inc, rmin, rmax, angle_max, frame, x, y, q, cov,
                   goal):
    cap = Captured(node)
    if goal is not None:
        node._on_goal(goal_msg(*goal))
    if node.ctl.goal is None:
        node._on_goal(goal_msg(2.5, 1.0))
    node._on_scan(scan_msg(ranges, angle_min, inc, rmin, rmax, frame, angle_max))
    node._on_odom(odom_msg(x, y, q, cov))
    node._on_timer()
    for (v, w), d in zip(cap.cmds, [d for d in cap.decisions if d.command], strict=True):
        assert (v, w) == d.command
        cmd = type('C', (), {'v': v, 'w': w})
        obstacles = d.result.obstacles if d.result is not None else np.zeros((0, 2))
        check_command(cmd, node.ctl.pose, obstacles)


# --- each kind of bad input, with its defined result ------------------------------------------

def drive(node, scan, pose=(0.0, 0.0), goal=(3.0, 0.0), q=(0, 0, 0, 1), stamp=0):
    """The decision of a fresh loop on these inputs, once past the first cycles of a new
    memory (``stopped: mapping``, at most FIRST_SCANS of them)."""
    cap = Captured(node)
    node._on_goal(goal_msg(*goal))
    node._on_scan(scan)
    node._on_odom(odom_msg(*pose, q, stamp=stamp))
    for _ in range(FIRST_SCANS + 1):
        node._on_timer()
        if not cap.decisions or cap.decisions[-1].reason != 'mapping':
            break
    return cap.decisions[-1]


FREE = [math.inf] * 360


def test_wrong_frame_scan_is_dropped(node):
    node.ctl.scan = None
    d = drive(node, scan_msg(FREE, 0.0, math.pi / 180, 0.12, 3.5, 'laser'))
    assert d.command is None and d.text == 'waiting: no scan yet'


@pytest.mark.parametrize('inc', [0.0, -0.01, math.nan])
def test_bad_angle_increment_stops(node, inc):
    d = drive(node, scan_msg([1.0] * 10, 0.0, inc, 0.12, 3.5, 'base_scan'))
    assert d.command == (0.0, 0.0) and d.text == 'stopped: invalid_scan'


def test_nan_angle_min_with_finite_angle_max_stops(node):
    msg = scan_msg([1.0] * 10, math.nan, 0.01, 0.12, 3.5, 'base_scan', angle_max=1.0)
    assert geometry_warning(10, math.nan, 1.0, 0.01) is None
    d = drive(node, msg)
    assert d.command == (0.0, 0.0) and d.text == 'stopped: invalid_scan'


def test_length_mismatch_and_intensities_do_not_matter(node):
    """A header whose angle_max does not match the ranges (and stray intensities) is used
    with beam i at angle_min + i * increment: the same decision as a consistent header."""
    ranges = list(FREE)
    ranges[20:30] = [0.5] * 10   # a wall to the front left bends the path
    good = drive(node, scan_msg(ranges, 0.0, math.pi / 180, 0.12, 3.5, 'base_scan'))
    msg = scan_msg(ranges, 0.0, math.pi / 180, 0.12, 3.5, 'base_scan', angle_max=1.0)
    msg.intensities = [1.0, 2.0]
    assert geometry_warning(360, 0.0, 1.0, math.pi / 180) is not None
    d = drive(node, msg)
    assert d.text == good.text and d.text.startswith('driving')
    assert d.command == good.command and good.command[1] < 0.0   # turns right, away
    np.testing.assert_array_equal(d.result.obstacles, good.result.obstacles)


def test_all_inf_and_empty_scans_are_open_space(node):
    assert drive(node, scan_msg(FREE, 0.0, math.pi / 180, 0.12, 3.5, 'base_scan')
                 ).text.startswith('driving')
    assert drive(node, scan_msg([], 0.0, 0.0, 0.12, 3.5, 'base_scan')).text.startswith(
        'driving')


def test_obstacle_ahead_inside_the_safety_distance_zeroes_forward_speed(node):
    ranges = list(FREE)
    ranges[0] = 0.15 + 0.032   # 0.15 m ahead of base_footprint (safety_distance 0.18 m)
    d = drive(node, scan_msg(ranges, 0.0, math.pi / 180, 0.12, 3.5, 'base_scan'))
    assert d.command is not None and d.command[0] == 0.0
    ranges[0] = 0.6 + 0.032    # farther: the robot drives
    d = drive(node, scan_msg(ranges, 0.0, math.pi / 180, 0.12, 3.5, 'base_scan'))
    assert d.command is not None and d.command[0] > 0.0


def test_nan_pose_dropped_and_quaternion_normalised(node):
    node.ctl.pose = None
    d = drive(node, scan_msg(FREE, 0.0, math.pi / 180, 0.12, 3.5, 'base_scan'),
              pose=(math.nan, 0.0))
    assert d.command is None and d.text == 'waiting: no odom yet'
    drive(node, scan_msg(FREE, 0.0, math.pi / 180, 0.12, 3.5, 'base_scan'),
          q=(0.0, 0.0, 2.0, 2.0))   # |q| = 2.8: yaw pi/2 after normalising
    assert node.ctl.pose[2] == pytest.approx(math.pi / 2)


def test_inputs_stamped_ahead_of_the_clock_are_dropped(node):
    """What a killed simulator had in flight, stamped before its successor's clock went
    back to zero, is not taken as the new simulation's scan and odometry."""
    ahead = node.get_clock().now().nanoseconds // 10**9 + 10   # [s]
    scan = scan_msg(FREE, 0.0, math.pi / 180, 0.12, 3.5, 'base_scan')
    scan.header.stamp.sec = ahead
    cap = Captured(node)
    node._on_goal(goal_msg(3.0, 0.0))
    node._on_scan(scan)
    node._on_odom(odom_msg(0.0, 0.0, (0, 0, 0, 1), stamp=ahead))
    node._on_timer()
    assert node.ctl.scan is None and node.ctl.pose is None
    assert cap.decisions[-1].text == 'waiting: no scan yet' and not cap.cmds
    scan.header.stamp.sec = ahead - 10   # the clock's own time: taken
    node._on_scan(scan)
    assert node.ctl.scan is not None


def test_odometry_time_going_back_clears_history():
    ctl = DecisionLoop(CFG)
    assert ctl.update_odom(5.0, np.zeros(3), 5.0)
    assert not ctl.update_odom(1.0, np.ones(3), 5.1)
    assert len(ctl.poses) == 1


@pytest.mark.parametrize('goal, frame', [((math.nan, 1.0), 'odom'), ((1.0, 1.0), 'base_link'),
                                         ((math.inf, 1.0), 'map')])
def test_bad_goals_are_refused(node, goal, frame):
    node.ctl.goal = None
    node._on_goal(goal_msg(*goal, frame=frame))
    assert node.ctl.goal is None


def test_goal_inside_obstacle_stops_with_reason():
    ctl = DecisionLoop(CFG)
    ctl.set_goal(np.array([1.0, 0.0]))
    ranges = np.full(360, np.inf)
    ranges[0] = 1.032   # a return exactly at the goal
    ctl.update_scan(Scan(ranges, 0.0, math.pi / 180, 0.12, 3.5, 0.0), 0.0)
    ctl.update_odom(0.0, np.zeros(3), 0.0)
    d = ctl.tick(0.0)
    assert d.command == (0.0, 0.0) and d.text == 'stopped: goal_in_obstacle'


def test_a_goal_inside_an_obstacle_is_given_up_like_an_unreachable_one():
    """goal_in_obstacle (a goal inside a wall of a drifted memory, or someone standing
    on it) does not hold the robot until the time limit: with goal_unreachable in turn,
    unreachable_timeout of them ends the attempt; the clock does not restart between
    the two."""
    ctl = DecisionLoop(CFG, Supervision(unreachable_timeout=3.0))
    ctl.set_goal(np.array([5.0, 0.0]))
    script = iter([Status.GOAL_IN_OBSTACLE, Status.GOAL_UNREACHABLE] * 20)
    ctl.planner.step = lambda *a, **k: PlanResult(Command(0.0, 0.0, next(script)))
    scan = Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, 0.0)
    texts = []
    for k in range(20):   # ticks 0.25 s apart
        ctl.update_scan(scan, 0.25 * k)
        ctl.update_odom(0.25 * k, np.zeros(3), 0.25 * k)
        texts.append(ctl.tick(0.25 * k).text)
    assert texts[0] == 'stopped: goal_in_obstacle'
    given_up = next(k for k, t in enumerate(texts) if t.startswith('unreachable'))
    assert given_up == 13                       # more than 3 s since tick 0
    assert ctl.state is State.UNREACHABLE


def test_goal_equal_to_start_is_reached_at_once():
    ctl = DecisionLoop(CFG)
    ctl.set_goal(np.array([0.0, 0.0]))
    ctl.update_scan(Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, 0.0), 0.0)
    ctl.update_odom(0.0, np.zeros(3), 0.0)
    assert ctl.tick(0.0).text.startswith('reached') and ctl.goal is None


def test_goal_behind_a_wall_without_progress_becomes_stuck():
    """The paper's traditional field in front of a wall it cannot pass: the robot (odometry
    fixed, as if pushing) makes no progress, and the progress checker gives the goal up."""
    ctl = DecisionLoop(CFG.replace(method='traditional', attraction_field='euclidean'))
    ctl.limits = type(ctl.limits)(progress_timeout=2.0)
    ctl.set_goal(np.array([0.0, 3.0]))
    ranges = np.full(360, np.inf)
    a = np.radians(np.arange(360))
    ahead = np.abs(np.remainder(a + np.pi, 2 * np.pi) - np.pi) < 1.2    # a wall 1 m ahead
    ranges[ahead] = 1.0 / np.cos(a[ahead])
    scan = Scan(ranges, 0.0, math.pi / 180, 0.12, 3.5, 0.0)
    states = []
    for k in range(20):   # the robot does not move (pose fixed): no progress
        ctl.update_scan(scan, 0.2 * k)
        ctl.update_odom(0.2 * k, np.array([0.0, 0.0, math.pi / 2]), 0.2 * k)
        states.append(ctl.tick(0.2 * k).text)
    assert states[-1] == 'stuck: no progress, goal abandoned'
    assert ctl.tick(4.0).command == (0.0, 0.0)


def _standing_ticks(command, ticks: int) -> tuple[list[str], list[float]]:
    """``ticks`` ticks 0.25 s apart of a robot that stands where it is while the plan
    says ``command()`` (blocked_timeout 1 s, progress_timeout 10 s, two recoveries that
    only count themselves): each tick's text, and the times the recoveries hold until."""
    ctl = DecisionLoop(CFG, Supervision(blocked_timeout=1.0, progress_timeout=10.0,
                                        recoveries=2))
    tried = []

    class Mark:
        def run(self, memory, pose, distance, radius, until):
            tried.append(until)
            return True
    ctl.recoveries.behaviours = (Mark(),)
    ctl.set_goal(np.array([5.0, 0.0]))
    ctl.planner.step = lambda *a, **k: PlanResult(command())
    scan = Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, 0.0)
    texts = []
    for k in range(ticks):
        ctl.update_scan(scan, 0.25 * k)
        ctl.update_odom(0.25 * k, np.zeros(3), 0.25 * k)
        texts.append(ctl.tick(0.25 * k).text)
    return texts, tried


def test_standing_with_no_safe_move_starts_a_recovery_after_blocked_timeout():
    """A gap the local layer finds no safe sample into: the way ahead is marked tried
    after blocked_timeout of no_safe_move (a cycle that moves restarts that clock), not
    after progress_timeout; with no recovery left, the goal is given up only on the
    progress checker's own clock."""
    script = iter([Status.NO_SAFE_MOVE] * 4 + [Status.DRIVING] + [Status.NO_SAFE_MOVE] * 100)
    texts, tried = _standing_ticks(lambda: Command(0.0, 0.0, next(script)), 100)
    marked = [k for k, t in enumerate(texts) if 'marked tried' in t]
    assert marked == [10, 16]        # more than 1 s of no_safe_move from tick 5, and again
    assert texts[10] == 'driving: no safe move: the way ahead marked tried (1 of 2), another way'
    stuck = texts.index('stuck: no progress, goal abandoned')
    assert stuck == 58               # more than 10 s after the tick after the last recovery
    assert len(tried) == 2


@pytest.mark.parametrize('turn, marked', [(0.01, True), (0.5, False)])
def test_blocked_ahead_without_turning_counts_as_standing(turn, marked):
    """blocked_ahead with no forward speed and hardly a turn (the local target straight
    ahead in a gap the footprint does not pass) keeps the robot where it is as surely as
    no_safe_move: the way ahead is marked tried after blocked_timeout. Turning out of
    it at 0.5 rad/s is no standing."""
    texts, tried = _standing_ticks(lambda: Command(0.0, turn, Status.BLOCKED_AHEAD), 20)
    assert any('no safe move: the way ahead marked tried' in t for t in texts) is marked
    assert len(tried) == (2 if marked else 0)


def test_goal_unreachable_is_given_up_after_its_timeout_unless_a_way_opens():
    """goal_unreachable for unreachable_timeout ends the attempt (state unreachable,
    zero velocity, and it stays so); a cycle with a way restarts the clock; the same
    goal sent again tries again."""
    ctl = DecisionLoop(CFG, Supervision(unreachable_timeout=3.0))
    ctl.set_goal(np.array([5.0, 0.0]))
    script = iter([Status.GOAL_UNREACHABLE] * 10 + [Status.DRIVING]
                  + [Status.GOAL_UNREACHABLE] * 30)
    ctl.planner.step = lambda *a, **k: PlanResult(Command(0.0, 0.0, next(script)))
    scan = Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, 0.0)
    texts = []
    for k in range(41):   # ticks 0.25 s apart (exact in binary)
        ctl.update_scan(scan, 0.25 * k)
        ctl.update_odom(0.25 * k, np.zeros(3), 0.25 * k)
        texts.append(ctl.tick(0.25 * k).text)
    assert texts[:10] == ['stopped: goal_unreachable'] * 10    # 2.5 s: still waiting
    assert texts[10] == 'driving: driving'                      # a way: the clock restarts
    given_up = next(k for k, t in enumerate(texts) if t.startswith('unreachable'))
    assert given_up == 11 + 13                  # more than 3 s of it since tick 11
    assert texts[given_up] == ('unreachable: no way to the goal for 3 s (goal_unreachable), '
                               'goal abandoned')   # (a memory says why: no_way)
    assert all(t == texts[given_up] for t in texts[given_up:])
    assert ctl.tick(9.0).command == (0.0, 0.0)
    assert ctl.set_goal(np.array([5.0, 0.0]))                  # sent again: a new attempt
    assert ctl.state is State.DRIVING


def test_tf_frames_follow_rep105():
    from subapf_planner.core.robot import BURGER, JACKAL, TURTLEBOT4
    from subapf_planner.ros.conversions import transform_msg
    from subapf_planner.ros.sim_node import static_links
    t = transform_msg('odom', 'base_footprint', (1.0, 2.0, 0.0), math.pi / 2, 3.5)
    assert (t.header.frame_id, t.child_frame_id) == ('odom', 'base_footprint')
    assert t.transform.rotation.z == pytest.approx(math.sqrt(0.5))
    assert t.header.stamp.sec == 3 and t.header.stamp.nanosec == 500_000_000
    # the burger: base_scan 0.172 m above base_link, base_link 0.010 m above base_footprint
    (p0, c0, up, yaw0), (p1, c1, laser, yaw1) = static_links(BURGER)
    assert (p0, c0, up, yaw0) == ('base_footprint', 'base_link', (0.0, 0.0, 0.010), 0.0)
    assert (p1, c1, yaw1) == ('base_link', 'base_scan', 0.0)
    assert laser == pytest.approx((-0.032, 0.0, 0.172))
    # base_link is the base frame of the TurtleBot 4 (its lidar turned a quarter) and Jackal
    assert [(p, c) for p, c, _, _ in static_links(TURTLEBOT4)] == [('base_link', 'rplidar_link')]
    assert static_links(TURTLEBOT4)[0][3] == pytest.approx(math.pi / 2)
    assert static_links(JACKAL)[0][:2] == ('base_link', 'front_laser')


def test_seed_command_sets_where_the_acceleration_limits_start():
    """A replay that starts mid-run seeds the command the robot was last sent: the first
    planned forward speed is within one period's acceleration of it, not of zero."""
    def first_v(seed):
        ctl = DecisionLoop(CFG.replace(scan_alignment=False))   # no first scans standing
        ctl.set_goal(np.array([3.0, 0.0]))
        ctl.update_odom(0.0, np.array([0.0, 0.0, 0.0]), 0.0)
        ctl.update_scan(Scan(np.full(360, np.inf), 0.0, math.pi / 180, 0.12, 3.5, 0.0), 0.0)
        if seed is not None:
            ctl.seed_command(seed)
        return ctl.tick(0.0).command[0]
    step = CFG.max_linear_acceleration * CFG.period
    assert first_v(None) == pytest.approx(step)
    assert first_v((0.2, 0.0)) == pytest.approx(min(0.2 + step, CFG.max_linear_velocity))
