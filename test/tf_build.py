"""tf2_msgs for the tests, where no ROS install provides it (the PyPI ROS wheels do not).

Its interface is one message, ``geometry_msgs/TransformStamped[] transforms``.
:func:`tf2_msgs_paths` writes that interface package (FILES) into a cache keyed by the
inputs and builds it once with colcon and the ROS interface generators from PyPI, in a
venv of their own (test/tf2_msgs_build_requirements.txt), and returns the paths a
process needs to import it. The package lives only in the cache: a package.xml in
the source tree would be built by colcon and taken by rosdep for the real tf2_msgs.
The generator wheels' CMake exports name their builder's Python and numpy include
directories (/opt/python/cp311-cp311/...); they are pointed at this machine's first.
Takes about a minute the first time (the pip install; the build itself 12 s),
nothing after.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
import shutil
import subprocess
import sys

REQUIREMENTS = Path(__file__).resolve().parent / 'tf2_msgs_build_requirements.txt'
#: The interface package: path -> text.
FILES = {
    'package.xml': """<?xml version="1.0"?>
<package format="3">
  <name>tf2_msgs</name>
  <version>0.36.0</version>
  <description>tf2_msgs/TFMessage only, built for subapf_planner's tests</description>
  <maintainer email="dev@subapf.invalid">subapf developers</maintainer>
  <license>BSD-3-Clause</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <buildtool_depend>rosidl_default_generators</buildtool_depend>
  <depend>geometry_msgs</depend>
  <exec_depend>rosidl_default_runtime</exec_depend>
  <member_of_group>rosidl_interface_packages</member_of_group>
  <export><build_type>ament_cmake</build_type></export>
</package>
""",
    'CMakeLists.txt': """cmake_minimum_required(VERSION 3.8)
project(tf2_msgs)
find_package(ament_cmake REQUIRED)
find_package(rosidl_default_generators REQUIRED)
find_package(geometry_msgs REQUIRED)
rosidl_generate_interfaces(${PROJECT_NAME} "msg/TFMessage.msg" DEPENDENCIES geometry_msgs)
ament_export_dependencies(rosidl_default_runtime)
ament_package()
""",
    'msg/TFMessage.msg': 'geometry_msgs/TransformStamped[] transforms\n',
}
CACHE = Path(os.environ.get('XDG_CACHE_HOME', Path.home() / '.cache')) / 'subapf_planner'
#: Where the wheels were built: their exports name these.
BUILDER_PYTHON_INCLUDE = '/opt/python/cp311-cp311/include/python3.11'
BUILDER_NUMPY_INCLUDE = '/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include'


class BuildError(RuntimeError):
    pass


def _key() -> str:
    h = hashlib.sha256(sys.version.encode() + REQUIREMENTS.read_bytes())
    for name, text in sorted(FILES.items()):
        h.update(name.encode() + text.encode())
    return h.hexdigest()[:16]


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


def build(root: Path) -> Path:
    """Write and build the package under ``root``; returns its colcon install prefix."""
    for tool in ('cmake', 'c++'):
        if shutil.which(tool) is None:
            raise BuildError(f'{tool} not found: building tf2_msgs needs cmake and a '
                             'C++ compiler (Debian: cmake, g++)')
    root.mkdir(parents=True, exist_ok=True)
    log, venv = root / 'build.log', root / 'venv'
    if not (venv / 'bin' / 'colcon').exists():
        _run([sys.executable, '-m', 'venv', str(venv)], log)
        _run([str(venv / 'bin' / 'pip'), 'install', '-q', '-r', str(REQUIREMENTS)], log)
        _point_exports_here(venv)
    env = dict(os.environ, PATH=f'{venv / "bin"}{os.pathsep}{os.environ["PATH"]}',
               AMENT_PREFIX_PATH=str(venv), CMAKE_PREFIX_PATH=str(venv),
               PYTHONPATH=str(venv / 'lib' / f'python{sys.version_info.major}.'
                              f'{sys.version_info.minor}' / 'site-packages'))
    src = root / 'src' / 'tf2_msgs'
    for name, text in FILES.items():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        (src / name).write_text(text)
    _run([str(venv / 'bin' / 'colcon'), 'build', '--base-paths', str(src),
          '--build-base', str(root / 'build'), '--install-base', str(root / 'install'),
          '--cmake-args', f'-DPython3_EXECUTABLE={venv / "bin" / "python"}',
          '-DBUILD_TESTING=OFF'], log, env=env, cwd=root)
    return root / 'install' / 'tf2_msgs'


def tf2_msgs_paths() -> dict[str, str]:
    """What a process needs to import the built tf2_msgs and find its message
    definition (share/tf2_msgs/msg, for MCAP and Foxglove schemas), to put in front of
    its PYTHONPATH, LD_LIBRARY_PATH and AMENT_PREFIX_PATH (conftest.with_paths), as a
    sourced workspace would. Builds it first if it is not cached."""
    root = CACHE / f'tf2_msgs-{_key()}'
    prefix = root / 'install' / 'tf2_msgs'
    if not (root / 'ok').exists():
        if root.exists():
            shutil.rmtree(root)
        prefix = build(root)
        (root / 'ok').write_text('built\n')
    site = next(prefix.glob('lib/python*/site-packages'))
    return {'PYTHONPATH': str(site), 'LD_LIBRARY_PATH': str(prefix / 'lib'),
            'AMENT_PREFIX_PATH': str(prefix)}
