"""What a new user types first: ``--help`` on every console script (usage, parameters,
where defaults come from; exit 0, nothing started), a ROS argument before
``--ros-args``, and the README's shell example of sending a goal."""

import dataclasses
import os
from pathlib import Path
import re
import subprocess
import sys
import uuid

from conftest import REPO, marked_processes, wait_for
import pytest
from test_docs import fenced, readme_section, setup_literal
import yaml

pytestmark = pytest.mark.node

#: setup.py's console scripts: (module:function, ros2 run name, venv command).
EXECUTABLES = setup_literal('EXECUTABLES')
NODES = {'subapf-planner': 'planner_node', 'subapf-sim': 'sim_node',
         'subapf-foxglove': 'foxglove_node'}


def own_lines(stderr: str) -> list[str]:
    """The lines of ``stderr`` but pybullet's build-time banner (its import prints it)."""
    return [line for line in stderr.splitlines() if not line.startswith('pybullet build time')]


def run_script(command: str, *args: str, env: dict | None = None
               ) -> subprocess.CompletedProcess:
    """The installed console script ``command`` (next to this Python), tagged so that
    anything it started can be found afterwards."""
    exe = Path(sys.executable).parent / command
    assert exe.is_file(), f'{exe}: not installed (pip install -e .)'
    marker = uuid.uuid4().hex
    r = subprocess.run([str(exe), *args], capture_output=True, text=True, timeout=60,
                       env=dict(env or os.environ, SUBAPF_TEST_MARKER=marker))
    # nothing it started outlives it (a node, a child process)
    wait_for(lambda: not marked_processes(marker), 5.0, f'no process left by {command}')
    return r


@pytest.mark.parametrize('command', sorted(alias for *_, alias in EXECUTABLES))
def test_every_console_script_answers_help(command):
    r = run_script(command, '--help')
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f'usage: {command} '), r.stdout[:200]
    assert '[INFO]' not in r.stdout + r.stderr and 'Traceback' not in r.stderr


@pytest.mark.parametrize('command', sorted(NODES))
def test_a_node_prints_every_parameter_with_its_default_and_starts_nothing(command):
    """-h as --help, before rclpy starts: every parameter of the node's sections, its
    default as a params file writes it, and where defaults come from."""
    import importlib
    module = importlib.import_module(f'subapf_planner.ros.{NODES[command]}')
    r = run_script(command, '-h')
    assert r.returncode == 0 and own_lines(r.stderr) == [], r.stderr
    text = r.stdout
    assert f'ros2 run subapf_planner {NODES[command]}' in text
    assert 'config/planner.yaml' in text
    for _, cls in module.SECTIONS:
        for f in dataclasses.fields(cls):
            default = list(f.default) if isinstance(f.default, tuple) else f.default
            shown = yaml.safe_dump(default, default_flow_style=True, width=10**6).strip()
            shown = shown.removesuffix('\n...').removesuffix('...').strip()
            assert f'  {f.name} (default {shown})' in text, f.name
    if command == 'subapf-planner':
        assert 'config/robots/<robot>.yaml' in text


@pytest.mark.parametrize('command', sorted(NODES))
def test_an_argument_before_ros_args_is_one_clear_error(command):
    r = run_script(command, '--params', 'config/planner.yaml')
    assert r.returncode == 2, r.stdout + r.stderr
    lines = own_lines(r.stderr)
    assert len(lines) == 1 and lines[0].startswith(f'{command}: error: unrecognized '
                                                   'arguments: --params')
    assert '--ros-args' in lines[0]


def test_the_readme_shell_goal_is_a_pose_stamped():
    """The README's ``ros2 topic pub`` example: its message text is YAML that sets fields
    PoseStamped has, to a goal in odom (as ros2 topic pub fills a message)."""
    from geometry_msgs.msg import PoseStamped
    section = readme_section('## The planner node').split('### Sending a goal\n', 1)[1]
    pub = next(line for cmd in fenced(section) for line in cmd.splitlines()
               if line.startswith('ros2 topic pub'))
    topic, kind, values = re.match(r'ros2 topic pub --once(?: -w \d)? (\S+) (\S+) "(.+)"$',
                                   pub).groups()
    assert (topic, kind) == ('/goal_pose', 'geometry_msgs/msg/PoseStamped')

    def fill(msg, fields):
        for name, value in fields.items():
            assert hasattr(msg, name), name   # (ros2 topic pub refuses unknown fields)
            if isinstance(value, dict):
                fill(getattr(msg, name), value)
            else:
                setattr(msg, name, value)
        return msg
    goal = fill(PoseStamped(), yaml.safe_load(values))
    assert goal.header.frame_id == 'odom'
    assert (goal.pose.position.x, goal.pose.position.y) == (2.0, 0.5)
    assert (REPO / 'test' / 'test_goals_dds.py').is_file()   # runs the script beside it
