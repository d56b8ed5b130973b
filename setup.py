"""ament_python build of subapf_planner (colcon) that also installs with pip."""

from glob import glob
import os
import sys

from setuptools import find_packages, setup

PACKAGE = 'subapf_planner'

# (module:function, ros2 run name, plain command name)
EXECUTABLES = [
    ('ros.planner_node:main', 'planner_node', 'subapf-planner'),
    ('ros.lifecycle_node:main', 'lifecycle_planner_node', 'subapf-planner-lifecycle'),
    ('ros.sim_node:main', 'sim_node', 'subapf-sim'),
    ('ros.foxglove_node:main', 'foxglove_node', 'subapf-foxglove'),
    ('tools.bringup:main', 'bringup', 'subapf-bringup'),
    ('tools.bench:main', 'bench', 'subapf-bench'),
    ('tools.results:main', 'results', 'subapf-results'),
    ('tools.fingerprint:main', 'fingerprint', 'subapf-fingerprint'),
    ('tools.figures:main', 'figures', 'subapf-figures'),
    ('tools.perf:main', 'perf', 'subapf-perf'),
    ('tools.nodeperf:main', 'nodeperf', 'subapf-nodeperf'),
    ('tools.record:main', 'record', 'subapf-record'),
    ('tools.replay:main', 'replay', 'subapf-replay'),
    ('tools.soak:main', 'soak', 'subapf-soak'),
    ('tools.worlds:main', 'worlds', 'subapf-worlds'),
]

# Runtime dependencies from PyPI. The ROS 2 packages (rclpy and the message packages)
# come from ROS in a sourced Jazzy shell (ROS_DISTRO set), where the ros-jazzy-*
# wheels would install a second rclpy; anywhere else `pip install .` alone must give
# working commands, so it brings the wheels (requirements.txt pins the same ones).
# colcon never installs install_requires; its dependencies are package.xml's.
ROS_WHEELS = ['ros-jazzy-rclpy[fastrtps]==7.1.6', 'ros-jazzy-common-interfaces==5.3.6']
INSTALL_REQUIRES = [
    'numpy>=1.26,<3',
    'scipy>=1.11',
    'pybullet==3.2.7',
    'mcap>=1.2,<2',
    'matplotlib>=3.8',
    'pyyaml>=6',
    'tqdm>=4.66',
    'scikit-fmm>=2024.5',
    'distributed>=2024.1',   # subapf-bench --cluster (Dask)
    'foxglove-sdk>=0.30,<1',   # subapf-foxglove (live view)
]

# Which names the console scripts get. The bare names (planner_node, bench, perf, ...)
# are what `ros2 run subapf_planner <exe>` looks for in <prefix>/lib/subapf_planner;
# on a venv's PATH they would clash with other programs (`perf` is the Linux
# profiler), so a pip install only gets the subapf-* names.
#
# colcon's ament_python build (colcon-core's PythonBuildTask, seen in a real
# `colcon build`) runs this file directly, as
#   setup.py egg_info ... build ... install ... --install-scripts $base/lib/subapf_planner
# or, with --symlink-install, as
#   setup.py develop --editable ... --no-deps symlink_data
# whereas pip builds through the PEP 517/660 backend (setuptools.build_meta, see
# pyproject.toml [build-system]), which runs `setup.py egg_info`, `dist_info`,
# `bdist_wheel` or `editable_wheel`, never `install` or `develop`. So the command
# line tells the two apart. (colcon also sets COLCON=1 in the environment, but every
# process under `colcon test` inherits that too, a pip wheel build included.)
COLCON_COMMANDS = {'install', 'develop'}
ROS_BUILD = bool(COLCON_COMMANDS & set(sys.argv[1:]))

console_scripts = [f'{alias} = {PACKAGE}.{target}' for target, _, alias in EXECUTABLES]
if ROS_BUILD:
    console_scripts += [f'{name} = {PACKAGE}.{target}' for target, name, _ in EXECUTABLES]

setup(
    name=PACKAGE,
    version='0.9.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE]),
        ('share/' + PACKAGE, ['package.xml']),
        ('share/' + PACKAGE + '/config',
         glob('config/*.yaml') + glob('config/*.xml') + glob('config/*.rviz')),
        ('share/' + PACKAGE + '/config/robots', glob('config/robots/*.yaml')),
        ('share/' + PACKAGE + '/launch', glob('launch/*.launch.py')),
        ('share/' + PACKAGE + '/worlds', glob('sim/worlds/*.yaml')),
    ],
    install_requires=INSTALL_REQUIRES + ([] if os.environ.get('ROS_DISTRO') else ROS_WHEELS),
    zip_safe=True,
    maintainer='subapf developers',
    maintainer_email='dev@subapf.invalid',
    description='Subharmonic APF local planner with circular sampling, for ROS 2 Jazzy',
    license='Apache-2.0',
    python_requires='>=3.10',
    entry_points={'console_scripts': console_scripts},
)
