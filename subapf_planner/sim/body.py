"""The simulated robot's body, built from its description (core/robot.py).

One URDF per robot, written when the simulator starts: the footprint as the body's
collision shape (a cylinder for a disc; for a polygon, the prism over it, which PyBullet
takes as its convex hull), two wheels on the axle at the description's separation and
radius, each velocity-driven with the description's torque limit, and two frictionless
caster spheres half-way to the footprint's front and back. Body and casters are one
link (base_footprint, on the ground at the axle's centre: REP-105), so only the wheels
push against the ground. Mass and inertia: the description's ``body``; where it states
no inertia, a uniform box over the footprint's extent (body) and a uniform cylinder
(wheels, each 3 % of the body's mass). The body's centre of mass is above
base_footprint's origin: PyBullet gives a body's pose as its centre of mass's, which
is then base_footprint's pose (sim/simulator.py true_pose).

Contact of any part of it with an obstacle is a collision (sim/simulator.py): the
footprint the planner keeps clear is what the simulator checks.
"""

from __future__ import annotations

from collections.abc import Iterator
import contextlib
from pathlib import Path
import tempfile

import numpy as np

from ..core.robot import RobotDescription

#: Each wheel's mass as a fraction of the body's.
WHEEL_MASS_FRACTION = 0.03


def _n(value: float) -> str:
    """A number for the URDF, rounded to a micrometre (0.07, not 0.06999999999999999)."""
    return repr(round(float(value), 6))


def _xyz(*values: float) -> str:
    return ' '.join(_n(v) for v in values)


def body_inertia(robot: RobotDescription) -> tuple[float, float, float]:
    """(ixx, iyy, izz) of the body [kg m^2]: the description's, else a uniform box over
    the footprint's extent and the body's height."""
    body = robot.body
    if body.inertia is not None:
        return body.inertia
    outline = robot.outline()
    lx, ly = np.ptp(outline, axis=0)
    m, h = body.mass, body.height
    return (m * (ly ** 2 + h ** 2) / 12.0, m * (lx ** 2 + h ** 2) / 12.0,
            m * (lx ** 2 + ly ** 2) / 12.0)


def wheel_inertia(robot: RobotDescription) -> tuple[float, float, float]:
    """(ixx, iyy, izz) of a wheel about its own centre [kg m^2], the URDF's axes (the
    spin axis is z before the wheel's collision is turned onto y): the description's,
    else a uniform cylinder."""
    if robot.body.wheel_inertia is not None:
        return robot.body.wheel_inertia
    m = WHEEL_MASS_FRACTION * robot.body.mass
    r, w = robot.wheel_radius, robot.body.wheel_width
    side = m * (3.0 * r ** 2 + w ** 2) / 12.0
    return (side, side, m * r ** 2 / 2.0)


def prism_obj(outline: np.ndarray, bottom: float, top: float) -> str:
    """A Wavefront OBJ of the prism over ``outline`` (k, 2) from ``bottom`` to ``top`` [m]."""
    k = len(outline)
    lines = [f'v {_xyz(x, y, z)}' for z in (bottom, top) for x, y in outline]
    lines.append('f ' + ' '.join(str(i + 1) for i in reversed(range(k))))
    lines.append('f ' + ' '.join(str(k + i + 1) for i in range(k)))
    for i in range(k):
        j = (i + 1) % k
        lines.append(f'f {i + 1} {j + 1} {k + j + 1} {k + i + 1}')
    return '\n'.join(lines) + '\n'


def robot_urdf(robot: RobotDescription, mesh: str | None = None) -> str:
    """The URDF of ``robot``'s stand-in; ``mesh``: the path of the footprint's prism (an
    OBJ, prism_obj) for a polygon footprint."""
    body = robot.body
    outline = robot.outline()
    ixx, iyy, izz = body_inertia(robot)
    mass_z = body.bottom + body.height / 2.0 if body.mass_height is None else body.mass_height
    if robot.footprint:
        if mesh is None:
            raise ValueError(f'{robot.name}: a polygon footprint needs its mesh file')
        shape = f'<mesh filename="{mesh}"/>'
        shape_at = _xyz(0.0, 0.0, 0.0)
    else:
        shape = f'<cylinder radius="{_n(robot.radius)}" length="{_n(body.height)}"/>'
        shape_at = _xyz(0.0, 0.0, body.bottom + body.height / 2.0)
    caster = body.bottom / 2.0
    front, back = 2.0 / 3.0 * outline[:, 0].max(), 2.0 / 3.0 * outline[:, 0].min()
    wixx, wiyy, wizz = wheel_inertia(robot)
    wheel_mass = body.wheel_mass if body.wheel_mass is not None \
        else WHEEL_MASS_FRACTION * body.mass

    def wheel(side: str) -> str:
        return f"""  <link name="wheel_{side}_link">
    <inertial>
      <mass value="{_n(wheel_mass)}"/>
      <inertia ixx="{_n(wixx)}" ixy="0" ixz="0" iyy="{_n(wiyy)}" iyz="0" izz="{_n(wizz)}"/>
    </inertial>
    <collision>
      <origin xyz="0 0 0" rpy="1.5707963 0 0"/>
      <geometry><cylinder radius="{_n(robot.wheel_radius)}" length="{_n(body.wheel_width)}"/>\
</geometry>
    </collision>
  </link>
"""

    def joint(side: str, y: float) -> str:
        return f"""  <joint name="wheel_{side}_joint" type="continuous">
    <parent link="base_footprint"/>
    <child link="wheel_{side}_link"/>
    <origin xyz="{_xyz(0.0, y, robot.wheel_radius)}"/>
    <axis xyz="0 1 0"/>
  </joint>
"""

    half = robot.wheel_separation / 2.0
    return f"""<?xml version="1.0"?>
<!-- {robot.name} stand-in for the headless PyBullet simulator of subapf_planner,
     written from its description (subapf_planner/core/robot.py, sim/body.py). -->
<robot name="{robot.name}_standin">
  <link name="base_footprint">
    <inertial>
      <origin xyz="{_xyz(0.0, 0.0, mass_z)}"/>
      <mass value="{_n(body.mass)}"/>
      <inertia ixx="{_n(ixx)}" ixy="0" ixz="0" iyy="{_n(iyy)}" iyz="0" izz="{_n(izz)}"/>
    </inertial>
    <collision>
      <origin xyz="{shape_at}"/>
      <geometry>{shape}</geometry>
    </collision>
    <collision>
      <origin xyz="{_xyz(front, 0.0, caster)}"/>
      <geometry><sphere radius="{_n(caster)}"/></geometry>
    </collision>
    <collision>
      <origin xyz="{_xyz(back, 0.0, caster)}"/>
      <geometry><sphere radius="{_n(caster)}"/></geometry>
    </collision>
  </link>
{wheel('left')}{wheel('right')}{joint('left', half)}{joint('right', -half)}</robot>
"""


@contextlib.contextmanager
def urdf_file(robot: RobotDescription) -> Iterator[Path]:
    """The robot's URDF (and its footprint's mesh) in a temporary directory, for
    PyBullet's loadURDF; removed afterwards."""
    with tempfile.TemporaryDirectory(prefix='subapf_robot_') as folder:
        mesh = None
        if robot.footprint:
            mesh = Path(folder) / 'footprint.obj'
            mesh.write_text(prism_obj(robot.outline(), robot.body.bottom,
                                      robot.body.bottom + robot.body.height))
        path = Path(folder) / f'{robot.name}.urdf'
        path.write_text(robot_urdf(robot, None if mesh is None else str(mesh)))
        yield path


def wheel_speeds(robot: RobotDescription, v: float, w: float) -> tuple[float, float]:
    """The wheels' angular velocities (left, right) [rad/s] for the base's (v, w)."""
    return ((v - w * robot.wheel_separation / 2) / robot.wheel_radius,
            (v + w * robot.wheel_separation / 2) / robot.wheel_radius)
