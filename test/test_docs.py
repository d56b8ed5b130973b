"""The README stays true to CI and the package; the package metadata to the code."""

import ast
import importlib.metadata
from pathlib import Path
import re
import sys
import xml.etree.ElementTree as ET

from conftest import REPO
import pytest

pytestmark = pytest.mark.core

#: package.xml's rosdep keys for PyPI distributions.
ROSDEP_KEYS = {'python3-numpy': 'numpy', 'python3-scipy': 'scipy', 'python3-yaml': 'pyyaml',
               'python3-matplotlib': 'matplotlib', 'python3-tqdm': 'tqdm'}


def fenced_commands():
    return fenced(readme_section('## Fresh machine: two commands'))


def readme_section(title: str) -> str:
    return (REPO / 'README.md').read_text().split(title + '\n', 1)[1].split('\n## ', 1)[0]


def fenced(section: str) -> list[str]:
    return re.findall(r'```bash\n(.+?)\n```', section, re.S)


def setup_literal(name: str):
    """A module-level literal of setup.py, without running it."""
    tree = ast.parse((REPO / 'setup.py').read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, 'id', None) == name
                                                for t in node.targets):
            return ast.literal_eval(node.value)
    raise AssertionError(f'no {name} in setup.py')


def dist_name(requirement: str) -> str:
    return re.match(r'[A-Za-z0-9_.-]+', requirement).group(0).lower().replace('_', '-')


def imports() -> set[str]:
    """Top-level names of every absolute import under subapf_planner/ and launch/."""
    found = set()
    for path in [*(REPO / 'subapf_planner').rglob('*.py'), *(REPO / 'launch').glob('*.py')]:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                found |= {a.name.split('.')[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                found.add(node.module.split('.')[0])
    return found - set(sys.stdlib_module_names) - {'subapf_planner', '__future__'}


def is_ros(module: str) -> bool:
    return module in ('rclpy', 'ament_index_python', 'launch', 'launch_ros') \
        or module.endswith(('_msgs', '_interfaces'))


def test_readme_has_exactly_two_fresh_machine_commands():
    cmds = fenced_commands()
    assert len(cmds) == 2 and all('\n' not in c for c in cmds)
    demo, tests = cmds
    assert 'subapf-bringup --world sim/worlds/fig6d_big_wall.yaml' in demo
    assert 'pytest' in tests


def test_ci_runs_the_readme_test_command_verbatim():
    ci = (REPO / '.ci' / 'run').read_text().splitlines()
    assert fenced_commands()[1] in ci


def test_readme_executables_table_is_setup_py():
    section = readme_section('## In a ROS 2 Jazzy workspace')
    rows = re.findall(r'^\| `(\w+)` \| `(subapf-[\w-]+)` \|', section, re.M)
    assert sorted(rows) == sorted((exe, alias) for _, exe, alias in setup_literal('EXECUTABLES'))


def test_package_xml_names_every_ros_package_imported_and_no_other():
    root = ET.parse(REPO / 'package.xml').getroot()
    ros_depends = {e.text for e in root.findall('exec_depend')
                   if not e.text.startswith('python3-')}
    assert ros_depends == {m for m in imports() if is_ros(m)}


def test_install_requires_is_what_the_code_imports_minus_ros():
    dists = importlib.metadata.packages_distributions()
    needed = set()
    for module in imports():
        if is_ros(module):
            continue
        assert module in dists, f'{module} is imported but not installed'
        needed |= {d.lower().replace('_', '-') for d in dists[module]}
    required = {dist_name(r) for r in setup_literal('INSTALL_REQUIRES')}
    assert not any(is_ros(r.replace('-', '_')) or r.startswith('ros-') for r in required)
    assert needed == required


def test_workspace_instructions_install_every_non_ros_dependency_once():
    """rosdep (package.xml's python3-* keys) plus the README's pip line give exactly
    install_requires, and the pip line pins as setup.py does; no ROS wheel from pip."""
    section = readme_section('## In a ROS 2 Jazzy workspace')
    pip = [line for cmd in fenced(section) for line in cmd.splitlines()
           if line.startswith('pip install')]
    assert len(pip) == 1 and 'requirements' not in pip[0] and 'ros-' not in pip[0]
    pinned = set(re.findall(r"'([^']+)'", pip[0]))
    root = ET.parse(REPO / 'package.xml').getroot()
    rosdep = {ROSDEP_KEYS[e.text] for e in root.findall('exec_depend')
              if e.text.startswith('python3-')}
    required = set(setup_literal('INSTALL_REQUIRES'))
    assert pinned <= required
    assert {dist_name(r) for r in pinned} | rosdep == {dist_name(r) for r in required}
    assert not {dist_name(r) for r in pinned} & rosdep


def test_requirements_txt_holds_only_the_ros_wheels():
    lines = [line for line in (REPO / 'requirements.txt').read_text().splitlines()
             if line.strip() and not line.startswith('#')]
    assert lines and all(line.startswith('ros-jazzy-') for line in lines)
    test_lines = (REPO / 'requirements-test.txt').read_text().splitlines()
    assert '-r requirements.txt' in test_lines


def test_docs_cited_by_the_code_exist():
    """Every docs/... file a module, test or the README points to is in the repository."""
    for path in [*(REPO / 'subapf_planner').rglob('*.py'), *(REPO / 'test').glob('*.py'),
                 REPO / 'README.md']:
        for cited in re.findall(r'\bdocs/[\w./-]+\.(?:md|png)', path.read_text()):
            assert (REPO / cited).is_file(), f'{Path(path).name} cites missing {cited}'
