"""The headless simulator and the planner on its clock:
``ros2 launch subapf_planner sim.launch.py world:=<world file> rate:=1.0 robot:=burger``.

sim_node (the PyBullet simulator of ``robot``, core/robot.py) publishes /clock, scan,
odom and each goal's outcome; planner.launch.py's planner runs on that clock with the
same robot's config. Send goals on goal_pose (RViz "2D Goal Pose", frame odom), one
after another: the simulator goes on after each outcome, and each goal has the world's
time limit of its own. subapf-bringup does all this in one process tree for the
world's goal alone.
``foxglove:=true`` also starts foxglove_node: the run served live to Foxglove on
ws://127.0.0.1:<foxglove_port>.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription, OpaqueFunction
from launch.conditions import IfCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

PACKAGE = 'subapf_planner'
ROBOTS = ['burger', 'waffle_pi', 'turtlebot4', 'jackal']


def _simulator(context) -> list[Node]:
    """sim_node as the robot chosen, its base's cmd_vel type with it."""
    from subapf_planner.core.robot import ROBOTS as DESCRIPTIONS
    robot = LaunchConfiguration('robot').perform(context)
    share = FindPackageShare(PACKAGE)
    return [Node(
        package=PACKAGE,
        executable='sim_node',
        name='subapf_sim',
        output='screen',
        parameters=[
            PathJoinSubstitution([share, 'config', 'planner.yaml']),
            {'world': LaunchConfiguration('world'),
             'rate': LaunchConfiguration('rate'),
             'robot': robot,
             'enable_stamped_cmd_vel': DESCRIPTIONS[robot].stamped_cmd_vel},
        ],
    )]


def generate_launch_description() -> LaunchDescription:
    share = FindPackageShare(PACKAGE)
    return LaunchDescription([
        DeclareLaunchArgument(
            'world', default_value=PathJoinSubstitution([share, 'worlds',
                                                         'fig6d_big_wall.yaml']),
            description='World file (format v1 YAML; the shipped ones are in share/worlds)'),
        DeclareLaunchArgument('rate', default_value='1.0',
                              description='Simulated seconds per wall-clock second'),
        DeclareLaunchArgument('robot', default_value='burger', choices=ROBOTS,
                              description='The robot simulated and planned for '
                              '(config/robots/<robot>.yaml)'),
        OpaqueFunction(function=_simulator),
        DeclareLaunchArgument('foxglove', default_value='false', choices=['true', 'false'],
                              description='Serve the run live to Foxglove (foxglove_node)'),
        DeclareLaunchArgument('foxglove_port', default_value='8765',
                              description='WebSocket port of foxglove_node'),
        Node(
            package=PACKAGE,
            executable='foxglove_node',
            name='subapf_foxglove',
            output='screen',
            condition=IfCondition(LaunchConfiguration('foxglove')),
            parameters=[
                PathJoinSubstitution([share, 'config', 'planner.yaml']),
                {'port': LaunchConfiguration('foxglove_port')},
            ],
        ),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(
                PathJoinSubstitution([share, 'launch', 'planner.launch.py'])),
            launch_arguments={'robot': LaunchConfiguration('robot'),
                              'use_sim_time': 'true'}.items(),
        ),
    ])
