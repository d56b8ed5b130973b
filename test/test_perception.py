"""Perception judged by the truth: the scan alignment's pose stays near the true one in a
real building (a map from a real laser log, ../shared/dev_maps) with perfect and with
drifting wheel odometry. Bounds stated here are what the package promises with the
ideal sensor with 1 cm noise; docs/alignment.md has the realistic sensor's figures."""

import dataclasses
from pathlib import Path

import pytest

from subapf_planner.core.config import load_config
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
