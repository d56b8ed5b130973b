"""The planner in a Nav2 system, in place of Nav2's controller server and bt_navigator:
``ros2 launch subapf_planner nav2.launch.py robot:=burger``.

Starts the planner as a managed node (``lifecycle_planner_node``, node name
``subapf_planner``: the ``navigate_to_pose`` action, goals on ``goal_pose``) and a
``nav2_lifecycle_manager`` that configures and activates it (``autostart``), as Nav2's
bringup does for its servers. The planner offers no bond (the ``bond`` package), so the
manager is told not to wait for one (``bond_timeout: 0.0``). Start Nav2's localisation
beside it if the robot has a map (``nav2_bringup``'s localization_launch.py): the
planner's memory then starts from the map (``use_map``); it needs only ``scan`` and
``odom``. Parameters as planner.launch.py loads them.
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
    use_sim_time = LaunchConfiguration('use_sim_time')
    return LaunchDescription([
        DeclareLaunchArgument('robot', default_value='burger', choices=ROBOTS,
                              description='Robot config: config/robots/<robot>.yaml'),
        DeclareLaunchArgument('use_sim_time', default_value='false',
                              description='Run on /clock (with sim.launch.py or Gazebo)'),
        Node(
            package=PACKAGE,
            executable='lifecycle_planner_node',
            name='subapf_planner',
            output='screen',
            parameters=[
                PathJoinSubstitution([share, 'config', 'planner.yaml']),
                PathJoinSubstitution([share, 'config', 'robots', [robot, '.yaml']]),
                {'use_sim_time': use_sim_time},
            ],
        ),
        Node(
            package='nav2_lifecycle_manager',
            executable='lifecycle_manager',
            name='lifecycle_manager_subapf',
            output='screen',
            parameters=[{'use_sim_time': use_sim_time, 'autostart': True,
                         'node_names': ['subapf_planner'], 'bond_timeout': 0.0}],
        ),
    ])
