"""Parameters a user gets wrong: a name the node does not have (reported with the
closest one) and a velocity limit beyond what the robot can do (clamped at start with
a warning naming both numbers, refused at run time). Through the nodes' own parameter
scheme: --params-file and -p as ros2 run and launch pass them."""

from conftest import PARAMS, WORLDS
import pytest
import rclpy
from rclpy.parameter import Parameter

from subapf_planner.core.config import PlannerConfig, beyond_robot, clamp_to_robot
from subapf_planner.core.robot import BURGER, ROBOTS
from subapf_planner.ros.parameters import undeclared
from subapf_planner.ros.planner_node import PlannerNode

pytestmark = pytest.mark.node

ROBOT_FILES = PARAMS.parent / 'robots'


@pytest.fixture
def node_with():
    """node_with(cls, *ros_args, **overrides): a node built as its executable builds it,
    from these command-line ROS arguments, in a context of its own."""
    made = []

    def make(cls=PlannerNode, *ros_args, **overrides):
        context = rclpy.Context()
        rclpy.init(context=context, args=['--ros-args', *ros_args] if ros_args else [])
        made.append(context)
        node = cls(context=context, parameter_overrides=[
            Parameter(k, value=v) for k, v in overrides.items()])
        made.append(node)
        return node
    yield make
    for thing in reversed(made):
        if isinstance(thing, rclpy.Context):
            rclpy.try_shutdown(context=thing)
        else:
            thing.destroy_node()


def test_a_misspelt_name_in_a_params_file_is_reported_with_the_closest(
        node_with, tmp_path, capfd):
    mine = tmp_path / 'mine.yaml'
    mine.write_text('subapf_planner:\n  ros__parameters:\n    max_linear_velocty: 0.1\n'
                    '    goal_tolerence: 0.3\n    use_gpu: true\n')
    node = node_with(PlannerNode, '--params-file', str(PARAMS), '--params-file', str(mine))
    lines = undeclared(node)
    assert lines == [
        "'goal_tolerence' is not a parameter of subapf_planner: its value is ignored; "
        "did you mean 'goal_tolerance'?",
        "'max_linear_velocty' is not a parameter of subapf_planner: its value is ignored; "
        "did you mean 'max_linear_velocity'?",
        "'use_gpu' is not a parameter of subapf_planner: its value is ignored; see --help"]
    err = capfd.readouterr().err
    assert all(line in err for line in lines), err   # said at start, as warnings
    assert node.ctl.cfg.max_linear_velocity == BURGER.max_linear_velocity   # (ignored)
    # the shipped files name only parameters the node has
    assert undeclared(node_with(PlannerNode, '--params-file', str(PARAMS), '--params-file',
                                str(ROBOT_FILES / 'turtlebot4.yaml'))) == []


def test_a_misspelt_name_on_the_command_line_and_for_the_simulator(node_with, capfd):
    from subapf_planner.ros.sim_node import SimNode
    node = node_with(PlannerNode, '-p', 'danger_distanse:=0.3')
    assert undeclared(node) == ["'danger_distanse' is not a parameter of subapf_planner: its "
                                "value is ignored; did you mean 'danger_distance'?"]
    sim = node_with(SimNode, '-p', f'world:={WORLDS / "u_trap.yaml"}', '-p', 'rat:=5.0')
    assert undeclared(sim) == ["'rat' is not a parameter of subapf_sim: its value is "
                               "ignored; did you mean 'rate'?"]
    assert "did you mean 'rate'?" in capfd.readouterr().err
    sim.close()


def test_a_velocity_beyond_the_burger_is_clamped_with_both_numbers(node_with, capfd):
    node = node_with(PlannerNode, '--params-file', str(PARAMS), '-p',
                     'max_linear_velocity:=5.0')
    assert node.ctl.cfg.max_linear_velocity == 0.22
    assert node.get_parameter('max_linear_velocity').value == 0.22   # what is in force
    err = capfd.readouterr().err
    assert 'max_linear_velocity: 5 m/s is beyond what the turtlebot3_burger can do ' \
        '(0.22 m/s' in err and 'clamped to 0.22 m/s' in err, err
    # within the limit: nothing said, the value kept
    node = node_with(PlannerNode, '-p', 'max_linear_velocity:=0.15')
    assert node.ctl.cfg.max_linear_velocity == 0.15
    assert 'beyond' not in capfd.readouterr().err


def test_each_robot_file_bounds_the_limits_by_its_robot(node_with, capfd):
    node = node_with(PlannerNode, '--params-file', str(PARAMS), '--params-file',
                     str(ROBOT_FILES / 'turtlebot4.yaml'), '-p', 'max_angular_velocity:=2.0')
    assert node.options.robot == 'turtlebot4'
    assert node.ctl.cfg.max_angular_velocity == ROBOTS['turtlebot4'].max_angular_velocity
    assert 'max_angular_velocity: 2 rad/s is beyond what the turtlebot4 can do (1 rad/s' \
        in capfd.readouterr().err
    # a robot of one's own: not checked
    node = node_with(PlannerNode, '-p', 'robot:=other', '-p', 'max_linear_velocity:=1.5')
    assert node.ctl.cfg.max_linear_velocity == 1.5
    assert 'beyond' not in capfd.readouterr().err


def test_at_run_time_a_limit_beyond_the_robot_is_refused(node_with):
    node = node_with()
    result = node.set_parameters([Parameter('max_linear_velocity', value=5.0)])[0]
    assert not result.successful
    assert result.reason == 'max_linear_velocity: 5 m/s is beyond what the ' \
        'turtlebot3_burger can do (0.22 m/s, core/robot.py)'
    assert node.get_parameter('max_linear_velocity').value == 0.22
    assert node.ctl.cfg.max_linear_velocity == 0.22
    ok = node.set_parameters([Parameter('max_linear_velocity', value=0.2)])[0]
    assert ok.successful and node.ctl.cfg.max_linear_velocity == 0.2


@pytest.mark.core
def test_the_limits_checked_are_those_the_robot_states():
    """core/config.py: velocities against every robot; an acceleration only against a
    description that states one (the shipped ones do not)."""
    from dataclasses import replace
    fast = PlannerConfig(max_linear_velocity=0.5, reverse_speed=0.5,
                         max_angular_velocity=5.0, max_linear_acceleration=10.0)
    assert [b[0] for b in beyond_robot(fast, BURGER)] == [
        'max_linear_velocity', 'reverse_speed', 'max_angular_velocity']
    rated = replace(BURGER, max_linear_acceleration=2.5, max_angular_acceleration=3.2)
    cfg, notes = clamp_to_robot(fast, rated)
    assert (cfg.max_linear_velocity, cfg.reverse_speed, cfg.max_angular_velocity,
            cfg.max_linear_acceleration) == (0.22, 0.22, 2.84, 2.5)
    assert notes[-1] == ('max_linear_acceleration: 10 m/s^2 is beyond what the '
                         'turtlebot3_burger can do (2.5 m/s^2, core/robot.py): clamped to '
                         '2.5 m/s^2')
    for robot in ROBOTS.values():   # every robot's own defaults are within it
        assert beyond_robot(PlannerConfig.for_robot(robot), robot) == []
