"""Where the package's shipped files are: worlds, the parameter file, the DDS profile.

Looked up in this order: the ament index (colcon workspace or the pip
install's share/ folder), then the source checkout this module lives in.
"""

from __future__ import annotations

import os
from pathlib import Path
import sys

PACKAGE = 'subapf_planner'


def _share_candidates() -> list[Path]:
    out = []
    for prefix in filter(None, os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep)):
        out.append(Path(prefix) / 'share' / PACKAGE)
    out.append(Path(sys.prefix) / 'share' / PACKAGE)
    out.append(Path(__file__).resolve().parents[2])  # source checkout: sim/, config/
    return out


def _find(*relative: str) -> Path:
    tried = []
    for base in _share_candidates():
        for rel in relative:
            p = base / rel
            if p.exists():
                return p
            tried.append(str(p))
    raise FileNotFoundError(f'none of these exist: {", ".join(tried)}')


def shipped_worlds_dir() -> Path:
    """Folder of the shipped world files (share/subapf_planner/worlds or sim/worlds)."""
    return _find('worlds', 'sim/worlds')


def default_params_file() -> Path:
    """The package's config/planner.yaml."""
    return _find('config/planner.yaml')


def robot_params_file(robot: str) -> Path:
    """The planner parameters of a shipped robot: config/robots/<robot>.yaml."""
    return _find(f'config/robots/{robot}.yaml')


def fastdds_profile_file() -> Path:
    """The package's Fast DDS profile, config/fastdds.xml (see ros/processes.py)."""
    return _find('config/fastdds.xml')
