"""Robot configs: each config/robots file, loaded after planner.yaml through the planner
node's own parameter scheme (--params-file, as ros2 run and launch pass them), gives a
node whose core and options are that robot's."""

import math

from conftest import PARAMS
import pytest
import rclpy

from subapf_planner.core.robot import BURGER, ROBOTS
from subapf_planner.ros.planner_node import PlannerNode

pytestmark = pytest.mark.node


@pytest.mark.parametrize('key', sorted(ROBOTS))
def test_each_robot_file_configures_the_node(key):
    robot = ROBOTS[key]
    context = rclpy.Context()
    rclpy.init(context=context, args=['--ros-args', '--params-file', str(PARAMS),
                                      '--params-file', str(PARAMS.parent / 'robots'
                                                           / f'{key}.yaml')])
    try:
        node = PlannerNode(context=context)
        cfg, options = node.ctl.cfg, node.options
        assert cfg.robot_radius == robot.radius
        # a polygon: the field keeps its half-width from walls, the rest checks the polygon
        half_width = max(abs(y) for _, y in robot.footprint) if robot.footprint else None
        assert cfg.inflation_radius == (half_width or robot.radius)
        assert (cfg.polygon is None) == (half_width is None)
        assert cfg.sample_clearance == pytest.approx(robot.radius + 0.03)
        assert cfg.planning_frequency == robot.planning_frequency
        assert cfg.safety_distance > robot.radius
        assert cfg.laser_mount == pytest.approx(robot.laser.planar, abs=1e-6)
        assert cfg.max_linear_velocity == robot.max_linear_velocity
        assert cfg.max_angular_velocity == robot.max_angular_velocity
        assert cfg.obstacle_range == min(robot.laser_range, cfg.map_size / 2)
        assert (options.base_frame, options.laser_frame) == (robot.base_frame,
                                                             robot.laser_frame)
        assert options.enable_stamped_cmd_vel == robot.stamped_cmd_vel
        assert options.robot == key and options.robot_description is robot
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def test_the_robots_differ_where_their_specifications_do():
    assert BURGER is ROBOTS['burger']
    radii = {k: r.radius for k, r in ROBOTS.items()}
    assert radii['burger'] < radii['turtlebot4'] < radii['waffle_pi'] < radii['jackal']
    # the TurtleBot 4's RPLIDAR is mounted turned a quarter turn, in its own frame
    tb4 = ROBOTS['turtlebot4']
    assert tb4.laser.yaw == pytest.approx(math.pi / 2) and tb4.laser_frame == 'rplidar_link'
    assert all(r.source for r in ROBOTS.values())
