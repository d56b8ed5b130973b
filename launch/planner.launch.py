"""The planner for one robot: ``ros2 launch subapf_planner planner.launch.py robot:=burger``.

Loads config/planner.yaml (every parameter's default), then config/robots/<robot>.yaml
(what comes from the robot: footprint, laser mounting and frame, limits, cmd_vel type).
``robot``: burger, waffle_pi or turtlebot4. For parameters of your own, copy this file
and add your params file after the robot's.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

PACKAGE = 'subapf_planner'
ROBOTS = ['burger', 'waffle_pi', 'turtlebot4', 'jackal']


def generate_launch_description() -> LaunchDescription:
    share = FindPackageShare(PACKAGE)
    robot = LaunchConfiguration('robot')
    return LaunchDescription([
        DeclareLaunchArgument('robot', default_value='burger', choices=ROBOTS,
                              description='Robot config: config/robots/<robot>.yaml'),
        DeclareLaunchArgument('use_sim_time', default_value='false',
                              description='Run on /clock (with sim.launch.py or Gazebo)'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='Namespace of the node and its topics'),
        Node(
            package=PACKAGE,
            executable='planner_node',
            name='subapf_planner',
            namespace=LaunchConfiguration('namespace'),
            output='screen',
            parameters=[
                PathJoinSubstitution([share, 'config', 'planner.yaml']),
                PathJoinSubstitution([share, 'config', 'robots', [robot, '.yaml']]),
                {'use_sim_time': LaunchConfiguration('use_sim_time')},
            ],
        ),
    ])
