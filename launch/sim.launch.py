"""The headless simulator and the planner on its clock:
``ros2 launch subapf_planner sim.launch.py world:=<world file> rate:=1.0``.

sim_node (the PyBullet burger stand-in) publishes /clock, scan, odom and each goal's
outcome; planner.launch.py's planner runs on that clock with the burger's config (the
stand-in is a burger). Send goals on goal_pose (RViz "2D Goal Pose", frame odom), one
after another: the simulator goes on after each outcome, and each goal has the world's
time limit of its own. subapf-bringup does all this in one process tree for the
world's goal alone.
``foxglove:=true`` also starts foxglove_node: the run served live to Foxglove on
ws://127.0.0.1:<foxglove_port>.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.conditions import IfCondition
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare

PACKAGE = 'subapf_planner'


def generate_launch_description() -> LaunchDescription:
    share = FindPackageShare(PACKAGE)
    return LaunchDescription([
        DeclareLaunchArgument(
            'world', default_value=PathJoinSubstitution([share, 'worlds',
                                                         'fig6d_big_wall.yaml']),
            description='World file (format v1 YAML; the shipped ones are in share/worlds)'),
        DeclareLaunchArgument('rate', default_value='1.0',
                              description='Simulated seconds per wall-clock second'),
        Node(
            package=PACKAGE,
            executable='sim_node',
            name='subapf_sim',
            output='screen',
            parameters=[
                PathJoinSubstitution([share, 'config', 'planner.yaml']),
                {'world': LaunchConfiguration('world'),
                 'rate': LaunchConfiguration('rate')},
            ],
        ),
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
            launch_arguments={'robot': 'burger', 'use_sim_time': 'true'}.items(),
        ),
    ])
