"""``config/planner.yaml`` written from the parameter dataclasses' metadata.

The file documents every parameter of both nodes (default, unit, range or
choices, read-only) and is the params file the nodes, ``subapf-bench`` and
``subapf-replay`` read; ``test/test_config.py`` checks the committed file equals
what :func:`render` writes, so it cannot drift from the code. Regenerate with
``python -m subapf_planner.tools.paramdoc config/planner.yaml``.
"""

from __future__ import annotations

import dataclasses
import sys
import textwrap

import yaml

from ..core.config import PlannerConfig
from ..core.loop import Supervision
from ..sim.faults import ScanFaults
from ..sim.simulator import SimConfig

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
    m = f.metadata
    text = m['description'] + (f' [{m["unit"]}]' if m['unit'] else '')
    if m.get('choices'):
        text += '; one of: ' + ', '.join(m['choices'])
    elif m.get('lo') is not None:
        text += f'; range [{m["lo"]}, {m["hi"]}]'
    if m.get('read_only'):
        text += '; read-only'
    return textwrap.wrap(text + '.', 76, initial_indent='    # ', subsequent_indent='    # ')


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
    from ..ros.planner_node import NodeOptions
    from ..ros.sim_node import SimNodeOptions
    planner = _section('subapf_planner', [('node (ros/planner_node.py)', NodeOptions),
                                          ('supervision (core/loop.py)', Supervision),
                                          ('planner core (core/config.py)', PlannerConfig)])
    sim = _section('subapf_sim', [('node (ros/sim_node.py)', SimNodeOptions),
                                  ('simulator (sim/simulator.py)', SimConfig),
                                  ('scan faults (sim/faults.py)', ScanFaults)])
    return HEADER + '\n'.join(planner + [''] + sim) + '\n'


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    text = render()
    if argv:
        with open(argv[0], 'w') as out:
            out.write(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
