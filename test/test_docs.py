"""The README's two fresh-machine commands stay true to CI and the package."""

import re

from conftest import REPO


def fenced_commands():
    text = (REPO / 'README.md').read_text()
    section = text.split('## Fresh machine: two commands', 1)[1].split('\n## ', 1)[0]
    return re.findall(r'```bash\n(.+?)\n```', section, re.S)


def test_readme_has_exactly_two_fresh_machine_commands():
    cmds = fenced_commands()
    assert len(cmds) == 2 and all('\n' not in c for c in cmds)
    demo, tests = cmds
    assert 'subapf-bringup --world sim/worlds/fig6d_big_wall.yaml' in demo
    assert 'pytest' in tests


def test_ci_runs_the_readme_test_command_verbatim():
    ci = (REPO / '.ci' / 'run').read_text().splitlines()
    assert fenced_commands()[1] in ci
