"""Builds: colcon puts the ros2 run executables in lib/subapf_planner; a pip wheel
puts only the subapf-* commands on PATH (setup.py tells the two apart)."""

import ast
import configparser
import os
from pathlib import Path
import shutil
import subprocess
import sys
import zipfile

from conftest import REPO
import pytest

pytestmark = pytest.mark.slow


def executables() -> list[tuple[str, str, str]]:
    """setup.py's EXECUTABLES: (module:function, ros2 run name, subapf-* name)."""
    for node in ast.parse((REPO / 'setup.py').read_text()).body:
        if isinstance(node, ast.Assign) and node.targets[0].id == 'EXECUTABLES':
            return ast.literal_eval(node.value)
    raise AssertionError('no EXECUTABLES in setup.py')


BARE = tuple(name for _, name, _ in executables())
ALIASES = tuple(alias for _, _, alias in executables())


def copy_source(dest: Path) -> Path:
    shutil.copytree(REPO, dest, ignore=shutil.ignore_patterns(
        '.venv', '.git', 'build', 'install', 'log', '__pycache__', '*.egg-info', 'out',
        '.hypothesis', '.pytest_cache', '.ruff_cache', 'dist'))
    return dest


def test_executable_names():
    assert len(BARE) == len(set(BARE)) >= 10 and 'perf' in BARE
    assert all(a.startswith('subapf-') for a in ALIASES)


@pytest.mark.skipif(shutil.which('colcon', path=str(Path(sys.executable).parent)) is None,
                    reason='colcon not installed (pip install -r requirements-test.txt)')
def test_colcon_build_installs_ros2_run_executables(tmp_path):
    copy_source(tmp_path / 'src' / 'subapf_planner')
    colcon = str(Path(sys.executable).parent / 'colcon')
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    r = subprocess.run([colcon, 'build', '--base-paths', 'src'], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    prefix = tmp_path / 'install' / 'subapf_planner'
    lib = prefix / 'lib' / 'subapf_planner'
    for exe in BARE:   # the bare names, where `ros2 run subapf_planner <exe>` looks
        assert os.access(lib / exe, os.X_OK), exe
    assert not (prefix / 'bin').exists()   # nothing of ours on PATH
    check = (
        'from ament_index_python.packages import get_package_prefix, '
        'get_package_share_directory\n'
        'print(get_package_prefix("subapf_planner"))\n'
        'print(get_package_share_directory("subapf_planner"))\n')
    env['AMENT_PREFIX_PATH'] = str(prefix)
    r = subprocess.run([sys.executable, '-c', check], env=env, capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.split()
    assert Path(lines[0]) == prefix
    share = Path(lines[1])
    assert (share / 'config' / 'planner.yaml').is_file()
    assert (share / 'config' / 'subapf.rviz').is_file()
    assert len(list((share / 'worlds').glob('*.yaml'))) >= 8
    # what `ros2 launch subapf_planner <file>` and the robot configs need
    assert {p.name for p in (share / 'launch').iterdir()} == {
        'planner.launch.py', 'sim.launch.py', 'nav2.launch.py'}
    assert {p.name for p in (share / 'config' / 'robots').iterdir()} == {
        'burger.yaml', 'waffle_pi.yaml', 'turtlebot4.yaml', 'jackal.yaml'}
    # an installed executable runs (figures needs no ROS graph), from its entry point
    env['PYTHONPATH'] = os.pathsep.join(
        str(p) for p in prefix.glob('lib/python*/site-packages'))
    r = subprocess.run([str(lib / 'figures'), '--help'], env=env, capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0 and 'usage' in r.stdout, r.stderr


def build_wheel(src: Path, out: Path, ros_distro: str | None) -> zipfile.ZipFile:
    env = {k: v for k, v in os.environ.items() if k != 'ROS_DISTRO'}
    if ros_distro:
        env['ROS_DISTRO'] = ros_distro
    r = subprocess.run([sys.executable, '-m', 'pip', 'wheel', '--no-deps', '-q',
                        '-w', str(out), str(src)],
                       capture_output=True, text=True, timeout=600, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    (wheel,) = out.glob('subapf_planner-*.whl')
    return zipfile.ZipFile(wheel)


def wheel_metadata(z: zipfile.ZipFile) -> tuple[configparser.ConfigParser, list[str]]:
    info = next(n for n in z.namelist() if n.endswith('.dist-info/entry_points.txt'))
    entry_points = configparser.ConfigParser()
    entry_points.read_string(z.read(info).decode())
    metadata = z.read(info.replace('entry_points.txt', 'METADATA')).decode()
    return entry_points, [line for line in metadata.splitlines()
                          if line.startswith('Requires-Dist:')]


def test_pip_wheel_puts_only_subapf_commands_on_path(tmp_path):
    """Only subapf-* commands; the ROS wheels are required outside a sourced Jazzy shell
    (`pip install .` alone works) and not inside one (no second rclpy)."""
    src = copy_source(tmp_path / 'src')
    plain = build_wheel(src, tmp_path / 'plain', None)
    entry_points, requires = wheel_metadata(plain)
    scripts = dict(entry_points['console_scripts'])
    assert set(scripts) == set(ALIASES)
    for target, _, alias in executables():
        assert scripts[alias] == f'subapf_planner.{target}'
    assert 'data/scripts' not in ''.join(plain.namelist())
    assert any('ros-jazzy-rclpy' in line for line in requires)
    _, requires = wheel_metadata(build_wheel(copy_source(tmp_path / 'src2'),
                                             tmp_path / 'sourced', 'jazzy'))
    assert requires and not any('ros-' in line or 'rclpy' in line for line in requires)
