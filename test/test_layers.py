"""The dependency rule between the package's layers, read from the imports.

core/  pure numpy/scipy: no ROS, no simulator, no plotting, no bags; imports core only
sim/   the simulator and the in-process loop: no ROS, no bags, no plotting; core and sim
bag/   MCAP reading and writing: nothing of the package
ros/   nodes and conversions: core, sim, bag, ros; never tools
tools/ commands: anything
"""

import ast
from pathlib import Path

import pytest

pytestmark = pytest.mark.core

PACKAGE = Path(__file__).resolve().parents[1] / 'subapf_planner'
ROS = ('rclpy', 'rcl_interfaces', 'builtin_interfaces', 'rosidl_runtime_py',
       'ament_index_python')
ALLOWED_LAYERS = {
    'core': {'core'},
    'sim': {'core', 'sim'},
    'bag': {'bag'},
    'ros': {'core', 'sim', 'bag', 'ros'},
    'tools': {'core', 'sim', 'bag', 'ros', 'tools'},
}
FORBIDDEN_THIRD_PARTY = {
    'core': ROS + ('pybullet', 'matplotlib', 'mcap', 'mcap_ros2', 'tqdm'),
    'sim': ROS + ('matplotlib', 'mcap', 'mcap_ros2', 'tqdm'),
    'bag': ('pybullet', 'matplotlib'),
    'ros': ('matplotlib', 'tqdm'),
    'tools': (),
}


def imports_of(path: Path) -> list[tuple[str, int]]:
    """(imported module, level) for every import in the file, nested ones included."""
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out += [(alias.name, 0) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            out.append((node.module or '', node.level))
    return out


def layer_of_import(module: str, level: int, package: tuple[str, ...]) -> str | None:
    """The package layer an import reaches from a module of ``package`` (its folders
    under subapf_planner/, e.g. ('core', 'critics')), or None for a third-party module."""
    if level > 0:
        parts = [*package[:len(package) - (level - 1)], *filter(None, module.split('.'))]
        return parts[0] if parts else None
    if module.startswith('subapf_planner.'):
        return module.split('.')[1]
    return None


def modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob('*.py') if p.parent != PACKAGE)


def folders(path: Path) -> tuple[str, ...]:
    """A module's folders under subapf_planner/: its layer first."""
    return path.relative_to(PACKAGE).parts[:-1]


def test_every_module_lives_in_a_layer():
    assert {folders(p)[0] for p in modules()} == set(ALLOWED_LAYERS)
    top = {p.name for p in PACKAGE.glob('*.py')}
    assert top == {'__init__.py'}, f'modules outside a layer: {top}'


@pytest.mark.parametrize('path', modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_follow_the_layer_rule(path):
    layer = folders(path)[0]
    bad = []
    for module, level in imports_of(path):
        reached = layer_of_import(module, level, folders(path))
        if reached is not None and reached not in ALLOWED_LAYERS[layer]:
            bad.append(f'{module or "."} (level {level}) -> {reached}')
        top = module.split('.')[0]
        if level == 0 and (top in FORBIDDEN_THIRD_PARTY[layer] or (
                layer in ('core', 'sim') and top.endswith('_msgs'))):
            bad.append(module)
    assert not bad, f'{layer}/{path.name} imports {bad}'


def test_the_rule_catches_a_violation(tmp_path):
    bad = tmp_path / 'core' / 'x.py'
    bad.parent.mkdir()
    bad.write_text('from ..ros.conversions import scan_from_msg\nimport rclpy\n')
    found = imports_of(bad)
    assert layer_of_import(*found[0], ('core',)) == 'ros'
    assert layer_of_import(*found[0], ('core', 'critics')) == 'core'
    assert layer_of_import('ros.conversions', 3, ('core', 'critics')) == 'ros'
    assert found[1] == ('rclpy', 0)
