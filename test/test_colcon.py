"""A colcon build in a temporary workspace puts the executables where `ros2 run` looks."""

import os
from pathlib import Path
import shutil
import subprocess
import sys

from conftest import REPO
import pytest

EXECUTABLES = ('planner_node', 'sim_node', 'bringup', 'bench', 'figures', 'perf', 'nodeperf',
               'record', 'soak',
               'replay')


@pytest.mark.skipif(shutil.which('colcon', path=str(Path(sys.executable).parent)) is None,
                    reason='colcon not installed (pip install -r requirements-test.txt)')
def test_colcon_build_installs_ros2_run_executables(tmp_path):
    src = tmp_path / 'src' / 'subapf_planner'
    shutil.copytree(REPO, src, ignore=shutil.ignore_patterns(
        '.venv', '.git', 'build', 'install', 'log', '__pycache__', '*.egg-info', 'out'))
    colcon = str(Path(sys.executable).parent / 'colcon')
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    r = subprocess.run([colcon, 'build', '--base-paths', 'src'], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    prefix = tmp_path / 'install' / 'subapf_planner'
    check = (
        'from ament_index_python.packages import get_package_prefix, '
        'get_package_share_directory\n'
        'import os\n'
        'p = get_package_prefix("subapf_planner")\n'
        'print(p)\n'
        'print(get_package_share_directory("subapf_planner"))\n'
        f'for exe in {EXECUTABLES!r}:\n'
        '    f = os.path.join(p, "lib", "subapf_planner", exe)\n'
        '    assert os.access(f, os.X_OK), f\n')
    env['AMENT_PREFIX_PATH'] = str(prefix)
    r = subprocess.run([sys.executable, '-c', check], env=env, capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.split()
    assert Path(lines[0]) == prefix
    share = Path(lines[1])
    assert (share / 'config' / 'planner.yaml').is_file()
    assert len(list((share / 'worlds').glob('*.yaml'))) >= 8
