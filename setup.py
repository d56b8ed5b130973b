"""ament_python build of subapf_planner (colcon) that also installs with pip."""

from glob import glob

from setuptools import find_packages, setup

PACKAGE = 'subapf_planner'

# (module:function, ros2 run name, plain command name)
EXECUTABLES = [
    ('ros.planner_node:main', 'planner_node', 'subapf-planner'),
    ('ros.sim_node:main', 'sim_node', 'subapf-sim'),
    ('tools.bringup:main', 'bringup', 'subapf-bringup'),
    ('tools.bench:main', 'bench', 'subapf-bench'),
    ('tools.figures:main', 'figures', 'subapf-figures'),
    ('tools.perf:main', 'perf', 'subapf-perf'),
    ('tools.nodeperf:main', 'nodeperf', 'subapf-nodeperf'),
    ('tools.record:main', 'record', 'subapf-record'),
    ('tools.replay:main', 'replay', 'subapf-replay'),
    ('tools.soak:main', 'soak', 'subapf-soak'),
]

setup(
    name=PACKAGE,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    package_data={PACKAGE + '.sim': ['urdf/*.urdf']},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + PACKAGE]),
        ('share/' + PACKAGE, ['package.xml']),
        ('share/' + PACKAGE + '/config', glob('config/*.yaml')),
        ('share/' + PACKAGE + '/worlds', glob('sim/worlds/*.yaml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='subapf developers',
    maintainer_email='dev@subapf.invalid',
    description='Subharmonic APF local planner with circular sampling, for ROS 2 Jazzy',
    license='Apache-2.0',
    python_requires='>=3.10',
    entry_points={
        'console_scripts': [f'{name} = {PACKAGE}.{target}' for target, name, _ in EXECUTABLES]
        + [f'{alias} = {PACKAGE}.{target}' for target, _, alias in EXECUTABLES],
    },
)
