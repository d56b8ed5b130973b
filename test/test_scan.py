"""Scan conversion: invalid beams dropped, geometry right, downsampling."""

import math

from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
import numpy as np
import pytest

from subapf_planner.core.scan import (
    GRAZING_MEMORY,
    GRAZING_OBSTACLES,
    MAX_SWEEP,
    Scan,
    ScanError,
    denoise,
    scan_to_points,
    valid_beams,
    voxel_downsample,
)

pytestmark = pytest.mark.core

ranges_st = arrays(np.float64, st.integers(0, 500),
                   elements=st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                                      st.floats(0.0, 5.0)))


@given(r=ranges_st)
@settings(max_examples=300, deadline=None)
def test_only_valid_returns_become_points(r):
    pts = scan_to_points(Scan(r, 0.0, 2 * math.pi / max(len(r), 1), 0.12, 3.5), (1.0, -2.0, 0.3))
    expected = np.sum(np.isfinite(r) & (r >= 0.12) & (r < 3.5))
    assert pts.shape == (expected, 2)
    assert np.all(np.isfinite(pts))
    if expected:
        d = np.hypot(pts[:, 0] - 1.0, pts[:, 1] + 2.0)
        assert np.all(d >= 0.12 - 1e-9) and np.all(d < 3.5)


def test_lds01_zero_and_lds02_nan_are_dropped():
    r = np.array([0.0, np.nan, np.inf, -np.inf, -1.0, 0.05, 1.0, 3.5, 100.0])
    assert valid_beams(r, 0.12, 3.5).tolist() == [False] * 6 + [True, False, False]
    assert valid_beams(r, 0.0, 100.0).tolist() == [False] * 5 + [True, True, True, False]


def test_geometry_with_pose_and_laser_offset():
    # one beam straight ahead at 1 m, laser 0.1 m behind the base, robot at (2, 3) facing +y
    pts = scan_to_points(Scan([1.0], 0.0, 0.01, 0.1, 3.5), (2.0, 3.0, math.pi / 2),
                         (-0.1, 0.0, 0.0))
    np.testing.assert_allclose(pts, [[2.0, 3.9]], atol=1e-12)
    # beam at +90 deg in a laser yawed by pi
    pts = scan_to_points(Scan([0.0, 1.0], 0.0, math.pi / 2, 0.1, 3.5), (0, 0, 0),
                         (0, 0, math.pi))
    np.testing.assert_allclose(pts, [[0.0, -1.0]], atol=1e-12)


def test_empty_scan_and_bad_geometry():
    assert scan_to_points(Scan([], 0.0, 0.0, 0.1, 3.5), (0, 0, 0)).shape == (0, 2)
    with pytest.raises(ScanError, match='angle_increment'):
        scan_to_points(Scan([1.0, 1.0], 0.0, 0.0, 0.1, 3.5), (0, 0, 0))
    with pytest.raises(ScanError, match='angle_increment'):
        scan_to_points(Scan([1.0, 1.0], 0.0, -0.1, 0.1, 3.5), (0, 0, 0))
    with pytest.raises(ScanError, match='non-finite'):
        scan_to_points(Scan([1.0], math.nan, 0.1, 0.1, 3.5), (0, 0, 0))


def test_voxel_downsample_bounds_wall_density():
    dense = np.column_stack((np.linspace(0, 0.999, 1000), np.full(1000, 0.52)))
    sparse = dense[25::50]   # one beam per 5 cm
    a, b = voxel_downsample(dense, 0.05), voxel_downsample(sparse, 0.05)
    assert len(a) == 20 and len(b) == 20   # 1 m of wall: 20 cells, whatever the density
    # every input point is within one cell diagonal of a kept point
    d = np.min(np.hypot(*(dense[:, None, :] - a[None]).transpose(2, 0, 1)), axis=1)
    assert d.max() <= 0.05 * math.sqrt(2)
    x = dense.copy()
    voxel_downsample(x, 0.05)
    np.testing.assert_array_equal(x, dense)
    np.testing.assert_array_equal(voxel_downsample(dense, 0.0), dense)


def test_geometry_warning_survives_a_denormal_increment():
    """A header whose span over its increment overflows (a denormal increment, found by
    the node fuzz) is reported, not a crash."""
    from subapf_planner.core.scan import geometry_warning
    assert 'too small' in geometry_warning(2, 1.0, 0.0, 2.2e-309)


@pytest.mark.parametrize('increment, expected', [
    (0.2 / 360, 0.2 / 360),   # an LDS-01 sweep
    (0.0, 0.0), (-1e-3, 0.0), (math.nan, 0.0), (math.inf, 0.0),
    (1.0, 0.0),               # 360 s for a sweep: not a sweep
])
def test_beam_interval_is_a_sweep_s_or_nothing(increment, expected):
    """A driver's time_increment dates the beams only when it describes a sweep: NaN,
    negative or a sweep longer than MAX_SWEEP is taken as a scan taken at once."""
    scan = Scan(np.ones(360), 0.0, 2 * math.pi / 360, 0.1, 10.0, 0.0, increment, 0.2)
    assert scan.beam_interval == expected
    assert 359 * scan.beam_interval <= MAX_SWEEP


def test_denoise_leaves_grazing_returns_to_the_memory():
    """Exact returns from a crenellated wall (5 cm teeth every 10 cm) 1 m away, the
    planner expecting the LDS-01's noise. Where the rays meet the wall at more than 45
    degrees from its normal, lines fitted across seven beams span several teeth: the
    obstacles' bound (GRAZING_OBSTACLES) moves these exact returns by centimetres, the
    memory's (GRAZING_MEMORY) by millimetres. (Moved by centimetres as the robot drives
    past, the memory's walls drew the drive 1 % long:
    test_alignment.py::test_stepped_walls_do_not_stretch_the_drive.)"""
    n = 720
    angles = 2 * math.pi * np.arange(n) / n
    up = (angles > 0.05) & (angles < math.pi - 0.05)
    t = np.arange(0.0, 4.0, 2e-4)
    x = np.cos(angles[up])[:, None] * t
    y = np.sin(angles[up])[:, None] * t
    wall = 1.0 + 0.05 * (np.floor(x / 0.1) % 2)
    first = np.argmax(y >= wall, axis=1)   # the first sample on or beyond the wall
    ranges = np.full(n, np.nan)
    ranges[up] = np.where(first > 0, t[first], np.nan)
    scan = Scan(ranges, 0.0, 2 * math.pi / n, 0.1, 3.5, 0.0)
    grazing = up & (np.abs(np.sin(angles)) < math.cos(math.radians(45))) & (ranges < 3.5)
    assert np.count_nonzero(grazing) > 100
    moved = {bound: np.mean(np.abs(denoise(scan, 0.015, 0.025, grazing=bound).ranges
                                   - ranges)[grazing])
             for bound in (GRAZING_OBSTACLES, GRAZING_MEMORY)}
    assert moved[GRAZING_OBSTACLES] > 0.01 and moved[GRAZING_MEMORY] < 0.005


@pytest.mark.parametrize('shift, moved', [(0.4, 0), (0.6, 1), (-0.6, -1)])
def test_flags_of_the_grid_s_beams_follow_each_return_to_its_own_direction(shift, moved):
    """The tracker flags beams of the scan on its grid of angles; the memory takes the
    same sweep with each return at its own direction: each return takes the flag of the
    grid's beam its direction is nearest (a turn around the full circle wraps)."""
    from subapf_planner.core.scan import on_grid
    n, inc = 360, math.radians(1.0)
    grid = Scan(np.full(n, 2.0), 0.0, inc, 0.12, 3.5)
    exact = Scan(np.full(n, 2.0), 0.0, inc, 0.12, 3.5,
                 bearings=(np.arange(n) + shift) * inc)
    flags = np.zeros(n, bool)
    flags[[10, 11, 12, 0]] = True
    got = on_grid(flags, grid, exact)
    assert np.array_equal(np.flatnonzero(got),
                          np.sort(np.mod(np.array([10, 11, 12, 0]) - moved, n)))
    assert on_grid(flags, grid, grid) is flags      # both on the grid: as they are


@pytest.mark.parametrize('seconds, period, scans', [(2.0, 0.2, 10), (2.0, 0.05, 40),
                                                     (5.0, 0.05, 100), (0.01, 0.2, 1)])
def test_a_wait_in_seconds_is_as_many_scans_as_the_planning_rate_takes(seconds, period, scans):
    """What the memory waits for (a cluster on what has stood STANDING_TIME, walls that
    have stood MIN_WALL_AGE for small pieces of the scan) is a time: counted in scans
    at the planning rate, at least one."""
    from subapf_planner.core.scan import scans_in
    assert scans_in(seconds, period) == scans
