"""``config/planner.yaml`` and ``config/robots/*.yaml`` written from the code.

``planner.yaml`` documents every parameter of both nodes (default, unit, range or
choices, read-only) and is the params file the nodes, ``subapf-bench`` and
``subapf-replay`` read. Each robot file holds the planner node's parameters that
come from one robot (core/robot.py ROBOTS: its name as ``robot``, footprint and the
clearances derived from it, laser mounting, frame and range, limits, cmd_vel type),
loaded after
planner.yaml. ``test/test_config.py`` checks the committed files equal what
:func:`render` and :func:`render_robot` write, so they cannot drift from the code.
Regenerate with ``python -m subapf_planner.tools.paramdoc config/planner.yaml
config/robots``.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
import sys
import textwrap

import yaml

from ..core.config import robot_fields
from ..core.params import describe
from ..core.robot import ROBOTS, RobotDescription

HEADER = """\
# Parameters of the subapf_planner nodes (ROS 2 params file), written by
# `python -m subapf_planner.tools.paramdoc config/planner.yaml` from the code's
# metadata. Load with:
#   subapf-planner --ros-args --params-file config/planner.yaml
#   ros2 run subapf_planner planner_node --ros-args --params-file config/planner.yaml
# subapf-bench and subapf-replay read the subapf_planner section. Every value
# below is the default; units are SI and angles radians. Ranges are enforced at
# start (exit code 2 naming the parameter) and at run time (refused, old value
# kept); read-only parameters are read at start only.
"""


def _comment(f: dataclasses.Field) -> list[str]:
    return textwrap.wrap(describe(f), 76, initial_indent='    # ', subsequent_indent='    # ')


def _section(node: str, groups: list[tuple[str, type]]) -> list[str]:
    lines = [f'{node}:', '  ros__parameters:']
    for title, cls in groups:
        lines.append(f'    # --- {title} ' + '-' * max(3, 70 - len(title)))
        for f in dataclasses.fields(cls):
            value = yaml.safe_dump({f.name: f.default}, default_flow_style=True, width=200)
            lines += _comment(f) + ['    ' + value.strip()[1:-1]]
    return lines


def render() -> str:
    """The whole params file."""
    from ..ros.foxglove_node import SECTIONS as FOXGLOVE_SECTIONS
    from ..ros.planner_node import SECTIONS as PLANNER_SECTIONS
    from ..ros.sim_node import SECTIONS as SIM_SECTIONS
    planner = _section('subapf_planner', PLANNER_SECTIONS)
    sim = _section('subapf_sim', SIM_SECTIONS)
    relay = _section('subapf_foxglove', FOXGLOVE_SECTIONS)
    return HEADER + '\n'.join(planner + [''] + sim + [''] + relay) + '\n'


def robot_parameters(robot: RobotDescription) -> dict[str, float | str | bool]:
    """The planner node's parameters that come from ``robot``: its base and laser
    frames, its cmd_vel type and core/config.py's robot_fields."""
    return {'base_frame': robot.base_frame, 'laser_frame': robot.laser_frame,
            'enable_stamped_cmd_vel': robot.stamped_cmd_vel, **robot_fields(robot)}


def render_robot(key: str) -> str:
    """The parameter file of ``ROBOTS[key]``."""
    robot = ROBOTS[key]
    lines = [f'# {robot.name}: the planner node parameters that come from the robot,',
             '# written by `python -m subapf_planner.tools.paramdoc config/planner.yaml '
             'config/robots`', '# from core/robot.py. Load after planner.yaml:',
             f'#   --params-file config/planner.yaml --params-file config/robots/{key}.yaml',
             f'#   (or launch/planner.launch.py robot:={key}).',
             *textwrap.wrap('Sources: ' + robot.source + '.', 86, initial_indent='# ',
                            subsequent_indent='#   '),
             'subapf_planner:', '  ros__parameters:']
    for name, value in {'robot': key, **robot_parameters(robot)}.items():
        lines.append('    ' + yaml.safe_dump({name: value}, default_flow_style=True,
                                              width=200).strip()[1:-1])
    return '\n'.join(lines) + '\n'


def main(argv: list[str] | None = None) -> int:
    """``paramdoc [planner.yaml [robots/]]``: the params file (stdout without a path)
    and the robot files in the folder."""
    argv = sys.argv[1:] if argv is None else argv
    text = render()
    if argv:
        with open(argv[0], 'w') as out:
            out.write(text)
    else:
        sys.stdout.write(text)
    if len(argv) > 1:
        folder = Path(argv[1])
        folder.mkdir(parents=True, exist_ok=True)
        for key in ROBOTS:
            (folder / f'{key}.yaml').write_text(render_robot(key))
    return 0


if __name__ == '__main__':
    sys.exit(main())
