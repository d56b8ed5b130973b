"""Perception judged by the truth: the scan alignment's pose stays near the true one in a
real building (a map from a real laser log, ../shared/dev_maps) with perfect and with
drifting wheel odometry, and the walls it matches to, drawn through the realistic lidar,
stand where they are. Bounds stated for whole runs are what the package promises with
the ideal sensor with 1 cm noise; docs/alignment.md has the realistic sensor's
figures."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from subapf_planner.core.config import load_config
from subapf_planner.core.memory import NavigationMemory
from subapf_planner.core.robot import compose, invert
from subapf_planner.core.scan import scan_to_points
from subapf_planner.ros.paths import default_params_file
from subapf_planner.sim.episode import run_episode
from subapf_planner.sim.simulator import SimConfig
from subapf_planner.sim.world import load_world

pytestmark = pytest.mark.sim

DEV_MAPS = Path(__file__).resolve().parents[2] / 'shared' / 'dev_maps'
CFG = load_config(default_params_file())
#: The sensor these bounds hold for: exact rays with Gazebo's 1 cm noise (through the
#: realistic lidar they do not yet: docs/alignment.md), and the planner told so.
IDEAL = SimConfig(sensor='ideal', range_noise=0.01)
IDEAL_CFG = CFG.replace(range_noise_floor=0.01, range_noise_fraction=0.0)


def _dev_map(name: str):
    path = DEV_MAPS / f'{name}.yaml'
    if not path.is_file():
        pytest.skip(f'{path} is not here (the real-building maps lie beside the checkout)')
    return load_world(path)


def test_with_perfect_odometry_the_alignment_keeps_the_pose_near_the_truth():
    """A task through a real building (MIT CSAIL, 9 m of corridors and doors) with
    perfect odometry: whatever the alignment corrects is its own error; the pose it
    plans from stays within 6 cm of the truth all the way, and the robot arrives."""
    world = _dev_map('csail_003')
    result = run_episode(world, IDEAL_CFG, IDEAL)
    assert str(result.outcome) == 'reached'
    assert result.pose_error.size and result.pose_error.max() < 0.06


def test_on_a_drifting_run_through_a_real_building_the_alignment_corrects_it():
    """The same building with odometry that reports 2 % too much distance and 3 % too
    much turn: at the end odometry alone is decimetres off, the aligned pose within
    10 cm of the truth."""
    world = _dev_map('csail_003')
    drift = dataclasses.replace(IDEAL, odom_distance_scale=1.02, odom_yaw_scale=1.03)
    result = run_episode(world, IDEAL_CFG, drift)
    assert result.odom_error[-1] > 0.2
    assert result.pose_error[-1] < 0.10 and result.pose_error.max() < 0.15


@pytest.mark.parametrize('name', ['orebro_004', 'fr101_013'])
def test_walls_drawn_through_the_realistic_lidar_are_matched_where_they_stand(
        name, monkeypatch):
    """Along a real corridor (Orebro, 9 m; Freiburg 101, 17 m) through the LDS-01's
    noise, a memory drawn at the true poses (perfect odometry): each scan matched to it
    from the true pose, before it is added, lands on average within 2.5 mm of it across
    the way and 1 mrad in heading. Walls cleared by the rays of their returns that fell
    long, and never from behind, were drawn behind themselves: on Orebro's corridor the
    matches leant 2.3 mm and 1.6 mrad, scan after scan (core/occupancy.py's walls'
    layer)."""
    world = _dev_map(name)
    walls = NavigationMemory(CFG)   # the alignment's memory, drawn at the true poses
    offsets = []
    integrate = NavigationMemory.integrate

    def matched_then_integrated(self, scan, scan_pose, *args, **kwargs):
        if self is not walls:   # the planner's own memory: odometry is the truth here
            truth = np.asarray(scan_pose, float)
            base = scan_to_points(scan, (0.0, 0.0, 0.0), CFG.laser_mount, CFG.obstacle_range)
            if len(base) and walls.grid.scans:
                m = walls.align(base, truth)
                if m.accepted:   # the match in the true pose's frame: across, heading
                    offsets.append(compose(invert(truth), m.pose)[1:])
            walls.integrate(scan, scan_pose, *args, **kwargs)
        return integrate(self, scan, scan_pose, *args, **kwargs)

    monkeypatch.setattr(NavigationMemory, 'integrate', matched_then_integrated)
    result = run_episode(world, CFG.replace(scan_alignment=False), SimConfig())
    assert str(result.outcome) == 'reached' and len(offsets) > 150
    across, heading = np.mean(offsets, axis=0)
    assert abs(across) < 0.0025 and abs(heading) < 0.001, (across, heading)
