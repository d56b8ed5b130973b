"""Shared fixtures; every process a test starts gets localhost-only DDS and its own domain."""

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
WORLDS = REPO / 'sim' / 'worlds'
PARAMS = REPO / 'config' / 'planner.yaml'

os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ.setdefault('ROS_DOMAIN_ID', str(50 + os.getpid() % 50))


@pytest.fixture
def worlds_dir() -> Path:
    return WORLDS
