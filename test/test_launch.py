"""Launch files: ``launch`` is not on PyPI, so what can be checked here is: each file
parses, and every executable, file, parameter and launch argument it names exists
(colcon installing them: test_colcon.py)."""

import ast
import dataclasses

from conftest import REPO
import pytest
from test_colcon import BARE

from subapf_planner.core.robot import ROBOTS
from subapf_planner.ros.foxglove_node import FoxgloveOptions
from subapf_planner.ros.planner_node import GROUPS as PLANNER_GROUPS
from subapf_planner.ros.sim_node import GROUPS as SIM_GROUPS

pytestmark = pytest.mark.core

LAUNCH = REPO / 'launch'
#: Where setup.py installs each share/ folder from (share/<pkg>/<key> <- repo/<value>).
SHARE = {'config': REPO / 'config', 'worlds': REPO / 'sim' / 'worlds', 'launch': LAUNCH}
PARAMETERS = {
    'planner_node': {f.name for g in PLANNER_GROUPS for f in dataclasses.fields(g)},
    'lifecycle_planner_node': {f.name for g in PLANNER_GROUPS for f in dataclasses.fields(g)},
    'sim_node': {f.name for g in SIM_GROUPS for f in dataclasses.fields(g)},
    'foxglove_node': {f.name for f in dataclasses.fields(FoxgloveOptions)},
}


def calls(tree: ast.AST, name: str) -> list[ast.Call]:
    return [n for n in ast.walk(tree) if isinstance(n, ast.Call)
            and getattr(n.func, 'id', getattr(n.func, 'attr', None)) == name]


def keyword(call: ast.Call, name: str):
    return next((k.value for k in call.keywords if k.arg == name), None)


def constant(tree: ast.Module, expr: ast.expr):
    """The value of a literal, or of a module-level NAME = literal."""
    if isinstance(expr, ast.Name):
        expr = next(n.value for n in tree.body
                    if isinstance(n, ast.Assign) and n.targets[0].id == expr.id)
    return ast.literal_eval(expr)


def declared(tree: ast.AST) -> dict[str, ast.Call]:
    return {ast.literal_eval(c.args[0]): c for c in calls(tree, 'DeclareLaunchArgument')}


def share_paths(tree: ast.AST) -> list[list]:
    """The constant parts after FindPackageShare of each PathJoinSubstitution([share, ...]);
    a part built from substitutions is a list of constants and None."""
    out = []
    for c in calls(tree, 'PathJoinSubstitution'):
        parts = c.args[0].elts
        if isinstance(parts[0], ast.Name) and parts[0].id == 'share':
            out.append([p.value if isinstance(p, ast.Constant) else
                        [q.value if isinstance(q, ast.Constant) else None for q in p.elts]
                        for p in parts[1:]])
    return out


@pytest.fixture(params=sorted(p.name for p in LAUNCH.glob('*.launch.py')))
def launch_file(request):
    path = LAUNCH / request.param
    return path, ast.parse(path.read_text(), filename=str(path))


def test_both_launch_files_ship():
    assert {p.name for p in LAUNCH.glob('*.launch.py')} == {
        'planner.launch.py', 'sim.launch.py', 'nav2.launch.py'}


def test_a_launch_file_defines_its_description(launch_file):
    _, tree = launch_file
    assert any(isinstance(n, ast.FunctionDef) and n.name == 'generate_launch_description'
               for n in tree.body)


#: Nodes of Nav2 a launch file may start: (package, executable) -> the parameters it
#: may set (nav2_lifecycle_manager's, as docs.nav2.org lists them for Jazzy).
NAV2 = {('nav2_lifecycle_manager', 'lifecycle_manager'): {
    'autostart', 'node_names', 'bond_timeout', 'bond_heartbeat_period',
    'attempt_respawn_reconnection', 'bond_respawn_max_duration', 'service_timeout'}}


def test_nodes_name_existing_executables_and_parameters(launch_file):
    _, tree = launch_file
    for node in calls(tree, 'Node'):
        package = constant(tree, keyword(node, 'package'))
        exe = constant(tree, keyword(node, 'executable'))
        if package != 'subapf_planner':
            assert (package, exe) in NAV2, (package, exe)
            for item in keyword(node, 'parameters').elts:
                names = {ast.literal_eval(k) for k in item.keys}
                assert names <= NAV2[package, exe] | {'use_sim_time'}, names
            continue
        assert exe in BARE, exe
        for item in keyword(node, 'parameters').elts:
            if isinstance(item, ast.Dict):   # parameters set in the file
                names = {ast.literal_eval(k) for k in item.keys}
                assert names <= PARAMETERS[exe] | {'use_sim_time'}, names


def test_share_files_named_exist_in_the_source_tree(launch_file):
    _, tree = launch_file
    robot_choices = None
    arg = declared(tree).get('robot')
    if arg is not None:
        robot_choices = constant(tree, keyword(arg, 'choices'))
    for parts in share_paths(tree):
        folder, *rest = parts
        if rest and isinstance(rest[-1], list):   # <robot>.yaml: every choice must exist
            assert rest[-1][1:] == ['.yaml'] and robot_choices
            for robot in robot_choices:
                assert (SHARE[folder].joinpath(*rest[:-1]) / f'{robot}.yaml').is_file()
        else:
            assert SHARE[folder].joinpath(*rest).is_file(), parts
    if robot_choices is not None:
        assert set(robot_choices) == set(ROBOTS)


def test_included_launch_arguments_are_declared_there():
    sim = ast.parse((LAUNCH / 'sim.launch.py').read_text())
    planner_args = set(declared(ast.parse((LAUNCH / 'planner.launch.py').read_text())))
    include = calls(sim, 'IncludeLaunchDescription')
    assert len(include) == 1
    given = keyword(include[0], 'launch_arguments').func.value   # {...}.items()
    assert {ast.literal_eval(k) for k in given.keys} <= planner_args
    robot = given.values[[ast.literal_eval(k) for k in given.keys].index('robot')]
    assert ast.literal_eval(robot.args[0]) == 'robot'   # LaunchConfiguration('robot')
    assert 'robot' in declared(sim)
