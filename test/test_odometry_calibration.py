"""Odometry calibration (core/odometry_calibration.py): a scaled motion is the arc
scaled, two scans register to their relative pose, a drive round a room learns the
wheels' scales, perfect odometry stays at 1, and a featureless corridor teaches the
distance nothing."""

import math

import numpy as np
import pytest
from test_alignment import room, seen_from, segment

from subapf_planner.core.odometry_calibration import (
    MIN_SAMPLES,
    OdometryCalibration,
    register,
    scaled,
)
from subapf_planner.core.robot import compose, invert


def arc(length, turn):
    """The motion (x, y, yaw) along an arc of ``length`` [m] turning ``turn`` [rad]."""
    if turn == 0.0:
        return length, 0.0, 0.0
    r = length / turn
    return r * math.sin(turn), r * (1.0 - math.cos(turn)), turn


@pytest.mark.core
@pytest.mark.parametrize('length,turn', [(0.5, 0.0), (0.0, 0.6), (0.4, 0.3), (0.3, -0.5)])
def test_a_scaled_motion_is_the_arc_with_its_length_and_turn_scaled(length, turn):
    """Within a millimetre for the arcs between two scans (exact on a line or on the
    spot)."""
    k = (0.97, 1.04)
    want = arc(k[0] * length, k[1] * turn)
    got = scaled(arc(length, turn), k)
    assert np.allclose(got[:2], want[:2], atol=1e-3) and got[2] == pytest.approx(want[2])


@pytest.mark.core
def test_two_scans_register_to_their_relative_pose():
    """Seen 0.45 m and 0.3 rad apart through 1 cm of range noise, from a guess 3 % off:
    within 5 mm and 3 mrad of the truth."""
    walls = room()
    a, b = (-1.0, -0.5, 0.2), (-0.6, -0.3, 0.5)
    truth = np.array(compose(invert(a), b))
    found = register(seen_from(walls, a, seed=1), seen_from(walls, b, seed=2),
                     scaled(truth, (1.03, 1.03)))
    assert found is not None
    assert np.hypot(*(found.pose[:2] - truth[:2])) < 0.005
    assert abs(found.pose[2] - truth[2]) < 0.003


def drive(walls, poses, wheels, seed=0):
    """Calibrate along the true ``poses`` (k, 3) with odometry whose distance and turn
    are ``wheels`` times the truth's; the learnt scales and sample counts."""
    cal = OdometryCalibration()
    odom = np.array(poses[0], float)
    for i, pose in enumerate(poses):
        if i:
            odom = np.array(compose(odom, scaled(compose(invert(poses[i - 1]), pose),
                                                 wheels)))
        cal.observe(seen_from(walls, pose, seed=seed + i), odom)
    return cal.scales, cal.samples


def circle(centre, radius, turns=1.5, step=0.04):
    """Poses every ``step`` [m] round a circle, heading along it (counter-clockwise)."""
    a = np.arange(0.0, turns * 2 * math.pi, step / radius)
    return np.column_stack((centre[0] + radius * np.sin(a), centre[1] - radius * np.cos(a),
                            a))


@pytest.mark.core
def test_a_drive_round_a_room_learns_the_wheels_scales():
    """Odometry 2 % long and turning 3 % too far (the bench's drifting wheels): after
    11 m round the room both scales are within 0.5 % of the truth, and they stay within
    0.5 % of 1 with perfect odometry."""
    poses = circle((-0.5, 0.0), 1.2)
    (k_d, k_y), samples = drive(room(), poses, (1.02, 1.03))
    assert min(samples) >= 10
    assert k_d == pytest.approx(1 / 1.02, abs=0.005)
    assert k_y == pytest.approx(1 / 1.03, abs=0.005)
    (k_d, k_y), _ = drive(room(), poses, (1.0, 1.0), seed=1000)
    assert k_d == pytest.approx(1.0, abs=0.005) and k_y == pytest.approx(1.0, abs=0.005)


@pytest.mark.core
def test_one_registration_does_not_set_a_scale():
    """A scale is taken once MIN_SAMPLES samples of it have been: with odometry 5 % long
    and turning 5 % too far, the first metre round the room (two or three samples of
    each) leaves both scales at 1; the rest of the drive learns them."""
    poses = circle((-0.5, 0.0), 1.2)
    (k_d, k_y), samples = drive(room(), poses[:26], (1.05, 1.05))
    assert 0 < max(samples) < MIN_SAMPLES and (k_d, k_y) == (1.0, 1.0)
    (k_d, k_y), samples = drive(room(), poses, (1.05, 1.05))
    assert min(samples) >= MIN_SAMPLES and k_d < 0.97 and k_y < 0.97


@pytest.mark.core
def test_a_featureless_corridor_teaches_the_distance_nothing():
    """Two parallel walls, nothing across: a registration there fixes the pose across
    the corridor, not along it, and the distance scale stays within 0.5 % of 1 while
    odometry is 5 % long."""
    walls = np.vstack([segment((-30.0, -1.0), (30.0, -1.0)), segment((-30.0, 1.0), (30.0, 1.0))])
    poses = np.column_stack((np.arange(0.0, 8.0, 0.04), np.zeros(200), np.zeros(200)))
    (k_d, _), _ = drive(walls, poses, (1.05, 1.0))
    assert k_d == pytest.approx(1.0, abs=0.01)


@pytest.mark.core
def test_too_few_returns_register_nothing():
    assert register(np.zeros((5, 2)), np.zeros((5, 2)), (0.0, 0.0, 0.0)) is None
    cal = OdometryCalibration()
    for x in np.arange(0.0, 3.0, 0.1):
        cal.observe(np.zeros((0, 2)), (x, 0.0, 0.0))
    assert cal.scales == (1.0, 1.0) and cal.samples == [0, 0]


@pytest.mark.core
def test_a_turn_is_corrected_by_its_registration_before_anything_is_learnt():
    """Turning 0.8 rad on the spot with odometry turning 3 % too far: the pose predicted
    by odometry (scales 1, nothing learnt) is 0.024 rad off; corrected by the turn's
    registration to the keyframe (placed where it truly was), within 5 mrad. A scan of
    another place is not taken (the prediction stands)."""
    walls = room()
    a, b = np.array([-1.0, -0.5, 0.2]), np.array([-1.0, -0.5, 1.0])
    cal = OdometryCalibration()
    cal.observe(seen_from(walls, a, seed=3), a)
    cal.place(a)
    odom_b = np.array(compose(a, scaled(compose(invert(a), b), (1.0, 1.03))))
    predicted = odom_b   # odom is the memory's frame here
    cal.observe(seen_from(walls, b, seed=4), odom_b)
    assert cal.samples[1] == 1 and cal.scales[1] == 1.0   # a sample, not yet a scale
    assert abs(predicted[2] - b[2]) > 0.02
    corrected = cal.correct(predicted)
    assert abs(corrected[2] - b[2]) < 0.005 and np.hypot(*(corrected[:2] - b[:2])) < 0.01
    cal.place(corrected)
    elsewhere = seen_from(walls + np.array([0.7, 0.4]), (1.0, 0.5, 2.0), seed=5)
    cal.observe(elsewhere, compose(odom_b, (0.6, 0.0, 0.0)))
    ahead = np.array(compose(corrected, (0.6, 0.0, 0.0)))
    assert np.allclose(cal.correct(ahead), ahead)
