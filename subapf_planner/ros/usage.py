"""``--help`` of the package's nodes: usage, topics and every parameter with its default,
from the same dataclass metadata the nodes declare their parameters from.

Printed by ros/spinning.spin_node before rclpy is initialised: nothing is started.
"""

from __future__ import annotations

import dataclasses
import textwrap

import yaml

from ..core.params import describe
from .paths import default_params_file

WIDTH = 88


def _default(value: object) -> str:
    """A default as a params file writes it (YAML flow style: true, 0.22, [a, b])."""
    text = yaml.safe_dump({'v': value}, default_flow_style=True, width=10**6).strip()
    return text[len('{v: '):-1]


def _params_file() -> str:
    try:
        return str(default_params_file())
    except FileNotFoundError:
        return 'config/planner.yaml (not found in this install)'


def node_usage(prog: str, exe: str, node_name: str, summary: str,
               sections: tuple[tuple[str, type], ...], defaults: str = '') -> str:
    """The help text of a node: ``prog`` (the venv command) and ``exe`` (the ``ros2 run``
    name), ``summary`` (paragraphs), then each section's parameters with type, default
    and description; ``defaults`` says where else defaults come from."""
    wrap = textwrap.TextWrapper(WIDTH)
    lines = [f'usage: {prog} [-h] [--ros-args [-p NAME:=VALUE] [--params-file FILE] ...]',
             f'       ros2 run subapf_planner {exe} [--ros-args ...]', '']
    for paragraph in summary.strip().split('\n\n'):
        lines += wrap.wrap(' '.join(paragraph.split())) + ['']
    where = (f'Parameters of node {node_name}: -p NAME:=VALUE or a --params-file (its '
             f'"{node_name}: ros__parameters:" section, or "/**"); at run time with ros2 '
             'param set, validated (refused with the reason, old value kept), except '
             'read-only ones. A bad value at start exits with code 2 naming it; a name '
             'the node does not have is reported with the closest one. Defaults: the '
             "values below, from the code's dataclass metadata; the package's params file "
             f'holds the same ({_params_file()}, section {node_name}). Besides these, '
             "ROS's own use_sim_time.")
    lines += wrap.wrap(where + (' ' + defaults if defaults else '')) + ['']
    body = textwrap.TextWrapper(WIDTH, initial_indent=' ' * 8, subsequent_indent=' ' * 8)
    for title, cls in sections:
        lines.append(f'{title}:')
        for f in dataclasses.fields(cls):
            lines.append(f'  {f.name} (default {_default(f.default)})')
            lines += body.wrap(describe(f))
        lines.append('')
    return '\n'.join(lines).rstrip() + '\n'
