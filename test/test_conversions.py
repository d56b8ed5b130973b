"""Message <-> array conversions, with messages built directly (no rclpy.init)."""

import math

from builtin_interfaces.msg import Time
import numpy as np
import pytest

from subapf_planner.core.known_map import KnownMap, KnownMapError
from subapf_planner.core.occupancy import OccupancyGrid
from subapf_planner.core.scan import Scan
from subapf_planner.ros.conversions import (
    cmd_from_msg,
    cmd_to_msg,
    grid_to_msg,
    known_map_from_msg,
    known_map_to_msg,
    odom_to_msg,
    path_to_msg,
    pose_from_odom,
    scan_from_msg,
    scan_to_msg,
    seconds_to_stamp,
    stamp_to_seconds,
)

pytestmark = pytest.mark.node


def test_grid_message_keeps_geometry_and_maps_log_odds_to_percent():
    grid = OccupancyGrid(0.1, 2.0)
    grid.log_odds[3, 5] = 3.5          # occupied
    grid.log_odds[4, 5] = -2.0         # free
    msg = grid_to_msg(grid, 'odom', Time(sec=7))
    assert msg.header.frame_id == 'odom' and msg.header.stamp.sec == 7
    assert (msg.info.width, msg.info.height) == (20, 20)
    assert msg.info.resolution == pytest.approx(0.1)
    assert (msg.info.origin.position.x, msg.info.origin.position.y) == (-1.0, -1.0)
    data = np.asarray(msg.data).reshape(20, 20)          # row-major, row = y
    assert data[3, 5] == 97 and data[4, 5] == 12 and data[0, 0] == -1
    assert (data == -1).sum() == 398


def test_grid_and_markers_of_a_corrected_memory_are_drawn_in_odom():
    """With a drift correction (the memory's frame = odom turned by 0.1 rad and moved),
    the grid's origin and every marker carry the memory frame's pose in odom, so a
    memory point lands where odom has it."""
    from subapf_planner.core.command import Command
    from subapf_planner.core.planner import PlanResult
    from subapf_planner.core.robot import compose, invert, to_parent
    from subapf_planner.core.status import Status
    from subapf_planner.ros.markers import markers_from_result
    correction = (0.3, -0.2, 0.1)
    in_odom = invert(correction)
    grid = OccupancyGrid(0.1, 2.0)
    msg = grid_to_msg(grid, 'odom', Time(), in_odom)
    o = msg.info.origin
    expect = compose(in_odom, (-1.0, -1.0, 0.0))
    assert (o.position.x, o.position.y) == pytest.approx(expect[:2])
    assert 2 * math.atan2(o.orientation.z, o.orientation.w) == pytest.approx(-0.1)
    point = np.array([1.0, 2.0])
    result = PlanResult(Command(0.1, 0.0, Status.DRIVING), chosen_point=point,
                        obstacles=point[None], pose=np.array([1.0, 2.0, 0.0]),
                        correction=correction)
    markers = {m.ns: m for m in markers_from_result(result, 'odom', Time(), 0.25, 0.105).markers}
    chosen = markers['chosen_point'].pose.position
    assert (chosen.x, chosen.y) == pytest.approx(to_parent(in_odom, point)[0])
    obs = markers['obstacles']
    yaw = 2 * math.atan2(obs.pose.orientation.z, obs.pose.orientation.w)
    drawn = to_parent((obs.pose.position.x, obs.pose.position.y, yaw),
                      [[obs.points[0].x, obs.points[0].y]])
    np.testing.assert_allclose(drawn[0], to_parent(in_odom, point)[0], atol=1e-9)


def test_path_message_orients_each_pose_along_the_path():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    msg = path_to_msg(pts, 'odom', Time())
    assert [p.header.frame_id for p in msg.poses] == ['odom'] * 3
    yaw = [2 * math.atan2(p.pose.orientation.z, p.pose.orientation.w) for p in msg.poses]
    assert yaw[0] == pytest.approx(0.0) and yaw[1] == pytest.approx(math.pi / 2)
    assert len(path_to_msg(np.zeros((0, 2)), 'odom', Time()).poses) == 0


def test_round_trips():
    assert stamp_to_seconds(seconds_to_stamp(12.345678912)) == pytest.approx(12.345678912)
    for stamped in (True, False):
        assert cmd_from_msg(cmd_to_msg(0.1, -0.5, stamped)) == (0.1, -0.5)
    pose = np.array([1.0, -2.0, 2.5])
    np.testing.assert_allclose(pose_from_odom(odom_to_msg(pose, (0.0, 0.0), 3.0)), pose)
    ranges = np.array([1.0, np.inf, np.nan, 0.0])
    scan = scan_from_msg(scan_to_msg(Scan(ranges, -0.1, 0.01, 0.12, 3.5, 4.0), 'base_scan'))
    np.testing.assert_array_equal(scan.ranges, ranges.astype(np.float32))
    assert scan.stamp == pytest.approx(4.0) and scan.angle_increment == pytest.approx(0.01)


def test_planar_transform_gives_the_planar_part_and_whether_it_is_level():
    import math

    from subapf_planner.ros.conversions import planar_transform, transform_msg
    t = transform_msg('base_link', 'laser', (0.1, -0.2, 0.3), 1.2, 0.0)
    parent, child, pose, level = planar_transform(t)
    assert (parent, child, level) == ('base_link', 'laser', True)
    assert pose == pytest.approx((0.1, -0.2, 1.2))
    t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, \
        t.transform.rotation.w = 1.0, 0.0, 0.0, 0.0   # upside down (roll pi)
    assert planar_transform(t)[3] is False
    s = math.sin(0.01)   # a hundredth of a radian of pitch is level
    t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, \
        t.transform.rotation.w = 0.0, s, 0.0, math.cos(0.01)
    assert planar_transform(t)[3] is True
    t.transform.rotation.x, t.transform.rotation.y = 0.0, 0.0   # zero: no rotation at all
    t.transform.rotation.z, t.transform.rotation.w = 0.0, 0.0
    assert planar_transform(t)[3] is False


def test_footprint_marker_outlines_the_robot_and_points_its_heading():
    from subapf_planner.core.command import Command
    from subapf_planner.core.planner import PlanResult
    from subapf_planner.core.status import Status
    from subapf_planner.ros.markers import markers_from_result
    pose = np.array([1.0, -2.0, 0.5])
    result = PlanResult(Command(0.0, 0.0, Status.DRIVING), obstacles=np.zeros((0, 2)),
                        pose=pose)
    markers = {m.ns: m for m in markers_from_result(result, 'odom', Time(), 0.25, 0.105).markers}
    for ns, radius in (('footprint', 0.105), ('danger_circle', 0.25)):
        xy = np.array([[p.x, p.y] for p in markers[ns].points])
        np.testing.assert_allclose(np.hypot(*(xy[:-1] - pose[:2]).T), radius, atol=1e-12)
        np.testing.assert_allclose(xy[0], pose[:2] + radius * np.array([np.cos(0.5),
                                                                         np.sin(0.5)]))
        np.testing.assert_allclose(xy[-1], pose[:2])   # the heading ends at the centre


def test_a_map_message_round_trips_and_a_malformed_one_is_refused():
    cells = np.zeros((3, 4), np.int8)
    cells[1, 2], cells[0, 0] = 100, -1
    msg = known_map_to_msg(KnownMap(cells, (1.0, -2.0), 0.05), 'map', Time())
    assert (msg.info.width, msg.info.height, msg.header.frame_id) == (4, 3, 'map')
    back = known_map_from_msg(msg)
    assert np.array_equal(back.cells, cells) and back.resolution == pytest.approx(0.05)
    # (the origin is the placement: the same cells at the same places)
    assert back.at([(1.0 + 2.5 * 0.05, -2.0 + 1.5 * 0.05)])[0] == 100
    msg.data = msg.data[:-1]
    with pytest.raises(KnownMapError):
        known_map_from_msg(msg)
    msg = known_map_to_msg(KnownMap(cells, (0.0, 0.0), 0.05), 'map', Time())
    msg.info.resolution = 0.0
    with pytest.raises(KnownMapError):
        known_map_from_msg(msg)
