"""The README and docs/ stay true to CI and the package; the package metadata to the
code; the CHANGELOG is by version; the results pages are what subapf-results writes."""

import ast
import importlib.metadata
from pathlib import Path
import re
import sys
import xml.etree.ElementTree as ET

from conftest import REPO
import pytest
import yaml

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
    """Every docs/... file a module, test or page points to is in the repository."""
    for path in [*(REPO / 'subapf_planner').rglob('*.py'), *(REPO / 'test').glob('*.py'),
                 *pages()]:
        for cited in re.findall(r'\bdocs/[\w./-]+\.(?:md|png|json|yaml)', path.read_text()):
            assert (REPO / cited).is_file(), f'{Path(path).name} cites missing {cited}'


# --- the manual: README, docs/, CHANGELOG ----------------------------------------------

#: Keep a Changelog's sections.
CHANGELOG_SECTIONS = {'Added', 'Changed', 'Deprecated', 'Removed', 'Fixed', 'Security'}
README_MAX_LINES = 400
DATA_FLOW_MAX_LINES = 40


def pages() -> list[Path]:
    """The manual's pages: README, CHANGELOG and docs/*.md."""
    return [REPO / 'README.md', REPO / 'CHANGELOG.md', *sorted((REPO / 'docs').glob('*.md'))]


def hand_written() -> list[Path]:
    """The pages written by hand (docs/results.md is subapf-results' output)."""
    return [p for p in pages() if p != REPO / 'docs' / 'results.md']


def slug(heading: str) -> str:
    """GitHub's anchor for a Markdown heading."""
    text = re.sub(r'[^\w\- ]', '', heading.strip().lower())
    return text.replace(' ', '-')


def anchors(page: Path) -> set[str]:
    """The anchors of a page's headings (duplicates numbered as GitHub does)."""
    seen: dict[str, int] = {}
    found = set()
    text = re.sub(r'```.*?```', '', page.read_text(), flags=re.S)
    for heading in re.findall(r'^#{1,6} (.+)$', text, re.M):
        base = slug(heading)
        found.add(base if base not in seen else f'{base}-{seen[base]}')
        seen[base] = seen.get(base, 0) + 1
    return found


def links(page: Path) -> list[str]:
    """The targets of a page's Markdown links, outside code."""
    text = re.sub(r'```.*?```', '', page.read_text(), flags=re.S)
    text = re.sub(r'`[^`\n]*`', '', text)
    return re.findall(r'\]\(([^)\s]+)\)', text)


def test_links_between_pages_resolve():
    """Every relative link of the manual names an existing file, and an anchor in a
    Markdown page names one of its headings."""
    for page in pages():
        for target in links(page):
            if re.match(r'[a-z]+:', target):
                continue
            path, _, anchor = target.partition('#')
            file = (page.parent / path).resolve() if path else page
            assert file.exists(), f'{page.name} links to missing {target}'
            if anchor and file.suffix == '.md':
                assert anchor in anchors(file), f'{page.name} links to no heading: {target}'


def test_readme_is_short_and_keeps_its_sections():
    text = (REPO / 'README.md').read_text()
    assert len(text.splitlines()) <= README_MAX_LINES
    for title in ('## Contents', '## Fresh machine: two commands',
                  '## In a ROS 2 Jazzy workspace', '## The planner node', '## Robot configs',
                  '## Watching a run', '## Results', '## Layout'):
        assert f'\n{title}\n' in text, title
    layout = readme_section('## Layout')
    flow = layout.split('### Data flow of one cycle\n', 1)
    assert len(flow) == 2, 'no "### Data flow of one cycle" under Layout'
    assert len(flow[1].rstrip().splitlines()) <= DATA_FLOW_MAX_LINES


def test_the_manual_tells_no_history():
    """The pages describe the package as it is: no working sessions or rounds, and no
    commit hashes in prose (a table may name the commit that produced its figures)."""
    history = re.compile(r'\bsessions?\b|\b(?:this|that|next|previous|last|earlier|each'
                         r'|first|second|third|fourth|fifth|sixth|seventh|eighth|ninth'
                         r'|tenth) rounds?\b|\b(?:ninth|tenth|eleventh|twelfth)\b', re.I)
    commit = re.compile(r'\b(?=[0-9a-f]*[0-9])(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}\b')
    for page in hand_written():
        for n, line in enumerate(page.read_text().splitlines(), 1):
            assert not history.search(line), f'{page.name}:{n}: {line}'
            if not line.lstrip().startswith('|'):
                assert not commit.search(line), f'{page.name}:{n}: {line}'


def released_versions() -> list[tuple[str, str]]:
    """(version, date) of the CHANGELOG's releases, newest first."""
    return re.findall(r'^## \[(\d+\.\d+\.\d+)\] - (\d{4}-\d{2}-\d{2})$',
                      (REPO / 'CHANGELOG.md').read_text(), re.M)


def setup_version() -> str:
    """setup.py's ``version=``, without running it."""
    tree = ast.parse((REPO / 'setup.py').read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and getattr(node.func, 'id', None) == 'setup':
            for kw in node.keywords:
                if kw.arg == 'version':
                    return ast.literal_eval(kw.value)
    raise AssertionError('no setup(version=...) in setup.py')


def test_changelog_is_by_version():
    """Keep a Changelog: Unreleased first, then releases newest first with their dates,
    each section one of Added, Changed, Deprecated, Removed, Fixed, Security."""
    text = (REPO / 'CHANGELOG.md').read_text()
    headings = re.findall(r'^## (.+)$', text, re.M)
    assert headings[0] == '[Unreleased]'
    releases = released_versions()
    assert len(releases) == len(headings) - 1 >= 1, 'a release heading out of format'
    numbers = [tuple(int(x) for x in v.split('.')) for v, _ in releases]
    assert numbers == sorted(numbers, reverse=True) and len(set(numbers)) == len(numbers)
    dates = [d for _, d in releases]
    assert dates == sorted(dates, reverse=True)
    assert set(re.findall(r'^### (.+)$', text, re.M)) <= CHANGELOG_SECTIONS


def test_package_version_is_the_newest_release():
    newest = released_versions()[0][0]
    xml_version = ET.parse(REPO / 'package.xml').getroot().findtext('version')
    assert setup_version() == xml_version == newest


def tables(text: str, first_header: str) -> list[str]:
    """The Markdown tables of ``text`` whose header's first cell is ``first_header``."""
    found = re.findall(r'^\|.*\|\n(?:\|.*\|\n?)+', text, re.M)
    return [t for t in found if t.startswith(f'| {first_header} |')]


def test_parameters_named_in_the_docs_exist():
    """Every parameter in the README's and docs/parameters.md's parameter tables is in
    config/planner.yaml."""
    doc = yaml.safe_load((REPO / 'config' / 'planner.yaml').read_text())
    known = {name for node in doc.values() for name in node['ros__parameters']}
    text = readme_section('## The planner node') + (REPO / 'docs' / 'parameters.md').read_text()
    rows = re.findall(r'^\| ((?:`\w+`(?: / )?)+) \|', ''.join(tables(text, 'parameter')), re.M)
    named = {n for row in rows for n in re.findall(r'`(\w+)`', row)}
    assert len(named) > 50
    assert named <= known, named - known


def test_results_pages_are_what_subapf_results_writes():
    """docs/results.md and the README's headline table come from docs/results/data/
    (run subapf-results after changing a results file, never edit them by hand)."""
    from subapf_planner.tools.results import main
    data = REPO / 'docs' / 'results' / 'data'
    assert main(['--check', '--data', str(data), '--out', str(REPO / 'docs' / 'results.md'),
                 '--readme', str(REPO / 'README.md')]) == 0


def test_the_readme_state_table_is_the_state_enum():
    """README "States": one row per State, in the enum's order, its final column
    State.final; mapping documented as the normal first state."""
    from subapf_planner.core.status import State
    table, = tables(readme_section('## The planner node'), 'state')
    rows = re.findall(r'^\| `(\w+)` \| (.+) \| (yes|no) \|$', table, re.M)
    assert [(name, final == 'yes') for name, _, final in rows] == \
        [(str(s), s.final) for s in State]
    meaning = {name: text for name, text, _ in rows}
    assert 'normal first state' in meaning['mapping']
    assert {str(s) for s in State if s.final} == {'reached', 'stuck', 'unreachable'}

